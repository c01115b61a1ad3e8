# The compiled rows of the jerk-limited law (_rows.c), built by pip where a C compiler is.
VERSION: int

def block(grid: object, pcols: object, tlo: object, thi: object, h: object, J: object,
          Tk: object, sigma: object, w: object, alpha: object, kinds: object, lims: object,
          fric: object, F: object, norm: object, C: object, k: object, sizes: object,
          m: int, has_cap: int, k0: int, k1: int, cfloor: float, S: float,
          neg_inv_S: float, near: float, bulge: float, mid_bulge: float, grad: bool,
          /) -> tuple[int, int, int, int]: ...
def monitor(grid: object, lo: object, hi: object, s: object, v: object, a: object,
            kinds: object, lims: object, dt: float, c2: object, /) -> None: ...
def columns(pts: object, x0: object, kinds: object, pars: object, root: object, cols: object,
           m: int, has_cap: int, /) -> float: ...
