"""A compiler wrapper that caches object files, for the mutation campaign (benchmarks/mutation.py).

setuptools recompiles *every* source of an extension when one of them (or a header it lists in
``depends``) is newer than the extension; a one-line mutant of pdw/core/csrc/pdw_cdm.c would
recompile the 240 kB generated model and the Cython output of three extensions (about a minute
on a quiet machine). With ``CC="python benchmarks/mutation_cc.py gcc"`` each compile is keyed
by its arguments (output path left out) and its preprocessed source (``gcc -E``), so only the
translation units whose preprocessed text a mutant changed are compiled again; the rest are
copied from the cache (``$PDW_MUTATION_CACHE``, default ``build/mutation-cc``). Link commands
(no ``-c``) run unchanged. Not used by the normal build.
"""
from __future__ import annotations

import hashlib
import os
import pathlib
import shutil
import subprocess
import sys


def _split(args):
    """(arguments without ``-o OUT``, OUT) of a compile command."""
    rest, out, skip = [], None, False
    for k, a in enumerate(args):
        if skip:
            skip = False
            continue
        if a == "-o" and k + 1 < len(args):
            out, skip = args[k + 1], True
            continue
        rest.append(a)
    return rest, out


def main(argv):
    cc, args = argv[0], argv[1:]
    if "-c" not in args:
        return subprocess.call([cc] + args)
    rest, out = _split(args)
    if out is None:
        return subprocess.call([cc] + args)
    cache = pathlib.Path(os.environ.get("PDW_MUTATION_CACHE", "build/mutation-cc"))
    cache.mkdir(parents=True, exist_ok=True)
    pre = subprocess.run([cc, "-E"] + [a for a in rest if a != "-c"], capture_output=True)
    if pre.returncode != 0:                      # let the compiler report the error
        return subprocess.call([cc] + args)
    key = hashlib.sha256("\0".join([cc] + rest).encode() + b"\0" + pre.stdout).hexdigest()
    obj = cache / (key + ".o")
    if obj.exists():
        pathlib.Path(out).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(obj, out)
        return 0
    rc = subprocess.call([cc] + args)
    if rc == 0:
        tmp = obj.with_suffix(".tmp%d" % os.getpid())
        shutil.copyfile(out, tmp)
        os.replace(tmp, obj)
    return rc


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
