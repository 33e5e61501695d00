"""Run every study of pdw/examples/studies/*.toml (the paper's Table 5 and Figs. 11-14), copy the
figures to docs/figures/study_<name>.png and print the trends (first -> last point of each
line) next to the paper's (benchmarks/results/studies.txt). `make study` runs it through
tests/studies/test_sweep.py::test_all_studies (slow).

Usage: .venv/bin/python benchmarks/studies.py [NAME ...] [--workers N]
"""
import argparse
import pathlib
import shutil
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))
from _results import FIGURES, publish  # noqa: E402

from pdw import sweep  # noqa: E402
from pdw.present.study_plots import plot_study  # noqa: E402

STUDIES = ROOT / "pdw" / "examples" / "studies"


def trend_lines(res):
    st = res.study
    names = st.axis_names
    groups = [None] if len(names) == 1 else sorted({r[names[1]] for r in res.rows})
    lines = []
    for gv in groups:
        sel = [r for r in res.rows if gv is None or r[names[1]] == gv]
        ok = [r for r in sel if r["gait"] == "period-1"]
        head = "%s%s" % (st.name, "" if gv is None else " (%s = %g)" % (names[1], gv))
        if len(ok) < 2:
            lines.append("%s: fewer than two period-one points" % head)
            continue
        a, b = ok[0], ok[-1]
        bad = len(sel) - len(ok)
        lines.append("%-34s %s %8.4g -> %-8.4g L %.4f -> %.4f m | P %.4f -> %.4f s | "
                     "v %.4f -> %.4f m/s | DS %.2f -> %.2f %%%s"
                     % (head, names[0], a[names[0]], b[names[0]], a["L"], b["L"], a["P"], b["P"],
                        a["v"], b["v"], 100 * a["ds_fraction"], 100 * b["ds_fraction"],
                        "" if not bad else "  (%d point(s) not period-one: %s)"
                        % (bad, ", ".join("%s=%g %s/%s" % (names[0], r[names[0]], r["status"],
                                                           r["gait"] or "-")
                                          for r in sel if r["gait"] != "period-1"))))
    p = st.paper
    if p:
        at = ", ".join("%s = %g" % kv for kv in p.get("at", {}).items())
        lines.append("%-34s %s: L %s m | P %s s | v %s m/s"
                     % ("  paper (%s)" % at, names[0],
                        " -> ".join("%g" % x for x in p["L"]),
                        " -> ".join("%g" % x for x in p["P"]),
                        " -> ".join("%g" % x for x in p["v"])))
    return lines


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("names", nargs="*")
    ap.add_argument("--workers", type=int)
    ap.add_argument("--out", default=str(ROOT / "out" / "studies"))
    args = ap.parse_args(argv)
    files = sorted(STUDIES.glob("*.toml"))
    if args.names:
        files = [f for f in files if f.stem in args.names]
    FIGURES.mkdir(parents=True, exist_ok=True)
    lines = ["Studies (pdw/examples/studies/*.toml): first -> last period-one point of each line", ""]
    total = 0.0
    for f in files:
        res = sweep.run_study(f, pathlib.Path(args.out) / f.stem, workers=args.workers,
                              resume=False, progress=False, figures=plot_study)
        total += res.wall_s
        if "png" in res.paths:
            shutil.copy(res.paths["png"], FIGURES / ("study_%s.png" % f.stem))
        lines += trend_lines(res)
        lines.append("  (%d points in %.1f s)" % (len(res.rows), res.wall_s))
    lines.append("")
    lines.append("total %.1f s" % total)
    publish("studies.txt", lines)


if __name__ == "__main__":
    main()
