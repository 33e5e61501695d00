"""Contact laws: which normal and friction law a simulation uses, with physical parameters.

The laws are derived once in ``derive/contact_laws.py`` and compiled ahead of time: one kernel
per contact variant and normal law (docs/contact_laws.md). A `Contact` names the laws and their
parameters; ``pdw.simulate(..., contact=Contact(...))`` (or a dict of the same fields, or a
scene's ``[contact]`` table) selects them. The default, ``Contact()``, is the paper's model:
Hunt-Crossley with the parameters of `pdw.Params` and the smooth Coulomb friction of Eq. 10;
it runs the very kernels it always did.

=====================  ============================================  =====================
normal law             F_n for depth delta > 0, rate delta_dot       parameters (units)
=====================  ============================================  =====================
hunt_crossley          k delta^1.5 + d delta^1.5 delta_dot (Eq. 3, 6)  k [N/m^1.5], d [N s/m^2.5]
hertz                  k delta^1.5                                    k [N/m^1.5]
kelvin_voigt           k delta + d delta_dot                          k [N/m], d [N s/m]
lankarani_nikravesh    k delta^1.5 (1 + 3(1-e^2)/4 delta_dot/v0)      k [N/m^1.5], e [-]
flores                 k delta^1.5 (1 + 8(1-e)/(5e) delta_dot/v0)     k [N/m^1.5], e [-]
=====================  ============================================  =====================

Every damped law is clamped at 0 (the ground cannot pull). v0 = max(v_in, v_in_min), v_in the
foot's approach speed captured at its touch-down. The laws whose k has ``Params.k_n``'s units
(N/m^1.5: hunt_crossley, hertz, lankarani_nikravesh, flores) default k to ``Params.k_n``, and
hunt_crossley d to ``Params.d_n``. kelvin_voigt's k and d have other units (N/m, N s/m): they
never take `Params`' numbers, but default to the law's own calibration to the paper's ground
(``KELVIN_VOIGT_DEFAULTS``: k = 7318 N/m, d = 112.2 N s/m, the static sink and the drop-test
restitution of `Params.paper_steady()`'s Hunt-Crossley ground, `pdw.analysis.numerics.calibration`;
docs/contact_laws.md), filled in when the Contact is made, so its repr shows them.

=====================  ====================================================================
friction law           friction force F_f (+X) of a penetrating support foot, slip velocity v
=====================  ====================================================================
coulomb (default)      mu(v) F_n, the smooth law of Eq. 10 (parameters in `Params`)
lugre                  -(sigma0 z + sigma1 dz/dt + sigma2 v) F_n, with a bristle state z [m]
                       per foot: dz/dt = v - sigma0 |v| z / g(v),
                       g(v) = mu_c + (mu_s - mu_c) exp(-(v/v_s)^2)  (Canudas de Wit et al. 1995)
=====================  ====================================================================

Both keep the tangential spring-damper of Eqs. 7, 11. LuGre's state is [q, qd, z1, z2]
(``pdw.core._layout.STATE_LAYOUTS``); z is reset to 0 at the foot's touch-down.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from . import _layout, checks
from .errors import InvalidInputError
from .params import Params

NORMAL_LAWS = _layout.NORMAL_LAWS
FRICTION_LAWS = _layout.FRICTION_LAWS
#: which parameters each normal law takes (the others must be left unset)
LAW_PARAMETERS = {
    "hunt_crossley": ("k", "d"),
    "hertz": ("k",),
    "kelvin_voigt": ("k", "d"),
    "lankarani_nikravesh": ("k", "e", "v_in_min"),
    "flores": ("k", "e", "v_in_min"),
}
UNITS = {
    "hunt_crossley": {"k": "N/m^1.5", "d": "N s/m^2.5"},
    "hertz": {"k": "N/m^1.5"},
    "kelvin_voigt": {"k": "N/m", "d": "N s/m"},
    "lankarani_nikravesh": {"k": "N/m^1.5", "e": "-", "v_in_min": "m/s"},
    "flores": {"k": "N/m^1.5", "e": "-", "v_in_min": "m/s"},
}
#: kelvin_voigt's defaults: its own calibration to the paper's ground (not ``Params.k_n``,
#: ``Params.d_n``, whose units differ): k = W / delta_s (the Hunt-Crossley static sink under the
#: walker's weight W) and d such that the drop test at the typical landing gives Hunt-Crossley's
#: restitution 0.1405 (`pdw.analysis.numerics.calibration.calibrate` of `Params.paper_steady()`: k =
#: 7318.12 N/m, d = 112.211 N s/m; here to 4 figures; a test recomputes them).
KELVIN_VOIGT_DEFAULTS = {"k": 7318.0, "d": 112.2}
#: LuGre's parameters: (lower bound, lower bound open, unit, meaning)
LUGRE_PARAMETERS = {
    "sigma0": (0.0, True, "1/m", "bristle stiffness per unit normal force"),
    "sigma1": (0.0, False, "s/m", "bristle damping per unit normal force"),
    "sigma2": (0.0, False, "s/m", "viscous friction per unit normal force"),
    "mu_s": (0.0, True, "-", "static friction coefficient (Stribeck curve at v = 0)"),
    "mu_c": (0.0, True, "-", "Coulomb friction coefficient (Stribeck curve at |v| >> v_s)"),
    "v_s": (0.0, True, "m/s", "Stribeck velocity"),
}
#: LuGre's defaults for sigma0, sigma1, sigma2 (Canudas de Wit et al. 1995's values for a unit
#: normal force); mu_s, mu_c, v_s default to the paper's law (``lugre_stribeck``).
LUGRE_DEFAULTS = {"sigma0": 1e5, "sigma1": math.sqrt(1e5), "sigma2": 0.0}
#: the prefix of a contact parameter as a continuation parameter (``"contact.d"``, `Contact.axes`)
AXIS_PREFIX = "contact."
_LG_P = {"sigma0": "sigma0", "sigma1": "sigma1", "sigma2": "sigma2", "mu_s": "lg_mu_s",
         "mu_c": "lg_mu_c", "v_s": "lg_v_s"}


def lugre_stribeck(params: Params) -> dict:
    """LuGre's Stribeck curve matched to the paper's Eq. 10: mu_s = `Params.mu_s`, mu_c =
    `Params.mu_d`, and v_s such that g falls half-way from mu_s to mu_c where Eq. 10's cubic step
    does, at (v_s + v_d)/2 of `Params`: v_s(LuGre) = (v_s + v_d) / (2 sqrt(ln 2))."""
    return {"mu_s": params.mu_s, "mu_c": params.mu_d,
            "v_s": 0.5 * (params.v_s + params.v_d) / math.sqrt(math.log(2.0))}


_P = {n: i for i, n in enumerate(_layout.PARAMS + _layout.DERIVED + _layout.CONTACT_PARAMS)}


@dataclass(frozen=True)
class Contact:
    """The contact laws of a simulation and their parameters (SI units, see the module table).

    Parameters
    ----------
    normal : str
        Normal law, one of ``NORMAL_LAWS``; default the paper's ``"hunt_crossley"``.
    friction : str
        Friction law, one of ``FRICTION_LAWS`` (``"coulomb"``: the smooth law of Eq. 10 with the
        tangential spring-damper of Eqs. 7, 11).
    k : float, optional
        Normal stiffness [N/m^1.5; N/m for kelvin_voigt]; default ``Params.k_n``, except
        kelvin_voigt: its calibrated 7318 N/m (``KELVIN_VOIGT_DEFAULTS``, set on the Contact).
    d : float, optional
        Normal damping of hunt_crossley [N s/m^2.5] or kelvin_voigt [N s/m]; default
        ``Params.d_n`` for hunt_crossley, the calibrated 112.2 N s/m for kelvin_voigt.
    e : float, optional
        Coefficient of restitution of lankarani_nikravesh and flores, in (0, 1]; required there.
    v_in_min : float, optional
        Smallest approach speed those laws divide by [m/s] (a foot that starts in contact, or
        lands slower than this, uses it); default 0.01 m/s.
    sigma0, sigma1, sigma2 : float, optional
        LuGre only: bristle stiffness (> 0) [1/m], bristle damping (>= 0) [s/m] and viscous
        friction (>= 0) [s/m], per unit normal force; default ``LUGRE_DEFAULTS``.
    mu_s, mu_c, v_s : float, optional
        LuGre only: its Stribeck curve's static and Coulomb coefficients (> 0) [-] and Stribeck
        velocity (> 0) [m/s]; default the paper's law matched (``lugre_stribeck``).

    Raises
    ------
    pdw.InvalidInputError
        An unknown law, a parameter the law does not take, or a value out of range.
    """

    normal: str = "hunt_crossley"
    friction: str = "coulomb"
    k: float | None = None
    d: float | None = None
    e: float | None = None
    v_in_min: float | None = None
    sigma0: float | None = None
    sigma1: float | None = None
    sigma2: float | None = None
    mu_s: float | None = None
    mu_c: float | None = None
    v_s: float | None = None

    def __post_init__(self):
        if self.normal not in NORMAL_LAWS:
            raise InvalidInputError("contact.normal must be one of %s, got %r"
                                    % (", ".join(NORMAL_LAWS), self.normal))
        if self.friction not in FRICTION_LAWS:
            raise InvalidInputError("contact.friction must be one of %s, got %r"
                                    % (", ".join(FRICTION_LAWS), self.friction))
        allowed = LAW_PARAMETERS[self.normal]
        for name, lo, hi, lo_open in (("k", 0.0, math.inf, True), ("d", 0.0, math.inf, False),
                                      ("e", 0.0, 1.0, True), ("v_in_min", 0.0, math.inf, True)):
            v = getattr(self, name)
            if v is None:
                continue
            if name not in allowed:
                raise InvalidInputError("contact.%s is not a parameter of the %s law (it takes %s)"
                                        % (name, self.normal, ", ".join(allowed)))
            v = checks._real("contact." + name, v)   # no strings, booleans or complex
            bad = not math.isfinite(v) or (v <= lo if lo_open else v < lo) or v > hi
            if bad:
                raise InvalidInputError("contact.%s = %r is out of range; allowed: %s %g%s [%s]"
                                        % (name, v, ">" if lo_open else ">=", lo,
                                           " and <= 1" if hi == 1.0 else "",
                                           UNITS[self.normal][name]))
            object.__setattr__(self, name, v)
        for name, (lo, lo_open, unit, _) in LUGRE_PARAMETERS.items():
            v = getattr(self, name)
            if v is None:
                continue
            if self.friction != "lugre":
                raise InvalidInputError("contact.%s is a parameter of the lugre friction law, not "
                                        "of %s" % (name, self.friction))
            v = checks._real("contact." + name, v)   # no strings, booleans or complex
            if not math.isfinite(v) or (v <= lo if lo_open else v < lo):
                raise InvalidInputError("contact.%s = %r is out of range; allowed: %s %g [%s]"
                                        % (name, v, ">" if lo_open else ">=", lo, unit))
            object.__setattr__(self, name, v)
        if self.normal == "kelvin_voigt":     # its own units: never Params' k_n, d_n
            for name, v in KELVIN_VOIGT_DEFAULTS.items():
                if getattr(self, name) is None:
                    object.__setattr__(self, name, v)
        if "e" in allowed and self.e is None:
            raise InvalidInputError("contact.e (coefficient of restitution, 0 < e <= 1) is "
                                    "required by the %s law" % self.normal)

    @classmethod
    def coerce(cls, contact) -> "Contact":
        """A `Contact` from None (the default), a Contact, a law name, or a dict of fields."""
        if contact is None:
            return _DEFAULT if cls is Contact else cls()     # immutable: one shared default
        if isinstance(contact, cls):
            return contact
        if isinstance(contact, str):
            return cls(normal=contact)
        if isinstance(contact, dict):
            unknown = set(contact) - set(cls.__dataclass_fields__)
            if unknown:
                raise InvalidInputError("unknown contact field(s) %s; allowed: %s"
                                        % (", ".join(sorted(map(str, unknown))),
                                           ", ".join(cls.__dataclass_fields__)))
            return cls(**contact)
        raise InvalidInputError("contact must be a pdw.Contact, a dict or a law name, got %s"
                                % type(contact).__name__)

    @property
    def is_default(self) -> bool:
        """The paper's laws with the parameters of `Params` (the default kernels)."""
        return self == _DEFAULT

    def parameters(self, params: Params) -> Params:
        """``params`` with k_n and d_n set from this contact's k and d (if given); hertz sets
        d_n = 0 (no damping), lankarani_nikravesh and flores leave d_n unused."""
        changes = {}
        if self.k is not None:
            changes["k_n"] = self.k
        if self.d is not None:
            changes["d_n"] = self.d
        if self.normal == "hertz":
            changes["d_n"] = 0.0
        return params.replace(**changes) if changes else params

    @property
    def nx(self) -> int:
        """Size of the continuous state under this friction law (``pdw.core._layout.STATE_LAYOUTS``)."""
        return len(_layout.STATE_LAYOUTS[self.friction])

    @property
    def state_names(self) -> tuple:
        """Names of the state components under this friction law."""
        return _layout.STATE_LAYOUTS[self.friction]

    def for_features(self, features) -> "Contact":
        """The contact a run with only these force elements (``pdw.core._layout.FEATURES``)
        simulates. Each element means under LuGre what it means under the default law:
        ``hip_spring``, ``hip_damper``, ``normal_damping`` and ``tangential`` (the spring-damper
        of Eqs. 7, 11, which LuGre keeps) are switched off by zeroing their parameters on the
        law's kernel (`Params.without`), the friction law untouched. ``friction`` is the
        friction law's force itself: a LuGre contact without it has no friction force, so no
        bristles; the run is then its normal law with the default friction law, switched off
        the same way (mu_s = mu_d = 0), and an 8-entry state. Returns this contact, or that
        one (LuGre's parameters dropped)."""
        if self.friction == "coulomb" or "friction" in features:
            return self
        return Contact(**{n: v for n, v in self.as_dict().items()
                          if n != "friction" and n not in LUGRE_PARAMETERS})

    def run_state(self, x, features=None) -> np.ndarray:
        """The initial state of a run under this friction law from a checked x0, shape (nx,):
        a mechanical x0 (`pdw.STATE`) gets bristle states 0 (relaxed). With ``features``
        (`for_features`), the state of the contact that run simulates: a LuGre x0 of a run
        without friction loses its bristle states (they act through the friction force
        only)."""
        x = np.asarray(x, dtype=float)
        run = self if features is None else self.for_features(features)
        if run.friction == "coulomb":
            if len(x) == self.nx and run is not self:
                x = x[:run.nx]
            if len(x) != len(_layout.STATE):
                raise InvalidInputError("x0 has %d entries: the state of the %s friction law has "
                                        "%d (%s)" % (len(x), self.friction, self.nx,
                                                     ", ".join(self.state_names)))
            return x
        return np.concatenate([x, np.zeros(self.nx - len(x))]) if len(x) < self.nx else x

    def lugre_parameters(self, params: Params) -> dict:
        """LuGre's six parameters with the defaults filled in (sigma0, sigma1, sigma2, mu_s,
        mu_c, v_s)."""
        out = dict(LUGRE_DEFAULTS, **lugre_stribeck(params))
        out.update({n: getattr(self, n) for n in LUGRE_PARAMETERS if getattr(self, n) is not None})
        for name in ("mu_s", "mu_c"):           # defaults from Params may be 0 (no friction)
            if not out[name] > 0:
                raise InvalidInputError(
                    "contact.%s = %r (from Params.%s) is out of range; allowed: > 0 [-] (LuGre "
                    "divides by its Stribeck curve): set contact.%s" % (
                        name, out[name], "mu_s" if name == "mu_s" else "mu_d", name))
        return out

    def vector(self, p: np.ndarray, features=None, params: Params | None = None) -> np.ndarray:
        """Fill the contact-law entries (`pdw.core._layout.CONTACT_PARAMS`) of a kernel parameter
        vector ``p`` (from `pdw.core.model.parameter_vector`) in place; returns ``p``. Without the
        ``normal_damping`` feature, e = 1 (no damping). LuGre's unset Stribeck parameters come
        from ``params`` (default `Params.paper`)."""
        if self.friction == "lugre":
            for name, v in self.lugre_parameters(params or Params.paper()).items():
                p[_P[_LG_P[name]]] = v
        if "e" in LAW_PARAMETERS[self.normal]:
            damped = features is None or "normal_damping" in features
            p[_P["e_n"]] = self.e if damped else 1.0
            p[_P["v_in_min"]] = 0.01 if self.v_in_min is None else self.v_in_min
        return p

    # --- continuation axes: the contact's parameters as continuation parameters --------------

    def axes(self) -> tuple:
        """The parameters of this contact a continuation can follow, as ``"contact.<name>"``
        (`pdw.continue_gait`): the normal law's (``LAW_PARAMETERS``) and, under LuGre
        friction, LuGre's six (``LUGRE_PARAMETERS``)."""
        names = LAW_PARAMETERS[self.normal]
        if self.friction == "lugre":
            names = names + tuple(LUGRE_PARAMETERS)
        return tuple(AXIS_PREFIX + n for n in names)

    def _axis(self, axis: str) -> str:
        if not (isinstance(axis, str) and axis in self.axes()):
            raise InvalidInputError("%r is not a parameter of the contact (%s normal law, %s "
                                    "friction); allowed: %s" % (axis, self.normal, self.friction,
                                                                ", ".join(self.axes())))
        return axis[len(AXIS_PREFIX):]

    def axis_value(self, axis: str, params: Params) -> float:
        """The value of the contact parameter ``axis`` (``"contact.<name>"``) a run with
        ``params`` uses: the Contact's own, else its default (k: ``params.k_n``; d:
        ``params.d_n``; v_in_min: 0.01 m/s; LuGre's: `lugre_parameters`)."""
        name = self._axis(axis)
        v = getattr(self, name)
        if v is not None:
            return float(v)
        if name in LUGRE_PARAMETERS:
            return float(self.lugre_parameters(params)[name])
        return float({"k": params.k_n, "d": params.d_n, "v_in_min": 0.01}[name])

    def axis_unit(self, axis: str) -> str:
        """The unit of the contact parameter ``axis`` under this contact's laws (e.g.
        ``"N s/m"`` for kelvin_voigt's d, ``"N s/m^2.5"`` for hunt_crossley's)."""
        name = self._axis(axis)
        return LUGRE_PARAMETERS[name][2] if name in LUGRE_PARAMETERS else UNITS[self.normal][name]

    def with_axis(self, axis: str, value: float) -> "Contact":
        """This contact with the parameter ``axis`` (``"contact.<name>"``) set to ``value``
        (checked as the constructor checks it: `pdw.InvalidInputError` when out of range)."""
        name = self._axis(axis)
        return Contact(**{**self.as_dict(), name: value})

    def as_dict(self) -> dict:
        """The fields that are set (for scenes and reports)."""
        return {n: getattr(self, n) for n in self.__dataclass_fields__
                if getattr(self, n) is not None}


#: The default contact (the paper's laws), shared: a Contact is immutable.
_DEFAULT = Contact()
