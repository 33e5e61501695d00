"""The compiled exact monodromy (issue #24 "Speed"; pdw/core/csrc/pdw_cvar.c through
`variational.step_jacobian(engine="compiled")`, the default) against the Python version
(engine="python": SciPy Radau + LSODA) and against finite differences, per contact law."""
import numpy as np
import pytest

import pdw
from pdw.analysis.stepmap import limit_cycle as LC
from pdw.analysis.stepmap import section as S
from pdw.analysis.stepmap import variational as V
from pdw.core import _core

pytest.importorskip("scipy")

P = pdw.Params.paper_steady()


def _mult(M):
    return np.sort_complex(np.linalg.eigvals(M))


@pytest.fixture(scope="module")
def z0():
    return pdw.find_gait(P, workers=1).details["z"]


def _agree(c, z, mult_tol, m_tol):
    """compiled and Python: the same events (kinds, times to 1e-9 s), z' to 1e-9, the
    multipliers to mult_tol and M to m_tol x max|M|; returns the compiled result."""
    a = V.step_jacobian(z, P, contact=c)
    b = V.step_jacobian(z, P, contact=c, engine="python")
    assert [e[1:] for e in a["events"]] == [e[1:] for e in b["events"]]
    np.testing.assert_allclose([e[0] for e in a["events"]], [e[0] for e in b["events"]],
                               atol=1e-9)
    assert a["T"] == pytest.approx(b["T"], abs=1e-9)
    assert np.max(np.abs(a["z"] - b["z"])) < 1e-9
    assert np.max(np.abs(_mult(a["M"]) - _mult(b["M"]))) < mult_tol
    assert np.max(np.abs(a["M"] - b["M"])) < m_tol * np.abs(b["M"]).max()
    return a


def test_compiled_matches_python_and_differences_at_paper_steady(z0):
    """The default law: multipliers equal to the Python version's to 1e-7 (measured 2.3e-8;
    below 1e-8 with rtol 1e-12 and phi_rtol 1e-10: they converge together), M to 1e-5 of its
    largest entry, and M equal to central differences (good to ~1e-4) to 1e-4."""
    a = _agree(None, z0, 1e-7, 1e-5)
    J, _, _ = LC.jacobian(z0, P, **LC.TIGHT, workers=1)
    assert np.max(np.abs(a["M"] - J)) < 1e-4 * np.abs(J).max()
    tight = V.step_jacobian(z0, P, rtol=1e-12, atol=1e-14, phi_rtol=1e-10)
    b = V.step_jacobian(z0, P, engine="python", rtol=1e-12, atol=1e-14, phi_rtol=1e-11)
    assert np.max(np.abs(_mult(tight["M"]) - _mult(b["M"]))) < 1e-8


def test_compiled_with_approach_speeds_and_reentries(z0):
    """lankarani_nikravesh (e = 0.5; the state carries v_in, its saltations the reset): from
    the default gait's z with v_in = 0.3 m/s the stance foot rises and re-enters; every event
    and the multipliers (to 1e-7; measured 4.6e-9) as the Python version's."""
    c = pdw.Contact("lankarani_nikravesh", e=0.5)
    a = _agree(c, np.r_[z0, 0.3], 1e-7, 1e-5)
    assert a["M"].shape == (7, 7) and [e[1] for e in a["events"]].count("reentry") == 1


@pytest.mark.parametrize("law", ["hertz", "flores"])
def test_interval_matches_lsoda_per_law(z0, law):
    """One interval of fixed flags (both feet down, no events), 20 ms from the default gait's
    touch-down: (x, Phi) of pdw_cvar.c equal LSODA's (rtol 1e-12) of Phi' = A Phi, with A the
    kernel's Jacobian (and df/dv_in, central differences, for flores), to 1e-7 of |Phi|."""
    from scipy.integrate import solve_ivp
    c = pdw.Contact.coerce({"flores": pdw.Contact("flores", e=0.18)}.get(law, law))
    z = np.r_[z0, 0.3] if law == "flores" else z0
    x0, v0 = S.start(z, P, c, "paper")
    na = 0 if v0 is None else 2
    f = pdw.ode_function(P, flags=(1, 1), contact=c,
                         approach_speeds=v0 if na else (0.0, 0.0))
    F = V._Field(f, na, P)
    y0 = np.r_[x0, v0] if na else x0.copy()
    n = F.n

    def aug(t, yy):
        return np.concatenate([F(t, yy[:n]), (F.jac(t, yy[:n]) @ yy[n:].reshape(n, n)).ravel()])

    T = 0.02
    ref = solve_ivp(aug, (0.0, T), np.r_[y0, np.eye(n).ravel()], method="LSODA", rtol=1e-12,
                    atol=1e-14)
    y, Phi = y0.copy(), np.eye(n)
    rc, t, k, _ = _core.cvar_interval(f, P.l, P.r, na, [], 0.0, y, Phi, 1e-4, T,
                                      phi_error=True, phi_rtol=1e-9, phi_atol=1e-9)
    assert rc == 1 and t == T and k == -1
    assert np.max(np.abs(y - ref.y[:n, -1])) < 1e-9
    PhiR = ref.y[n:, -1].reshape(n, n)
    assert np.max(np.abs(Phi - PhiR)) < 1e-7 * np.abs(PhiR).max()


def test_events_are_located_to_rounding(z0):
    """The first event from the touch-down (the trailing foot's height through 0 upwards):
    the state returned is on the shifted surface to ~1e-15 m, at the Python version's time."""
    x0, _ = S.start(z0, P, pdw.Contact.coerce(None), "paper")
    f = pdw.ode_function(P, flags=(1, 1))
    y, Phi = x0.copy(), np.eye(8)
    rc, t, k, _ = _core.cvar_interval(f, P.l, P.r, 0, [(1, 0, 1.0), (0, 1, 0.0)], 0.0, y, Phi,
                                      1e-4, 1.0)
    g = y[1] - P.r - (P.l - P.r) * np.cos(y[2])
    assert rc == 0 and k == 0 and abs(g - 1e-14) < 1e-15
    r = V.step_jacobian(z0, P, engine="python")
    assert t == pytest.approx(r["events"][0][0], abs=1e-9)


def test_bad_input_is_named(z0):
    with pytest.raises(pdw.InvalidInputError, match="engine"):
        V.step_jacobian(z0, P, engine="fortran")
    g = pdw.ode_function(P, flags=(1, 1), contact={"friction": "lugre"})
    with pytest.raises(pdw.InvalidInputError, match="Coulomb"):
        _core.cvar_interval(g, P.l, P.r, 0, [], 0.0, np.zeros(10), np.eye(10), 1e-4, 1.0)
    with pytest.raises(pdw.InvalidInputError, match="t_max"):
        V.step_jacobian(z0, P, t_max=0.1)


@pytest.mark.slow
def test_kelvin_voigt_gait_compiled_against_python_and_differences():
    """Kelvin-Voigt (calibrated gait; three rises and two re-entries, its force jumps by
    d * rate): the saltations of the rises are ill-conditioned in the event state (a 1e-11 s
    shift moves them by 1e-3), so the engines' M agree to ~1e-4 of its largest entry and the
    multipliers to 2e-4 (measured 2.3e-5); the flip multiplier -1.4493 as the finite
    differences' to 2e-4."""
    c = pdw.Contact("kelvin_voigt")
    g = pdw.find_gait(P, contact=c, workers=1)
    a = _agree(c, g.details["z"], 2e-4, 2e-3)
    m = np.linalg.eigvals(a["M"])
    assert np.min(np.abs(m - g.multipliers[0])) < 2e-4


def test_continuation_problem_passes_its_contact_law_to_the_exact_monodromy(z0):
    """ContinuousProblem(monodromy="exact") with a law that has approach speeds: before, M was
    asked of the default law (and a 7-coordinate z was refused); now M is the law's, equal to
    the finite differences' to 1e-4 of its largest entry, and dP/dk_hip (the variational
    step's parameter column) to 1e-4 of its size (measured 8e-6)."""
    from pdw.analysis.stepmap.gait_maps import ContinuousProblem
    c = pdw.Contact("flores", e=0.18)
    z = np.r_[z0, 0.3]
    out = {}
    for mono in ("differences", "exact"):
        prob = ContinuousProblem(P, "k_hip", workers=1, options={"contact": c})
        prob.monodromy = mono
        ev = prob.evaluate(z, P.k_hip)
        assert ev.ok, ev.status
        out[mono] = ev
    J = out["differences"].M
    assert out["exact"].M.shape == (7, 7)
    assert np.max(np.abs(out["exact"].M - J)) < 1e-4 * np.abs(J).max()
    d = out["differences"].P_lam
    assert np.max(np.abs(out["exact"].P_lam - d)) < 1e-4 * np.abs(d).max()
