"""Command line: ``pdw walk`` (also ``python -m pdw walk``), the main job, and ``pdw run``.

``pdw walk`` runs the paper's typical gait (Sec. 3.2: `Params.paper()`, x0 of
`pdw.sim.simulation.X0_PAPER`, 3.5 s, dt = 1e-4, the central difference method), prints the step
table next to the paper's numbers, and writes the report and the figures (Figs. 4-7 and an
animated GIF) to an output folder. Every option can also come from a TOML scene file
(``--scene FILE``); options given on the command line win.

``pdw run SCENE.toml`` runs a `pdw.Scene` file (docs/scenes.md): it prints the run's summary,
its gait descriptors and their steady values, and with ``--out DIR`` writes steps.csv,
run.json and the scene as run (scene.toml).
"""
from __future__ import annotations

import argparse
import json
import pathlib
import sys
import tomllib

import numpy as np

from ..core.errors import PdwError
from ..core.integrators import METHODS
from ..core.params import X0_PAPER, Params
from ..sim.gait import steps
from ..sim.scene import Scene
from ..sim.simulation import simulate
from .cli_sweep import add_cli as add_sweep_cli
from .report import walk_report

WALK_KEYS = {
    "t_end": float, "dt": float, "variant": str, "preset": str, "method": str, "out": str,
    "x0": list, "flags0": list, "record_every": int, "figures": bool, "params": dict,
}
WALK_DEFAULTS = {"t_end": 3.5, "dt": 1e-4, "variant": "paper", "preset": "paper", "method": "cdm",
                 "out": "out/typical_gait", "x0": list(X0_PAPER), "flags0": [0, 1],
                 "record_every": 1, "figures": True, "params": {}}


def load_scene(path) -> dict:
    """Read a walk scene (TOML). Unknown keys and wrong types are errors naming the key."""
    path = pathlib.Path(path)
    try:
        data = tomllib.loads(path.read_text())
    except (OSError, tomllib.TOMLDecodeError) as e:
        raise PdwError("cannot read scene file %s: %s" % (path, e)) from None
    for key, value in data.items():
        if key not in WALK_KEYS:
            raise PdwError("%s: unknown key %r; allowed: %s" % (path, key, ", ".join(WALK_KEYS)))
        typ = WALK_KEYS[key]
        ok = isinstance(value, (int, float)) and not isinstance(value, bool) if typ is float \
            else isinstance(value, typ) and not (typ is int and isinstance(value, bool))
        if not ok:
            raise PdwError("%s: key %r must be of type %s, got %r" % (path, key, typ.__name__, value))
    return data


def _walk(args):
    cfg = dict(WALK_DEFAULTS)
    if args.scene:
        cfg.update(load_scene(args.scene))
    for key in ("t_end", "dt", "variant", "preset", "method", "out", "record_every"):
        v = getattr(args, key)
        if v is not None:
            cfg[key] = v
    if args.no_figures:
        cfg["figures"] = False
    params = Params.preset(cfg["preset"], **cfg["params"])
    res = simulate(cfg["x0"], cfg["t_end"], cfg["dt"], params=params, variant=cfg["variant"],
                   method=cfg["method"], flags0=tuple(cfg["flags0"]),
                   record_every=cfg["record_every"], on_failure="return")
    text = walk_report(res)
    print(text)
    out = pathlib.Path(cfg["out"])
    out.mkdir(parents=True, exist_ok=True)
    (out / "report.txt").write_text(text + "\n")
    _write_steps_csv(steps(res), out / "steps.csv")
    meta = {k: (v if not isinstance(v, np.ndarray) else v.tolist()) for k, v in cfg.items()}
    meta.update(status=res.status, params=params.as_dict(), wall_time_s=res.wall_time,
                failure=None if res.failure is None else
                {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in res.failure.items()})
    (out / "run.json").write_text(json.dumps(meta, indent=2) + "\n")
    written = [out / "report.txt", out / "steps.csv", out / "run.json"]
    if cfg["figures"]:
        if res.x.shape[0] < 2:
            print("no figures: nothing was recorded (record_every = 0)")
        else:
            from .plots import save_all
            written += save_all(res, out)
    print("\nwrote: " + ", ".join(str(p) for p in written))
    return 0 if res.status == "walked" else 3


def _write_steps_csv(st, path):
    path.write_text(",".join(st.table) + "\n" + "\n".join(
        ",".join(str(st.table[k][i].item()) for k in st.table) for i in range(len(st))) + "\n")


def _jsonable(v):
    if isinstance(v, np.ndarray):
        return v.tolist()
    if isinstance(v, (np.floating, np.integer)):
        return v.item()
    if isinstance(v, dict):
        return {k: _jsonable(x) for k, x in v.items()}
    if isinstance(v, float) and not np.isfinite(v):
        return None
    return v


def _run(args):
    scene = Scene.load(args.scene)
    res = scene.run()
    st = steps(res)
    lines = ["scene: %s (%s)" % (scene.name or "-", args.scene), res.summary()]
    if res.failure:
        lines.append("failure: %s at t = %.4f s" % (res.failure["reason"], res.failure["t"]))
    kept = "" if res.events_recorded or res.n_gait_steps <= len(st) else \
        " (the last %d of %d, computed online)" % (len(st), res.n_gait_steps)
    lines += ["", "gait steps%s:" % kept, st.to_text() if len(st) else "(no complete step)"]
    if len(st):
        sd = st.steady()
        lines += ["", "steady (mean of the last %d steps): L = %.4f m, travel = %.4f m, P = %.4f s, "
                  "v = %.4f m/s, cycle = %.4f s, double support = %.1f ms (%.2f %%)"
                  % (sd["last"], sd["L"], sd["travel"], sd["P"], sd["v"], sd["cycle"],
                     1e3 * sd["double_support"], 100 * sd["ds_fraction"])]
    text = "\n".join(lines)
    print(text)
    if args.out:
        out = pathlib.Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        _write_steps_csv(st, out / "steps.csv")
        scene.save(out / "scene.toml")
        meta = dict(scene=scene.to_dict(), status=res.status, stop_reason=res.stop_reason,
                    t_final=res.t_final, n_steps=res.n_steps, n_gait_steps=res.n_gait_steps,
                    event_counts=res.event_counts, wall_time_s=res.wall_time, stats=res.stats,
                    params=res.params.as_dict(), features=list(res.features),
                    steady=st.steady() if len(st) else None, failure=res.failure)
        (out / "run.json").write_text(json.dumps(_jsonable(meta), indent=2) + "\n")
        print("\nwrote: %s" % ", ".join(str(out / n) for n in ("steps.csv", "run.json", "scene.toml")))
    return 0 if res.walked else 3


def main(argv=None):
    ap = argparse.ArgumentParser(prog="pdw", description="pdw: passive dynamic walking on compliant ground")
    sub = ap.add_subparsers(dest="command", required=True)
    w = sub.add_parser("walk", help="simulate the paper's typical gait: step table, report, figures")
    w.add_argument("--scene", help="TOML file with any of: %s" % ", ".join(WALK_KEYS))
    w.add_argument("--t-end", dest="t_end", type=float, help="duration [s] (default 3.5)")
    w.add_argument("--dt", type=float, help="time step [s] (default 1e-4)")
    w.add_argument("--variant", choices=("paper", "consistent"), help="contact variant (MODEL.md section 6)")
    w.add_argument("--preset", choices=("paper", "paper_steady"), help="parameter preset")
    w.add_argument("--method", choices=METHODS, help="integrator (default cdm, the paper's)")
    w.add_argument("--record-every", dest="record_every", type=int, help="record every k-th step")
    w.add_argument("--out", help="output folder (default out/typical_gait)")
    w.add_argument("--no-figures", action="store_true", help="skip the figures and the GIF")
    r = sub.add_parser("run", help="run a scene file (docs/scenes.md): summary, gait descriptors")
    r.add_argument("scene", help="TOML scene file (pdw.Scene)")
    r.add_argument("--out", help="also write steps.csv, run.json and scene.toml to this folder")
    add_sweep_cli(sub)                      # ``pdw sweep STUDY.toml`` (cli_sweep.py)
    args = ap.parse_args(argv)
    try:
        if hasattr(args, "func"):
            return args.func(args)
        return _run(args) if args.command == "run" else _walk(args)
    except PdwError as e:
        print("pdw: error: %s" % e, file=sys.stderr)
        return 2
    except ValueError as e:
        print("pdw: invalid input: %s" % e, file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
