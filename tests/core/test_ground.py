"""pdw.Ground: the ground as data (docs/terrain.md) -- shapes, the compiled table, TOML, errors."""
import math

import numpy as np
import pytest

import pdw
from pdw.core.ground import Ground, Patch

S = np.linspace(-1.9, 20.0, 40001)


def _fd(g, s, eps=1e-6):
    return (g.h(s + eps) - g.h(s - eps)) / (2 * eps)


SHAPES = [
    Ground.plane(0.02),
    Ground.steps([1.0, 2.0], [-0.01, 0.02], width=0.02),
    Ground.profile([0, 1, 2, 3], [0, 0.01, -0.01, 0.0]),
    Ground.profile([0, 1, 2, 3], [0, 0.01, -0.01, 0.0], order=1),
    Ground.sine(0.01, 0.5, phase=0.3),
    Ground.random(0.005, 0.1, seed=3),
    Ground.step(1.0, -0.02) + Ground.random(0.002, 0.1, seed=1),
]


@pytest.mark.parametrize("g", SHAPES, ids=lambda g: g.kind)
def test_derivatives_are_those_of_h(g):
    s = np.linspace(-1.0, 5.0, 997) + 1e-3 * math.pi     # off the knots (C1 kinds: h'' jumps)
    h, d, dd = g.evaluate(s)
    assert np.allclose(d, _fd(g, s), atol=1e-6)
    assert np.allclose(dd, (g.dh(s + 1e-6) - g.dh(s - 1e-6)) / 2e-6, atol=1e-3, rtol=1e-4)


@pytest.mark.parametrize("g", SHAPES, ids=lambda g: g.kind)
def test_table_matches_the_exact_shape(g):
    """The compiled table (what C evaluates) against NumPy's exact h, h', h''."""
    h, d, dd = g.evaluate(S)
    th, td, tdd = g.table().evaluate(S)
    assert np.abs(th - h).max() < 1e-10
    assert np.abs(td - d).max() < 1e-7
    assert np.abs(tdd - dd).max() < 1e-4 * max(1.0, np.abs(dd).max())


def test_polynomial_kinds_are_exact_in_the_table():
    for g in SHAPES[:4]:
        h, d, _ = g.evaluate(S)
        th, td, _ = g.table().evaluate(S)
        assert np.abs(th - h).max() < 1e-14 and np.abs(td - d).max() < 1e-12


def test_shapes():
    assert Ground.plane(0.1).h(2.0) == pytest.approx(-2.0 * math.tan(0.1))
    g = Ground.steps([1.0], [-0.03], width=0.02)
    assert g.h(0.98) == 0.0 and g.h(1.02) == pytest.approx(-0.03) and g.h(1.0) == pytest.approx(-0.015)
    p = Ground.profile([0, 1, 2], [0.0, 0.01, 0.0])
    assert p.h(np.array([0.0, 1.0, 2.0])) == pytest.approx([0.0, 0.01, 0.0])
    assert p.ddh(0.0) == pytest.approx(0.0, abs=1e-14)            # natural spline
    assert Ground.sine(0.01, 0.5).h(0.125) == pytest.approx(0.01)
    assert Ground.flat(offset=0.02).h(3.0) == 0.02
    assert Ground().is_flat and not Ground.flat(offset=0.01).is_flat


def test_arc_length_of_a_plane():
    g = Ground.plane(0.05)
    a = g.table().arc_length(np.array([0.0, 3.0]))
    assert a[1] - a[0] == pytest.approx(3.0 / math.cos(0.05), rel=1e-14)


def test_random_ground_is_the_same_everywhere():
    """Constants computed once (numpy PCG64's raw stream, our transformation)."""
    g = Ground.random(0.01, 0.1, seed=7)
    want = [0.00999423668321636, 0.011027552089457526, -0.0025310849619195877,
            0.0004111450246851378]
    assert g.h(np.array([0.0, 0.5, 1.0, 10.0])) == pytest.approx(want, rel=1e-12, abs=1e-15)
    assert g._modes()[0][:3] == pytest.approx([11.186632301507776, -2.21461055069933,
                                               0.444669246736568], rel=1e-13)
    assert not np.array_equal(g.h(S), Ground.random(0.01, 0.1, seed=8).h(S))


def test_random_ground_statistics():
    g = Ground.random(0.01, 0.2, seed=11)
    s = np.linspace(0.0, 400.0, 40001)
    h = g.h(s)
    assert np.sqrt(np.mean(h ** 2)) == pytest.approx(0.01, rel=0.05)


def test_toml_round_trip():
    gs = SHAPES + [Ground.flat(offset=0.01, extent=(-1.0, 30.0)),
                   Ground.flat(patches=[dict(s_a=1.0, s_b=2.0, k_n=2e4)], blend=0.02)]
    for g in gs:
        d = g.to_dict()
        assert Ground.from_dict(d) == g
        assert pdw.core._toml.loads(pdw.core._toml.dumps({"ground": d}))["ground"] == d


def test_patch_table():
    g = Ground.flat(patches=[Patch.make(1.0, 2.0, k_n=2e4, mu_s=0.3), dict(s_a=2.0, s_b=3.0, k_n=5e4)])
    t = g.table()
    assert t.patches.shape == (2, 4)
    assert np.isnan(t.patches[1, 3]) and t.patches[1, 2] == 5e4
    assert list(t.zones) == pytest.approx([0.995, 1.005, 1.995, 2.005, 2.995, 3.005])


@pytest.mark.parametrize("make, field", [
    (lambda: Ground.profile([0, 1, 1, 2], [0, 0, 1, 1]), "ground.s"),
    (lambda: Ground.profile([0, 2, 1], [0, 0, 1]), "ground.s"),
    (lambda: Ground.profile([0, 1], [0, 0, 1]), "ground.h"),
    (lambda: Ground.random(-0.01), "ground.sigma"),
    (lambda: Ground.random(0.01, correlation=0.0), "ground.correlation"),
    (lambda: Ground.random(0.01, seed=-1), "ground.seed"),
    (lambda: Ground.steps([2.0, 1.0], [0.01, 0.01]), "ground.edges"),
    (lambda: Ground.steps([1.0], [0.01], width=0.0), "ground.width"),
    (lambda: Ground.sine(0.01, -1.0), "ground.wavelength"),
    (lambda: Ground.plane(float("nan")), "ground.slope"),
    (lambda: Ground.flat(extent=(2.0, 1.0)), "ground.extent"),
    (lambda: Ground.flat(patches=[dict(s_a=1.0, s_b=2.0, k_n=-1.0)]), "k_n"),
    (lambda: Ground.flat(patches=[dict(s_a=1.0, s_b=2.0, d_n=-1.0)]), "d_n"),
    (lambda: Ground.flat(patches=[dict(s_a=1.0, s_b=2.0, sigma0=0.0)]), "sigma0"),
    (lambda: Ground.flat(patches=[dict(s_a=1.0, s_b=2.0, bogus=1.0)]), "bogus"),
    (lambda: Ground.flat(patches=[dict(s_a=2.0, s_b=1.0, k_n=1.0)]), "s_b"),
    (lambda: Ground.flat(patches=[dict(s_a=1.0, s_b=3.0, k_n=1.0), dict(s_a=2.0, s_b=4.0, k_n=1.0)]),
     "overlap"),
    (lambda: Ground.flat(patches=[dict(s_a=3.0, s_b=4.0, k_n=1.0), dict(s_a=1.0, s_b=2.0, k_n=1.0)]),
     "sorted"),
    (lambda: Ground.from_dict({"kind": "sine", "amplitude": 0.01}), "wavelength"),
    (lambda: Ground.from_dict({"kind": "moon"}), "ground.kind"),
    (lambda: Ground.from_dict({"kind": "flat", "slope": 1}), "slope"),
])
def test_bad_input_names_the_field(make, field):
    with pytest.raises(pdw.InvalidInputError, match=field):
        make()


def test_replace_gives_a_ground_with_its_own_table():
    """dataclasses.replace must not hand the new ground the old one's cached table (the cache
    was an init field: the replaced ground ran on the original's shape)."""
    import dataclasses
    g = Ground.sine(0.001, 0.8)
    t = g.table()
    g2 = dataclasses.replace(g, offset=0.01)
    assert g2.table() is not t
    assert np.allclose(g2.table().cells[:, 2] - t.cells[:, 2], 0.01, rtol=0, atol=1e-15)
    a = pdw.simulate(params=pdw.Params.paper_steady(), t_end=0.05, ground=g2,
                     record=pdw.Record(every=0))
    b = pdw.simulate(params=pdw.Params.paper_steady(), t_end=0.05,
                     ground=Ground.sine(0.001, 0.8, offset=0.01), record=pdw.Record(every=0))
    assert np.array_equal(a.x_final, b.x_final)


def test_compiled_ground_is_made_once_per_ground_and_maker():
    from pdw.core import _core
    g = Ground.random(0.0005, 0.1, seed=1, extent=(-1.0, 5.0))
    c = g.compiled(_core.CGround)
    assert g.compiled(_core.CGround) is c
    assert Ground.random(0.0005, 0.1, seed=2, extent=(-1.0, 5.0)).compiled(_core.CGround) is not c
    # a cached struct gives the same run as a fresh one
    P = pdw.Params.paper_steady()
    r1 = pdw.simulate(params=P, t_end=0.3, ground=g, record=pdw.Record(every=0))
    r2 = pdw.simulate(params=P, t_end=0.3, ground=g, record=pdw.Record(every=0))
    r3 = pdw.simulate(params=P, t_end=0.3, record=pdw.Record(every=0),
                      ground=Ground.random(0.0005, 0.1, seed=1, extent=(-1.0, 5.0)))
    assert np.array_equal(r1.x_final, r2.x_final) and np.array_equal(r1.x_final, r3.x_final)


def test_a_ground_with_its_compiled_struct_pickles():
    import pickle

    from pdw.core import _core
    g = Ground.sine(0.001, 0.8)
    g.compiled(_core.CGround)
    g2 = pickle.loads(pickle.dumps(g))
    assert g2 == g and "table" in g2._cache
    assert not any(isinstance(k, tuple) for k in g2._cache)
    assert g2.compiled(_core.CGround) is not g.compiled(_core.CGround)
