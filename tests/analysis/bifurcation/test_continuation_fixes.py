"""Issue #24's fixes: honest locations, stalls, option checks, end reasons (docs/continuation.md)."""
import numpy as np
import pytest

import pdw
from pdw import hybrid as H
from pdw.analysis.bifurcation.continuation import continue_gait, run_continuation
from pdw.analysis.stepmap.gait_maps import Evaluation

COMPASS = H.compass_gait_params()


class _Line:
    """A 1-d map with the fixed-point family z = a and multiplier lam(a):
    z' = a + lam(a) (z - a). ``fail(a)`` makes the map fail there (as a walker that falls);
    ``jac_error`` scales the reported M - 1 (a wrong Jacobian, beyond a = jac_from)."""

    model, parameter, period, ADMISSIBLE = "map", "a", 1, {}

    def __init__(self, lam, fail=None, jac_error=1.0, jac_from=np.inf):
        self.lam, self.fail, self.dim, self.n_maps, self.opts = lam, fail, 1, 0, {}
        self.jac_error, self.jac_from = jac_error, jac_from

    def value(self, mu):
        return float(mu)

    def coord(self, v):
        return float(v)

    def f(self, z, a):
        return a + self.lam(a) * (z - a)

    def evaluate(self, z, mu, jac=True):
        self.n_maps += 1
        if self.fail is not None and self.fail(mu):
            return Evaluation(False, "fell")
        h = 1e-7
        P_lam = (self.f(z, mu + h) - self.f(z, mu - h)) / (2 * h)
        M = np.array([[self.lam(mu)]])
        if mu > self.jac_from:
            M = np.array([[1.0 + self.jac_error * (self.lam(mu) - 1.0)]])
        info = {"period": 1.0, "step_length": float(z[0]), "double_support": 0.0, "state": z,
                "orbit": np.array([z])}
        return Evaluation(True, "ok", self.f(z, mu), M, P_lam, info, {})

    def gait(self, z, mu, ev, mult):
        return pdw.Gait(state=z, period=1.0, step_length=1.0, double_support=0.0,
                        multipliers=mult, model="map")


# --- 1. a failed location is not reported as located ---------------------------------------

def test_a_smooth_period_doubling_is_located_to_locate_tol():
    """The control: lam(a) = -a crosses -1 at a = 1, located, bracket < locate_tol."""
    b = run_continuation(_Line(lambda a: -a), [0.5], 0.5, 1.5, tol=1e-12)
    (pd,) = b.of_kind("period_doubling")
    assert pd.located and pd.tolerance < 1e-6 and abs(pd.value - 1.0) < 1e-6
    assert pd.bracket[0] <= 1.0 <= pd.bracket[1]
    assert pd.label == "PD1"


def test_a_jump_of_the_multiplier_is_detected_not_located():
    """lam jumps from -0.9 to -1.5 at a = 1 (a kink of the map, as the Kelvin-Voigt map's):
    the bracket narrows to locate_tol but det(M + I) does not vanish. Before the fix this was
    a 'period doubling at 1.0 (+-1e-7)' with the multiplier -1.5 there."""
    b = run_continuation(_Line(lambda a: -0.9 if a < 1.0 else -1.5), [0.5], 0.5, 1.5,
                         tol=1e-12)
    (pd,) = b.of_kind("period_doubling")
    assert pd.located is False
    assert "jumps" in pd.location_note
    assert pd.bracket[0] <= 1.0 <= pd.bracket[1] and pd.bracket[1] - pd.bracket[0] < 1e-5
    assert "NOT LOCATED" in repr(pd) and pd.as_dict()["located"] is False


def test_a_bracket_the_corrector_cannot_enter_is_detected_not_located():
    """lam(a) = -a crosses -1 at 1, but the map fails for 0.97 < a < 1.03 (the corrector cannot
    go there): the crossing is stepped over, its bracket stays wide, and it is reported as
    detected between the points around the gap, not as a located value."""
    b = run_continuation(_Line(lambda a: -a, fail=lambda a: 0.97 < a < 1.03), [0.5], 0.5, 1.5,
                         tol=1e-12, step=0.2, step_max=0.5)
    pds = b.of_kind("period_doubling")
    assert len(pds) == 1
    pd = pds[0]
    assert pd.located is False and "corrector fails" in pd.location_note
    assert pd.bracket[0] <= 0.97 and pd.bracket[1] >= 1.03
    assert pd.tolerance > 0.06


# --- 3. a stalled continuation stops and says why ------------------------------------------

def test_a_stalled_continuation_stops_with_the_reason():
    """A wrong Jacobian beyond a = 0.3 (M - 1 off by 25 %, as a finite difference across a
    kink): Newton converges only linearly, so only tiny steps succeed and the branch crawls.
    Before the fix it crawled to max_points (200 points within 2e-3 of a)."""
    prob = _Line(lambda a: 0.5 - 0.0 * a, jac_error=1.25, jac_from=0.3)
    b = run_continuation(prob, [0.0], 0.0, 1.0, tol=1e-10, max_points=200)
    assert b.stop_reason.startswith("stalled"), b.stop_reason
    assert len(b) < 60
    assert "last failure" in b.stop_reason


def test_a_healthy_continuation_does_not_stall():
    b = run_continuation(_Line(lambda a: 0.5), [0.0], 0.0, 1.0, tol=1e-12)
    assert "reached stop" in b.stop_reason


# --- 4. options range-checked -----------------------------------------------------------------

@pytest.mark.parametrize("kw, name", [
    (dict(step_max=-1.0), "step_max"), (dict(step_min=0.0), "step_min"),
    (dict(step=-0.1), "step"), (dict(tol=-1e-9), "tol"), (dict(tol=float("nan")), "tol"),
    (dict(locate_tol=0.0), "locate_tol"), (dict(max_newton=0), "max_newton"),
    (dict(max_newton=2.5), "max_newton"), (dict(max_points=2.9), "max_points"),
    (dict(max_points=1), "max_points"), (dict(period=1.5), "period"),
    (dict(fd_step=0.0), "fd_step"), (dict(workers=0), "workers"),
    (dict(at=[float("inf")]), "at"), (dict(step_min=0.5, step_max=0.1), "step_min"),
    (dict(stall_points=1), "stall_points"), (dict(stall_length=-1.0), "stall_length"),
    (dict(method="newton"), "method"), (dict(detect=("cusp",)), "detect"),
])
def test_every_option_is_range_checked_by_name(kw, name):
    with pytest.raises(pdw.InvalidInputError, match=name):
        continue_gait(COMPASS, "gamma", 0.06, model="hybrid", **kw)


def test_stop_must_be_finite():
    with pytest.raises(pdw.InvalidInputError, match="stop"):
        continue_gait(COMPASS, "gamma", float("nan"), model="hybrid")


def test_the_same_checks_on_the_engine_entry_point():
    with pytest.raises(pdw.InvalidInputError, match="max_points"):
        run_continuation(_Line(lambda a: 0.5), [0.0], 0.0, 1.0, max_points=2.9)
    with pytest.raises(pdw.InvalidInputError, match="tol"):
        run_continuation(_Line(lambda a: 0.5), [0.0], 0.0, 1.0, tol=0.0)


def test_the_branch_going_back_without_a_fold_is_not_called_a_fold():
    """Only a located fold makes 'returned past the start value (after the fold ...)'."""
    b = continue_gait(COMPASS, "gamma", 0.06, model="hybrid", max_points=3)
    assert "past the start" not in b.stop_reason


# --- 5. ends caused by min_step_angle say so ---------------------------------------------------

def test_an_end_caused_by_min_step_angle_names_the_option():
    """With min_step_angle raised to 97 % of the compass gait's step angle at 4.5 deg (the step
    angle shrinks with the slope), strikes are not armed below some slope: continued downwards,
    the family ends there, and the end and the stop reason name the option."""
    g = H.find_gait(COMPASS.replace(gamma=np.deg2rad(4.5)))
    ang = g.details["y_minus"][1] - g.details["y_minus"][0]
    lim = 0.97 * ang
    b = continue_gait(COMPASS.replace(gamma=np.deg2rad(4.5)), "gamma", np.deg2rad(3.0),
                      model="hybrid", options=dict(min_step_angle=lim))
    assert "min_step_angle" in b.stop_reason, b.stop_reason
    ends = b.of_kind("end")
    assert ends and "min_step_angle" in ends[-1].reason


def _simplest(gamma, m_l):
    return pdw.Params(l=1.0, c=1.0, w=0.0, r=0.0, J_l=0.0, m_h=1.0, m_l=m_l, k_hip=0.0,
                      d_hip=0.0, gamma=gamma, g=1.0)


def test_simplest_walker_limit_of_the_period_doubling():
    """The README's 0.015073 is the m_l/m_h = 1e-4 preset's; the limit m_l/m_h -> 0 is
    0.0150884: the doubling converges linearly in m_l/m_h (each decade closes the gap ten-fold),
    so gamma(1e-8) is within 2e-8 of the limit."""
    g = {m: continue_gait(_simplest(0.009, m), "gamma", 0.02, model="hybrid",
                          locate_tol=1e-11).of_kind("period_doubling")[0].value
         for m in (1e-4, 1e-6, 1e-7, 1e-8)}
    assert abs(g[1e-4] - 0.015073) < 5e-7
    r = (g[1e-6] - g[1e-7]) / (g[1e-7] - g[1e-8])
    assert 8.0 < r < 12.0
    limit = g[1e-8] - (g[1e-7] - g[1e-8]) / 9.0
    assert abs(limit - 0.0150884) < 5e-8


def _kelvin_voigt(d):
    """Kelvin-Voigt at the calibrated stiffness k = W / delta_s (the Hunt-Crossley static sink
    under the weight, pdw.analysis.numerics.calibration: 7318.12 N/m) and damping d [N s/m]."""
    P0 = pdw.Params.paper_steady()
    return pdw.Contact("kelvin_voigt", k=P0.weight / (P0.weight / P0.k_n) ** (2.0 / 3.0), d=d)


def _exact_flip(z, d):
    """Newton's method on P(z) - z with the exact step Jacobian (variational equations, no
    finite differences, no continuation) at damping d: (z*, the flip multiplier)."""
    from pdw.analysis.stepmap import variational as V
    P0, c = pdw.Params.paper_steady(), _kelvin_voigt(d)
    for _ in range(12):
        r = V.step_jacobian(z, P0, contact=c)
        if np.max(np.abs(r["z"] - z)) < 1e-10:
            break
        z = z - np.linalg.solve(r["M"] - np.eye(len(z)), r["z"] - z)
    assert np.max(np.abs(r["z"] - z)) < 1e-9
    return z, float(np.min(np.real(np.linalg.eigvals(r["M"]))))


@pytest.mark.slow
def test_kelvin_voigt_period_doubling_in_contact_d_and_stall_stop():
    """The Kelvin-Voigt ground's doubling (docs/contact_laws.md), continued in the Contact's
    own damping "contact.d" from 109.5 with steps of 0.1: with finite differences it is located
    at 109.74536 (the multiplier -1 to 1e-3), the cross-check against the exact monodromy
    flags the kink next to it, and the branch beyond stops as stalled at 109.886. Independent
    check (Newton with the exact Jacobian): the flip multiplier passes -1 between 109.7495
    (-0.99982) and 109.7498 (-1.00003), so the finite-difference location is 0.0044 low;
    long walks: period 1 at 109.745 and 109.747 (the alternation decays), period 2 at 109.752."""
    P0 = pdw.Params.paper_steady()
    with pytest.warns(UserWarning, match="kink of the step map"):
        b = continue_gait(P0, "contact.d", 110.2, step=0.1, max_points=30,
                          options=dict(contact=_kelvin_voigt(109.5)), workers=2)
    (pd,) = b.of_kind("period_doubling")
    assert pd.located and 109.744 < pd.value < 109.747
    assert np.min(np.abs(pd.multipliers + 1.0)) < 1e-3
    assert b.stop_reason.startswith("stalled") and len(b) < 30
    z, lo = _exact_flip(b.z[0], 109.7495)
    _, hi = _exact_flip(z, 109.7498)
    assert -1.0 < lo < -0.9995 and -1.0005 < hi < -1.0


@pytest.mark.slow
def test_kelvin_voigt_period_doubling_with_the_exact_monodromy():
    """The same continuation with monodromy="exact" passes the kink: the doubling at 109.74972,
    inside the independent bracket [109.7495, 109.7498] (test above), and the branch reaches
    its stop (no stall: the exact multipliers are smooth, -1.11 at 109.85, where the
    finite-difference ones jumped to -1.41)."""
    with pytest.warns(UserWarning, match="depend on the step"):   # the cross-check: FD
        b = continue_gait(pdw.Params.paper_steady(), "contact.d", 110.2, step=0.1,
                          max_points=30, options=dict(contact=_kelvin_voigt(109.5)),
                          workers=2, monodromy="exact")
    (pd,) = b.of_kind("period_doubling")
    assert pd.located and 109.7495 < pd.value < 109.7498
    assert b.stop_reason.startswith("reached stop")
    i = np.argmin(np.abs(b.values - 109.85))
    assert abs(np.min(np.real(b.multipliers[i])) + 1.11) < 0.01


def test_a_parameter_kelvin_voigt_does_not_read_is_refused():
    """Contact("kelvin_voigt") takes k, d from the Contact, never Params' k_n, d_n: continuing
    in d_n varied nothing (the same multiplier -1.44936 at every d_n) and ended "reached stop"."""
    with pytest.raises(pdw.InvalidInputError, match="not read by the kelvin_voigt law"):
        continue_gait(pdw.Params.paper_steady(), "d_n", 110.2, step=0.1, max_points=3,
                      options=dict(contact=pdw.Contact("kelvin_voigt")))
