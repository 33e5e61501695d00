"""Build the compiled core (layer pdw.core): generated/pdw_model.c (the model) + pdw/core/csrc (time
loops) + Cython, and the hybrid walker (generated/pdw_hybrid.c).

Portable, reproducible optimisation (no -march=native or -ffast-math unless asked for through
PDW_CFLAGS). Release builds carry no debug symbols (-g0, and stripped at link on Linux); set
PDW_DEBUG=1 to keep them.
"""
import glob
import os
import sys

from Cython.Build import cythonize
from setuptools import Extension, setup

CSRC = "pdw/core/csrc"
DEBUG = os.environ.get("PDW_DEBUG", "") not in ("", "0")
extra = ["-O3", "-std=c99", "-fno-math-errno"] + ([] if DEBUG else ["-g0"]) \
    + os.environ.get("PDW_CFLAGS", "").split()
link = [] if DEBUG or not sys.platform.startswith("linux") else ["-s"]
hybrid = ["pdw/core/_hybrid.pyx", "generated/pdw_hybrid.c", CSRC + "/pdw_hybrid_sim.c",
          CSRC + "/pdw_hybrid_var.c"]
batch = sorted(glob.glob(CSRC + "/pdw_batch*.c"))
loops = sorted(set(glob.glob(CSRC + "/*.c")) - set(hybrid) - set(batch))
sources = ["pdw/core/_core.pyx", "generated/pdw_model.c"] + loops
# The ensemble engine (docs/ensemble.md): -fopenmp-simd enables `#pragma omp simd` / `declare
# simd` only (no OpenMP runtime); the vector sin/cos come from glibc's libmvec.
batch_sources = ["pdw/core/_batch.pyx", "generated/pdw_model.c"] + loops + batch

setup(
    ext_modules=cythonize(
        [Extension("pdw.core._core", sources=sources, include_dirs=["generated", CSRC],
                   extra_compile_args=extra, extra_link_args=link, libraries=["m"]),
         Extension("pdw.core._batch", sources=batch_sources, include_dirs=["generated", CSRC],
                   extra_compile_args=extra + ["-fopenmp-simd", "-ffp-contract=off"], extra_link_args=link,
                   libraries=["mvec", "m"]),
         Extension("pdw.core._hybrid", sources=hybrid, include_dirs=["generated", CSRC],
                   extra_compile_args=extra, extra_link_args=link, libraries=["m"])],
        compiler_directives={"language_level": "3", "boundscheck": False, "wraparound": False,
                             "cdivision": True, "initializedcheck": False},
    ),
)
