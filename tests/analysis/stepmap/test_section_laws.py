"""The touch-down Poincaré section for every contact law (pdw.analysis.stepmap.section): LuGre's section
carries the trailing foot's bristle, Lankarani-Nikravesh's and Flores' its approach speed, so
find_gait, Floquet multipliers and continuation work with them and the map is the continuous
run's; the default laws keep their 6-coordinate section bit for bit."""
import numpy as np
import pytest

import pdw
from pdw import cell_mapping as CM
from pdw import limit_cycle as LC
from pdw.analysis.bifurcation.continuation import continue_gait
from pdw.analysis.numerics.calibration import calibrate_lugre
from pdw.analysis.stepmap import section as S
from pdw.core.contact import Contact

P = pdw.Params.paper_steady()
FLORES = Contact("flores", e=0.18)
#: LuGre's map at rtol 1e-10 costs ~3 s a step (400 000 rodas4 steps); these tests take the
#: looser map (0.3 s a step, reproducible to ~1e-8), Newton to 1e-6, fd_step 1e-4.
LG_OPTS = dict(rtol=1e-8, atol=1e-10, event_tol=1e-12)
LG_TOL = 1e-6

#: find_gait(Params.paper_steady()).details["z"] computed by main at 16421c7 (before the
#: section had extra coordinates), as float.hex: the default law's result must stay bitwise.
MAIN_Z = ['-0x1.76dd5271ee15dp-2', '0x1.872ee8a4232bap-2', '0x1.ba289d16b390ap-1',
          '-0x1.84726eaa0e4fbp-3', '-0x1.cc7839b778309p+0', '-0x1.ab904e54acb68p+0']
MAIN_PERIOD, MAIN_L = '0x1.28f970c6e792dp-1', '0x1.79d25f9ea200cp-2'


@pytest.fixture(scope="module")
def default_gait():
    return LC.find_gait(P, workers=2)


@pytest.fixture(scope="module")
def lugre():
    return calibrate_lugre(P).contact


@pytest.fixture(scope="module")
def lugre_gait(default_gait, lugre):
    return LC.find_gait(P, guess=default_gait, contact=lugre, workers=2, tol=LG_TOL,
                        fd_step=1e-4, **LG_OPTS)


@pytest.fixture(scope="module")
def flores_gait():
    return LC.find_gait(P, contact=FLORES, workers=2)


def _touch_downs(r, contact, speeds0=None):
    """Section points of a continuous run at each of its touch-downs (both feet down)."""
    out = []
    for e in (e for e in r.events if e.kind == "touch_down"):
        i = int(np.searchsorted(r.t, e.t))
        held = None if speeds0 is None else S.held_speeds(r, e.t, speeds0, r.params)
        out.append(LC.section_coordinates(r.x[i], e.leg, contact, held))
    return out


def _run(z, contact, t_end, **tolerances):
    x0, a0 = S.start(z, P, contact)
    r = pdw.simulate(x0, t_end=t_end, params=P, method="rodas4", flags0=(1, 1), contact=contact,
                     integrator=pdw.Integrator(**tolerances), record=pdw.Record(every=1),
                     approach_speeds0=a0)
    return r, a0


# --- the default laws: unchanged ----------------------------------------------------------------

def test_default_section_and_gait_are_bitwise_main(default_gait):
    for c in (None, Contact(), Contact("hertz"), Contact("kelvin_voigt", k=1e5, d=1e3)):
        assert LC.section_names(c) == LC.SECTION and len(LC.SECTION) == 6
    g = default_gait
    assert [float(v).hex() for v in g.details["z"]] == MAIN_Z
    assert g.period.hex() == MAIN_PERIOD and g.step_length.hex() == MAIN_L
    assert len(g.multipliers) == 6 and g.state.shape == (8,)
    # an explicit default Contact() is the same map, bit for bit
    g2 = LC.find_gait(P, contact=Contact(), guess=g.details["z"], workers=2)
    z = g.details["z"]
    np.testing.assert_array_equal(LC.step_map(z, P, contact=Contact()), LC.step_map(z, P))
    np.testing.assert_array_equal(g2.details["z"], z)


def test_cell_mapping_with_section_extras(lugre, flores_gait):
    """Cell mapping runs every law: a cell's extra section coordinates (LuGre's trailing
    bristle, Flores's trailing approach speed) are the reference point's, as its four
    non-grid mechanical ones; each image is the law's own step map from the cell's centre."""
    zf = flores_gait.details["z"]
    for c, n in ((FLORES, 7), (lugre, 7)):
        cm = CM.cell_map(P, phi=(0.74, 0.78, 2), thetad2=(-1.9, -1.5, 1), contact=c, workers=2)
        ref = cm.info["reference"]
        assert len(ref) == n and cm.rest.shape == (2, n - 2) and cm.image_point.shape == (2, n)
        np.testing.assert_array_equal(cm.rest[:, 4:], np.tile(ref[6:], (2, 1)))
        A, B = cm.centers()
        for k in range(2):
            z = CM.cell_state(A[k], B[k], cm.rest[k], P)
            assert len(z) == n and z[6] == ref[6]
            s = LC.step(z, P, contact=c, t_hint=0.6, **LC.LOOSE)
            assert s["status"] == "ok" and cm.status[k] in ("ok", "left")   # left: off the grid
            np.testing.assert_array_equal(s["z"], cm.image_point[k])
        if c is FLORES:
            # the extras are not the default law's: the images move with the law
            assert abs(ref[6] - 0.0) > 0.1                       # an approach speed [m/s]
            conv, steps = CM.point_mapping_basin(cm, zf, n_steps=3, tol=10.0, workers=2)
            assert conv.all() and (steps == 1).all()
    with pytest.raises(pdw.InvalidInputError, match="reference"):
        CM.cell_map(P, phi=(0.7, 0.8, 2), thetad2=(-2, -1, 2), contact=FLORES,
                    reference=np.zeros(6))


def test_section_sizes_embedding_and_names(lugre):
    both = Contact("flores", e=0.18, friction="lugre")
    assert LC.section_names(lugre)[6:] == ("z1_um",)
    assert LC.section_names(FLORES)[6:] == ("v_in1",)
    assert LC.section_names(both)[6:] == ("z1_um", "v_in1")
    assert S.section_units(both)[6:] == ("um", "m/s")
    z = np.array([-0.36, 0.38, 0.86, -0.19, -1.8, -1.67, -0.6, 0.7])
    x = LC.embed(z, P, both)
    assert x.shape == (10,) and x[8] == -0.6e-6 and x[9] == 0.0   # leading bristle: 0
    # relabelling at a touch-down of leg 1: the trailing foot is leg 2
    xs = x[[0, 1, 3, 2, 4, 5, 7, 6, 9, 8]]
    np.testing.assert_allclose(LC.section_coordinates(xs, 1, both, (0.3, 0.7)), z, rtol=1e-15)
    with pytest.raises(pdw.InvalidInputError, match="z1_um"):
        LC.step(np.zeros(6), P, contact=lugre)
    with pytest.raises(pdw.InvalidInputError, match="approach_speeds"):
        LC.section_coordinates(x[:8], 2, FLORES)


# --- LuGre --------------------------------------------------------------------------------------

def test_lugre_fixed_point_is_the_continuous_periodic_orbit(lugre_gait, lugre):
    g = lugre_gait
    z = g.details["z"]
    assert g.details["section_names"][-1] == "z1_um" and len(z) == 7
    assert g.details["residual"] < LG_TOL and g.state.shape == (10,)
    assert abs(z[6]) > 0.1                  # the trailing bristle [um] is not relaxed
    # 7 Floquet multipliers, inside the unit circle: a stable gait, the paper's dominant pair
    m = np.abs(g.multipliers)
    assert len(m) == 7 and g.stable and m[0] == pytest.approx(0.504, abs=3e-3)
    # a continuous run from embed(z*) comes back to z* at every touch-down ...
    r, _ = _run(z, lugre, 2.4, **LG_OPTS)
    d = [np.max(np.abs(zk - z)) for zk in _touch_downs(r, lugre)]
    assert len(d) >= 4 and max(d) < 5 * LG_TOL, d
    # ... and with the trailing bristle relaxed (the old, re-initialised section) it does not
    r0, _ = _run(np.append(z[:6], 0.0), lugre, 0.7, **LG_OPTS)
    assert np.max(np.abs(_touch_downs(r0, lugre)[0][:6] - z[:6])) > 20 * LG_TOL


def test_lugre_continuation_points_are_fixed_points(lugre_gait, lugre):
    b = continue_gait(P, "k_hip", 0.97, max_points=3, step=0.01, start=lugre_gait, workers=2,
                      tol=LG_TOL, fd_step=1e-4, options=dict(contact=lugre, **LG_OPTS),
                      detect=())
    assert len(b) == 3 and b.z.shape == (3, 7) and b.multipliers.shape == (3, 7)
    assert b.values[-1] > b.values[0] and b.state.shape == (3, 10)
    for k in range(len(b)):
        Pz = LC.step_map(b.z[k], P.replace(k_hip=b.values[k]), contact=lugre, **LG_OPTS)
        assert np.max(np.abs(Pz - b.z[k])) < 2 * LG_TOL, k
    assert b.stable.all()


def test_lugre_find_gait_at_the_newton_tolerances(lugre_gait, lugre):
    """The accurate search (default guesses, rtol 1e-10): ~1.4 s on 2 threads (136 s with the
    LuGre kernels' first finite-difference Jacobian step, cbrt(eps), which made rodas4 take
    ~70x the steps: docs/contact_laws.md, "Integrators")."""
    g = LC.find_gait(P, contact=lugre, workers=2)
    assert g.details["residual"] < 1e-9 and len(g.multipliers) == 7 and g.stable
    np.testing.assert_allclose(g.details["z"], lugre_gait.details["z"], atol=1e-6)


# --- Flores (the approach-speed laws) -----------------------------------------------------------

def test_flores_fixed_point_has_seven_coordinates(flores_gait):
    g = flores_gait
    z = g.details["z"]
    assert g.details["section_names"][-1] == "v_in1" and len(z) == 7
    assert g.details["residual"] < 1e-9 and len(g.multipliers) == 7 and g.stable
    # period 1: the trailing foot landed as fast as the leading one
    assert z[6] == pytest.approx(S.leading_speed(LC.embed(z, P, FLORES), P), abs=1e-8)
    r, a0 = _run(z, FLORES, 2.4, **LC.TIGHT)
    d = [np.max(np.abs(zk - z)) for zk in _touch_downs(r, FLORES, a0)]
    assert len(d) >= 4 and d[0] < 1e-8 and max(d) < 1e-7, d


def test_flores_map_off_the_fixed_point_is_the_continuous_run(flores_gait):
    """Two steps of the map from a perturbed z (the trailing foot landed 0.15 m/s faster than
    the leading one, the angles and rates off too) equal one continuous run over the two steps;
    the old section's assumption (v_in1 = the leading foot's speed) does not."""
    z = flores_gait.details["z"] + np.array([2e-3, -1e-3, 5e-3, 0.0, 0.02, -0.03, 0.15])
    Z, info = LC.orbit(z, 2, P, contact=FLORES, **LC.TIGHT)
    assert [s["status"] for s in info] == ["ok", "ok"]
    r, a0 = _run(z, FLORES, info[0]["period"] + info[1]["period"] + 0.05, **LC.TIGHT)
    zs = _touch_downs(r, FLORES, a0)
    assert len(zs) >= 2
    np.testing.assert_allclose(zs[0], Z[1], atol=1e-8)
    np.testing.assert_allclose(zs[1], Z[2], atol=1e-8)
    assert zs[0][6] == a0[1]                 # the old leading foot now trails
    # the old section: both feet at the leading foot's speed
    old = S.extend(z[:6], P, FLORES)
    assert np.max(np.abs(LC.step_map(old, P, contact=FLORES, **LC.TIGHT)[:6] - Z[1][:6])) > 1e-5


def test_kelvin_voigt_period_one_gait_is_unstable_by_a_flip():
    """Calibrated like the others (same sink, same landing restitution), Kelvin-Voigt's
    period-1 gait on paper_steady exists but is unstable with a real multiplier near -1.45 (a
    flip), which is why its walk stays irregular (docs/contact_laws.md)."""
    from pdw.analysis.numerics.calibration import calibrate
    kv = calibrate(P).contacts["kelvin_voigt"]
    g = LC.find_gait(P, contact=kv, workers=2)
    m = g.multipliers[0]
    assert g.details["residual"] < 1e-9 and not g.stable
    assert abs(m.imag) < 1e-9 and -1.6 < m.real < -1.3, g.multipliers
    assert abs(g.step_length - 0.34596) < 1e-4
