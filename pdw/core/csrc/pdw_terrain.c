/* The shaped-ground kernel (pdw_terrain.h; docs/terrain.md). */
#include <math.h>
#include <string.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#include "pdw_terrain.h"
#include "pdw_jacobian.h"

/* 1/N = 1/sqrt(1 + h'^2) of both feet: with SSE2 one vector multiply, add, square root and
 * division (each an IEEE operation on each lane: the bits of the scalar expression) instead of
 * two chains of them; the time loops wait on these values. Level ground under both feet (h' = 0:
 * a plane, the flat parts of steps and patches) gives 1 exactly without them. */
static inline void inv_normals(double dh0, double dh1, double *n0, double *n1)
{
    /* a foot on level ground (h' = 0: a plane on the slope, the flat parts of steps and patches)
     * gets 1 exactly (1/sqrt(1 + 0)) without waiting for the other foot's square root: a support
     * foot on a flat part while the swing foot passes an edge (branches, not a blend, so that no
     * value waits on the other lane) */
    if (dh0 == 0.0) {
        *n0 = 1.0;
        *n1 = dh1 == 0.0 ? 1.0 : 1.0 / sqrt(1.0 + dh1*dh1);
        return;
    }
    if (dh1 == 0.0) {
        *n0 = 1.0 / sqrt(1.0 + dh0*dh0);
        *n1 = 1.0;
        return;
    }
#if defined(__SSE2__)
    const __m128d d = _mm_set_pd(dh1, dh0), one = _mm_set1_pd(1.0);
    const __m128d r = _mm_div_pd(one, _mm_sqrt_pd(_mm_add_pd(one, _mm_mul_pd(d, d))));
    _mm_storel_pd(n0, r);
    _mm_storeh_pd(n1, r);
#else
    *n0 = 1.0 / sqrt(1.0 + dh0*dh0);
    *n1 = 1.0 / sqrt(1.0 + dh1*dh1);
#endif
}

/* Copy n doubles one at a time. The contact stage has just stored them one by one, and a wider
 * load across two fresh 8-byte stores cannot take its value from the store buffer (it waits
 * until they are written: tens of cycles per load); the empty asm keeps the compiler from
 * merging the copies into vector moves. */
static inline void copy_fresh(double *dst, const double *src, int n)
{
    for (int f = 0; f < n; ++f) {
        dst[f] = src[f];
#if defined(__GNUC__)
        __asm__ volatile("" ::: "memory");
#endif
    }
}

void pdw_terrain_kinematics(const pdw_kernel *k, const pdw_ground *g, const double *x,
                            const double *trig, const double *p, const double *anchors,
                            double *kin, double *gnd, double *cell)
{
    double sA[2], e[2][3];
    pdw_ground_points(x, trig, p, sA);
    for (int i = 0; i < 2; ++i) {
        double *gi = gnd + i*PDW_NGROUND;
        const long c = pdw_ground_cell_hint(g, sA[i], cell + i);
        if (pdw_ground_cell_level(g, c) && sA[i] - sA[i] == 0.0) {
            /* a level cell (finite s): exactly pdw_ground_eval_cell's values (pdw_ground.h),
             * known before s_A is (the time loop's chain skips u and the quintic) */
            e[i][0] = g->cells[c*PDW_NGCELL + PDW_GCELL_A0] + 0.0;
            e[i][1] = e[i][2] = 0.0;
        } else {
            pdw_ground_eval_cell(g, c, sA[i], e[i]);
        }
        gi[PDW_GROUND_H] = e[i][0];
        gi[PDW_GROUND_DH] = e[i][1];
        gi[PDW_GROUND_DDH] = e[i][2];
    }
    inv_normals(e[0][1], e[1][1], gnd + PDW_GROUND_INV_N, gnd + PDW_NGROUND + PDW_GROUND_INV_N);
    for (int i = 0; i < 2; ++i) {
        double *gi = gnd + i*PDW_NGROUND;
        if (k->variant == 1) {          /* consistent: the rolling coordinate needs sigma, alpha */
            gi[PDW_GROUND_SIGMA] = pdw_ground_arc(g, sA[i]);
            gi[PDW_GROUND_ALPHA] = atan(e[i][1]);
        } else {
            gi[PDW_GROUND_SIGMA] = 0.0;
            gi[PDW_GROUND_ALPHA] = 0.0;
        }
    }
    if (k->variant == 1) pdw_consistent_ground_kinematics(x, trig, p, anchors, gnd, kin);
    else pdw_paper_ground_kinematics(x, trig, p, anchors, gnd, kin);
    for (int i = 0; i < 2; ++i)
        kin[i*PDW_NKIN + PDW_KIN_Z] = k->nx > PDW_NX ? x[PDW_X_Z1 + i] : 0.0;
}

void pdw_terrain_contact(const pdw_kernel *k, const pdw_ground *g, const double *kin,
                         const int *flags, const double *p, double *contact, int partials)
{
    void (*stage)(const double *, const int *, const double *, double *) =
        partials ? k->contact_partials : k->contact;
    if (g->n_patches == 0 || (!pdw_ground_patched(g, kin[PDW_KIN_X_D])
                              && !pdw_ground_patched(g, kin[PDW_NKIN + PDW_KIN_X_D]))) {
        stage(kin, flags, p, contact);      /* neither foot on a patch: the run's parameters */
        return;
    }
    double pi[PDW_NP], ci[2*PDW_NCONTACT];
    /* Every contact stage writes 0.0 for a foot that is not a penetrating support foot,
     * whatever p (derive/emit.py _contact_function): with at most one penetrating foot, one call
     * with that foot's parameters gives both feet's values (single support, the common case) */
    const int pen0 = flags[0] && kin[PDW_KIN_Y_D] < 0.0;
    const int pen1 = flags[1] && kin[PDW_NKIN + PDW_KIN_Y_D] < 0.0;
    if (!(pen0 && pen1)) {
        const double s = kin[(pen1 ? PDW_NKIN : 0) + PDW_KIN_X_D];
        if (!(pen0 || pen1) || !pdw_ground_patched(g, s)) {
            stage(kin, flags, p, contact);
            return;
        }
        memcpy(pi, p, sizeof pi);
        pdw_ground_params(g, s, p, pi);
        stage(kin, flags, pi, contact);
        return;
    }
    for (int i = 0; i < 2; ++i) {
        const int fl[2] = {i == 0 ? flags[0] : 0, i == 1 ? flags[1] : 0};
        memcpy(pi, p, sizeof pi);
        pdw_ground_params(g, kin[i*PDW_NKIN + PDW_KIN_X_D], p, pi);
        stage(kin, fl, pi, ci);
        copy_fresh(contact + i*PDW_NCONTACT, ci + i*PDW_NCONTACT, PDW_NCONTACT);
    }
}

void pdw_terrain_forces(const double *contact, const double *gnd, const double *p, double *cw,
                        double *moment)
{
    double gf[2*PDW_NGFORCE];
    copy_fresh(cw, contact, 2*PDW_NCONTACT);
    if (gnd[PDW_GROUND_DH] == 0.0 && gnd[PDW_NGROUND + PDW_GROUND_DH] == 0.0) {
        /* level under both feet (h' = +0 and 1/N = 1: pdw_terrain_kinematics sets them so):
         * ground_forces' expressions with dh = 0 and 1/N = 1 written out, each product by 1/N = 1
         * dropped (x * 1 is x, bit for bit, NaN and signed zeros included): the same values
         * without the multiplications the forces wait on */
        const double r = p[PDW_P_R];
        for (int i = 0; i < 2; ++i) {
            const double fn = contact[i*PDW_NCONTACT + PDW_CONTACT_F_N];
            const double ft = contact[i*PDW_NCONTACT + PDW_CONTACT_F_T];
            const double dh = gnd[i*PDW_NGROUND + PDW_GROUND_DH];
            const double t0 = -fn*dh + ft, t1 = fn + ft*dh;
            cw[i*PDW_NCONTACT + PDW_CONTACT_F_N] = t1;
            cw[i*PDW_NCONTACT + PDW_CONTACT_F_T] = t0;
            moment[i] = r*(dh*t1 - t0*(1.0 - 1.0));
        }
        return;
    }
    pdw_ground_forces(contact, gnd, p, gf);
    for (int i = 0; i < 2; ++i) {
        cw[i*PDW_NCONTACT + PDW_CONTACT_F_N] = gf[i*PDW_NGFORCE + PDW_GFORCE_F_Y];
        cw[i*PDW_NCONTACT + PDW_CONTACT_F_T] = gf[i*PDW_NGFORCE + PDW_GFORCE_F_X];
        moment[i] = gf[i*PDW_NGFORCE + PDW_GFORCE_M_THETA];
    }
}

void pdw_terrain_rhs(const pdw_kernel *k, const pdw_ground *g, const double *x, const double *p,
                     const int *flags, const double *anchors, double *xdot, double *work)
{
    double *trig = work + PDW_WORK_TRIG, *kin = work + PDW_WORK_KIN;
    double *contact = work + PDW_WORK_CONTACT, *M = work + PDW_WORK_M;
    double *f = work + PDW_WORK_F, *qdd = work + PDW_WORK_QDD, *gnd = work + PDW_WORK_GROUND;
    double cw[2*PDW_NCONTACT], moment[2];
    pdw_trig(x, trig);
    pdw_terrain_kinematics(k, g, x, trig, p, anchors, kin, gnd, work + PDW_WORK_GROUND_CELL);
    pdw_terrain_contact(k, g, kin, flags, p, contact, 0);
    pdw_terrain_forces(contact, gnd, p, cw, moment);
    k->dynamics(x, trig, p, cw, M, f);
    f[PDW_X_THETA1] += moment[0];
    f[PDW_X_THETA2] += moment[1];
    pdw_solve_dblock(M, f, qdd);
    for (int i = 0; i < PDW_NQ; ++i) { xdot[i] = x[PDW_NQ + i]; xdot[PDW_NQ + i] = qdd[i]; }
    if (k->nx > PDW_NX)
        for (int i = 0; i < 2; ++i) xdot[PDW_X_Z1 + i] = contact[i*PDW_NCONTACT + PDW_CONTACT_ZDOT];
}

/* The smooth Coulomb law's kernels: the derived Jacobian, the mechanics kernel's
 * dynamics_jacobian at the slope-frame forces with every contact partial 0, plus the ground's
 * part (derive/terrain.py ground_jacobian), solved with M as the generated kernels do. LuGre's
 * (nx > PDW_NX): central differences, step sqrt(eps) max(1, |x_j|) (the reasons are LuGre's, in
 * derive/emit.py). Leaves work at x. */
void pdw_terrain_jacobian(const pdw_kernel *k, const pdw_ground *g, const double *x,
                          const double *p, const int *flags, const double *anchors, double *J,
                          double *work)
{
    const int nx = k->nx;
    if (nx == PDW_NX) {
        double xdot[PDW_NX], A[PDW_NQ*PDW_NX];
        double cw[2*PDW_NCONTACT], moment[2];
        double *contact = work + PDW_WORK_CONTACT, *gnd = work + PDW_WORK_GROUND;
        pdw_terrain_rhs(k, g, x, p, flags, anchors, xdot, work);
        pdw_terrain_contact(k, g, work + PDW_WORK_KIN, flags, p, contact, 1);
        pdw_terrain_forces(contact, gnd, p, cw, moment);
        for (int i = 0; i < 2; ++i) {
            double *c = cw + i*PDW_NCONTACT;
            c[PDW_CONTACT_DFN_DDELTA] = c[PDW_CONTACT_DFN_DDELTAD] = 0.0;
            c[PDW_CONTACT_DFT_DXI] = c[PDW_CONTACT_DFT_DV] = c[PDW_CONTACT_MU] = 0.0;
        }
        k->dynamics_jacobian(x, work + PDW_WORK_TRIG, p, cw, work + PDW_WORK_QDD, A);
        if (k->variant == 1)
            pdw_consistent_ground_jacobian(x, work + PDW_WORK_TRIG, p, contact, gnd, A);
        else
            pdw_paper_ground_jacobian(x, work + PDW_WORK_TRIG, p, contact, gnd, A);
        pdw_jacobian_from_dynamics(work + PDW_WORK_M, A, J);
        return;
    }
    double xp[PDW_NX_MAX], fp[PDW_NX_MAX], fm[PDW_NX_MAX];
    for (int j = 0; j < nx; ++j) xp[j] = x[j];
    for (int j = 0; j < nx; ++j) {
        const double h = 1.4901161193847656e-08 * fmax(1.0, fabs(x[j]));
        xp[j] = x[j] + h;
        const double hp = xp[j] - x[j];
        pdw_terrain_rhs(k, g, xp, p, flags, anchors, fp, work);
        xp[j] = x[j] - h;
        const double hm = x[j] - xp[j];
        pdw_terrain_rhs(k, g, xp, p, flags, anchors, fm, work);
        xp[j] = x[j];
        for (int i = 0; i < nx; ++i) J[i*nx + j] = (fp[i] - fm[i]) / (hp + hm);
    }
    pdw_terrain_rhs(k, g, x, p, flags, anchors, fp, work);
}

void pdw_terrain_cdm_terms(const pdw_kernel *k, const double *x, const double *trig,
                           const double *p, const double *contact, const double *gnd, double *M,
                           double *C, double *QmG)
{
    double cw[2*PDW_NCONTACT], moment[2];
    pdw_terrain_forces(contact, gnd, p, cw, moment);
    k->cdm_terms(x, trig, p, cw, M, C, QmG);
    QmG[PDW_X_THETA1] += moment[0];
    QmG[PDW_X_THETA2] += moment[1];
}
