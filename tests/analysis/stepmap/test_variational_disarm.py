"""The exact step arms and disarms a swing foot as the compiled loop does (pdw_discrete.c,
pdw_update_flags: a swing foot whose contact point is not ahead of the other one's,
x_D,i <= x_D,j, is disarmed; one ahead and above the ground is armed, at once after its
lift-off too). Before, `variational.step_jacobian` armed a swing foot only when its contact
point passed the other one's forwards, and never disarmed it: an armed foot that swung back
behind the stance foot and came down there touched down behind it and ended the step, and a
foot that lifted off ahead of the other one never touched down again."""
import numpy as np
import pytest

import pdw
from pdw.analysis.stepmap import section as S
from pdw.analysis.stepmap import variational as V

P0 = pdw.Params.paper_steady()
#: hopping states of the paper_steady walker (found by a random search around the default
#: gait's section point, -0.36608, 0.38201 being its angles), each with the law and the
#: parameters:
CASES = {
    # Hertz, k_n = 1e6: both feet leave the ground, leg 1 swings ahead (armed) and back behind
    # leg 2 (disarmed, 0.40641 s) before it comes down; leg 2 lands twice and leg 1 touches
    # down ahead of it at 1.04519 s. Before: leg 1 down behind leg 2 at 0.4292 s (state 3.2 away)
    "disarm": (np.array([-0.366078651622521, 0.38201488019766894, 2.419019273326961,
                         -1.032550974039524, 1.5556159131309388, -2.7496003862317147]),
               P0.replace(k_n=1e6), pdw.Contact("hertz")),
    # the default law: leg 2 lifts off at once, ahead of leg 1 (armed), lands at 0.0935 s, and
    # leg 1 touches down at 0.22793 s. Before: leg 2, never armed, passed through the ground
    # ("no touch-down by t_max")
    "lift_off_ahead": (np.array([-0.366078651622521, 0.38201488019766894, 1.7929178134632795,
                                 0.5670424402353061, -0.10394058395202166,
                                 -0.45256800879813286]), P0, None),
}


def _simulated(z, P, c):
    """The compiled loop's own step (pdw.simulate, rodas4 at the step map's tolerances, fall
    limits relaxed: the walker hops): leg 1's first touch-down, the state there, the events."""
    x0, _ = S.start(z, P, c, "paper")
    res = pdw.simulate(x0, 2.5, 1e-4, params=P, flags0=(1, 1), contact=c,
                       limits=pdw.Limits(fall_hip_height=-10.0, fall_depth=10.0,
                                         on_failure="return"),
                       integrator=pdw.Integrator(method="rodas4", rtol=1e-10, atol=1e-12,
                                                 event_tol=1e-12),
                       record=pdw.Record(every=1))
    td = next(e for e in res.events if e.leg == 1 and e.kind == "touch_down")
    return td.t, res.x[int(np.argmin(np.abs(res.t - td.t)))], [
        (e.kind, e.leg) for e in res.events if e.t <= td.t]


@pytest.mark.parametrize("engine", ["compiled", "python"])
@pytest.mark.parametrize("case", sorted(CASES))
def test_the_step_ends_where_the_compiled_loop_touches_down(case, engine):
    """Both engines end the step at the compiled loop's touch-down, through the same flag
    switches (measured: T to 1e-9 s, the state to 2e-8)."""
    z, P, c = CASES[case]
    t_td, x_td, sim_events = _simulated(z, P, c)
    r = V.step_jacobian(z, P, contact=c, engine=engine, max_events=80)
    assert abs(r["T"] - t_td) < 1e-6
    np.testing.assert_allclose(r["x"], x_td, atol=1e-6)
    switches = [(kind, leg) for _, kind, leg in r["events"] if kind in ("lift_off", "touch_down")]
    assert switches + [("touch_down", 1)] == sim_events
    if case == "disarm":
        assert ("disarm", 1) in [(kind, leg) for _, kind, leg in r["events"]]


def test_the_disarm_event_is_in_both_engines_event_lists():
    """Unit level: an armed swing foot has its backward "ahead" crossing as an event (slots 6,
    7 of the compiled engine's list, pdw_cvar.h's PDW_CVAR_EV_AHEAD with direction -1); a
    support foot and an unarmed one have none."""
    flags, pending, sunk, gate = [0, 1], [False, False], [False, False], [0.0, 0.0]
    specs = V._specs(flags, pending, [True, False], gate, sunk)
    assert len(specs) == 8
    assert specs[6] == (V._EV_AHEAD, 0, -1.0) and specs[7][0] == V._EV_NONE
    assert V._specs(flags, pending, [False, False], gate, sunk)[6][0] == V._EV_NONE
    assert V._specs([1, 1], pending, [True, True], gate, sunk)[6][0] == V._EV_NONE
