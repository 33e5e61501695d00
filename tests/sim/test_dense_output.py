"""simulate(record=Record(t_eval=..., dense_output=True)): the interpolant between accepted
steps."""

import numpy as np
import pytest

import pdw
from pdw.sim import dense
from pdw.sim.buffers import RecordBuffer

# flight: both feet swing, hip 1.5 m above the slope; smooth (gravity, hip spring and damper),
# no flag change within T
X_FLIGHT = np.array([0.0, 1.5, -0.3, 0.25, 0.4, 0.5, 2.0, -1.5])
T = 0.3
KW = dict(flags0=(0, 0), limits=pdw.Limits(fall_hip_height=0.1))


@pytest.fixture(scope="module")
def reference():
    r = pdw.simulate(X_FLIGHT, t_end=T, method="rodas4", dt=1e-6,
                     integrator=pdw.Integrator(rtol=1e-12, atol=1e-14, check_step="off"),
                     record=pdw.Record(dense_output=True), **KW)
    assert r.events == [] and r.walked
    return r


@pytest.mark.parametrize("method", pdw.METHODS)
def test_t_eval_at_the_recorded_steps_is_the_recorded_state(method):
    dt = 1e-3
    r = pdw.simulate(pdw.X0_PAPER, t_end=0.4, method=method,
                     dt=2e-6 if method in ("rk4", "dopri5")
                     else dt,
                     integrator=pdw.Integrator(check_step="off"),
                     record=pdw.Record(dense_output=True))
    pick = r.t[:: max(1, len(r.t) // 50)]
    s = pdw.simulate(pdw.X0_PAPER, t_end=0.4, method=method,
                     dt=2e-6 if method in ("rk4", "dopri5")
                     else dt,
                     integrator=pdw.Integrator(check_step="off"), record=pdw.Record(t_eval=pick))
    np.testing.assert_array_equal(s.t, pick)
    idx = np.searchsorted(r.t, pick, side="right") - 1
    np.testing.assert_array_equal(s.x, r.x[idx])
    np.testing.assert_array_equal(s.flags, r.flags[idx])
    np.testing.assert_allclose(s.Fn, r.Fn[idx], rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(s.Ft, r.Ft[idx], rtol=1e-12, atol=1e-9)
    assert len(r.events) > 0 and [e.t for e in s.events] == [e.t for e in r.events]


@pytest.mark.parametrize("method, dts", [("cdm", (4e-3, 2e-3, 1e-3)), ("verlet", (4e-3, 2e-3, 1e-3)),
                                         ("rk4", (2e-2, 1e-2, 5e-3))])
def test_between_steps_converges_with_the_method_order(method, dts, reference):
    order = pdw.core.integrators.get(method).order
    errs = []
    for dt in dts:
        t_mid = (np.arange(int(round(T / dt))) + 0.5) * dt      # midway between steps
        r = pdw.simulate(X_FLIGHT, t_end=T, method=method, dt=dt,
                         integrator=pdw.Integrator(check_step="off"),
                         record=pdw.Record(t_eval=t_mid), **KW)
        errs.append(np.max(np.abs(r.x - reference.sol(t_mid))))
    observed = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(observed > order - 0.4) and np.all(observed < order + 1.0), (errs, observed)


@pytest.mark.parametrize("method", ["dopri5", "rodas4"])
def test_adaptive_between_steps_is_as_accurate_as_at_steps(method, reference):
    """Adaptive methods: at each tolerance the error midway between accepted steps is within
    a small factor of the error at the steps, and both fall with the tolerance."""
    mids, ats = [], []
    for rtol in (1e-5, 1e-7, 1e-9):
        r = pdw.simulate(X_FLIGHT, t_end=T, method=method, dt=1e-4,
                         integrator=pdw.Integrator(rtol=rtol, atol=rtol * 1e-2, check_step="off"),
                         record=pdw.Record(dense_output=True), **KW)
        tm = 0.5 * (r.sol.t[1:] + r.sol.t[:-1])
        mids.append(np.max(np.abs(r.sol(tm) - reference.sol(tm))))
        ats.append(np.max(np.abs(r.x - reference.sol(r.t))))
    assert mids[0] > 10 * mids[2], mids
    assert all(m < 5 * a + 1e-12 for m, a in zip(mids, ats)), (mids, ats)


def test_quintic_interpolant_is_exact_for_quintics():
    """The basis reproduces a degree-5 polynomial from values and two derivatives."""
    t = np.array([0.0, 0.7, 1.5])
    c = np.arange(1, 7.0)
    P = np.polynomial.Polynomial(c)
    sol = dense.DenseOutput.__new__(dense.DenseOutput)
    sol.t, sol.order = t, 5
    sol.x = np.repeat(P(t)[:, None], 8, axis=1)
    sol.f0 = sol.f1 = None
    d1, d2 = P.deriv(1), P.deriv(2)
    sol.f0 = np.repeat(d1(t[:-1])[:, None], 8, axis=1)
    sol.f1 = np.repeat(d1(t[1:])[:, None], 8, axis=1)
    sol.a0 = np.repeat(d2(t[:-1])[:, None], 8, axis=1)
    sol.a1 = np.repeat(d2(t[1:])[:, None], 8, axis=1)
    tq = np.linspace(0, 1.5, 37)
    np.testing.assert_allclose(sol(tq)[:, 3], P(tq), rtol=1e-12)


@pytest.mark.parametrize("bad", [[0.2, 0.1], [-0.1], [0.0, 99.0], [[0.1]], [np.nan]])
def test_bad_t_eval_is_refused(bad):
    with pytest.raises(pdw.InvalidInputError, match="t_eval"):
        pdw.simulate(t_end=0.5, record=pdw.Record(t_eval=bad))


def test_t_eval_needs_every_step_recorded():
    with pytest.raises(pdw.InvalidInputError, match=r"record\.every"):
        pdw.simulate(t_end=0.5, record=pdw.Record(t_eval=[0.1], every=10))


@pytest.mark.parametrize("method", ["cdm", "rodas4"])
def test_record_buffer_gives_the_same_run(method):
    buf = pdw.RecordBuffer()
    fresh = pdw.simulate(t_end=0.8, method=method, integrator=pdw.Integrator(check_step="off"))
    a = pdw.simulate(t_end=0.8, method=method, integrator=pdw.Integrator(check_step="off"),
                     record=pdw.Record(out=buf))
    for k in ("t", "x", "flags", "Fn", "Ft"):
        np.testing.assert_array_equal(getattr(a, k), getattr(fresh, k))
    if method == "cdm":
        assert np.shares_memory(a.x, buf.x)
        b = pdw.simulate(t_end=0.8, x0=pdw.X0_DISTURBED, method=method,
                         integrator=pdw.Integrator(check_step="off"), record=pdw.Record(out=buf))
        assert np.array_equal(a.x, b.x)          # a view: overwritten by the next run
    with pytest.raises(pdw.InvalidInputError, match="out"):
        pdw.simulate(t_end=0.1, record=pdw.Record(out=np.zeros(3)))


@pytest.mark.parametrize("method", pdw.METHODS)
@pytest.mark.parametrize("contact", [pdw.Contact("flores", e=0.18),
                                     pdw.Contact("lankarani_nikravesh", e=0.9),
                                     pdw.Contact("kelvin_voigt", k=7318.0, d=112.0)])
def test_t_eval_with_another_normal_law_is_the_recorded_run(method, contact):
    """t_eval at the recorded steps gives the recorded states and forces with every normal law:
    the approach speeds captured at the touch-downs are part of what the interpolant sees."""
    kw = dict(t_end=0.8, method=method, dt=2e-6 if method in ("rk4", "dopri5") else 1e-4,
              integrator=pdw.Integrator(check_step="off"), contact=contact)
    r = pdw.simulate(pdw.X0_PAPER, record=pdw.Record(dense_output=True), **kw)
    assert sum(e.kind == "touch_down" and e.leg == 1 for e in r.events) >= 1
    pick = r.t[:: max(1, len(r.t) // 60)]
    s = pdw.simulate(pdw.X0_PAPER, record=pdw.Record(t_eval=pick), **kw)
    idx = np.searchsorted(r.t, pick, side="right") - 1
    np.testing.assert_array_equal(s.x, r.x[idx])
    np.testing.assert_allclose(s.Fn, r.Fn[idx], rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(s.Ft, r.Ft[idx], rtol=1e-12, atol=1e-9)
    if contact.normal != "kelvin_voigt":
        # without the captured approach speeds (v_in -> v_in_min) the stance forces differ:
        # the test above sees them
        an = r.sol.anchors.copy()
        an[:, 2:] = 0.0
        stance = (r.flags[:, 0] == 1) & (r.Fn[:, 0] > 1.0)
        i = np.flatnonzero(stance)[len(np.flatnonzero(stance)) // 2]
        c_ok = pdw.contact_forces(r.x[i], r.params, flags=tuple(r.flags[i]),
                                  anchors=tuple(r.sol.anchors[i]), contact=contact)
        c_no = pdw.contact_forces(r.x[i], r.params, flags=tuple(r.flags[i]),
                                  anchors=tuple(an[i]), contact=contact)
        assert c_ok.F_n[0] == pytest.approx(r.Fn[i, 0], rel=1e-12)
        assert abs(c_no.F_n[0] - r.Fn[i, 0]) > 1e-3 * r.Fn[i, 0]


@pytest.mark.parametrize("cap", [-1, "x", 1.5, float("nan"), 2 ** 41, None])
def test_record_buffer_capacity_is_checked(cap):
    with pytest.raises(pdw.InvalidInputError, match="capacity"):
        RecordBuffer(cap)


def test_a_well_formed_record_buffer_still_gives_the_same_run():
    b = RecordBuffer(10)
    r1 = pdw.simulate(t_end=0.01, record=pdw.Record(out=b))
    r2 = pdw.simulate(t_end=0.01)
    assert np.array_equal(r1.x, r2.x) and b.capacity >= len(r2.t)


@pytest.mark.parametrize("kw,field", [(dict(t_eval=np.array([0.01 + 1j])), "t_eval"),
                                      (dict(t_eval=[0.0, float("nan")]), "t_eval"),
                                      (dict(dense_output="yes"), "dense_output")])
def test_dense_output_arguments_are_strict(kw, field):
    """A complex t_eval was its real part; dense_output="yes" was True."""
    with pytest.raises(pdw.InvalidInputError, match=field):
        pdw.simulate(t_end=0.02, method="rodas4", record=kw)     # the table, read by simulate


@pytest.mark.parametrize("tq", ["0.01", 0.01 + 1j, np.full((2, 2), 0.01), float("nan"), 5.0])
def test_dense_interpolant_refuses_bad_times(tq):
    """sol("0.01") was parsed; complex and 2-D times gave raw TypeError / ValueError."""
    sol = pdw.simulate(t_end=0.02, method="rodas4", record=pdw.Record(dense_output=True)).sol
    with pytest.raises(pdw.InvalidInputError, match="t"):
        sol(tq)
    assert sol(0.01).shape == (8,) and sol([0.005, 0.01]).shape == (2, 8)
