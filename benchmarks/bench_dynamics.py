"""Exact inverse dynamics per sample on 1e6 samples, one core, A/B in one process.

Run: taskset -c 0 python benchmarks/bench_dynamics.py

Side by side, interleaved (each round times every variant once, best of 7 rounds with the
median and the worst shown, so that the shared machine's swings hit them alike):

* ``inverse_dynamics`` as installed: the compiled kernel (``dextar/dynamics/_kernel.c``, built
  by pip where a C compiler is), and the raw kernel call without the input checks,
* the numpy kernel, what an install without a C compiler runs (blocks of 8192 samples; 4096
  and 16384 beside it),
* the kernel it replaced (the per-body evaluation ``_pose``/``_rates``/``_loads`` that
  ``joint_reactions`` and ``kinetic_energy`` still use, plus the stack into (n, 2)),
* the memory floor: a copy of the three inputs into arrays already allocated,
* when numba is installed, a compiled scalar loop of the same equations: the figure a
  compiled dependency would buy (not a run-time path of dextar; its results are compared),

then the floor (40 ns/sample) and the MuJoCo cross-check's cost on the same states.
"""

from __future__ import annotations

import math
import time

import numpy as np

from dextar.dynamics import Model, exact, inverse_dynamics, paper_inertia
from dextar.dynamics.exact import _kernel_constants, _lumped, _run, _torques
from dextar.geometry import DEXTAR_MM
from dextar.laws import solve_optimal_law
from dextar.output.mjcf import mujoco_state, to_mjcf
from dextar.paths import Arc
from dextar.trajectory import sample_trajectory

ROUNDS = 7


def previous_kernel(model, q, dq, ddq):
    """inverse_dynamics as it was: the per-body kernel and a stack into (n, 2)."""
    out = _run(model, q, dq, ddq, gravity=True, friction=True)
    return np.stack([out["tau1"], out["tau2"]], axis=-1)


def compiled(model):
    """A numba loop over the samples with the fused kernel's equations (None without numba)."""
    try:
        from numba import njit
    except ImportError:
        return None
    c = _lumped(model, True, True)

    def pair(v):
        a = np.broadcast_to(np.asarray(0.0 if v is None else v, dtype=float), (2, 1))
        return float(a[0, 0]), float(a[1, 0])

    l1, l2 = pair(c.l)
    L1s, L2s = pair(c.Lsq)
    J1, J2 = pair(c.J)
    cK1, cK2 = pair(c.cK)
    ax_1, ax_2 = pair(c.Gax)
    ay_1, ay_2 = pair(c.Gay)
    v1, v2 = pair(c.viscous)
    co1, co2 = pair(c.coulomb)
    d, ue0, cst, sg, MP, MPgx, MPgy, ivs = (c.d, c.ue0, c.cst, float(c.sign), c.MP, c.MPgx,
                                            c.MPgy, c.inv_vs)

    friction = co1 != 0.0 or co2 != 0.0

    @njit(cache=False, fastmath=False)
    def kernel(q, dq, ddq, out):  # pragma: no cover - compiled
        for i in range(q.shape[0]):
            w1, w2, a1, a2 = dq[i, 0], dq[i, 1], ddq[i, 0], ddq[i, 1]
            t1, t2 = math.tan(0.5 * q[i, 0]), math.tan(0.5 * q[i, 1])  # one libm call each
            f1, f2 = 2.0 * l1 / (1.0 + t1 * t1), 2.0 * l2 / (1.0 + t2 * t2)
            Ax1, Ay1 = f1 - l1, f1 * t1
            Ax2, Ay2 = f2 - l2, f2 * t2
            vx, vy = Ax1 - Ax2 + d, Ay1 - Ay2
            del2 = vx * vx + vy * vy
            idel = 1.0 / del2
            kk = 0.5 + cst * idel
            hh = math.sqrt(max(L2s * idel - kk * kk, 0.0))
            ue = ue0 - 0.5 * del2
            idet = -sg * idel / hh
            ex, ey = kk * vx - sg * hh * vy, kk * vy + sg * hh * vx
            ux, uy = ex - vx, ey - vy
            b1, b2 = Ax1 * uy - Ay1 * ux, Ax2 * ey - Ay2 * ex
            c1, c2 = Ax1 * ux + Ay1 * uy, Ax2 * ex + Ay2 * ey
            r1, r2 = b1 * w1, b2 * w2
            Om1 = (L1s * r2 - ue * r1) * idet - w1 * c1
            Om2 = -(L2s * r1 - ue * r2) * idet - w2 * c2
            rr1 = b1 * a1 - (Om1 * Om1 / L1s + w1 * w1 * c1)
            rr2 = b2 * a2 - (Om2 * Om2 / L2s + w2 * w2 * c2)
            Y1 = (L1s * rr2 - ue * rr1) * idet
            Y2 = -(L2s * rr1 - ue * rr2) * idet
            k1 = cK1 * (Y1 - a1 * c1 - w1 * r1)
            k2 = cK2 * (Y2 - a2 * c2 - w2 * r2)
            lr1 = (MP * Y1 - MPgy * ux + MPgx * uy + L1s * k1 + ue * k2) * idet
            lr2 = -(MP * Y2 - MPgy * ex + MPgx * ey + L2s * k2 + ue * k1) * idet
            out[i, 0] = (b1 * lr2 - k1 * c1 + J1 * a1 + ax_1 * Ax1 + ay_1 * Ay1 + v1 * w1)
            out[i, 1] = (b2 * lr1 - k2 * c2 + J2 * a2 + ax_2 * Ax2 + ay_2 * Ay2 + v2 * w2)
            if friction:
                out[i, 0] += co1 * math.tanh(w1 * ivs)
                out[i, 1] += co2 * math.tanh(w2 * ivs)

    def run(q, dq, ddq):
        out = np.empty_like(q)
        kernel(q, dq, ddq, out)
        return out

    return run


def main() -> None:
    robot = DEXTAR_MM.scaled(1 / 87)
    path = Arc(120 / 87, 0.0, np.pi)
    tr = sample_trajectory(robot, path, solve_optimal_law(path, eta=0.1), samples=10001)
    model = Model(robot, paper_inertia(robot).with_(rotor=(0.01, 0.01), gravity=(0.0, -1.0)))
    n = 1_000_000
    idx = np.random.default_rng(0).integers(0, tr.t.size, n)
    q, dq, ddq = tr.q[idx], tr.dq[idx], tr.ddq[idx]
    copies = [np.empty_like(x) for x in (q, dq, ddq)]

    def floor():
        for dst, src in zip(copies, (q, dq, ddq), strict=True):
            np.copyto(dst, src)

    def numpy_kernel(block=exact.FUSED_BLOCK):
        exact.USE_COMPILED = False
        try:
            return _torques(model, q, dq, ddq, gravity=True, friction=True, block=block)
        finally:
            exact.USE_COMPILED = exact._compiled is not None

    consts, raw_out = _kernel_constants(_lumped(model, True, True)), np.empty_like(q)
    variants = {}
    if exact._compiled is not None:
        variants["inverse_dynamics (compiled kernel)"] = lambda: inverse_dynamics(model, q, dq,
                                                                                  ddq)
        variants["  the kernel call alone (no checks)"] = lambda: exact._compiled.torques(
            consts, q, dq, ddq, raw_out)
    else:
        print("the compiled kernel is not built (no C compiler at install): numpy only")
    variants |= {
        "numpy kernel (no C compiler)": numpy_kernel,
        "  the same, blocks of 4096": lambda: numpy_kernel(4096),
        "  the same, blocks of 16384": lambda: numpy_kernel(16384),
        "previous kernel (per body)": lambda: previous_kernel(model, q, dq, ddq),
        "memory floor (copy the inputs)": floor,
    }
    fast = compiled(model)
    if fast is not None:
        fast(q[:10], dq[:10], ddq[:10])  # compile outside the timing
        variants["numba loop (not a dextar path)"] = lambda: fast(q, dq, ddq)
    ours = inverse_dynamics(model, q, dq, ddq)
    ref = previous_kernel(model, q, dq, ddq)
    scale = np.abs(ref).max()
    print(f"inverse_dynamics vs previous kernel: max |difference| / max |tau| = "
          f"{np.abs(ours - ref).max() / scale:.1e}")
    print(f"numpy kernel vs previous kernel: max |difference| / max |tau| = "
          f"{np.abs(numpy_kernel() - ref).max() / scale:.1e}")
    if fast is not None:
        print(f"numba loop vs fused kernel: {np.abs(fast(q, dq, ddq) - ours).max() / scale:.1e}")
    times = {k: [] for k in variants}
    for _ in range(ROUNDS):
        for name, fn in variants.items():
            t0 = time.perf_counter()
            fn()
            times[name].append((time.perf_counter() - t0) / n * 1e9)
    print(f"ns/sample on {n:.0e} samples, best of {ROUNDS} interleaved rounds (median, max):")
    for name, t in times.items():
        t = np.array(t)
        print(f"  {name:<34} {t.min():7.1f}  ({np.median(t):6.1f}, {t.max():6.1f})")
    first = next(iter(times))
    for other in ("numpy kernel (no C compiler)", "previous kernel (per body)"):
        if other != first:
            ratio = np.array(times[other]) / np.array(times[first])
            print(f"  {other.split(' (')[0]} / {first.split(' (')[0]}, round by round: best "
                  f"{ratio.max():.2f}x, median {np.median(ratio):.2f}x")
    print(f"floor: 40 ns/sample for inverse_dynamics: {min(times[first]):.1f} ns")
    try:
        import mujoco
    except ImportError:
        print("mujoco not installed: no comparison")
        return
    m = mujoco.MjModel.from_xml_string(to_mjcf(model))
    d = mujoco.MjData(m)
    k = 20000
    qpos, qvel = mujoco_state(model, q[:k], dq[:k])
    acc = np.empty((k, 2))
    t0 = time.perf_counter()
    for i in range(k):
        d.qpos[:] = qpos[i]
        d.qvel[:] = qvel[i]
        d.ctrl[:] = ours[i]
        mujoco.mj_forward(m, d)
        acc[i] = d.qacc[[0, 2]]
    mj = (time.perf_counter() - t0) / k * 1e9
    rel = np.abs(acc - ddq[:k]).max() / np.abs(ddq[:k]).max()
    best = min(times[first])
    print(f"MuJoCo mj_forward:      {mj:7.1f} ns/sample on {k:.0e} samples (Python loop), "
          f"{mj / best:.0f}x ours")
    print(f"MuJoCo accelerations vs ours: max relative difference {rel:.1e}")


if __name__ == "__main__":
    main()
