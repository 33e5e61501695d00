"""The flag update's shaped-ground kinematics (pdw_terrain.c pdw_terrain_flag_kinematics): a swing
foot whose flag rules the ground's bounds decide is not sampled (docs/terrain.md "Costs"); every
value the rules, pdw_check_feet, the contact stage and the forces read must decide as the full
kinematics' do, and the support foot's values must be the full kinematics' bits."""
import numpy as np
import pytest

import pdw
from pdw import Ground
from pdw.core import _core, _layout
from pdw.core.model import kernel_index, parameter_vector

P = pdw.Params.paper_steady()
K = {f: i for i, f in enumerate(_layout.KIN)}
G = {f: i for i, f in enumerate(_layout.GROUND)}
FALL_DEPTH = 0.25 * P.l
GROUNDS = [Ground.sine(0.001, 0.8), Ground.random(0.0005, 0.1, seed=1, extent=(-1.0, 5.0)),
           Ground.sine(0.02, 0.3), Ground.steps([0.3, 0.5], [-0.003, 0.004])]


def _states(ground):
    """States of a walk on `ground` (cdm, every 7th step) and perturbed copies: hips lowered
    and raised, legs swung, so that feet are near, above and below the ground."""
    r = pdw.simulate(params=P, method="cdm", t_end=1.2, ground=ground,
                     record=pdw.Record(every=7), limits=pdw.Limits(on_failure="return"))
    rng = np.random.default_rng(5)
    x = np.repeat(r.x, 3, axis=0)
    x[1::3, 1] += rng.uniform(-0.02, 0.02, len(r.x))
    x[2::3, 2:4] += rng.uniform(-0.05, 0.05, (len(r.x), 2))
    return x


def _rules(kin, i, fall_depth):
    """What pdw_update_flags_trig and pdw_check_feet read of swing foot i (the other a support
    foot): disarmed (behind), armed (above ground), touch-down, too deep."""
    ki, kj = kin[i], kin[1 - i]
    y, vy = ki[K["y_D"]], ki[K["v_y"]]
    behind = ki[K["x_D"]] <= kj[K["x_D"]]
    return (behind, (not behind) and y > 0.0, y < 0.0 and vy < 0.0 and not behind,
            y < -fall_depth)


@pytest.mark.parametrize("variant", ["paper", "consistent"])
@pytest.mark.parametrize("ground", GROUNDS, ids=lambda g: g.kind)
def test_flag_kinematics_decide_as_the_full_ones(variant, ground):
    k = kernel_index(variant, None)
    p = parameter_vector(P)
    cg = _core.CGround(ground.table())
    anchors = np.array([0.1, 0.25, 0.3, 0.2])
    skipped = 0
    for x in _states(ground):
        for f1, f2 in ((1, 0), (0, 1), (1, 1), (0, 0)):
            kf, gf = _core.ground_kinematics(k, cg, x, p, f1, f2, anchors)
            kl, gl = _core.ground_kinematics(k, cg, x, p, f1, f2, anchors, FALL_DEPTH)
            flags = (f1, f2)
            for j in range(2):
                if flags[j] or flags[0] == flags[1]:     # sampled: the full kinematics' bits
                    assert kl[j].tobytes() == kf[j].tobytes()
                    for f in ("h", "dh", "inv_n", "s_n", "sigma", "alpha"):
                        assert gl[j, G[f]].tobytes() == gf[j, G[f]].tobytes()
            if f1 == f2:
                continue
            i = 0 if f2 else 1
            if kl[i].tobytes() != kf[i].tobytes():
                skipped += 1
                assert gl[i, G["dh"]] == 0.0 and gl[i, G["inv_n"]] == 1.0
                assert gl[i, G["s_n"]] == 0.0
            assert _rules(kl, i, FALL_DEPTH) == _rules(kf, i, FALL_DEPTH)
            # the contact stage: the same forces for both feet
            fl = np.array([flags], np.intc)
            c_full, c_lean = (np.zeros((1, 2 * len(_layout.CONTACT))) for _ in range(2))
            _core.contact_batch(k, kf.reshape(1, -1), fl, p, c_full)
            _core.contact_batch(k, kl.reshape(1, -1), fl, p, c_lean)
            assert c_full.tobytes() == c_lean.tobytes()
    if ground.kind != "steps":          # the case the skip is for: it happens
        assert skipped > 50


def test_a_ground_without_bounds_samples_both_feet():
    """A swing foot far above the ground with nothing to decide by (the support foot on a
    level cell, where the exact kinematics take the flat kernel's form) is sampled."""
    g = Ground.steps([5.0], [0.01])
    k = kernel_index("paper", None)
    p = parameter_vector(P)
    cg = _core.CGround(g.table())
    x = np.array(pdw.X0_PAPER, float)
    x[1] += 0.05
    anchors = np.zeros(4)
    kf, _ = _core.ground_kinematics(k, cg, x, p, 0, 1, anchors)
    kl, _ = _core.ground_kinematics(k, cg, x, p, 0, 1, anchors, FALL_DEPTH)
    assert kl.tobytes() == kf.tobytes()
