"""The continuous model against the hybrid (rigid-ground) model: the paper's Fig. 8 and the
rigid-ground limit (issue 7; docs/studies.md).

* Fig. 8 (docs/figures/fig8.png): the limit cycles in the theta-thetadot plane of leg 1 over
  one stride, continuous model (`Params.paper_steady()`, `paper` and `consistent` variants, the
  Newton fixed point of pdw.limit_cycle, rodas4) and hybrid model (pdw.hybrid), same structural
  parameters.
* Rigid limit (docs/figures/rigid_limit.png, benchmarks/results/rigid_limit.txt): the
  continuous gait (Newton, consistent variant) as k_n grows from 1e5 to 1e9 N/m^1.5 with
  d_n = d_n0 (k_n / k_n0)^(4/3), which keeps the linearised damping ratio of the stance
  contact at its static sink fixed (docs/studies.md derives it), against the hybrid gait.

Usage: .venv/bin/python benchmarks/rigid_limit.py   (about a minute; `make study` runs it)
"""
import math
import pathlib
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))
from _results import FIGURES, publish  # noqa: E402

import pdw  # noqa: E402
from pdw import hybrid as H  # noqa: E402
from pdw import limit_cycle as LC  # noqa: E402

P0 = pdw.Params.paper_steady()
K_N = (1e5, 3e5, 1e6, 3e6, 1e7, 3e7, 1e8, 3e8, 1e9)


def scaled(kn, params=P0, exponent=4 / 3):
    """Params with k_n and d_n = d_n0 (k_n/k_n0)^exponent."""
    return params.replace(k_n=kn, d_n=params.d_n * (kn / params.k_n) ** exponent)


def damping_ratio(params):
    """Linearised damping ratio of the stance contact at its static sink under the walker's
    weight W (one foot, Hunt-Crossley with m = p = 1.5, q = 1, total mass on the foot):
    delta0 = (W/k)^(2/3), K = 1.5 k delta0^0.5, C = d delta0^1.5, zeta = C / (2 sqrt(K M))."""
    W = params.weight
    M = params.m_h + 2 * params.m_l
    d0 = (W / params.k_n) ** (2 / 3)
    K = 1.5 * params.k_n * math.sqrt(d0)
    C = params.d_n * d0 ** 1.5
    return C / (2 * math.sqrt(K * M)), d0


def stride(gait, variant):
    """Two steps of the continuous model from its fixed point, every accepted step recorded."""
    p = gait.params
    return pdw.simulate(gait.state, t_end=2 * gait.period + 1e-6, params=p, variant=variant,
                        method="rodas4", flags0=(1, 1),
                        integrator=pdw.Integrator(rtol=1e-10, atol=1e-12),
                        record=pdw.Record(every=1, forces=False))


def rigid_limit():
    gh = H.find_gait(P0)
    rows, cycles = [], {}
    for variant in ("consistent", "paper"):
        guess = None
        for kn in K_N:
            P = scaled(kn)
            t0 = time.perf_counter()
            try:
                g = LC.find_gait(P, variant=variant, guess=guess)
            except pdw.PdwError as e:
                rows.append(dict(variant=variant, k_n=kn, d_n=P.d_n, ok=False,
                                 why=str(e)[:90]))
                guess = None
                continue
            guess = g
            zeta, d0 = damping_ratio(P)
            rows.append(dict(variant=variant, k_n=kn, d_n=P.d_n, ok=True, T=g.period,
                             L=g.step_length, DS=g.double_support, mu=abs(g.multipliers[0]),
                             zeta=zeta, sink=d0, wall=time.perf_counter() - t0))
            if variant == "consistent" and kn in (1e5, 1e7, 1e9):
                cycles[kn] = stride(g, variant)
    return gh, rows, cycles


def fig8(gh):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    trh = H.simulate_hybrid(P0, gh.state, 2, dt_out=0.001)
    fig, axs = plt.subplots(1, 2, figsize=(11, 4.6), constrained_layout=True)
    for ax, variant in zip(axs, ("paper", "consistent")):
        g = LC.find_gait(P0, variant=variant)
        r = stride(g, variant)
        th, w = r.x[:, 2], r.x[:, 6]
        ds = r.flags.all(axis=1)
        ax.plot(th, w, "-", color="C0", lw=1.4, label="continuous, %s variant" % variant)
        ax.plot(np.where(ds, th, np.nan), np.where(ds, w, np.nan), "-", color="C3", lw=3,
                label="double support (%.1f ms per step)" % (1e3 * g.double_support))
        # hybrid: leg 1 over its stride; impacts (jumps in thetadot) dashed
        xh = trh.x
        thh, wh = xh[:, 2], xh[:, 6]
        jump = np.flatnonzero(np.diff(trh.t) == 0)
        seg = np.split(np.arange(len(thh)), jump + 1)
        for k, sidx in enumerate(seg):
            ax.plot(thh[sidx], wh[sidx], "-", color="k", lw=1,
                    label="hybrid (rigid ground)" if k == 0 else None)
        for j in jump:
            ax.plot(thh[j:j + 2], wh[j:j + 2], ":", color="k", lw=1,
                    label="hybrid impact" if j == jump[0] else None)
        ax.set_xlabel(r"$\theta_1$ [rad]")
        ax.set_ylabel(r"$\dot\theta_1$ [rad/s]")
        ax.set_title("(%s) continuous model, %s variant: period %.4f s, L %.4f m\n"
                     "hybrid: period %.4f s, L %.4f m"
                     % ("ab"[variant == "consistent"], variant, g.period, g.step_length,
                        gh.period, gh.step_length), fontsize=9)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="lower left")
    fig.suptitle("Fig. 8: limit cycles of leg 1 over one stride, Params.paper_steady() "
                 "(structural parameters of Table 1, d_hip = 0.010)", fontsize=10)
    FIGURES.mkdir(parents=True, exist_ok=True)
    fig.savefig(FIGURES / "fig8.png", dpi=110)
    plt.close(fig)


def plot_rigid(gh, rows, cycles):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axs = plt.subplots(2, 2, figsize=(10, 7.5), constrained_layout=True)
    for variant, mk in (("consistent", "o-"), ("paper", "s--")):
        rs = [r for r in rows if r["variant"] == variant and r["ok"]]
        k = np.array([r["k_n"] for r in rs])
        axs[0, 0].semilogx(k, [r["T"] for r in rs], mk, label=variant)
        axs[0, 1].semilogx(k, [r["L"] for r in rs], mk, label=variant)
        axs[1, 0].loglog(k, [1e3 * r["DS"] for r in rs], mk, label=variant)
    axs[0, 0].axhline(gh.period, color="k", lw=1, label="hybrid")
    axs[0, 1].axhline(gh.step_length, color="k", lw=1, label="hybrid")
    axs[0, 0].set_ylabel("period (touch-down to touch-down) [s]")
    axs[0, 1].set_ylabel("step length (footprint spacing) [m]")
    axs[1, 0].set_ylabel("double support per step [ms]")
    for ax in (axs[0, 0], axs[0, 1], axs[1, 0]):
        ax.set_xlabel(r"$k_n$ [N/m$^{1.5}$]  ($d_n \propto k_n^{4/3}$)")
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=8)
    ax = axs[1, 1]
    trh = H.simulate_hybrid(P0, gh.state, 2, dt_out=0.001)
    for i, (kn, r) in enumerate(sorted(cycles.items())):
        ax.plot(r.x[:, 2], r.x[:, 6], "-", lw=1.2, color="C%d" % i,
                label=r"continuous (consistent), $k_n$ = %.0e" % kn)
    ax.plot(trh.x[:, 2], trh.x[:, 6], "k:", lw=1.2, label="hybrid")
    ax.set_xlabel(r"$\theta_1$ [rad]")
    ax.set_ylabel(r"$\dot\theta_1$ [rad/s]")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3)
    fig.suptitle("Rigid-ground limit: continuous model -> hybrid model as k_n grows "
                 "(Params.paper_steady(), d_n scaled to keep the contact's damping ratio)",
                 fontsize=10)
    fig.savefig(FIGURES / "rigid_limit.png", dpi=110)
    plt.close(fig)


def main():
    t0 = time.perf_counter()
    gh, rows, cycles = rigid_limit()
    lines = ["Rigid-ground limit (benchmarks/rigid_limit.py): Params.paper_steady(), Newton fixed "
             "points (rodas4, rtol 1e-10)",
             "d_n = 1e6 (k_n/1e5)^(4/3): damping ratio of the stance contact at its static sink "
             "kept at %.3f" % damping_ratio(P0)[0],
             "hybrid: period %.6f s, L %.6f m, |mu| %.4f" % (gh.period, gh.step_length,
                                                            abs(gh.multipliers[0])),
             "",
             "| variant | k_n | d_n | static sink [mm] | period [s] | L [m] | DS [ms] | "
             "period - hybrid [s] | L - hybrid [m] | largest abs(mu) |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if r["ok"]:
            lines.append("| %s | %.0e | %.2e | %.3f | %.6f | %.6f | %.3f | %+.2e | %+.2e | %.4f |"
                         % (r["variant"], r["k_n"], r["d_n"], 1e3 * r["sink"], r["T"], r["L"],
                            1e3 * r["DS"], r["T"] - gh.period, r["L"] - gh.step_length, r["mu"]))
        else:
            lines.append("| %s | %.0e | %.2e | | no gait: %s | | | | | |"
                         % (r["variant"], r["k_n"], r["d_n"], r["why"]))
    rs = [r for r in rows if r["variant"] == "consistent" and r["ok"]]
    k = np.log10([r["k_n"] for r in rs])
    for name, key in (("DS", "DS"), ("|period - hybrid|", "T"), ("|L - hybrid|", "L")):
        y = [r[key] if key == "DS" else abs(r[key] - (gh.period if key == "T" else
                                                       gh.step_length)) for r in rs]
        slope = np.polyfit(k[-5:], np.log10(y[-5:]), 1)[0]
        lines.append("consistent, last five k_n: %s ~ k_n^%.2f" % (name, slope))
    fig8(gh)
    plot_rigid(gh, rows, cycles)
    lines.append("")
    lines.append("figures: %s, %s (%.0f s)" % (FIGURES / "fig8.png", FIGURES / "rigid_limit.png",
                                               time.perf_counter() - t0))
    publish("rigid_limit.txt", lines)


if __name__ == "__main__":
    main()
