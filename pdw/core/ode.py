"""The model as an ODE object for external solvers (`scipy.integrate.solve_ivp`, optimizers,
control loops): what PyDy's ``generate_ode_function`` gives its users.

`ode_function` validates its inputs once and returns an `OdeFunction` (compiled,
`pdw.core._core`): ``f(t, x)`` is f(x) of Eq. A.4 (docs/model.md section 3) with the support
flags and the tangential anchors held fixed, ``f.jac(t, x)`` its symbolic Jacobian,
``f.batch(X)`` the rows of an (N, 8) array in one compiled loop. The discrete state of
docs/model.md sections 5-6 (flags, arming, anchors) is *not* updated: integrate a stretch
without flag changes, or use `pdw.simulate`, which does.
"""
from __future__ import annotations

from typing import Iterable

from . import _core, _layout, checks
from .contact import Contact
from .errors import InvalidInputError
from .model import check_variant, kernel_index, parameter_vector
from .params import Params

OdeFunction = _core.OdeFunction


def _check_discrete(flags, anchors):
    """Flags: two integers in {0, 1}; anchors: two finite real numbers [m] (`checks`)."""
    f = checks.flags("flags", flags)
    a = checks.real_array("anchors", anchors, [(2,)])
    return f, (float(a[0]), float(a[1]))


def _check_features(features):
    if features is None:
        return _layout.FEATURES
    if isinstance(features, str):
        raise InvalidInputError("features must be a collection of names, got the string %r"
                                % features)
    try:
        unknown = set(features) - set(_layout.FEATURES)
    except TypeError:
        raise InvalidInputError("features must be a collection of names from %s, got %r"
                                % (", ".join(_layout.FEATURES), features)) from None
    if unknown:
        raise InvalidInputError("unknown feature(s) %s; allowed: %s"
                                % (", ".join(sorted(map(str, unknown))),
                                   ", ".join(_layout.FEATURES)))
    return tuple(f for f in _layout.FEATURES if f in set(features))


def ode_function(params: Params | None = None, variant: str = "paper",
                 flags: tuple[int, int] = (0, 1), anchors: tuple[float, float] = (0.0, 0.0),
                 features: Iterable[str] | None = None, *, contact=None,
                 approach_speeds: tuple[float, float] = (0.0, 0.0)) -> OdeFunction:
    """The right-hand side f(t, x) of Eq. A.4 as a fast callable for external solvers.

    Parameters
    ----------
    params : Params, optional
        Default `Params.paper()`.
    variant : {"paper", "consistent"}
        Contact reading of docs/model.md section 6.
    flags : (int, int)
        Support flags of legs 1 and 2 (1 support, 0 swing; docs/model.md section 5), held fixed.
    anchors : (float, float)
        Rolling coordinate s_i at the last touch-down of each foot [m] (only the
        ``consistent`` variant uses them), held fixed.
    features : iterable of str, optional
        Force elements present (``pdw.core._layout.FEATURES``; default all), as in `pdw.simulate`.
    contact : pdw.Contact, dict or str, optional
        Contact laws (docs/contact_laws.md; default the paper's, `pdw.Contact`), as in
        `pdw.simulate`: the compiled f and Jacobian of that law's kernel. Under LuGre friction
        the state has 10 entries (``f.nx``; the bristle deflections z1, z2 [m] last), and the
        kernel's Jacobian is a central difference of f (the Coulomb laws' is symbolic).
    approach_speeds : (float, float)
        Approach speeds (v_in1, v_in2) [m/s] captured at each foot's touch-down, held fixed;
        only the lankarani_nikravesh and flores laws read them (through
        max(v_in, contact.v_in_min)).

    Returns
    -------
    OdeFunction
        ``f(t, x)`` -> ndarray (nx,) for a float64 state x of shape (nx,) [m, rad, m/s, rad/s]
        (nx = 8, 10 under LuGre friction)
        (t is ignored: the model is autonomous); ``f.jac(t, x)`` -> (8, 8). Both return a
        fresh array every call (a copy of an internal buffer): keeping it is safe, as
        ``solve_ivp`` does;
        ``f.batch(X, out=None)`` -> (N, 8) for X of shape (N, 8); ``f.set_discrete(f1, f2,
        a1, a2)`` changes the flags and anchors (unchecked: use `ode_function` to validate).

    Notes
    -----
    Inputs are validated here, once; a call checks only that x is a C-contiguous float64
    array of shape (8,) (its raw buffer is then read in place; the cost per call is in
    docs/benchmarks.md) and converts anything else (a list, another dtype, a strided view);
    a wrong shape is `pdw.InvalidInputError` naming x. A state with a NaN or infinite
    component gives NaN in every entry of f(t, x) and f.jac(t, x) (and in its row of
    f.batch): NaN in, NaN out (`pdw.rhs` refuses such a state). ``solve_ivp(f, (0, T), x0,
    method="Radau", jac=f.jac)`` integrates one stretch of constant support flags; see
    docs/benchmarks.md for the cost per call (benchmarks/bench_io.py).

    Examples
    --------
    >>> import numpy as np, pdw
    >>> f = pdw.ode_function()
    >>> f(0.0, np.array(pdw.X0_PAPER)).shape
    (8,)
    """
    params = Params.paper() if params is None else params
    if not isinstance(params, Params):
        raise InvalidInputError("params must be a pdw.Params, got %s" % type(params).__name__)
    try:
        check_variant(variant)
    except ValueError as e:
        raise InvalidInputError(str(e)) from None
    feats = _check_features(features)
    (f1, f2), (a1, a2) = _check_discrete(flags, anchors)
    v = checks.real_array("approach_speeds", approach_speeds, [(2,)])
    law = Contact.coerce(contact).for_features(feats)
    if law.is_default:
        k = kernel_index(variant, feats)
        p = parameter_vector(params if feats == _layout.FEATURES else params.without(feats))
    else:                           # as `pdw.simulate` builds the kernel's parameters
        params = law.parameters(params)
        k = kernel_index(variant, feats, law.normal, law.friction)
        if feats != _layout.FEATURES:
            params = params.without(feats)
        p = law.vector(parameter_vector(params), feats, params)
    f = OdeFunction(k, p, f1, f2, a1, a2)
    f.set_discrete(f1, f2, a1, a2, (float(v[0]), float(v[1])))
    return f

