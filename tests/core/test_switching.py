"""The support-flag switching rules of Eq. 18 and the scuffing guard (docs/model.md section 5),
checked directly against a Python reference of the rules, not against another copy of the C.

The compiled loops update the flags once per step from (U_n, U'_n) (docs/model.md section 7),
before the step's forces, and record the sample with the updated flags. `_replay` applies the
rules of section 5 in Python to every recorded state, with the kinematics y_D, v_y, x_D of
`pdw.contact_forces` (Eqs. 4, 5 and 9 of the variant in use), and must give the recorded flags
at every sample, and the recorded contact forces with the anchors it captured at each touch-down.
The states are crafted to straddle every threshold: a foot 1e-6..3e-5 m from the ground, moving
up or down at a few cm/s to 1 m/s, feet a fraction of a millimetre up- or downhill of each other,
so that each branch of each rule is taken, and not taken, within three steps of 0.1 ms
(asserted: the test cannot pass vacuously).
"""
import numpy as np
import pytest

import pdw

P = pdw.Params.paper()
DT = 1e-4


def _kin(x, variant):
    c = pdw.contact_forces(x, P, flags=(1, 1), variant=variant)
    return c.y_D, c.v_y, c.x_D, c.s


def _reference_update(flags, armed, anchors, y, vy, xd, s, seen):
    """docs/model.md section 5, in order, for each leg: lift-off (18a); else disarm, arm,
    touch-down (18b), from one state's y_D, v_y, x_D, s (each (2,)). Updates flags, armed,
    anchors in place; counts the branches in `seen`."""
    for i in range(2):
        j = 1 - i
        if flags[i]:
            if y[i] > 0.0 and vy[i] > 0.0:
                flags[i], armed[i] = 0, 0
                seen["lift_off"] += 1
            else:
                seen["stays_support"] += 1
                seen["support_above_moving_down" if y[i] > 0.0 else "support_below"] += 1
            continue
        if xd[i] <= xd[j]:
            seen["disarmed" if armed[i] else "uphill_unarmed"] += 1
            armed[i] = 0
        elif y[i] > 0.0:
            seen["armed"] += 1
            armed[i] = 1
        if armed[i] and y[i] < 0.0 and vy[i] < 0.0:
            flags[i], armed[i] = 1, 0
            anchors[i] = s[i]
            seen["touch_down"] += 1
        elif y[i] < 0.0:
            seen["below_no_touch_down_" + ("unarmed" if not armed[i] else "moving_up")] += 1


def _replay(r, flags0, variant, seen):
    """Check every recorded sample of r against the reference rules (flags, and the forces
    with the reference's anchors)."""
    y, vy, xd, s = (a.tolist() for a in _kin(r.x, variant))
    flags, armed = list(flags0), [0, 0]
    anchors = [s[0][i] if flags0[i] else 0.0 for i in range(2)]
    F, A = np.empty((len(r.t), 2), dtype=int), np.empty((len(r.t), 2))
    for n in range(len(r.t)):
        _reference_update(flags, armed, anchors, y[n], vy[n], xd[n], s[n], seen)
        F[n], A[n] = flags, anchors
    bad = np.nonzero((F != r.flags).any(axis=1))[0]
    assert len(bad) == 0, (bad[0], r.flags[bad[0]], F[bad[0]])
    c = pdw.contact_forces(r.x, P, flags=F, anchors=A, variant=variant)
    np.testing.assert_allclose(r.Fn, c.F_n, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(r.Ft, c.F_t, rtol=1e-12, atol=1e-9)


def _crafted(rng, n):
    """n states whose feet straddle the thresholds: leg `k` (random) at height h from the ground
    (|h| <= 3e-5 m) moving at v (|v| <= 1 m/s), the other leg's angle close to or away from
    its own (up- and downhill by fractions of a millimetre); random support flags."""
    l, r = P.l, P.r
    out = []
    for _ in range(n):
        k = int(rng.integers(2))
        th = np.empty(2)
        th[k] = rng.uniform(-0.3, 0.3)
        # the other foot: mostly within +-1e-3 rad (x_D within 0.3 mm), sometimes far
        th[1 - k] = th[k] + (rng.uniform(-1e-3, 1e-3) if rng.random() < 0.5 else rng.uniform(-0.5, 0.5))
        h = rng.choice([-1, 1]) * 10 ** rng.uniform(-6, np.log10(3e-5))
        y_o = h + r + (l - r) * np.cos(th[k])
        qd = np.concatenate([rng.uniform(-0.5, 0.5, 2), rng.uniform(-3, 3, 2)])
        out.append((np.array([0.0, y_o, th[0], th[1], *qd]), tuple(int(f) for f in rng.integers(0, 2, 2))))
    return out


@pytest.mark.parametrize("variant", pdw.VARIANTS)
@pytest.mark.parametrize("method", ["cdm", "verlet"])
def test_flags_of_crafted_states_follow_the_rules(variant, method):
    rng = np.random.default_rng(18 + len(variant) + len(method))
    seen = dict.fromkeys(["lift_off", "stays_support", "support_above_moving_down", "support_below",
                          "disarmed", "uphill_unarmed", "armed", "touch_down",
                          "below_no_touch_down_unarmed", "below_no_touch_down_moving_up"], 0)
    for x0, flags0 in _crafted(rng, 160):
        r = pdw.simulate(x0, t_end=3 * DT, dt=DT, method=method, variant=variant, flags0=flags0,
                         integrator=pdw.Integrator(check_step="off"), record=pdw.Record(every=1),
                         limits=pdw.Limits(on_failure="return"))
        _replay(r, flags0, variant, seen)
    # every branch taken and not taken (a rule never exercised is not tested); an armed foot
    # below the ground moving up needs the paper's v_y (dy/dt + r thetad): with the consistent
    # one (v_y = dy/dt) a foot that was above gets below only moving down
    missing = [k for k, v in seen.items() if v == 0
               and not (k == "below_no_touch_down_moving_up" and variant == "consistent")]
    assert not missing, (missing, seen)


@pytest.mark.parametrize("variant", pdw.VARIANTS)
def test_flags_of_a_walk_follow_the_rules(variant):
    """A walk of 2 s (touch-downs, lift-offs, double support, the guard at mid-stance), and a
    disturbed start that falls: every sample's flags and forces as the reference says."""
    seen = {k: 0 for k in ("lift_off", "stays_support", "support_above_moving_down", "support_below",
                           "disarmed", "uphill_unarmed", "armed", "touch_down",
                           "below_no_touch_down_unarmed", "below_no_touch_down_moving_up")}
    for x0 in (pdw.X0_PAPER, pdw.X0_DISTURBED):
        r = pdw.simulate(x0, t_end=2.0, dt=DT, variant=variant,
                         integrator=pdw.Integrator(check_step="off"), record=pdw.Record(every=1),
                         limits=pdw.Limits(on_failure="return"))
        _replay(r, (0, 1), variant, seen)
    assert seen["touch_down"] >= 4 and seen["lift_off"] >= 4 and seen["uphill_unarmed"] >= 1, seen


def _state(theta1, theta2, h1, dy1, thetad1, variant="paper"):
    """Foot 1 at height h1 [m] with dy_D1/dt = dy1 [m/s] and thetad1; hip at x_o = 0."""
    l, r = P.l, P.r
    y_o = h1 + r + (l - r) * np.cos(theta1)
    yd = dy1 - (l - r) * np.sin(theta1) * thetad1
    return np.array([0.0, y_o, theta1, theta2, 0.0, yd, thetad1, 0.0])


@pytest.mark.parametrize("case, expect", [
    # foot 1 downhill, 1e-6 m up at t = 0 (armed), below the ground after one step moving down
    (dict(theta1=0.2, theta2=-0.1, h1=1e-6, dy1=-0.3, thetad1=0.0), 1),
    # the same foot, its paper-variant v_y = dy/dt + r thetad1 positive: Eq. 18b says no
    (dict(theta1=0.2, theta2=-0.1, h1=1e-6, dy1=-0.3, thetad1=3.0), 0),
    # 0.3 mm uphill of the other foot: never armed, no touch-down
    (dict(theta1=-0.1 - 1e-3, theta2=-0.1, h1=1e-6, dy1=-0.3, thetad1=0.0), 0),
    # just downhill of the other foot: armed, touches down
    (dict(theta1=-0.1 + 1e-3, theta2=-0.1, h1=1e-6, dy1=-0.3, thetad1=0.0), 1),
    # below the ground from the start (never above): not armed
    (dict(theta1=0.2, theta2=-0.1, h1=-1e-6, dy1=-0.3, thetad1=0.0), 0),
])
def test_touch_down_needs_armed_below_and_moving_down(case, expect):
    """Eq. 18b and the guard on hand-made states (paper variant), one step of cdm: the outcome
    is the rules' (stated per case), not whatever another copy of the rule says."""
    x0 = _state(**case)
    r = pdw.simulate(x0, t_end=2 * DT, dt=DT, flags0=(0, 0),
                     integrator=pdw.Integrator(check_step="off"), record=pdw.Record(every=1),
                     limits=pdw.Limits(on_failure="return"))
    td = [e for e in r.events if e.leg == 1 and e.kind == "touch_down"]
    assert len(td) == expect, (case, r.events)
    if expect:
        assert td[0].t == pytest.approx(DT, abs=1e-12)


@pytest.mark.parametrize("h2, dy2, expect", [(1e-6, 0.3, 1), (1e-6, -0.3, 0), (-1e-6, 0.3, 0)])
def test_lift_off_needs_above_and_moving_up(h2, dy2, expect):
    """Eq. 18a at t = 0 (consistent variant: v_y = dy_D/dt): a support foot lifts off only when
    above the ground and moving up."""
    x0 = _state(-0.1, 0.2, h2, dy2, 0.0)[[0, 1, 3, 2, 4, 5, 7, 6]]     # the foot as leg 2
    r = pdw.simulate(x0, t_end=DT, dt=DT, variant="consistent", flags0=(0, 1),
                     integrator=pdw.Integrator(check_step="off"), record=pdw.Record(every=1),
                     limits=pdw.Limits(on_failure="return"))
    lo = [e for e in r.events if e.leg == 2 and e.kind == "lift_off" and e.t == 0.0]
    assert len(lo) == expect, r.events


@pytest.mark.parametrize("method", ["cdm", "rodas4"])
def test_lane_loops_switch_crafted_states_as_the_scalar_loop(method, monkeypatch):
    """The ensemble engine's copies of the rules (the masks of the structure-of-arrays lane
    loops, per instruction set) on the crafted threshold states: each walker's flags, event
    counts and final state bit for bit the scalar loop's, which the tests above pin to the
    reference. Many of these states switch in their first steps, where the lane loops hand
    over between the start-up and the lanes."""
    from pdw.core import _batch
    from pdw.sim.batch import ISA_ENV, simulate_batch
    cases = _crafted(np.random.default_rng(7), 48)
    X = np.array([c[0] for c in cases])
    F = np.array([c[1] for c in cases])
    kw = dict(t_end=6 * DT, dt=DT, method=method, variant="paper",
              integrator=pdw.Integrator(check_step="off"))
    if method == "rodas4":
        kw.update(integrator=pdw.Integrator(check_step="off", rtol=1e-6, atol=1e-8))
    ref = [pdw.simulate(x, flags0=tuple(f), record=pdw.Record(every=0),
                        limits=pdw.Limits(on_failure="return"), **kw)
           for x, f in zip(X, F)]
    assert sum(r.event_counts["touch_down"] + r.event_counts["lift_off"] for r in ref) >= 20
    for isa in [n for n in _batch.ISAS if _batch.isa_supported(n)]:
        monkeypatch.setenv(ISA_ENV, isa)
        b = simulate_batch(X, flags0=F, lanes=8, threads=1, **kw)
        for i, r in enumerate(ref):
            assert b.status[i] == r.status, (isa, i)
            assert b.n_touch_down[i] == r.event_counts["touch_down"], (isa, i)
            assert b.n_lift_off[i] == r.event_counts["lift_off"], (isa, i)
            np.testing.assert_array_equal(b.x_final[i], r.x_final, err_msg="%s %d" % (isa, i))


@pytest.mark.parametrize("method", ["rodas4", "dopri5"])
def test_adaptive_methods_settle_a_lift_off_and_its_arming_together(method):
    """A downhill support foot just above the ground and rising lifts off at t = 0 and, in the
    same update, is armed (it is a swing foot above the ground, downhill of the other): the
    adaptive loops apply the rules until nothing changes, so no switch is pending at the start
    of the first step, which is then the full trial step, not one cut at the arming."""
    x0 = _state(0.2, -0.1, 1e-6, 0.3, 0.0)
    r = pdw.simulate(x0, t_end=2e-3, dt=1e-4, method=method, variant="consistent", flags0=(1, 1),
                     integrator=pdw.Integrator(check_step="off"), record=pdw.Record(every=1),
                     limits=pdw.Limits(on_failure="return"))
    assert [(e.t, e.leg, e.kind) for e in r.events] == [(0.0, 1, "lift_off")]
    assert r.t[1] - r.t[0] == pytest.approx(1e-4, rel=1e-12)
