/* Discrete state of the walker: support flags, arming, anchors (docs/model.md sections 5, 6),
 * recording and stop checks shared by every time loop. */
#include <math.h>
#include <string.h>
#include "pdw_sim.h"

static void kinematics(const pdw_kernel *k, const pdw_ground *g, const double *p, const double *x,
                       const double *anchors, double *work)
{
    pdw_trig(x, work + PDW_WORK_TRIG);
    if (g) pdw_terrain_kinematics(k, g, x, work + PDW_WORK_TRIG, p, anchors, work + PDW_WORK_KIN,
                                  work + PDW_WORK_GROUND, work + PDW_WORK_GROUND_CELL);
    else k->kinematics(x, work + PDW_WORK_TRIG, p, anchors, work + PDW_WORK_KIN);
}

/* The blend zone of foot i's contact point (support), -1 (swing or no patches); hint: its zone at
 * the last step (or -1). */
static inline int zone_of(const pdw_ground *g, int support, const double *ki, int hint)
{
    return g && g->n_zones > 0 && support ? pdw_ground_zone_hint(g, ki[PDW_KIN_X_D], hint) : -1;
}

void pdw_discrete_init(const pdw_kernel *k, const pdw_ground *g, const double *p, const double *x,
                       const int flags0[2], pdw_discrete *d, double *work)
{
    const double zero[PDW_NANCHOR] = {0.0};
    kinematics(k, g, p, x, zero, work);
    for (int i = 0; i < 2; ++i) {
        const double *ki = work + PDW_WORK_KIN + i*PDW_NKIN;
        d->flags[i] = flags0[i] ? 1 : 0;
        d->armed[i] = 0;
        d->anchors[i] = d->flags[i] ? ki[PDW_KIN_S] : 0.0;
        /* approach speed of a foot that starts in contact: its penetration rate, if any (the
         * laws that use it take at least v_in_min) */
        d->anchors[PDW_ANCHOR_V_IN1 + i] = d->flags[i] ? fmax(-ki[PDW_KIN_V_Y], 0.0) : 0.0;
        d->zone[i] = zone_of(g, d->flags[i], ki, -1);
    }
}

static void fail(pdw_sim *s, int status, int reason, int leg, double t)
{
    s->status = status;
    s->failure.reason = reason;
    s->failure.leg = leg;
    s->failure.t = t;
    memcpy(s->failure.x, s->x, sizeof s->x);
}

/* ---- online gait analysis: the definitions of pdw/sim/gait.py, event by event -------------- */

void pdw_gait_init(pdw_gait *g)
{
    memset(g, 0, sizeof *g);
    g->ds_leg = -1;
}

/* Do the last k steps agree (each periodic field: max - min <= tol |latest|)? */
static int periodic(const pdw_sim *s)
{
    static const int fields[PDW_NPERIODIC] = PDW_PERIODIC_FIELDS;
    const pdw_gait *g = &s->gait;
    const long k = s->opt.periodic_k < PDW_STEP_RING ? s->opt.periodic_k : PDW_STEP_RING;
    if (k < 2 || g->n_steps < k) return 0;
    const double *last = g->ring[(g->n_steps - 1) % PDW_STEP_RING];
    for (int f = 0; f < PDW_NPERIODIC; ++f) {
        const double ref = last[fields[f]];
        double lo = ref, hi = ref;
        for (long j = 2; j <= k; ++j) {
            const double v = g->ring[(g->n_steps - j) % PDW_STEP_RING][fields[f]];
            lo = fmin(lo, v);
            hi = fmax(hi, v);
        }
        if (!(hi - lo <= s->opt.periodic_tol * fabs(ref))) return 0;   /* NaN: not periodic */
    }
    return 1;
}

/* Touch-down of leg j at (t, x): a complete step when leg j's lift-off, the other leg's
 * touch-down and a previous touch-down are known. Returns a PDW_STOP_* condition met, or 0. */
static int gait_touch_down(pdw_sim *s, int j, double t, double x)
{
    pdw_gait *g = &s->gait;
    const int i = 1 - j;
    int stop = PDW_STOP_NONE;
    g->n_touch_down++;
    g->ds_leg = -1;         /* the previous step's double support, if still open, stays NaN */
    if (g->has_lo[j] && g->has_td[i] && g->has_prev_td) {
        double *r = g->ring[g->n_steps % PDW_STEP_RING];
        r[PDW_STEP_LEG] = j;
        r[PDW_STEP_T_LIFT_OFF] = g->lo_t[j];
        r[PDW_STEP_T_TOUCH_DOWN] = t;
        r[PDW_STEP_L] = x - g->td_x[i];
        r[PDW_STEP_TRAVEL] = x - g->lo_x[j];
        r[PDW_STEP_P] = t - g->lo_t[j];
        r[PDW_STEP_V] = r[PDW_STEP_P] > 0.0 ? r[PDW_STEP_L] / r[PDW_STEP_P] : NAN;
        r[PDW_STEP_CYCLE] = t - g->prev_td_t;
        r[PDW_STEP_DOUBLE_SUPPORT] = NAN;
        r[PDW_STEP_DS_FRACTION] = NAN;
        g->n_steps++;
        g->ds_leg = i;
        if (s->opt.stop_steps > 0 && g->n_steps >= s->opt.stop_steps) stop = PDW_STOP_STEPS;
        else if (s->opt.periodic_k > 0 && periodic(s)) stop = PDW_STOP_PERIODIC;
    }
    g->td_t[j] = t;
    g->td_x[j] = x;
    g->has_td[j] = 1;
    g->prev_td_t = t;
    g->has_prev_td = 1;
    if (stop == PDW_STOP_NONE && s->opt.stop_touch_down == j + 1) stop = PDW_STOP_TOUCH_DOWN;
    return stop;
}

/* Lift-off of leg j at (t, x): closes the latest step's double support if it awaited it. */
static void gait_lift_off(pdw_sim *s, int j, double t, double x)
{
    pdw_gait *g = &s->gait;
    g->n_lift_off++;
    if (g->ds_leg == j && g->n_steps > 0) {
        double *r = g->ring[(g->n_steps - 1) % PDW_STEP_RING];
        r[PDW_STEP_DOUBLE_SUPPORT] = t - r[PDW_STEP_T_TOUCH_DOWN];
        r[PDW_STEP_DS_FRACTION] = r[PDW_STEP_DOUBLE_SUPPORT] / r[PDW_STEP_CYCLE];
        g->ds_leg = -1;
    }
    g->lo_t[j] = t;
    g->lo_x[j] = x;
    g->has_lo[j] = 1;
}

/* One event: stored (if recorded), then seen by the gait analysis. Returns a PDW_STOP_*. */
static int push_event(pdw_sim *s, double t, int leg, int kind, const double *ki)
{
    if (s->opt.record_events) {
        double *e = s->events + s->n_events * PDW_NEVENT;
        e[PDW_EVENT_T] = t;
        e[PDW_EVENT_LEG] = leg;
        e[PDW_EVENT_KIND] = kind;
        e[PDW_EVENT_X_D] = ki[PDW_KIN_X_D];
        e[PDW_EVENT_Y_D] = ki[PDW_KIN_Y_D];
        s->n_events++;
    }
    if (kind == PDW_EVKIND_TOUCH_DOWN) return gait_touch_down(s, leg, t, ki[PDW_KIN_X_D]);
    gait_lift_off(s, leg, t, ki[PDW_KIN_X_D]);
    return PDW_STOP_NONE;
}

int pdw_update_flags(pdw_sim *s, double t)
{
    if (!pdw_events_room(s, 2)) return -1;
    pdw_trig(s->x, s->work + PDW_WORK_TRIG);
    return pdw_update_flags_trig(s, t);
}

int pdw_update_flags_trig(pdw_sim *s, double t)
{
    pdw_discrete *d = &s->disc;
    double *kin = s->work + PDW_WORK_KIN;
    int changed = 0, stop = PDW_STOP_NONE;
    if (!pdw_events_room(s, 2)) return -1;
    pdw_sim_flag_kinematics(s, s->work);
    for (int i = 0; i < 2; ++i) {
        const double *ki = kin + i*PDW_NKIN, *kj = kin + (1 - i)*PDW_NKIN;
        const double y = ki[PDW_KIN_Y_D], vy = ki[PDW_KIN_V_Y];
        if (d->flags[i]) {
            if (y > 0.0 && vy > 0.0) {                       /* Eq. 18a: lift-off */
                d->flags[i] = 0;
                d->armed[i] = 0;
                push_event(s, t, i, PDW_EVKIND_LIFT_OFF, ki);   /* never a stop */
            }
            continue;
        }
        /* scuffing guard: armed once above ground while downhill of the other foot */
        if (ki[PDW_KIN_X_D] <= kj[PDW_KIN_X_D]) d->armed[i] = 0;
        else if (y > 0.0) d->armed[i] = 1;
        if (d->armed[i] && y < 0.0 && vy < 0.0) {            /* Eq. 18b: touch-down */
            d->flags[i] = 1;
            d->armed[i] = 0;
            d->anchors[i] = ki[PDW_KIN_S];
            d->anchors[PDW_ANCHOR_V_IN1 + i] = -vy;           /* approach speed, > 0 */
            if (s->nx > PDW_NX) s->x[PDW_X_Z1 + i] = 0.0;     /* LuGre: relaxed bristles */
            const int st = push_event(s, t, i, PDW_EVKIND_TOUCH_DOWN, ki);
            if (st != PDW_STOP_NONE && stop == PDW_STOP_NONE) stop = st;
            changed = 1;
        }
    }
    /* a new anchor changes xi: refresh the kinematics (trig stays valid) */
    if (changed) pdw_sim_flag_kinematics(s, s->work);
    if (s->ground && s->ground->n_zones > 0)    /* else both stay -1 (pdw_discrete_init) */
        for (int i = 0; i < 2; ++i) d->zone[i] = zone_of(s->ground, d->flags[i], kin + i*PDW_NKIN,
                                                d->zone[i]);
    if (stop != PDW_STOP_NONE) {
        s->stop_reason = stop;
        s->status = stop == PDW_STOP_PERIODIC ? PDW_STATUS_PERIODIC : PDW_STATUS_DONE;
        return 1;
    }
    return 0;
}

void pdw_record_final(pdw_sim *s, double t)
{
    if (s->opt.record_every <= 0 || s->n % s->opt.record_every != 0) return;
    pdw_sim_contact(s, s->work);
    pdw_record_now(s, t);
}

int pdw_check_feet_fail(pdw_sim *s, double t)
{
    const double *kin = s->work + PDW_WORK_KIN;
    for (int i = 0; i < 2; ++i) {
        if (kin[i*PDW_NKIN + PDW_KIN_Y_D] < -s->opt.fall_depth) {
            fail(s, PDW_STATUS_FELL, PDW_REASON_FOOT_DEEP, i, t);
            return 1;
        }
    }
    return 0;
}

int pdw_check_state_fail(pdw_sim *s, const double *xnew, double t)
{
    /* the walker's 8 states with a compile-time loop (the common case costs what it did before
     * LuGre), then the friction law's extra states, if any */
    double nan_if_any = 0.0;                 /* x*0 is 0 for finite x, NaN for inf or NaN */
    for (int i = 0; i < PDW_NX; ++i) nan_if_any += xnew[i] * 0.0;
    for (int i = PDW_NX; i < s->nx; ++i) nan_if_any += xnew[i] * 0.0;
    if (nan_if_any != 0.0) { fail(s, PDW_STATUS_DIVERGED, PDW_REASON_NONFINITE, -1, t); return 1; }
    for (int i = PDW_NQ; i < PDW_NX; ++i) {
        if (fabs(xnew[i]) > s->opt.max_speed) { fail(s, PDW_STATUS_DIVERGED, PDW_REASON_SPEED, -1, t); return 1; }
    }
    if (xnew[PDW_X_Y_O] < s->opt.fall_hip_height) {
        fail(s, PDW_STATUS_FELL, PDW_REASON_HIP_LOW, -1, t);
        return 1;
    }
    /* shaped ground: the hip within a leg length of the defined extent's ends (a foot could
     * otherwise reach past them) */
    if (s->ground && (xnew[PDW_X_X_O] - s->p[PDW_P_L] < s->ground->s_min
                      || xnew[PDW_X_X_O] + s->p[PDW_P_L] > s->ground->s_max)) {
        fail(s, PDW_STATUS_FELL, PDW_REASON_OFF_GROUND, -1, t);
        return 1;
    }
    return 0;
}

int pdw_switch_pending(const pdw_sim *s, const double *x, double *work)
{
    /* keep in step with pdw_update_flags above */
    const pdw_discrete *d = &s->disc;
    const double *kin = work + PDW_WORK_KIN;
    int mask = 0;
    kinematics(s->kernel, s->ground, s->p, x, d->anchors, work);
    for (int i = 0; i < 2; ++i) {
        const double *ki = kin + i*PDW_NKIN, *kj = kin + (1 - i)*PDW_NKIN;
        const double y = ki[PDW_KIN_Y_D], vy = ki[PDW_KIN_V_Y];
        if (d->flags[i]) {
            if (y > 0.0 && vy > 0.0) mask |= 1 << i;           /* lift-off */
            continue;
        }
        int armed = d->armed[i];
        if (ki[PDW_KIN_X_D] <= kj[PDW_KIN_X_D]) armed = 0;
        else if (y > 0.0) armed = 1;
        if (armed != d->armed[i] || (armed && y < 0.0 && vy < 0.0)) mask |= 1 << i;
    }
    if (s->ground && s->ground->n_zones > 0)         /* a support foot entered another blend zone */
        for (int i = 0; i < 2; ++i)
            if (zone_of(s->ground, d->flags[i], kin + i*PDW_NKIN, d->zone[i]) != d->zone[i]) mask |= 1 << i;
    return mask;
}

void pdw_record_now(pdw_sim *s, double t)
{
    if (s->n_rec >= s->rec_capacity) return;
    const long r = s->n_rec++;
    s->rec_t[r] = t;
    pdw_copy_state(s, s->rec_x + r*s->nx, s->x);
    s->rec_flags[2*r] = s->disc.flags[0];
    s->rec_flags[2*r + 1] = s->disc.flags[1];
    if (s->rec_contact) {
        const double *c = s->work + PDW_WORK_CONTACT;
        double *o = s->rec_contact + r*PDW_NREC;
        o[PDW_REC_F_N1] = c[PDW_CONTACT_F_N];
        o[PDW_REC_F_T1] = c[PDW_CONTACT_F_T];
        o[PDW_REC_F_N2] = c[PDW_NCONTACT + PDW_CONTACT_F_N];
        o[PDW_REC_F_T2] = c[PDW_NCONTACT + PDW_CONTACT_F_T];
    }
}
