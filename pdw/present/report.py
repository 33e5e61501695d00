"""Text reports of a run: the step table next to the paper's numbers, and the contact forces."""
from __future__ import annotations

import numpy as np

from ..core.params import Params
from ..sim.gait import steps

#: The paper's typical gait (Sec. 3.2, Figs. 4-7, docs/model.md section 8). L, P and v are read
#: at k_n = 1e5 from the k_n study (Fig. 11), the cycle and double support from Sec. 3.2.
PAPER_TYPICAL = {"L": 0.397, "P": 0.621, "v": 0.639, "cycle": 0.6275, "double_support": 0.017,
                 "ds_fraction": 0.0271}


def _smooth(y, n):
    if n <= 1 or len(y) < n:
        return y
    return np.convolve(y, np.ones(n) / n, mode="same")


def stance_forces(result, smooth_fraction=0.1):
    """Contact forces of every complete stance of a run with recorded forces.

    For each stance (a touch-down of a leg to its next lift-off): the peak normal force, the
    settled normal force (mean over the middle half of the stance), the walker's weight
    normal to the slope, the mean tangential force over the first and the last 40 % of the
    stance, and the times at which the tangential force, smoothed by a moving average over
    ``smooth_fraction`` of the stance (the central difference method's friction chatters
    from step to step), changes sign.

    Returns
    -------
    list of dict
    """
    if result.Fn.shape[0] != result.t.shape[0] or len(result.t) < 2:
        raise ValueError("stance_forces needs a result recorded with record_forces=True")
    dt_rec = result.t[1] - result.t[0]
    out = []
    for e in (e for e in result.events if e.kind == "touch_down"):
        lo = next((f for f in result.events if f.kind == "lift_off" and f.leg == e.leg and f.t > e.t),
                  None)
        if lo is None:
            continue
        i, dur = e.leg - 1, lo.t - e.t
        m = (result.t >= e.t) & (result.t <= lo.t)
        t, fn, ft = result.t[m], result.Fn[m, i], result.Ft[m, i]
        if len(t) < 10:
            continue
        rel = (t - e.t) / dur
        n = max(1, int(round(smooth_fraction * dur / dt_rec)))
        fts = _smooth(ft, n)
        core = slice(n // 2, len(fts) - n // 2)      # drop the moving average's edges
        sg = np.sign(fts[core])
        k = np.nonzero(sg[:-1] * sg[1:] < 0)[0]
        out.append({"leg": e.leg, "t_touch_down": e.t, "t_lift_off": lo.t,
                    "Fn_peak": float(fn.max()), "t_peak": float(t[np.argmax(fn)]),
                    "Fn_settled": float(fn[(rel >= 0.25) & (rel <= 0.75)].mean()),
                    "weight": result.params.weight,
                    "Ft_early": float(ft[rel <= 0.4].mean()), "Ft_late": float(ft[rel >= 0.6].mean()),
                    "Ft_sign_changes": [(float(t[core][j]), "-+" if sg[j] < 0 else "+-") for j in k]})
    return out


def why_not_the_paper(result) -> list:
    """The lines under the comparison with the paper that say why the numbers differ
    (docs/reproduction.md section 4): at the paper's d_hip = 0.018 there is no periodic gait,
    so the last steps are a decaying transient; the steady preset's gait is 7-9 % shorter and
    quicker than the paper's; other parameters are not the paper's walker."""
    p = result.params
    if p == Params.paper():
        return ["Why pdw differs from the paper here: at the paper's d_hip = 0.018 there is no "
                "periodic gait: the",
                "  steps shrink every step and the walker falls soon after 3.5 s (at 3.8 s from "
                "the paper's start,",
                "  variant paper: pdw walk --t-end 6). These are steps of a decaying transient, "
                "not a steady gait.",
                "  The steady preset (--preset paper_steady, d_hip = 0.010) converges to "
                "L = 0.3685 m, P = 0.5644 s,",
                "  7-9 % shorter and quicker than the paper's (docs/reproduction.md, section 4)."]
    if p == Params.paper_steady():
        return ["The paper's column is its typical gait at d_hip = 0.018, which has no periodic "
                "gait; this steady",
                "  preset (d_hip = 0.010) walks 7-9 % shorter and quicker steps than the paper "
                "reports (docs/reproduction.md, section 4)."]
    return ["The paper's column is its typical gait (Params.paper()); these parameters differ "
            "from it."]


def walk_report(result, last=4) -> str:
    """The main job's report: run summary, step table, steady values against the paper, forces."""
    st = steps(result)
    lines = ["pdw walk: %s, variant %s, dt = %g s, t_end = %g s" % (
        result.method, result.variant, result.dt, result.t_end),
        "status: %s (%s); wall time %.1f ms" % (result.status, result.summary(), 1e3 * result.wall_time),
        "", "Steps (docs/model.md section 8 definitions):", st.to_text(), ""]
    if len(st):
        sd = st.steady(last)
        lines.append("Last %d steps (mean, largest change between successive steps%s) vs the "
                     "paper:" % (sd["last"], "" if sd["converged"] else "; not converged")
                     if result.walked else
                     "Last %d steps before the run %s (mean, largest change; not a steady gait):"
                     % (sd["last"], result.status))
        lines.append("%-22s %10s %10s %10s" % ("", "pdw", "change", "paper"))
        for name, label, scale in (("L", "step length L [m]", 1), ("travel", "swing travel [m]", 1),
                                   ("P", "step period P [s]", 1), ("v", "velocity v [m/s]", 1),
                                   ("cycle", "cycle [s]", 1), ("double_support", "double support [ms]", 1e3),
                                   ("ds_fraction", "double support [%]", 100)):
            paper = PAPER_TYPICAL.get(name)
            lines.append("%-22s %10.4f %10.2g %10s" % (
                label, scale * sd[name], scale * sd["spread_" + name],
                "%.4g" % (scale * paper) if paper is not None else "-"))
        lines += why_not_the_paper(result)
        lines.append("")
    if result.Fn.shape[0] == result.t.shape[0] and len(result.t) > 1:
        lines.append("Stances: normal force peak / settled vs the weight %.2f N; friction sign changes"
                     % result.params.weight)
        lines.append("  (Ft: mean over the first / last 40 % of the stance, and sign changes of Ft"
                     " smoothed over 10 % of the stance)")
        for s in stance_forces(result):
            ch = s["Ft_sign_changes"]
            up = [t for t, d in ch if d == "-+"]
            ch = ("- to + at %.3f s (%d sign changes within %.0f ms: chatter)"
                  % (up[0], len(ch), 1e3 * (ch[-1][0] - ch[0][0])) if up else
                  "none" if not ch else "+ to - only")
            lines.append("  leg %d %.3f-%.3f s: Fn peak %.1f N at %.4f s, settled %.1f N (%.2f W);"
                         " Ft %+.2f N -> %+.2f N, sign changes: %s" % (
                             s["leg"], s["t_touch_down"], s["t_lift_off"], s["Fn_peak"], s["t_peak"],
                             s["Fn_settled"], s["Fn_settled"] / s["weight"], s["Ft_early"],
                             s["Ft_late"], ch))
    return "\n".join(lines)
