"""The level-cell path of the shaped-ground kernel (pdw_ground.h pdw_ground_cell_level,
pdw_terrain.c): where a cell's a_1 .. a_5 are all +0.0 the kernel takes h = a_0, h' = h'' = 0 and
1/N = 1 without evaluating the quintic, and the level-ground force rotation without the
multiplications by 1/N. These are claimed to be bitwise the general path's values: checked here
by running the same ground with its level cells' zero coefficients turned into -0.0 (the same
polynomial, which the level test refuses, so every evaluation takes the general path) and
comparing the recorded runs byte for byte. (Where h' = 0 under both feet the paper variant takes
the flat kernel's kinematics less the height in both runs, the -0.0 cells' h' being a zero too:
that path is checked against the flat model in test_terrain.py, to rounding.)"""
import dataclasses

import numpy as np
import pytest

import pdw
from pdw import Ground

P = pdw.Params.paper_steady()
GROUNDS = {
    # a support foot on a flat part while the swing foot passes an edge, at a height offset
    "steps": lambda: Ground.steps([0.45, 0.75, 1.05], [-0.002, 0.0015, -0.001], offset=0.0007),
    "plane": lambda: Ground.plane(0.0, offset=-0.0004),
    "patches": lambda: Ground.steps([0.6], [-0.001]).with_patches(
        [dict(s_a=0.3, s_b=0.5, k_n=8e4), dict(s_a=0.9, s_b=1.2, mu_s=0.45)]),
}


def _level(cells):
    """Rows whose a_1 .. a_5 are all +0.0 (the C test: all bits zero)."""
    a = cells[:, 3:8]
    return np.all((a == 0.0) & ~np.signbit(a), axis=1)


def _general_path(g):
    """g with its table's level cells made non-level by -0.0 coefficients (the same values)."""
    t = g.table()
    cells = t.cells.copy()
    lev = _level(cells)
    cells[lev, 3:8] = -0.0
    assert not _level(cells).any()
    h = Ground.from_dict(g.to_dict())
    h._cache["table"] = dataclasses.replace(t, cells=np.ascontiguousarray(cells))
    return h


def _run(g, method, variant):
    kw = dict(method="cdm") if method == "cdm" else dict(
        integrator=pdw.Integrator(method=method, rtol=1e-8, atol=1e-10))
    r = pdw.simulate(params=P, variant=variant, ground=g, t_end=1.2,
                     limits=pdw.Limits(on_failure="return"), **kw)
    return r


@pytest.mark.parametrize("name", list(GROUNDS))
def test_flat_parts_of_the_tables_are_level(name):
    # the speed-up needs the table builder to write exact +0.0 where the shape is flat; the
    # smoothed edges of steps are not level
    t = GROUNDS[name]().table()
    lev = _level(t.cells)
    assert lev.sum() >= 0.5 * len(lev)
    if name != "plane":
        assert not lev.all()


@pytest.mark.parametrize("variant", ["paper", "consistent"])
@pytest.mark.parametrize("method", ["cdm", "rodas4"])
@pytest.mark.parametrize("name", list(GROUNDS))
def test_level_path_is_the_general_path_bitwise(name, method, variant):
    g = GROUNDS[name]()
    a = _run(g, method, variant)
    b = _run(_general_path(g), method, variant)
    assert a.status == b.status and a.n_steps == b.n_steps
    assert a.n_gait_steps >= 1                       # feet crossed cells and edges
    for f in ("t", "x", "flags", "Fn", "Ft"):
        assert getattr(a, f).tobytes() == getattr(b, f).tobytes(), f
    assert repr(a.events) == repr(b.events)



# ---- patches: one contact call with the penetrating foot's parameters (pdw_terrain.c) -------

def _patched(*patches):
    return Ground.flat(extent=(-2.0, 50.0)).with_patches(list(patches))


@pytest.mark.parametrize("contact", [None, {"normal": "flores", "e": 0.5}], ids=["hc", "flores"])
@pytest.mark.parametrize("method", ["cdm", "rodas4"])
def test_a_patch_only_a_swing_foot_passes_over_changes_nothing(method, contact):
    # paper_steady's support feet roll over s in [0.33, 0.48], [0.69, 0.85], [1.06, 1.22]: the
    # swing foot passes over the patches at [0.54, 0.64] and [0.90, 1.00], no support foot
    # touches them, so the run is bitwise the one with the patch far away; a kernel that took a
    # swing foot's parameters for the support foot would differ (k_n 1e3 vs 2e5)
    kw = dict(params=P, t_end=2.0, limits=pdw.Limits(on_failure="return"), contact=contact)
    kw.update(method="cdm" if method == "cdm" else None)
    if method != "cdm":
        kw["integrator"] = pdw.Integrator(method=method, rtol=1e-8, atol=1e-10)
    far = pdw.simulate(ground=_patched(dict(s_a=40.0, s_b=41.0, k_n=1e3)), **kw)
    near = pdw.simulate(ground=_patched(dict(s_a=0.54, s_b=0.64, k_n=1e3),
                                        dict(s_a=0.90, s_b=1.00, k_n=1e3, mu_s=0.1)), **kw)
    assert far.n_gait_steps >= 2 and far.event_counts is not None
    for f in ("t", "x", "flags", "Fn", "Ft"):
        assert getattr(far, f).tobytes() == getattr(near, f).tobytes(), f
    # a patch under a support foot does change the run
    under = pdw.simulate(ground=_patched(dict(s_a=0.70, s_b=0.80, k_n=3e4)), **kw)
    assert not np.array_equal(under.x, far.x)
