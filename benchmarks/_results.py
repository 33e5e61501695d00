"""Where benchmark and study scripts put their output.

By default everything goes under ``out/benchmarks/`` (``results/`` for the text and JSON,
``figures/`` for the figures), so a quick or exploratory run never overwrites what the docs
show. ``--update-docs`` on any script's command line (or ``PDW_UPDATE_DOCS=1``) writes to the
committed places instead: ``benchmarks/results/`` and ``docs/figures/``.
"""
import os
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
UPDATE_DOCS = "--update-docs" in sys.argv or os.environ.get("PDW_UPDATE_DOCS", "") == "1"
if "--update-docs" in sys.argv:          # consumed here, so every script's parser accepts it
    sys.argv.remove("--update-docs")

if UPDATE_DOCS:
    RESULTS = ROOT / "benchmarks" / "results"
    FIGURES = ROOT / "docs" / "figures"
else:
    RESULTS = ROOT / "out" / "benchmarks" / "results"
    FIGURES = ROOT / "out" / "benchmarks" / "figures"


def publish(name, lines):
    """Print the report ``lines`` and write them to ``RESULTS/name``."""
    text = "\n".join(lines)
    print(text)
    RESULTS.mkdir(parents=True, exist_ok=True)
    (RESULTS / name).write_text(text + "\n")
    if not UPDATE_DOCS:
        print("(written to %s; --update-docs writes the committed results and figures)"
              % (RESULTS / name))
    return lines
