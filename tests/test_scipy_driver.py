"""The scipy driver of the work-precision benchmark (benchmarks/scipy_driver.py): scipy's
solve_ivp on pdw's compiled f and Jacobian, the flag switches of docs/model.md section 5 as terminal
events. The comparison in docs/work_precision.md is fair only if the driver integrates the same
hybrid system as pdw's loops: same switch rules, same event times."""
import numpy as np
import pytest

import pdw

pytest.importorskip("scipy")
from benchmarks.scipy_driver import Discrete, Model, simulate_scipy, update_flags  # noqa: E402

T_END = 1.0


@pytest.fixture(scope="module")
def rodas4_events():
    r = pdw.simulate(method="rodas4", t_end=T_END,
                     integrator=pdw.Integrator(rtol=1e-10, atol=1e-12), record=pdw.Record(every=0))
    assert r.walked
    return r


@pytest.mark.parametrize("method", ["LSODA", "Radau"])
def test_touch_down_times_match_pdw_rodas4(rodas4_events, method):
    """Every touch-down and lift-off of the typical gait's first second, same leg, same kind,
    at pdw rodas4's times within 1e-5 s; the final state agrees too."""
    s = simulate_scipy(method, t_end=T_END, rtol=1e-8, atol=1e-10)
    assert s.status == "walked" and s.t_final == T_END
    ref = rodas4_events.events
    assert [(e.leg, e.kind) for e in s.events] == [(e.leg, e.kind) for e in ref]
    tds = [(a.t, b.t) for a, b in zip(s.events, ref) if b.kind == "touch_down"]
    assert len(tds) >= 1
    for ta, tb in tds:
        assert abs(ta - tb) < 1e-5
    for a, b in zip(s.events, ref):
        assert abs(a.t - b.t) < 1e-5 and abs(a.x_D - b.x_D) < 1e-5
    assert np.abs(s.x_final - rodas4_events.x_final).max() < 1e-5
    assert s.stats["rhs"] > 0 and s.stats["segments"] > len(ref)  # arming switches restart too


def test_update_flags_mirrors_the_c_rules():
    """One pass of update_flags on hand-made kinematics follows pdw_update_flags rule by rule."""
    from pdw.core import _layout
    K = {n: i for i, n in enumerate(_layout.KIN)}

    def kin(xd1, y1, vy1, xd2, y2, vy2, s1=0.1, s2=0.2):
        k = np.zeros((2, len(_layout.KIN)))
        for i, (xd, y, vy, s) in enumerate(((xd1, y1, vy1, s1), (xd2, y2, vy2, s2))):
            k[i, K["x_D"]], k[i, K["y_D"]], k[i, K["v_y"]], k[i, K["s"]] = xd, y, vy, s
        return k

    ev = []
    d = Discrete(flags=[0, 1])                       # swing foot behind: stays unarmed
    update_flags(kin(-0.1, 0.01, 0.1, 0.0, -0.001, 0.0), d, 0.0, ev)
    assert (d.flags, d.armed, ev) == ([0, 1], [0, 0], [])
    update_flags(kin(0.1, 0.01, -0.1, 0.0, -0.001, 0.0), d, 0.1, ev)   # ahead and above: armed
    assert d.armed == [1, 0] and ev == []
    update_flags(kin(0.2, -1e-6, -0.1, 0.0, -0.001, 0.0), d, 0.2, ev)  # armed, down, moving down
    assert d.flags == [1, 1] and d.armed == [0, 0] and d.anchors[0] == 0.1
    assert [(e.leg, e.kind) for e in ev] == [(1, "touch_down")]
    update_flags(kin(0.2, -1e-3, 0.0, 0.0, 1e-6, 0.1), d, 0.3, ev)     # rear foot up, moving up
    assert d.flags == [1, 0] and [(e.leg, e.kind) for e in ev][-1] == (2, "lift_off")
    # an armed foot that falls behind the other is disarmed before it can touch down
    d = Discrete(flags=[0, 1], armed=[1, 0])
    update_flags(kin(-0.1, -1e-6, -0.1, 0.0, -0.001, 0.0), d, 0.0, ev)
    assert d.flags == [0, 1] and d.armed == [0, 0]


def test_model_wrapper_is_pdw_rhs_and_jacobian():
    m = Model(pdw.Params.paper(), "paper")
    m.set_discrete((0, 1), (0.0, 0.03))
    x = np.array(pdw.X0_PAPER)
    np.testing.assert_array_equal(m.fun(0.0, x), pdw.rhs(x, flags=(0, 1), anchors=(0.0, 0.03)))
    np.testing.assert_array_equal(m.jac(0.0, x), pdw.jacobian(x, flags=(0, 1), anchors=(0.0, 0.03)))
    c = pdw.contact_forces(x, flags=(0, 1), anchors=(0.0, 0.03))
    k = m.kinematics(x)
    np.testing.assert_array_equal(k[:, 1], c.y_D)
    np.testing.assert_array_equal(k[:, 3], c.v_y)
