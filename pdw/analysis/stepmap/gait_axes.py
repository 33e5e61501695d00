"""A continuation problem's parameter and the comparison of two multiplier sets
(`pdw.analysis.stepmap.gait_maps`; docs/continuation.md "Contact parameters", "Cross-check at
every bifurcation").

A parameter is a `Params` field, a parameter of the continuous model's contact law
(``"contact.<name>"``, `pdw.Contact.axes`), or any name with ``params_of``: `check_parameter`
says which and refuses the rest with the allowed names, `parameter_unit` gives its unit (the
law's, for a contact parameter). `multiplier_gap` compares finite-difference and exact
multipliers for the cross-check.
"""
from __future__ import annotations

import numpy as np

from ...core.contact import AXIS_PREFIX, Contact
from ...core.errors import InvalidInputError
from ...core.params import Params


def multiplier_gap(a, b, floor=0.1) -> float:
    """The largest distance from a multiplier of modulus >= ``floor`` in ``a`` or ``b`` to the
    nearest one of the other set (0 when none is that large). Nearest-neighbour matching, not
    sorting (a sort by real part pairs a real multiplier with a complex one when they swap
    order); the small multipliers are left out: they take no part in a bifurcation and central
    differences do not resolve them where M is ill-conditioned (Kelvin-Voigt at d = 109 N s/m:
    entries of M up to 426, a pair 0.007 +- 0.020i the differences give as 0.006 +- 0.011i)."""
    a, b = np.asarray(a), np.asarray(b)
    d = ([float(np.min(np.abs(b - x))) for x in a if abs(x) >= floor]
         + [float(np.min(np.abs(a - x))) for x in b if abs(x) >= floor])
    return max(d, default=0.0)


def check_parameter(parameter, params_of=None, contact=None, contact_axes=True,
                    model="continuous"):
    """Check a continuation parameter's name: a `Params` field, a parameter of the contact
    law (``"contact.<name>"``, `pdw.Contact.axes`; continuous model only, not with
    ``params_of``), or any name with ``params_of``. Returns the contact axis or None.

    Raises
    ------
    pdw.InvalidInputError
        Naming the parameter and listing the allowed names.
    """
    law = Contact.coerce(contact)
    if isinstance(parameter, str) and parameter.startswith(AXIS_PREFIX):
        if not contact_axes:
            raise InvalidInputError("parameter %r: the %s model has rigid ground, no contact "
                                    "law to continue; allowed: a Params field (%s)"
                                    % (parameter, model, ", ".join(Params.__dataclass_fields__)))
        if params_of is not None:
            raise InvalidInputError("parameter %r is a contact parameter: it takes no "
                                    "params_of (params_of moves Params fields)" % parameter)
        law._axis(parameter)
        return parameter
    if params_of is None and parameter not in Params.__dataclass_fields__:
        raise InvalidInputError("parameter must be a Params field (%s)%s or come with "
                                "params_of, got %r"
                                % (", ".join(Params.__dataclass_fields__),
                                   (", a parameter of the contact (%s)" % ", ".join(law.axes()))
                                   if contact_axes else "", parameter))
    return None


def parameter_unit(parameter, contact=None) -> str:
    """The unit of a continuation parameter: a `Params` field's (its metadata), or the contact
    law's for ``"contact.<name>"`` (`pdw.Contact.axis_unit`); "" when unknown."""
    if isinstance(parameter, str) and parameter.startswith(AXIS_PREFIX):
        try:
            return Contact.coerce(contact).axis_unit(parameter)
        except InvalidInputError:
            return ""
    f = Params.__dataclass_fields__.get(parameter)
    return f.metadata.get("unit", "") if f is not None else ""
