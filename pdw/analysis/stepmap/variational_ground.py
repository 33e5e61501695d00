"""The exact derivative of the continuous walker's touch-down map with respect to the ground
heights under its feet (issue #22 item 5: the compliant model's gait sensitivity norm from
the exact linearization, docs/robustness.md).

The disturbance of the gait sensitivity norm is a floor-height change: in the section's frame
(leg 2 has just touched down at s = 0, flags (1, 1); `pdw.analysis.stepmap.section`) the
ground under leg 2 stays at 0, the ground under leg 1 is

* h_trail [m] while leg 1 is the trailing support foot (from the section to its lift-off;
  the previous step's floor change, seen from the stance foot: -e_prev), and
* h_land [m] where it touches down (the section of the next step: this step's floor change e),

each a constant height perpendicular to the mean slope (a step edge far from both feet's
contact regions: `Ground.steps([-edge, edge], [e_prev, e], offset=-e_prev)`, the edges halfway
between the footprints, as the finite-difference map of
`pdw.analysis.robust.robustness_continuous` builds it). Leg 1 changes from the one height to
the other during its swing, where it carries no force and no height event is watched (an
unarmed swing foot waits for its arming, docs/model.md section 5).

The state is augmented by the constant parameters p = (h_trail, h_land), p' = 0, and the
variational equations of `pdw.analysis.stepmap.variational.step_jacobian` (its Python engine)
carry their columns:

* df/dh_trail while leg 1 is support: on a level ground at height h a foot's contact forces
  are its flat-ground forces at the gap y_o - r - (l - r) cos(theta) - h (docs/model.md
  section 11 with h' = 0: normal n = e_y, penetration along it; the paper variant's tangential
  deformation xi = (l - r) sin(theta) (Eq. 8) and the normal and slip rates do not involve h),
  and M(q), the gravity and hip terms do not involve y_o (the hip's coordinate perpendicular
  to the slope). So f = f_free(x) + f_1(x - h_trail e_y) + f_2(x), and
  df/dh_trail = -df_1/dy_o = -(column y_o of the Jacobian with leg 1's flag alone on, minus the
  one with both off): the compiled symbolic Jacobian (`pdw.ode_function(...).jac`), exact.
  df/dh_land = 0: leg 1 touches down on h_land only at the section.
* the height events of leg 1 (g_1 = y_o - r - (l - r) cos(theta_1) - h): its lift-off, rise
  and re-entry (Eq. 18a, on h_trail) and its touch-down, the section (Eq. 18b, on h_land)
  have dg_1/dh = -1 in their gradients, so the saltation matrices and the section's projection
  carry the parameter columns (`_Field.height_grad`). The rate events (v_1, Eq. 5), the arming
  and Eq. 11's gates do not involve h.

The result: dz'/dp (nz, 2), dT/dp and dL/dp besides dz'/dz, from one integration (about a
second of CPU, the Python engine: the compiled engine, pdw/core/csrc/pdw_cvar.c, integrates
the state without parameters). Scope: the paper variant, the laws with Coulomb friction (as
`step_jacobian`); the step edges must stay clear of the feet's contact regions (true for the
gait sensitivity norm's infinitesimal disturbance: the edges are at +-L/2).
"""
from __future__ import annotations

import math

import numpy as np

from . import section as _section
from .variational import N, _Field, step_jacobian

#: the parameters' names, in the augmented state's order after x (and v_in)
PARAMETERS = ("h_trail", "h_land")


class GroundField(_Field):
    """f and df/dy of y = (x, [v_in1, v_in2,] h_trail, h_land), the heights constant
    (module docstring)."""

    def __init__(self, f, na, params):
        super().__init__(f, na, params)
        self.m = N + na                  # the state without the parameters
        self.n_par = len(PARAMETERS)
        self.n = self.m + self.n_par

    def __call__(self, t, y):
        out = np.zeros(self.n)
        out[:self.m] = super().__call__(t, y[:self.m])
        return out

    def jac(self, t, y):
        A = np.zeros((self.n, self.n))
        A[:self.m, :self.m] = super().jac(t, y[:self.m])[:self.m, :self.m]
        if self.flags[0]:               # leg 1 support: its forces on the ground h_trail
            A[:N, self.m] = -self.foot_y_column(t, y, 0)
        return A

    def foot_y_column(self, t, y, leg):
        """d(f)/d(y_o) (8,) of leg's contact forces alone: the symbolic Jacobian's y_o column
        with leg's flag alone on minus the one with both flags off (the flags restored)."""
        x = np.ascontiguousarray(y[:N])
        cols = []
        for on in (1, 0):
            self._discrete([on if i == leg else 0 for i in (0, 1)], y)
            cols.append(self.f.jac(t, x)[:, 1])
        self._discrete(self.flags, y)
        return cols[0] - cols[1]

    def _discrete(self, flags, y):
        if self.na:
            self.f.set_discrete(flags[0], flags[1], 0.0, 0.0, (float(y[N]), float(y[N + 1])))
        else:
            self.f.set_discrete(flags[0], flags[1], 0.0, 0.0)

    def height_grad(self, leg):
        """d g_leg / d(h_trail, h_land): -1 on leg 1's current ground (h_trail while it is
        support, h_land once it swings: its touch-down is the section); leg 2's ground is 0."""
        out = np.zeros(self.n_par)
        if leg == 0:
            out[0 if self.flags[0] else 1] = -1.0
        return out


def ground_step_jacobian(z, params=None, *, contact=None, rtol: float = 1e-10,
                         atol: float = 1e-12, phi_rtol: float | None = None,
                         t_max: float = 2.5, max_events: int = 40) -> dict:
    """One step of the touch-down map from section point z and its exact derivatives in z and
    in the ground heights (h_trail, h_land) (module docstring), at h_trail = h_land = 0.

    Parameters
    ----------
    z : array_like (nz,)
        Section point (`pdw.analysis.stepmap.section.section_names` of ``contact``).
    params : Params
        Default `Params.paper_steady()`.
    contact : pdw.Contact, dict or str, optional
        As `pdw.analysis.stepmap.variational.step_jacobian` (Coulomb friction).
    rtol, atol, phi_rtol, t_max, max_events
        As `step_jacobian` (``engine="python"``: Radau for x, LSODA for (x, Phi)).

    Returns
    -------
    dict
        ``z`` (z' (nz,)), ``M`` (nz, nz) dz'/dz, ``B`` (nz, 2) dz'/d(h_trail, h_land) [1/m
        for the angles' rows, ...], ``T`` (touch-down to touch-down [s]) and ``dT``
        (nz + 2,) [s per unit of z, s/m], ``L`` (the step length [m]: leg 1's contact point
        at its touch-down, leg 2's at s = 0, as `pdw.analysis.stepmap.poincare.step`) and
        ``dL`` (nz + 2,), ``events`` (as `step_jacobian`).
    """
    p = _section._params(params)
    out = step_jacobian(z, p, contact=contact, rtol=rtol, atol=atol, phi_rtol=phi_rtol,
                        t_max=t_max, max_events=max_events, engine="python",
                        field=GroundField)
    nz = len(out["z"])
    x, dx = out["x"], out["dx_dz"][:N]
    L = x[0] + (p.l - p.r) * math.sin(x[2])
    dL = dx[0] + (p.l - p.r) * math.cos(x[2]) * dx[2]
    return {"z": out["z"], "M": out["M"][:, :nz], "B": out["M"][:, nz:], "T": out["T"],
            "dT": out["dT"], "L": L, "dL": dL, "events": out["events"]}
