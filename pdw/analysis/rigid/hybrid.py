"""The hybrid (impact-momentum) walker of docs/model.md section 9, for comparison with the compliant one.

Rigid ground; the stance foot rolls without slip (its material contact point has zero
velocity), so the stance phase is a 2-DOF system in the reduced state

    y = [theta_st, theta_sw, thetad_st, thetad_sw]      (`STATE`; rad, rad/s)

derived from the same Lagrangian as the full model (derive/hybrid.py, generated/pdw_hybrid.c).
The hip follows from the stance angle: x_o = s0 - (l - r) sin(theta_st) - r theta_st,
y_o = r + (l - r) cos(theta_st), s0 the stance foot's rolling coordinate.

A *step* (`step_map`, compiled, GIL released): integrate the stance (Dormand-Prince 5(4), error
control rtol/atol) until heel strike -- the armed swing foot reaching the ground moving down,
located by regula falsi to ``event_tol`` -- then the inelastic impact
M (qd+ - qd-) = J_sw^T Lambda, J_sw qd+ = 0 (a 6x6 KKT system), then relabel the legs
(the old swing leg becomes the stance leg). The swing foot is armed as in docs/model.md section 5
(above the ground while downhill of the stance foot), which ignores mid-stance scuffing.

Poincaré section: just after heel strike, after relabelling. On it theta_sw = -theta_st (both
feet on the ground), so it is 3-dimensional, with coordinates z = (theta_st, thetad_st,
thetad_sw); `find_gait` solves P(z) = z by Newton's method and reports the 3 Floquet
multipliers of the 3x3 Jacobian (the 4x4 Jacobian in y has a 4th, trivial, multiplier 0).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...core import _hybrid, _layout, checks  # type: ignore[attr-defined]  # compiled, no stub
from ...core.errors import (
    FellError,
    InvalidInputError,
    SimulationError,
    SingularSystemError,
)
from ...core.model import parameter_vector
from ...core.params import Params
from ..gait_types import Gait, GaitNotFoundError

STATE = ("theta_st", "theta_sw", "thetad_st", "thetad_sw")
#: Options of the compiled step map and their defaults (see pdw/core/csrc/pdw_hybrid_sim.h).
DEFAULT_OPTIONS = dict(_hybrid.default_options())

_SECTION = (0, 2, 3)     # section coordinates z = y[[0, 2, 3]], with y[1] = -y[0]


def compass_gait_params(**overrides) -> Params:
    """The classic compass gait of Goswami, Thuilot & Espiau (1998): point feet, l = 1 m,
    point-mass legs of 5 kg at 0.5 m from the hip, hip mass 10 kg, slope 3 deg, no hip
    spring or damper, g = 9.81."""
    base = dict(l=1.0, c=0.5, w=0.0, r=0.0, J_l=0.0, m_h=10.0, m_l=5.0, k_hip=0.0, d_hip=0.0,
                gamma=np.deg2rad(3.0), g=9.81)
    return Params(**{**base, **overrides})


def _p(params):
    return parameter_vector(params)


def _state(y, name="state"):
    return np.ascontiguousarray(checks.real_array(name, y, [(4,)], labels=STATE))


#: Allowed ranges of the step map's options (lo, hi; both closed unless noted in _OPEN).
_OPTION_RANGES = {"rtol": (0.0, 1.0), "atol": (0.0, None), "h0": (0.0, None),
                  "h_max": (0.0, None), "t_max": (0.0, None), "event_tol": (0.0, None),
                  "min_step_angle": (0.0, np.pi), "fall_angle": (0.0, np.pi),
                  "dt_out": (0.0, None), "dh": (None, None), "max_slope": (0.0, None)}
_OPEN = {"rtol", "atol", "h0", "h_max", "t_max", "event_tol", "fall_angle", "max_slope"}


def _options(options):
    unknown = set(options) - set(DEFAULT_OPTIONS)
    if unknown:
        raise InvalidInputError("unknown hybrid option(s) %s; allowed: %s"
                                % (", ".join(sorted(unknown)), ", ".join(DEFAULT_OPTIONS)))
    out = {}
    for k, v in options.items():
        if k == "max_steps":
            out[k] = checks.count("max_steps", v, lo=1, hi=10 ** 9)
        else:
            lo, hi = _OPTION_RANGES[k]
            out[k] = checks.number(k, v, lo=lo, hi=hi, lo_open=k in _OPEN)
    return out


def ground_ref(ground):
    """The compiled hook of a `pdw.Ground` for the hybrid loop, or None for a flat ground (any
    offset and patches: the rigid ground has no contact parameters, and only height
    differences matter), which runs the flat code path bitwise. docs/hybrid.md, "On a shaped
    ground": the stance foot rolls on a level parallel to the mean slope at the height of its
    touch-down point, and the heel strike is when the swing foot reaches the ground under it.
    A tilted plane is refused (it is the walker on another slope: change ``gamma``)."""
    if ground is None:
        return None
    from ...core.ground import Ground

    g = Ground.coerce(ground)
    if g.kind == "flat":
        return None
    kinds = [q.kind for q in g.parts] if g.kind == "sum" else [g.kind]
    if "plane" in kinds:
        raise InvalidInputError("ground: the hybrid model takes no tilted plane (its stance foot "
                                "rolls on levels parallel to the mean slope); use "
                                "Params(gamma=gamma + slope) instead")
    return _hybrid.GroundRef(g.table())


# --- the reduced model, pointwise ------------------------------------------------------------

def stance_rhs(y, params=None) -> np.ndarray:
    """dy/dt of the stance phase (rigid ground, stance foot rolling without slip)."""
    return _hybrid.rhs(_p(params), _state(y))


def stance_terms(y, params=None):
    """(M_r, f_r): the reduced mass matrix (2, 2) and force (2,) of M_r phidd = f_r."""
    return _hybrid.stance_terms(_p(params), _state(y))


def ground_force(y, params=None) -> np.ndarray:
    """Ground reaction (F_x, F_y) on the stance foot's material point [N] at y (stance phase)."""
    p = _p(params)
    y = _state(y)
    return _hybrid.ground_force(p, y, np.ascontiguousarray(_hybrid.rhs(p, y)[2:]))


def energies(y, params=None) -> dict:
    """T, V_gravity, V_hip and E [J] at y (V_gravity with the stance rolling coordinate 0)."""
    e = _hybrid.energies(_p(params), _state(y))
    return {"T": e[0], "V_gravity": e[1], "V_hip": e[2], "E": float(e.sum())}


def swing_foot(y, params=None) -> dict:
    """Swing foot height y_sw and normal rate vy_sw, contact points x_sw, x_st [m] (s0 = 0)."""
    f = _hybrid.swing_foot(_p(params), _state(y))
    return dict(zip(("y_sw", "vy_sw", "x_sw", "x_st"), f))


def full_state(y, params=None, s0=0.0, stance_leg=1) -> np.ndarray:
    """Full-model state(s) [x_o, y_o, theta1, theta2, ...] (docs/model.md section 2) of reduced
    state(s) y, shape (4,) or (N, 4); ``s0`` the stance foot's rolling coordinate, and
    ``stance_leg`` (1 or 2, scalar or per row) which leg is in stance."""
    Y = np.ascontiguousarray(np.atleast_2d(checks.real_array("y", y, [(4,), (-1, 4)])))
    X = np.empty((len(Y), len(_layout.STATE)))
    _hybrid.full_state_batch(_p(params), Y, X)
    X[:, 0] += np.broadcast_to(np.asarray(s0, dtype=float), (len(Y),))
    swap = np.broadcast_to(np.asarray(stance_leg), (len(Y),)) == 2
    X[swap] = X[swap][:, [0, 1, 3, 2, 4, 5, 7, 6]]
    return X[0] if np.ndim(y) == 1 else X


def impact(y_minus, params=None) -> dict:
    """The impact map at a pre-impact state (both feet on the ground).

    Returns a dict: ``y_plus`` (relabelled), ``qd_minus`` / ``qd_plus`` (full-model velocities,
    old stance leg as leg 1), ``impulse`` (Lambda_x, Lambda_y) on the new stance foot [N s],
    ``v_old`` (the old stance foot's material-point velocity after impact; v_old[1] > 0: it
    leaves upward), ``old_foot_down``, ``T_minus``, ``T_plus`` [J].
    """
    return _hybrid.impact(_p(params), _state(y_minus, "y_minus"))


# --- the step map ----------------------------------------------------------------------------

def step(state, params=None, *, ground=None, s0=0.0, **options) -> dict:
    """One step from ``state`` (just after a heel strike, or any stance state): the details.

    ``ground`` (a `pdw.Ground`, default flat) is the ground under the walker and ``s0`` the
    stance foot's rolling coordinate on it [m] (its contact point is s0 - r theta_st); the
    option ``dh`` [m] adds a floor offset under the swing foot for this step (a step down:
    dh < 0). Never raises on a failed step: ``status`` says what happened ("ok", "fell",
    "no_strike", "tripped", "off_ground", ...). Other keys: ``t_strike`` (stance duration
    [s]), ``y_minus``, ``y_plus``, ``h_st``, ``h_touch`` (ground heights under the stance foot
    and the new footprint [m]),
    ``step_length`` (footprint spacing [m]), ``T_minus``, ``T_plus``, ``impulse``, ``v_old``,
    ``old_foot_down``, ``E0`` and ``dE_max`` (largest drift of T + V during the stance [J]),
    ``Fn_min`` (smallest normal ground force [N]), ``ratio_max`` (largest |F_t/F_n|), work
    counters. Options: see `DEFAULT_OPTIONS`.
    """
    g = ground_ref(ground)
    res, _, _ = _hybrid.step(_p(params), _state(state), _options(options), 0.0,
                             checks.number("s0", s0), 0, g)
    return res


def step_map(state, params=None, **options) -> np.ndarray:
    """P(state): the state just after the next heel strike (relabelled), shape (4,).

    Raises `FellError`, `SingularSystemError` or `SimulationError` when the step fails.
    """
    res = step(state, params, **options)
    _raise_for(res, params)
    return res["y_plus"]


def _raise_for(res, params=None):
    """Raise the error of a failed step, carrying the step's start as a full-model state (8,)."""
    st = res["status"]
    if st == "ok":
        return
    msg = "hybrid step failed: %s after %.4g s (state at start %r)" % (st, res["t_strike"],
                                                                         res["y0"])
    cls = {"fell": FellError, "singular": SingularSystemError}.get(st, SimulationError)
    raise cls(msg, t=res["t_strike"], x=full_state(res["y0"], params), reason=st)


def _y_of(z):
    z = np.asarray(z, dtype=float)
    return np.stack([z[..., 0], -z[..., 0], z[..., 1], z[..., 2]], axis=-1)


def _section_map(p, Z, opts):
    """P on the section for each row of Z (N, 3); NaN rows where the step failed."""
    Y = np.ascontiguousarray(_y_of(Z))
    out = np.empty_like(Y)
    status = np.empty(len(Y), dtype=np.intc)
    _hybrid.step_batch(p, Y, opts, out, status)
    out[status != 0] = np.nan
    return out[:, _SECTION]


def _jacobian(p, z, h, opts):
    """Central-difference Jacobian of the section map at z, and P(z)."""
    E = np.eye(3) * h
    Z = np.vstack([z[None, :], z + E, z - E])
    P = _section_map(p, Z, opts)
    return (P[1:4] - P[4:7]).T / (2 * h), P[0]


def floquet(state, params=None, fd_step=1e-6, exact=False, **options):
    """(multipliers, jacobian) of the step map on the section at ``state`` (on the section).

    The 3x3 Jacobian in z = (theta_st, thetad_st, thetad_sw) is taken by central differences
    with step ``fd_step`` in each coordinate, or with ``exact=True`` from `step_jacobian`;
    multipliers sorted by decreasing modulus.
    """
    opts = {**_TIGHT, **_options(options)}
    if exact:
        _, DP = step_jacobian(state, params, **options)
        J = DP[list(_SECTION)] @ _SECTION_EMBED
    else:
        J, _ = _jacobian(_p(params), _state(state)[list(_SECTION)], fd_step, opts)
    mult = np.linalg.eigvals(J)
    return mult[np.argsort(-np.abs(mult))], J


#: d y / d z of the section's embedding y = (z0, -z0, z1, z2)
_SECTION_EMBED = np.array([[1.0, 0, 0], [-1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0]])


def step_jacobian(state, params=None, **options):
    """(P(state), DP): one step and its exact Jacobian d y+ / d y0 (4, 4).

    DP = D_Delta S Phi(T) (docs/continuation.md): the variational equations of the symbolic
    stance Jacobian integrated to the heel strike with the step map's own Dormand-Prince 5(4)
    and tolerances (default rtol = atol = 1e-12 here), the saltation matrix S of the strike
    event and the derivative of the impact map, all from derive/hybrid.py. Raises like
    `step_map` when the step fails.
    """
    res, DP = _hybrid.step_jac(_p(params), _state(state), {**_TIGHT, **_options(options)})
    _raise_for(res, params)
    return res["y_plus"], DP


_TIGHT = dict(rtol=1e-12, atol=1e-12)


def default_guesses(params):
    """Starting guesses on the section: half inter-leg angles 0.15-0.45 rad, stance rates
    scaled with sqrt(g/l), swing rates a fraction of the stance rate."""
    w0 = np.sqrt(params.g / params.l)
    out = []
    for a in (0.25, 0.35, 0.15, 0.45):
        for k in (1.3, 1.0, 1.8):
            for ratio in (0.35, 0.0, 1.0):
                out.append(np.array([a, -a, -k * a * w0, -ratio * k * a * w0]))
    return out


def find_gait(params=None, guess=None, *, tol=1e-10, max_iter=30, fd_step=1e-6, settle_steps=30,
              **options) -> Gait:
    """The period-one gait of the hybrid walker: Newton shooting on the step map.

    Parameters
    ----------
    params : Params
        Default `Params.paper_steady()`.
    guess : array_like (4,), optional
        A state on (or near) the section, `STATE` layout. Default: `default_guesses`, tried in
        turn. Each guess is first walked for up to ``settle_steps`` steps (a stable gait
        attracts it); Newton starts from where the walk got to (or from the guess itself
        when the walker fell at once). An integer in [0, `MAX_STEPS`].
    tol : float
        Newton converges when max |P(z) - z| < tol (> 0).
    max_iter : int
        Newton iterations per start, in [1, 10**6].
    fd_step : float
        Step of the central differences of the Jacobian (Newton and multipliers; > 0).
    options
        Step-map options (`DEFAULT_OPTIONS`); default rtol = atol = 1e-12 here.

    Returns
    -------
    Gait
        ``state`` just after heel strike (relabelled), ``period``, ``step_length``,
        ``double_support`` = 0, ``multipliers`` (3, the section's), ``details``.

    Raises
    ------
    GaitNotFoundError
        No guess converged (``attempts`` says what happened to each).
    pdw.InvalidInputError
        A count or tolerance out of its range (the message names it).
    """
    params = Params.paper_steady() if params is None else params
    settle_steps = checks.count("settle_steps", settle_steps, lo=0, hi=MAX_STEPS)
    max_iter = checks.count("max_iter", max_iter, lo=1, hi=10 ** 6)
    tol = checks.positive("tol", tol)
    fd_step = checks.positive("fd_step", fd_step)
    opts = {**_TIGHT, **_options(options)}
    p = _p(params)
    guesses = [_state(guess, "guess")] if guess is not None else default_guesses(params)
    attempts = []
    for g in guesses:
        starts = []
        if settle_steps > 0:
            res, *_ = _hybrid.walk(p, g, 0.0, settle_steps, opts, 0)
            last_ok = [r for r in res if r["status"] == "ok"]
            if last_ok:
                starts.append(last_ok[-1]["y_plus"])
        starts.append(g)
        for y0 in starts:
            z, info = _newton(p, y0[list(_SECTION)], tol, max_iter, fd_step, opts)
            attempts.append({"guess": g, "start": y0, **info})
            if z is not None:
                return _gait(params, p, z, fd_step, opts, info)
    raise GaitNotFoundError("no hybrid gait found from %d starting guess(es); last: %s"
                            % (len(guesses), attempts[-1]["reason"] if attempts else "-"),
                            attempts)


def _newton(p, z, tol, max_iter, h, opts):
    z = np.array(z, dtype=float)
    r = None
    for it in range(max_iter):
        J, Pz = _jacobian(p, z, h, opts)
        if not np.isfinite(Pz).all():
            return None, {"reason": "step failed at Newton iterate %d" % it, "iterations": it}
        r = Pz - z
        if np.max(np.abs(r)) < tol:
            return z, {"reason": "converged", "iterations": it, "residual": float(np.max(np.abs(r)))}
        A = J - np.eye(3)
        if not np.isfinite(A).all():
            return None, {"reason": "Jacobian not finite at iterate %d" % it, "iterations": it}
        try:
            dz = np.linalg.solve(A, -r)
        except np.linalg.LinAlgError:
            return None, {"reason": "singular Newton matrix", "iterations": it}
        # damped: halve the step until the residual decreases (or give up halving)
        lam, n0 = 1.0, np.max(np.abs(r))
        for _ in range(8):
            zt = z + lam * dz
            Pt = _section_map(p, zt[None, :], opts)[0]
            if np.isfinite(Pt).all() and np.max(np.abs(Pt - zt)) < n0:
                break
            lam *= 0.5
        z = z + lam * dz
    return None, {"reason": "no convergence in %d iterations (residual %.3g)"
                  % (max_iter, np.nan if r is None else np.max(np.abs(r))),
                  "iterations": max_iter}


def _gait(params, p, z, h, opts, info):
    y = _y_of(z)
    res, _, _ = _hybrid.step(p, np.ascontiguousarray(y), opts)
    J, _ = _jacobian(p, z, h, opts)
    mult = np.linalg.eigvals(J)
    mult = mult[np.argsort(-np.abs(mult))]
    details = {
        "section": "just after heel strike, relabelled; z = (theta_st, thetad_st, thetad_sw), "
                   "theta_sw = -theta_st",
        "jacobian": J, "fd_step": h, "options": dict(opts),
        "newton_iterations": info["iterations"], "residual": info["residual"],
        "y_minus": res["y_minus"],
        "energy_loss": res["T_minus"] - res["T_plus"], "T_minus": res["T_minus"],
        "T_plus": res["T_plus"], "impulse": res["impulse"], "v_old": res["v_old"],
        "old_foot_down": res["old_foot_down"], "vy_strike": res["vy_strike"],
        "stance_energy_drift": res["dE_max"], "Fn_min": res["Fn_min"],
        "friction_needed": res["ratio_max"],
    }
    # the swing foot's own travel: from its lift-off point (at the start, behind the stance
    # foot) to its touch-down point
    x_sw0 = _hybrid.swing_foot(p, np.ascontiguousarray(y))[2]
    details["swing_travel"] = res["x_touch"] - x_sw0
    return Gait(state=y, period=res["t_strike"], step_length=res["step_length"],
                double_support=0.0, multipliers=mult, model="hybrid", params=params,
                details=details)


# --- trajectories ----------------------------------------------------------------------------

@dataclass
class HybridTrajectory:
    """Outcome of `simulate_hybrid`.

    Attributes
    ----------
    t : ndarray (N,)
        Sample times [s]; the heel-strike instants appear twice (before and after impact).
    y : ndarray (N, 4)
        Reduced states, `STATE` (stance / swing leg of that sample's step).
    x : ndarray (N, 8)
        Full-model states in the slope frame, the model's legs 1 and 2 (docs/model.md section 2).
    stance_leg : ndarray (N,)
        1 or 2: the leg in stance at each sample.
    step : ndarray (N,)
        Index of the step each sample belongs to.
    steps : list of dict
        Per step: the details of `step` (``t0``, ``t_strike``, ``step_length``, impact ...).
    status : str
        "ok" when every step was completed, else the failing step's status.
    """

    t: np.ndarray
    y: np.ndarray
    x: np.ndarray
    stance_leg: np.ndarray
    step: np.ndarray
    steps: list = field(default_factory=list)
    status: str = "ok"

    @property
    def strike_times(self) -> np.ndarray:
        """Absolute times of the heel strikes [s]."""
        return np.array([s["t0"] + s["t_strike"] for s in self.steps if s["status"] == "ok"])

    @property
    def footprints(self) -> np.ndarray:
        """Contact points of the feet at their touch-downs along the slope [m]."""
        return np.array([s["x_touch"] for s in self.steps if s["status"] == "ok"])


#: Most steps one walk takes (`simulate_hybrid`'s n_steps, `find_gait`'s settle_steps): the
#: step results alone take about 0.5 kB a step.
MAX_STEPS = 10 ** 7
#: Largest record `simulate_hybrid` allocates [bytes] (48 bytes a sample).
MAX_RECORD_BYTES = 4e9


def simulate_hybrid(params=None, state0=None, n_steps=10, *, dt_out=0.002, stance_leg=2,
                    s0=0.0, ground=None, **options) -> HybridTrajectory:
    """Walk ``n_steps`` steps of the hybrid model from ``state0`` (reduced, `STATE`).

    ``state0`` defaults to the gait of `find_gait`. ``stance_leg`` is the full model's leg
    in stance at the start (2: as at the paper's initial condition, docs/model.md section 5), ``s0``
    its rolling coordinate. ``ground``: a `pdw.Ground` (default flat; see `ground_ref`).
    Samples every ``dt_out`` seconds (0: every integrator step),
    plus each step's start and its pre-impact state. Does not raise when the walker falls:
    ``status`` and ``steps`` say what happened. Ctrl-C stops the walk within a second
    (`KeyboardInterrupt`, the partial trajectory as ``.result``, status "interrupted").
    """
    params = Params.paper_steady() if params is None else params
    if stance_leg not in (1, 2):
        raise InvalidInputError("stance_leg must be 1 or 2, got %r" % (stance_leg,))
    n_steps = checks.count("n_steps", n_steps, lo=1, hi=MAX_STEPS)
    s0 = checks.number("s0", s0)
    opts = _options({**options, "dt_out": dt_out})
    dt_out = opts["dt_out"]
    p = _p(params)
    y0 = find_gait(params).state if state0 is None else _state(state0, "state0")
    t_max = opts.get("t_max", DEFAULT_OPTIONS["t_max"])
    per_step = int(t_max / dt_out) + 4 if dt_out > 0 else int(opts.get("max_steps", 10000)) + 4
    cap = int(n_steps) * min(per_step, 20000)
    if cap > 10 ** 6:       # a large record: walk unrecorded first (cheap) to size it
        cap = 0
    g = ground_ref(ground)
    res, t, y, k = _walk(p, y0, float(s0), int(n_steps), opts, cap, params, stance_leg, g)
    if cap == 0 or any(r["rec_full"] for r in res):
        # size the record from the steps the walk took and walk again (the steps are
        # deterministic: the second walk is the first one, recorded whole)
        need = sum((int(r["t_strike"] / dt_out) + 4) if dt_out > 0 else r["n_steps"] + 4
                   for r in res) + 16
        if need * 48 > MAX_RECORD_BYTES:
            raise InvalidInputError(
                "simulate_hybrid: recording %d steps at dt_out = %g needs %d samples (%.3g GB, "
                "more than %.3g GB): use a larger dt_out" % (n_steps, dt_out, need,
                                                             need * 48 / 1e9, MAX_RECORD_BYTES / 1e9))
        res, t, y, k = _walk(p, y0, float(s0), int(n_steps), opts, need, params, stance_leg, g)
        if any(r["rec_full"] for r in res):      # cannot happen; never report it as ok
            raise SimulationError("simulate_hybrid: the record of %d samples was still too small"
                                  % need)
    return _trajectory(params, res, t, y, k, stance_leg, n_steps)


def _walk(p, y0, s0, n_steps, opts, cap, params, stance_leg, ground=None):
    """_hybrid.walk; on Ctrl-C the KeyboardInterrupt carries the partial trajectory
    (``.result``, status "interrupted")."""
    try:
        return _hybrid.walk(p, y0, s0, n_steps, opts, cap, ground)
    except KeyboardInterrupt as e:
        if getattr(e, "partial", None) is not None:
            e.result = _trajectory(params, *e.partial, stance_leg, n_steps)
        raise


def _trajectory(params, res, t, y, k, stance_leg, n_steps):
    legs = np.where(k % 2 == 0, stance_leg, 3 - stance_leg)
    s0s = np.array([r["s0"] for r in res])
    x = full_state(y, params, s0=s0s[k], stance_leg=legs) if len(y) else np.empty((0, 8))
    h_st = np.array([r.get("h_st", 0.0) for r in res])
    if len(y) and h_st.any():
        x[:, 1] += h_st[k]          # the stance foot's level on a shaped ground
    status = "ok" if all(r["status"] == "ok" for r in res) and len(res) == n_steps \
        else res[-1]["status"] if res else "interrupted"
    return HybridTrajectory(t=t, y=y, x=x, stance_leg=legs, step=k, steps=res, status=status)
