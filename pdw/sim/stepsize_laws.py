"""The step-size check of `pdw.sim.stepsize` for every contact law (issue 12).

`pdw.sim.stepsize.step_limit` and `check_step` estimate the largest safe fixed step of the
default law (Hunt-Crossley with Eq. 10's friction) from the linear stability of the method at
stance states (docs/stability.md section 6). For another law of `pdw.Contact` the limit is that
estimate at the run's parameters (``contact.parameters(params)``: the law's k and d in k_n,
d_n) times a per-law, per-method factor `LAW_CALIBRATION` fitted on the limits measured with
each law calibrated to the paper's ground on `paper_steady` (benchmarks/step_limits_laws.py,
docs/contact_laws.md). The factor keeps each law's limit as far below its measured walking edge
as the default law's is there. It carries the law's own physics -- LuGre's bristle damping
sigma1 F_n above all -- only at the calibrated parameters, plus LuGre's sigma1 (`law_factor`).

Kelvin-Voigt's k [N/m] and d [N s/m] have other units than the default law's k_n, d_n: read as
Hunt-Crossley numbers they mean another ground, so its estimate is taken at its calibrated k, d
(`law_params`: the point its factor was fitted at), and the factor is scaled by how much the
explicit limit of the law's own contact oscillator (`oscillator_limit`, the landing foot's
effective mass on the law's spring and damper) falls from its calibrated k, d to the run's
(issue 26.4: k = 1e5 N/m, d = 1e6 N s/m diverged at 0.2 ms under cdm at dt = 1e-4 and the
estimate, at 4.9e-4 s, said nothing).
"""
from __future__ import annotations

import math

from ..core.contact import KELVIN_VOIGT_DEFAULTS, LUGRE_DEFAULTS

#: Per variant, contact law and fixed-step method: dt_max = factor x the default law's estimate
#: at the run's parameters. Fitted by benchmarks/step_limits_laws.py (benchmarks/results/
#: step_limits_laws.txt) with the laws calibrated to the paper's ground on `paper_steady`: the
#: law's walking edge (the largest step that walks with the rodas4 reference's touch-downs)
#: over its estimate, divided by the same ratio for hunt_crossley, rounded down to two digits.
#: So each law's limit sits as far below its measured edge as the default law's does there.
#: hertz does not walk at any step (it falls after one step under rodas4 too): it keeps the
#: default law's factor. "lugre" is LuGre friction on the Hunt-Crossley ground (its bristle
#: damping sigma1 F_n sets the limit, ~20 x below the default's); LuGre on another normal law
#: takes the smaller of the two factors (not measured). LuGre's factor is for its calibrated
#: bristle damping `LUGRE_SIGMA1`; a larger sigma1 scales it by LUGRE_SIGMA1 / sigma1 (a
#: damper's explicit limit; measured: the edges fall as sigma1^-0.2 ... -0.9 from 15 to 316 s/m,
#: benchmarks/results/step_limits_laws.txt), a smaller one keeps it.
LAW_CALIBRATION = {
    "paper": {
        "hunt_crossley": {"cdm": 1.0, "verlet": 1.0, "rk4": 1.0},
        "hertz": {"cdm": 1.0, "verlet": 1.0, "rk4": 1.0},
        "kelvin_voigt": {"cdm": 0.54, "verlet": 0.7, "rk4": 1.3},
        "lankarani_nikravesh": {"cdm": 1.4, "verlet": 1.0, "rk4": 1.3},
        "flores": {"cdm": 1.1, "verlet": 1.0, "rk4": 0.93},
        "lugre": {"cdm": 0.045, "verlet": 0.012, "rk4": 0.011},
    },
    "consistent": {
        "hunt_crossley": {"cdm": 1.0, "verlet": 1.0, "rk4": 1.0},
        "hertz": {"cdm": 1.0, "verlet": 1.0, "rk4": 1.0},
        "kelvin_voigt": {"cdm": 0.011, "verlet": 0.0045, "rk4": 0.028},
        "lankarani_nikravesh": {"cdm": 0.29, "verlet": 0.36, "rk4": 0.42},
        "flores": {"cdm": 0.48, "verlet": 0.52, "rk4": 0.48},
        "lugre": {"cdm": 0.06, "verlet": 0.015, "rk4": 0.012},
    },
}
#: The bristle damping [s/m] of the LuGre law `LAW_CALIBRATION` was fitted with
#: (`pdw.calibration.calibrate_lugre` on paper_steady: critically damped bristles).
LUGRE_SIGMA1 = 45.09


def law_of(contact) -> str:
    """The key of `LAW_CALIBRATION` for a `pdw.Contact` (None: the default law)."""
    if contact is None:
        return "hunt_crossley"
    if contact.friction == "lugre":
        return "lugre" if contact.normal == "hunt_crossley" else "lugre+" + contact.normal
    return contact.normal


#: Effective mass of a landing foot along the normal [kg] (`pdw.analysis.numerics.calibration.
#: typical_landing` on the default walker, docs/contact_laws.md): the mass of the contact
#: oscillator of `oscillator_limit`.
LANDING_MASS = 0.455


def oscillator_limit(k: float, d: float, m: float = LANDING_MASS) -> float:
    """Explicit (central difference) stability limit [s] of the contact oscillator
    m x'' + d x' + k x = 0: (2 / w) (sqrt(1 + z^2) - z), w = sqrt(k / m), z = d / (2 m w)
    (Belytschko, Liu & Moran, Nonlinear Finite Elements, 2000, Eq. 6.3.23); 2 m / d when the
    damper dominates, 2 / w when the spring does."""
    w = math.sqrt(k / m)
    z = d / (2.0 * m * w)
    return 2.0 / w / (math.sqrt(1.0 + z * z) + z)     # = (2/w)(sqrt(1+z^2) - z), no cancellation


def law_params(params, contact):
    """The parameters the default law's estimate is taken at for ``contact``'s law: the run's
    (``contact.parameters(params)``), except Kelvin-Voigt's, whose k, d are not Hunt-Crossley
    numbers: its calibrated ones (`KELVIN_VOIGT_DEFAULTS`; d_n stays 0 without normal
    damping)."""
    if contact is None or contact.normal != "kelvin_voigt":
        return params
    kv = KELVIN_VOIGT_DEFAULTS
    return params.replace(k_n=kv["k"], d_n=kv["d"] if params.d_n != 0 else 0.0)


def law_factor(law: str, method: str, contact=None, variant: str = "paper") -> float:
    """`LAW_CALIBRATION` [variant][law][method]; LuGre on another normal law: the smaller
    factor; LuGre with a bristle damping sigma1 above `LUGRE_SIGMA1`: times
    LUGRE_SIGMA1 / sigma1; Kelvin-Voigt stiffer or more damped than calibrated: times
    `oscillator_limit` at its k, d over that at `KELVIN_VOIGT_DEFAULTS`."""
    cal = LAW_CALIBRATION[variant]
    if law.startswith("lugre+"):
        f = min(cal["lugre"][method], cal[law[6:]][method])
    else:
        f = cal[law][method]
    if law.startswith("lugre") and contact is not None:
        s1 = contact.sigma1 if contact.sigma1 is not None else LUGRE_DEFAULTS["sigma1"]
        f *= min(1.0, LUGRE_SIGMA1 / s1) if s1 > 0 else 1.0
    if law.endswith("kelvin_voigt") and contact is not None:
        ref = oscillator_limit(**KELVIN_VOIGT_DEFAULTS)
        f *= min(1.0, oscillator_limit(contact.k, contact.d) / ref)
    return f


def law_message(lim, dt: float) -> str:
    """The warning / error text of a `StepLimit` of a non-default law at step ``dt``."""
    return ("dt = %.3g s exceeds the estimated stability limit %.2g s of method %r with the "
            "contact law %r (variant %r): the default law's estimate at these parameters%s, "
            "%.2g s, times the law's factor %.2g, fitted on its measured limit "
            "(docs/contact_laws.md). Above it the typical gait falls or diverges spuriously. "
            "Use dt <= %.2g, or method='rodas4' (L-stable, no step limit); check_step='off' "
            "disables this check."
            % (dt, lim.dt_max, lim.method, lim.law, lim.variant,
               " (Kelvin-Voigt's: at its calibrated k, d; the factor scaled to the run's)"
               if lim.law.endswith("kelvin_voigt") else "", lim.dt_max / lim.law_factor,
               lim.law_factor, lim.dt_max))
