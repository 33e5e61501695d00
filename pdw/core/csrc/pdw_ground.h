/* The compiled ground (docs/terrain.md): its height h(s) above the mean slope, h'(s), h''(s), its
 * arc length and its contact patches, read from caller-allocated const tables (built by
 * pdw/core/ground.py's GroundTable; no globals, no allocation). Every function is inline so that
 * the time loops (pdw_terrain.c) and the hybrid loop can reuse it.
 *
 * Height: cells k = 0..n-1 on knots s_0 < ... < s_n, each row (layout GROUND_CELL)
 *     [s_k, 1/w_k, a_0 .. a_5],   h(s) = sum_j a_j d^j,  d = s - s_k in [0, w_k],
 * a piecewise quintic (C2 where the shape is). The cell is found in O(1): lut[j] is the cell
 * containing s_min + j/lut_inv, then a short forward scan.
 * Patches: rows [s_a, s_b, v_1 .. v_f] (NaN: field not set), field i sets p[field[i]]; within
 * blend/2 of an edge the value is blended by the C2 smoothstep.
 * Off the defined extent [s_min, s_max] the end cells' polynomials continue (used only inside
 * trial steps): the loops check every accepted state (pdw_ground_inside) and stop with
 * PDW_REASON_OFF_GROUND, never extrapolating silently. */
#ifndef PDW_GROUND_EVAL_H
#define PDW_GROUND_EVAL_H

#include <math.h>
#include <string.h>
#include "pdw_model.h"

typedef struct pdw_ground {
    double s_min, s_max;        /* defined extent [m] */
    long n_cells;
    const double *cells;        /* (n_cells, PDW_NGCELL) */
    const double *arc;          /* (n_cells, 6): the arc length sigma(s) in the same form */
    long n_lut;
    double lut_inv;             /* lut bins per metre */
    const long *lut;            /* (n_lut,) */
    int n_patches, n_fields;
    const int *fields;          /* (n_fields,) PDW_P_* indices the patches set */
    const double *patches;      /* (n_patches, 2 + n_fields) */
    double blend;               /* patch-edge blend width [m] */
    int n_zones;
    const double *zones;        /* (n_zones,) sorted blend-zone boundaries [m] (events) */
    /* bounds over the defined extent (pdw_ground_set_bounds; bounded = 0: none, e.g. a struct
     * zeroed by its caller): h(s) <= h_top, |h'(s)| <= dh_max, 1/N >= inv_n_min */
    int bounded;
    double h_top, dh_max, inv_n_min;
} pdw_ground;

/* The cell containing s (the end cells beyond the extent). */
static inline long pdw_ground_cell(const pdw_ground *g, double s)
{
    double jf = (s - g->s_min) * g->lut_inv;
    long j = jf <= 0.0 ? 0 : (jf >= (double)(g->n_lut - 1) ? g->n_lut - 1 : (long)jf);
    long k = g->lut[j];
    while (k + 1 < g->n_cells && s >= g->cells[(k + 1)*PDW_NGCELL + PDW_GCELL_S]) ++k;
    while (k > 0 && s < g->cells[k*PDW_NGCELL + PDW_GCELL_S]) --k;
    return k;
}

/* pdw_ground_cell with a hint: *hint (the caller's scratch, a cell index as a double; any value,
 * NaN included, is safe) if that cell contains s, else the search; *hint := the cell found. The
 * cell is pdw_ground_cell's (the one k with s_k <= s < s_k+1, the end cells beyond the extent).
 * A foot moves a fraction of a cell per step: the test is a predicted branch and the cell's
 * coefficients load before s is known, where the search waits on s. */
static inline long pdw_ground_cell_hint(const pdw_ground *g, double s, double *hint)
{
    const double hd = *hint;
    if (hd >= 0.0 && hd < (double)g->n_cells) {
        const long k = (long)hd;
        if ((k == 0 || s >= g->cells[k*PDW_NGCELL + PDW_GCELL_S])
            && (k + 1 == g->n_cells || s < g->cells[(k + 1)*PDW_NGCELL + PDW_GCELL_S]))
            return k;
    }
    const long k = pdw_ground_cell(g, s);
    *hint = (double)k;
    return k;
}

/* Is cell k level: a_1 .. a_5 all +0.0 (all bits zero; h = a_0 over the cell: a plane on the
 * slope, the flat parts of steps and patches)? There, for every finite s, pdw_ground_eval_cell
 * gives exactly h = a_0 + 0.0 (a_0, or +0 for a_0 = -0) and h' = h'' = +0: each product with a
 * +0 coefficient is a zero, and a sum with a zero is the other term (+0 when both are zeros,
 * round to nearest). The coefficients' loads and the test need only k, not s: a predicted
 * branch the time loops do not wait on. */
static inline int pdw_ground_cell_level(const pdw_ground *g, long k)
{
    const double *a = g->cells + k*PDW_NGCELL + PDW_GCELL_A0;
    unsigned long long bits = 0, b;
    for (int j = 1; j < 6; ++j) { memcpy(&b, a + j, sizeof b); bits |= b; }
    return bits == 0;
}

/* h, h' at s in cell k into out[0..1]. Estrin's scheme in d itself: short dependency chains
 * (the time loops wait on h', and no scaling u = d/w sits before it or after it); the
 * derivative's coefficients (2 a_2, ...) need only the cell, not s. */
static inline void pdw_ground_eval_cell_dh(const pdw_ground *g, long k, double s, double *out)
{
    const double *c = g->cells + k*PDW_NGCELL;
    const double d = s - c[PDW_GCELL_S];
    const double *a = c + PDW_GCELL_A0;
    const double d2 = d*d, d4 = d2*d2;
    out[0] = (a[0] + a[1]*d) + d2*(a[2] + a[3]*d) + d4*(a[4] + a[5]*d);
    out[1] = (a[1] + 2.0*a[2]*d) + d2*(3.0*a[3] + 4.0*a[4]*d) + d4*(5.0*a[5]);
}

/* h, h', h'' at s in cell k into out[0..2] (h, h': pdw_ground_eval_cell_dh's, the same bits;
 * h'' only the Jacobian reads). */
static inline void pdw_ground_eval_cell(const pdw_ground *g, long k, double s, double *out)
{
    pdw_ground_eval_cell_dh(g, k, s, out);
    const double *a = g->cells + k*PDW_NGCELL + PDW_GCELL_A0;
    const double d = s - g->cells[k*PDW_NGCELL + PDW_GCELL_S];
    out[2] = (2.0*a[2] + 6.0*a[3]*d) + (d*d)*(12.0*a[4] + 20.0*a[5]*d);
}

/* Set g's bounds over the defined extent [s_min, s_max] (g->bounded = 1 when they are finite),
 * from the cells' coefficients: on cell k, d = s - s_k lies in [0, w_k] (w_k the distance to the
 * next knot, or to s_max for the last cell, widened by 1e-12 relative for the rounding of d), so
 *     h <= a_0 + sum_j |a_j| w_k^j,     |h'| <= sum_j j |a_j| w_k^(j-1),
 * rigorous upper bounds (each widened by 1e-12 relative and 1e-15 m), whatever the polynomial;
 * 1/N = 1/sqrt(1 + h'^2) >= inv_n_min (1/sqrt(1 + dh_max^2), lowered by 1e-12 relative). Call
 * once after the other fields are set. */
static inline void pdw_ground_set_bounds(pdw_ground *g)
{
    double top = -INFINITY, dmax = 0.0;
    for (long k = 0; k < g->n_cells; ++k) {
        const double *c = g->cells + k*PDW_NGCELL, *a = c + PDW_GCELL_A0;
        const double end = k + 1 < g->n_cells ? c[PDW_NGCELL + PDW_GCELL_S] : g->s_max;
        const double w = fmax(end - c[PDW_GCELL_S], 0.0) * (1.0 + 1e-12);
        double hb = a[0], db = 0.0, wj = 1.0;          /* wj = w^(j-1) */
        for (int j = 1; j < 6; ++j) {
            db += j * fabs(a[j]) * wj;
            wj *= w;
            hb += fabs(a[j]) * wj;
        }
        top = fmax(top, hb);
        dmax = fmax(dmax, db);
    }
    g->h_top = top + 1e-12 * fabs(top) + 1e-15;
    g->dh_max = dmax * (1.0 + 1e-12) + 1e-15;
    g->inv_n_min = (1.0 / sqrt(1.0 + g->dh_max * g->dh_max)) * (1.0 - 1e-12);
    g->bounded = g->n_cells > 0 && isfinite(g->h_top) && isfinite(g->dh_max)
                 && isfinite(g->s_min) && isfinite(g->s_max);
}

/* h, h', h'' at s into out[0..2]. */
static inline void pdw_ground_eval(const pdw_ground *g, double s, double *out)
{
    pdw_ground_eval_cell(g, pdw_ground_cell(g, s), s, out);
}

/* The arc length sigma(s) [m] from s_min. */
static inline double pdw_ground_arc(const pdw_ground *g, double s)
{
    const long k = pdw_ground_cell(g, s);
    const double *c = g->cells + k*PDW_NGCELL, *a = g->arc + k*6;
    const double u = (s - c[PDW_GCELL_S]) * c[PDW_GCELL_INV_W], u2 = u*u, u4 = u2*u2;
    return (a[0] + a[1]*u) + u2*(a[2] + a[3]*u) + u4*(a[4] + a[5]*u);
}

/* Is s inside the defined extent? */
static inline int pdw_ground_inside(const pdw_ground *g, double s)
{
    return s >= g->s_min && s <= g->s_max;
}

/* Weight of a patch [s_a, s_b] at s: 0 outside, 1 inside, the C2 smoothstep across each edge's
 * blend zone [edge - blend/2, edge + blend/2]. The zone tests come first: only a point inside a
 * blend zone pays for the divisions (a foot crosses a zone in a few steps of thousands). */
static inline double pdw_ground_window(double s, double s_a, double s_b, double blend)
{
    const double hb = 0.5*blend;
    if (s <= s_a - hb || s >= s_b + hb) return 0.0;
    double w = 1.0;
    if (s < s_a + hb) { const double ua = (s - (s_a - hb)) / blend; w *= ua*ua*ua*(10.0 + ua*(-15.0 + 6.0*ua)); }
    if (s > s_b - hb) { const double ub = ((s_b + hb) - s) / blend; w *= ub*ub*ub*(10.0 + ub*(-15.0 + 6.0*ub)); }
    return w;
}

/* The parameter vector at s: p_out = p with the patches' fields blended in (p_out may be p's copy;
 * only the patched fields are written). Each patch's window once (patches in order, each field
 * summed in that order). */
static inline void pdw_ground_params(const pdw_ground *g, double s, const double *p, double *p_out)
{
    const int nf = g->n_fields;
    for (int f = 0; f < nf; ++f) p_out[g->fields[f]] = p[g->fields[f]];
    for (int i = 0; i < g->n_patches; ++i) {
        const double *row = g->patches + i*(2 + nf);
        const double w = pdw_ground_window(s, row[0], row[1], g->blend);
        if (!(w > 0.0)) continue;
        for (int f = 0; f < nf; ++f) {
            const int idx = g->fields[f];
            const double pv = row[2 + f];
            if (pv == pv) p_out[idx] += w * (pv - p[idx]);     /* NaN: not set here */
        }
    }
}

/* Does any patch reach s (a nonzero window)? */
static inline int pdw_ground_patched(const pdw_ground *g, double s)
{
    for (int i = 0; i < g->n_patches; ++i) {
        const double *row = g->patches + i*(2 + g->n_fields);
        if (s > row[0] - 0.5*g->blend && s < row[1] + 0.5*g->blend) return 1;
    }
    return 0;
}

/* The blend zone of s: the number of zone boundaries <= s (a change is an event). */
static inline int pdw_ground_zone(const pdw_ground *g, double s)
{
    int z = 0;
    while (z < g->n_zones && g->zones[z] <= s) ++z;
    return z;
}

/* pdw_ground_zone with a hint z (the foot's zone at the last step, or -1): z itself while s stays
 * inside that zone's interval [zones[z-1], zones[z]) (the cached interval), else the scan. */
static inline int pdw_ground_zone_hint(const pdw_ground *g, double s, int z)
{
    if (z >= 0 && z <= g->n_zones && (z == 0 || g->zones[z - 1] <= s)
        && (z == g->n_zones || s < g->zones[z]))
        return z;
    return pdw_ground_zone(g, s);
}

#endif /* PDW_GROUND_EVAL_H */
