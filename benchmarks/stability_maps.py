"""Stability maps of the integrators (docs/stability.md): the largest step at which the typical
gait walks, and walks correctly, per fixed-step method, as a function of each contact
parameter over ranges a decade beyond the paper's; the linearized estimate beside it; the
adaptive methods' largest accepted step and work; chatter onsets; the paper's claims; the
energy balance. Run by `make study` (a few minutes on 2 cores); writes
benchmarks/results/stability_maps.{json,txt} and docs/figures/stability_*.png.

    python benchmarks/stability_maps.py [--jobs N] [--quick] [--no-figures] [--only PART ...]
"""
from __future__ import annotations

import argparse
import json
import math
import multiprocessing as mp
import pathlib
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))

from _results import FIGURES, RESULTS, publish  # noqa: E402

import pdw  # noqa: E402
from pdw.analysis.numerics import stability_maps as S  # noqa: E402
from pdw.sim import stepsize as SL  # noqa: E402

FIXED = SL.FIXED_STEP
#: swept parameters: values (the paper's range is marked) -- a decade beyond each end
SWEEPS = {
    "k_n": ([5e3, 1.6e4, 5e4, 1e5, 2.5e5, 8e5, 2.5e6], (0.5e5, 2.5e5)),
    "d_n": ([5e4, 1.6e5, 5e5, 1e6, 2.5e6, 8e6, 2.5e7], (0.5e6, 2.5e6)),
    "v_s": ([1e-6, 1e-5, 1e-4, 1e-3, 1e-2], (1e-4, 1e-4)),
    "k_t": ([1.0, 3.0, 10.0, 30.0, 90.0, 300.0, 850.0], (10.0, 85.0)),
    "d_t": ([10.0, 30.0, 100.0, 300.0, 900.0, 3000.0, 1e4], (100.0, 1000.0)),
}
QUICK = {k: ([v[0][0], v[0][len(v[0]) // 2], v[0][-1]], v[1]) for k, v in SWEEPS.items()}
BASE = "paper_steady"
VARIANTS = ("paper", "consistent")
ADAPTIVE_RTOL = 1e-6
DOPRI5_T_END = 0.4      # first stance and touch-down: dopri5 is stability-bound, ~1e6 steps/s
MARGIN_T_END = 5.0      # a cell whose reference falls before this is marked marginal


def params_for(name, value, preset=BASE):
    kw = {name: value}
    if name == "v_s":
        kw["v_d"] = 10 * value
    return pdw.Params.preset(preset, **kw)


def _trajectory_states(ref, t_max=1.0, n_single=60, n_double=60):
    """Subsample of the reference's states up to t_max: evenly in single support, densely in
    double support (where the limit is smallest)."""
    m = ref.t <= t_max
    idx = np.where(m)[0]
    ds = idx[ref.flags[idx].sum(axis=1) == 2]
    ss = idx[ref.flags[idx].sum(axis=1) < 2]
    pick = lambda a, n: a[np.linspace(0, len(a) - 1, min(n, len(a))).astype(int)] if len(a) else a
    return np.unique(np.concatenate([pick(ss, n_single), pick(ds, n_double)]))


def linear_along(ref, method, idx=None):
    """Min over the reference trajectory of the linear limit without friction: (h, t, flags)."""
    P = ref.params
    idx = _trajectory_states(ref) if idx is None else idx
    anchors = S._anchors(ref)
    best = (math.inf, None, None)
    for i in idx:
        J = pdw.jacobian(ref.x[i], P, flags=tuple(ref.flags[i]), anchors=tuple(anchors[i]),
                         variant=ref.variant, features=SL._NO_FRICTION)
        h = SL.linear_limit(method, J)
        if h < best[0]:
            best = (h, float(ref.t[i]), tuple(int(f) for f in ref.flags[i]))
    return best


def adaptive_stats(P, method, ref):
    x0 = SL.typical_start(P, ref.variant)
    t_end = DOPRI5_T_END if method == "dopri5" else ref.t_end
    t0 = time.perf_counter()
    r = S._sim(x0=x0, t_end=t_end, dt=1e-5, params=P, method=method, rtol=ADAPTIVE_RTOL,
               variant=ref.variant,
               atol=ADAPTIVE_RTOL * 1e-2, record_every=1, record_forces=False)
    wall = time.perf_counter() - t0
    h = np.diff(r.t)
    single = r.flags[:-1].sum(axis=1) == 1
    out = {"status": r.status, "t_end": t_end, "steps": r.stats["steps"], "rhs": r.stats["rhs"],
           "jacobians": r.stats["jacobians"], "rejected": r.stats["rejected"], "wall": wall,
           "h_max": float(h.max()) if len(h) else math.nan,
           "h_median_single": float(np.median(h[single])) if single.any() else math.nan,
           "steps_per_s": r.stats["steps"] / max(r.t_final, 1e-12)}
    if method == "rodas4":
        v = S.judge(r, ref)
        out.update(walks=v.walks, correct=v.correct, td_error=v.td_error)
    return out


def cell(args):
    """Everything measured at one parameter point."""
    name, value, preset, variant = args
    t0 = time.perf_counter()
    P = params_for(name, value, preset)
    ref = S.reference(P, variant)
    out = {"param": name, "value": value, "preset": preset, "variant": variant,
           "ref_status": ref.status, "ref_touch_downs": len(S.touch_downs(ref)),
           "ref_gain": S.energy_gain(ref), "ref_t_final": ref.t_final, "methods": {},
           "adaptive": {}}
    walks = ref.status == "walked"
    # a marginal gait (the reference falls soon after t_end) decides "walks" by chance
    longer = S._sim(x0=SL.typical_start(P, variant), t_end=MARGIN_T_END, params=P, method="rodas4",
                    variant=variant, rtol=1e-9, atol=1e-11, record_every=0)
    out["marginal"] = None if longer.status == "walked" else "reference %s at %.2f s" % (
        longer.status, longer.t_final)
    legs = [leg for _, leg in S.touch_downs(ref)]
    if any(a == b for a, b in zip(legs[:-1], legs[1:])):
        out["marginal"] = "reference bounces (a foot touches down twice in a row)"
    idx = _trajectory_states(ref)
    for m in FIXED:
        d = {}
        if walks:
            ls = S.largest_step(P, m, ref, variant=variant, lo=1e-6)
            d["walk"] = ls["walk"]
            d["correct"] = ls["correct"]
            d["runs"] = [(dt, v.walks, v.correct, v.reason) for dt, v in ls["runs"]]
        d["h_states"] = SL._limits(P, m, variant)
        d["step_limit"] = SL.step_limit(P, m, variant).dt_max
        d["h_traj"], d["t_traj"], d["flags_traj"] = linear_along(ref, m, idx)
        d["sensitivity"] = SL.sensitivity(P, m, variant)
        d["force"] = SL.step_limit(P, m, variant).force
        out["methods"][m] = d
    if walks:
        for m in ("dopri5", "rodas4"):
            out["adaptive"][m] = adaptive_stats(P, m, ref)
        out["adaptive"]["dopri5"]["h_linear_friction"] = SL.step_limit(P, "dopri5", variant).dt_chatter
    out["wall"] = time.perf_counter() - t0
    return out


def chatter_cell(args):
    """Chatter and spurious-slip onsets of each fixed-step method at one parameter point."""
    name, value, preset, variant = args
    P = params_for(name, value, preset)
    ref = S.reference(P, variant, t_end=S.CHATTER_WINDOW[1])
    v = S.slip(ref, 2, S.CHATTER_WINDOW)
    out = {"param": name, "value": value, "ref_stuck": float(np.mean(np.abs(v) < P.v_s)),
           "ref_v_max": float(np.max(np.abs(v))), "methods": {}}
    for m in FIXED:
        out["methods"][m] = {
            "slides": S.chatter_onset(P, m, variant, key="slides", hi=1e-3),
            "chatters": S.chatter_onset(P, m, variant, key="chatters", hi=1e-3),
            "linear": SL.step_limit(P, m, variant).dt_chatter,
        }
    return out


def claims():
    """The paper's values: walking edge of cdm at d_n = 1e6 and 2.5e6 (Params.paper and
    paper_steady), linear estimate along the method's own trajectory near the edge, chatter of
    cdm at every step from 1e-5 to the edge."""
    out = {}
    for preset in ("paper", "paper_steady"):
        for dn in (1e6, 2.5e6):
            P = pdw.Params.preset(preset, d_n=dn)
            ref = S.reference(P)
            ls = S.largest_step(P, "cdm", ref, refine=5)
            key = "%s d_n=%g" % (preset, dn)
            out[key] = {"ref_status": ref.status, "walk": ls["walk"], "correct": ls["correct"],
                        "h_traj": linear_along(ref, "cdm")[0],
                        "step_limit": SL.step_limit(P, "cdm").dt_max,
                        "dt_1e-4": [(dt, v.walks, v.correct, v.td_error) for dt, v in ls["runs"]
                                    if abs(dt - 1e-4) < 1e-12]}
            if ls["walk"][0]:
                # linear limit along cdm's own trajectory at 0.9 x its walking edge
                dt = 0.9 * ls["walk"][0]
                r = S._sim(x0=SL.typical_start(P), t_end=1.0, dt=dt, params=P, method="cdm",
                           record_every=1, record_forces=False)
                out[key]["h_own_trajectory"] = linear_along(r, "cdm", np.arange(len(r.t)))
                out[key]["own_dt"] = dt
    # chatter of cdm over the walking range at the paper's values
    P = pdw.Params.paper()
    out["cdm_chatter_paper"] = [
        S.chatter(P, "cdm", dt).__dict__ for dt in (1e-6, 2e-6, 5e-6, 1e-5, 3e-5, 1e-4, 3e-4, 1e-3, 2e-3)]
    out["chatter_all_methods_paper"] = {
        m: [S.chatter(P, m, dt).__dict__ for dt in (1e-6, 1e-5, 1e-4, 1e-3)] for m in FIXED}
    return out


def energy_table():
    """Energy-balance residual of rodas4 vs rtol and h_max, and of the fixed-step methods."""
    rows = []
    P = pdw.Params.paper_steady()
    x0 = pdw.X0_PAPER
    for rtol in (1e-4, 1e-6, 1e-8, 1e-10):
        for h_max in (1e-3, 1e-4):
            r = S._sim(x0=x0, t_end=3.5, dt=1e-5, params=P, method="rodas4", rtol=rtol,
                       atol=rtol * 1e-2, h_max=h_max, record_every=1)
            for quad in ("trapezoid", "simpson"):
                b = S.energy_balance(r, quad)
                rows.append({"method": "rodas4", "rtol": rtol, "h_max": h_max, "quadrature": quad,
                             "steps": r.stats["steps"],
                             "max_abs_residual": float(np.max(np.abs(b["residual"]))),
                             "max_step_relative": float(np.max(np.abs(b["step_relative"]))),
                             "gravity_work_per_step": float(np.mean(b["step_gravity_work"]))})
    for m, dt in (("cdm", 1e-4), ("cdm", 1e-5), ("verlet", 1e-5), ("rk4", 1e-5), ("rk4", 1e-6)):
        r = S._sim(x0=x0, t_end=3.5, dt=dt, params=P, method=m, record_every=1)
        b = S.energy_balance(r, "trapezoid")
        rows.append({"method": m, "dt": dt, "quadrature": "trapezoid", "steps": r.stats["steps"],
                     "max_abs_residual": float(np.max(np.abs(b["residual"]))),
                     "max_step_relative": float(np.max(np.abs(b["step_relative"]))),
                     "gravity_work_per_step": float(np.mean(b["step_gravity_work"]))})
    return rows


# ---------------------------------------------------------------------------------- report ----

def _fmt(x):
    if x is None:
        return "-"
    if isinstance(x, (list, tuple)):
        a, b = x
        if a is None:
            return "< %.2g" % b
        if b is None:
            return ">= %.2g" % a
        return "%.2g" % a
    return "%.2g" % x


def report(cells, chat, cl, energy):
    lines = ["Stability maps (benchmarks/stability_maps.py); base parameters Params.%s, start "
             "stability.typical_start, 3.5 s." % BASE, ""]
    lines.append("Largest step [s]: walks / walks correctly (touch-downs within max(2 ms, 1%% "
                 "cycle)); lin = linear limit min along the reference; S = step_limit; "
                 "marg. = marginal gait (reference falls before %g s)" % MARGIN_T_END)
    for variant in VARIANTS:
        vc = [c for c in cells if c.get("variant", "paper") == variant]
        if not vc:
            continue
        lines.append("")
        lines.append("== variant %s ==" % variant)
        for name in SWEEPS:
            lines.append("")
            lines.append("%-8s %-5s | %s" % (name, "ref", " | ".join(
                "%-6s walk    correct  lin      S        force" % m for m in FIXED)))
            for c in [c for c in vc if c["param"] == name]:
                row = "%-8.3g %-5s |" % (c["value"], "marg." if c.get("marginal") else c["ref_status"][:5])
                for m in FIXED:
                    d = c["methods"][m]
                    row += " %-6s %-8s %-8s %-8s %-8s %-5s |" % (
                        "", _fmt(d.get("walk")), _fmt(d.get("correct")), _fmt(d["h_traj"]),
                        _fmt(d["step_limit"]), d.get("force", ""))
                lines.append(row)
        lines.append("")
        lines.append("Failure at the first failing step (walks):")
        for c in vc:
            row = []
            for m in FIXED:
                x = c["methods"][m]
                if not x.get("walk") or x["walk"][1] is None:
                    continue
                r = [r for r in x["runs"] if abs(r[0] - x["walk"][1]) < 1e-15]
                row.append("%s %.2g: %s" % (m, x["walk"][1], r[0][3] if r else "?"))
            lines.append("  %s=%-8g %s" % (c["param"], c["value"], " | ".join(row)))
    lines.append("")
    lines.append("Adaptive (rtol %g): rodas4 over 3.5 s, dopri5 over %.1f s" % (ADAPTIVE_RTOL, DOPRI5_T_END))
    lines.append("%-8s %-8s | rodas4: steps  h_max    h_med(ss) correct | dopri5: steps/s  h_max    "
                 "h_med(ss) lin(fric)" % ("param", "value"))
    for c in [c for c in cells if c.get("variant", "paper") == "paper"]:
        a = c["adaptive"]
        if not a:
            continue
        r4, d5 = a["rodas4"], a["dopri5"]
        lines.append("%-8s %-8.3g | %12d %-8.2g %-9.2g %-7s | %14.3g %-8.2g %-9.2g %-8.2g" % (
            c["param"], c["value"], r4["steps"], r4["h_max"], r4["h_median_single"], r4["correct"],
            d5["steps_per_s"], d5["h_max"], d5["h_median_single"], d5["h_linear_friction"]))
    lines.append("")
    lines.append("Chatter: onset of spurious slip / chatter (largest dt without, smallest with) and "
                 "the linear limit with friction")
    for c in chat:
        row = "%-5s %-8.3g stuck %.2f |" % (c["param"], c["value"], c["ref_stuck"])
        for m in FIXED:
            d = c["methods"][m]
            row += " %s slide %s chat %s lin %.2g |" % (m, _fmt(d["slides"]), _fmt(d["chatters"]), d["linear"])
        lines.append(row)
    lines.append("")
    lines.append("Claims (cdm):")
    for k, v in cl.items():
        if k.startswith("paper"):
            lines.append("  %s: ref %s, walks to %s (fails at %s), correct to %s, lin along ref %.2g, "
                         "along own trajectory at %.2g: %.2g, step_limit %.2g" % (
                             k, v["ref_status"], _fmt(v["walk"]), _fmt(v["walk"][1]), _fmt(v["correct"]),
                             v["h_traj"], v.get("own_dt", math.nan),
                             v.get("h_own_trajectory", [math.nan])[0], v["step_limit"]))
    lines.append("  cdm chatter at the paper's values: " + ", ".join(
        "%.0e: %s (rev %.2f, slip %.2f)" % (d["dt"], "chatters" if d["chatters"] else
                                             ("slides" if d["slides"] else "sticks"),
                                             d["reversal_rate"], d["slip_fraction"])
        for d in cl.get("cdm_chatter_paper", [])))
    lines.append("")
    lines.append("Energy balance (typical gait, paper_steady, 3.5 s): max |E - E0 - W| [J] and max "
                 "per-step residual / gravity work")
    for r in energy:
        lines.append("  %-7s %-22s %-9s steps %8d: %.2e J, %.2e" % (
            r["method"], ("rtol %g h_max %g" % (r["rtol"], r["h_max"])) if "rtol" in r else "dt %g" % r["dt"],
            r["quadrature"], r["steps"], r["max_abs_residual"], r["max_step_relative"]))
    return lines


# ---------------------------------------------------------------------------------- figures ---

def figures(cells, chat):
    for variant in VARIANTS:
        vc = [c for c in cells if c.get("variant", "paper") == variant]
        if vc:
            map_figure(vc, variant)
    adaptive_figure([c for c in cells if c.get("variant", "paper") == "paper"], chat)


def map_figure(cells, variant):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    FIGURES.mkdir(parents=True, exist_ok=True)
    colors = {"cdm": "C0", "verlet": "C1", "rk4": "C2"}
    labels = {"k_n": r"$k_n$ [N/m$^{1.5}$]", "d_n": r"$d_n$ [N s/m$^{2.5}$]",
              "v_s": r"$v_s$ [m/s] ($v_d = 10 v_s$)", "k_t": r"$k_t$", "d_t": r"$d_t$"}
    fig, axes = plt.subplots(2, 3, figsize=(15, 9), constrained_layout=True)
    for ax, name in zip(axes.flat, SWEEPS):
        cs = sorted([c for c in cells if c["param"] == name], key=lambda c: c["value"])
        v = np.array([c["value"] for c in cs])
        for m in FIXED:
            col = colors[m]
            get = lambda key, m=m, cs=cs: np.array([(c["methods"][m].get(key) or [np.nan])[0] or np.nan
                                        for c in cs], dtype=float)
            ax.plot(v, get("walk"), "o-", color=col, label="%s walks" % m)
            ax.plot(v, get("correct"), "s--", color=col, mfc="none", label="%s walks correctly" % m)
            ax.plot(v, [c["methods"][m]["h_traj"] for c in cs], ":", color=col, lw=1.5,
                    label="%s linear (min along ref.)" % m)
            ax.plot(v, [c["methods"][m]["step_limit"] for c in cs], "-", color=col, lw=0.8,
                    alpha=0.6, label="%s step_limit" % m)
        for c in cs:
            if c["ref_status"] != "walked" or c.get("marginal"):
                ax.axvline(c["value"], color="0.7", lw=6, alpha=0.4)
        lo, hi = SWEEPS[name][1]
        if lo < hi:
            ax.axvspan(lo, hi, color="y", alpha=0.15, label="paper's range")
        else:
            ax.axvline(lo, color="y", lw=3, alpha=0.5, label="paper's value")
        ax.axhline(1e-4, color="k", lw=0.8, ls="-.", label="paper's dt = 1e-4")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(labels[name])
        ax.set_ylabel("largest step [s]")
        ax.set_ylim(1e-6, 0.2)
        ax.grid(True, which="major", alpha=0.3)
    ax = axes.flat[5]
    ax.axis("off")
    h, l = axes.flat[0].get_legend_handles_labels()
    ax.legend(h, l, fontsize=8, ncol=2, loc="lower left", frameon=False)
    ax.text(0.0, 1.0, "Typical gait, Params.%s, 3.5 s, variant '%s'.\n"
            "walks: reaches 3.5 s with the reference's touch-downs\n"
            "  and no energy gain beyond the reference's + 0.1 J\n"
            "walks correctly: + touch-downs within max(2 ms, 1 %% cycle)\n"
            "linear: min over the rodas4 reference of the largest\n"
            "  stable step of the method on df/dx without friction\n"
            "step_limit: pdw.sim.stepsize.step_limit (calibrated)\n"
            "grey bars: marginal gait (the rodas4 reference falls\n"
            "  before 5 s, or bounces): 'walks' is decided by chance\n"
            "  there; not used for the calibration" % (BASE, variant),
            va="top", family="monospace", fontsize=9)
    fig.savefig(FIGURES / ("stability_maps.png" if variant == "paper"
                           else "stability_maps_%s.png" % variant), dpi=90)
    plt.close(fig)


def adaptive_figure(cells, chat):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    colors = {"cdm": "C0", "verlet": "C1", "rk4": "C2"}
    labels = {"k_n": r"$k_n$ [N/m$^{1.5}$]", "d_n": r"$d_n$ [N s/m$^{2.5}$]",
              "v_s": r"$v_s$ [m/s] ($v_d = 10 v_s$)", "k_t": r"$k_t$", "d_t": r"$d_t$"}
    fig, axes = plt.subplots(1, 5, figsize=(18, 4), constrained_layout=True)
    for ax, name in zip(axes, SWEEPS):
        cs = sorted([c for c in cells if c["param"] == name and c["adaptive"]], key=lambda c: c["value"])
        v = [c["value"] for c in cs]
        ax.plot(v, [c["adaptive"]["rodas4"]["h_max"] for c in cs], "o-", color="C3", label="rodas4 largest step")
        ax.plot(v, [c["adaptive"]["rodas4"]["h_median_single"] for c in cs], "o--", color="C3", mfc="none",
                label="rodas4 median step, single support")
        ax.plot(v, [c["adaptive"]["dopri5"]["h_max"] for c in cs], "s-", color="C4", label="dopri5 largest step")
        ax.plot(v, [c["adaptive"]["dopri5"]["h_median_single"] for c in cs], "s--", color="C4", mfc="none",
                label="dopri5 median step, single support")
        ax.plot(v, [c["adaptive"]["dopri5"]["h_linear_friction"] for c in cs], ":", color="C4",
                label="dopri5 linear limit incl. friction")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(labels[name])
        ax.grid(True, alpha=0.3)
    axes[0].set_ylabel("step [s] (rtol %g)" % ADAPTIVE_RTOL)
    axes[0].legend(fontsize=7)
    fig.savefig(FIGURES / "stability_adaptive.png", dpi=90)
    plt.close(fig)

    # chatter
    if chat:
        fig, axes = plt.subplots(1, 2, figsize=(11, 4.2), constrained_layout=True)
        for ax, name in zip(axes, ("v_s", "k_n")):
            cs = sorted([c for c in chat if c["param"] == name], key=lambda c: c["value"])
            if not cs:
                continue
            v = [c["value"] for c in cs]
            for m in FIXED:
                col = colors[m]
                # onset = smallest step where it happens; nothing if it never does up to hi
                onset = lambda ab: ab[1] if ab[1] is not None else np.nan
                sl = [onset(c["methods"][m]["slides"]) for c in cs]
                ch = [onset(c["methods"][m]["chatters"]) for c in cs]
                ax.plot(v, sl, "o-", color=col, label="%s: stuck foot slides from" % m)
                ax.plot(v, ch, "s--", color=col, mfc="none", ms=9,
                        label="%s: chatters from (none: never up to 3e-3)" % m)
                ax.plot(v, [c["methods"][m]["linear"] for c in cs], ":", color=col,
                        label="%s: linear limit incl. friction" % m)
            ax.axhline(1e-4, color="k", lw=0.8, ls="-.")
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlabel(labels[name])
            ax.set_ylabel("step [s]")
            ax.grid(True, alpha=0.3)
        axes[0].legend(fontsize=7)
        fig.savefig(FIGURES / "stability_chatter.png", dpi=90)
        plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--quick", action="store_true", help="3 values per parameter")
    ap.add_argument("--no-figures", action="store_true")
    ap.add_argument("--only", nargs="*", default=["maps", "chatter", "claims", "energy"])
    a = ap.parse_args(argv)
    sweeps = QUICK if a.quick else SWEEPS
    t0 = time.perf_counter()
    tasks = [(name, v, BASE, "paper") for name, (vals, _) in sweeps.items() for v in vals] + \
            [(name, v, BASE, "consistent") for name, (vals, _) in QUICK.items() for v in vals]
    chat_tasks = [("v_s", v, BASE, "paper") for v in sweeps["v_s"][0]] + \
                 [("k_n", v, BASE, "paper") for v in sweeps["k_n"][0]]
    path = RESULTS / "stability_maps.json"
    data = json.loads(path.read_text()) if path.exists() else {}
    with mp.Pool(a.jobs) as pool:
        if "maps" in a.only:
            data["cells"] = pool.map(cell, tasks, chunksize=1)
        if "chatter" in a.only:
            data["chatter"] = pool.map(chatter_cell, chat_tasks, chunksize=1)
    if "claims" in a.only:
        data["claims"] = claims()
    if "energy" in a.only:
        data["energy"] = energy_table()
    data["calibration"] = calibration(data.get("cells", []))
    RESULTS.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(data, indent=1, default=float))
    lines = report(data.get("cells", []), data.get("chatter", []), data.get("claims", {}),
                   data.get("energy", []))
    lines.append("")
    for variant, cal in data["calibration"].items():
        lines.append("Calibration, variant %s (smallest walking edge / linear limit at the stance "
                     "states): " % variant + ", ".join(
                         "%s %.3g (median %.3g, max %.3g, at %s)" % (m, c["min"], c["median"], c["max"], c["at"])
                         for m, c in cal.items()))
    lines.append("wall %.0f s" % (time.perf_counter() - t0))
    publish("stability_maps.txt", lines)
    if not a.no_figures:
        figures(data.get("cells", []), data.get("chatter", []))


def calibration(cells):
    """Ratio of the measured walking edge to the uncalibrated linear limit at the stance states
    (min over the states), per variant and method: its minimum over the non-marginal cells is
    `pdw.sim.stepsize.CALIBRATION`."""
    out = {}
    for variant in VARIANTS:
        out[variant] = {}
        for m in FIXED:
            ratios = []
            for c in cells:
                d = c["methods"][m]
                if c.get("variant", "paper") == variant and d.get("walk") and d["walk"][0] \
                        and not c.get("marginal"):
                    ratios.append((d["walk"][0] / min(d["h_states"]), "%s=%g" % (c["param"], c["value"])))
            if ratios:
                r = min(ratios)
                out[variant][m] = {"min": r[0], "at": r[1], "max": max(ratios)[0],
                                   "median": float(np.median([x for x, _ in ratios]))}
    return out


if __name__ == "__main__":
    main()
