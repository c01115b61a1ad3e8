"""The limits as rows of the transcription, at any motion, with their gradients in the states
at the knots and the duration (the linearisation each linear programme takes)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..._arrays import Array
from ..._compiled import usable
from ..constraints import (
    AccelerationLimit,
    Constraint,
    DegeneracyCondition,
    JerkLimit,
    PointRows,
    SpeedLimit,
    Tangent,
    TorqueLimit,
    TorqueRateLimit,
    TorqueSpeedEnvelope,
    point_rows,
    speed_cap,
)
from .mesh import Mesh, Motion, knot_T
from .table import DA, DB, DG, Q1, Q2, Q3, A, B, Table, interp

try:  # the rows compiled (_rows.c), built by pip where a C compiler is
    from . import _rows as _compiled
except ImportError:  # pragma: no cover - installed without a C compiler: the numpy rows
    _compiled = None  # type: ignore[assignment]  # the module or None, as USE_COMPILED says

#: The compiled rows' interface this module calls (``ROWS_VERSION`` in _rows.c): a build of
#: another version (an old one left in place) is not used.
ROWS_VERSION = 5
if not usable(_compiled, ROWS_VERSION):
    _compiled = None  # type: ignore[assignment]  # an old build: the numpy rows instead

#: Whether the rows are built compiled (where it was built): False builds them with numpy
#: (the same rows to rounding, the same bits where the C library's ``pow`` and ``cosh`` are
#: numpy's; the tests compare the two).
USE_COMPILED = _compiled is not None

#: The second-order rows are at the inner knots and the intervals' middles, and at their
#: first and third quarters where they are near their limits (above ``-QUARTER_NEAR``, in
#: units of the limit) and bulge above the chord of the rows on either side (the
#: interval's start and middle, or middle and end) by more than ``QUARTER_BULGE``: a
#: limit's use between points a quarter of an interval apart exceeds theirs by a quarter
#: of what points at the middles allow, about the check's tolerance at the knots' density
#: of :func:`.start.fractions` (a pick-and-place move whose torque passed the envelope by
#: 0.23 % between a middle and a knot, refined: now within it); a row no more curved than
#: that (an acceleration along a constant jerk) adds nothing, and the interior point's
#: iterations grow with such rows (10 for 8 on that move).
QUARTER_NEAR = 0.02
QUARTER_BULGE = 1e-4
#: An interval's middle rows, of the second and the third order, are kept only where they
#: bulge above the chord of the same rows at its start and end by more than this (in units
#: of the limit; the first and last intervals keep theirs: the path's ends have no
#: second-order rows). A row no more curved than that is within ``MIDDLE_BULGE`` of the
#: larger of the rows at the ends, which the programme holds; on a fine mesh nearly every
#: middle is such a row, and a near copy of its neighbours: with the limit reached along a
#: stretch, three nearly parallel rows an interval, on which the interior point takes
#: short steps. Measured (``bench_smooth.py scaling``, and the refined chain): the rows
#: 30 % fewer, the same plans (the line's durations to 2e-8), the interior point's
#: iterations 10-25 % fewer, the chain's CPU time 29 % less (six sizes); 80 random corners'
#: durations the same on average (-0.05 % and +0.02 % on two seeds, CPU -2.5 % and -6.5 %).
MIDDLE_BULGE = 1e-4
#: Intervals whose rows are built at once (the temporaries of a block are a few hundred
#: bytes a row).
CHUNK = 2048


@dataclass(frozen=True)
class Rows:
    """The rows ``F <= 0`` (R,) at a motion, each at a point of an interval ``k`` (R,), and
    their gradients in the LP's variables of that interval: ``C`` (R, 5) in ``sigma_k, w_k,
    alpha_k, alpha_k+1, T`` (the jerk of the interval is ``(alpha_k+1 - alpha_k) / h``).

    Each row is its limit's polynomial form (``pu alpha + px w^2 - ph T^2``, ``q' J + ...
    - j_max T^3``) over a normalisation ``norm`` (R,) taken at the motion (its limit's scale:
    ``|ph| T^2``, ``j_max T^3``): the gradients keep the normalisation fixed, so the linear
    model is the polynomial form's, whose dependence on ``T`` is concave (a tangent above
    it: the model never underestimates a row when ``T`` shrinks)."""

    F: Array
    k: Array
    C: Array
    norm: Array
    sizes: Array  # (R, 5) float32: |d/d sigma|, |d/d w|, |d/d alpha|, |d/d J|, |d/d T|
    kinds: tuple[tuple[str, int], ...] = ()  # (what, how many) per block (development)

    def kind_of(self, i: int) -> str:
        """The block row ``i`` belongs to (for the log)."""
        for name, n in self.kinds:
            if i < n:
                return name
            i -= n
        return "?"

    def scaling(self) -> tuple[float, float]:
        """The factor on the durations that brings every scaling row's use to its limit if
        each scaled exactly as its power ``p`` (how its use scales with ``1 / T`` for a fixed
        normalised motion, about: the speed cap 1, the torques and accelerations 2, the
        third-order limits 3; 0 for the rows that do not scale): the largest
        ``max(1 + F, 0) ^ (1 / p)``; and the power of the largest row."""
        tops, exps = [], []
        at, i, p_worst = 0, int(np.argmax(self.F)), 0.0
        for name, n in self.kinds:
            p = _power(name)
            if at <= i < at + n:
                p_worst = p
            if p > 0 and n > 0:  # (x^(1/p) grows with x: each block's largest row)
                tops.append(self.F[at:at + n].max())
                exps.append(1.0 / p)
            at += n
        if not tops:
            return 1.0, p_worst
        use = np.maximum(np.array(tops) + 1.0, 0.0)
        return float(np.max(use ** np.array(exps))), p_worst

    def linear(self, d_sigma: Array, d_w: Array, d_alpha: Array, d_alpha_end: Array,
               d_T: Array) -> Array:
        """The rows' linear model after a change of the knots' states (M + 1,), of the
        intervals' end accelerations in their own normalisation and of their durations
        (M,)."""
        k, C = self.k, self.C
        return np.asarray(self.F + C[:, 0] * d_sigma[k] + C[:, 1] * d_w[k]
                          + C[:, 2] * d_alpha[k] + C[:, 3] * d_alpha_end[k]
                          + C[:, 4] * d_T[k])


def compiled_monitor(grid: Array, lo: Array, hi: Array, s: Array, v: Array, a: Array,
                     kinds: Sequence[float], lims: Sequence[Array], dt: float
                     ) -> Array | None:
    """:func:`.start.fractions`' monitor by the compiled rows (``monitor`` of _rows.c, the
    same arithmetic as its numpy code), or None where they are not used."""
    if not (USE_COMPILED and _compiled is not None and len(s) >= 2 and len(kinds)):
        return None
    out = np.empty(len(s))
    g, lo, hi, s, v, a, k, lim = (np.ascontiguousarray(x, dtype=float) for x in (
        grid, lo, hi, s, v, a, kinds, np.concatenate([np.broadcast_to(x, (2,)) for x in lims])))
    _compiled.monitor(g, lo, hi, s, v, a, k, lim, float(dt), out)
    return out


def local(h: Array, k: Array, theta: Array, gs: Array, gw: Array, ga: Array, gj: Array,
           gT: Array) -> tuple[Array, Array]:
    """A row's gradient ``C`` (n, 5) in its interval's ``sigma_k, w_k, alpha_k``, end
    acceleration and duration ``T_k`` (all in the interval's normalisation) from its
    derivatives in the point's ``sigma, w, alpha``, the interval's jerk ``J`` and ``T_k``
    (each (n,)), the point ``theta`` into the interval ``k``; and those derivatives'
    sizes (n, 5) float32, for the bound of the row's change in a trust region."""
    cJ = gs * theta**3 / 6 + gw * theta**2 / 2 + ga * theta + gj
    ca = gs * theta**2 / 2 + gw * theta + ga
    hk = h[k]
    C = np.empty((len(k), 5))
    C[:, 0] = gs
    C[:, 1] = gs * theta + gw
    C[:, 3] = cJ / hk
    C[:, 2] = ca - C[:, 3]
    C[:, 4] = gT
    sizes = np.empty((len(k), 5), np.float32)  # (each cast once, as astype would)
    for i, g in enumerate((gs, gw, ga, gj, gT)):
        sizes[:, i] = np.abs(g)
    return C, sizes


def _second_values(vals: Array, m: int, al: Array, w: Array, T: Array, phmax: float
                   ) -> tuple[Array, Array]:
    """The second-order rows' values (n, m) and their normalisations from their columns
    ``vals`` (n, 4 m + ...) at points of the states ``al, w`` and durations ``T`` (n,):
    ``(pu alpha + px w^2 - ph T^2) / c``, ``c = max(|ph|, floor) T^2``."""
    pu, px, ph = vals[:, :m], vals[:, m:2 * m], vals[:, 2 * m:3 * m]
    a_, w_, T_ = al[:, None], w[:, None], T[:, None]
    c = np.maximum(np.abs(ph), 1e-9 * phmax + 1e-300) * T_ * T_
    return np.asarray((pu * a_ + px * w_ * w_ - ph * T_ * T_) / c), np.asarray(c)


def _power(kind: str) -> float:
    """How a block of rows' use scales with ``1 / T`` (:meth:`Rows.scaling`)."""
    return {"second-order": 2.0, "cap": 1.0, "w>=0": 0.0}.get(kind, 3.0)


def columns(pr: PointRows, root_cap: Array | None) -> tuple[Array, int, float]:
    """The second-order rows' columns at the table's points, side by side (N + 1, 4 m + 1):
    ``pu``, ``px``, ``ph`` (0 where it is not finite), whether it is finite (1.0 or 0.0),
    then the speed cap's root (with one); their number ``m``, and the largest finite
    ``|ph|``."""
    finite = np.isfinite(pr.ph)
    phmax = float(np.abs(np.where(finite, pr.ph, 0.0)).max(initial=0.0))
    cols = [pr.pu, pr.px, np.where(finite, pr.ph, 0.0), finite.astype(float)]
    if root_cap is not None:
        cols.append(root_cap[:, None])
    return np.concatenate(cols, axis=1), pr.pu.shape[1], phmax


def _compiled_columns(second: Sequence[Constraint], table: Table
                     ) -> tuple[Array, Array, Array] | None:
    """What the compiled :meth:`RowModel._columns` takes: the table's per-point columns and
    each constraint's kind (0 a torque limit, 1 the torque-speed envelope, 2 an
    acceleration limit) and limits; None where a constraint is of another class (its own
    ``rows``: a plugin's, or a subclass's)."""
    def pair(v: object) -> Array:
        return np.broadcast_to(np.asarray(v, float), (2,))

    co = table.moving
    kinds: list[float] = []
    pars: list[Array] = []
    for c in second:
        if type(c) is TorqueLimit:
            kinds.append(0.0)
            pars.append(np.concatenate([pair(c.peak), np.zeros(4)]))
        elif type(c) is TorqueSpeedEnvelope:
            kinds.append(1.0)
            pars.append(np.concatenate([pair(x) for x in (c.peak, c.max_speed, c.knee)]))
        elif type(c) is AccelerationLimit:
            kinds.append(2.0)
            pars.append(np.concatenate([pair(c.max_acceleration), np.zeros(4)]))
        elif type(c) is SpeedLimit or (type(c) is DegeneracyCondition and not co.conditions):
            continue  # (no rows at the points)
        else:
            return None
    if not kinds:
        return None
    up, down = co.friction_sides
    inner = slice(1, -1)
    pts = np.concatenate([x[inner] for x in (
        co.a, co.b, co.g, co.dq_ds, co.ddq_ds, up, down, co.viscous * np.abs(co.dq_ds),
        np.broadcast_to(np.asarray(co.coulomb, float), co.dq_ds.shape))], axis=1)
    return (np.ascontiguousarray(pts, dtype=float), np.array(kinds),
            np.ascontiguousarray(np.concatenate(pars), dtype=float))


def _key(mo: Motion) -> tuple[Array, ...]:
    """What the rows at a motion depend on (with the row model's mesh, table and limits)."""
    return (mo.J, mo.Tk, mo.sigma, mo.w, mo.alpha, mo.w_end, mo.alpha_end)


class RowModel:
    """The rows of the transcription at any motion (see the module doc)."""

    def __init__(self, mesh: Mesh, table: Table, second: Sequence[Constraint],
                 third: Sequence[Constraint], length: float) -> None:
        self.mesh, self.table, self.length = mesh, table, length
        self.second, self.third = list(second), list(third)
        M, h = mesh.M, mesh.h
        k = np.arange(M)
        # the points of the second-order rows: the inner knots and every interval's middle,
        # then its first and third quarters (see :data:`QUARTER_NEAR`)
        self.k2 = np.concatenate([k[1:], k, k, k])
        self.t2 = np.concatenate([np.zeros(M - 1), h / 2, h / 4, 3 * h / 4])
        self.quarter = np.arange(len(self.k2)) >= 2 * M - 1
        cap = speed_cap(second, table.co)
        self._grad = True
        self._kept: dict[tuple[int, int, int], tuple[Any, ...]] = {}
        self._last: tuple[tuple[Array, ...], Rows] | None = None
        self.root_cap = (None if not np.isfinite(cap).any()
                         else np.sqrt(np.where(np.isfinite(cap), cap, 1e300)))
        self._spec = _compiled_columns(self.second, table)
        # the third-order limits as the compiled rows take them: kind (0 jerk, 1 torque
        # rate), limits, and the friction (viscous, Coulomb, its regularisation speed)
        spec = [(0.0, c.max_jerk) if isinstance(c, JerkLimit) else (1.0, c.max_torque_rate)
                for c in self.third if isinstance(c, (JerkLimit, TorqueRateLimit))]
        co = table.co
        self._third_spec = (np.array([kind for kind, _ in spec], float),
                            np.array([np.broadcast_to(np.asarray(lim, float), (2,))
                                      for _, lim in spec], float).reshape(-1),
                            np.concatenate([np.broadcast_to(np.asarray(co.viscous, float), (2,)),
                                            np.broadcast_to(np.asarray(co.coulomb, float), (2,)),
                                            [float(co.coulomb_speed)]]))

    def tangent(self, mo: Motion) -> Array:
        """The tangent points of the speed-dependent bounds on the grid: the motion's squared
        speeds (floored at 1e-4 of the largest: a tangent above the speed is still an upper
        bound, and near rest the viscous torque it bounds is small)."""
        x = (np.maximum(mo.w, 0.0) / knot_T(mo.Tk)) ** 2
        x0 = np.interp(self.table.s, mo.sigma, x)
        return np.asarray(np.maximum(x0, 1e-4 * float(x0.max()) + 1e-300))

    def rows(self, mo: Motion, gradients: bool = True, keep: bool = False) -> Rows:
        """All rows at the motion, normalised by their limits (at its durations), built
        :data:`CHUNK` intervals at a time (their temporaries bounded); without
        ``gradients``, their values only (``C`` and ``sizes`` empty). With ``keep``, they
        are kept until the next call, which returns them (and lets them go) if it asks for
        the same motion (its jerks, durations and knots' states equal) and no more."""
        kept, self._last = self._last, None
        if kept is not None and (kept[1].C.shape[0] == kept[1].F.shape[0] or not gradients) \
                and all(np.array_equal(x, y) for x, y in zip(kept[0], _key(mo), strict=True)):
            return kept[1]
        del kept  # (one set at a time)
        out = self._rows(mo, gradients)
        if keep:
            self._last = (_key(mo), out)
        return out

    def _rows(self, mo: Motion, gradients: bool) -> Rows:
        """All rows at the motion (:meth:`rows`)."""
        self._grad = gradients
        cols, m, phmax = self._columns(self.tangent(mo))
        spans = [(k0, min(k0 + CHUNK, self.mesh.M)) for k0 in range(0, self.mesh.M, CHUNK)]
        if USE_COMPILED and _compiled is not None:
            return self._compiled_rows(mo, cols, m, phmax, spans)
        parts = [self._block(mo, cols, m, phmax, k0, k1) for k0, k1 in spans]
        if len(parts) == 1:
            return parts[0]
        return Rows(np.concatenate([r.F for r in parts]), np.concatenate([r.k for r in parts]),
                    np.concatenate([r.C for r in parts]),
                    np.concatenate([r.norm for r in parts]),
                    np.concatenate([r.sizes for r in parts]),
                    tuple(kind for r in parts for kind in r.kinds))

    def _columns(self, x0: Array) -> tuple[Array, int, float]:
        """The second-order rows' columns at the table's points with the tangent points
        ``x0`` (:func:`columns`): compiled for the built-in constraints where built (the
        same operations in the same order as their ``rows``; a few hundred array operations
        of a few hundred points each cost more than their arithmetic), else by the
        constraint objects."""
        if USE_COMPILED and _compiled is not None and self._spec is not None:
            pts, kinds, pars = self._spec
            m = 4 * len(kinds)
            root = (np.zeros(0) if self.root_cap is None
                    else np.ascontiguousarray(self.root_cap, dtype=float))
            cols = np.empty((len(x0), 4 * m + (0 if self.root_cap is None else 1)))
            phmax = _compiled.columns(pts, np.ascontiguousarray(x0, dtype=float), kinds, pars,
                                     root, cols, m, int(self.root_cap is not None))
            return cols, m, phmax
        pr = point_rows(self.second, Tangent(self.table.moving,
                                             np.concatenate([x0[:1], x0, x0[-1:]])))
        return columns(PointRows(pr.pu[1:-1], pr.px[1:-1], pr.ph[1:-1]), self.root_cap)

    def _loc(self, h: Array, k: Array, theta: Array, gs: Array, gw: Array, ga: Array,
             gj: Array, gT: Array, keep: Array | None = None) -> list[Array]:
        """The arguments of :func:`local` after ``h`` for the rows (those ``keep`` selects),
        or none when the rows are built without their gradients: every block's are joined
        for one call (:meth:`_gradients`: elementwise, the same as a call per block)."""
        if not self._grad:
            return []
        args = [k, theta, gs, gw, ga, gj, gT]
        return args if keep is None else [a[keep] for a in args]

    def _gradients(self, blocks: list[list[Array]]) -> tuple[Array, Array]:
        """``C`` (R, 5) and the sizes (R, 5) float32 of the blocks' rows (:meth:`_loc`)."""
        blocks = [b for b in blocks if b]
        if not blocks:
            return np.zeros((0, 5)), np.zeros((0, 5), np.float32)
        return local(self.mesh.h, *(np.concatenate([b[i] for b in blocks]) for i in range(7)))

    def _points(self, k0: int, k1: int, m: int) -> tuple[Any, ...]:
        """The points of the intervals ``k0`` to ``k1`` (excluded), the same at every motion
        (kept): the second-order rows' intervals and offsets, and which are quarters, each
        repeated for the ``m`` rows at a point; the intervals; the third-order rows'
        intervals, offsets and which are at an interval's end."""
        key = (k0, k1, m)
        if key not in self._kept:
            in2 = (self.k2 >= k0) & (self.k2 < k1)
            k, th = self.k2[in2], self.t2[in2]
            kM = np.arange(k0, k1)
            n1 = k1 - k0
            h = self.mesh.h
            on = ~self.quarter[in2]  # (the first points: the knots and the middles)
            self._kept[key] = (k, th, np.repeat(k, m), np.repeat(th, m),
                               np.repeat(~on, m), int(on.sum()), kM,
                               np.concatenate([kM, kM, kM]),
                               np.concatenate([np.zeros(n1), h[kM] / 2, h[kM]]),
                               np.arange(3 * n1) >= 2 * n1)
        return self._kept[key]

    def _second_F(self, mo: Motion, cols: Array, m: int, phmax: float, k: Array, th: Array
                  ) -> Array:
        """The second-order rows' values (n, m) at offsets ``th`` into the intervals ``k``
        (n,), as :meth:`_block` makes them."""
        sig, w, al = mo.at(self.mesh, k, th)
        return _second_values(interp(self.table.s, cols, sig)[0], m, al, w, mo.Tk[k],
                              phmax)[0]

    def _block(self, mo: Motion, cols: Array, m: int, phmax: float, k0: int, k1: int
               ) -> Rows:
        """The rows of the intervals ``k0`` to ``k1`` (excluded), from the second-order
        rows' ``m`` columns at the table's points (:func:`columns`)."""
        if USE_COMPILED and _compiled is not None:
            return self._compiled_rows(mo, cols, m, phmax, [(k0, k1)])
        mesh, tab, S = self.mesh, self.table, self.length
        h = mesh.h
        k, th, kk, tt, quarter, n2, kM, k3, th3, end3 = self._points(k0, k1, m)
        sig, w, al = mo.at(mesh, k, th)
        # the rows' coefficients, whether each is finite, and the speed cap's root: one
        # interpolation (each column's arithmetic as apart)
        vals, slopes = interp(tab.s, cols, sig)
        pu, px, ph = vals[:, :m], vals[:, m:2 * m], vals[:, 2 * m:3 * m]
        dpu, dpx, dph = slopes[:, :m], slopes[:, m:2 * m], slopes[:, 2 * m:3 * m]
        a_, w_, T = al[:, None], w[:, None], mo.Tk[k][:, None]
        F, c = _second_values(vals, m, al, w, mo.Tk[k], phmax)
        zero = np.zeros(len(kk))

        def flat(v: Array) -> Array:
            return np.asarray(v.reshape(-1))

        # the finite rows, at a quarter only those near their limits and above the chord of
        # the rows on either side (the interval's start and middle, or middle and end)
        kq = k[n2:]
        hq = h[kq]
        first = np.arange(len(kq)) < len(kq) // 2  # (the first quarters, then the third)
        fa = self._second_F(mo, cols, m, phmax, kq, np.where(first, 0.0, hq / 2))
        fb = self._second_F(mo, cols, m, phmax, kq, np.where(first, hq / 2, hq))
        bulge = np.concatenate([np.ones((n2, m), bool),
                                F[n2:] > (fa + fb) / 2 + QUARTER_BULGE]).reshape(-1)
        keep = (vals[:, 3 * m:4 * m] > 1 - 1e-12).reshape(-1) & (
            ~quarter | ((flat(F) > -QUARTER_NEAR) & bulge))
        # the middles (after the inner knots) only above the chord of the interval's ends
        # (the rows at its start and end: the first quarters' and the third quarters'
        # chords' own, kq being the intervals kM twice)
        mid = np.zeros((len(F), m), bool)
        mid[n2 - len(kM):n2] = ~self._middles_kept(kM, F[n2 - len(kM):n2], fa[:len(kM)],
                                                   fb[len(kM):])
        keep &= ~mid.reshape(-1)

        Cs = [self._loc(h, kk, tt, flat((dpu * a_ + dpx * w_ * w_ - dph * T * T) / c),
                        flat(2 * px * w_ / c), flat(pu / c), zero, flat(-2 * ph * T / c),
                        keep)]
        norms = [flat(np.broadcast_to(c, F.shape))[keep]]
        Fs, ks, names = [flat(F)[keep]], [kk[keep]], ["second-order"]
        k, th, w = k[:n2], th[:n2], w[:n2]  # (the speed's rows: at the knots and middles)
        if self.root_cap is not None:  # w <= sqrt(cap) T
            rv, rs = vals[:n2, 4 * m], slopes[:n2, 4 * m]
            T = mo.Tk[k]
            c2 = np.maximum(rv, 1e-300) * T
            Fc = (w - rv * T) / c2
            Fs.append(Fc)
            Cs.append(self._loc(h, k, th, -rs * T / c2, 1.0 / c2, np.zeros(n2),
                                np.zeros(n2), -rv / c2))
            norms.append(c2)
            ks.append(k)
            names.append("cap")
        Fs.append(-w / S)  # the speed stays >= 0
        norms.append(np.full(n2, S))
        Cs.append(self._loc(h, k, th, np.zeros(n2), np.full(n2, -1.0 / S), np.zeros(n2),
                            np.zeros(n2), np.zeros(n2)))
        ks.append(k)
        names.append("w>=0")
        # the third-order rows at every interval's start, middle and end (at its end, the
        # table's segment before the point; at the middle only above the chord of the
        # others, see MIDDLE_BULGE), all at once
        sig, w, al = mo.at(mesh, k3, th3)
        v, d = tab.at(sig, end3)
        F3, C3, kk3, n3 = self._third_at(mo, k3, th3, v, d, w, al)
        norms.append(n3)
        Fs.append(F3)
        Cs.extend(C3)
        ks.append(kk3)
        names.append("third")
        C, sizes = self._gradients(Cs)
        del Cs
        return Rows(np.concatenate(Fs), np.concatenate(ks).astype(np.int32), C,
                    np.concatenate(norms), sizes,
                    tuple((n, len(f)) for n, f in zip(names, Fs, strict=True)))

    def _middles_kept(self, k: Array, mid: Array, start: Array, end: Array) -> Array:
        """Which rows ``mid`` (n, columns) at the middles of the intervals ``k`` (n,) are
        kept: those above the chord of the same rows at the intervals' ``start`` and ``end``
        by more than :data:`MIDDLE_BULGE`, and all of the mesh's first and last intervals."""
        outer = (k == 0) | (k == self.mesh.M - 1)
        return np.asarray(outer[:, None] | (mid > (start + end) / 2 + MIDDLE_BULGE))

    def _room(self, m: int, k0: int, k1: int) -> int:
        """The most rows the intervals ``k0`` to ``k1`` (excluded) can have (_rows.c's
        bound)."""
        nint = k1 - k0
        n2 = max(k1 - max(k0, 1), 0) + nint  # (knots and middles; the quarters 2 nint)
        cap = self.root_cap is not None
        return (n2 + 2 * nint) * m + (n2 if cap else 0) + n2 + 12 * nint * len(
            self._third_spec[0])

    def _empty(self, n: int) -> tuple[Array, Array, Array, Array, Array]:
        """Room for ``n`` rows: ``F, norm, k, C, sizes`` (the gradients only where asked)."""
        g = n if self._grad else 0
        return (np.empty(n), np.empty(n), np.empty(n, np.int32), np.empty((g, 5)),
                np.empty((g, 5), np.float32))

    def _cut(self, out: tuple[Array, Array, Array, Array, Array], n: int,
             names: tuple[tuple[str, int], ...]) -> Rows:
        """The first ``n`` rows of ``out`` as :class:`Rows` (the room for rows left out, a
        limit not finite or a quarter not near its limit, given back in place: no copy)."""
        F, norm, k, C, sizes = out
        for x in (F, norm, k):
            x.resize(n, refcheck=False)
        for g in (C, sizes):
            g.resize((n if self._grad else 0, 5), refcheck=False)
        return Rows(F, k, C, norm, sizes, names)

    def _compiled_rows(self, mo: Motion, cols: Array, m: int, phmax: float,
                       spans: list[tuple[int, int]]) -> Rows:
        """The rows of the intervals ``k0`` to ``k1`` (excluded) of each of ``spans`` by
        the compiled rows (_rows.c: :meth:`_block`'s rows in its order), written into one
        set of arrays, each block after the rows before it, then cut in place (joining the
        blocks' arrays afterwards cost as much as a tenth of a 16k-knot plan: a copy of
        every row, four times a programme)."""
        out = self._empty(sum(self._room(m, k0, k1) for k0, k1 in spans))
        kinds: list[tuple[str, int]] = []
        at = 0
        for k0, k1 in spans:
            n, names = self._block_compiled(mo, cols, m, phmax, k0, k1, out, at)
            at += n
            kinds.extend(names)
        return self._cut(out, at, tuple(kinds))

    def _block_compiled(self, mo: Motion, cols: Array, m: int, phmax: float, k0: int,
                        k1: int, out: tuple[Array, Array, Array, Array, Array], at: int
                        ) -> tuple[int, tuple[tuple[str, int], ...]]:
        """The compiled rows of the intervals ``k0`` to ``k1`` (excluded) written into
        ``out`` from row ``at`` (its room for them, :meth:`_room`): how many, and their
        kinds."""
        assert _compiled is not None
        tab = self.table
        kinds, lims, fric = self._third_spec
        cap = self.root_cap is not None
        rmax = self._room(m, k0, k1)
        grad = self._grad
        F, norm, k = (x[at:at + rmax] for x in out[:3])
        C, sizes = (g[at:at + rmax] if grad else g for g in out[3:])

        def f64(x: Array) -> Array:
            return np.ascontiguousarray(x, dtype=float)

        n_second, n_cap, n_w, n_third = _compiled.block(
            f64(tab.s), f64(cols), f64(tab.lo), f64(tab.hi),
            f64(self.mesh.h), f64(mo.J), f64(mo.Tk), f64(mo.sigma), f64(mo.w), f64(mo.alpha),
            kinds, lims, fric, F, norm, C, k, sizes, m, int(cap), k0, k1,
            1e-9 * phmax + 1e-300, self.length, -1.0 / self.length, QUARTER_NEAR,
            QUARTER_BULGE, MIDDLE_BULGE, grad)
        R = n_second + n_cap + n_w + n_third
        return R, (("second-order", n_second), *([("cap", n_cap)] if cap else []),
                   ("w>=0", n_w), ("third", n_third))

    def _third_at(self, mo: Motion, k: Array, theta: Array, v: Array, d: Array, w: Array,
                  al: Array) -> tuple[Array, list[list[Array]], Array, Array]:
        """The joint jerk and torque-rate rows, on both sides of each limit, at offsets
        ``theta`` into the intervals ``k`` (n,: their starts, then middles, then ends, as
        :meth:`_points` gives them; the middles within :data:`MIDDLE_BULGE` of their chord
        left out), with the table's columns ``v`` and slopes ``d`` (n, 18) and the states
        ``w, al`` (n,) there: rows, their gradients' arguments (:meth:`_loc`), intervals,
        normalisations."""
        T = mo.Tk[k][:, None]
        h = self.mesh.h
        q1, q2, q3 = v[:, Q1], v[:, Q2], v[:, Q3]
        dq1, dq2, dq3 = d[:, Q1], d[:, Q2], d[:, Q3]
        jj, ww, aa = mo.J[k][:, None], w[:, None], al[:, None]
        Fs: list[Array] = []
        Cs: list[list[Array]] = []
        Ns: list[Array] = []
        Ks: list[Array] = []
        for c in self.third:
            if isinstance(c, JerkLimit):
                lim = np.asarray(c.max_jerk, float)
                val = q1 * jj + 3 * q2 * ww * aa + q3 * ww**3
                if self._grad:
                    gs = dq1 * jj + 3 * dq2 * ww * aa + dq3 * ww**3
                    gw = 3 * q2 * aa + 3 * q3 * ww * ww
                    ga = 3 * q2 * ww
                    gj = q1
                    gT = np.zeros_like(val)
            elif isinstance(c, TorqueRateLimit):
                lim = np.asarray(c.max_torque_rate, float)
                a, b = v[:, A], v[:, B]
                da, db, dg = v[:, DA], v[:, DB], v[:, DG]
                co = self.table.co
                vs = co.coulomb_speed
                # the friction's slope in the joint speed at the motion's speed (held in the
                # linearisation: near a reversal the regularised Coulomb torque's is steep)
                cf = co.viscous + co.coulomb / vs / np.cosh(np.clip(q1 * ww / T / vs,
                                                                    -300, 300)) ** 2
                acc = q1 * aa + q2 * ww * ww  # T^2 qddot
                val = (a * jj + (da + 2 * b) * ww * aa + db * ww**3 + dg * ww * T * T
                       + cf * acc * T)
                if self._grad:
                    gs = (d[:, A] * jj + (d[:, DA] + 2 * d[:, B]) * ww * aa
                          + d[:, DB] * ww**3 + d[:, DG] * ww * T * T
                          + cf * (dq1 * aa + dq2 * ww * ww) * T)
                    gw = ((da + 2 * b) * aa + 3 * db * ww * ww + dg * T * T
                          + cf * 2 * q2 * ww * T)
                    ga = (da + 2 * b) * ww + cf * q1 * T
                    gj = a
                    gT = 2 * dg * ww * T + cf * acc
            else:
                continue
            scale = lim * T**3
            kk, tt = np.repeat(k, 2), np.repeat(theta, 2)
            for sign in (1.0, -1.0):
                F = ((sign * val - scale) / scale).reshape(-1)
                keep = self._third_middles(F, k)
                Fs.append(F[keep])
                Ns.append(np.broadcast_to(scale, val.shape).reshape(-1)[keep])
                Ks.append(kk[keep])
                if not self._grad:
                    continue
                g_s, g_w, g_a, g_j = ((sign * x / scale).reshape(-1) for x in (gs, gw, ga, gj))
                Cs.append(self._loc(h, kk, tt, g_s, g_w, g_a, g_j,
                                    ((sign * gT - 3 * lim * T * T) / scale).reshape(-1),
                                    keep))
        if not Fs:
            return np.zeros(0), [], np.zeros(0, int), np.zeros(0)
        return np.concatenate(Fs), Cs, np.concatenate(Ks), np.concatenate(Ns)

    def _third_middles(self, F: Array, k: Array) -> Array:
        """Which of a limit's third-order rows ``F`` (3 n, 2 joints: the intervals ``k``'
        starts, middles, then ends) are kept: all but the middles within
        :data:`MIDDLE_BULGE` of their chord (the first and last intervals' kept)."""
        n = len(k) // 3
        F3 = F.reshape(3, n, 2)
        keep = np.ones((3, n, 2), bool)
        keep[1] = self._middles_kept(k[:n], F3[1], F3[0], F3[2])
        return np.asarray(keep.reshape(-1))
