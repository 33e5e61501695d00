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
# the hybrid integrators read dopri5's coefficients from the one tableau (pdw_dp5.h)
hybrid_extra = [CSRC + "/pdw_tableaus.c"]
batch = sorted(glob.glob(CSRC + "/pdw_batch*.c"))
loops = sorted(set(glob.glob(CSRC + "/*.c")) - set(hybrid) - set(batch))
sources = ["pdw/core/_core.pyx", "generated/pdw_model.c"] + loops
# The ensemble engine (docs/ensemble.md): -fopenmp-simd enables `#pragma omp simd` / `declare
# simd` only (no OpenMP runtime); the vector sin/cos come from glibc's libmvec.
batch_sources = ["pdw/core/_batch.pyx", "generated/pdw_model.c"] + loops + batch
# The lane loops (pdw_batch_soa.inc, generated/pdw_batch_gen.h) must vectorize: -fno-wrapv undoes
# Python's -fwrapv (with it GCC cannot count a loop `l < l0 + 8` and vectorizes none of them);
# -fno-trapping-math and -fno-tree-sink let it turn the contact law's branches into selects
# (neither changes a value);
# -ffp-contract=off: no FMA contraction on FMA targets (ISO C mode has it off already), so every
# instruction set gives the scalar stages' bits.
BATCH_FLAGS = ["-fopenmp-simd", "-fno-wrapv", "-fno-trapping-math", "-fno-tree-sink",
               "-ffp-contract=off"]
# headers and the lane loop's template: a change rebuilds every object (setuptools compares
# only a source's own time stamp otherwise)
depends = sorted(glob.glob(CSRC + "/*.h") + glob.glob(CSRC + "/*.inc") + glob.glob("generated/*.h"))

setup(
    ext_modules=cythonize(
        [Extension("pdw.core._core", sources=sources, include_dirs=["generated", CSRC],
                   extra_compile_args=extra, extra_link_args=link, libraries=["m"],
                   depends=depends),
         Extension("pdw.core._batch", sources=batch_sources, include_dirs=["generated", CSRC],
                   depends=depends,
                   extra_compile_args=extra + BATCH_FLAGS, extra_link_args=link,
                   libraries=["mvec", "m"]),
         Extension("pdw.core._hybrid", sources=hybrid + hybrid_extra, include_dirs=["generated", CSRC],
                   extra_compile_args=extra, extra_link_args=link, libraries=["m"],
                   depends=depends)],
        compiler_directives={"language_level": "3", "boundscheck": False, "wraparound": False,
                             "cdivision": True, "initializedcheck": False,
                             # typed signatures in __doc__: _shapes.pxi's _named_buffers reads them
                             "embedsignature": True},
    ),
)
