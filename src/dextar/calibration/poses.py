"""Measurement poses for a calibration: chosen from the reachable workspace of the working
modes, away from both singularity types, to maximise the observability index O1
(:mod:`dextar.calibration.observability`), in an order a robot can visit.

1. **Candidates**: a grid over the legs' reach in each working mode (offset by the seed
   within a cell; over the part of it inside ``region``, the box where the instrument can
   measure, when one is given, as many points along its longer side but at most 4 times
   as dense), kept where both legs reach, the pose is in the robot's
   assembly mode,
   its normalised distances to serial and parallel singularities are at least ``margin``
   and the distal rods keep ``closure_slack`` from stretched or folded (so that the real
   robot, off by its errors, still assembles at the commanded readings).
2. **D-optimal design** (O1 is the information matrix's determinant to the power
   ``1 / 2p``): a greedy pass adds the candidate that raises the determinant most (the
   matrix determinant lemma, vectorised over candidates), then Fedorov exchange passes swap
   a chosen pose for the best candidate while the determinant grows. Poses of a working
   mode keep ``spacing`` apart, so the design spreads over the workspace instead of
   repeating its extreme points. Every working mode asked for that has candidates gets at
   least its share of a quarter of the poses (``max(1, count // (4 k))`` of ``k`` modes,
   or all its candidates when fewer): the determinant alone may leave a mode out (a
   90/120/70 mm robot got 40 poses in 3 of the 4 modes), while poses of every mode decouple
   the parameters (Joubair, Slamani and Bonev). On the DexTAR the determinant alone already
   gives the rarest mode that share (3 of 60 poses, 2 of 40, 1 of 20), so its designs are
   unchanged. A mode without candidates is named (``missing_modes``). With a stated noise each candidate's information is
   whitened by its covariance ``sigma^2 I + s_r^2 J_q J_q^T`` (a pose where the encoders'
   resolution blurs the point counts for less).
3. **Order**: working modes in a Gray-code order from the robot's (one leg changes its
   sign at a time, the way a five-bar changes mode through a serial singularity), poses
   of a mode by a nearest-neighbour tour in joint space (the larger of the two motor moves).

Joubair, Slamani and Bonev measured their DexTAR in all four working modes: poses of one
mode leave the parameters more correlated (see :mod:`dextar.calibration`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from .._arrays import Array
from ..errors import ParameterError
from ..geometry import (
    WORKING_MODES,
    canonical_working_mode,
    parse_assembly_mode,
    parse_working_mode,
)
from ..kinematics import assembly_mode, inverse_kinematics
from ..kinematics.checker import pose_distances, reach_violation
from ..params import number_words
from .model import NAMES, ROBOT, KinematicModel, characteristic_scales, closure, jacobian
from .observability import Observability, identifiability, observability

#: Default distance (normalised, the sine of the angle at an elbow or at P) from both
#: singularity types.
DEFAULT_MARGIN = 0.2
#: Default slack (m) of the distal rods from stretched and folded at a pose.
DEFAULT_SLACK = 4e-3


@dataclass(frozen=True)
class PoseSelection:
    """Measurement poses in visiting order (SI).

    Attributes
    ----------
    modes : tuple of str
        Working mode of each pose.
    assembly : str
        The assembly mode of every pose (``"up"`` or ``"down"``).
    readings : ndarray, shape (n, 2)
        Encoder readings to command (rad): the nominal inverse kinematics minus the
        nominal offsets.
    points : ndarray, shape (n, 2)
        Nominal end-effector points (m), robot frame.
    type1, type2 : ndarray, shape (n,)
        Normalised distances to serial and parallel singularities.
    parameters : tuple of str
        The parameters the design is for.
    observability : Observability
        Of ``parameters`` over the poses (unweighted, scaled Jacobian).
    index : str
        The maximised index, ``"O1"``.
    n_candidates : int
    status : int
        0; 1 when fewer candidates than poses asked for were far enough apart (the spacing
        was relaxed); 2 when working modes asked for have no candidate (``missing_modes``).
    message : str
    missing_modes : tuple of str
        Working modes asked for without a candidate pose (in the region, the assembly, at
        the margin from the singularities).
    region : tuple of float, optional
        ``(xmin, xmax, ymin, ymax)`` (m, robot frame) every pose is inside.
    """

    modes: tuple[str, ...]
    assembly: str
    readings: Array
    points: Array
    type1: Array
    type2: Array
    parameters: tuple[str, ...]
    observability: Observability
    index: str
    n_candidates: int
    status: int
    message: str
    missing_modes: tuple[str, ...] = ()
    region: tuple[float, float, float, float] | None = None

    @property
    def success(self) -> bool:
        """True when ``status`` is 0."""
        return self.status == 0

    def __len__(self) -> int:
        return len(self.readings)


@dataclass(frozen=True)
class _Candidates:
    modes: Array       # (c,) index into the modes tuple
    q: Array           # (c, 2) geometric angles
    P: Array           # (c, 2)
    type1: Array
    type2: Array
    J: Array           # (c, 2, 10) robot frame (theta0 = 0)


#: A region: ``(xmin, xmax, ymin, ymax)`` (robot frame).
Region = tuple[float, float, float, float]


def checked_region(values: object, name: str = "region") -> Region:
    """``values`` as a region ``(xmin, xmax, ymin, ymax)``: four finite numbers, each
    minimum below its maximum; :class:`ParameterError` naming ``name`` otherwise (units are
    the caller's)."""
    v = list(values) if isinstance(values, (list, tuple)) else None
    if (v is None or len(v) != 4
            or not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v)):
        raise ParameterError(f"{name} must be four numbers [xmin, xmax, ymin, ymax], got "
                             f"{values!r}")
    x0, x1, y0, y1 = (float(x) for x in v)
    if not all(math.isfinite(x) for x in (x0, x1, y0, y1)):
        raise ParameterError(f"{name} {[x0, x1, y0, y1]} must be finite numbers "
                             "[xmin, xmax, ymin, ymax]")
    if not (x0 < x1 and y0 < y1):
        raise ParameterError(f"{name} {[x0, x1, y0, y1]} is empty: [xmin, xmax, ymin, ymax] "
                             "with xmin < xmax and ymin < ymax")
    return (x0, x1, y0, y1)


def region_text(region: Region) -> str:
    """A region (m) in words, in mm."""
    x0, x1, y0, y1 = (1e3 * v for v in region)
    return f"x {x0:g} to {x1:g} mm, y {y0:g} to {y1:g} mm (robot frame)"


def candidates(nominal: KinematicModel, modes: Sequence[str], assembly: int, *,
               margin: float, closure_slack: float, resolution: int,
               rng: np.random.Generator, region: Region | None = None
               ) -> tuple[tuple[str, ...], _Candidates]:
    """Candidate poses of ``modes`` (step 1 of the module doc), inside ``region``
    ``(xmin, xmax, ymin, ymax)`` (m, robot frame) when given."""
    r = nominal.robot
    reach = max(r.l1 + r.L1, r.l2 + r.L2)
    h = 0.5 * r.d
    lo, hi = np.array([-h - reach, -reach]), np.array([h + reach, reach])
    whole = float((hi - lo).max()) / (resolution - 1)
    if region is not None:
        lo = np.maximum(lo, [region[0], region[2]])
        hi = np.minimum(hi, [region[1], region[3]])
        if (hi <= lo).any():
            raise ParameterError(f"the region {region_text(region)} lies outside the legs' "
                                 f"reach (x {1e3 * (-h - reach):.6g} to "
                                 f"{1e3 * (h + reach):.6g} mm, y {-1e3 * reach:.6g} to "
                                 f"{1e3 * reach:.6g} mm)")
    # over a region as many grid points along its longer side, at most 4 x as dense as
    # over the whole reach (closer candidates only repeat each other)
    step = max(float((hi - lo).max()) / (resolution - 1), 0.25 * whole)
    off = rng.uniform(0.0, step, 2)
    xs = np.arange(lo[0] + off[0], hi[0], step)
    ys = np.arange(lo[1] + off[1], hi[1], step)
    xs, ys = xs[xs <= hi[0]], ys[ys <= hi[1]]
    X, Y = np.meshgrid(xs, ys)
    grid = np.stack([X.ravel(), Y.ravel()], axis=-1)
    out, _ = reach_violation(r, grid)
    grid = grid[(out == 0).all(axis=1)]
    m_all, q_all, P_all = [], [], []
    names = tuple(canonical_working_mode(m) for m in modes)
    base = nominal.with_frame(0.0, 0.0, 0.0)
    for i, mode in enumerate(names):
        q = inverse_kinematics(r, grid, mode)
        d = pose_distances(r, q, grid)
        ok = (d.type1 >= margin) & (d.type2 >= margin)
        ok &= assembly_mode(r, q, grid) == assembly
        k = closure(base, q - base.offsets, assembly)
        bc = np.hypot(*(k.B - k.C).T)
        ok &= (bc <= r.L1 + r.L2 - closure_slack) & (bc >= abs(r.L1 - r.L2) + closure_slack)
        m_all.append(np.full(int(ok.sum()), i))
        q_all.append(q[ok])
        P_all.append(grid[ok])
    q = np.concatenate(q_all)
    P = np.concatenate(P_all)
    d = pose_distances(r, q, P)
    k = closure(base, q - base.offsets, assembly)
    return names, _Candidates(np.concatenate(m_all), q, P, d.type1, d.type2,
                              jacobian(base, k))


def _gains(Jc: Array, Minv: Array) -> Array:
    """``det(I + J_i M^-1 J_i^T)`` of each candidate (c,): the factor by which adding it
    multiplies ``det M``."""
    A = (Jc.reshape(-1, Jc.shape[-1]) @ Minv).reshape(Jc.shape)  # one BLAS product
    g00 = np.einsum("ck,ck->c", A[:, 0], Jc[:, 0])
    g11 = np.einsum("ck,ck->c", A[:, 1], Jc[:, 1])
    g01 = np.einsum("ck,ck->c", A[:, 0], Jc[:, 1])
    g10 = np.einsum("ck,ck->c", A[:, 1], Jc[:, 0])
    return np.asarray((1.0 + g00) * (1.0 + g11) - g01 * g10)


def _d_optimal(Jc: Array, modes: Array, P: Array, count: int, spacing: float,
               passes: int, quota: Array | None = None) -> tuple[Array, bool]:
    """Indices of ``count`` candidates maximising ``det(sum J_i^T J_i)`` (greedy, then
    Fedorov exchange), poses of one mode ``spacing`` apart when possible, at least
    ``quota[m]`` poses of mode ``m``; and whether the spacing held."""
    c, _, p = Jc.shape
    quota = np.zeros(int(modes.max(initial=0)) + 1, int) if quota is None else quota
    n_mode = np.zeros(len(quota), int)
    F = np.einsum("cki,ckj->cij", Jc, Jc)
    ridge = 1e-9 * float(np.trace(F.mean(axis=0))) / p * np.eye(p)
    chosen: list[int] = []
    M = ridge.copy()
    spaced = True

    def near(j: int) -> Array:
        """Candidates within ``spacing`` of candidate ``j`` in its mode (``j`` included)."""
        return np.asarray((modes == modes[j]) & (np.hypot(*(P - P[j]).T) < spacing), dtype=int)

    blocked = np.zeros(c, int)  # chosen poses within spacing of each candidate
    taken = np.zeros(c, bool)
    for _ in range(count):
        g = _gains(Jc, np.linalg.inv(M))
        need = np.maximum(quota - n_mode, 0)
        # the last free slots go to the modes still below their quota
        allowed = need[modes] > 0 if count - len(chosen) <= need.sum() else np.ones(c, bool)
        ok = (blocked == 0) & ~taken & allowed
        if not ok.any():
            spaced = False
            ok = ~taken & allowed
        j = int(np.argmax(np.where(ok, g, -np.inf)))
        chosen.append(j)
        taken[j] = True
        n_mode[modes[j]] += 1
        blocked += near(j)
        M += F[j]
    for _ in range(passes):
        improved = False
        for s in range(count):
            old = chosen[s]
            Mm = M - F[old]
            g = _gains(Jc, np.linalg.inv(Mm))
            nb = near(old)
            ok = ((blocked - nb) == 0) & ~taken
            if n_mode[modes[old]] <= quota[modes[old]]:  # its mode at its quota: stay in it
                ok &= modes == modes[old]
            ok[old] = True
            j = int(np.argmax(np.where(ok, g, -np.inf)))
            if j != old and g[j] > g[old] * (1.0 + 1e-9):
                chosen[s] = j
                taken[old], taken[j] = False, True
                n_mode[modes[old]] -= 1
                n_mode[modes[j]] += 1
                blocked += near(j) - nb
                M = Mm + F[j]
                improved = True
        if not improved:
            break
    return np.array(chosen), spaced


def _gray_order(modes: Sequence[str], start: str) -> list[str]:
    """The modes in an order that changes one leg's sign at a time where it can, from
    ``start`` (or the first mode when ``start`` is not among them)."""
    todo = list(dict.fromkeys(modes))
    cur = start if start in todo else todo[0]
    order = [cur]
    todo.remove(cur)
    while todo:
        a = parse_working_mode(cur)
        nxt = min(todo, key=lambda m: (sum(x != y for x, y in zip(a, parse_working_mode(m),
                                                                   strict=True)),
                                       WORKING_MODES.index(m)))
        order.append(nxt)
        todo.remove(nxt)
        cur = nxt
    return order


def _tour(q: Array, start: Array) -> list[int]:
    """A tour of joint positions (n, 2) from ``start`` (2,), the distance the larger motor
    move: nearest neighbours, then 2-opt passes (reverse a stretch while that shortens it)."""
    pts = np.concatenate([start[None], q])
    diff = np.abs(np.angle(np.exp(1j * (pts[:, None, :] - pts[None, :, :]))))
    D = diff.max(axis=-1)
    left = list(range(1, len(pts)))
    order = [0]
    while left:
        i = left.pop(int(np.argmin(D[order[-1], left])))
        order.append(i)
    n = len(order)
    for _ in range(50):  # open path from the fixed start: reverse order[i:j + 1]
        better = False
        for i in range(1, n - 1):
            o = np.array(order)
            j = np.arange(i + 1, n)
            nxt = np.where(j + 1 < n, o[np.minimum(j + 1, n - 1)], -1)
            tail_old = np.where(nxt >= 0, D[o[j], np.maximum(nxt, 0)], 0.0)
            tail_new = np.where(nxt >= 0, D[o[i], np.maximum(nxt, 0)], 0.0)
            gain = D[o[i - 1], o[i]] + tail_old - D[o[i - 1], o[j]] - tail_new
            k = int(np.argmax(gain))
            if gain[k] > 1e-12:
                jj = int(j[k])
                order[i:jj + 1] = order[i:jj + 1][::-1]
                better = True
        if not better:
            break
    return [i - 1 for i in order[1:]]


def select_poses(nominal: KinematicModel, count: int, *,
                 modes: Sequence[str] = WORKING_MODES, start_mode: str = "+-",
                 assembly: str | int = "up", frame: str = "instrument",
                 margin: float = DEFAULT_MARGIN, closure_slack: float = DEFAULT_SLACK,
                 spacing: float | None = None, point_std: float | None = None,
                 reading_std: float | None = None, resolution: int = 61, seed: int = 0,
                 passes: int = 4, region: Sequence[float] | None = None) -> PoseSelection:
    """Choose ``count`` measurement poses (see the module doc).

    Parameters
    ----------
    nominal : KinematicModel
        The nominal robot (SI) and encoder offsets.
    count : int
        Poses wanted (at least twice the parameters: 20, or 14 in the robot frame).
    modes : sequence of str
        Working modes to measure in (default all four).
    start_mode : str
        The robot's working mode (the tour starts there).
    assembly : {"up", "down"}
        The robot's assembly mode.
    frame : {"instrument", "robot"}
        Whether the instrument frame is unknown (ten parameters) or the data will be in
        the robot frame (seven).
    margin : float
        Least normalised distance to both singularity types.
    closure_slack : float
        Least slack (m) of the distal rods from stretched or folded.
    spacing : float, optional
        Least distance (m) between poses of a mode (default 4 % of the legs' mean reach).
    point_std, reading_std : float, optional
        The instrument's noise per axis (m) and the encoders' (rad): with both, each
        candidate's information is weighted by its covariance.
    resolution : int
        Grid points along the longer side of the workspace's box.
    seed : int
        Offsets the candidate grid within a cell.
    passes : int
        Most exchange passes.
    region : sequence of 4 float, optional
        ``(xmin, xmax, ymin, ymax)`` (m, robot frame): every pose inside (where the
        instrument can measure).

    Returns
    -------
    PoseSelection

    Raises
    ------
    ParameterError
        Too few poses asked for, fewer candidates than poses, a region that is not one or
        lies outside the legs' reach.
    """
    names = _checked_parameters(frame, count, margin, resolution, modes)
    if not (isinstance(seed, (int, np.integer)) and seed >= 0):
        raise ParameterError(f"seed {seed!r} must be a whole number, 0 or more")
    box = None if region is None else checked_region(region)
    sign = parse_assembly_mode(assembly)
    r = nominal.robot
    if spacing is None:
        spacing = 0.02 * (r.l1 + r.L1 + r.l2 + r.L2)
    rng = np.random.default_rng(seed)
    mode_names, cand = candidates(nominal, modes, sign, margin=margin,
                                  closure_slack=closure_slack, resolution=resolution, rng=rng,
                                  region=box)
    n_c = len(cand.q)
    where = "" if box is None else f" in the region {region_text(box)}"
    if n_c < count:
        raise ParameterError(
            f"{n_c} candidate poses in working mode{'s' if len(mode_names) > 1 else ''} "
            f"{', '.join(mode_names)}{where} (assembly {assembly}, margin {margin:g} from the "
            f"singularities), fewer than the {count} asked for: lower the margin or the count"
            f"{'' if box is None else ', or widen the region'}")
    per_mode = np.bincount(cand.modes, minlength=len(mode_names))
    missing = tuple(m for m, n in zip(mode_names, per_mode, strict=True) if n == 0)
    share = max(1, int(count) // (4 * (len(mode_names) - len(missing))))
    quota = np.minimum(per_mode, share)
    ident = identifiability(cand.J, names)
    if ident.not_identifiable:
        names = ident.identifiable
    S = characteristic_scales(r)
    Js = _information(cand.J, [NAMES.index(x) for x in names], S, point_std, reading_std)
    chosen, spaced = _d_optimal(Js, cand.modes, cand.P, int(count), float(spacing),
                                passes, quota)
    o = _visiting_order(cand, chosen, mode_names, canonical_working_mode(start_mode))
    obs = observability(cand.J[o], names, S)
    msg = (f"{count} poses in {len(set(cand.modes[o].tolist()))} working modes{where} from "
           f"{n_c} candidates: O1 {obs.o1:.4g}, O3 {obs.o3:.4g}, condition number "
           f"{obs.condition_number:.4g}")
    if not spaced:
        msg += f"; fewer candidates than poses {1e3 * spacing:.3g} mm apart: spacing relaxed"
    if missing:
        msg += (f"; working mode{'s' if len(missing) > 1 else ''} {', '.join(missing)} "
                f"asked for but without a pose{where or ' in the workspace'} (assembly "
                f"{'up' if sign > 0 else 'down'}, margin {margin:g} from the singularities)")
    status = 2 if missing else 0 if spaced else 1
    return PoseSelection(tuple(mode_names[i] for i in cand.modes[o]),
                         "up" if sign > 0 else "down",
                         cand.q[o] - nominal.offsets, cand.P[o], cand.type1[o],
                         cand.type2[o], tuple(names), obs, "O1", n_c, status, msg, missing,
                         box)


def _checked_parameters(frame: str, count: int, margin: float, resolution: int,
                        modes: Sequence[str]) -> tuple[str, ...]:
    """The parameters of a calibration in ``frame``, the request of :func:`select_poses`
    checked (:class:`ParameterError` naming what is wrong)."""
    if frame not in ("instrument", "robot"):
        raise ParameterError(f"frame {frame!r} must be 'instrument' or 'robot'")
    names = NAMES if frame == "instrument" else ROBOT
    if not (isinstance(count, (int, np.integer)) and count >= 2 * len(names)):
        raise ParameterError(f"{count!r} poses: a calibration of {len(names)} parameters "
                             f"needs at least {2 * len(names)}")
    if not (math.isfinite(margin) and 0.0 <= margin < 1.0):
        raise ParameterError(f"singularity margin {number_words(margin)} must be in [0, 1)")
    if not 10 <= resolution <= 1001:
        raise ParameterError(f"pose grid resolution {resolution} must be in 10 ... 1001")
    if not modes:
        raise ParameterError("no working mode to choose poses in")
    return names


def _information(J: Array, idx: Sequence[int], S: Array, point_std: float | None,
                 reading_std: float | None) -> Array:
    """The candidates' scaled Jacobians (c, 2, k) of the parameters ``idx`` (scales ``S``),
    whitened by each one's covariance ``sigma^2 I + s_r^2 J_q J_q^T`` (times ``sigma``)
    when both noises are given (step 2 of the module doc)."""
    Js = np.ascontiguousarray(J[:, :, idx] * S[idx])  # (fancy indexing leaves it strided)
    if point_std is None or reading_std is None:
        return Js
    Jq = J[:, :, 5:7]
    Sig = point_std ** 2 * np.eye(2) + reading_std ** 2 * np.einsum("cik,cjk->cij", Jq, Jq)
    Lc = np.linalg.cholesky(Sig)
    return np.asarray(np.linalg.solve(Lc, Js) * point_std)


def _visiting_order(cand: _Candidates, chosen: Array, mode_names: Sequence[str],
                    start: str) -> Array:
    """The chosen candidates' indices in visiting order (step 3 of the module doc): the
    modes in Gray-code order from ``start``, each mode's poses by a tour from where the
    previous mode's ended."""
    order: list[int] = []
    prev = None
    for m in _gray_order([mode_names[i] for i in cand.modes[chosen]], start):
        sel = chosen[cand.modes[chosen] == mode_names.index(m)]
        q = cand.q[sel]
        begin = q[0] if prev is None else prev
        tour = _tour(q, begin)
        order.extend(int(sel[t]) for t in tour)
        prev = q[tour[-1]]
    return np.array(order)
