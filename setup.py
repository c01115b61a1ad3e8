"""The compiled part of dextar: the fused torque kernel (src/dextar/dynamics/_kernel.c), which
dextar.dynamics.exact uses where it was built. Everything else is in pyproject.toml.

The extension is optional: an install without a C compiler goes on, and dextar uses the numpy
kernel (the same torques to rounding, three times slower: benchmarks/bench_dynamics.py). No
contraction into fused multiply-adds: the same torques on every instruction set.
"""

import sys

from setuptools import Extension, setup

FLAGS = [] if sys.platform == "win32" else ["-O3", "-ffp-contract=off", "-fno-math-errno"]

setup(ext_modules=[Extension("dextar.dynamics._kernel", ["src/dextar/dynamics/_kernel.c"],
                             optional=True, extra_compile_args=FLAGS)])
