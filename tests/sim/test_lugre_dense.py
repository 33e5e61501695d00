"""LuGre friction everywhere `simulate` goes (docs/contact_laws.md, "LuGre friction"): t_eval
and dense output of the 10-entry state, a RecordBuffer shared with the default law, and
features=."""
import numpy as np
import pytest

import pdw
from pdw.analysis.numerics.calibration import calibrate_lugre
from pdw.core import _core, _layout
from pdw.sim import dense

P = pdw.Params.paper_steady()
NX = _core.NX
NAMES = _layout.STATE_LAYOUTS["lugre"]
#: paper start to just past leg 1's touch-down (0.342 s) and leg 2's lift-off (0.358 s)
T_WALK = 0.36
#: fixed steps that walk with the calibrated LuGre law (docs/contact_laws.md)
DT = {"cdm": 2e-5, "verlet": 1e-5, "rk4": 2e-5, "dopri5": 2e-5, "rodas4": 2e-5}
#: the landing window: from T_LAND, 2.4 ms of double support, leg 1 sliding at 0.28 ... 0.04 m/s
#: while its bristle follows z_ss (relaxation rate sigma0 |v| / g up to 7e4 /s), leg 2 creeping;
#: no flag change, no sign change of either slip velocity
T_LAND, T_WIN = 0.3431, 2.4e-3


@pytest.fixture(scope="module")
def contact():
    return calibrate_lugre(P).contact


def _kw(contact, method, rtol=1e-8, atol=1e-10, **kw):
    tol = dict(rtol=rtol, atol=atol) if method in ("dopri5", "rodas4") else {}
    out = dict(params=P, method=method, dt=DT[method], contact=contact,
               integrator=pdw.Integrator(check_step="off", **tol))
    out.update(kw)
    return out


@pytest.fixture(scope="module")
def landing(contact):
    """The state at T_LAND (both feet in support) and a reference over the window: rk4 at
    dt = 1e-7 (its own error is below 1e-12), every step recorded."""
    x0 = pdw.simulate(t_end=T_LAND, **_kw(contact, "rodas4", rtol=1e-9, atol=1e-11,
                                           record=pdw.Record(every=0))).x_final
    kw = dict(params=P, contact=contact, flags0=(1, 1))
    ref = pdw.simulate(x0, t_end=T_WIN, method="rk4", dt=1e-7,
                       integrator=pdw.Integrator(check_step="off"),
                       record=pdw.Record(dense_output=True), **kw)
    assert ref.events == [] and ref.walked and np.all(ref.flags == 1)
    return x0, kw, ref


@pytest.mark.parametrize("method", pdw.METHODS)
def test_t_eval_at_the_recorded_steps_is_the_recorded_state(method, contact):
    """Every method: t_eval at recorded steps gives the recorded 10-entry states exactly (the
    bristle columns too), the flags, and the forces to 1e-12; across a touch-down, where the
    landing foot's z is reset, the interpolant holds the swing value up to the touch-down."""
    z1 = 3e-6                           # leg 1 swings from the start: its z stays until the reset
    kw = _kw(contact, method, t_end=T_WALK, x0=np.r_[pdw.X0_PAPER, z1, 0.0])
    r = pdw.simulate(record=pdw.Record(dense_output=True), **kw)
    assert r.x.shape[1] == len(NAMES) and r.sol.nx == len(NAMES)
    td = [e for e in r.events if e.kind == "touch_down" and e.leg == 1]
    assert len(td) == 1
    i = int(np.searchsorted(r.t, td[0].t))          # the step where flag 1 became 1
    assert r.flags[i - 1, 0] == 0 and r.flags[i, 0] == 1
    assert r.x[i - 1, 8] == z1 and r.x[i, 8] == 0.0
    pick = np.union1d(r.t[:: max(1, len(r.t) // 60)], r.t[i - 2:i + 3])
    pick = pick[pick <= T_WALK]             # n dt may round past t_end
    s = pdw.simulate(record=pdw.Record(t_eval=pick, energies=True), **kw)
    idx = np.searchsorted(r.t, pick, side="right") - 1
    np.testing.assert_array_equal(s.t, pick)
    np.testing.assert_array_equal(s.x, r.x[idx])
    np.testing.assert_array_equal(s.flags, r.flags[idx])
    np.testing.assert_allclose(s.Fn, r.Fn[idx], rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(s.Ft, r.Ft[idx], rtol=1e-12, atol=1e-9)
    assert [e.t for e in s.events] == [e.t for e in r.events]
    np.testing.assert_allclose(s.energies["E"], pdw.energies(s.x[:, :NX], P)["E"], rtol=1e-13)
    # the interval before the touch-down: swing, z1 frozen at its value (the recorded step at
    # the touch-down holds the reset z1 = 0 and starts the next interval)
    tq = r.t[i - 1] + np.array([0.25, 0.5, 0.75, 0.999]) * (r.t[i] - r.t[i - 1])
    np.testing.assert_allclose(r.sol(tq)[:, 8], z1, rtol=1e-12)
    assert r.sol(r.t[i])[8] == 0.0


@pytest.mark.parametrize("method, dts", [("cdm", (1e-5, 5e-6, 2.5e-6)),
                                         ("verlet", (1e-5, 5e-6, 2.5e-6)),
                                         ("rk4", (4e-5, 2e-5, 1e-5))])
def test_between_steps_converges_with_the_method_order(method, dts, landing):
    """Midway between the steps of the landing window the error falls with the method's order,
    in the mechanical and the bristle columns separately."""
    x0, kw, ref = landing
    order = pdw.core.integrators.get(method).order
    errs = []
    for dt in dts:
        t_mid = (np.arange(int(round(T_WIN / dt))) + 0.5) * dt
        r = pdw.simulate(x0, t_end=T_WIN, method=method, dt=dt,
                         integrator=pdw.Integrator(check_step="off"),
                         record=pdw.Record(t_eval=t_mid), **kw)
        d = np.abs(r.x - ref.sol(t_mid))
        errs.append((d[:, :NX].max(), d[:, NX:].max()))
    errs = np.array(errs)
    observed = np.log2(errs[:-1] / errs[1:])
    assert np.all(observed > order - 0.4) and np.all(observed < order + 1.0), (errs, observed)


@pytest.mark.parametrize("method", ["dopri5", "rodas4"])
def test_adaptive_between_steps_is_as_accurate_as_at_steps(method, landing):
    x0, kw, ref = landing
    mids, ats = [], []
    for rtol in (1e-5, 1e-7, 1e-9):
        r = pdw.simulate(x0, t_end=T_WIN, method=method, dt=1e-6,
                         integrator=pdw.Integrator(rtol=rtol, atol=rtol * 1e-2, check_step="off"),
                         record=pdw.Record(dense_output=True), **kw)
        tm = 0.5 * (r.sol.t[1:] + r.sol.t[:-1])
        dm, da = np.abs(r.sol(tm) - ref.sol(tm)), np.abs(r.x - ref.sol(r.t))
        mids.append((dm[:, :NX].max(), dm[:, NX:].max()))
        ats.append((da[:, :NX].max(), da[:, NX:].max()))
    mids, ats = np.array(mids), np.array(ats)
    assert np.all(mids[0] > 10 * mids[2]), mids
    # as accurate as at the steps, to within an order of magnitude: measured at most 5.6x (the
    # bristle column of dopri5 at rtol 1e-5, relaxing at up to 7e4 /s within a step)
    assert np.all(mids < 10 * ats + 1e-18), (mids, ats)


def _fd_jf(sol, xs, f, h):
    """J f by central differences of the LuGre kernel's right-hand side, step h max(1, |x_j|)
    (what the generated Jacobian does, with its step h)."""
    n, jf = len(xs), np.zeros_like(f)
    for j in range(sol.nx):
        hj = h * np.maximum(1.0, np.abs(xs[:, j]))
        fs = []
        for sgn in (1.0, -1.0):
            xp = np.array(xs)
            xp[:, j] += sgn * hj
            out = np.empty((n, sol.nx))
            _core.rhs_batch(sol._k, xp, sol._p, sol._fl, sol._an, out, np.empty((n, _core.NWORK)))
            fs.append(out)
        jf += (fs[0] - fs[1]) / (2 * hj)[:, None] * f[:, j:j + 1]
    return jf


def _interpolation_errors(ref, order, ks, jacobian=None):
    """Max error over the fine steps between every k-th recorded step of ``ref``, per column
    group (mechanical, bristle), of the interpolant built on those steps alone. ``jacobian``:
    x'' = J f with "kernel" (the generated Jacobian) or a float (central differences with that
    step) instead of the interpolant's own x''."""
    out = []
    for k in ks:
        sol = dense.DenseOutput(ref.t[::k], ref.x[::k], ref.flags[::k], ref.params, "paper",
                                None, order, ref.contact)
        n = len(sol.t) - 1
        for xs, f, name in ((sol.x[:-1], sol.f0, "a0"), (sol._x1, sol.f1, "a1")):
            if jacobian == "kernel":
                J = np.empty((n, sol.nx ** 2))
                _core.jacobian_batch(sol._k, np.ascontiguousarray(xs), sol._p, sol._fl,
                                     sol._an, J, np.empty((n, _core.NWORK)))
                setattr(sol, name, np.einsum("nij,nj->ni", J.reshape(n, sol.nx, sol.nx), f))
            elif jacobian is not None:
                setattr(sol, name, _fd_jf(sol, np.ascontiguousarray(xs), f, jacobian))
        m = np.ones(len(ref.t), bool)
        m[::k] = False
        m[np.searchsorted(ref.t, sol.t[-1]):] = False
        d = np.abs(sol(ref.t[m]) - ref.x[m])
        out.append((d[:, :NX].max(), d[:, NX:].max()))
    return np.array(out)


def test_interpolant_order_on_the_lugre_state(landing):
    """The interpolant itself, on exact data (every k-th step of the fine reference, h = k e-7
    s): the cubic is fourth order, the quintic sixth, in every column group. The quintic's x''
    is a fourth-order difference of f along f with a step h/8 (`DenseOutput._along`); x'' =
    J f with the LuGre kernel's Jacobian (central differences, step sqrt(eps) max(1, |x|))
    gives the same order and accuracy. The control: J by central differences with the step
    cbrt(eps) = 6e-6 max(1, |x|) that the kernel used before, larger than the creeping foot's
    3e-6 m/s slip, straddles the kink of |v|: second order and, at h = 6.4e-5 s, 100 times less
    accurate in q, qd (10 times in z)."""
    ref = landing[2]
    ks = (640, 1280, 2560)
    cubic = _interpolation_errors(ref, 3, (160, 320, 640, 1280))
    quintic = _interpolation_errors(ref, 5, ks)
    kernel = _interpolation_errors(ref, 5, ks, jacobian="kernel")
    old = _interpolation_errors(ref, 5, ks, jacobian=6.0554544523933395e-06)
    o3 = np.log2(cubic[1:] / cubic[:-1])
    o5 = np.log2(quintic[1:] / quintic[:-1])
    ok = np.log2(kernel[1:] / kernel[:-1])
    oold = np.log2(old[1:] / old[:-1])
    assert np.all((o3 > 3.6) & (o3 < 4.5)), (cubic, o3)
    assert np.all((o5 > 5.2) & (o5 < 6.5)), (quintic, o5)
    assert np.all((ok > 5.2) & (ok < 6.5)), (kernel, ok)
    assert np.all(kernel < 1.5 * quintic) and np.all(quintic < 1.5 * kernel), (kernel, quintic)
    assert np.all(oold[:, 0] < 3.0), (old, oold)
    assert old[0, 0] > 100 * quintic[0, 0] and old[0, 1] > 10 * quintic[0, 1], (old, quintic)


# --- out = RecordBuffer --------------------------------------------------------------------------

@pytest.mark.parametrize("method", ["cdm", "rodas4"])
def test_record_buffer_shared_by_lugre_and_the_default_law(method, contact):
    """One buffer, reused by a LuGre run and a default run in either order, gives the arrays of
    fresh runs, as views into the same memory (nothing reallocated when the width changes)."""
    tol = dict(rtol=1e-8, atol=1e-10) if method == "rodas4" else {}
    kw = dict(params=P, t_end=0.2, method=method, dt=2e-5,
              integrator=pdw.Integrator(check_step="off", **tol))
    fresh = {law: pdw.simulate(contact=c, **kw) for law, c in (("lugre", contact),
                                                               ("default", None))}
    for first, second in (("lugre", "default"), ("default", "lugre")):
        buf = pdw.RecordBuffer(12000)
        store = buf._states
        for law in (first, second, first):
            r = pdw.simulate(contact=contact if law == "lugre" else None,
                             record=pdw.Record(out=buf), **kw)
            for name in ("t", "x", "flags", "Fn", "Ft"):
                np.testing.assert_array_equal(getattr(r, name), getattr(fresh[law], name))
            assert r.x.shape[1] == (len(NAMES) if law == "lugre" else NX)
            assert np.shares_memory(r.x, store) and np.shares_memory(r.t, buf.t)
        assert buf._states is store and buf.capacity == 12000


def test_record_buffer_of_the_default_law_unchanged():
    """The default law's buffer is what it was: x (capacity, 8), the same run, no realloc."""
    buf = pdw.RecordBuffer(100)
    assert buf.x.shape == (100, NX)
    r = pdw.simulate(t_end=0.005, record=pdw.Record(out=buf))
    x = buf.x
    r2 = pdw.simulate(t_end=0.005, record=pdw.Record(out=buf))
    assert buf.x is x and np.shares_memory(r2.x, x)
    np.testing.assert_array_equal(r.x, pdw.simulate(t_end=0.005).x)


def test_record_buffer_refuses_foreign_arrays_of_the_wrong_width(contact):
    buf = pdw.RecordBuffer(600)
    buf.x = np.zeros((600, NX))                   # the user's own array: not re-viewed
    with pytest.raises(pdw.InvalidInputError, match=r"out.x .*\(600, 10\)"):
        pdw.simulate(params=P, t_end=0.005, dt=2e-5, contact=contact,
                     integrator=pdw.Integrator(check_step="off"), record=pdw.Record(out=buf))


# --- features ---------------------------------------------------------------------------------

def _without(*absent):
    return tuple(f for f in _layout.FEATURES if f not in absent)


def test_features_without_tangential_is_lugre_alone(contact):
    """Without ``tangential`` (the spring-damper of Eqs. 7, 11) the run is the LuGre kernel with
    k_t = d_t = 0, and the tangential force is LuGre's, -(sigma0 z + sigma1 dz/dt + sigma2 v)
    F_n, recomputed here from the recorded states; with it (the control), it is not."""
    kw = dict(params=P, t_end=0.4, dt=2e-5, method="rk4", contact=contact,
              integrator=pdw.Integrator(check_step="off"))
    a = pdw.simulate(features=_without("tangential"), **kw)
    b = pdw.simulate(**dict(kw, params=P.replace(k_t=0.0, d_t=0.0)))
    assert a.contact == contact and a.x.shape[1] == len(NAMES)
    for name in ("x", "Fn", "Ft"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    full = pdw.simulate(**kw)
    lp = contact.lugre_parameters(P)

    def lugre_force(r):
        v = pdw.contact_forces(r.x, r.params, flags=r.flags, contact=contact).v_x
        z = r.x[:, NX:]
        g = lp["mu_c"] + (lp["mu_s"] - lp["mu_c"]) * np.exp(-(v / lp["v_s"]) ** 2)
        zdot = v - lp["sigma0"] * np.abs(v) * z / g
        return -(lp["sigma0"] * z + lp["sigma1"] * zdot + lp["sigma2"] * v) * r.Fn

    assert (a.Fn > 0).sum() > 1000
    np.testing.assert_allclose(a.Ft, lugre_force(a), rtol=1e-12, atol=1e-12)
    assert np.abs(full.Ft - lugre_force(full)).max() > 1.0
    # t_eval with features: the recorded steps, exactly
    s = pdw.simulate(features=_without("tangential"), record=pdw.Record(t_eval=a.t[::500]), **kw)
    np.testing.assert_array_equal(s.x, a.x[::500])


@pytest.mark.parametrize("absent", [("hip_spring", "hip_damper"), ("normal_damping",)])
def test_features_of_the_walker_and_the_normal_law_under_lugre(absent, contact):
    """The elements outside the friction law mean what they mean under the default law: their
    parameters zeroed (`Params.without`) on the LuGre kernel."""
    kw = dict(t_end=0.2, dt=2e-5, method="rk4", contact=contact,
              integrator=pdw.Integrator(check_step="off"))
    a = pdw.simulate(params=P, features=_without(*absent), **kw)
    b = pdw.simulate(params=P.without(_without(*absent)), **kw)
    np.testing.assert_array_equal(a.x, b.x)
    assert a.x.shape[1] == len(NAMES) and a.params == P.without(_without(*absent))


@pytest.mark.parametrize("normal", ["hunt_crossley", "flores"])
def test_features_without_friction_drops_the_bristles(normal, contact):
    """Without ``friction`` there is no friction force, so no bristle: the run is the normal law
    with the default friction law switched off, 8-entry state, `Result.contact` saying so; a
    10-entry x0 loses its z. Without ``tangential`` too, F_t is 0."""
    c = (contact if normal == "hunt_crossley" else
         pdw.Contact("flores", friction="lugre", e=0.18, sigma1=contact.sigma1))
    plain = pdw.Contact(normal, e=c.e)
    kw = dict(params=P, t_end=0.3, dt=2e-5, method="rk4", integrator=pdw.Integrator(check_step="off"))
    a = pdw.simulate(contact=c, features=_without("friction"), **kw)
    b = pdw.simulate(contact=plain, features=_without("friction"), **kw)
    assert a.contact == plain and a.x.shape[1] == NX and a.state_names == pdw.STATE
    for name in ("x", "Fn", "Ft"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    x10 = np.r_[pdw.X0_PAPER, 1e-6, -1e-6]
    np.testing.assert_array_equal(
        pdw.simulate(x10, contact=c, features=_without("friction"), **kw).x, a.x)
    none = pdw.simulate(contact=c, features=_without("friction", "tangential"), **kw)
    assert (none.Fn > 0).any() and not none.Ft.any()
    # the step-size check is the normal law's (no bristle damping to limit the step)
    with pytest.warns(pdw.StepSizeWarning):
        pdw.simulate(params=P, t_end=0.01, dt=2e-4, contact=c,
                     integrator=pdw.Integrator(check_step="warn"))
    pdw.simulate(params=P, t_end=0.01, dt=2e-4, contact=c, features=_without("friction"),
                 integrator=pdw.Integrator(check_step="error"))


def test_contact_forces_evaluates_the_lugre_kernel(contact):
    """`pdw.contact_forces(contact=LuGre)` takes the 10-entry state and gives the run's forces
    (it gave the Coulomb kernel's for 8 entries before)."""
    r = pdw.simulate(params=P, t_end=0.05, dt=2e-5, method="rk4", contact=contact,
                     integrator=pdw.Integrator(check_step="off"))
    cs = pdw.contact_forces(r.x, r.params, flags=r.flags, contact=contact)
    np.testing.assert_array_equal(cs.F_t, r.Ft)
    with pytest.raises(pdw.InvalidInputError, match="x"):
        pdw.contact_forces(r.x[:, :NX], r.params, flags=r.flags, contact=contact)
