"""Build the compiled core (layer pdw.core): generated/pdw_model.c (the model) + pdw/core/csrc (time
loops) + Cython, and the hybrid walker (generated/pdw_hybrid.c)."""
import glob
import os

from Cython.Build import cythonize
from setuptools import Extension, setup

CSRC = "pdw/core/csrc"
# Portable, reproducible optimisation; no -march=native or -ffast-math unless asked for.
extra = ["-O3", "-std=c99", "-fno-math-errno"] + os.environ.get("PDW_CFLAGS", "").split()
hybrid = ["pdw/core/_hybrid.pyx", "generated/pdw_hybrid.c", CSRC + "/pdw_hybrid_sim.c"]
sources = (["pdw/core/_core.pyx", "generated/pdw_model.c"]
           + sorted(set(glob.glob(CSRC + "/*.c")) - set(hybrid)))

setup(
    ext_modules=cythonize(
        [Extension("pdw.core._core", sources=sources, include_dirs=["generated", CSRC],
                   extra_compile_args=extra, libraries=["m"]),
         Extension("pdw.core._hybrid", sources=hybrid, include_dirs=["generated", CSRC],
                   extra_compile_args=extra, libraries=["m"])],
        compiler_directives={"language_level": "3", "boundscheck": False, "wraparound": False,
                             "cdivision": True, "initializedcheck": False},
    ),
)
