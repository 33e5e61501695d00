/* Discrete state of the walker: support flags, arming, anchors (MODEL.md sections 5, 6),
 * recording and stop checks shared by every time loop. */
#include <math.h>
#include <string.h>
#include "pdw_sim.h"

static void kinematics(const pdw_kernel *k, const double *p, const double *x,
                       const double *anchors, double *work)
{
    pdw_trig(x, work + PDW_WORK_TRIG);
    k->kinematics(x, work + PDW_WORK_TRIG, p, anchors, work + PDW_WORK_KIN);
}

void pdw_discrete_init(const pdw_kernel *k, const double *p, const double *x,
                       const int flags0[2], pdw_discrete *d, double *work)
{
    const double zero[2] = {0.0, 0.0};
    kinematics(k, p, x, zero, work);
    for (int i = 0; i < 2; ++i) {
        d->flags[i] = flags0[i] ? 1 : 0;
        d->armed[i] = 0;
        d->anchors[i] = d->flags[i] ? work[PDW_WORK_KIN + i*PDW_NKIN + PDW_KIN_S] : 0.0;
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

static void push_event(pdw_sim *s, double t, int leg, int kind, const double *ki)
{
    double *e = s->events + s->n_events * PDW_NEVENT;
    e[PDW_EVENT_T] = t;
    e[PDW_EVENT_LEG] = leg;
    e[PDW_EVENT_KIND] = kind;
    e[PDW_EVENT_X_D] = ki[PDW_KIN_X_D];
    e[PDW_EVENT_Y_D] = ki[PDW_KIN_Y_D];
    s->n_events++;
}

int pdw_update_flags(pdw_sim *s, double t)
{
    pdw_discrete *d = &s->disc;
    double *kin = s->work + PDW_WORK_KIN;
    int changed = 0;
    if (s->n_events + 2 > s->ev_capacity) return -1;
    kinematics(s->kernel, s->p, s->x, d->anchors, s->work);
    for (int i = 0; i < 2; ++i) {
        const double *ki = kin + i*PDW_NKIN, *kj = kin + (1 - i)*PDW_NKIN;
        const double y = ki[PDW_KIN_Y_D], vy = ki[PDW_KIN_V_Y];
        if (d->flags[i]) {
            if (y > 0.0 && vy > 0.0) {                       /* Eq. 18a: lift-off */
                d->flags[i] = 0;
                d->armed[i] = 0;
                push_event(s, t, i, PDW_EVKIND_LIFT_OFF, ki);
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
            push_event(s, t, i, PDW_EVKIND_TOUCH_DOWN, ki);
            changed = 1;
        }
    }
    /* a new anchor changes xi: refresh the kinematics (trig stays valid) */
    if (changed) s->kernel->kinematics(s->x, s->work + PDW_WORK_TRIG, s->p, d->anchors, kin);
    return 0;
}

int pdw_check_feet(pdw_sim *s, double t)
{
    const double *kin = s->work + PDW_WORK_KIN;
    for (int i = 0; i < 2; ++i) {
        if (kin[i*PDW_NKIN + PDW_KIN_Y_D] < -s->fall_depth) {
            fail(s, PDW_STATUS_FELL, PDW_REASON_FOOT_DEEP, i, t);
            return 1;
        }
    }
    return 0;
}

int pdw_check_state(pdw_sim *s, const double *xnew, double t)
{
    for (int i = 0; i < PDW_NX; ++i) {
        if (!isfinite(xnew[i])) { fail(s, PDW_STATUS_DIVERGED, PDW_REASON_NONFINITE, -1, t); return 1; }
    }
    for (int i = PDW_NQ; i < PDW_NX; ++i) {
        if (fabs(xnew[i]) > s->max_speed) { fail(s, PDW_STATUS_DIVERGED, PDW_REASON_SPEED, -1, t); return 1; }
    }
    if (xnew[PDW_X_Y_O] < s->fall_hip_height) {
        fail(s, PDW_STATUS_FELL, PDW_REASON_HIP_LOW, -1, t);
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
    kinematics(s->kernel, s->p, x, d->anchors, work);
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
    return mask;
}

void pdw_record(pdw_sim *s, double t)
{
    if (s->record_every <= 0 || s->n % s->record_every != 0) return;
    pdw_record_now(s, t);
}

void pdw_record_now(pdw_sim *s, double t)
{
    if (s->n_rec >= s->rec_capacity) return;
    const long r = s->n_rec++;
    s->rec_t[r] = t;
    memcpy(s->rec_x + r*PDW_NX, s->x, sizeof s->x);
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
