"""Build the compiled core: generated/pdw_model.c (the model) + pdw/csrc (time loops) + Cython."""
import glob
import os

from Cython.Build import cythonize
from setuptools import Extension, setup

# Portable, reproducible optimisation; no -march=native or -ffast-math unless asked for.
extra = ["-O3", "-std=c99", "-fno-math-errno"] + os.environ.get("PDW_CFLAGS", "").split()
hybrid = ["pdw/_hybrid.pyx", "generated/pdw_hybrid.c", "pdw/csrc/pdw_hybrid_sim.c",
          "pdw/csrc/pdw_hybrid_var.c"]
sources = ["pdw/_core.pyx", "generated/pdw_model.c"] + sorted(set(glob.glob("pdw/csrc/*.c")) - set(hybrid))

setup(
    ext_modules=cythonize(
        [Extension("pdw._core", sources=sources, include_dirs=["generated", "pdw/csrc"],
                   extra_compile_args=extra, libraries=["m"]),
         Extension("pdw._hybrid", sources=hybrid, include_dirs=["generated", "pdw/csrc"],
                   extra_compile_args=extra, libraries=["m"])],
        compiler_directives={"language_level": "3", "boundscheck": False, "wraparound": False,
                             "cdivision": True, "initializedcheck": False},
    ),
)
