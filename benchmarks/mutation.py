"""Mutation campaign over the physics, the integrators and the statuses (issue #26 item 18).

Each mutant is a small, deliberate bug: an operator swapped, an index off by one or pointing at
the other leg, a sign flipped, a condition dropped, a constant changed. The driver applies one
mutant to the working tree, rebuilds what it touched (C, .inc, .h or .pyx: ``setup.py
build_ext --inplace`` through `mutation_cc.py`, a compiler wrapper that caches object files, so
only the translation units the mutant changed are compiled again), runs a focused subset of the
test suite (``pytest -x``, niced, with a timeout) and records whether a test failed (*killed*)
or not (*survived*). The source is restored after every mutant (``try``/``finally``; the
extensions are rebuilt from the restored source before the next Python mutant and at the end;
the next compiled mutant's own build does it from the cache), and at the end the driver checks
that ``git diff`` of every mutated file is empty.

The mutants are a fixed list (`MUTANTS`), chosen by hand over the hand-written C
(pdw/core/csrc/*.c, *.h, *.inc; never generated/), the Python of pdw/sim and pdw/analysis and
the few other places issue #26 names; each names the tests that should see it. A mutant may
edit several lines when the same rule has several copies (the switching rules of Eq. 18 live in
the scalar loop, the switch predicate and two lane loops): the bug "the rule is wrong
everywhere" is one mutant. `EQUIVALENT` lists mutants argued to change no observable result.

Usage (from the repository root; ``make mutation`` runs the whole list)::

    .venv/bin/python benchmarks/mutation.py [--only ID,ID] [--area physics] [--timeout 400]
                                            [--out benchmarks/results/mutation.json] [--list]

It changes the working tree while it runs: do not edit the source meanwhile (run it in a
scratch copy of the repository to keep working: ``PYTHONPATH=$COPY`` picks the copy's ``pdw``).
Results: ``benchmarks/results/mutation.json`` (per mutant: killed / survived / build_error,
seconds, the test that killed it; written after every mutant, so an interrupted campaign
resumes with ``--resume``).

The module runs past 500 lines because of `MUTANTS`: 92 entries of old and new text kept in one
list, the campaign's record of what was planted; the driver itself is about 200 lines.
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import os
import pathlib
import re
import signal
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
OUT = ROOT / "benchmarks" / "results" / "mutation.json"

# ---- focused test subsets (new component tests first: they are the fast, precise ones) ------
SWITCH = ["tests/core/test_switching.py", "tests/sim/test_simulation.py", "tests/sim/test_batch.py"]
GAIT = ["tests/sim/test_online_gait.py", "tests/sim/test_gait.py", "tests/sim/test_scenes.py"]
CDM = ["tests/core/test_cdm.py", "tests/sim/test_simulation.py", "tests/core/test_model_physics.py"]
BATCH = ["tests/sim/test_batch_paths.py", "tests/sim/test_batch.py"]
ODE = ["tests/core/test_error_control.py", "tests/core/test_switching.py", "tests/core/test_integrators.py",
       "tests/sim/test_simulation.py", "tests/sim/test_dense_output.py"]
STATUS = ["tests/sim/test_statuses.py", "tests/core/test_switching.py", "tests/sim/test_simulation.py",
          "tests/analysis/numerics/test_stability.py::test_singular_system_error_carries_time_state_reason"]
LUGRE = ["tests/core/test_lugre.py"]
SECTION = ["tests/analysis/stepmap/test_poincare.py", "tests/analysis/stepmap/test_limit_cycle.py", "tests/analysis/stepmap/test_step_maps.py"]
BASIN = ["tests/analysis/basins/test_basin.py", "tests/sim/test_ensemble.py"]
HYBRID = ["tests/analysis/rigid/test_hybrid_options.py", "tests/analysis/rigid/test_hybrid.py"]
STUDY = ["tests/studies/test_study_axes.py", "tests/studies/test_sweep.py"]

D = "pdw/core/csrc/pdw_discrete.c"
CD = "pdw/core/csrc/pdw_cdm.c"
BA = "pdw/core/csrc/pdw_batch.c"
SO = "pdw/core/csrc/pdw_batch_soa.inc"
RO = "pdw/core/csrc/pdw_batch_ros.inc"
OD = "pdw/core/csrc/pdw_ode.c"


@dataclasses.dataclass(frozen=True)
class Mutant:
    id: str
    area: str               # physics | integrator | status | analysis
    edits: tuple            # ((path, old, new), ...): each old occurs exactly once in its file
    tests: tuple
    what: str

    def key(self):
        return json.dumps([self.edits, self.tests], sort_keys=True)


def M(id, area, path, old, new, tests, what):
    return Mutant(id, area, ((path, old, new),), tuple(tests), what)


def MM(id, area, edits, tests, what):
    return Mutant(id, area, tuple(edits), tuple(tests), what)


MUTANTS = [
    # ---- switching rules of Eq. 18 and the scuffing guard (pdw_discrete.c) ------------------
    M("d_liftoff_or", "physics", D, "if (y > 0.0 && vy > 0.0) {", "if (y > 0.0 || vy > 0.0) {",
      SWITCH, "lift-off when above ground OR moving up (Eq. 18a needs both)"),
    M("d_liftoff_vy_sign", "physics", D, "if (y > 0.0 && vy > 0.0) {", "if (y > 0.0 && vy < 0.0) {",
      SWITCH, "lift-off needs the foot moving down"),
    M("d_disarm_flip", "physics", D, "if (ki[PDW_KIN_X_D] <= kj[PDW_KIN_X_D]) d->armed[i] = 0;",
      "if (ki[PDW_KIN_X_D] > kj[PDW_KIN_X_D]) d->armed[i] = 0;", SWITCH,
      "scuffing guard disarms the foot downhill of the other instead of uphill"),
    M("d_arm_below", "physics", D, "else if (y > 0.0) d->armed[i] = 1;",
      "else if (y < 0.0) d->armed[i] = 1;", SWITCH, "armed below the ground instead of above"),
    M("d_td_other_anchor", "physics", D, "d->anchors[i] = ki[PDW_KIN_S];",
      "d->anchors[i] = kj[PDW_KIN_S];", SWITCH + ["tests/core/test_features.py"],
      "touch-down anchors the other foot's rolling coordinate"),
    M("d_td_vin_sign", "physics", D, "d->anchors[PDW_ANCHOR_V_IN1 + i] = -vy;",
      "d->anchors[PDW_ANCHOR_V_IN1 + i] = vy;", SWITCH + ["tests/core/test_contact_laws.py"],
      "approach speed captured with the wrong sign"),
    M("d_init_anchor_swap", "physics", D, "d->anchors[i] = d->flags[i] ? ki[PDW_KIN_S] : 0.0;",
      "d->anchors[i] = d->flags[i] ? 0.0 : ki[PDW_KIN_S];", SWITCH + ["tests/core/test_features.py"],
      "initial anchor of a support foot left at 0"),
    MM("td_no_vy_everywhere", "physics",
       [(D, "if (d->armed[i] && y < 0.0 && vy < 0.0) {", "if (d->armed[i] && y < 0.0) {"),
        (D, "(armed && y < 0.0 && vy < 0.0)", "(armed && y < 0.0)"),
        (SO, "const int td = (!f) & a_new & down & (vy < 0.0);", "const int td = (!f) & a_new & down;"),
        (RO, "down = (y < 0.0) & (vy < 0.0);", "down = (y < 0.0);")],
       SWITCH, "touch-down without Eq. 18b's v_y < 0, in every copy of the rule"),
    MM("liftoff_no_vy_everywhere", "physics",
       [(D, "if (y > 0.0 && vy > 0.0) {", "if (y > 0.0) {"),
        (D, "if (y > 0.0 && vy > 0.0) mask |= 1 << i;", "if (y > 0.0) mask |= 1 << i;"),
        (SO, "const int lift = f & up_ & (vy > 0.0);", "const int lift = f & up_;"),
        (RO, "r |= f & up_ & (vy > 0.0);", "r |= f & up_;")],
       SWITCH, "lift-off without Eq. 18a's v_y > 0, in every copy of the rule"),
    MM("arm_at_equal_everywhere", "physics",
       [(D, "if (ki[PDW_KIN_X_D] <= kj[PDW_KIN_X_D]) d->armed[i] = 0;",
         "if (ki[PDW_KIN_X_D] < kj[PDW_KIN_X_D] - 0.01) d->armed[i] = 0;"),
        (D, "if (ki[PDW_KIN_X_D] <= kj[PDW_KIN_X_D]) armed = 0;",
         "if (ki[PDW_KIN_X_D] < kj[PDW_KIN_X_D] - 0.01) armed = 0;"),
        (SO, "(!(PDW_SOA_KIN(i, X_D) <= PDW_SOA_KIN(j, X_D)))",
         "(!(PDW_SOA_KIN(i, X_D) < PDW_SOA_KIN(j, X_D) - 0.01))"),
        (RO, "(!(PDW_ROS_KIN(i, X_D) <= PDW_ROS_KIN(j, X_D)))",
         "(!(PDW_ROS_KIN(i, X_D) < PDW_ROS_KIN(j, X_D) - 0.01))")],
       SWITCH, "scuffing guard with a 1 cm margin, in every copy"),
    M("sp_liftoff_sign", "integrator", D, "if (y > 0.0 && vy > 0.0) mask |= 1 << i;",
      "if (y > 0.0 && vy < 0.0) mask |= 1 << i;", SWITCH + ODE,
      "switch predicate of the adaptive methods: wrong lift-off sign"),
    # ---- online gait descriptors (pdw_discrete.c) --------------------------------------------
    M("g_L_own_foot", "physics", D, "r[PDW_STEP_L] = x - g->td_x[i];", "r[PDW_STEP_L] = x - g->td_x[j];",
      GAIT, "step length from the swing foot's own previous footprint"),
    M("g_travel_other", "physics", D, "r[PDW_STEP_TRAVEL] = x - g->lo_x[j];",
      "r[PDW_STEP_TRAVEL] = x - g->lo_x[i];", GAIT, "travel from the other foot's lift-off"),
    M("g_P_other", "physics", D, "r[PDW_STEP_P] = t - g->lo_t[j];", "r[PDW_STEP_P] = t - g->lo_t[i];",
      GAIT, "period from the other leg's lift-off"),
    M("g_cycle_own", "physics", D, "r[PDW_STEP_CYCLE] = t - g->prev_td_t;",
      "r[PDW_STEP_CYCLE] = t - g->td_t[j];", GAIT, "cycle from the leg's own previous touch-down"),
    M("g_ds_from_liftoff", "physics", D,
      "r[PDW_STEP_DOUBLE_SUPPORT] = t - r[PDW_STEP_T_TOUCH_DOWN];",
      "r[PDW_STEP_DOUBLE_SUPPORT] = t - r[PDW_STEP_T_LIFT_OFF];", GAIT,
      "double support measured from the lift-off"),
    M("g_ds_leg_flip", "physics", D, "if (g->ds_leg == j && g->n_steps > 0) {",
      "if (g->ds_leg != j && g->n_steps > 0) {", GAIT, "double support closed by the wrong leg"),
    M("g_ds_leg_self", "physics", D, "g->ds_leg = i;", "g->ds_leg = j;", GAIT,
      "double support awaits the swing leg's own lift-off"),
    M("g_periodic_window", "status", D, "for (long j = 2; j <= k; ++j) {",
      "for (long j = 2; j < k; ++j) {", GAIT, "periodic stop compares k - 1 steps"),
    M("g_periodic_k", "status", D,
      "const long k = s->periodic_k < PDW_STEP_RING ? s->periodic_k : PDW_STEP_RING;",
      "const long k = s->periodic_k < PDW_STEP_RING ? s->periodic_k - 1 : PDW_STEP_RING;", GAIT,
      "periodic window one step short"),
    M("g_periodic_abs", "status", D, "if (!(hi - lo <= s->periodic_tol * fabs(ref))) return 0;",
      "if (!(hi - lo <= s->periodic_tol)) return 0;", GAIT,
      "periodic tolerance absolute instead of relative"),
    M("g_stop_steps_late", "status", D, "if (s->stop_steps > 0 && g->n_steps >= s->stop_steps)",
      "if (s->stop_steps > 0 && g->n_steps > s->stop_steps)", GAIT, "stop_steps one step late"),
    # ---- statuses and checks (pdw_discrete.c) ------------------------------------------------
    M("s_feet_depth", "status", D, "if (kin[i*PDW_NKIN + PDW_KIN_Y_D] < -s->fall_depth) {",
      "if (kin[i*PDW_NKIN + PDW_KIN_Y_D] < -2.0 * s->fall_depth) {", STATUS,
      "a foot may sink twice fall_depth"),
    M("s_feet_leg", "status", D, "fail(s, PDW_STATUS_FELL, PDW_REASON_FOOT_DEEP, i, t);",
      "fail(s, PDW_STATUS_FELL, PDW_REASON_FOOT_DEEP, 1 - i, t);", STATUS,
      "the other leg reported as too deep"),
    M("s_speed_skip", "status", D, "for (int i = PDW_NQ; i < PDW_NX; ++i) {",
      "for (int i = PDW_NQ + 1; i < PDW_NX; ++i) {", STATUS, "max_speed ignores the hip's x speed"),
    M("s_hip_diverged", "status", D, "fail(s, PDW_STATUS_FELL, PDW_REASON_HIP_LOW, -1, t);",
      "fail(s, PDW_STATUS_DIVERGED, PDW_REASON_HIP_LOW, -1, t);", STATUS,
      "a low hip is a divergence, not a fall"),
    M("s_stop_status", "status", D,
      "s->status = stop == PDW_STOP_PERIODIC ? PDW_STATUS_PERIODIC : PDW_STATUS_DONE;",
      "s->status = stop == PDW_STOP_STEPS ? PDW_STATUS_PERIODIC : PDW_STATUS_DONE;", STATUS + GAIT,
      "a steps stop reported as periodic"),
    M("s_rec_fn2", "status", D, "o[PDW_REC_F_N2] = c[PDW_NCONTACT + PDW_CONTACT_F_N];",
      "o[PDW_REC_F_N2] = c[PDW_CONTACT_F_N];", CDM + ["tests/sim/test_gait.py"],
      "recorded F_n2 is leg 1's"),
    # ---- the central difference method (pdw_cdm.c, Eqs. 13-17) -------------------------------
    M("c_start_sign", "integrator", CD,
      "s->u_prev[i] = s->x[i] - dt*s->x[PDW_NQ + i] + 0.5*dt*dt*xdot[PDW_NQ + i];",
      "s->u_prev[i] = s->x[i] + dt*s->x[PDW_NQ + i] + 0.5*dt*dt*xdot[PDW_NQ + i];", CDM,
      "U_-1 = U_0 + dt U'_0 + ..."),
    M("c_start_index", "integrator", CD,
      "s->u_prev[i] = s->x[i] - dt*s->x[PDW_NQ + i] + 0.5*dt*dt*xdot[PDW_NQ + i];",
      "s->u_prev[i] = s->x[i] - dt*s->x[PDW_NQ + i] + 0.5*dt*dt*xdot[i];", CDM,
      "start-up takes the velocity as the acceleration"),
    M("c_start_half", "integrator", CD,
      "s->u_prev[i] = s->x[i] - dt*s->x[PDW_NQ + i] + 0.5*dt*dt*xdot[PDW_NQ + i];",
      "s->u_prev[i] = s->x[i] - dt*s->x[PDW_NQ + i] + 0.25*dt*dt*xdot[PDW_NQ + i];", CDM,
      "start-up's dt^2/2 halved"),
    M("c_K_sign", "integrator", CD, "K[i*PDW_NQ + j] = m*idt2 + c*ih;",
      "K[i*PDW_NQ + j] = m*idt2 - c*ih;", CDM, "M/dt^2 - C/2dt on the left"),
    M("c_ku_sign", "integrator", CD, "ku += (m*idt2 - c*ih) * s->u_prev[j];",
      "ku += (m*idt2 + c*ih) * s->u_prev[j];", CDM, "M/dt^2 + C/2dt on U_n-1"),
    M("c_b_two", "integrator", CD, "b[i] = QmG[i] + 2.0*idt2*mu - ku;", "b[i] = QmG[i] + idt2*mu - ku;",
      CDM, "2/dt^2 M U_n halved"),
    M("c_vel_backward", "integrator", CD, "xnew[PDW_NQ + i] = (u[i] - s->u_prev[i]) * ih;",
      "xnew[PDW_NQ + i] = (u[i] - s->x[i]) / dt;", CDM,
      "backward difference instead of Eq. 17's centred velocity"),
    M("c_ih", "integrator", CD, "const double dt = s->dt, idt2 = 1.0/(dt*dt), ih = 0.5/dt;",
      "const double dt = s->dt, idt2 = 1.0/(dt*dt), ih = 1.0/dt;", CDM, "1/(2 dt) doubled"),
    M("c_bristle_sign", "integrator", CD,
      "xnew[PDW_X_Z1 + i] = s->x[PDW_X_Z1 + i] + dt * phi * zd;",
      "xnew[PDW_X_Z1 + i] = s->x[PDW_X_Z1 + i] - dt * phi * zd;", LUGRE,
      "LuGre bristles integrated backwards under cdm"),
    M("c_done_flip", "status", CD, "if (r == 0) s->status = PDW_STATUS_DONE;      /* else",
      "if (r != 0) s->status = PDW_STATUS_DONE;      /* else", CDM + GAIT,
      "cdm's end-of-run status inverted"),
    # ---- the ensemble engine (pdw_batch.c, pdw_batch_soa.inc) --------------------------------
    M("b_scalar_vec_arg", "integrator", BA, "a[W + l] = walker[l] >= 0 ? x[PDW_X_THETA2] : 0.0;",
      "a[W + l] = walker[l] >= 0 ? x[PDW_X_THETA1] : 0.0;", BATCH,
      "scalar-ISA vector path: sin/cos of theta2 taken of theta1 (issue #26's survivor)"),
    M("b_scalar_vec_cos", "integrator", BA, "trig[PDW_TRIG_COS_THETA2] = cs[W + l];",
      "trig[PDW_TRIG_COS_THETA2] = cs[l];", BATCH, "scalar-ISA vector path: cos theta2 of theta1"),
    M("b_libm_trig", "integrator", BA, "const double s1 = sin(a1), c1 = cos(a1), s2 = sin(a2), c2 = cos(a2);",
      "const double s1 = sin(a1), c1 = cos(a1), s2 = sin(a2), c2 = cos(a1);", BATCH,
      "SoA libm trig: cos theta2 of theta1"),
    M("b_soa_time", "integrator", BA, "s->t = s->n * s->dt;", "s->t = (s->n + 1) * s->dt;", BATCH,
      "SoA lane's time one step ahead"),
    M("b_upd", "integrator", BA, "S->upd[l] = s->n > 0;", "S->upd[l] = s->n > 1;", BATCH,
      "SoA lane skips the flag update of its second step"),
    M("b_finish_lo", "integrator", BA, "job->n_lift_off[i] = s->gait.n_lift_off;",
      "job->n_lift_off[i] = s->gait.n_touch_down;", BATCH, "batch lift-off count"),
    M("b_finish_ring", "integrator", BA,
      "const long slot = (s->gait.n_steps - keep + r) % PDW_STEP_RING;",
      "const long slot = (s->gait.n_steps - keep + r + 1) % PDW_STEP_RING;", BATCH,
      "batch gait rows rotated by one"),
    M("so_vec_arg", "integrator", SO,
      "PDW_SOA_FN(vcos)(W, x + PDW_X_THETA2*PDW_SOA, trig + PDW_TRIG_COS_THETA2*PDW_SOA);",
      "PDW_SOA_FN(vcos)(W, x + PDW_X_THETA1*PDW_SOA, trig + PDW_TRIG_COS_THETA2*PDW_SOA);", BATCH,
      "SoA vector path: cos theta2 of theta1"),
    M("so_lift", "integrator", SO, "const int lift = f & up_ & (vy > 0.0);",
      "const int lift = f & up_ & (vy < 0.0);", BATCH, "SoA lift-off mask sign"),
    M("so_depth", "status", SO, "r |= y < -depth[l];", "r |= y < -2.0 * depth[l];", BATCH,
      "SoA misses a foot too deep"),
    M("so_hip", "status", SO, "bad |= u1 < hip[l];", "bad |= u0 < hip[l];", BATCH,
      "SoA hip check on x_o"),
    M("so_vel", "integrator", SO, "const double v0 = (u0 - p0) * ih, v1 = (u1 - p1) * ih;",
      "const double v0 = (u0 - x0) * ih, v1 = (u1 - p1) * ih;", BATCH, "SoA velocity of x_o"),
    # ---- the other integrators (pdw_ode.c, verlet, tableaux, rodas4, linear algebra) ----------
    M("o_err_sqrt", "integrator", OD, "return sqrt(acc / s->nx);", "return sqrt(acc);", ODE,
      "error norm not averaged (tolerance sqrt(8) tighter)"),
    M("o_err_fmin", "integrator", OD,
      "const double sc = s->atol + s->rtol * fmax(fabs(x[i]), fabs(xnew[i]));",
      "const double sc = s->atol + s->rtol * fmin(fabs(x[i]), fabs(xnew[i]));", ODE,
      "error scale from the smaller state"),
    M("o_hermite", "integrator", OD, "+ (th - 1.0)*h*f0[i] + th*h*f1[i]);",
      "+ (th + 1.0)*h*f0[i] + th*h*f1[i]);", ODE, "Hermite extension's f0 weight"),
    M("o_bisect_swap", "integrator", OD, "if (pdw_switch_pending(s, xi, s->work)) tb = tm; else ta = tm;",
      "if (pdw_switch_pending(s, xi, s->work)) ta = tm; else tb = tm;", ODE,
      "event bisection keeps the wrong half"),
    M("o_time_redo", "integrator", OD, "s->t = last ? t_end : s->t + h_acc;",
      "s->t = last ? t_end : s->t + h;", ODE, "time after an event redo advances by the full step"),
    M("o_last_step", "integrator", OD, "if (h >= rem - 1e-12 * fmax(1.0, t_end)) { h = rem; last = 1; }",
      "if (h >= rem - 1e-12 * fmax(1.0, t_end)) { last = 1; }", ODE, "last step overshoots t_end"),
    M("o_fsal", "integrator", OD, "if (T->fsal) pdw_copy_state(s, xnew, xs);",
      "if (!T->fsal) pdw_copy_state(s, xnew, xs);", ODE, "rk4 takes its last stage point"),
    M("o_settle_once", "integrator", OD, "for (int it = 0; it < 3; ++it) {",
      "for (int it = 0; it < 1; ++it) {", ODE, "flags settled once after an adaptive step"),
    M("v_predictor", "integrator", "pdw/core/csrc/pdw_verlet.c",
      "xp[PDW_NQ + i] = vh[i] + 0.5 * h * a[i];", "xp[PDW_NQ + i] = vh[i];", ODE,
      "Verlet's velocity predictor at the half step"),
    M("v_corrector", "integrator", "pdw/core/csrc/pdw_verlet.c",
      "xnew[PDW_NQ + i] = vh[i] + 0.5 * h * a[i];", "xnew[PDW_NQ + i] = vh[i] + h * a[i];", ODE,
      "Verlet's corrector weight"),
    M("t_rk4_b", "integrator", "pdw/core/csrc/pdw_tableaus.c", "{1.0/6.0, 1.0/3.0, 1.0/3.0, 1.0/6.0},",
      "{1.0/6.0, 1.0/3.0, 1.0/6.0, 1.0/3.0},", ODE, "rk4 weights swapped"),
    M("t_dp5_e", "integrator", "pdw/core/csrc/pdw_tableaus.c", "22.0/525.0, -1.0/40.0},",
      "22.0/525.0, 1.0/40.0},", ODE, "dopri5 error estimate's last weight"),
    M("t_rodas_m", "integrator", "pdw/core/csrc/pdw_tableaus.c", "{A51, A52, A53, A54, 1.0, 1.0},",
      "{A51, A52, A53, A54, 1.0, 0.0},", ODE, "rodas4 takes its embedded order-3 solution"),
    M("r_schur_sign", "integrator", "pdw/core/csrc/pdw_rodas4.c",
      "c->S[i * PDW_NQ + j] = -J_B(c->J, i, j) - gh * J_A(c->J, i, j);",
      "c->S[i * PDW_NQ + j] = -J_B(c->J, i, j) + gh * J_A(c->J, i, j);", ODE,
      "rodas4's Schur complement sign"),
    M("r_ih", "integrator", "pdw/core/csrc/pdw_rodas4.c", "const double ih = 1.0 / h;",
      "const double ih = 2.0 / h;", ODE, "rodas4's C/h term doubled"),
    M("l_dblock_u3", "integrator", "pdw/core/csrc/pdw_linalg.h",
      "u[3] = (b[3] - K[12]*u[0] - K[13]*u[1]) * fac[1];",
      "u[3] = (b[3] - K[12]*u[0] - K[13]*u[1]) * fac[0];", CDM + ODE,
      "block solve: theta2's row by theta1's diagonal"),
    M("l_dblock_s10", "integrator", "pdw/core/csrc/pdw_linalg.h",
      "const double s10 = K[4] - K[6]*K[8]*id0 - K[7]*K[12]*id1;",
      "const double s10 = K[4] - K[6]*K[9]*id0 - K[7]*K[12]*id1;", CDM + ODE,
      "block factor: Schur complement index"),
    M("l_lu_pivot", "integrator", "pdw/core/csrc/pdw_lu.h", "if (a > amax) { amax = a; p = i; }",
      "if (a < amax) { amax = a; p = i; }", ODE, "LU picks the smallest pivot"),
    # ---- Python: gait descriptors and statuses (pdw/sim) -------------------------------------
    M("p_steady_window", "physics", "pdw/sim/gait.py", "a = a[np.isfinite(a)][-last:]",
      "a = a[np.isfinite(a)][-last - 1:]", GAIT, "Steps.steady averages one step too many"),
    M("p_ds_leg", "physics", "pdw/sim/gait.py", 'if f.kind == "lift_off" and f.leg == i and np.isnan(ds):',
      'if f.kind == "lift_off" and f.leg == j and np.isnan(ds):', GAIT,
      "offline double support ends at the swing leg's lift-off"),
    M("p_ds_cut", "physics", "pdw/sim/gait.py",
      "if nxt_td is not None and not np.isnan(ds) and ds > nxt_td - e.t:",
      "if nxt_td is not None and not np.isnan(ds) and ds < nxt_td - e.t:", GAIT,
      "offline double support discarded when it is valid"),
    M("p_cycle", "physics", "pdw/sim/gait.py", "cycle=e.t - prev_td_t,", "cycle=e.t - last_lo[j][0],",
      GAIT, "offline cycle from the lift-off"),
    M("p_travel", "physics", "pdw/sim/gait.py", "travel=e.x_D - last_lo[j][1],",
      "travel=e.x_D - last_td[i][1],", GAIT, "offline travel is the step length"),
    M("q_singular_fell", "status", "pdw/sim/simulation.py",
      'public = {"done": "walked", "singular": "diverged"}.get(status, status)',
      'public = {"done": "walked", "singular": "fell"}.get(status, status)', STATUS,
      "a singular system reported as a fall"),
    M("q_nosteps_liftoff", "status", "pdw/sim/simulation.py",
      'if raw["event_counts"]["touch_down"] == 0 and raw["t_final"] >= NO_STEP_PERIODS * period:',
      'if raw["event_counts"]["lift_off"] == 0 and raw["t_final"] >= NO_STEP_PERIODS * period:', STATUS,
      "no_steps judged on lift-offs"),
    M("q_runaway_leg", "status", "pdw/sim/simulation.py",
      "bad = (X[:, 1] > hip_max) | (np.abs(X[:, 2:4]) > RUNAWAY_ANGLE).any(axis=1)",
      "bad = (X[:, 1] > hip_max) | (np.abs(X[:, 2:3]) > RUNAWAY_ANGLE).any(axis=1)", STATUS,
      "runaway check ignores leg 2"),
    M("q_batch_status", "status", "pdw/sim/batch.py", '5: "diverged", 6: "periodic"}',
      '5: "fell", 6: "periodic"}', BATCH + STATUS, "batch: a singular walker is a fall"),
    M("q_honest_batch", "status", "pdw/sim/chunks.py",
      "if b.n_touch_down[i] == 0 and b.t_final[i] >= NO_STEP_PERIODS * period:",
      "if b.n_lift_off[i] == 0 and b.t_final[i] >= NO_STEP_PERIODS * period:", BATCH + STATUS,
      "batch no_steps judged on lift-offs"),
    # ---- Python: Poincare section, basin, Floquet, hybrid options, study axes ----------------
    M("k_interp_side", "analysis", "pdw/analysis/stepmap/poincare.py",
      "x = res.x[i - 1] + s * (x - res.x[i - 1])", "x = x + s * (x - res.x[i - 1])", SECTION,
      "fixed-step section interpolated beyond the crossing (issue #26's survivor)"),
    M("k_interp_frac", "analysis", "pdw/analysis/stepmap/poincare.py", "s = y0 / (y0 - y1)",
      "s = y1 / (y0 - y1)", SECTION, "fixed-step section: wrong fraction"),
    M("k_interp_time", "analysis", "pdw/analysis/stepmap/poincare.py",
      "t = float(res.t[i - 1] + s * (res.t[i] - res.t[i - 1]))",
      "t = float(res.t[i] + s * (res.t[i] - res.t[i - 1]))", SECTION,
      "fixed-step section: period from the wrong sample"),
    M("k_step_length", "analysis", "pdw/analysis/stepmap/poincare.py",
      "step_length=x[0] + (p.l - p.r) * math.sin(x[2]),",
      "step_length=x[0] + (p.l - p.r) * math.sin(x[3]),", SECTION, "step length of the wrong leg"),
    M("e_embed", "analysis", "pdw/analysis/stepmap/section.py",
      "x = np.array([-(p.l - p.r) * math.sin(th2), p.r + (p.l - p.r) * math.cos(th2),",
      "x = np.array([-(p.l - p.r) * math.sin(th1), p.r + (p.l - p.r) * math.cos(th2),", SECTION,
      "section embedding puts the wrong foot at the origin"),
    M("e_relabel", "analysis", "pdw/analysis/stepmap/section.py", "z = x[[3, 2, 4, 5, 7, 6]].copy()",
      "z = x[[3, 2, 5, 4, 7, 6]].copy()", SECTION, "relabelling swaps the hip velocities"),
    M("n_basin_or", "analysis", "pdw/analysis/basins/basin.py",
      "same = (np.abs(L - L0) <= match_tol * abs(L0)) & (np.abs(P - P0) <= match_tol * P0)",
      "same = (np.abs(L - L0) <= match_tol * abs(L0)) | (np.abs(P - P0) <= match_tol * P0)", BASIN,
      "basin cell is the gait when L or P matches (issue #26's survivor)"),
    M("n_basin_undecided", "analysis", "pdw/analysis/basins/basin.py",
      "out = np.where(res.walked, UNDECIDED, FELL)", "out = np.where(res.walked, FELL, UNDECIDED)",
      BASIN, "walking cells counted as fallen"),
    M("f_floquet_order", "analysis", "pdw/analysis/stepmap/limit_cycle.py",
      "return mult[np.argsort(-np.abs(mult))], J", "return mult[np.argsort(np.abs(mult))], J",
      SECTION, "Floquet multipliers in increasing modulus (issue #26: floquet never called)"),
    M("f_jacobian_step", "analysis", "pdw/analysis/stepmap/limit_cycle.py",
      "J = np.column_stack([(val[1 + k] - val[1 + n + k]) / (2 * fd_step) for k in range(n)])",
      "J = np.column_stack([(val[1 + k] - val[1 + n + k]) / fd_step for k in range(n)])", SECTION,
      "central difference without its 2"),
    M("h_opt_hmax", "analysis", "pdw/core/_hybrid.pyx", 'elif k == "h_max": o.h_max = v',
      'elif k == "h_max": o.h0 = v', HYBRID, "hybrid option h_max written into h0 (issue #26)"),
    M("h_opt_angle", "analysis", "pdw/core/_hybrid.pyx",
      'elif k == "min_step_angle": o.min_step_angle = v', 'elif k == "min_step_angle": o.fall_angle = v',
      HYBRID, "hybrid option min_step_angle written into fall_angle"),
    M("h_arm_angle", "physics", "pdw/core/csrc/pdw_hybrid_sim.c",
      "&& y[PDW_HY_THETA_SW] - y[PDW_HY_THETA_ST] >= o->min_step_angle) return 1;",
      "&& y[PDW_HY_THETA_ST] - y[PDW_HY_THETA_SW] >= o->min_step_angle) return 1;", HYBRID,
      "hybrid arming angle measured the wrong way"),
    M("y_log_axis", "analysis", "pdw/studies/study.py",
      'vals = np.geomspace(ax["start"], ax["stop"], ax["num"])',
      'vals = np.linspace(ax["start"], ax["stop"], ax["num"])', STUDY,
      "log study axis spaced linearly (issue #26's survivor)"),
]

#: Mutants argued to change no observable result (id -> the argument).
EQUIVALENT: dict[str, str] = {
    "b_upd": "S->upd marks a lane whose flags the start-up has just updated (n = 0). soa_load "
             "sets it from s->n after a start (n = 0) or after a scalar (rare) step; a rare step "
             "at n = 0 can only be a foot too deep or a failed state check (the flag masks are "
             "off at n = 0), both of which end the walker, so soa_load never sees n = 1 and "
             "`n > 1` gives the same upd as `n > 0` on every path; the ordinary commit sets upd "
             "= 1 itself.",
    "l_dblock_u3": "fac[0] = 1/K[10] and fac[1] = 1/K[15] are the same number for this walker: the "
                   "two legs share m_l, c, w and J_l, so M[2][2] = M[3][3] = m_l (c^2 + w^2) + J_l "
                   "bitwise, and rows 2, 3 of C are zero (docs/model.md section 3), so the cdm "
                   "matrix M/dt^2 + C/2dt has equal diagonal entries there too; Params has no "
                   "per-leg inertia that could tell them apart.",
}

_BUILT = re.compile(r"\.(c|h|inc|pyx|pxi)$")


def _sh(cmd, **kw):
    return subprocess.run(cmd, cwd=ROOT, **kw)


def build(timeout):
    """Rebuild the extensions in place through the object cache; returns (ok, seconds, tail)."""
    env = dict(os.environ)
    env["CC"] = "%s %s gcc" % (sys.executable, ROOT / "benchmarks" / "mutation_cc.py")
    env.setdefault("PDW_MUTATION_CACHE", str(ROOT / "build" / "mutation-cc"))
    t0 = time.perf_counter()
    try:
        p = _sh(["nice", "-n", "15", sys.executable, "setup.py", "-q", "build_ext", "--inplace"],
                env=env, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return False, time.perf_counter() - t0, "build timed out"
    return p.returncode == 0, time.perf_counter() - t0, (p.stdout + p.stderr)[-2000:]


def run_tests(tests, timeout):
    """(outcome, seconds, detail): killed when a test fails, errors or times out."""
    present = [t for t in tests if (ROOT / t.split("::")[0]).exists()]
    cmd = ["nice", "-n", "15", "timeout", str(timeout), sys.executable, "-m", "pytest", "-x", "-q",
           "-p", "no:cacheprovider", "--no-header", "-W", "ignore"] + present
    # no .pyc of a mutated module (a same-size mutant restored within the same second could
    # otherwise leave a stale one behind)
    env = dict(os.environ, PYTHONDONTWRITEBYTECODE="1")
    t0 = time.perf_counter()
    p = _sh(cmd, capture_output=True, text=True, env=env)
    dt = time.perf_counter() - t0
    out = p.stdout + p.stderr
    if p.returncode == 0:
        return "survived", dt, ""
    if p.returncode == 124:
        return "killed", dt, "timeout after %d s" % timeout
    if p.returncode == 5:
        return "error", dt, "no tests collected"
    failed = re.findall(r"^(?:FAILED|ERROR) (\S+)", out, re.M)
    return "killed", dt, failed[0] if failed else out.strip().splitlines()[-1][-200:]


def apply(m):
    """Apply mutant m; returns {path: original text}. Raises if an edit does not match once."""
    originals = {}
    for path, old, new in m.edits:
        f = ROOT / path
        text = originals.get(path) or f.read_text()
        originals.setdefault(path, text)
        cur = f.read_text()
        if cur.count(old) != 1:
            raise ValueError("mutant %s: %r occurs %d times in %s" % (m.id, old, cur.count(old), path))
        f.write_text(cur.replace(old, new))
    return originals


def restore(originals):
    for path, text in originals.items():
        (ROOT / path).write_text(text)


def clean_tree(paths):
    """Is every mutated file as committed (git diff empty)?"""
    p = _sh(["git", "diff", "--quiet", "--"] + sorted(paths))
    return p.returncode == 0


def summarize(results):
    """Per area and in all: killed, survived (not argued equivalent), equivalent; ``kill_rate``
    = killed / all mutants run, ``kill_rate_non_equivalent`` = killed / (killed + survived)."""
    out = {}
    for r in results.values():
        if r["outcome"] not in ("killed", "survived"):
            continue
        a = out.setdefault(r["area"], {"killed": 0, "survived": 0, "equivalent": 0})
        if r["outcome"] == "survived" and r["id"] in EQUIVALENT:
            a["equivalent"] += 1
        else:
            a[r["outcome"]] += 1
    tot = {k: sum(a[k] for a in out.values()) for k in ("killed", "survived", "equivalent")}
    out["all"] = tot
    core = [out[k] for k in ("physics", "integrator", "status") if k in out]
    out["physics+integrator+status"] = {k: sum(a[k] for a in core)
                                        for k in ("killed", "survived", "equivalent")}
    for a in out.values():
        n = a["killed"] + a["survived"]
        a["kill_rate"] = round(a["killed"] / (n + a["equivalent"]), 4) if n else None
        a["kill_rate_non_equivalent"] = round(a["killed"] / n, 4) if n else None
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--only", default="", help="comma-separated mutant ids")
    ap.add_argument("--area", default="", help="physics, integrator, status or analysis")
    ap.add_argument("--timeout", type=int, default=400, help="per mutant's tests [s]")
    ap.add_argument("--out", default=str(OUT))
    ap.add_argument("--resume", action="store_true", help="skip mutants already in --out")
    ap.add_argument("--list", action="store_true")
    ap.add_argument("--label", default="", help="a note stored with the results")
    a = ap.parse_args(argv)
    chosen = [m for m in MUTANTS if (not a.only or m.id in a.only.split(","))
              and (not a.area or m.area == a.area)]
    ids = [m.id for m in MUTANTS]
    assert len(ids) == len(set(ids)), "duplicate mutant ids"
    if a.list:
        for m in chosen:
            print("%-24s %-10s %s" % (m.id, m.area, m.what))
        print(len(chosen), "mutants")
        return 0
    # SIGTERM (and SIGINT, even where a background shell ignores it) end the campaign through
    # the finally blocks: the source is restored and rebuilt
    for sig in (signal.SIGTERM, signal.SIGINT):
        signal.signal(sig, lambda signum, frame: sys.exit(128 + signum))
    out = pathlib.Path(a.out)
    data = {"mutants": {}}
    if out.exists() and (a.resume or a.only):
        data = json.loads(out.read_text())
    results = data["mutants"]
    touched = {p for m in MUTANTS for p, _, _ in m.edits}
    stale = [(m.id, p) for m in MUTANTS for p, old, _ in m.edits
             if (ROOT / p).read_text().count(old) != 1]
    if stale:
        print("stale mutants (their text does not occur exactly once): %s" % stale, file=sys.stderr)
        return 2
    if not clean_tree(touched):
        print("refusing to start: the files the mutants edit have uncommitted changes", file=sys.stderr)
        return 2
    ok, dt, tail = build(1800)             # the object cache's baseline (and a sane start)
    if not ok:
        print("the unmutated tree does not build:\n" + tail, file=sys.stderr)
        return 2
    print("baseline build %.1f s" % dt, flush=True)
    t_start = time.time()
    stale_build = False        # the compiled extensions are a mutant's (its source restored)
    try:
        for k, m in enumerate(chosen):
            if a.resume and m.id in results and results[m.id].get("key") == m.key():
                continue
            rec = {"id": m.id, "area": m.area, "what": m.what, "key": m.key(),
                   "files": sorted({p for p, _, _ in m.edits}), "tests": list(m.tests)}
            compiled = any(_BUILT.search(p) for p, _, _ in m.edits)
            if stale_build and not compiled:
                # a Python mutant needs the unmutated extensions (a compiled mutant's own build
                # rebuilds the restored units from the cache anyway)
                ok, rec["rebuild_s"], tail = build(900)
                if not ok:
                    raise RuntimeError("the restored tree does not build:\n" + tail)
                stale_build = False
            originals = {}
            try:
                originals = apply(m)
                if compiled:
                    stale_build = True
                    ok, rec["build_s"], tail = build(900)
                    if not ok:
                        rec.update(outcome="build_error", detail=tail[-500:])
                if "outcome" not in rec:
                    rec["outcome"], rec["test_s"], rec["detail"] = run_tests(m.tests, a.timeout)
            finally:
                restore(originals)
            if m.id in EQUIVALENT:
                rec["equivalent"] = EQUIVALENT[m.id]
            results[m.id] = rec
            print("[%d/%d] %-24s %-11s %6.1f s  %s" % (k + 1, len(chosen), m.id, rec["outcome"],
                                                     rec.get("test_s", 0.0) + rec.get("build_s", 0.0),
                                                     rec.get("detail", "")), flush=True)
            data.update(summary=summarize(results), label=a.label,
                        driver="benchmarks/mutation.py", equivalent=EQUIVALENT)
            out.parent.mkdir(parents=True, exist_ok=True)
            out.write_text(json.dumps(data, indent=1, sort_keys=True) + "\n")
    finally:
        clean = clean_tree(touched)
        if not clean:
            print("ERROR: mutated files differ from git after the campaign", file=sys.stderr)
        elif stale_build:
            ok, _, tail = build(1800)          # the extensions of the restored source
            if not ok:
                print("ERROR: the restored tree does not build:\n" + tail, file=sys.stderr)
    if not clean:
        return 3
    print("campaign %.0f s; %s" % (time.time() - t_start, json.dumps(summarize(results))))
    return 0


if __name__ == "__main__":
    sys.exit(main())
