"""``python -m derive [--root DIR] [--check]``: regenerate generated/ and pdw/core/_layout.py.

``--check`` regenerates into a temporary tree and exits 1 if any file differs from
the committed one (used by ``make check-generated``).
"""
import argparse
import filecmp
import pathlib
import sys
import tempfile

from .emit import write_all


def main(argv=None):
    ap = argparse.ArgumentParser(prog="python -m derive", description=__doc__)
    ap.add_argument("--root", default=str(pathlib.Path(__file__).resolve().parent.parent),
                    help="repository root to write into (default: this checkout)")
    ap.add_argument("--check", action="store_true",
                    help="regenerate into a temporary folder and compare with --root")
    args = ap.parse_args(argv)
    root = pathlib.Path(args.root)
    if not args.check:
        for path in write_all(root):
            print("wrote", path.relative_to(root))
        return 0
    with tempfile.TemporaryDirectory() as tmp:
        bad = []
        for path in write_all(pathlib.Path(tmp)):
            rel = path.relative_to(tmp)
            if not (root / rel).exists() or not filecmp.cmp(path, root / rel, shallow=False):
                bad.append(str(rel))
        if bad:
            print("generated files differ from derive/: %s (run `make derive`)" % ", ".join(bad))
            return 1
        print("generated files match derive/")
        return 0


if __name__ == "__main__":
    sys.exit(main())
