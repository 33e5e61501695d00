"""The exact monodromy for every contact law with Coulomb friction (issue #24 item 2):
`pdw.ode_function(contact=...)` and `variational.step_jacobian(contact=...)` against finite
differences of the compiled step map."""
import numpy as np
import pytest

import pdw
from pdw.analysis.stepmap import limit_cycle as LC
from pdw.analysis.stepmap import variational as V

pytest.importorskip("scipy")


def test_ode_function_reaches_every_law():
    """Each law's kernel: f differs from the default law's in contact, its Jacobian matches
    central differences of f; LuGre has 10 states, NaN in gives NaN out; a bad law is named."""
    x = np.array(pdw.X0_PAPER)
    x[1] -= 2e-3                                # both feet 2 mm in the ground
    f0 = pdw.ode_function(flags=(1, 1))(0.0, x)
    for law in ("hertz", "kelvin_voigt", {"normal": "flores", "e": 0.2}):
        f = pdw.ode_function(flags=(1, 1), contact=law, approach_speeds=(0.3, 0.3))
        assert f.nx == 8 and np.max(np.abs(f(0.0, x) - f0)) > 1e-3
        J = f.jac(0.0, x)
        Jn = np.column_stack([(f(0.0, x + e) - f(0.0, x - e)) / 2e-7 for e in np.eye(8) * 1e-7])
        assert np.max(np.abs(J - Jn)) < 1e-4 * np.abs(J).max()
    g = pdw.ode_function(flags=(1, 1), contact={"friction": "lugre"})
    assert g.nx == 10 and g.jac(0.0, np.r_[x, 0.0, 0.0]).shape == (10, 10)
    assert np.isnan(g(0.0, np.r_[x, np.nan, 0.0])).all()
    with pytest.raises(pdw.InvalidInputError, match="shape"):
        g(0.0, x)
    with pytest.raises(pdw.InvalidInputError, match="contact.normal"):
        pdw.ode_function(contact="rubber")


def test_flores_exact_monodromy_with_its_approach_speed():
    """Flores (e = 0.18): the seventh section coordinate (the trailing foot's approach speed)
    differentiated too; M equals central differences (1e-5 and 1e-6 agree to 1.4e-4) to 1e-4."""
    P = pdw.Params.paper_steady()
    c = pdw.Contact("flores", e=0.18)
    z = pdw.find_gait(P, contact=c, workers=1).details["z"]
    r = V.step_jacobian(z, P, contact=c)
    J5, Pz, _ = LC.jacobian(z, P, fd_step=1e-5, **LC.TIGHT, contact=c, workers=1)
    J6, _, _ = LC.jacobian(z, P, fd_step=1e-6, **LC.TIGHT, contact=c, workers=1)
    assert r["M"].shape == (7, 7) and np.max(np.abs(r["z"] - Pz)) < 1e-8
    assert np.max(np.abs(J5 - J6)) < 1e-3
    assert np.max(np.abs(r["M"] - J5)) < 1e-4 * np.abs(J5).max()


def test_lugre_is_refused_with_the_reason():
    with pytest.raises(pdw.InvalidInputError, match="lugre"):
        V.step_jacobian(np.zeros(7), pdw.Params.paper_steady(), contact={"friction": "lugre"})


@pytest.mark.slow
def test_kelvin_voigt_exact_monodromy_through_its_force_jumps():
    """Kelvin-Voigt (calibrated): the trailing foot starts above the ground, the stance foot
    rises and re-enters twice (its force jumps by d * rate): M equals central differences to
    1.2e-3 (their own spread) and the flip multiplier -1.4494 to 1e-4. With the one-sided
    limits taken 1e-9 s along f (the first version) M was off by 0.2."""
    P = pdw.Params.paper_steady()
    c = pdw.Contact("kelvin_voigt")
    g = pdw.find_gait(P, contact=c, workers=1)
    z = g.details["z"]
    r = V.step_jacobian(z, P, contact=c)
    J5, _, _ = LC.jacobian(z, P, fd_step=1e-5, **LC.TIGHT, contact=c, workers=1)
    assert [e[1] for e in r["events"]].count("reentry") == 2
    assert np.max(np.abs(r["M"] - J5)) < 2e-3
    m = np.linalg.eigvals(r["M"])
    assert np.min(np.abs(m - g.multipliers[0])) < 1e-4
