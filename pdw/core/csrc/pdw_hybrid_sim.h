/* The hybrid (impact-momentum) walker of docs/model.md section 9: compiled step map.
 *
 * One step = the stance phase of the reduced 2-DOF system (generated/pdw_hybrid.c; state
 * y = [theta_st, theta_sw, thetad_st, thetad_sw]) integrated by Dormand-Prince 5(4) with error
 * control until heel strike, then the inelastic impact (a 6x6 KKT system solved here) and the
 * relabelling of the legs. The caller allocates everything; nothing here allocates.
 *
 * Heel strike: the *armed* swing foot reaches the ground (y_sw = 0) moving down. As in
 * docs/model.md section 5, the swing foot is armed once it has been above the ground (y_sw > 0)
 * while downhill of the stance foot (x_sw > x_st) and, here also, with the inter-leg angle
 * theta_sw - theta_st >= min_step_angle; it is disarmed whenever it is uphill again
 * (x_sw <= x_st); a strike also needs the foot downhill (x_sw > x_st) at the step's end.
 * This ignores the swing foot's scuffing at mid-stance, as every planar
 * walker model does. Arming is checked at the accepted integrator steps; h_max bounds the
 * step so that the above-ground excursion before a strike cannot hide inside one step. */
#ifndef PDW_HYBRID_SIM_H
#define PDW_HYBRID_SIM_H

#include "pdw_hybrid.h"

typedef struct pdw_hybrid_opts {
    double rtol, atol;        /* DOPRI5 error control, per component:
                                 |err_i| <= atol + rtol * max(|y_i|, |ynew_i|) (RMS norm) */
    double h0;                /* first step [s] */
    double h_max;             /* largest step [s] */
    double t_max;             /* a stance longer than this is a failure (no heel strike) [s] */
    double event_tol;         /* heel-strike time located to this [s] */
    double min_step_angle;    /* arming also needs theta_sw - theta_st >= this [rad] */
    double fall_angle;        /* fell when |theta_st| >= this [rad] */
    long max_steps;           /* integrator steps per stance phase */
    double dt_out;            /* recording: sample every dt_out [s] of absolute time
                                 (dense, by re-stepping); 0 = every accepted step */
    int (*poll)(void *ctx);   /* called at each step's start and every PDW_HYBRID_POLL_RHS
                                 right-hand sides within it (NULL: never); nonzero stops the
                                 step with PDW_HYBRID_INTERRUPTED (Ctrl-C) */
    void *poll_ctx;
    /* The ground (docs/hybrid.md, "On a shaped ground"). Heel strike is when the armed swing
     * foot's contact point reaches the ground under it: y_sw = level, with
     *   level = dh + (ground ? h(s0 + x_sw) - h_st : 0),
     * h_st the ground's height at the stance foot's touch-down point; the stance foot rolls on
     * the mean slope plane at its own level. dh = 0 and ground = NULL: flat, bitwise the
     * model without these fields. */
    double dh;                /* ground under the swing foot relative to the stance foot's
                                 level for the whole step [m] (a step-down: dh < 0) */
    int (*ground)(const void *ctx, double s, double *h, double *slope);
                              /* height h(s) [m] above the mean slope plane at s [m] into *h,
                                 dh/ds into *slope when slope != NULL; returns nonzero when s
                                 is outside the ground's defined extent (a strike or a stance
                                 there stops the step: PDW_HYBRID_OFF_GROUND); NULL: flat */
    const void *ground_ctx;
    double max_slope;         /* a strike where |dh/ds| > max_slope is a trip (the foot hit
                                 a riser): status PDW_HYBRID_TRIPPED */
} pdw_hybrid_opts;

enum { PDW_HYBRID_POLL_RHS = 4096 };

enum {
    PDW_HYBRID_OK = 0,
    PDW_HYBRID_NO_STRIKE = 1,     /* t_max reached without heel strike */
    PDW_HYBRID_FELL = 2,          /* |theta_st| >= fall_angle */
    PDW_HYBRID_SINGULAR = 3,      /* singular reduced mass matrix or KKT matrix */
    PDW_HYBRID_NONFINITE = 4,     /* NaN or infinity */
    PDW_HYBRID_MAX_STEPS = 5,     /* max_steps integrator steps without heel strike */
    PDW_HYBRID_STEP_TINY = 6,     /* step size underflow */
    PDW_HYBRID_INTERRUPTED = 7,   /* opts->poll asked to stop (Ctrl-C) */
    PDW_HYBRID_TRIPPED = 8,       /* the swing foot struck a riser (|dh/ds| > max_slope) */
    PDW_HYBRID_OFF_GROUND = 9     /* a foot outside the ground's defined extent */
};

typedef struct pdw_hybrid_result {
    int status;                 /* PDW_HYBRID_* */
    double t0;                  /* absolute time at the start of the stance [s] */
    double s0;                  /* stance foot's rolling coordinate (input) [m] */
    double y0[4];               /* state at the start of the stance */
    double t_strike;            /* duration of the stance: touch-down to touch-down [s] */
    double y_minus[4];          /* just before heel strike (stance, swing of this step) */
    double y_plus[4];           /* just after, relabelled: stance = the old swing leg */
    double qd_minus[4];         /* full-model velocities before/after the impact, with */
    double qd_plus[4];          /*   the old stance leg as leg 1 */
    double impulse[2];          /* (Lambda_x, Lambda_y) of the ground on the new stance foot [N s] */
    double v_old[2];            /* old stance foot's material-point velocity after impact [m/s] */
    int old_foot_down;          /* 1 when v_old[1] <= 0: the old foot does not leave upward */
    double vy_strike;           /* swing foot's normal velocity at heel strike [m/s] (< 0) */
    double T_minus, T_plus;     /* kinetic energy before / after the impact [J] */
    double x_touch;             /* new footprint: swing foot's contact point at touch-down [m] */
    double step_length;         /* footprint spacing: x_touch - stance contact point at t0 [m] */
    double s0_next;             /* rolling coordinate of the new stance foot [m] */
    double E0, dE_max;          /* stance energy T + V at t0; max |E - E0| at accepted steps [J] */
    double Fn_min;              /* smallest normal ground force during the stance [N] */
    double ratio_max;           /* largest |F_t / F_n| (friction needed to roll) */
    long n_steps, n_rejected, n_rhs;
    long n_rec;                 /* samples written to the record buffers */
    int rec_full;               /* 1 if the record buffer filled up */
    double h_st;                /* ground height under the stance foot's touch-down point [m] */
    double h_touch;             /* ground height under the new footprint [m] */
} pdw_hybrid_result;

/* Default options (rtol 1e-10, atol 1e-12, h0 1e-3 s, h_max 0.01 s, t_max 5 s,
 * event_tol 1e-13 s, min_step_angle 0.1 rad, fall_angle 1.4 rad, max_steps 100000, dt_out 0,
 * dh 0, ground NULL, max_slope 1).
 * min_step_angle > 0 excludes the degenerate "gait" in which the swing leg barely passes the
 * stance leg and swings back onto the ground next to the stance foot (zero step length). */
void pdw_hybrid_default_opts(pdw_hybrid_opts *o);

/* The impact map at a pre-impact state (stance = leg 1, swing = leg 2): fills y_plus,
 * qd_minus, qd_plus, impulse, v_old, old_foot_down, T_minus, T_plus of r. Returns
 * PDW_HYBRID_OK or PDW_HYBRID_SINGULAR. */
int pdw_hybrid_impact(const double *p, const double *y_minus, pdw_hybrid_result *r);

/* One step from y0 (time t0, stance rolling coordinate s0): stance phase, heel strike,
 * impact, relabelling. Records samples (t, y) into rec_t (rec_cap) and rec_y (rec_cap x 4)
 * when rec_cap > 0, starting at index 0; the last sample is the pre-impact state. Returns
 * r->status. */
int pdw_hybrid_step(const double *p, const double *y0, double t0, double s0,
                    const pdw_hybrid_opts *o, pdw_hybrid_result *r,
                    double *rec_t, double *rec_y, long rec_cap);

/* n_steps steps from y0; results has room for n_steps. Samples of all steps go to one record
 * buffer, with rec_step[k] the step index of sample k. Returns the number of completed
 * steps (< n_steps when a step failed: results[returned].status says why). */
long pdw_hybrid_walk(const double *p, const double *y0, double s0, long n_steps,
                     const pdw_hybrid_opts *o, pdw_hybrid_result *results,
                     double *rec_t, double *rec_y, long *rec_step, long rec_cap);

/* Solve the n x n system A x = b (row-major, overwritten) by Gaussian elimination with partial
 * pivoting; returns 0, or -1 when singular. n <= 8. */
int pdw_hybrid_solve(int n, double *A, double *b, double *x);

/* Exact derivatives (pdw_hybrid_var.c): ydot and A = d ydot / d y (4x4 row-major) of the
 * stance phase (-1 on a singular M_r); the impact-and-relabel map's derivative D (4x4) at a
 * pre-impact state; and one step of the map (as pdw_hybrid_step from t0 = s0 = 0, filling r)
 * with its Jacobian DP = D S Phi(T) (4x4 row-major): the variational equations integrated to
 * the strike time with the saltation matrix S of the heel-strike event. Return PDW_HYBRID_*. */
int pdw_hybrid_rhs_jac(const double *y, const double *p, double *ydot, double *A);
int pdw_hybrid_impact_jac(const double *p, const double *ym, double *D);
int pdw_hybrid_step_jac(const double *p, const double *y0, const pdw_hybrid_opts *o,
                        pdw_hybrid_result *r, double *DP);

/* As pdw_hybrid_step_jac, and the sensitivities of the pre-impact state and the strike time
 * to the initial state and to the floor offset o->dh (the disturbance of the gait
 * sensitivity norm): dym_dy0 = S Phi(T) (4x4), dym_ddh = f / (grad g . f) (4),
 * dT_dy0 = -grad g Phi / (grad g . f) (4), *dT_ddh = 1 / (grad g . f). A ground function
 * (o->ground) is refused (PDW_HYBRID_SINGULAR): its slope would enter the event. */
int pdw_hybrid_step_sens(const double *p, const double *y0, const pdw_hybrid_opts *o,
                         pdw_hybrid_result *r, double *DP, double *dym_dy0, double *dym_ddh,
                         double *dT_dy0, double *dT_ddh);

/* n_steps steps from y0 (s0 = 0, on o->ground if set) with the floor offset dh_seq[k] at
 * step k (o->dh ignored; a failed step, or one whose old foot does not leave, ends the walk);
 * y_out (n_steps x 4) the post-impact states, t_out (n_steps) the stance durations. Returns
 * the completed steps; *status the failing step's status (PDW_HYBRID_OK if none). */
long pdw_hybrid_walk_dh(const double *p, const double *y0, long n_steps, const double *dh_seq,
                        const pdw_hybrid_opts *o, double *y_out, double *t_out, int *status);

#endif /* PDW_HYBRID_SIM_H */
