# The compiled banded interior point (_ipm.c), built by pip where a C compiler is.
VERSION: int

def solve(c: object, rk: object, ra: object, rg: object, rb: object, E: object, e: object,
          lo: object, hi: object, rq: object, x0: object, x: object, tol: float, dual_tol: float,
          gap_tol: float, maxiter: int, /) -> tuple[int, int]: ...
