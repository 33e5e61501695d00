"""Continuation studies (docs/continuation.md): writes continuation_<part>.txt and the figures
continuation_*.png under out/benchmarks/ (with --update-docs: benchmarks/results/ and
docs/figures/; `make bench` runs the issue's two codim-2 speed benchmarks, codim2 and fold_kn).

    python benchmarks/continuation.py hybrid    # compass cascade + simplest walker (seconds)
    python benchmarks/continuation.py hybrid_paper  # paper_steady on rigid ground, 8 parameters
    python benchmarks/continuation.py gamma     # continuous model, the slope both ways
    python benchmarks/continuation.py dhip      # continuous model, d_hip from 0.010 to the end
    python benchmarks/continuation.py rigid     # k_n 1e5 -> 1e9, consistent, d_n ~ k_n^(4/3)
    python benchmarks/continuation.py rigid_paper  # the same in the paper variant: its end
    python benchmarks/continuation.py fig11     # Fig. 11 (k_n): continuation vs the sweep
    python benchmarks/continuation.py simplest_limit  # simplest walker's doubling, m_l/m_h -> 0
    python benchmarks/continuation.py kelvin_voigt    # Kelvin-Voigt's contact.d branch (docs/contact_laws.md)
    python benchmarks/continuation.py codim2    # compass doubling curve in (slope, c): CPU time
    python benchmarks/continuation.py goswami   # compass regions in (slope, b/a), (slope, m_H/m)
    python benchmarks/continuation.py region_hip  # paper walker (hybrid): region in (k_hip, d_hip)
    python benchmarks/continuation.py fold_kn   # continuous: paper walker's d_n fold in (k_n, d_n)
    python benchmarks/continuation.py region_kn # continuous: its whole region in (k_n, d_n), checked
    python benchmarks/continuation.py region_hip_continuous  # the same in (k_hip, d_hip)
    python benchmarks/continuation.py codim2_schemes  # continuous fold curve: why it stalled
    python benchmarks/continuation.py ns_search # complex multiplier pairs: any Neimark-Sacker?
    python benchmarks/continuation.py chaos     # orbit diagram, Lyapunov exponents, Feigenbaum
    python benchmarks/continuation.py monodromy # exact (variational) vs finite-difference M
"""
from __future__ import annotations

import os
import pathlib
import sys
import tempfile
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from _results import FIGURES as FIGS  # noqa: E402  (out/benchmarks/ unless --update-docs)
from _results import RESULTS  # noqa: E402

import pdw  # noqa: E402
from pdw import hybrid as H  # noqa: E402
from pdw.analysis.bifurcation.continuation import continue_gait, follow_cascade  # noqa: E402
from pdw.present.cli_continue import preset  # noqa: E402
from pdw.present.plots_continuation import plot_branches, plot_curves  # noqa: E402

DEG = np.pi / 180
OUT = []


def say(*a):
    line = " ".join(str(x) for x in a)
    print(line, flush=True)
    OUT.append(line)


def _bifs(b, scale=1.0, unit=""):
    for f in b.bifurcations:
        if not f.located:
            say("  " + f.describe())
            continue
        say("  %s %-16s at %s = %.10g%s (bracket %.2g): %s"
            % (f.label, f.kind, b.parameter, f.value * scale, unit, f.tolerance * scale,
               f.reason))


def _branch_line(b):
    say("period %d: %d points, %s in [%.8g, %.8g], %d map evaluations (steps), %.2f s; stop: %s"
        % (b.period_n, len(b), b.parameter, b.values.min(), b.values.max(), b.n_maps,
           b.wall_time, b.stop_reason))


def part_hybrid():
    say("== compass gait (Goswami et al. 1998), hybrid model, exact monodromy ==")
    bs = follow_cascade(H.compass_gait_params(), "gamma", 5.3 * DEG, depth=3, model="hybrid",
                        step=0.05 * DEG)
    for b in bs:
        _branch_line(b)
        _bifs(b, 1 / DEG, " deg")
    pd = [b.of_kind("period_doubling")[0].value / DEG for b in bs if b.of_kind("period_doubling")]
    if len(pd) >= 3:
        say("Feigenbaum ratios (g_{k}-g_{k-1})/(g_{k+1}-g_k): %s"
            % ", ".join("%.3f" % ((pd[k] - pd[k - 1]) / (pd[k + 1] - pd[k]))
                        for k in range(1, len(pd) - 1)))
    ax = plot_branches(bs, y="z0", x_scale=1 / DEG, x_label="slope gamma [deg]",
                       title="Compass gait: period-doubling cascade (hybrid model)",
                       path=FIGS / "continuation_compass.png")
    import matplotlib.pyplot as plt
    plt.close(ax.figure)
    say("== simplest walker (Garcia et al. 1998): m_l = 1e-4 m_h, r = 0, g = l = 1 ==")
    for ml in (1e-3, 1e-4, 1e-5):
        b = continue_gait(preset("simplest", m_l=ml), "gamma", 0.0185, model="hybrid")
        say("m_l/m_h = %g:" % ml)
        _branch_line(b)
        _bifs(b)


def part_hybrid_paper():
    say("== the paper's walker (paper_steady) on rigid ground (hybrid model): one parameter at a "
        "time ==")
    P = pdw.Params.paper_steady()
    for par, stop in (("d_hip", 0.1), ("gamma", 0.2), ("gamma", 0.001), ("k_hip", 5.0),
                      ("k_hip", 0.0), ("r", 0.45), ("c", 0.4), ("m_h", 20.0)):
        b = continue_gait(P, par, stop, model="hybrid", max_points=150)
        say("%s from %g towards %g:" % (par, getattr(P, par), stop))
        _branch_line(b)
        _bifs(b)


def part_gamma():
    say("== continuous model (paper_steady, paper variant): the slope gamma, both ways ==")
    P = pdw.Params.paper_steady()
    for stop in (0.002, 0.08):
        b = continue_gait(P, "gamma", stop, max_points=40, workers=2)
        _branch_line(b)
        _bifs(b)
        say("  gamma: %s" % " ".join("%.5f" % v for v in b.values))
        say("  max |mu|: %s" % " ".join("%.3f" % v for v in np.abs(b.multipliers).max(1)))


def part_dhip():
    say("== continuous model (paper_steady, paper variant): d_hip from 0.010 upwards ==")
    b = continue_gait(pdw.Params.paper_steady(d_hip=0.010), "d_hip", 0.03, max_points=60)
    _branch_line(b)
    _bifs(b)
    for i in range(0, len(b), max(1, len(b) // 12)):
        m = np.abs(b.multipliers[i])
        say("  d_hip %.6f  period %.6f s  L %.6f m  DS %.3f ms  |mu| %s  %s"
            % (b.values[i], b.period[i], b.step_length[i], 1e3 * b.double_support[i],
               " ".join("%.4f" % v for v in m[:3]), "stable" if b.stable[i] else "UNSTABLE"))
    ax = plot_branches([b], y="step_length", x_label="hip damping d_hip [N m s/rad]",
                       title="Continuous walker (paper_steady): d_hip",
                       path=FIGS / "continuation_d_hip.png")
    import matplotlib.pyplot as plt
    plt.close(ax.figure)


RIGID_TABLE = {  # docs/studies.md section 3 (benchmarks/rigid_limit.py), consistent variant
    1e5: (0.574051, 0.300107), 3e5: (0.567910, 0.324148), 1e6: (0.566191, 0.333655),
    3e6: (0.565439, 0.337214), 1e7: (0.564938, 0.338931), 3e7: (0.564633, 0.339629),
    1e8: (0.564415, 0.339977), 3e8: (0.564285, 0.340119), 1e9: (0.564193, 0.340188)}


STEADY = pdw.Params.paper_steady()


def _rigid_params_of(k):
    return STEADY.replace(k_n=k, d_n=1e6 * (k / 1e5) ** (4 / 3))


def part_rigid_paper():
    say("== k_n 1e5 -> 1e9 (log), PAPER variant, d_n = 1e6 (k_n/1e5)^(4/3): where does it end? ==")
    b = continue_gait(pdw.Params.paper_steady(), "k_n", 1e9, variant="paper",
                      params_of=_rigid_params_of, value=1e5, log=True, max_points=80)
    _branch_line(b)
    _bifs(b)
    for i in range(len(b)):
        say("  k_n %.4g  period %.6f  L %.6f  DS %.3f ms  |mu| %s %s"
            % (b.values[i], b.period[i], b.step_length[i], 1e3 * b.double_support[i],
               " ".join("%.4f" % v for v in np.abs(b.multipliers[i])[:3]),
               "stable" if b.stable[i] else "UNSTABLE"))
    ax = plot_branches([b], y="max_multiplier", x_label="k_n [N/m^1.5] (d_n ~ k_n^(4/3))",
                       title="paper variant towards rigid ground",
                       path=FIGS / "continuation_k_n_paper.png")
    import matplotlib.pyplot as plt
    plt.close(ax.figure)


def part_rigid():
    say("== rigid limit: k_n 1e5 -> 1e9 (log), consistent, d_n = 1e6 (k_n/1e5)^(4/3) ==")
    p0 = pdw.Params.paper_steady()
    b = continue_gait(p0, "k_n", 1e9, variant="consistent", params_of=_rigid_params_of,
                      value=1e5, log=True, max_points=80, at=list(RIGID_TABLE))
    _branch_line(b)
    _bifs(b)
    say("k_n | period (branch) | table | L (branch) | table | largest abs(mu)")
    for k, (P, L) in RIGID_TABLE.items():
        i = int(np.argmin(np.abs(np.log(b.values / k))))
        say("%.0e | %.6f | %.6f | %.6f | %.6f | %.4f (branch point at %.6g)"
            % (k, b.period[i], P, b.step_length[i], L, np.abs(b.multipliers[i]).max(),
               b.values[i]))
    ax = plot_branches([b], y="step_length", x_label="k_n [N/m^1.5] (d_n ~ k_n^(4/3))",
                       title="Rigid limit (consistent variant)",
                       path=FIGS / "continuation_rigid_limit.png")
    import matplotlib.pyplot as plt
    plt.close(ax.figure)


SWEEP = """
name = "fig11_k_n_095"
preset = "paper_steady"
variant = "paper"
method = "rodas4"
[params]
k_hip = 0.95
[[axes]]
name = "k_n"
start = 0.5e5
stop = 2.5e5
num = 9
[run]
mode = "simulate"
t_end = 16.0
steady = 4
rtol = 1e-7
atol = 1e-9
"""


def part_fig11(rounds=2):
    from pdw import limit_cycle as LC
    from pdw import sweep
    say("== Fig. 11 (k_n, k_hip = 0.95): continuation against the brute-force sweep ==")
    say("sweep: 9 points, 16 s of walking each (rodas4 rtol 1e-7), 2 threads; continuation: "
        "tight = rodas4 rtol 1e-10, Newton tol 1e-8, fd 1e-5 (default); loose = rtol 1e-7, "
        "atol 1e-9, event_tol 1e-10, Newton tol 1e-6, fd 1e-4; both 2 threads, a point at "
        "each of the sweep's k_n; rounds interleaved")
    say("load average before: %s" % (os.getloadavg(),))
    study = sweep.parse_study(SWEEP)
    base = pdw.Params.paper_steady(k_hip=0.95, k_n=0.5e5)
    ks = list(np.linspace(0.5e5, 2.5e5, 9))
    runs = {"tight": {}, "loose": dict(options=dict(LC.LOOSE), tol=1e-6, fd_step=1e-4)}
    for r in range(rounds):
        with tempfile.TemporaryDirectory() as tmp:
            t0 = time.perf_counter()
            res = sweep.run_study(study, tmp, workers=2, progress=False, figures=False,
                                  resume=False)
            t_sweep = time.perf_counter() - t0
        n_sweep = sum(int(row.get("n_steps") or 0) for row in res.rows)
        say("round %d: sweep %d points, %d steps walked, %.2f s" % (r, len(res.rows), n_sweep,
                                                                   t_sweep))
        for name, kw in runs.items():
            t0 = time.perf_counter()
            b = continue_gait(base, "k_n", 2.5e5, workers=2, at=ks, **kw)
            t = time.perf_counter() - t0
            say("round %d: continuation (%s) %d points, %d map evaluations (steps), %.2f s; "
                "wall ratio continuation/sweep %.1f; bifurcations %s"
                % (r, name, len(b), b.n_maps, t, t / t_sweep, b.bifurcations))
            if r == rounds - 1:
                for row in res.rows:
                    k = row["k_n"]
                    i = int(np.argmin(np.abs(b.values - k)))
                    say("  k_n %.4g: sweep L %.6f P %.6f | continuation (%s, at %.6g) L %.6f "
                        "P %.6f (swing = period - double support) |mu| %.4f"
                        % (k, row["L"], row["P"], name, b.values[i], b.step_length[i],
                           b.period[i] - b.double_support[i], np.abs(b.multipliers[i]).max()))
    say("load average after: %s" % (os.getloadavg(),))


def _simplest(gamma, m_l):
    return pdw.Params(l=1.0, c=1.0, w=0.0, r=0.0, J_l=0.0, m_h=1.0, m_l=m_l, k_hip=0.0,
                      d_hip=0.0, gamma=gamma, g=1.0)


def part_simplest_limit():
    say("== simplest walker: first period doubling against m_l/m_h (hybrid, locate_tol 1e-10) ==")
    vals = {}
    for m in (1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8):
        b = continue_gait(_simplest(0.009, m), "gamma", 0.02, model="hybrid", locate_tol=1e-10)
        pd = b.of_kind("period_doubling")[0]
        vals[m] = pd.value
        say("m_l/m_h = %.0e: gamma_PD = %.10f (located %s, bracket %.1e), %.2f s"
            % (m, pd.value, pd.located, pd.tolerance, b.wall_time))
    g7, g8 = vals[1e-7], vals[1e-8]
    say("linear extrapolation to m_l/m_h = 0 from 1e-7 and 1e-8: gamma_PD = %.10f"
        % (g8 - (g7 - g8) * 1e-8 / (1e-7 - 1e-8)))


def part_kelvin_voigt():
    from pdw.analysis.numerics.calibration import calibrate
    P0 = pdw.Params.paper_steady()
    kv = calibrate(P0).contacts["kelvin_voigt"]       # k = W / sink, d from the drop test
    say("== Kelvin-Voigt (k = %.6g, d = %.6g): continued in contact.d down to 10 =="
        % (kv.k, kv.d))
    b = continue_gait(P0, "contact.d", 10.0, step=5.0, max_points=40,
                      options=dict(contact=kv), workers=2)
    _branch_line(b)
    for f in b.bifurcations:
        say("  " + f.describe())
    for mono in ("differences", "exact"):
        say("== the same from contact.d = 109.5 up, step 0.1, monodromy=%r (the period "
            "doubling, located) ==" % mono)
        b = continue_gait(P0, "contact.d", 110.2, step=0.1, max_points=30,
                          options=dict(contact=kv.with_axis("contact.d", 109.5)), workers=2,
                          monodromy=mono)
        _branch_line(b)
        for f in b.bifurcations:
            say("  " + f.describe())
            say("    multipliers %s; cross-check (%s): %.3g %s"
                % (np.round(f.multipliers[:3], 5), f.details.get("fd_check_kind", ""),
                   f.details.get("fd_check", np.nan), f.details.get("fd_check_note", "")))
        for v, m in zip(b.values, b.multipliers):
            say("  contact.d = %.6f  multipliers %s" % (v, np.round(m[:3], 4)))


def part_codim2(rounds=3):
    from pdw.analysis.bifurcation.codim2 import continue_bifurcation
    say("== compass gait: the period-doubling curve in (gamma, c), c 0.5 -> 0.7 (hybrid) ==")
    say("load average before: %s" % (os.getloadavg(),))
    b = continue_gait(H.compass_gait_params(), "gamma", 5.0 * DEG, model="hybrid")
    pd = b.of_kind("period_doubling")[0]
    for r in range(rounds):
        t0 = time.process_time()
        cv = continue_bifurcation(pd, "c", 0.7)
        cpu = time.process_time() - t0
        say("round %d: %d points, gamma %.4f -> %.4f deg, c %.3f -> %.3f, %d map evaluations, "
            "%.2f s CPU (%.2f s wall); stop: %s"
            % (r, len(cv), cv.values[0, 0] / DEG, cv.values[-1, 0] / DEG, cv.values[0, 1],
               cv.values[-1, 1], cv.n_maps, cpu, cv.wall_time, cv.stop_reason))
    for v in cv.values[::3]:
        say("  gamma = %.6f deg  c = %.6f  (b/a = %.4f)" % (v[0] / DEG, v[1], v[1] / (1 - v[1])))
    lo = continue_bifurcation(pd, "c", 0.35)
    say("towards c = 0.35: %d points, %s" % (len(lo), lo.stop_reason))
    mh = [continue_bifurcation(pd, "m_h", s) for s in (5.0, 20.0)]
    for m in mh:
        say("in m_h (m_l = 5): gamma %.4f -> %.4f deg for m_h %.2f -> %.2f; %s"
            % (m.values[0, 0] / DEG, m.values[-1, 0] / DEG, m.values[0, 1], m.values[-1, 1],
               m.stop_reason))
    say("load average after: %s" % (os.getloadavg(),))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(9, 3.8), layout="constrained")
    plot_curves([lo, cv], ax=a1, y_scale=1 / DEG, labels=["from c = 0.5 down", "up"])
    a1.set_ylabel("gamma [deg]")
    a1.set_title("compass gait: its first period doubling in (c, gamma)", fontsize=9)
    plot_curves(mh, ax=a2, y_scale=1 / DEG, labels=["from m_h = 10 down", "up"])
    a2.set_ylabel("gamma [deg]")
    a2.set_xlabel("m_h [kg] (m_l = 5 kg)")
    fig.savefig(FIGS / "continuation_codim2.png", dpi=150)
    say("wrote docs/figures/continuation_codim2.png")


def part_goswami():
    """Goswami, Thuilot & Espiau's regions of the compass gait in the issue's axes: where the
    period-1 gait exists (below the end curve, the trailing foot leaves the ground), where it is
    stable (below its first doubling PD1), and where the period-2 gait is (PD1 to PD2)."""
    from pdw.analysis.bifurcation.codim2 import continue_bifurcation
    say("== compass gait: regions in (slope, b/a) and (slope, m_H/m) (hybrid, exact M) ==")
    say("load average before: %s" % (os.getloadavg(),))
    C = H.compass_gait_params()
    axes = {"b/a": (lambda P, r: P.replace(c=r / (1 + r) * P.l), 1.0, (0.25, 3.0)),
            "m_H/m": (lambda P, r: P.replace(m_h=r * P.m_l), 2.0, (0.1, 10.0))}
    t0 = time.process_time()
    b = continue_gait(C, "gamma", 15 * DEG, model="hybrid", max_points=400)
    pd1, ep = b.of_kind("period_doubling")[0], b.of_kind("end")[0]
    g2 = b.switch(pd1)
    b2 = continue_gait(g2.params, "gamma", 6 * DEG, model="hybrid", period=2, start=g2)
    pd2 = b2.of_kind("period_doubling")[0]
    curves = {}
    for name, (of, v0, stops) in axes.items():
        for lab, bif in (("PD1", pd1), ("PD2", pd2), ("end", ep)):
            parts = []
            for s in stops:
                c0 = time.process_time()
                marks = [r for r in ((0.5, 1.0, 2.0) if name == "b/a" else (0.5, 2.0, 5.0))
                         if min(v0, s) < r < max(v0, s)]
                cv = continue_bifurcation(bif, name, s, params_of=of, value=v0, max_points=300,
                                          at=marks)
                say("%-5s %-3s %s %.2f -> %.4g: %d points, %d maps, %.2f s CPU; gamma %.4f -> "
                    "%.4f deg; stop: %s" % (name, lab, name, v0, cv.values[-1, 1], len(cv),
                                            cv.n_maps, time.process_time() - c0,
                                            cv.values[0, 0] / DEG, cv.values[-1, 0] / DEG,
                                            cv.stop_reason))
                parts.append(cv.values[::-1] if s < v0 else cv.values)
            v = np.vstack([parts[0], parts[1][1:]])
            curves[name, lab] = v
            for r in (0.5, 1.0, 2.0) if name == "b/a" else (0.5, 2.0, 5.0):
                if v[:, 1].min() <= r <= v[:, 1].max():
                    say("      at %s = %.2f: gamma = %.4f deg" % (name, r, np.interp(
                        r, v[:, 1], v[:, 0]) / DEG))
    say("all curves: %.1f s CPU" % (time.process_time() - t0))
    say("load average after: %s" % (os.getloadavg(),))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axs = plt.subplots(1, 2, figsize=(10, 4.2), layout="constrained")
    for ax, name in zip(axs, axes):
        c1, c2 = curves[name, "PD1"] / [DEG, 1], curves[name, "PD2"] / [DEG, 1]
        # polygons: slope 0 to PD1 (period 1 stable), PD1 to PD2 (period 2 stable); both
        # doubling curves end on the end curve, which closes them there
        e = curves[name, "end"] / [DEG, 1]
        e = e[e[:, 1] < c1[0, 1]]              # the end curve below the corner (PD1 meets it)
        ax.fill(np.r_[e[:, 0], c1[:, 0], 0, 0], np.r_[e[:, 1], c1[:, 1], c1[-1, 1], e[0, 1]],
                color="C2", alpha=0.25, lw=0, label="period-1 gait stable")
        ax.fill(np.r_[c1[:, 0], c2[::-1, 0]], np.r_[c1[:, 1], c2[::-1, 1]], color="C1",
                alpha=0.25, lw=0, label="period-2 gait stable")
        for k, st in (("PD1", "C2-"), ("PD2", "C1-"), ("end", "k--")):
            c = curves[name, k]
            ax.plot(c[:, 0] / DEG, c[:, 1], st, lw=1.5,
                    label={"PD1": "PD of the period-1 gait", "PD2": "PD of the period-2 gait",
                           "end": "end: trailing foot stays down"}[k])
        ax.set_xlabel("slope gamma [deg]")
        ax.set_ylabel({"b/a": "b/a [-] (hip-to-leg-mass / leg-mass-to-foot)",
                       "m_H/m": "m_H/m [-] (hip mass / leg mass)"}[name])
        ax.set_xlim(0, 13)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper right" if name == "b/a" else "lower right")
    axs[0].set_title("compass gait, m_H/m = 2", fontsize=9)
    axs[1].set_title("compass gait, b/a = 1", fontsize=9)
    fig.savefig(FIGS / "continuation_goswami.png", dpi=150)
    say("wrote docs/figures/continuation_goswami.png")


def _walks(y, P, n=400):
    """Walk n steps of the hybrid map from y: 0 falls, 1 settles (the last step moves the
    state by < 1e-8), 2 walks on without settling."""
    y_prev = y
    for _ in range(n):
        try:
            y_prev, y = y, H.step_map(y, P)
        except pdw.FellError:
            return 0
    return 1 if np.max(np.abs(y - y_prev)) < 1e-8 else 2


def part_region_hip():
    """The paper walker on rigid ground (hybrid model): where its gait exists and is stable in
    (k_hip, d_hip), the d_hip fold followed in k_hip, against a brute-force grid of find_gait."""
    from pdw.analysis.bifurcation.codim2 import continue_bifurcation
    say("== paper_steady (hybrid): the existence and stability region in (k_hip, d_hip) ==")
    say("load average before: %s" % (os.getloadavg(),))
    P = pdw.Params.paper_steady()
    t0 = time.process_time()
    b = continue_gait(P, "d_hip", 0.1, model="hybrid", max_points=150)
    fold = b.of_kind("fold")[0]
    parts = []
    for stop in (0.0, 6.0):
        c0 = time.process_time()
        cv = continue_bifurcation(fold, "k_hip", stop, max_points=300,
                                  at=[0.5] if stop < 0.95 else [2.0, 3.9838, 5.0])
        say("fold d_hip = %.7f at k_hip = 0.95 followed to k_hip %.4g: %d points, %d maps, "
            "%.2f s CPU; d_hip %.6f -> %.6f; stop: %s"
            % (fold.value, cv.values[-1, 1], len(cv), cv.n_maps, time.process_time() - c0,
               cv.values[0, 0], cv.values[-1, 0], cv.stop_reason))
        parts.append(cv.values[::-1] if stop < 0.95 else cv.values[1:])
    curve = np.vstack(parts)
    for k in (0.0, 0.5, 0.95, 2.0, 3.9838, 5.0):
        say("  k_hip = %.4f: fold at d_hip = %.6f" % (k, np.interp(k, curve[:, 1], curve[:, 0])))
    say("fold curve: %.2f s CPU" % (time.process_time() - t0))
    c0 = time.process_time()
    bk = continue_gait(P, "k_hip", 0.0, model="hybrid")
    b0 = continue_gait(P.replace(k_hip=0.0), "d_hip", 0.0, model="hybrid", start=bk.state[-1])
    pd = b0.of_kind("period_doubling")[0]
    pdc = continue_bifurcation(pd, "k_hip", 1.0)
    lobe = pdc.values
    say("period doubling at k_hip = 0, d_hip = %.7f (paper_steady's family continued to "
        "k_hip = 0, then in d_hip) followed in k_hip: %d points, %.2f s CPU, to k_hip = %.5f, "
        "d_hip = %.3g; stop: %s" % (pd.value, len(pdc), time.process_time() - c0,
                                    lobe[-1, 1], lobe[-1, 0], pdc.stop_reason))
    # brute force: long walks on a grid, each row from the gait of paper_steady's family at
    # d_hip = 0.005 (continued in k_hip: at small k_hip find_gait alone finds another, unstable
    # gait, multiplier 3.7 at k_hip = 0)
    t0 = time.process_time()
    ks, ds = np.linspace(0.0, 6.0, 25), np.linspace(0.0005, 0.024, 24)
    P5 = P.replace(d_hip=0.005)
    rows = [continue_gait(P5, "k_hip", s, model="hybrid", at=list(ks)) for s in (0.0, 6.0)]
    grid = np.zeros((len(ks), len(ds)), dtype=int)  # 0 falls, 1 settles on a gait, 2 walks on
    for i, k in enumerate(ks):
        r = rows[0] if k <= 0.95 else rows[1]
        y0 = r.state[int(np.argmin(np.abs(r.values - k)))]
        for j, d in enumerate(ds):
            grid[i, j] = _walks(y0, P.replace(k_hip=k, d_hip=d))
    say("grid %d x %d of 400-step walks: %d settle on a gait, %d walk on unsettled, %d fall; "
        "%.1f s CPU" % (len(ks), len(ds), (grid == 1).sum(), (grid == 2).sum(),
                        (grid == 0).sum(), time.process_time() - t0))
    d_at = np.interp(ks, curve[:, 1], curve[:, 0])
    wrong = [(k, d, grid[i, j]) for i, k in enumerate(ks) for j, d in enumerate(ds)
             if (grid[i, j] != 0) != (d < d_at[i])]
    say("grid points on the wrong side of the fold curve (walks above / falls below): %d %s"
        % (len(wrong), wrong[:6]))
    l_at = np.interp(ks, lobe[:, 1], lobe[:, 0], right=-1.0)
    wrong = [(k, d, grid[i, j]) for i, k in enumerate(ks) for j, d in enumerate(ds)
             if grid[i, j] != 0 and (grid[i, j] == 2) != (d < l_at[i])]
    say("walking grid points on the wrong side of the doubling curve (unsettled above / "
        "settled below): %d %s" % (len(wrong), wrong[:6]))
    say("load average after: %s" % (os.getloadavg(),))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6.2, 4.4), layout="constrained")
    ax.fill_between(curve[:, 1], 0, curve[:, 0], color="C2", alpha=0.2,
                    label="period-1 gait exists")
    ax.plot(curve[:, 1], curve[:, 0], "C2-", lw=1.8, label="fold (continue_bifurcation)")
    ax.fill(np.r_[lobe[:, 1], 0], np.r_[lobe[:, 0], 0], color="C1", alpha=0.35, lw=0,
            label="period-1 gait unstable (past a doubling)")
    ax.plot(lobe[:, 1], lobe[:, 0], "C1-", lw=1.5, label="period doubling")
    kk, dd = np.meshgrid(ks, ds, indexing="ij")
    for v, mk, lab in ((1, "C2o", "400-step walk settles"), (2, "C0^", "walks, unsettled"),
                       (0, "kx", "the walker falls")):
        m = grid == v
        ax.plot(kk[m], dd[m], mk, ms=2.5, label=lab)
    ax.plot([0.95], [0.010], "k*", ms=9, label="paper_steady")
    ax.set_xlabel("k_hip [N m/rad]")
    ax.set_ylabel("d_hip [N m s/rad]")
    ax.set_title("paper walker on rigid ground (hybrid), slope 0.02 rad", fontsize=9)
    ax.legend(fontsize=7, loc="upper right")
    ax.grid(alpha=0.3)
    fig.savefig(FIGS / "continuation_region_hip.png", dpi=150)
    say("wrote docs/figures/continuation_region_hip.png")


def part_fold_kn():
    """The continuous model's (paper_steady, paper variant) low-d_n fold followed in k_n: the
    edge of the paper walker's existence and stability region in (k_n, d_n), with CPU and wall
    time (the issue's budget: 10 minutes on 2 cores), against long walks of the step map."""
    from pdw.analysis.bifurcation.codim2 import continue_bifurcation
    from pdw.analysis.stepmap import poincare
    say("== paper_steady (continuous, paper variant): its d_n fold followed in k_n ==")
    say("load average before: %s" % (os.getloadavg(),))
    P = pdw.Params.paper_steady()
    w0, c0 = time.perf_counter(), time.process_time()
    b = continue_gait(P, "d_n", 1e3, log=True, max_points=25, workers=2)
    fold = b.of_kind("fold")[0]
    say("one parameter, d_n 1e6 -> down: %d points, %d maps, %.1f s wall, %.1f s CPU; first "
        "fold at d_n = %.7g (k_n = 1e5)" % (len(b), b.n_maps, time.perf_counter() - w0,
                                             time.process_time() - c0, fold.value))
    curves = []
    for stop in (3e5, 3e4):
        w0, c0 = time.perf_counter(), time.process_time()
        cv = continue_bifurcation(fold, "k_n", stop, fd_step=1e-4, max_points=60)
        say("fold curve k_n 1e5 -> %.3g: %d points, %d maps, %.1f s wall, %.1f s CPU (2 "
            "threads); d_n %.6g -> %.6g; max |mu - 1| of the nearest multiplier %.2g; stop: %s"
            % (stop, len(cv), cv.n_maps, time.perf_counter() - w0, time.process_time() - c0,
               cv.values[0, 0], cv.values[-1, 0],
               np.max(np.min(np.abs(cv.multipliers - 1.0), axis=1)), cv.stop_reason))
        curves.append(cv)
    for cv in curves:
        for v in cv.values[::4]:
            say("  k_n = %.6g  d_n = %.6g" % (v[1], v[0]))
    # brute force: 120-step walks on a grid, each column from the gait at d_n = 1e6
    w0, c0 = time.perf_counter(), time.process_time()
    kns = np.array([4e4, 6e4, 1e5, 1.5e5, 2e5, 3e5])
    dns = np.geomspace(1.5e4, 2e5, 9)
    rows = [continue_gait(P, "k_n", s, log=True, at=[k for k in kns if (k < 1e5) == (s < 1e5)],
                          max_points=30, workers=2) for s in (3e4, 3.5e5)]
    grid = np.zeros((len(kns), len(dns)), dtype=int)
    for i, k in enumerate(kns):
        r = rows[0] if k < 1e5 else rows[1]
        z0 = r.z[int(np.argmin(np.abs(r.values - k)))]
        for j, d in enumerate(dns):
            z, zp, ok = z0, z0, True
            for _ in range(120):
                out = poincare.step(z, P.replace(k_n=k, d_n=d))
                if out["status"] != "ok":
                    ok = False
                    break
                zp, z = z, out["z"]
            grid[i, j] = 0 if not ok else (1 if np.max(np.abs(z - zp)) < 1e-6 else 2)
    say("grid %d x %d of 120-step walks: %d settle, %d walk unsettled, %d fall; %.1f s wall, "
        "%.1f s CPU" % (len(kns), len(dns), (grid == 1).sum(), (grid == 2).sum(),
                        (grid == 0).sum(), time.perf_counter() - w0, time.process_time() - c0))
    allv = np.vstack([curves[1].values[::-1], curves[0].values[1:]])
    for i, k in enumerate(kns):
        say("  k_n = %.3g: walks (d_n: F fell, S settled, U unsettled): %s" % (k, " ".join(
            "%.3g:%s" % (d, "FSU"[grid[i, j]]) for j, d in enumerate(dns))))
    # the 10-minute benchmark of the issue: a longer fold curve, of the d_hip = 0.014 walker
    P14 = P.replace(d_hip=0.014)
    w0, c0 = time.perf_counter(), time.process_time()
    b14 = continue_gait(P14, "d_n", 1e8, log=True, max_points=30, workers=2)
    f14 = b14.of_kind("fold")[0]
    cv14 = continue_bifurcation(f14, "k_n", 1e6, fd_step=1e-4, max_points=80)
    say("d_hip = 0.014: fold at d_n = %.7g (k_n = 1e5) followed in k_n: %d points, %d maps, "
        "%.1f s wall, %.1f s CPU (2 threads, with the one-parameter run that found it); k_n "
        "in [%.4g, %.4g], d_n in [%.4g, %.4g]; max |mu - 1| %.2g; stop: %s"
        % (f14.value, len(cv14), cv14.n_maps, time.perf_counter() - w0,
           time.process_time() - c0, cv14.values[:, 1].min(), cv14.values[:, 1].max(),
           cv14.values[:, 0].min(), cv14.values[:, 0].max(),
           np.max(np.min(np.abs(cv14.multipliers - 1.0), axis=1)), cv14.stop_reason))
    say("load average after: %s" % (os.getloadavg(),))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax, a2) = plt.subplots(1, 2, figsize=(11, 4.4), layout="constrained")
    a2.plot(cv14.values[:, 1], cv14.values[:, 0], "C3.-", lw=1.5, ms=3)
    a2.plot([1e5], [f14.value], "ks", ms=5, label="start: LP of the d_n family")
    a2.set_xlabel("k_n [N/m^1.5]")
    a2.set_ylabel("d_n [N s/m^2.5]")
    a2.set_yscale("log")
    a2.set_title("d_hip = 0.014: the fold curve (%d points, %.0f s wall)"
                 % (len(cv14), time.perf_counter() - w0), fontsize=9)
    a2.legend(fontsize=7)
    a2.grid(alpha=0.3, which="both")
    ax.plot(allv[:, 1], allv[:, 0], "C3-", lw=1.8, label="fold (continue_bifurcation)")
    kk, dd = np.meshgrid(kns, dns, indexing="ij")
    for v, mk, lab in ((1, "C2o", "120-step walk settles"), (2, "C0^", "walks, unsettled"),
                       (0, "kx", "the walker falls")):
        m = grid == v
        ax.plot(kk[m], dd[m], mk, ms=4, label=lab)
    ax.plot([1e5], [1e6], "k*", ms=9, label="paper_steady")
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("k_n [N/m^1.5]")
    ax.set_ylabel("d_n [N s/m^2.5]")
    ax.set_title("paper_steady (d_hip = 0.01): fold of the low-d_n end, and long walks",
                 fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3, which="both")
    fig.savefig(FIGS / "continuation_fold_kn.png", dpi=150)
    say("wrote docs/figures/continuation_fold_kn.png")


def _columns(P, kns, d_lo, d_hi, max_points=50, outer="k_n", inner="d_n", log=True,
             start=None, row_points=40):
    """One-parameter continuations in ``inner`` (d_n) of the family of P at each ``outer``
    value in kns (k_n; started on the family's gait at P's ``inner``, reached by a continuation
    in ``outer`` from P's value both ways), down to d_lo and up to d_hi; ``log``: both axes
    logarithmic. A change of the step's event sequence is reported (UZ), not taken as the
    family's end."""
    from pdw.analysis.bifurcation import testfunctions as TF
    det = ("fold", "period_doubling", "neimark_sacker")
    k0 = getattr(P, outer)
    rows = [continue_gait(P, outer, s, log=log, at=[k for k in kns if (k < k0) == (s < k0)],
                          max_points=row_points, workers=2, start=start)
            for s in ((kns.min() * 0.9, kns.max() * 1.1) if log else (kns.min(), kns.max()))]
    cols = []
    for k in kns:
        r = rows[0] if k < k0 else rows[1]
        i = int(np.argmin(np.abs(np.log(r.values / k)) if log else np.abs(r.values - k)))
        if abs(r.values[i] - k) > 1e-6 * max(abs(k), 1.0):
            say("%s = %.4g: no column, the %s continuation at %s = %.4g ended at %.6g (%s)"
                % (outer, k, outer, inner, getattr(P, inner), r.values[i], r.stop_reason))
            continue
        z0 = r.z[i]
        Pk = P.replace(**{outer: float(r.values[i])})
        parts = {}
        for name, stop in (("down", d_lo), ("up", d_hi)):
            parts[name] = continue_gait(
                Pk, inner, stop, log=log, start=z0, workers=2,
                max_points=max_points if name == "down" else 25,
                detect=det, events=[TF.AdmissibleEnd(skip=("event_sequence",)),
                                    TF.SequenceChange()])
        cols.append((float(r.values[i]), parts))
    return cols


def _first_edge(b):
    """The first bifurcation along a branch from its start that ends the stable family: the
    first fold, doubling, NS or end (a UZ is not an edge), or None."""
    for f in b.bifurcations:
        if f.kind in ("fold", "period_doubling", "neimark_sacker", "end"):
            return f
    return None


def _stable_set(b):
    """Intervals of d_n where the branch has a stable point: runs of stable points, each
    extended to the bifurcation (fold, doubling, NS) of the step that leaves the run."""
    v, st = b.values, b.stable
    out, i = [], 0
    while i < len(v):
        if not st[i]:
            i += 1
            continue
        j = i
        while j + 1 < len(v) and st[j + 1]:
            j += 1
        lo, hi = min(v[i], v[j]), max(v[i], v[j])
        for f in b.bifurcations:
            if f.kind != "event" and f.index in (i - 1, j):
                lo, hi = min(lo, f.value), max(hi, f.value)
        out.append((lo, hi))
        i = j + 1
    return out


def _classify_walks(res):
    """0 fell, 1 settled on a period-1 gait, 2 on a period-2 gait, 3 walks on unsettled, from
    the last 8 step lengths of each walker of a batch (10 um)."""
    out = np.zeros(len(res), dtype=int)
    for i in range(len(res)):
        if res.status[i] not in ("walked", "periodic"):
            continue
        L = res.steps(i)["L"][-8:]
        if len(L) < 8 or not np.isfinite(L).all():
            out[i] = 3
        elif np.ptp(L) < 1e-5:
            out[i] = 1
        elif np.ptp(L[::2]) < 1e-5 and np.ptp(L[1::2]) < 1e-5:
            out[i] = 2
        else:
            out[i] = 3
    return out


def _edge_text(f, inner):
    if f is None:
        return "none"
    return "%s %s at %s = %.7g (%s)" % (
        f.label, f.kind, inner, f.value, "+-%.2g" % f.tolerance if f.located else
        "detected, not located: [%.7g, %.7g]" % f.bracket)


def _region(P, outer, inner, kns, d_lo, d_hi, kg, dg, log, t_walk, units, name,
            curves=(), start=None, row_points=40, follow=None):
    """The existence and stability region of P's family in (outer, inner): `_columns` at kns
    (each edge labelled), a brute-force grid (kg x dg) of walks of t_walk s on the ensemble
    engine compared with the columns' first edges below and above P's ``inner`` value, and
    the figure continuation_<name>.png; ``curves``: (label, values (N, 2) = (inner, outer))
    drawn over it; ``follow(cols)``: more such curves, from the columns' bifurcations."""
    s0 = getattr(P, inner)
    w0, c0 = time.perf_counter(), time.process_time()
    cols = _columns(P, kns, d_lo, d_hi, outer=outer, inner=inner, log=log, start=start,
                    row_points=row_points)
    kns = np.array([k for k, _ in cols])
    curves = list(curves) + (list(follow(cols)) if follow is not None else [])
    say("%d columns of %s continuations (down to %.3g, up to %.3g, from %s = %.3g): %.1f s "
        "wall, %.1f s CPU (2 threads)" % (len(cols), inner, d_lo, d_hi, inner, s0,
                                          time.perf_counter() - w0, time.process_time() - c0))
    say("per column: the first edge below and above %s = %.3g (label at value, bracket), the "
        "stable intervals, every special point below (UZ: the event sequence changes, "
        "bracketed), the stop" % (inner, s0))
    edges, ups, stab = [], [], []
    for k, parts in cols:
        dn, up = parts["down"], parts["up"]
        f, fu = _first_edge(dn), _first_edge(up)
        edges.append(f)
        ups.append(fu)
        ints = _stable_set(dn) + _stable_set(up)
        stab.append(ints)
        say("%s = %.4g: first edge %s; above: %s; stable %s in %s" % (
            outer, k, _edge_text(f, inner),
            "no edge up to %.3g" % up.values.max() if fu is None else _edge_text(fu, inner),
            inner, " ".join("[%.4g, %.4g]" % iv for iv in ints)))
        for g in dn.bifurcations:
            say("    %s" % g.describe())
        say("    down: %d points, %s down to %.5g, stop: %s" % (len(dn), inner, dn.values.min(),
                                                             dn.stop_reason))
        if fu is not None:
            say("    up: %d points, stop: %s" % (len(up), up.stop_reason))
    # brute force: walks of t_walk s on the ensemble engine (rodas4), each cell started on
    # the family's gait of the nearest column at the nearest value of the sheet connected to
    # the start (each run up to its first fold)
    dist = (lambda a, b: np.abs(np.log(a / b))) if log else (lambda a, b: np.abs(a - b))
    x0, plist = [], []
    for k in kg:
        ic = int(np.argmin(dist(kns, k)))
        parts = cols[ic][1]
        keep_v, keep_x = [], []
        for nm, f in (("down", edges[ic]), ("up", ups[ic])):
            br = parts[nm]
            n = len(br) if f is None or f.kind != "fold" else f.index + 1
            keep_v.append(br.values[:n])
            keep_x.append(br.state[:n])
        vals, states = np.concatenate(keep_v), np.vstack(keep_x)
        for d in dg:
            x0.append(states[int(np.argmin(dist(vals, d)))])
            plist.append(P.replace(**{outer: float(k), inner: float(d)}))
    w0, c0 = time.perf_counter(), time.process_time()
    res = pdw.simulate_batch(np.array(x0), t_walk, params=plist, flags0=(1, 1), threads=2,
                             integrator=pdw.Integrator(method="rodas4", rtol=1e-9,
                                                       atol=1e-11, dt=1e-4))
    grid = _classify_walks(res).reshape(len(kg), len(dg))
    say("brute force: %d x %d walks of %.0f s (%s %.4g .. %.4g, %s %.4g .. %.4g; "
        "simulate_batch, rodas4 rtol 1e-9): %d settle on a period-1 gait, %d period 2, %d walk "
        "on unsettled, %d fall; %.1f s wall, %.1f s CPU" % (
            len(kg), len(dg), t_walk, outer, kg[0], kg[-1], inner, dg[0], dg[-1],
            (grid == 1).sum(), (grid == 2).sum(), (grid == 3).sum(), (grid == 0).sum(),
            time.perf_counter() - w0, time.process_time() - c0))
    say("first edge below %s = %.3g, by column: %s" % (inner, s0, "; ".join(
        "%.4g: %s" % (k, "-" if f is None else "%s %.6g" % (f.label[:2], f.value))
        for (k, _), f in zip(cols, edges))))
    say("first edge above it, by column: %s" % "; ".join(
        "%.4g: %s" % (k, "-" if f is None else "%s %.6g" % (f.label[:2], f.value))
        for (k, _), f in zip(cols, ups)))
    # the cells against the columns: a walk starts on the sheet of the family connected to
    # P's gait, so it is predicted to settle where the value is in that sheet's stable
    # interval (the one containing s0: between the column's first edges). Cells in the
    # column's other stable intervals (another stable gait of the family: bistable) are
    # counted apart. Cells between two columns: compared where both neighbours agree.
    def on_start(lo, hi):           # (the down and up runs start at s0 to rounding)
        return lo <= s0 * (1 + 1e-9) and hi >= s0 * (1 - 1e-9)

    def main(ic, d):
        return any(lo <= d <= hi for lo, hi in stab[ic] if on_start(lo, hi))

    def other(ic, d):
        return any(lo <= d <= hi for lo, hi in stab[ic] if not on_start(lo, hi))
    wrong, skipped, ncmp, islands = [], 0, 0, []
    outside = [(k, d, "FS2U"[grid[a, j]]) for a, k in enumerate(kg) for j, d in enumerate(dg)
               if not kns.min() <= k <= kns.max()]
    if outside:
        say("cells beyond the last column (not compared): %d, walks there: %s" % (
            len(outside), " ".join("%.4g/%.4g:%s" % c for c in outside)))
    for a, k in enumerate(kg):
        if not kns.min() <= k <= kns.max():
            continue
        near = np.argsort(dist(kns, k))[:2]
        on = dist(kns[near[0]], k) < 1e-9 * max(1.0, abs(k))
        for j, d in enumerate(dg):
            ics = [near[0]] if on else list(near)
            pa = main(ics[0], d)
            if any(main(ic, d) != pa for ic in ics):
                skipped += 1
                continue
            if not pa and any(other(ic, d) for ic in ics):
                islands.append((k, d, "FS2U"[grid[a, j]]))
                continue
            ncmp += 1
            if pa != (grid[a, j] == 1):
                wrong.append((k, d, "FS2U"[grid[a, j]], pa))
    say("cells outside the start's stable interval where the column has another stable gait "
        "(bistable; the walk starts on the start's sheet): %d, walks there (F fell, S "
        "settled, U unsettled): %s" % (len(islands), " ".join("%.4g/%.4g:%s" % c
                                                              for c in islands)))
    say("cells compared: %d (on the columns and between two agreeing ones; %d between "
        "disagreeing columns not compared); disagreeing with the first edges: %d"
        % (ncmp, skipped, len(wrong)))
    for k, d, g, pa in wrong:
        say("  %s = %.4g %s = %.4g: walk %s (F fell, S settled, U unsettled), predicted %s"
            % (outer, k, inner, d, g, "to settle" if pa else "not to settle"))
    say("load average after: %s" % (os.getloadavg(),))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(7.6, 5.6), layout="constrained")
    kk, dd = np.meshgrid(kg, dg, indexing="ij")
    for v, mk, lab in ((1, "C2o", "walk settles (period 1)"), (2, "C1.", "period 2"),
                       (3, "C0^", "walks, unsettled"), (0, "kx", "the walker falls")):
        m = grid == v
        if m.any():
            ax.plot(kk[m], dd[m], mk, ms=3, alpha=0.55, label=lab)
    for k, parts in cols:
        for nm in ("down", "up"):
            br = parts[nm]
            for i in range(len(br) - 1):
                st = br.stable[i] and br.stable[i + 1]
                ax.plot([k, k], br.values[i:i + 2], "-", color="C2" if st else "0.6",
                        lw=3.0 if st else 1.0, solid_capstyle="butt")
            for f in br.bifurcations:
                mk = {"fold": "C3v", "neimark_sacker": "C4D", "period_doubling": "C1s",
                      "end": "ks", "event": "k|"}[f.kind]
                ax.plot([k], [f.value], mk, ms=6 if f.kind != "event" else 9,
                        mfc=mk[:2] if f.located else "none")
    # the edges of the stable family connected to P's gait: each column's first edges, where
    # the gait at the start value is stable (the shaded interval)
    lo_e = np.array([d_lo if f is None else f.value for f in edges])
    hi_e = np.array([d_hi if f is None else f.value for f in ups])
    kc = np.array([k for k, _ in cols])
    ok = np.array([any(on_start(lo, hi) for lo, hi in iv) for iv in stab])
    ax.fill_between(kc, lo_e, hi_e, where=ok, color="C2", alpha=0.10, lw=0)
    for e, f_list in ((lo_e, edges), (hi_e, ups)):
        sel = [i for i, f in enumerate(f_list) if f is not None and ok[i]]
        if sel:
            ax.plot(kc[sel], e[sel], "k--", lw=1.0)
            for i in sel:
                ax.annotate(f_list[i].label, (kc[i], e[i]), textcoords="offset points",
                            xytext=(4, -9), fontsize=7)
    ax.plot([], [], "k--", lw=1.0, label="first edges from the start (%s = %.3g), where "
            "stable" % (inner, s0))
    for lab, mk in (("LP fold", "C3v"), ("NS Neimark-Sacker", "C4D"),
                    ("PD period doubling", "C1s"), ("EP end", "ks"),
                    ("UZ event sequence changes (not an edge)", "k|")):
        ax.plot([], [], mk, label=lab)
    ax.plot([], [], "-", color="C2", lw=3, label="stable (columns: continue_gait in %s)"
            % inner)
    ax.plot([], [], "-", color="0.6", lw=1, label="unstable")
    for i, (lab, v) in enumerate(curves):
        ax.plot(v[:, 1], v[:, 0], "C3-", lw=1.5, label=lab if i == 0 or lab != curves[0][0]
                else None)
    ax.plot([getattr(pdw.Params.paper_steady(), outer)],
            [getattr(pdw.Params.paper_steady(), inner)], "k*", ms=10, label="paper_steady")
    if log:
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_ylim(dg[0] / 1.3, d_hi * 1.3)
    else:
        ax.set_ylim(min(dg[0], d_lo), d_hi)
    ax.set_xlabel("%s [%s]" % (outer, units[0]))
    ax.set_ylabel("%s [%s]" % (inner, units[1]))
    ax.set_title("paper_steady (continuous, paper variant): existence and stability in "
                 "(%s, %s)" % (outer, inner), fontsize=9)
    ax.legend(fontsize=6.5, loc="upper left" if log else "upper right", ncol=2)
    ax.grid(alpha=0.3, which="both")
    fig.savefig(FIGS / ("continuation_%s.png" % name), dpi=150)
    say("wrote docs/figures/continuation_%s.png" % name)


def part_region_kn(n_cols=11, n_rows=41, t_walk=60.0):
    """The continuous paper walker's (paper_steady, paper variant) existence and stability
    region in (k_n, d_n): columns of one-parameter d_n continuations at n_cols k_n (every
    edge labelled: LP, PD, NS, EP; changes of the event sequence UZ), the followed fold curve,
    and a brute-force grid of long walks on the ensemble engine, compared cell by cell."""
    from pdw.analysis.bifurcation.codim2 import continue_bifurcation
    say("== paper_steady (continuous, paper variant): existence and stability in (k_n, d_n) ==")
    say("load average before: %s" % (os.getloadavg(),))
    P = pdw.Params.paper_steady()
    # the fold of the d_n family at k_n = 1e5 (paper_steady's), followed in k_n both ways
    w0, c0 = time.perf_counter(), time.process_time()
    b = continue_gait(P, "d_n", 1e3, log=True, max_points=25, workers=2)
    fold = b.of_kind("fold")[0]
    kns = 10 ** np.linspace(4.5, 5.5, n_cols)
    fcs = []
    for stop in (kns.max(), kns.min()):
        cv = continue_bifurcation(fold, "k_n", stop, fd_step=1e-4, max_points=40,
                                  skip=("event_sequence",))
        fcs.append(cv)
        say("fold d_n = %.7g at k_n = 1e5 followed to %.3g: %d points, k_n %.4g -> %.4g, d_n "
            "%.6g -> %.6g; UZ %s; stop: %s" % (
                fold.value, stop, len(cv), cv.values[0, 1], cv.values[-1, 1], cv.values[0, 0],
                cv.values[-1, 0], ["%.4g" % f.value for f in cv.branch.bifurcations
                                   if f.kind == "event"], cv.stop_reason))
    say("fold curves: %.1f s wall, %.1f s CPU" % (time.perf_counter() - w0,
                                                  time.process_time() - c0))
    fc = np.vstack([fcs[1].values[::-1], fcs[0].values[1:]])
    d_lo, d_hi = 5e3, 1e7

    def follow(cols):
        """The first-edge folds of the columns at k_n = 6.31e4 and 2e5 followed in k_n both
        ways (the low-k_n fold and the upper sheet's fold)."""
        out = []
        for k_at, stops in ((6.31e4, (3e4, 1e5)), (1.995e5, (1.4e5, 3.3e5))):
            k, parts = min(cols, key=lambda c: abs(np.log(c[0] / k_at)))
            f = _first_edge(parts["down"])
            if f is None or f.kind != "fold" or not f.located:
                say("column k_n = %.4g: no located fold to follow" % k)
                continue
            w0, c0 = time.perf_counter(), time.process_time()
            vs = []
            for stop in stops:
                cv = continue_bifurcation(f, "k_n", stop, fd_step=1e-4, max_points=40,
                                          skip=("event_sequence",))
                vs.append(cv.values)
                say("fold d_n = %.7g at k_n = %.4g followed to %.3g: %d points, k_n %.4g -> "
                    "%.4g, d_n %.6g -> %.6g; UZ %s; stop: %s" % (
                        f.value, k, stop, len(cv), cv.values[0, 1], cv.values[-1, 1],
                        cv.values[0, 0], cv.values[-1, 0],
                        ["%.4g" % g.value for g in cv.branch.bifurcations
                         if g.kind == "event"], cv.stop_reason))
                for kv in (4e4, 5e4, 8e4, 1.5e5, 2.5e5, 3e5):
                    try:
                        say("    at k_n = %.4g: d_n = %.7g" % (kv, cv.at(kv)))
                    except pdw.InvalidInputError:
                        pass
            say("  %.1f s wall, %.1f s CPU" % (time.perf_counter() - w0,
                                              time.process_time() - c0))
            out.append(("fold curve (continue_bifurcation)",
                        np.vstack([vs[0][::-1], vs[1][1:]])))
        return out
    _region(P, "k_n", "d_n", kns, d_lo, d_hi, 10 ** np.linspace(4.5, 5.5, 2 * n_cols - 1),
            10 ** np.linspace(np.log10(d_lo) + 0.15, np.log10(d_hi), n_rows), True, t_walk,
            ("N/m^1.5", "N s/m^2.5"), "region_kn",
            curves=[("fold curve (continue_bifurcation)", fc)], follow=follow)


def part_region_hip_continuous(n_cols=13, n_rows=25, t_walk=60.0):
    """The continuous paper walker's existence and stability region in (k_hip, d_hip), as
    `part_region_kn` (the hybrid model's: `part_region_hip`): columns in d_hip from 0.002 at
    n_cols k_hip in [0, 6], against a brute-force grid."""
    say("== paper_steady (continuous, paper variant): existence and stability in (k_hip, "
        "d_hip) ==")
    say("load average before: %s" % (os.getloadavg(),))
    P5 = continue_gait(pdw.Params.paper_steady(), "d_hip", 0.002, max_points=30, workers=2)
    P = pdw.Params.paper_steady().replace(d_hip=0.002)
    say("paper_steady's family continued to d_hip = 0.002: %d points, stop: %s"
        % (len(P5), P5.stop_reason))
    kns = np.linspace(0.0, 6.0, n_cols)
    _region(P, "k_hip", "d_hip", kns, 0.0, 0.03, np.linspace(0.0, 6.0, 2 * n_cols - 1),
            np.linspace(0.0005, 0.03, n_rows), False, t_walk, ("N m/rad", "N m s/rad"),
            "region_hip_continuous", start=P5.z[-1], row_points=120)


def part_codim2_schemes():
    """The continuous fold curve's two derivative schemes interleaved (8 points each, two
    rounds), and sigma_tol = tol = 1e-9: the stall of the last round."""
    from pdw.analysis.bifurcation.codim2 import continue_bifurcation
    say("== d_hip = 0.014 walker's d_n fold in k_n: directional vs monodromy second "
        "differences ==")
    say("load average before: %s" % (os.getloadavg(),))
    P = pdw.Params.paper_steady(d_hip=0.014)
    b = continue_gait(P, "d_n", 1e8, log=True, max_points=30, workers=2)
    f = b.of_kind("fold")[0]
    for r in range(2):
        for sec in ("directional", "monodromy"):
            w0, c0 = time.perf_counter(), time.process_time()
            cv = continue_bifurcation(f, "k_n", 2e5, fd_step=1e-4, max_points=8, second=sec)
            say("round %d %-11s: %d points, %d maps, %.1f s wall, %.1f s CPU; to k_n = %.6g"
                % (r, sec, len(cv), cv.n_maps, time.perf_counter() - w0,
                   time.process_time() - c0, cv.values[-1, 1]))
    try:
        continue_bifurcation(f, "k_n", 2e5, fd_step=1e-4, max_points=8, sigma_tol=1e-9)
        say("sigma_tol = 1e-9: ran")
    except pdw.GaitNotFoundError as e:
        say("sigma_tol = 1e-9 (the last round's behaviour): %s" % e)
    say("load average after: %s" % (os.getloadavg(),))


def part_ns_search():
    """Where could a Neimark-Sacker point be? The largest modulus of a complex pair of
    multipliers along one-parameter families of the hybrid paper walker (d_hip from 0 to its
    fold, at 25 k_hip in [0, 6]; the slope from 0.02 to 0.2) and of the compass gait (slope)."""
    say("== Neimark-Sacker search: complex multiplier pairs along families (hybrid) ==")
    P = pdw.Params.paper_steady()
    t0 = time.process_time()
    best, n_pts, n_ns = (0.0, None), 0, 0
    P5 = P.replace(d_hip=0.005)
    ks = np.linspace(0.0, 6.0, 25)
    rows = [continue_gait(P5, "k_hip", s, model="hybrid", at=list(ks)) for s in (0.0, 6.0)]
    for k in ks:
        r = rows[0] if k <= 0.95 else rows[1]
        y0 = r.state[int(np.argmin(np.abs(r.values - k)))]
        for stop in (0.0, 0.1):
            b = continue_gait(P.replace(k_hip=k, d_hip=0.005), "d_hip", stop, model="hybrid",
                              start=y0, max_points=100)
            n_pts += len(b)
            n_ns += len(b.of_kind("neimark_sacker"))
            for v, m in zip(b.values, b.multipliers):
                cx = [abs(x) for x in m if abs(x.imag) > 1e-8]
                if cx and max(cx) > best[0]:
                    best = (max(cx), (k, v))
    say("paper walker, d_hip families at 25 k_hip: %d points, %d NS located; largest complex "
        "|mu| = %.4f at (k_hip, d_hip) = (%.3g, %.4g); %.1f s CPU"
        % (n_pts, n_ns, best[0], best[1][0], best[1][1], time.process_time() - t0))
    for name, Q, stop in (("paper walker, slope", P, 0.2),
                          ("compass gait, slope", H.compass_gait_params(), 12 * DEG)):
        b = continue_gait(Q, "gamma", stop, model="hybrid", max_points=300)
        cx = [abs(x) for m in b.multipliers for x in m if abs(x.imag) > 1e-8]
        say("%s to %.3g: %d points, %d NS located, largest complex |mu| = %s"
            % (name, stop, len(b), len(b.of_kind("neimark_sacker")),
               "%.4f" % max(cx) if cx else "none (all real)"))


def part_chaos():
    from pdw.analysis.rigid import chaos
    C = H.compass_gait_params()
    say("== compass gait: orbit diagram 4 -> 5.3 deg, 1000 slopes x 200 steps (keep 100) ==")
    say("load average before: %s" % (os.getloadavg(),))
    t0, c0 = time.perf_counter(), time.process_time()
    od = chaos.orbit_diagram(C, "gamma", np.linspace(4.0, 5.3, 1000) * DEG, n_steps=200,
                             keep=100, workers=2)
    say("orbit diagram: %.1f s wall, %.1f s CPU (2 threads); the walker falls at %d slopes, "
        "from %.4f deg" % (time.perf_counter() - t0, time.process_time() - c0,
                           od["fell"].sum(), od["values"][od["fell"]].min() / DEG
                           if od["fell"].any() else np.nan))
    s0 = H.find_gait(C.replace(gamma=4.5 * DEG)).state
    lam = []
    for g in np.arange(4.0, 5.21, 0.05):
        r = chaos.lyapunov(C.replace(gamma=g * DEG), n_steps=2000, n_transient=300, start=s0)
        lam.append((g, r["exponent"]))
        say("  gamma = %.2f deg: largest Lyapunov exponent %+.4f per step" % (g, r["exponent"]))
    bs = follow_cascade(C, "gamma", 5.3 * DEG, depth=3, model="hybrid", step=0.05 * DEG)
    pds = [b.of_kind("period_doubling")[0].value / DEG for b in bs if b.of_kind(
        "period_doubling")]
    say("located cascade: %s deg; Feigenbaum ratios %s (delta = 4.6692)"
        % (", ".join("%.5f" % v for v in pds),
           ", ".join("%.3f" % d for d in chaos.feigenbaum_ratios(pds))))
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(7, 6), sharex=True, layout="constrained",
                                  height_ratios=(3, 1.3))
    x = np.repeat(od["values"] / DEG, od["theta"].shape[1])
    ax.plot(x, od["theta"].ravel(), ",", color="k", alpha=0.6)
    for v in pds:
        ax.axvline(v, color="C3", lw=0.6, ls=":")
    ax.set_ylabel("stance leg angle theta_st after heel strike [rad]")
    ax.set_title("Compass gait: orbit diagram (1000 slopes x last 100 of 200 steps)")
    g, lv = np.array(lam).T
    ax2.plot(g, lv, "o-", ms=3)
    ax2.axhline(0, color="k", lw=0.6)
    ax2.set_ylabel("Lyapunov exp. [1/step]")
    ax2.set_xlabel("gamma [deg]")
    fig.savefig(FIGS / "continuation_orbit_diagram.png", dpi=150)
    say("wrote docs/figures/continuation_orbit_diagram.png")
    say("load average after: %s" % (os.getloadavg(),))


def part_monodromy(rounds=3):
    from pdw.analysis.stepmap import limit_cycle as LC
    from pdw.analysis.stepmap import variational as V
    P = pdw.Params.paper_steady()
    g = pdw.find_gait(P)
    z = g.details["z"]
    say("== continuous model, paper_steady's gait: one monodromy matrix, exact vs differences ==")
    say("load average before: %s" % (os.getloadavg(),))
    for r in range(rounds):
        c0, t0 = time.process_time(), time.perf_counter()
        J, _, _ = LC.jacobian(z, P, workers=1, **LC.TIGHT)
        c1, t1 = time.process_time(), time.perf_counter()
        res = V.step_jacobian(z, P)
        c2, t2 = time.process_time(), time.perf_counter()
        say("round %d: finite differences (13 maps, 1 thread) %.3f s CPU / %.3f s wall; "
            "variational (Python/SciPy) %.3f s CPU / %.3f s wall; ratio %.1f; max|M - J| %.2g"
            % (r, c1 - c0, t1 - t0, c2 - c1, t2 - t1, (c2 - c1) / (c1 - c0),
               np.max(np.abs(res["M"] - J))))
    say("load average after: %s" % (os.getloadavg(),))


if __name__ == "__main__":
    parts = sys.argv[1:] or ["hybrid"]
    RESULTS.mkdir(parents=True, exist_ok=True)
    FIGS.mkdir(parents=True, exist_ok=True)
    for part in parts:
        OUT.clear()
        t0 = time.perf_counter()
        {"hybrid": part_hybrid, "hybrid_paper": part_hybrid_paper, "gamma": part_gamma,
         "dhip": part_dhip, "rigid": part_rigid,
         "rigid_paper": part_rigid_paper, "fig11": part_fig11,
         "simplest_limit": part_simplest_limit, "kelvin_voigt": part_kelvin_voigt,
         "codim2": part_codim2, "goswami": part_goswami, "region_hip": part_region_hip,
         "fold_kn": part_fold_kn, "region_kn": part_region_kn,
         "region_kn_coarse": lambda: part_region_kn(3, 9, 30.0),
         "region_hip_continuous": part_region_hip_continuous,
         "region_hip_continuous_coarse": lambda: part_region_hip_continuous(4, 9, 30.0),
         "codim2_schemes": part_codim2_schemes,
         "ns_search": part_ns_search, "chaos": part_chaos,
         "monodromy": part_monodromy}[part]()
        say("(%s: %.1f s wall; python benchmarks/continuation.py %s)"
            % (part, time.perf_counter() - t0, part))
        (RESULTS / ("continuation_%s.txt" % part)).write_text("\n".join(OUT) + "\n")
