"""The gait descriptors (docs/model.md section 8) computed online by the compiled loops, against
the definitions applied here to the recorded samples; `pdw.steps` (offline, from the events)
against the online ones on several runs; the window of the periodic stop; Steps.steady's window.

The reference here reads nothing but the recorded flags and states: a touch-down of leg j is a
sample whose flag j went 0 -> 1, a lift-off 1 -> 0 (the fixed-step loops update the flags at
the sample, before its forces, docs/model.md section 7); the contact point x_D of a foot at a
sample is `pdw.contact_forces`'s (Eq. 4). Then, for the touch-down of leg j at sample n:
L = x_Dj(n) - x_Di(the other leg's previous touch-down), travel = x_Dj(n) - x_Dj(j's lift-off),
P = t_n - t(j's lift-off), cycle = t_n - t(previous touch-down), double support = t(the other
leg's next lift-off) - t_n (NaN when the run ends first or another touch-down comes first).
"""
import math

import numpy as np
import pytest

import pdw
from pdw.core import _layout
from pdw.sim.gait import FIELDS, Steps

STEADY = pdw.Params.paper_steady()


def _reference_steps(r, params, flags0=(0, 1)):
    """Steps from the recorded flags and states alone (see the module docstring)."""
    xd = pdw.contact_forces(r.x, params, variant=r.variant).x_D
    f = np.vstack([flags0, r.flags.astype(int)])      # row n + 1: the flags of sample n
    ev = []                                      # (sample, leg 0/1, kind)
    for n in range(len(r.t)):
        for j in range(2):
            if f[n + 1, j] != f[n, j]:
                ev.append((n, j, "td" if f[n + 1, j] else "lo"))
    last_td, last_lo, prev_td, rows = [None, None], [None, None], None, []
    for k, (n, j, kind) in enumerate(ev):
        if kind == "lo":
            last_lo[j] = n
            continue
        i = 1 - j
        if last_lo[j] is not None and last_td[i] is not None and prev_td is not None:
            ds = math.nan
            for m, leg, kd in ev[k + 1:]:
                if kd == "td":
                    break
                if leg == i:
                    ds = r.t[m] - r.t[n]
                    break
            P = r.t[n] - r.t[last_lo[j]]
            L = xd[n, j] - xd[last_td[i], i]
            rows.append(dict(leg=j + 1, t_lift_off=r.t[last_lo[j]], t_touch_down=r.t[n], L=L,
                             travel=xd[n, j] - xd[last_lo[j], j], P=P, v=L / P,
                             cycle=r.t[n] - r.t[prev_td], double_support=ds,
                             ds_fraction=ds / (r.t[n] - r.t[prev_td])))
        last_td[j], prev_td = n, n
    return {k: np.array([row[k] for row in rows]) for k in FIELDS}


RUNS = [
    dict(params=STEADY, t_end=6.0),
    dict(params=STEADY, t_end=6.0, variant="consistent"),
    dict(params=pdw.Params.paper(), t_end=6.0),                       # decays and falls
    dict(params=STEADY, x0=pdw.X0_DISTURBED, t_end=6.0),
    dict(params=pdw.Params.paper(), x0=pdw.X0_DISTURBED, t_end=4.0, variant="consistent"),
]


@pytest.mark.parametrize("kw", RUNS, ids=range(len(RUNS)))
def test_online_descriptors_follow_the_definitions(kw):
    kw = dict(kw)
    x0 = kw.pop("x0", pdw.X0_PAPER)
    r = pdw.simulate(x0, dt=1e-4, integrator=pdw.Integrator(check_step="off"),
                     record=pdw.Record(every=1, forces=False), limits=pdw.Limits(on_failure="return"),
                     **kw)
    ref = _reference_steps(r, kw["params"])
    assert len(ref["L"]) >= 3, r.status
    on = r.gait
    assert len(on) == len(ref["L"]) == r.n_gait_steps
    for name in FIELDS:
        np.testing.assert_allclose(on[name], ref[name], rtol=1e-12, atol=1e-12, err_msg=name)
    # not vacuous: footprint spacing and the swing foot's travel differ, and so do P and cycle
    assert np.all(np.abs(on["travel"] - on["L"]) > 0.05)
    assert np.all(np.abs(on["cycle"] - on["P"]) > 1e-3)
    assert np.isfinite(on["double_support"][:-1]).all()


@pytest.mark.parametrize("method, kw", [("cdm", dict(dt=1e-4)), ("rodas4", dict(rtol=1e-7, atol=1e-9)),
                                        ("rk4", dict(dt=2e-6))])     # the fields of pdw.Integrator
@pytest.mark.parametrize("variant", pdw.VARIANTS)
def test_online_descriptors_are_the_offline_ones(method, kw, variant):
    """`pdw.steps` from the events (offline) and the compiled loop's ring (online), bit for
    bit, on walks, a fall and a disturbed start, with events on the step grid (cdm, rk4) and
    located inside steps (rodas4)."""
    for x0, params, t_end in ((pdw.X0_PAPER, STEADY, 4.0), (pdw.X0_DISTURBED, pdw.Params.paper(), 4.5)):
        if method == "rk4":
            t_end = 1.6
        r = pdw.simulate(x0, t_end=t_end, params=params, method=method, variant=variant,
                         integrator=pdw.Integrator(check_step="off", **kw), record=pdw.Record(every=0),
                         limits=pdw.Limits(on_failure="return"))
        off = pdw.steps(r.events)
        assert len(off) >= 1
        assert len(r.gait) == len(off) == r.n_gait_steps
        for name in FIELDS:
            np.testing.assert_array_equal(r.gait[name], off[name], err_msg=name)
        assert r.event_counts["touch_down"] == sum(e.kind == "touch_down" for e in r.events)
        assert r.event_counts["lift_off"] == sum(e.kind == "lift_off" for e in r.events)


def _spread(tab, n, k):
    """Largest relative spread (max - min) / |latest| over the periodic fields of steps
    n-k .. n-1."""
    out = 0.0
    for f in _layout.PERIODIC_FIELDS:
        w = tab[f][n - k:n]
        out = max(out, (w.max() - w.min()) / abs(w[-1]))
    return out


@pytest.mark.parametrize("k", [2, 3, 5])
def test_periodic_stop_window_is_the_last_k_steps(k):
    """With a tolerance between what k - 1 and k steps need, the run stops where exactly k
    steps agree: not one step early (a window of k - 1) nor late (k + 1)."""
    full = pdw.simulate(t_end=12.0, params=STEADY, integrator=pdw.Integrator(check_step="off"),
                        record=pdw.Record(every=0))
    tab = pdw.steps(full).table
    N = len(tab["L"])
    # a tolerance whose stop under windows k - 1, k and k + 1 differ
    for m in range(k + 1, N):
        tol = _spread(tab, m, k) * (1 + 1e-9)
        first = {w: next((n for n in range(max(w, 2), N + 1) if _spread(tab, n, w) <= tol), None)
                 for w in (k - 1, k, k + 1) if w >= 1}
        if first[k] is not None and len({first[w] for w in first}) == len(first):
            break
    else:
        pytest.fail("no tolerance separates the windows")
    r = pdw.simulate(t_end=12.0, params=STEADY, integrator=pdw.Integrator(check_step="off"),
                     record=pdw.Record(every=0),
                     stop=pdw.Stop(periodic=True, periodic_steps=k, periodic_tol=tol))
    assert r.status == "periodic"
    assert r.n_gait_steps == first[k], (first, tol)
    assert r.t_final == tab["t_touch_down"][first[k] - 1]


def test_steady_averages_the_last_steps():
    """Steps.steady(last): the mean of the last `last` finite entries of each descriptor, and
    the largest difference between consecutive ones among them."""
    L = np.array([1.0, 2.0, 4.0, 8.0, 16.0, 32.0])
    ds = np.array([1.0, 2.0, 4.0, 8.0, np.nan, 32.0])
    table = {f: np.arange(6.0) + 1 for f in FIELDS}
    table.update(L=L, double_support=ds, leg=np.array([1, 2, 1, 2, 1, 2]))
    sd = Steps(table).steady(3)
    assert sd["L"] == pytest.approx((8 + 16 + 32) / 3)
    assert sd["spread_L"] == pytest.approx(16.0)
    assert sd["double_support"] == pytest.approx((4 + 8 + 32) / 3)      # NaN skipped
    assert sd["spread_double_support"] == pytest.approx(24.0)
    assert sd["P"] == pytest.approx(5.0)
    assert Steps(table).steady(1)["L"] == 32.0


def test_steady_of_a_run_is_the_mean_of_its_last_steps():
    r = pdw.simulate(t_end=8.0, params=STEADY, record=pdw.Record(every=0))
    st = pdw.steps(r)
    for last in (1, 2, 4):
        sd = st.steady(last)
        for name in ("L", "P", "travel", "cycle", "v"):
            assert sd[name] == pytest.approx(np.mean(st[name][-last:]), rel=1e-14), (name, last)
