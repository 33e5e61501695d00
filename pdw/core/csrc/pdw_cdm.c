/* The paper's central difference method, exactly as docs/model.md section 7 prints it (Eqs. 13-17).
 *
 *   start:    U_-1 = U_0 - dt U'_0 + dt^2/2 U''_0
 *   step:     (M/dt^2 + C/(2dt)) U_{n+1} = Q_f - G + (2/dt^2) M U_n - (M/dt^2 - C/(2dt)) U_{n-1}
 *   velocity: U'_{n+1} = (U_{n+1} - U_{n-1}) / (2dt)        (Eq. 17 as printed)
 *
 * M, C, Q_f, G are evaluated at (U_n, U'_n) with the flags updated from that state first (Fig. 3).
 * First order: Eq. 17's velocity is the centred velocity at t_n, used at t_{n+1}. */
#include <math.h>
#include <string.h>
#include "pdw_sim.h"
#include "pdw_linalg.h"

/* The start-up of Eq. 13: U_{-1} from x_0 and the right-hand side there; n = 0. Shared with the
 * lane loop of pdw_batch.c, so both take the very same arithmetic. */
void pdw_cdm_start(pdw_sim *s)
{
    const double dt = s->opt.dt;
    double xdot[PDW_NX_MAX];
    pdw_sim_rhs(s, s->x, xdot, s->work);
    for (int i = 0; i < PDW_NQ; ++i)
        s->u_prev[i] = s->x[i] - dt*s->x[PDW_NQ + i] + 0.5*dt*dt*xdot[PDW_NQ + i];
    s->cdm_kdiag[0] = s->cdm_kdiag[1] = 0.0;      /* pdw_cdm_update's cache: empty */
    s->started = 1;
    s->n = 0;
    s->t = 0.0;
    s->n_rhs = 1;
}

/* One central-difference update (Eqs. 14-17) at t from the stage outputs M, C and Q_f - G of
 * x_n: (M/dt^2 + C/2dt) U_{n+1} = ..., the centred velocity, the state check, n advanced.
 * Returns 0, or 1 when the run stops (singular system or failed state check; s->status set).
 * Shared with the lane loop of pdw_batch.c. */
/* LuGre's bristle states under the central difference method, which integrates q only: with the
 * slip velocity v frozen at x_n (the state the step's forces are taken at), dz/dt = v - a z
 * (a = sigma0 |v| / g(v) >= 0) is linear in z and integrated exactly over the step:
 *     z_{n+1} = z_n + dt phi(a dt) zdot_n,   phi(y) = (1 - exp(-y)) / y   (phi(0) = 1),
 * i.e. z relaxes toward z_ss = v/a with factor exp(-a dt). First order (v is held over the step,
 * as Eq. 17's velocity), exact for constant v, and unconditionally stable: 0 < phi <= 1. zdot_n
 * and a come from the contact stage of x_n, in s->work. */
#if defined(__GNUC__)
__attribute__((noinline))       /* off the default law's hot path (its registers stay as they were) */
#endif
static void bristle_update(const pdw_sim *s, double dt, double *xnew)
{
    const double *contact = s->work + PDW_WORK_CONTACT;
    for (int i = 0; i < 2; ++i) {
        const double zd = contact[i*PDW_NCONTACT + PDW_CONTACT_ZDOT];
        const double y = contact[i*PDW_NCONTACT + PDW_CONTACT_Z_RATE] * dt;
        const double phi = y > 1e-300 ? -expm1(-y) / y : 1.0;
        xnew[PDW_X_Z1 + i] = s->x[PDW_X_Z1 + i] + dt * phi * zd;
    }
}

/* pdw_solve_dblock needs the lower-right 2x2 block of K = M/dt^2 + C/(2dt) diagonal: a
 * compile-time check of the emitted pattern (an array of size -1 if an entry there is not zero) */
typedef char pdw_cdm_dblock_check[
    (PDW_CDM_NZ(PDW_CDM_M_NZ | PDW_CDM_C_NZ, 2, 3) || PDW_CDM_NZ(PDW_CDM_M_NZ | PDW_CDM_C_NZ, 3, 2))
    ? -1 : 1];

/* The assembly touches only the structural non-zeros of M and C (PDW_CDM_M_NZ, PDW_CDM_C_NZ,
 * emitted by derive/ from the symbolic matrices): with the 4x4 loops unrolled, each entry's test
 * is a compile-time constant and the terms of a zero entry are not compiled. The sums keep their
 * remaining terms in the dense loop's order (j ascending) and start from -0.0 (-0.0 + a = a), so
 * every value is the dense loop's (an exactly-zero term changes a sum only in the sign of a zero
 * result); the lane loop of pdw_batch_soa.inc gives the same bits. */
#if defined(__GNUC__)
__attribute__((always_inline))  /* one copy each in cdm_update and cdm_update_ground */
#endif
static inline int cdm_update_impl(pdw_sim *s, const double *M, const double *C,
                                  const double *QmG, const double *moment, double t)
{
    const double dt = s->opt.dt;
    if (dt != s->cdm_dt || dt == 0.0) {  /* 1/dt^2 and 1/(2 dt): computed once per run */
        s->cdm_dt = dt; s->cdm_idt2 = 1.0/(dt*dt); s->cdm_ih = 0.5/dt;
    }
    const double idt2 = s->cdm_idt2, ih = s->cdm_ih;
    double K[PDW_NQ*PDW_NQ], b[PDW_NQ], u[PDW_NQ], xnew[PDW_NX_MAX];
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC unroll 4
#endif
    for (int i = 0; i < PDW_NQ; ++i) {
        double mu = -0.0, ku = -0.0;
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC unroll 4
#endif
        for (int j = 0; j < PDW_NQ; ++j) {
            const int mz = PDW_CDM_NZ(PDW_CDM_M_NZ, i, j), cz = PDW_CDM_NZ(PDW_CDM_C_NZ, i, j);
            const int ij = i*PDW_NQ + j;
            double kp = 0.0, km = 0.0;       /* M/dt^2 + C/2dt and M/dt^2 - C/2dt at (i, j) */
            if (mz && cz) { kp = M[ij]*idt2 + C[ij]*ih; km = M[ij]*idt2 - C[ij]*ih; }
            else if (mz) kp = km = M[ij]*idt2;
            else if (cz) { kp = C[ij]*ih; km = -(C[ij]*ih); }
            K[ij] = kp;
            if (mz) mu += M[ij] * s->x[j];
            if (mz || cz) ku += km * s->u_prev[j];
        }
        /* a shaped ground's moments (pdw_terrain_cdm_terms_split): added to Q_f - G first, as
         * pdw_terrain_cdm_terms adds them, here where b waits on them (no store and reload) */
        const double q = moment && (i == PDW_X_THETA1 || i == PDW_X_THETA2)
                         ? QmG[i] + moment[i - PDW_X_THETA1] : QmG[i];
        b[i] = q + 2.0*idt2*mu - ku;
    }
    /* 1/K[2][2] and 1/K[3][3]: the diagonal block is M's (C's is zero), which in the walker's
     * mechanics depends on the parameters only; the last step's inverses are reused while the
     * entries are bitwise the same (the same divisions, not redone; s->cdm_kdiag is zero at
     * the start, and a zero entry is never reused) */
    double id[2];
    for (int i = 0; i < 2; ++i) {
        const double kd = K[(2 + i)*(PDW_NQ + 1)];
        if (kd == s->cdm_kdiag[i] && kd != 0.0) id[i] = s->cdm_kinv[i];
        else { id[i] = 1.0 / kd; s->cdm_kdiag[i] = kd; s->cdm_kinv[i] = id[i]; }
    }
    double fac[PDW_DBLOCK_NFAC];
    const int singular = pdw_dblock_factor_inv(K, id[0], id[1], fac);
    pdw_dblock_solve(K, fac, b, u);
    if (singular) {
        s->status = PDW_STATUS_SINGULAR;
        s->failure.reason = PDW_REASON_SINGULAR; s->failure.leg = -1; s->failure.t = t;
        memcpy(s->failure.x, s->x, sizeof s->x);
        return 1;
    }
    for (int i = 0; i < PDW_NQ; ++i) {
        xnew[i] = u[i];
        xnew[PDW_NQ + i] = (u[i] - s->u_prev[i]) * ih;
    }
    if (s->nx > PDW_NX) bristle_update(s, dt, xnew);
    if (pdw_check_state(s, xnew, t)) return 1;
    for (int i = 0; i < PDW_NQ; ++i) s->u_prev[i] = s->x[i];
    pdw_copy_state(s, s->x, xnew);
    s->n++;
    s->t = s->n * dt;
    s->n_rhs++;
    return 0;
}

/* The update on flat ground, and on a shaped ground with its moments (moment[0..1], added to
 * Q_f - G of theta_1, theta_2 first): two functions, so that the flat one is the update as it
 * was (moment NULL compiled out, called as before). */
#if defined(__GNUC__)
__attribute__((noinline))
#endif
static int cdm_update(pdw_sim *s, const double *M, const double *C, const double *QmG, double t)
{
    return cdm_update_impl(s, M, C, QmG, NULL, t);
}

#if defined(__GNUC__)
__attribute__((noinline))
#endif
static int cdm_update_ground(pdw_sim *s, const double *M, const double *C, const double *QmG,
                             const double *moment, double t)
{
    return cdm_update_impl(s, M, C, QmG, moment, t);
}

/* The shared entry (pdw_batch.c). */
int pdw_cdm_update(pdw_sim *s, const double *M, const double *C, const double *QmG, double t)
{
    return cdm_update(s, M, C, QmG, t);
}

int pdw_cdm_advance(pdw_sim *s)
{
    const pdw_kernel *k = s->kernel;
    const double dt = s->opt.dt;
    double *trig = s->work + PDW_WORK_TRIG, *kin = s->work + PDW_WORK_KIN;
    double *contact = s->work + PDW_WORK_CONTACT, *M = s->work + PDW_WORK_M;
    double C[PDW_NQ*PDW_NQ], QmG[PDW_NQ], moment[2];

    s->status = PDW_STATUS_RUNNING;
    if (!s->started) {
        const int r = pdw_update_flags(s, 0.0);
        if (r < 0) { s->status = PDW_STATUS_EVENTS_FULL; return s->status; }
        if (r > 0) { s->started = 1; pdw_record_final(s, 0.0); return s->status; }
        pdw_cdm_start(s);
        pdw_record(s, 0.0);
    }
    while (s->n < s->opt.n_steps) {
        /* a return here resumes exactly: at n > 0 the top of the loop recomputes work */
        if (s->n > 0 && !pdw_records_room(s)) { s->status = PDW_STATUS_RECORDS_FULL; return s->status; }
        if (s->n > 0 && pdw_poll_due(s)) return s->status;
        const double t = s->n * dt;
        /* flags from (U_n, U'_n); this also leaves trig and kin of x_n in work (at n = 0 the
         * start-up's update and right-hand side did) */
        if (s->n > 0) {
            const int r = pdw_update_flags(s, t);
            if (r < 0) { s->status = PDW_STATUS_EVENTS_FULL; return s->status; }
            if (r > 0) { pdw_record_final(s, t); return s->status; }   /* a stop condition */
        }
        if (pdw_check_feet(s, t)) return s->status;
        if (s->ground) {            /* shaped ground (pdw_terrain.c) */
            pdw_sim_contact(s, s->work);
            pdw_terrain_cdm_terms_split(k, s->x, trig, s->p, contact, s->work + PDW_WORK_GROUND,
                                        M, C, QmG, moment);
        } else {
            k->contact(kin, s->disc.flags, s->p, contact);
            k->cdm_terms(s->x, trig, s->p, contact, M, C, QmG);
        }
        if (s->n > 0) pdw_record(s, t);  /* sample 0 was recorded at the start */
        if (s->ground ? cdm_update_ground(s, M, C, QmG, moment, t) : cdm_update(s, M, C, QmG, t))
            return s->status;
    }
    /* final sample: flags and forces at t_end */
    const int r = pdw_update_flags(s, s->n * dt);
    if (r < 0) { s->status = PDW_STATUS_EVENTS_FULL; return s->status; }
    pdw_record_final(s, s->n * dt);
    if (r == 0) s->status = PDW_STATUS_DONE;      /* else: the stop condition's status */
    return s->status;
}
