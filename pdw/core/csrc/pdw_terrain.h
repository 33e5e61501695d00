/* The shaped-ground kernel (docs/terrain.md, docs/model.md section 11): any pdw_kernel's contact
 * laws and mechanics on a pdw_ground, composed from the derived shaped-ground stages of
 * generated/pdw_model.c (derive/terrain.py). Every array is caller-allocated; nothing here
 * allocates. The time loops reach these through pdw_sim.h's pdw_sim_* dispatch, which keeps
 * today's kernel (bitwise, at no cost) when a run's ground is flat (pdw_sim.ground == NULL). */
#ifndef PDW_TERRAIN_H
#define PDW_TERRAIN_H

#include "pdw_model.h"
#include "pdw_ground.h"

/* kin (2 PDW_NKIN, in the local surface frame: y_D the gap along the normal, v_x the slip, v_y the
 * normal rate) and gnd (2 PDW_NGROUND: the ground sampled under each foot) of x; trig given.
 * cell (2): each foot's height cell of the last call, a hint (any value is safe; work's
 * PDW_WORK_GROUND_CELL block), updated. */
void pdw_terrain_kinematics(const pdw_kernel *k, const pdw_ground *g, const double *x,
                            const double *trig, const double *p, const double *anchors,
                            double *kin, double *gnd, double *cell);

/* pdw_terrain_kinematics for the flag update of the time loops (pdw_update_flags_trig, flags:
 * the support flags the update starts from; fall_depth: its pdw_check_feet limit [m]): the
 * same kin for every foot whose values the update's rules, pdw_check_feet, the events, the
 * contact stage and the forces read; gnd without h'' (NaN: only the Jacobian reads it, after
 * its own pdw_terrain_rhs). A swing foot whose rules the ground's bounds decide (pdw_terrain.c
 * swing_decided: far behind the support foot, or ahead of it and clear of the ground) is not
 * sampled: its kin are those of a level ground at the ground's top bound, which decide the
 * rules the same way, and its contact stage writes 0.0 whatever its kin. */
void pdw_terrain_flag_kinematics(const pdw_kernel *k, const pdw_ground *g, const double *x,
                                 const double *trig, const double *p, const double *anchors,
                                 const int *flags, double fall_depth, double *kin, double *gnd,
                                 double *cell);

/* 1/N = 1/sqrt(1 + h'^2) of dh[0..n) as the kinematics computes it (in pairs, as the two feet;
 * an odd last one paired with 0), for tests. */
void pdw_terrain_inv_normals(long n, const double *dh, double *inv_n);

/* The kernel's contact stage (forces, or with partials = 1 forces and partials) with each foot's
 * parameters at its contact point (the patches of g, blended; none: one call, as the kernel). */
void pdw_terrain_contact(const pdw_kernel *k, const pdw_ground *g, const double *kin,
                         const int *flags, const double *p, double *contact, int partials);

/* The surface-frame forces of contact as the slope-frame forces the flat dynamics stage takes
 * (cw: only F_n := F_y, F_t := F_x are written, the only fields every dynamics and cdm_terms
 * stage reads; the Jacobian sets the partials it passes) and the moments moment[i] to add to
 * the theta_i rows of f (or Q_f - G). */
void pdw_terrain_forces(const double *contact, const double *gnd, const double *p, double *cw,
                        double *moment);

/* f(x) and df/dx (central differences, as LuGre's kernels) on the ground; work: PDW_NWORK. */
void pdw_terrain_rhs(const pdw_kernel *k, const pdw_ground *g, const double *x, const double *p,
                     const int *flags, const double *anchors, double *xdot, double *work);
void pdw_terrain_jacobian(const pdw_kernel *k, const pdw_ground *g, const double *x,
                          const double *p, const int *flags, const double *anchors, double *J,
                          double *work);

/* The central difference method's M, C, Q_f - G on the ground from contact (surface frame) and
 * gnd of x (trig given). */
void pdw_terrain_cdm_terms(const pdw_kernel *k, const double *x, const double *trig,
                           const double *p, const double *contact, const double *gnd, double *M,
                           double *C, double *QmG);

/* pdw_terrain_cdm_terms with the moments moment[0..1] returned, not added: QmG holds Q_f - G
 * of the slope-frame forces, and QmG[theta_i] + moment[i] is pdw_terrain_cdm_terms's QmG (the
 * central difference update adds them where it uses them: pdw_cdm.c). */
void pdw_terrain_cdm_terms_split(const pdw_kernel *k, const double *x, const double *trig,
                                 const double *p, const double *contact, const double *gnd,
                                 double *M, double *C, double *QmG, double *moment);

#endif /* PDW_TERRAIN_H */
