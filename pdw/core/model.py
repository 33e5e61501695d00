"""Evaluate the compiled model: right-hand side, Jacobian, mass matrix, contact forces, energies.

Every function accepts one state, shape (8,), or a batch, shape (N, 8), laid out as
`pdw.STATE` = [x_o, y_o, theta1, theta2, xd_o, yd_o, thetad1, thetad2] (paper Eq. 1;
metres, radians, and their rates), and returns arrays of matching leading shape.
"""
from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Iterable

import numpy as np
from numpy.typing import ArrayLike

from . import _core, _layout, checks
from .errors import InvalidInputError
from .params import Params

STATE = _layout.STATE
VARIANTS = _layout.VARIANTS
_KERNELS = {name: i for i, (name, _, _) in enumerate(_core.kernel_table())}
_IX = {n: i for i, n in enumerate(STATE)}


def kernel_index(variant: str = "paper", features=None, normal: str = "hunt_crossley",
                 friction: str = "coulomb") -> int:
    """Index of the generated kernel (`_kernel_index`; looked up once per combination)."""
    try:
        return _kernel_index_cached(variant, features, normal, friction)
    except TypeError:                   # unhashable features (a list): not cached
        return _kernel_index(variant, features, normal, friction)


@functools.lru_cache(maxsize=256)
def _kernel_index_cached(variant, features, normal, friction):
    return _kernel_index(variant, features, normal, friction)


def _kernel_index(variant: str = "paper", features=None, normal: str = "hunt_crossley",
                  friction: str = "coulomb") -> int:
    """Index of the generated kernel for ``variant`` with the given force elements, normal
    contact law (`pdw.core._layout.NORMAL_LAWS`) and friction law (`FRICTION_LAWS`).

    ``features=None`` means every element (``pdw.core._layout.FEATURES``). A combination without
    a specialized kernel falls back to the general one (of its normal law).
    """
    check_variant(variant)
    if friction != "coulomb":
        if friction not in _layout.FRICTION_LAWS or normal not in _layout.NORMAL_LAWS:
            raise ValueError("no kernel for normal law %r with friction law %r" % (normal, friction))
        law = "" if normal == "hunt_crossley" else "_" + normal
        return _KERNELS[variant + law + "_" + friction]
    if normal != "hunt_crossley":
        if normal not in _layout.NORMAL_LAWS:
            raise ValueError("normal law must be one of %s, got %r"
                             % (", ".join(_layout.NORMAL_LAWS), normal))
        return _KERNELS[variant + "_" + normal]
    feats = _layout.FEATURES if features is None else tuple(features)
    unknown = set(feats) - set(_layout.FEATURES)
    if unknown:
        raise InvalidInputError("unknown feature(s) %s; allowed: %s"
                                % (", ".join(sorted(unknown)), ", ".join(_layout.FEATURES)))
    name = variant + "".join("_no_" + f for f in _layout.FEATURES if f not in feats)
    return _KERNELS.get(name, _KERNELS[variant])


def check_variant(variant):
    if not isinstance(variant, str) or variant not in VARIANTS:
        raise InvalidInputError("variant must be one of %s, got %r" % (", ".join(map(repr, VARIANTS)), variant))


def parameter_vector(params: Params | None) -> np.ndarray:
    """Kernel parameter vector: `Params.as_array` plus derived constants, shape (NP,)."""
    params = Params.paper() if params is None else params
    if not isinstance(params, Params):
        raise InvalidInputError("params must be a pdw.Params, got %s" % type(params).__name__)
    return _parameter_vector(params).copy()


@functools.lru_cache(maxsize=256)
def _parameter_vector(params: Params) -> np.ndarray:
    """`parameter_vector`, computed once per Params (callers get a copy)."""
    p = np.zeros(_core.NP)
    _core.precompute(params.as_array(), p)
    p.flags.writeable = False
    return p


def _states(x, name="x", width=_core.NX):
    arr = checks.real_array(name, x, [(width,), (-1, width)],
                            labels=STATE if width == _core.NX else None)
    return np.ascontiguousarray(np.atleast_2d(arr)), arr.ndim == 1


def _discrete(flags, anchors, n):
    """Flags (n, 2) and anchors (n, 2) (s0 only) or (n, NANCHOR) (``pdw.core._layout.ANCHORS``:
    s0 and the approach speeds)."""
    f = checks.flags("flags", flags, n)
    f = np.ascontiguousarray(np.broadcast_to(np.asarray(f, dtype=np.intc), (n, 2)))
    na = len(_layout.ANCHORS)
    a = checks.real_array("anchors", anchors, [(2,), (n, 2), (na,), (n, na)])
    return f, np.ascontiguousarray(np.broadcast_to(a, (n, a.shape[-1])))


def _folded(params, features):
    """Parameters with absent force elements zeroed: a specialized kernel, or the general
    kernel's fallback, then computes exactly the requested forces."""
    params = Params.paper() if params is None else params
    return params if features is None else params.without(features)


def _evaluate(x, params, flags, anchors, variant, features=None, contact=None):
    if contact is not None and features is not None:
        contact = contact.for_features(checks.features(features, _layout.FEATURES))
    X, single = _states(x, width=_core.NX if contact is None else contact.nx)
    f, a = _discrete(flags, anchors, len(X))
    if contact is None or contact.is_default:
        k = kernel_index(variant, features)
        p = parameter_vector(_folded(params, features))
    else:                                       # another normal law, or LuGre friction
        params = contact.parameters(_folded(params, features))
        k = kernel_index(variant, features, contact.normal, contact.friction)
        p = contact.vector(parameter_vector(params), features, params)
    xdot = np.empty_like(X)
    work = np.empty((len(X), _core.NWORK))
    _core.rhs_batch(k, X, p, f, a, xdot, work)
    return X, single, k, p, f, a, xdot, work


_FLAGS0, _ANCHORS0 = (0, 1), (0.0, 0.0)     # rhs's defaults (its fast path tests identity)


def rhs(x: ArrayLike, params: Params | None = None, flags: ArrayLike = _FLAGS0,
        anchors: ArrayLike = _ANCHORS0, variant: str = "paper",
        features: Iterable[str] | None = None) -> np.ndarray:
    """Right-hand side f(x) = [qd; M^-1 (Q_f - C qd - G)] of Eq. A.4.

    Every argument is checked (`pdw.InvalidInputError` naming it). One finite, C-contiguous
    float64 state with default ``features`` takes a compiled fast path (its cost per call is
    in docs/benchmarks.md); for many calls with fixed arguments use `pdw.ode_function`.

    Parameters
    ----------
    x : array_like, shape (8,) or (N, 8)
        State [q, qd] [m, rad, m/s, rad/s].
    params : Params, optional
        Default `Params.paper()`.
    flags : (int, int) or array_like (N, 2)
        Support flags of legs 1 and 2 (1 support, 0 swing; docs/model.md section 5).
    anchors : (float, float) or array_like (N, 2)
        Rolling coordinate s_i at the last touch-down of each foot [m]; only the
        ``consistent`` variant's tangential deformation uses them.
    variant : {"paper", "consistent"}
        docs/model.md section 6.
    features : iterable of str, optional
        Force elements present (``pdw.core._layout.FEATURES``; default all).

    Returns
    -------
    ndarray, shape (8,) or (N, 8)
        dx/dt [m/s, rad/s, m/s^2, rad/s^2], a fresh array.
    """
    if features is None:
        # fast path: one finite, C-contiguous float64 state, checked in compiled code; the
        # default arguments skip even the cache lookup
        if params is None and flags is _FLAGS0 and anchors is _ANCHORS0 and variant == "paper":
            fn = _DEFAULT_RHS
        else:
            try:
                fn = _rhs_function(params, variant, flags, anchors)  # type: ignore[arg-type]
            except TypeError:   # unhashable arguments (a list of flags): the general path
                fn = None
        if fn is not None:
            out = fn.checked(x)
            if out is not None:
                return out
    X, single, *_, xdot, _ = _evaluate(x, params, flags, anchors, variant, features)
    return xdot[0] if single else xdot


@functools.lru_cache(maxsize=64)
def _rhs_function(params, variant, flags, anchors):
    """`rhs`'s fast path for one state: a validated `_core.OdeFunction` per (hashable)
    argument set, built once (the checks of the general path run the first time)."""
    if params is not None and not isinstance(params, Params):
        return None
    check_variant(variant)
    f, a = _discrete(flags, anchors, 1)
    return _core.OdeFunction(kernel_index(variant), parameter_vector(params),
                             int(f[0, 0]), int(f[0, 1]), float(a[0, 0]), float(a[0, 1]))


_DEFAULT_RHS = _rhs_function(None, "paper", _FLAGS0, _ANCHORS0)


def jacobian(x: ArrayLike, params: Params | None = None, flags: ArrayLike = (0, 1),
             anchors: ArrayLike = (0.0, 0.0), variant: str = "paper",
             features: Iterable[str] | None = None) -> np.ndarray:
    """Jacobian df/dx of `rhs` (Eq. A.4), from the symbolic derivation.

    At the switching surfaces of the force laws (clamp, friction branches, Eq. 11's gate)
    it is the derivative of the branch that is active at x.

    Parameters
    ----------
    x : array_like, shape (8,) or (N, 8)
        State [q, qd] [m, rad, m/s, rad/s].
    params : Params, optional
        Default `Params.paper()`.
    flags : (int, int) or array_like (N, 2)
        Support flags of legs 1 and 2 (1 support, 0 swing; docs/model.md section 5).
    anchors : (float, float) or array_like (N, 2)
        Rolling coordinate s_i at the last touch-down of each foot [m]; only the
        ``consistent`` variant's tangential deformation uses them.
    variant : {"paper", "consistent"}
        docs/model.md section 6.
    features : iterable of str, optional
        Force elements present (``pdw.core._layout.FEATURES``; default all).

    Returns
    -------
    ndarray, shape (8, 8) or (N, 8, 8)
        ``J[i, j] = d f_i / d x_j`` (units of f_i over units of x_j).
    """
    X, single = _states(x)
    k = kernel_index(variant, features)
    f, a = _discrete(flags, anchors, len(X))
    J = np.empty((len(X), _core.NX * _core.NX))
    work = np.empty((len(X), _core.NWORK))
    _core.jacobian_batch(k, X, parameter_vector(_folded(params, features)), f, a, J, work)
    J = J.reshape(len(X), _core.NX, _core.NX)
    return J[0] if single else J


def mass_matrix(q: ArrayLike, params: Params | None = None) -> np.ndarray:
    """Mass matrix M(q) of Eq. 2 (docs/model.md section 3).

    Parameters
    ----------
    q : array_like, shape (4,), (N, 4), (8,) or (N, 8)
        A configuration [x_o, y_o, theta1, theta2] [m, rad] or a full state (its velocities
        are ignored).
    params : Params, optional
        Default `Params.paper()`.

    Returns
    -------
    ndarray, shape (4, 4) or (N, 4, 4)
        Symmetric positive definite [kg, kg m, kg m^2 by block].
    """
    Q = checks.real_array("q", q, [(_core.NQ,), (-1, _core.NQ), (_core.NX,), (-1, _core.NX)])
    if Q.shape[-1] == _core.NQ:
        Q = np.concatenate([Q, np.zeros_like(Q)], axis=-1)
    *_, work = _evaluate(Q, params, (0, 0), (0.0, 0.0), "paper")
    M = work[:, _layout.WORK["M"][0]:_layout.WORK["M"][0] + 16].reshape(-1, 4, 4)
    return M[0] if np.ndim(q) == 1 else M


@dataclass(frozen=True)
class ContactState:
    """Contact kinematics and forces of both feet; each field has shape (..., 2) (foot 1, foot 2).

    x_D, y_D : contact point along / normal to the slope [m] (Eq. 4); depth = -y_D.
    v_x : slip velocity of the foot's material point [m/s] (Eq. 9).
    v_y : normal rate of the variant [m/s] (Eq. 5).
    s : rolling coordinate [m]; xi : tangential deformation of the variant [m].
    F_n, F_t : normal (+Y) and tangential (+X) contact forces [N]; mu : friction coefficient.
    """

    x_D: np.ndarray
    y_D: np.ndarray
    v_x: np.ndarray
    v_y: np.ndarray
    s: np.ndarray
    xi: np.ndarray
    F_n: np.ndarray
    F_t: np.ndarray
    mu: np.ndarray


def contact_forces(x: ArrayLike, params: Params | None = None, flags: ArrayLike = (0, 1),
                   anchors: ArrayLike = (0.0, 0.0), variant: str = "paper",
                   features: Iterable[str] | None = None, contact=None) -> ContactState:
    """Contact kinematics (Eqs. 4-9) and forces (Eqs. 3, 6, 7, 10, 11) of both feet.

    Forces act only on a support foot (flag 1) that penetrates (y_D < 0); otherwise 0.

    Parameters
    ----------
    x : array_like, shape (nx,) or (N, nx)
        State [q, qd] [m, rad, m/s, rad/s]: nx = 8, or ``contact.nx`` (10 with LuGre friction:
        then the bristle states z1, z2 [m] after it).
    params : Params, optional
        Default `Params.paper()`.
    flags : (int, int) or array_like (N, 2)
        Support flags of legs 1 and 2 (1 support, 0 swing; docs/model.md section 5).
    anchors : (float, float) or array_like (N, 2), or (4,) or (N, 4)
        Rolling coordinate s_i at the last touch-down of each foot [m]; only the
        ``consistent`` variant's tangential deformation uses them. Four columns: then the
        approach speeds v_in1, v_in2 [m/s] (``pdw.core._layout.ANCHORS``).
    variant : {"paper", "consistent"}
        docs/model.md section 6.
    features : iterable of str, optional
        Force elements present (``pdw.core._layout.FEATURES``; default all).
    contact : pdw.Contact, optional
        Another normal law, or LuGre friction (its kernel, its state width); default the
        paper's. With ``features`` without ``friction``, LuGre's run contact
        (`pdw.Contact.for_features`: no bristles).

    Returns
    -------
    ContactState
        Each field of shape (2,) for one state, (N, 2) for N (foot 1, foot 2).
    """
    X, single, *_, work = _evaluate(x, params, flags, anchors, variant, features, contact)
    k0, nk = _layout.WORK["kin"]
    c0, nc = _layout.WORK["contact"]
    kin = work[:, k0:k0 + nk].reshape(-1, 2, len(_layout.KIN))
    con = work[:, c0:c0 + nc].reshape(-1, 2, len(_layout.CONTACT))
    out = {}
    for i, name in enumerate(_layout.KIN):
        out[name] = kin[:, :, i]
    for name in ("F_n", "F_t", "mu"):
        out[name] = con[:, :, _layout.CONTACT.index(name)]
    if single:
        out = {k: v[0] for k, v in out.items()}
    return ContactState(**{k: out[k] for k in ContactState.__dataclass_fields__})


def energies(x: ArrayLike, params: Params | None = None) -> dict[str, np.ndarray | float]:
    """Kinetic energy T, gravitational potential V_gravity, hip-spring energy V_hip and their
    sum E [J] (docs/model.md section 3; V_gravity is zero at the slope-frame origin).

    Parameters
    ----------
    x : array_like, shape (8,) or (N, 8)
        State [q, qd] [m, rad, m/s, rad/s].
    params : Params, optional
        Default `Params.paper()`.

    Returns
    -------
    dict
        ``{"T", "V_gravity", "V_hip", "E"}`` -> float for one state, ndarray (N,) for N [J].
    """
    X, single = _states(x)
    e = np.empty((len(X), len(_layout.ENERGY)))
    _core.energies_batch(kernel_index("paper"), X, parameter_vector(params), e)
    out = {name: e[:, i] for i, name in enumerate(_layout.ENERGY)}
    out["E"] = e.sum(axis=1)
    return {k: (v[0] if single else v) for k, v in out.items()}


def state_index(name: str) -> int:
    """Index of a state component by name (see `STATE`)."""
    if name not in _IX:
        raise KeyError("unknown state component %r; allowed: %s" % (name, ", ".join(STATE)))
    return _IX[name]
