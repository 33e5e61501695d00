"""paper_steady's (continuous, paper variant) region in (k_n, d_n) (issue #24 a): a change of
the step's event sequence is a point of the branch, not its end (`testfunctions.SequenceChange`,
``AdmissibleEnd(skip=...)``); the Neimark-Sacker test reports a located-or-not complex pair
instead of dropping it; a logarithmic parameter far off is an invalid parameter, not an
OverflowError. The slow test checks a column's points against long walks."""
from types import SimpleNamespace

import numpy as np
import pytest

import pdw
from pdw.analysis.bifurcation import testfunctions as TF
from pdw.analysis.bifurcation.continuation import continue_gait
from pdw.analysis.stepmap import gait_maps, poincare


def _pt(n_events=2, admissible=None, mult=()):
    ev = SimpleNamespace(info={"n_events": n_events}, admissible=admissible or {})
    return SimpleNamespace(ev=ev, mult=np.asarray(mult, dtype=complex))


def test_admissible_end_skips_the_named_functions_and_checks_them():
    pt = _pt(admissible={"double_support": 0.03, "event_sequence": -1.5})
    assert set(TF.AdmissibleEnd().values(None, pt)) == {"end:double_support",
                                                         "end:event_sequence"}
    assert set(TF.AdmissibleEnd(skip=("event_sequence",)).values(None, pt)) == {
        "end:double_support"}
    with pytest.raises(pdw.InvalidInputError, match="skip"):
        TF.AdmissibleEnd(skip="event_sequence")
    with pytest.raises(pdw.InvalidInputError, match="skip"):
        TF.AdmissibleEnd(skip=(1,))


def test_sequence_change_crosses_at_a_change_and_back():
    sc = TF.SequenceChange()
    f = [sc.values(None, _pt(n))["event_sequence"] for n in (2, 2, 4, 4, 2)]
    crossed = [sc.crossed("event_sequence", a, b) for a, b in zip(f, f[1:])]
    assert crossed == [False, True, False, True]
    assert sc.values(None, SimpleNamespace(ev=SimpleNamespace(info={}))) == {}


def test_neimark_sacker_reports_an_unlocated_pair_and_rejects_a_neutral_saddle():
    ns = TF.NeimarkSacker()
    # a complex pair at |mu| = 1.006 (the corrector failed inside the bracket): reported
    off = _pt(mult=[1.006 * np.exp(0.88j), 1.006 * np.exp(-0.88j), 0.3])
    d = ns.describe(None, off, "neimark_sacker")
    assert d is not None and "1.006" in d[0]
    # a neutral saddle (real mu_1 mu_2 = 1) with a complex pair far off the circle: rejected
    saddle = _pt(mult=[2.0, 0.5, 0.4 * np.exp(1j), 0.4 * np.exp(-1j)])
    assert ns.describe(None, saddle, "neimark_sacker") is None


def test_a_log_parameter_out_of_range_is_an_invalid_parameter():
    prob = gait_maps.ContinuousProblem(pdw.Params.paper_steady(), "d_n", log=True)
    with pytest.raises(pdw.InvalidInputError, match="out of range"):
        prob.value(800.0)
    ev = prob.evaluate(np.zeros(prob.dim), 800.0, jac=False)
    assert not ev.ok and "invalid parameter" in ev.status


def test_continue_bifurcation_checks_skip():
    from pdw import hybrid as H
    from pdw.analysis.bifurcation.codim2 import continue_bifurcation
    b = continue_gait(H.compass_gait_params(), "gamma", 5.3 * np.pi / 180, model="hybrid")
    pd = b.of_kind("period_doubling")[0]
    for bad in ("event_sequence", ("no_such",)):
        with pytest.raises(pdw.InvalidInputError, match="skip"):
            continue_bifurcation(pd, "c", 0.7, skip=bad)


def _walk(z, P, n=300):
    """n steps of the step map from z: ("fell" | "settled" (the last step moves z by < 1e-6)
    | "unsettled", the last step's n_events)."""
    zp, s = z, None
    for _ in range(n):
        s = poincare.step(z, P)
        if s["status"] != "ok":
            return "fell", None
        zp, z = z, s["z"]
    return ("settled" if np.max(np.abs(z - zp)) < 1e-6 else "unsettled"), s["n_events"]


@pytest.mark.slow
def test_the_family_goes_on_through_the_event_sequence_change_and_ends_at_its_fold():
    """k_n = 1.5e5, from the stable gait at d_n = 4e4 down: the stance foot starts to lift off
    (and touch down again, unloaded) at d_n ~ 35453; the branch passes it (UZ, bracketed to
    locate_tol) and ends at the fold at d_n ~ 34127. Long walks of the step map: 1 % above and
    below the UZ both settle on a period-1 gait, with 2 and 4 support events per step; 1 %
    above the fold the walker settles, 1 % below it falls. On the code before, the branch ended
    at the change of the event sequence (EP)."""
    P = pdw.Params.paper_steady().replace(k_n=1.5e5, d_n=4e4)
    g = pdw.find_gait(P)
    b = continue_gait(P, "d_n", 3e4, log=True, start=g, max_points=40, workers=2,
                      detect=("fold", "period_doubling", "neimark_sacker"),
                      events=[TF.AdmissibleEnd(skip=("event_sequence",)), TF.SequenceChange()])
    uz = [f for f in b.bifurcations if f.kind == "event"]
    lp = [f for f in b.bifurcations if f.kind == "fold"]
    assert not [f for f in b.bifurcations if f.kind == "end"]
    assert uz and lp and lp[0].located and lp[0].value < uz[0].bracket[0]
    assert uz[0].bracket[1] - uz[0].bracket[0] < 1.0          # d_n, locate_tol of the run
    d_uz = 0.5 * sum(uz[0].bracket)
    assert 3.4e4 < d_uz < 3.7e4 and 3.3e4 < lp[0].value < 3.5e4
    for d, want in ((1.01 * d_uz, 2), (0.99 * d_uz, 4)):
        i = int(np.argmin(np.abs(b.values - d)))
        assert _walk(b.z[i], P.replace(d_n=d)) == ("settled", want)
    i = int(np.argmin(np.abs(b.values - 1.01 * lp[0].value)))
    assert _walk(b.z[i], P.replace(d_n=1.01 * lp[0].value))[0] == "settled"
    assert _walk(lp[0].z, P.replace(d_n=0.99 * lp[0].value))[0] == "fell"


@pytest.mark.slow
def test_a_walker_neimark_sacker_point_against_long_walks():
    """k_n = 1.5e5: paper_steady's family, continued down in d_n from 6e4, loses stability at
    a Neimark-Sacker point (d_n ~ 56704, a complex pair through |mu| = 1 at arg ~1.3 rad).
    Long walks of the step map from the NS point's gait: 1 % above it the step-to-step change
    decays (by more than 3x from steps 50-150 to 300-400), 1 % below it does not (a torus)
    and the walker does not fall."""
    P = pdw.Params.paper_steady().replace(k_n=1.5e5, d_n=6e4)
    b = continue_gait(P, "d_n", 5e4, log=True, start=pdw.find_gait(P), max_points=30,
                      workers=2)
    ns = b.of_kind("neimark_sacker")
    assert ns and ns[0].located and 5.5e4 < ns[0].value < 5.8e4
    m = ns[0].multipliers
    pair = m[np.argmin(np.abs(np.abs(m) - 1.0))]
    assert abs(abs(pair) - 1.0) < 1e-3 and 0.5 < abs(np.angle(pair)) < 2.5
    z = ns[0].z
    above, below = (_amplitudes(z, P.replace(d_n=f * ns[0].value)) for f in (1.01, 0.99))
    assert above[1] < 0.3 * above[0]             # decays: a stable focus
    assert below[1] > 0.8 * below[0] > 0          # does not decay, and the walker walks on


def _amplitudes(z, P, n=400):
    """The largest step-to-step change of z over steps 50..150 and over the last 100 of n
    (the walker must not fall)."""
    d = []
    for _ in range(n):
        s = poincare.step(z, P)
        assert s["status"] == "ok"
        d.append(np.max(np.abs(s["z"] - z)))
        z = s["z"]
    return max(d[50:150]), max(d[-100:])


@pytest.mark.slow
def test_the_fold_curve_passes_the_event_sequence_change_and_matches_a_column():
    """paper_steady's d_n fold (41685.5 at k_n = 1e5) followed in k_n with
    skip=("event_sequence",) passes the change of the event sequence near k_n = 1.14e5 (UZ;
    without skip the curve ended at 1.07e5) and, at k_n = 1.2e5, equals the fold that a
    one-parameter d_n continuation from d_n = 1e6 locates there (1e-3 relative). Walks of
    the step map from the fold's gait: 2 % above it the walker walks on, 2 % below it falls."""
    from pdw.analysis.bifurcation.codim2 import continue_bifurcation
    P = pdw.Params.paper_steady()
    fold = continue_gait(P, "d_n", 1e3, log=True, max_points=25, workers=2).of_kind("fold")[0]
    cv = continue_bifurcation(fold, "k_n", 1.2e5, fd_step=1e-4, max_points=30,
                              skip=("event_sequence",))
    assert cv.values[-1, 1] == pytest.approx(1.2e5)
    uz = [f for f in cv.branch.bifurcations if f.kind == "event"]
    assert uz and 1.1e5 < uz[0].value < 1.18e5
    col = continue_gait(P.replace(k_n=1.2e5), "d_n", 1e4, log=True, max_points=40, workers=2,
                        detect=("fold", "period_doubling", "neimark_sacker"),
                        events=[TF.AdmissibleEnd(skip=("event_sequence",)),
                                TF.SequenceChange()])
    lp = col.of_kind("fold")[0]
    assert lp.located and cv.values[-1, 0] == pytest.approx(lp.value, rel=1e-3)
    Pk = P.replace(k_n=1.2e5)
    assert _walk(lp.z, Pk.replace(d_n=1.02 * lp.value))[0] != "fell"
    assert _walk(lp.z, Pk.replace(d_n=0.98 * lp.value))[0] == "fell"
