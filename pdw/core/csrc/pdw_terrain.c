/* The shaped-ground kernel (pdw_terrain.h; docs/terrain.md). */
#include <math.h>
#include <string.h>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#include "pdw_terrain.h"
#include "pdw_jacobian.h"
#include "pdw_terrain_gen.h"

/* 1/N = (1 + q)^(-1/2), q = h'^2, for q <= INVN_QMAX (|h'| <= 0.0442): the binomial series
 * through q^5 (Estrin's scheme: four levels of multiplies and adds) in place of an add, a square
 * root and a division, which the time loops wait on. The series alternates with terms decreasing in
 * magnitude (|c_k+1 / c_k| = (2k+1)/(2k+2) < 1, q < 1), so the truncation error is below the
 * first omitted term, (231/1024) q^6 <= (231/1024) 2^-54 = 1.3e-17 (0.11 ulp of 1); with the
 * evaluation's roundings the value is within 1 ulp of the exact 1/N, as 1/sqrt(1 + q) rounded
 * twice is (tests/core/test_terrain_invn.py checks both against 1/N in exact arithmetic).
 * The coefficients are exact binary fractions; q = 0 (level ground) gives 1 exactly. */
#define INVN_QMAX 0x1p-9
#define INVN_C1 (-0.5)
#define INVN_C2 0.375
#define INVN_C3 (-0.3125)
#define INVN_C4 0.2734375
#define INVN_C5 (-0.24609375)

/* For q <= INVN_Q4MAX (|h'| <= 2^-7) the series' last sum adds nothing: r = (1 + c1 q) +
 * q^2 (c2 + c3 q) lies in [1 - 2^-15, 1] (its ulp below 1 is 2^-53) and the last term
 * |q^4 (c4 + c5 q)| <= 2^-56 * 0.274 < 2^-54, below half an ulp of r, so r + that term rounds
 * to r (round to nearest, no tie): the same bits without its two levels of latency
 * (tests/core/test_terrain_invn.py checks it against the full series' floating-point sums). */
#define INVN_Q4MAX 0x1p-14

static inline double inv_norm_series(double q)
{
    const double q2 = q*q, q4 = q2*q2;
    return ((1.0 + INVN_C1*q) + q2*(INVN_C2 + INVN_C3*q)) + q4*(INVN_C4 + INVN_C5*q);
}

static inline double inv_norm(double dh)
{
    const double q = dh*dh;
    if (q <= INVN_Q4MAX) return (1.0 + INVN_C1*q) + (q*q)*(INVN_C2 + INVN_C3*q);
    return q <= INVN_QMAX ? inv_norm_series(q) : 1.0 / sqrt(1.0 + q);
}

/* 1/N of both feet: with SSE2 one vector series (the same IEEE operations on each lane, the
 * bits of inv_norm) when both feet are in its range, else each foot's inv_norm. */
static inline void inv_normals(double dh0, double dh1, double *n0, double *n1)
{
#if defined(__SSE2__)
    const __m128d d = _mm_set_pd(dh1, dh0), q = _mm_mul_pd(d, d);
    if (_mm_movemask_pd(_mm_cmple_pd(q, _mm_set1_pd(INVN_Q4MAX))) == 3) {
        /* both in inv_norm's short range: its sums, the bits of the full series */
        const __m128d q2 = _mm_mul_pd(q, q);
        const __m128d p01 = _mm_add_pd(_mm_set1_pd(1.0), _mm_mul_pd(_mm_set1_pd(INVN_C1), q));
        const __m128d p23 = _mm_add_pd(_mm_set1_pd(INVN_C2), _mm_mul_pd(_mm_set1_pd(INVN_C3), q));
        const __m128d r = _mm_add_pd(p01, _mm_mul_pd(q2, p23));
        *n0 = _mm_cvtsd_f64(r);
        *n1 = _mm_cvtsd_f64(_mm_unpackhi_pd(r, r));
        return;
    }
    if (_mm_movemask_pd(_mm_cmple_pd(q, _mm_set1_pd(INVN_QMAX))) == 3) {
        const __m128d q2 = _mm_mul_pd(q, q), q4 = _mm_mul_pd(q2, q2);
        const __m128d p01 = _mm_add_pd(_mm_set1_pd(1.0), _mm_mul_pd(_mm_set1_pd(INVN_C1), q));
        const __m128d p23 = _mm_add_pd(_mm_set1_pd(INVN_C2), _mm_mul_pd(_mm_set1_pd(INVN_C3), q));
        const __m128d p45 = _mm_add_pd(_mm_set1_pd(INVN_C4), _mm_mul_pd(_mm_set1_pd(INVN_C5), q));
        const __m128d r = _mm_add_pd(_mm_add_pd(p01, _mm_mul_pd(q2, p23)), _mm_mul_pd(q4, p45));
        *n0 = _mm_cvtsd_f64(r);
        *n1 = _mm_cvtsd_f64(_mm_unpackhi_pd(r, r));
        return;
    }
#endif
    *n0 = inv_norm(dh0);
    *n1 = inv_norm(dh1);
}

void pdw_terrain_inv_normals(long n, const double *dh, double *inv_n)
{
    for (long i = 0; i < n; i += 2) {
        double b;
        inv_normals(dh[i], i + 1 < n ? dh[i + 1] : 0.0, inv_n + i, &b);
        if (i + 1 < n) inv_n[i + 1] = b;
    }
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

/* *src as a value of its own: the empty asm takes it in a register, so the compiler cannot merge
 * two such loads into one 16-byte load, which (across two fresh 8-byte stores of the contact
 * stage) would wait until the stores are written instead of taking the value from the store
 * buffer (copy_fresh's reason). */
static inline double load_fresh(const double *src)
{
    double v = *src;
#if defined(__GNUC__) && defined(__SSE2__)
    __asm__("" : "+x"(v));      /* "x": an SSE register, where the value is used */
#endif
    return v;
}

/* One foot's ground at s: h, h', h'' (out[0..2]; with ddh = 0 only h, h', out[2] := NaN) of its
 * cell (the hint updated). A level cell (finite s) gives exactly pdw_ground_eval_cell's values
 * (pdw_ground.h), known before s is (the time loop's chain skips the quintic). */
static inline void sample_foot(const pdw_ground *g, double s, double *hint, double *out, int ddh)
{
    const long c = pdw_ground_cell_hint(g, s, hint);
    if (pdw_ground_cell_level(g, c) && s - s == 0.0) {
        out[0] = g->cells[c*PDW_NGCELL + PDW_GCELL_A0] + 0.0;
        out[1] = out[2] = 0.0;
    } else if (ddh) {
        pdw_ground_eval_cell(g, c, s, out);
    } else {
        pdw_ground_eval_cell_dh(g, c, s, out);
        out[2] = NAN;
    }
}

/* One foot's sampled ground (layout GROUND) into gi. */
static inline void put_ground(double *gi, const double *e, double sigma, double alpha, double c)
{
    gi[PDW_GROUND_H] = e[0];
    gi[PDW_GROUND_DH] = e[1];
    gi[PDW_GROUND_DDH] = e[2];
    gi[PDW_GROUND_SIGMA] = sigma;
    gi[PDW_GROUND_ALPHA] = alpha;
    gi[PDW_GROUND_INV_N] = c;
    gi[PDW_GROUND_S_N] = e[1] * c;      /* h'/N: the forces' coefficient */
}

/* Is every rule of pdw_update_flags_trig for swing foot i decided without its ground, the other
 * foot j being a support foot (its kinematics exact)? With the ground's bounds (pdw_ground.h:
 * h <= h_top, |h'| <= dh_max, 1/N >= inv_n_min over the extent, s_A inside it), foot i's gap
 * g_i = (y_A - h)/N - r >= lb, lb = u/N_max - r (u >= 0) or u - r (u < 0), u = y_A - h_top,
 * and its contact point x_D = s_A + r h'/N lies within r dh_max of s_A (so does foot j's).
 * Decided:
 *   behind: s_Ai + 2 r dh_max + m < s_Aj, so x_Di <= x_Dj: disarmed and no touch-down whatever
 *           g_i; and lb > -fall_depth + m (pdw_check_feet passes);
 *   ahead:  s_Ai - 2 r dh_max - m > s_Aj, so x_Di > x_Dj, and lb > m: g_i > 0, armed, no
 *           touch-down;
 * m = 1e-9 m (+ 1e-15 |s|) covers every rounding of the evaluated expressions (relative 1e-16
 * of quantities of order 1 m). *lb := lb. NaN anywhere: not decided. */
static inline int swing_decided(const pdw_ground *g, const double *x, double cos_th,
                                const double *p, double s_i, double s_j, double fall_depth,
                                double *lb_out)
{
    if (!(s_i >= g->s_min && s_i <= g->s_max)) return 0;
    const double r = p[PDW_P_R];
    const double mx = 2.0 * r * g->dh_max + 1e-9 + 1e-15 * fabs(s_j);
    const double u = (x[PDW_X_Y_O] - cos_th * (p[PDW_P_L] - r)) - g->h_top;
    const double lb = (u >= 0.0 ? u * g->inv_n_min : u) - r;
    *lb_out = lb;
    if (s_i + mx < s_j) return lb > -fall_depth + 1e-9;
    return s_i - mx > s_j && lb > 1e-9;
}

/* The flag update's kinematics with support foot j (a constant) and swing foot i = 1 - j: 0 if
 * foot i's rules need its ground (e_j, foot j's sample, is then set for the caller), else 1
 * with kin and gnd written: foot j's exactly as pdw_terrain_kinematics writes them (the same
 * generated expressions: the two-foot kinematics, whose outputs for foot i are overwritten
 * at once, so the compiler drops foot i's arithmetic), foot i's as a swing foot the
 * rules read the same way (x_D = s_A, g = lb, no rate, no slip) on level ground (h' = +0,
 * 1/N = 1, h'/N = +0: the forces of its zero contact forces are +0, as with its own ground). */
#if defined(__GNUC__)
__attribute__((always_inline))
#endif
static inline int one_support(const pdw_kernel *k, const pdw_ground *g, const double *x,
                              const double *trig, const double *p, const double *anchors,
                              double fall_depth, const double *sA, int j, double *kin,
                              double *gnd, double *cell, double *e_j)
{
    const int i = 1 - j, consistent = k->variant == 1;
    double lb;
    sample_foot(g, sA[j], cell + j, e_j, 0);
    if (!((consistent || e_j[1] != 0.0)     /* else the level path may be the exact one */
          && swing_decided(g, x, trig[i ? PDW_TRIG_COS_THETA2 : PDW_TRIG_COS_THETA1], p, sA[i],
                           sA[j], fall_depth, &lb)))
        return 0;
    const double level[3] = {g->h_top, 0.0, NAN};
    double gl[2*PDW_NGROUND];
    const double c = inv_norm(e_j[1]);      /* inv_normals' bits for foot j */
    double sig = 0.0, al = 0.0;
    if (consistent) { sig = pdw_ground_arc(g, sA[j]); al = atan(e_j[1]); }
    put_ground(gl + j*PDW_NGROUND, e_j, sig, al, c);
    put_ground(gl + i*PDW_NGROUND, level, 0.0, 0.0, 1.0);
    if (consistent) pdw_consistent_ground_kinematics(x, trig, p, anchors, gl, kin);
    else pdw_paper_ground_kinematics(x, trig, p, anchors, gl, kin);
    double *ki = kin + i*PDW_NKIN;      /* foot i's values overwritten (its stores are dead) */
    ki[PDW_KIN_X_D] = sA[i];
    ki[PDW_KIN_Y_D] = lb;
    ki[PDW_KIN_V_X] = ki[PDW_KIN_V_Y] = ki[PDW_KIN_S] = ki[PDW_KIN_XI] = 0.0;
    ki[PDW_KIN_V_IN] = anchors[PDW_ANCHOR_V_IN1 + i];
    put_ground(gnd + j*PDW_NGROUND, e_j, sig, al, c);
    put_ground(gnd + i*PDW_NGROUND, level, 0.0, 0.0, 1.0);
    const int z = k->nx > PDW_NX;
    kin[PDW_KIN_Z] = z ? x[PDW_X_Z1] : 0.0;
    kin[PDW_NKIN + PDW_KIN_Z] = z ? x[PDW_X_Z1 + 1] : 0.0;
    return 1;
}

/* pdw_terrain_kinematics (full: flags == NULL) and pdw_terrain_flag_kinematics (flags given:
 * no h'' (NaN in gnd), and with one support foot a swing foot whose rules the bounds decide is
 * not sampled: one_support). Straight-line code on local arrays with constant indices (the
 * feet written out, the generated kinematics inline): the compiler keeps the ground values in
 * registers, where a loop over the feet passed them through memory on the time loop's chain;
 * gnd is stored field by field (for the forces and the Jacobian), never read back here. */
#if defined(__GNUC__)
__attribute__((always_inline))  /* specialized in each of the two entries below */
#endif
static inline void terrain_kinematics(const pdw_kernel *k, const pdw_ground *g, const double *x,
                                      const double *trig, const double *p, const double *anchors,
                                      const int *flags, double fall_depth, double *kin,
                                      double *gnd, double *cell)
{
    double sA[2], e0[3], e1[3], c0, c1, gl[2*PDW_NGROUND];
    double sig0 = 0.0, sig1 = 0.0, al0 = 0.0, al1 = 0.0;
    const int full = flags == NULL;
    const int consistent = k->variant == 1;
    pdw_ground_points(x, trig, p, sA);
    if (!full && g->bounded && flags[0] != flags[1]) {
        /* one support foot: its swing partner sampled only when its rules need it */
        if (flags[1]) {
            if (one_support(k, g, x, trig, p, anchors, fall_depth, sA, 1, kin, gnd, cell, e1))
                return;
            sample_foot(g, sA[0], cell, e0, 0);
        } else {
            if (one_support(k, g, x, trig, p, anchors, fall_depth, sA, 0, kin, gnd, cell, e0))
                return;
            sample_foot(g, sA[1], cell + 1, e1, 0);
        }
    } else {
        sample_foot(g, sA[0], cell, e0, full);
        sample_foot(g, sA[1], cell + 1, e1, full);
    }
    if (!consistent && e0[1] == 0.0 && e1[1] == 0.0) {
        /* h' = 0 under both feet (level cells: a plane on the slope, the flat parts of steps,
         * a flat ground with patches): the tangent lines are level, 1/N = 1, and the paper
         * variant's surface-frame kinematics are the flat kernel's own with y_D less the
         * height (derive/terrain.py with h' = 0; equal to rounding: another association of the
         * same sums). Not for the consistent variant, whose rolling coordinate starts from the
         * ground's arc length sigma and must stay one coordinate on every cell. */
        k->kinematics(x, trig, p, anchors, kin);
        kin[PDW_KIN_Y_D] -= e0[0];
        kin[PDW_NKIN + PDW_KIN_Y_D] -= e1[0];
        put_ground(gnd, e0, 0.0, 0.0, 1.0);
        put_ground(gnd + PDW_NGROUND, e1, 0.0, 0.0, 1.0);
        return;
    }
    inv_normals(e0[1], e1[1], &c0, &c1);
    if (consistent) {                   /* the rolling coordinate needs sigma, alpha */
        sig0 = pdw_ground_arc(g, sA[0]);
        al0 = atan(e0[1]);
        sig1 = pdw_ground_arc(g, sA[1]);
        al1 = atan(e1[1]);
    }
    put_ground(gl, e0, sig0, al0, c0);
    put_ground(gl + PDW_NGROUND, e1, sig1, al1, c1);
    if (consistent) pdw_consistent_ground_kinematics(x, trig, p, anchors, gl, kin);
    else pdw_paper_ground_kinematics(x, trig, p, anchors, gl, kin);
    put_ground(gnd, e0, sig0, al0, c0);
    put_ground(gnd + PDW_NGROUND, e1, sig1, al1, c1);
    const int z = k->nx > PDW_NX;
    kin[PDW_KIN_Z] = z ? x[PDW_X_Z1] : 0.0;
    kin[PDW_NKIN + PDW_KIN_Z] = z ? x[PDW_X_Z1 + 1] : 0.0;
}

void pdw_terrain_kinematics(const pdw_kernel *k, const pdw_ground *g, const double *x,
                            const double *trig, const double *p, const double *anchors,
                            double *kin, double *gnd, double *cell)
{
    terrain_kinematics(k, g, x, trig, p, anchors, NULL, 0.0, kin, gnd, cell);
}

void pdw_terrain_flag_kinematics(const pdw_kernel *k, const pdw_ground *g, const double *x,
                                 const double *trig, const double *p, const double *anchors,
                                 const int *flags, double fall_depth, double *kin, double *gnd,
                                 double *cell)
{
    terrain_kinematics(k, g, x, trig, p, anchors, flags, fall_depth, kin, gnd, cell);
}

void pdw_terrain_contact(const pdw_kernel *k, const pdw_ground *g, const double *kin,
                         const int *flags, const double *p, double *contact, int partials)
{
    void (*stage)(const double *, const int *, const double *, double *) =
        partials ? k->contact_partials : k->contact;
    if (g->n_patches == 0) {            /* no patches: the run's parameters (the common case) */
        stage(kin, flags, p, contact);
        return;
    }
    /* Every contact stage writes 0.0 for a foot that is not a penetrating support foot,
     * whatever p (derive/emit.py _contact_function): no penetrating foot, or one that no patch
     * reaches, takes the run's parameters; with one penetrating foot, one call with that foot's
     * parameters gives both feet's values (single support, the common case) */
    const int pen0 = flags[0] && kin[PDW_KIN_Y_D] < 0.0;
    const int pen1 = flags[1] && kin[PDW_NKIN + PDW_KIN_Y_D] < 0.0;
    if (g->n_patches == 0 || !(pen0 || pen1)) {
        stage(kin, flags, p, contact);
        return;
    }
    double pi[PDW_NP], ci[2*PDW_NCONTACT];
    if (!(pen0 && pen1)) {
        const double s = kin[(pen1 ? PDW_NKIN : 0) + PDW_KIN_X_D];
        if (!pdw_ground_patched(g, s)) {
            stage(kin, flags, p, contact);
            return;
        }
        memcpy(pi, p, sizeof pi);
        pdw_ground_params(g, s, p, pi);
        stage(kin, flags, pi, contact);
        return;
    }
    if (!pdw_ground_patched(g, kin[PDW_KIN_X_D])
        && !pdw_ground_patched(g, kin[PDW_NKIN + PDW_KIN_X_D])) {
        stage(kin, flags, p, contact);      /* neither foot on a patch: the run's parameters */
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

#if defined(__GNUC__)
__attribute__((always_inline))  /* inline in pdw_terrain_cdm_terms, the time loop's */
#endif
static inline void terrain_forces(const double *contact, const double *gnd, const double *p,
                                  double *cw, double *moment)
{
    double gf[2*PDW_NGFORCE], cf[2*PDW_NCONTACT], gd[2*PDW_NGROUND];
    for (int i = 0; i < 2; ++i) {       /* the inputs, one load each (load_fresh) */
        const int c = i*PDW_NCONTACT, j = i*PDW_NGROUND;
        cf[c + PDW_CONTACT_F_N] = load_fresh(contact + c + PDW_CONTACT_F_N);
        cf[c + PDW_CONTACT_F_T] = load_fresh(contact + c + PDW_CONTACT_F_T);
        gd[j + PDW_GROUND_DH] = load_fresh(gnd + j + PDW_GROUND_DH);
        gd[j + PDW_GROUND_INV_N] = load_fresh(gnd + j + PDW_GROUND_INV_N);
        gd[j + PDW_GROUND_S_N] = load_fresh(gnd + j + PDW_GROUND_S_N);
    }
    if (gd[PDW_GROUND_DH] == 0.0 && gd[PDW_NGROUND + PDW_GROUND_DH] == 0.0) {
        /* level under both feet (h' = +0, 1/N = 1 and h'/N = +0: pdw_terrain_kinematics sets
         * them so): ground_forces' expressions (pdw_terrain_gen.h) with each product by 1/N = 1
         * dropped (x * 1 is x, bit for bit, NaN and signed zeros included): the same values
         * without the multiplications the forces wait on */
        const double r = p[PDW_P_R];
        for (int i = 0; i < 2; ++i) {
            const double fn = cf[i*PDW_NCONTACT + PDW_CONTACT_F_N];
            const double ft = cf[i*PDW_NCONTACT + PDW_CONTACT_F_T];
            const double sn = gd[i*PDW_NGROUND + PDW_GROUND_S_N];
            const double t0 = fn*sn;
            cw[i*PDW_NCONTACT + PDW_CONTACT_F_N] = fn + ft*sn;
            cw[i*PDW_NCONTACT + PDW_CONTACT_F_T] = ft - t0;
            moment[i] = r*(ft*(1.0 - 1.0) + t0);
        }
        return;
    }
    pdw_ground_forces(cf, gd, p, gf);   /* reads only F_n, F_t of cf and 1/N, h'/N of gd */
    for (int i = 0; i < 2; ++i) {
        cw[i*PDW_NCONTACT + PDW_CONTACT_F_N] = gf[i*PDW_NGFORCE + PDW_GFORCE_F_Y];
        cw[i*PDW_NCONTACT + PDW_CONTACT_F_T] = gf[i*PDW_NGFORCE + PDW_GFORCE_F_X];
        moment[i] = gf[i*PDW_NGFORCE + PDW_GFORCE_M_THETA];
    }
}

void pdw_terrain_forces(const double *contact, const double *gnd, const double *p, double *cw,
                        double *moment)
{
    terrain_forces(contact, gnd, p, cw, moment);
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

void pdw_terrain_cdm_terms_split(const pdw_kernel *k, const double *x, const double *trig,
                                 const double *p, const double *contact, const double *gnd,
                                 double *M, double *C, double *QmG, double *moment)
{
    double cw[2*PDW_NCONTACT];
    terrain_forces(contact, gnd, p, cw, moment);
    k->cdm_terms(x, trig, p, cw, M, C, QmG);
}

void pdw_terrain_cdm_terms(const pdw_kernel *k, const double *x, const double *trig,
                           const double *p, const double *contact, const double *gnd, double *M,
                           double *C, double *QmG)
{
    double cw[2*PDW_NCONTACT], moment[2];
    terrain_forces(contact, gnd, p, cw, moment);
    k->cdm_terms(x, trig, p, cw, M, C, QmG);
    QmG[PDW_X_THETA1] += moment[0];
    QmG[PDW_X_THETA2] += moment[1];
}
