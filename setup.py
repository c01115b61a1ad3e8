"""The compiled parts of dextar, each used where it was built; everything else is in
pyproject.toml:

* the fused torque kernel (src/dextar/dynamics/_kernel.c) of dextar.dynamics.exact: without
  it the numpy kernel, the same torques to rounding, 1.5-3 times slower
  (benchmarks/bench_dynamics.py);
* the time-optimal law's reachability analysis (src/dextar/laws/_reach.c) of
  dextar.laws.time_optimal: without it the Python passes, the same law to the last bit,
  slower (benchmarks/bench_time_optimal.py); with it Clenshaw's recurrence for
  dextar.laws.optimal's long Chebyshev series (numpy's chebval otherwise, the same values);
* the jerk-limited law's banded interior point (src/dextar/laws/smooth/_ipm.c) of
  dextar.laws.smooth.banded: without it the numpy solver, the same solutions to the
  programmes' tolerances, slower (benchmarks/bench_smooth.py);
* the jerk-limited law's rows (src/dextar/laws/smooth/_rows.c) of
  dextar.laws.smooth.rows: without it the numpy rows, the same rows to rounding, slower.

The extensions are optional: an install without a C compiler goes on without them. No
contraction into fused multiply-adds: the same results on every instruction set.
"""

import sys

from setuptools import Extension, setup

FLAGS = [] if sys.platform == "win32" else ["-O3", "-ffp-contract=off", "-fno-math-errno"]

SHARED = ["src/dextar/_buffers.h"]

setup(ext_modules=[Extension("dextar.dynamics._kernel", ["src/dextar/dynamics/_kernel.c"],
                             depends=SHARED, optional=True, extra_compile_args=FLAGS),
                   Extension("dextar.laws._reach", ["src/dextar/laws/_reach.c"],
                             depends=SHARED, optional=True, extra_compile_args=FLAGS),
                   Extension("dextar.laws.smooth._ipm", ["src/dextar/laws/smooth/_ipm.c"],
                             depends=SHARED, optional=True, extra_compile_args=FLAGS),
                   Extension("dextar.laws.smooth._rows", ["src/dextar/laws/smooth/_rows.c"],
                             depends=SHARED, optional=True, extra_compile_args=FLAGS)])
