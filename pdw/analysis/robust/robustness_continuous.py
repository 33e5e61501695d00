"""The robustness measures for the continuous (compliant) model (docs/robustness.md, "The
compliant model"): the step or the rough ground is a `pdw.Ground` under `pdw.simulate`.

* The gait: `pdw.find_gait` (the touch-down section; leg 2 has just touched down at s = 0,
  flags (1, 1)). A walk starts there with ``flags0=(1, 1)``; its steps are `pdw.steps` of the
  run (``L`` footprint spacing, ``cycle`` touch-down to touch-down).
* A step of height H: ``Ground.step(edge, -H or +H)`` with the edge halfway between the stance
  foot (s = 0) and the gait's next footprint (s = L), smoothed over ``edge_width``.
* The trials of a `max_step` round are the walkers of one `pdw.simulate_batch` (each walker
  its own step ground; bitwise its `pdw.simulate` run), and so are the walkers of a chunk of
  `first_passage` (each its own random ground). The batch keeps each walker's last
  `STEP_RING` steps (`BatchResult.steps`), which is what "returned" looks at.
* The gait sensitivity norm: the touch-down map's exact Jacobian in the section coordinates
  and in the floor heights (`pdw.analysis.stepmap.variational_ground`: variational equations
  with the two ground heights as parameters), cross-checked by central differences; or
  (``method="fd"``) central differences at two steps (h and h/2); a warning when the two
  norms differ by more than ``rel_check``. The state is augmented by the previous step's floor
  height: during the double support the trailing foot still stands on it, so on compliant
  ground a disturbance acts on two steps (tested against the summed response of a walk).
"""
from __future__ import annotations

import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...core.errors import InvalidInputError
from ...core.ground import Ground
from ...sim.batch import simulate_batch
from ...sim.gait import steps as _steps
from ...sim.options import Integrator, Limits
from ...sim.simulation import simulate
from ..stepmap import limit_cycle as _lc
from . import robustness_core as _rb

#: integrator tolerances of the walks (rodas4)
WALK = dict(method="rodas4", rtol=1e-8, atol=1e-10)
#: the options of a walk that are fields of `pdw.Integrator` (the rest go to simulate as given)
_INTEGRATOR = ("method", "rtol", "atol", "h_max", "event_tol", "max_steps", "check_step")


def _run_kw(options):
    """WALK updated by ``options``, its integrator settings as one `pdw.Integrator`."""
    kw = {**WALK, **options}
    it = {k: kw.pop(k) for k in _INTEGRATOR if k in kw}
    return dict(kw, integrator=Integrator(**it))


def continuous_gait(params, gait=None):
    """The continuous model's period-one gait (`pdw.find_gait`), checked."""
    if gait is None:
        return _lc.find_gait(params)
    if getattr(gait, "model", None) != "continuous":
        raise InvalidInputError("gait must be a continuous pdw.Gait (pdw.find_gait), got %r"
                                % (gait,))
    return gait


def batch(params, gait, grounds, n_steps, *, threads=2, executor=None, **options):
    """`pdw.simulate_batch` of len(grounds) walkers from the gait's touch-down state, walker i
    on grounds[i], for ``n_steps`` gait periods and a half (as `walk`)."""
    n = len(grounds)
    x0 = np.repeat(np.asarray(gait.state, dtype=float)[None, :], n, axis=0)
    kw = _run_kw(options)
    return simulate_batch(x0, t_end=(n_steps + 1.5) * gait.period, params=params,
                          flags0=(1, 1), threads=threads, executor=executor, ground=list(grounds),
                          **kw)


def walk(params, gait, ground, n_steps, **options):
    """Walk ``n_steps`` steps from the gait's touch-down state on ``ground``: (status, L (k,),
    T (k,)), the step lengths [m] and touch-down-to-touch-down times [s] of the complete steps
    (the first is the step from the gait's state)."""
    t_end = (n_steps + 1.5) * gait.period
    kw = _run_kw(options)
    res = simulate(np.asarray(gait.state, dtype=float), t_end=t_end, params=params,
                   flags0=(1, 1), limits=Limits(on_failure="return"), ground=ground, **kw)
    st = _steps(res)
    L = np.asarray(st["L"], dtype=float)
    T = np.asarray(st["cycle"], dtype=float)
    # pdw.steps skips the run's first step (its stance foot's touch-down, at t = 0, is not an
    # event of the run): it is the first touch-down, its footprint measured from the stance
    # foot's contact point at s = 0 (the section's frame)
    td = next((e for e in res.events if e.kind == "touch_down"), None)
    if td is not None and (len(T) == 0 or td.t < st["t_touch_down"][0] - 0.5 * gait.period):
        L = np.concatenate([[td.x_D], L])
        T = np.concatenate([[td.t], T])
    return res.status, L, T


def edge_at(gait):
    """The step edge's position [m]: halfway from the stance foot (s = 0) to the next
    footprint."""
    return 0.5 * gait.step_length


@dataclass
class _Trials:
    gait: Any
    fn: Any

    def __call__(self, heights):
        return self.fn(heights)


def step_trials_fn(params, *, direction, budget, return_tol, gait=None, executor=None,
                   ground=None, threads=2, edge_width=0.01, **options):
    """The trial function of `max_step` for the continuous model: heights -> trial dicts."""
    if ground is not None:
        raise InvalidInputError("max_step(model='continuous') builds its own step ground; "
                                "ground must be None")
    gait = continuous_gait(params, gait)
    sign = -1.0 if direction == "down" else 1.0
    edge = edge_at(gait)

    def run(heights):
        hs = [float(h) for h in heights]
        b = batch(params, gait, [Ground.step(edge, sign * h, width=edge_width) for h in hs],
                  budget + 1, threads=threads, executor=executor, **options)
        out = []
        for i, h in enumerate(hs):
            n = int(b.n_touch_down[i])          # steps taken (each ends in a touch-down)
            surv = b.status[i] in ("walked", "periodic") and n >= budget
            ret, k = False, -1
            if surv:
                st = b.steps(i)                 # the last STEP_RING complete steps
                ret, k = _rb.returned(st["L"], st["cycle"], gait.step_length, gait.period,
                                      return_tol)
                k = k + n - len(st) if ret else -1
            out.append(dict(height=h, survived=bool(surv), returned=bool(ret),
                            steps_to_return=int(k), status=str(b.status[i])))
        return out

    return _Trials(gait=gait, fn=run)


def _section_step(z, params, ground, **options):
    """One touch-down map step from section point z on ``ground`` (`pdw.analysis.stepmap.poincare.step`,
    its tight tolerances): (z', touch-down-to-touch-down time [s], step length [m])."""
    from ..stepmap.poincare import step

    out = step(z, params, ground=ground, **options)
    if out["status"] != "ok":
        raise InvalidInputError("gait_sensitivity (continuous): a finite-difference step "
                                "failed (%s)" % out["status"])
    return out["z"], out["period"], out["step_length"]


def _indicator_rows(names, T, dT, L, dL):
    """The indicators' derivative rows from those of the step time T and length L."""
    rows = {"step_time": dT, "step_length": dL, "speed": (dL * T - L * dT) / T ** 2}
    return np.array([rows[n] for n in names])


def _jacobian_fd(params, z0, names, edge, h, options):
    """The map's Jacobian by central differences of step h: rows z' (nz) and the indicators,
    columns z (nz), e_prev, e (the previous step's and this step's floor change [m])."""
    def F(z, e_prev, e):
        g = None
        if e_prev != 0.0 or e != 0.0:       # trailing foot's ground, the stance's, the landing's
            g = Ground.steps([-edge, edge], [e_prev, e], width=0.01, offset=-e_prev)
        zn, T, L = _section_step(z, params, g, **options)
        v = {"step_time": T, "step_length": L, "speed": L / T}
        return np.concatenate([zn, [v[n] for n in names]])

    nz = len(z0)
    cols = []
    for j in range(nz + 2):
        dz = np.zeros(nz)
        if j < nz:
            dz[j] = h
            a, b = F(z0 + dz, 0.0, 0.0), F(z0 - dz, 0.0, 0.0)
        elif j == nz:
            a, b = F(z0, h, 0.0), F(z0, -h, 0.0)
        else:
            a, b = F(z0, 0.0, h), F(z0, 0.0, -h)
        cols.append((a - b) / (2 * h))
    return np.array(cols).T


def _jacobian_exact(params, z0, names, options, tol=None):
    """The map's Jacobian as `_jacobian_fd`'s from the variational equations with the ground
    heights as parameters (`pdw.analysis.stepmap.variational_ground`; ``tol``: its rtol, atol,
    phi_rtol): h_trail = -e_prev, h_land = e."""
    from ...core.contact import Contact
    from ..stepmap.variational_ground import ground_step_jacobian

    variant = options.get("variant", "paper")
    law = Contact.coerce(options.get("contact"))
    if variant != "paper" or law.friction != "coulomb":
        raise InvalidInputError("gait_sensitivity(model='continuous', method='exact') needs "
                                "variant='paper' and Coulomb friction (got variant=%r, "
                                "friction=%r): use method='fd'" % (variant, law.friction))
    J = ground_step_jacobian(z0, params, contact=options.get("contact"), **(tol or {}))
    nz = len(z0)
    sign = np.concatenate([np.ones(nz), [-1.0, 1.0]])       # d/de_prev = -d/dh_trail
    top = np.hstack([J["M"], J["B"]]) * sign
    rows = _indicator_rows(names, J["T"], J["dT"] * sign, J["L"], J["dL"] * sign)
    return np.vstack([top, rows])


def _system(J, nz):
    """The augmented linear system (A, B, C, D) in x = (z, e_prev) from the map's Jacobian J
    (rows z', indicators; columns z, e_prev, e): the disturbance of the previous step stays
    under the trailing foot during the double support, so it enters the next step too (a
    compliant-ground effect the hybrid model does not have)."""
    A = np.zeros((nz + 1, nz + 1))
    A[:nz, :nz + 1] = J[:nz, :nz + 1]
    B = np.zeros((nz + 1, 1))
    B[:nz, 0] = J[:nz, nz + 1]
    B[nz, 0] = 1.0                       # e becomes the next step's e_prev
    return A, B, J[nz:, :nz + 1], J[nz:, nz + 1:]


#: the largest relative difference of the exact and the finite-difference norms that passes
#: quietly (measured at paper_steady: 8.2e-5 at fd_step 1e-6, 1.1e-5 at 1e-5, the differences'
#: noise; docs/robustness.md)
REL_CHECK = 1e-3


def gait_sensitivity(params, names, *, gait=None, method="exact", check=True, fd_step=1e-6,
                     rel_check=REL_CHECK, **options):
    """The gait sensitivity norm of the continuous model (step time, step length and speed
    indicators): ``method="exact"`` from the variational equations with the ground heights as
    parameters, cross-checked (``check``) by central differences of step ``fd_step``;
    ``method="fd"`` by central differences, cross-checked (``check``) at h/2. A warning
    when the two norms differ by more than ``rel_check`` (relative)."""
    for n in names:
        if n not in ("step_time", "step_length", "speed"):
            raise InvalidInputError("gait_sensitivity(model='continuous') takes the indicators "
                                    "step_time, step_length, speed; got %r" % n)
    if method not in ("exact", "fd"):
        raise InvalidInputError("method must be 'exact' or 'fd', got %r" % (method,))
    gait = continuous_gait(params, gait)
    z0 = np.asarray(gait.details["z"], dtype=float)
    nz = len(z0)
    edge = edge_at(gait)
    if method == "exact":
        A, B, C, D = _system(_jacobian_exact(params, z0, names, options), nz)
    else:
        A, B, C, D = _system(_jacobian_fd(params, z0, names, edge, fd_step, options), nz)
    norm = _rb.h2_norm(A, B, C, D)
    chk = {}
    if check:
        h2 = fd_step if method == "exact" else 0.5 * fd_step
        norm2 = _rb.h2_norm(*_system(_jacobian_fd(params, z0, names, edge, h2, options), nz))
        rel = abs(norm - norm2) / max(abs(norm), 1e-300)
        chk = {"fd_norm" if method == "exact" else "fd_norm_half_step": norm2,
               "rel_diff": rel, "fd_step": h2}
        if rel > rel_check:
            what = ("the exact norm and the finite-difference one (step %g)" % h2
                    if method == "exact" else "the finite-difference norms at steps %g and %g"
                    % (fd_step, h2))
            warnings.warn("gait_sensitivity (continuous): %s differ by %.2g (relative): the "
                          "linearization is not resolved (or the map has a kink within the "
                          "step)" % (what, rel), stacklevel=3)
    per = {n: _rb.h2_norm(A, B, C[i:i + 1], D[i:i + 1]) for i, n in enumerate(names)}
    return _rb.GaitSensitivity(norm=norm, per_indicator=per, indicators=tuple(names), A=A, B=B,
                               C=C, D=D, method=method, check=chk, gait=gait)


def walker_ground(ground, seed, i, max_steps, step_length):
    """Walker i's own random ground: ``ground`` with seed ``seed + i``, defined from -2 m to
    1.25 (max_steps + 4) step lengths (a walker still walking when it leaves the extent is
    censored there, never extrapolated)."""
    spec = dict(ground.spec)
    ext = (-2.0, 1.25 * (max_steps + 4) * step_length)
    return Ground.random(spec["sigma"], spec["correlation"], seed=int(seed) + int(i),
                         modes=spec["modes"], offset=ground.offset, extent=ext)


def chunk(params, gait, ground, seed, lo, hi, max_steps, options):
    """Walkers lo..hi-1 of the continuous model on their own random grounds: (steps, failed,
    status), as `pdw.analysis.robust.first_passage._hybrid_chunk` (module level: executors take it).
    One `pdw.simulate_batch` (a ground per walker). A walker's first-passage time counts its
    steps (touch-downs) plus the failing one; one that walks ``max_steps`` steps, or leaves its
    ground's extent, is censored at its steps."""
    grounds = [walker_ground(ground, seed, i, max_steps, gait.step_length) for i in range(lo, hi)]
    b = batch(params, gait, grounds, max_steps, threads=1, **options)
    return outcomes(b, max_steps)


def outcomes(b, max_steps):
    """The first-passage data (steps (N,), failed (N,), status (N,)) of a batch of walkers
    (`batch`): see `chunk`."""
    n = np.asarray(b.n_touch_down, dtype=np.int64)      # steps taken
    # a walker that fell after max_steps steps (the run goes on for a period and a half) was
    # still walking at max_steps: censored there, not a failure
    fell = ~np.isin(b.status, ("walked", "periodic", "off_ground")) & (n < max_steps)
    steps = np.where(fell, n + 1, np.minimum(n, max_steps))
    return steps, fell, np.where(fell, b.status, "ok")
