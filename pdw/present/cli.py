"""Command line: ``pdw walk`` (the main job), ``pdw run`` (a scene) and ``pdw sweep`` (a study).

``pdw walk`` runs the paper's typical gait (Sec. 3.2: `Params.paper()`, x0 of
`pdw.X0_PAPER`, 3.5 s, dt = 1e-4, the central difference method), prints the step
table next to the paper's numbers, and writes the report, the step table, the run's metadata,
the scene as run and the figures (Figs. 4-7 and an animated GIF) to an output folder. With
``--scene FILE`` the run starts from a `pdw.Scene` file (the same schema as ``pdw run``);
options given on the command line win.

``pdw run SCENE.toml`` (or ``--example NAME``) runs a `pdw.Scene` file (docs/scenes.md): it
prints the run's summary, its gait descriptors and, for a run that walked, their steady values;
with ``--out DIR`` it writes steps.csv, run.json and the scene as run (scene.toml).

Exit codes (`EXIT_CODES`, the same for every command): 0 the run walked (or the command
succeeded); 2 invalid input or usage; 3 the run ended without walking (fell, or diverged, or no
gait was found: `pdw.SimulationError`, `pdw.GaitNotFoundError`); 4 an optional dependency is
missing (`pdw.present.deps`: checked before the work; the message names the extra to install
and the option that does without, e.g. ``--no-figures``); 130 interrupted; 141 the output was
closed (``pdw walk | head``).
"""
from __future__ import annotations

import argparse
import contextlib
import json
import os
import pathlib
import sys
import textwrap
import warnings

import numpy as np

from .. import examples
from ..analysis.gait_types import GaitNotFoundError
from ..core.errors import PdwError, SimulationError
from ..core.integrators import METHODS
from ..core.provenance import provenance
from ..sim.gait import steps
from ..sim.scene import PRESETS, Scene
from .cli_continue import add_cli as add_continue_cli
from .cli_robustness import add_cli as add_robustness_cli
from .cli_sweep import add_cli as add_sweep_cli
from .deps import EXTRAS, MissingDependency, missing_extra, require  # noqa: F401 (cli.EXTRAS)
from .report import walk_report

EXIT_CODES = {0: "the run walked (or the command succeeded)",
              2: "invalid input or usage (the message names the field)",
              3: "the run ended without walking: it fell or diverged (or no gait was found)",
              4: "an optional dependency is missing (checked before the work; the message "
                 "names the extra)",
              130: "interrupted (Ctrl-C)",
              141: "the output was closed early (e.g. `pdw walk | head`)"}


def _version() -> str:
    from ..core import __version__
    from ..core._layout import INPUT_HASH
    return "pdw %s (model input hash %s)" % (__version__, INPUT_HASH[:12])


# --- shared output ------------------------------------------------------------------------------

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
    if isinstance(v, (list, tuple)):
        return [_jsonable(x) for x in v]
    if isinstance(v, float) and not np.isfinite(v):
        return None
    return v


def _write_run(scene, res, st, out) -> list:
    """steps.csv, run.json, scene.toml and (for a run with recorded samples) the trajectory,
    trajectory.npz (`pdw.load`), of a run in ``out``; returns the paths."""
    out.mkdir(parents=True, exist_ok=True)
    _write_steps_csv(st, out / "steps.csv")
    scene.save(out / "scene.toml")
    meta = dict(scene=scene.to_dict(), status=res.status, stop_reason=res.stop_reason,
                t_final=res.t_final, n_steps=res.n_steps, n_gait_steps=res.n_gait_steps,
                event_counts=res.event_counts, wall_time_s=res.wall_time, stats=res.stats,
                params=res.params.as_dict(), features=list(res.features),
                steady=st.steady() if (len(st) and res.walked) else None, failure=res.failure,
                provenance=provenance())
    (out / "run.json").write_text(json.dumps(_jsonable(meta), indent=2) + "\n")
    written = [out / "steps.csv", out / "run.json", out / "scene.toml"]
    if len(res.t):
        res.scene = scene
        written.append(res.save(out / "trajectory.npz"))
    return written


# --- pdw walk -----------------------------------------------------------------------------------

def walk_scene(args) -> Scene:
    """The scene of ``pdw walk``: the scene file (or the default `Scene`, the paper's typical
    gait) with the command line's options applied; a fall or divergence is returned, not raised."""
    scene = Scene.load(args.scene) if args.scene else Scene(name="typical gait")
    top = {k: getattr(args, k) for k in ("preset", "variant") if getattr(args, k) is not None}
    integrator = {k: v for k, v in (("method", args.method), ("dt", args.dt)) if v is not None}
    stop = {"t_end": args.t_end} if args.t_end is not None else {}
    record = {"every": args.record_every} if args.record_every is not None else {}
    return scene.replace(**top, integrator=integrator, stop=stop, record=record,
                         limits={"on_failure": "return"})


def _walk(args):
    scene = walk_scene(args)
    if not args.no_figures and scene.record.every != 0:
        require("matplotlib", "PIL", purpose="the figures and the GIF")
    res = scene.run()
    text = walk_report(res)
    print(text)
    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "report.txt").write_text(text + "\n")
    written = [out / "report.txt"] + _write_run(scene, res, steps(res), out)
    if not args.no_figures:
        if res.x.shape[0] < 2:
            print("no figures: nothing was recorded (record.every = 0)")
        else:
            from .plots import save_all
            written += save_all(res, out, progress=not args.no_progress)
    print("\nwrote: " + ", ".join(str(p) for p in written))
    return 0 if res.walked else 3


# --- pdw run ------------------------------------------------------------------------------------

def _list_examples():
    """Every shipped example, by command, with its whole first sentence (wrapped, indented)."""
    for title, names, path_of in (
            ("example scenes (pdw run --example NAME)", examples.scenes(), examples.scene_path),
            ("example studies (pdw sweep --example NAME)", examples.studies(),
             examples.study_path),
            ("example continuations (pdw continue --example NAME)", examples.continuations(),
             examples.continuation_path)):
        print(title + ":")
        for name in names:
            print(textwrap.fill(examples.describe(path_of(name)), width=96,
                                initial_indent="  %-18s " % name, subsequent_indent=" " * 21))
    return 0


def _run(args):
    if args.list_examples:
        return _list_examples()
    if (args.scene is None) == (args.example is None):
        raise PdwError("give a scene file or --example NAME (one of them; --list-examples "
                       "lists the examples)")
    path = examples.scene_path(args.example) if args.example else args.scene
    scene = Scene.load(path)
    res = scene.run()
    st = steps(res)
    lines = ["scene: %s (%s)" % (scene.name or "-", args.example or args.scene), res.summary()]
    if res.failure:
        lines.append("failure: %s at t = %.4f s" % (res.failure["reason"], res.failure["t"]))
    kept = "" if res.events_recorded or res.n_gait_steps <= len(st) else \
        " (the last %d of %d, computed online)" % (len(st), res.n_gait_steps)
    lines += ["", "gait steps%s:" % kept, st.to_text() if len(st) else "(no complete step)"]
    if len(st) and res.walked:
        sd = st.steady()
        lines += ["", "steady (mean of the last %d steps): L = %.4f m, travel = %.4f m, P = %.4f s, "
                  "v = %.4f m/s, cycle = %.4f s, double support = %.1f ms (%.2f %%)"
                  % (sd["last"], sd["L"], sd["travel"], sd["P"], sd["v"], sd["cycle"],
                     1e3 * sd["double_support"], 100 * sd["ds_fraction"])]
        if not sd["converged"]:
            lines[-1] = lines[-1].replace("steady (", "not yet steady (", 1)
            lines.append("(not converged: L changes by up to %.2g m, P by %.2g s between the "
                         "last steps)" % (sd["spread_L"], sd["spread_P"]))
    elif not res.walked:
        lines += ["", "no steady values: the run %s at t = %.4f s" % (res.status, res.t_final)]
    print("\n".join(lines))
    if args.out:
        written = _write_run(scene, res, st, pathlib.Path(args.out))
        print("\nwrote: %s" % ", ".join(str(p) for p in written))
    return 0 if res.walked else 3


# --- main ---------------------------------------------------------------------------------------

def _parser():
    codes = "\n".join("  %3d  %s" % kv for kv in EXIT_CODES.items())
    ap = argparse.ArgumentParser(
        prog="pdw", description="pdw: passive dynamic walking on compliant ground "
                                "(the model: docs/model.md)",
        epilog="exit codes:\n" + codes, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--version", action="version", version=_version())
    sub = ap.add_subparsers(dest="command", required=True)
    w = sub.add_parser("walk", help="simulate the paper's typical gait: step table, report, figures")
    w.add_argument("--scene", help="a pdw.Scene TOML file (docs/scenes.md) to start from")
    w.add_argument("--t-end", dest="t_end", type=float, help="duration [s] (default 3.5)")
    w.add_argument("--dt", type=float, help="time step [s] (default 1e-4)")
    w.add_argument("--variant", choices=("paper", "consistent"),
                   help="contact variant (docs/model.md section 6)")
    w.add_argument("--preset", choices=PRESETS, help="parameter preset")
    w.add_argument("--method", choices=METHODS, help="integrator (default cdm, the paper's)")
    w.add_argument("--record-every", dest="record_every", type=int, help="record every k-th step")
    w.add_argument("--out", default="out/typical_gait",
                   help="output folder (default out/typical_gait)")
    w.add_argument("--no-figures", action="store_true", help="skip the figures and the GIF")
    w.add_argument("--no-progress", action="store_true",
                   help="no progress bar over the figures (drawn only on a terminal)")
    r = sub.add_parser("run", help="run a scene file (docs/scenes.md): summary, gait descriptors")
    r.add_argument("scene", nargs="?", help="TOML scene file (pdw.Scene)")
    r.add_argument("--example", help="run an example scene shipped with pdw (see --list-examples)")
    r.add_argument("--list-examples", action="store_true",
                   help="list the example scenes and studies shipped with pdw")
    r.add_argument("--out", help="also write steps.csv, run.json and scene.toml to this folder")
    add_sweep_cli(sub)                          # ``pdw sweep STUDY.toml`` (cli_sweep.py)
    add_continue_cli(sub)                       # ``pdw continue SPEC.toml`` (cli_continue.py)
    add_robustness_cli(sub)                     # ``pdw robustness SPEC.toml`` (cli_robustness.py)
    return ap


def _show_warning(message, category, filename, lineno, file=None, line=None):
    """Warnings as one line: ``pdw: StepSizeWarning: ...`` (no source path or line)."""
    print("pdw: %s: %s" % (category.__name__, message), file=file or sys.stderr)


def main(argv=None):
    """Run the command line; returns the exit code (`EXIT_CODES`)."""
    args = _parser().parse_args(argv)
    try:
        with warnings.catch_warnings():
            warnings.showwarning = _show_warning
            if hasattr(args, "func"):
                rc = args.func(args)
            else:
                rc = _run(args) if args.command == "run" else _walk(args)
        sys.stdout.flush()                  # a closed pipe shows here, not at exit
        return rc
    except BrokenPipeError:
        # the reader went away (``pdw walk | head``): stop quietly; silence the final flush
        with contextlib.suppress(OSError):
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())
        return 141
    except (SimulationError, GaitNotFoundError) as e:   # the run fell or diverged, no gait
        print("pdw: error: %s" % e, file=sys.stderr)
        return 3
    except PdwError as e:
        print("pdw: error: %s" % e, file=sys.stderr)
        return 2
    except OSError as e:                    # a file that cannot be read or written
        print("pdw: error: %s" % e, file=sys.stderr)
        return 2
    except ValueError as e:
        print("pdw: invalid input: %s" % e, file=sys.stderr)
        return 2
    except MissingDependency as e:         # found before the work (deps.require)
        print("pdw: error: %s" % e, file=sys.stderr)
        return 4
    except ImportError as e:
        hint = missing_extra(e)
        if hint is None:
            raise
        print("pdw: error: %s" % hint, file=sys.stderr)
        return 4
    except KeyboardInterrupt:
        print("pdw: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
