"""The jerk-limited law's solve: the start, the sequential linear programmes, the output check
with its refinement, and the registered ``time-optimal`` builder that takes this law when
the motors have a third-order limit."""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from ..._arrays import Array, check_whole
from ...errors import InfeasibleError, ParameterError
from ...motors import MotorLimits
from ...units import Units
from ..base import Law
from ..constraints import (
    AccelerationLimit,
    Constraint,
    PathDynamics,
    SpeedLimit,
    motor_constraints,
)
from ..time_optimal import (
    TimeOptimalLaw,
    grid_points,
    solve_time_optimal_law,
    split_segments,
)
from .check import RATE_KINDS, check
from .law import JerkLimitedLaw
from .mesh import Mesh, integrate, make_mesh
from .rows import RowModel
from .slp import FEAS_TOL, RESTART_DELTA, START_DELTA, Run, slp, time_scaled
from .start import (
    CapConstraint,
    Start,
    filtered,
    fractions,
    pinned,
    ramp,
    slowed_to_cap,
    start_jerks,
    third_order_cap,
    without_idle,
)
from .table import CachedDynamics, Table, make_table

log = logging.getLogger(__name__)

#: Fewest intervals of constant jerk of the first transcription (more where the monitor of
#: :func:`.start.fractions` asks, and refined where the check needs).
SEGMENTS = 32
#: Segments of the second-order law that starts the search (a coarse grid: it only gives the
#: start motion, which the programmes improve; the whole grid where the coarse one finds no
#: motion, e.g. a blend narrower than its segments, or stops inside the path: see
#: :data:`COARSE_STOP`).
START_GRID = 40
#: Greatest number of linear programmes of one SLP run, and of a run that can be followed by
#: a re-timing (a motion far from the answer, on knots placed for its start, moves slowly:
#: placed anew for the motion reached, the programmes go faster).
MAX_PROGRAMMES = 24
FIRST_PROGRAMMES = 8
#: The knots' density: the rows between them within about this of their values there.
KNOT_TOL = 5e-3
#: Rounds of refinement after the output check, then of tightening, then of stretching the
#: motion in time (a slower motion, never a false "no motion").
MAX_REFINE = 3
MAX_TIGHTEN = 2
MAX_STRETCH = 6
#: Rounds of re-timing (a motion with idle time, or whose programmes had not settled, solved
#: again from it with the knots placed anew). Measured on 80 random blended corners
#: (``benchmarks/bench_smooth.py blends``): with 2 rounds 4-5 in 40 did not settle and the
#: durations were 1.6-2.1 % above the best of four budgets on average, up to 21-26 %; with 6
#: rounds 0-1 did not settle, 0.2-0.3 % on average, up to 4.3 %, for 13-15 % more CPU time
#: on those corners (the programs that settle are unchanged).
MAX_RETIME = 6
#: A run that settles faster than the motion its knots were placed for by more than this
#: factor, on knots fewer than its own motion's rows ask (:func:`.start.fractions` on it) by
#: more than it, is solved again on those (counted as a re-timing): knots placed for a slow
#: start (one slowed to the cap, :func:`_placed`) are too coarse for the faster motion the
#: programmes reach (the first test spares a short move the monitor's cost). Measured on
#: blended spirals of 28 to 224 lines (``bench_smooth.py length``, three starting angles
#: each): 7 of 12 plans 0.6 to 5.9 % faster, none slower, for 27 % more CPU time in all
#: (1.25: 6 of 12; without the first test one of them 2.2 % faster instead of 0.6 %, but
#: every settled move paid the monitor: a pick-and-place move 1.93 times the second-order
#: law's planning time instead of 1.78). Random corners: within the local search's spread.
REMESH = 1.1
#: Rounds of the start's cap (see :func:`_start`), and the excess over it accepted.
START_ROUNDS = 4
START_SLACK = 0.1
#: A start whose rows ask its whole time stretched this many times or more (a joint jerk
#: eight times its limit) is slowed instead where it passes the cap (see :func:`_placed`).
#: Measured on a new user's blended chains of 6 to 28 lines (6 mm blends): on a fine
#: program grid the filter passes the blends' ends at 3 times their cap, the factor is 2.02
#: to 2.56 and the plans came out 1.3 to 16 % faster with the slowing (the 28 lines at
#: grid 1600: 4.739 s -> 3.998 s, against 3.746 s at grid 400); below the gate nothing
#: changes. Slowing every start that passes the cap made those chains 1 to 28 % faster but
#: 240 random blended corners (factors 1.04 to 1.91, three seeds) 0.5 to 1.2 % slower on
#: average, more the larger the factor (1.7 % from 1.5 to 2): from a start slower where it
#: passes the cap the local search finds a slower motion there than from the start
#: stretched whole.
STRETCH_GATE = 2.0
#: Tolerance of the third-order ratios (finite differences) on the check samples.
RATE_TOL = 1e-2
#: How the use of each kind of limit falls when a motion is stretched in time (about
#: ``T^-p``; gravity and friction do not fall, so stretching repeats).
_POWERS = {"speed": 1.0, "torque": 2.0, "acceleration": 2.0, "jerk": 3.0, "torque_rate": 3.0}


def solve_jerk_limited_law(dynamics: PathDynamics, *, motors: MotorLimits | None = None,
                           constraints: Sequence[Constraint] | None = None,
                           segments: int = SEGMENTS, grid: int | Array = 400,
                           tol: float = 1e-3,
                           rate_tol: float = RATE_TOL,
                           units: Units | None = None) -> JerkLimitedLaw:
    """The fastest rest-to-rest law along a path, with zero acceleration at both ends, within
    the motors' limits including jerk and torque rate (see :mod:`dextar.laws.smooth`).

    The search is local (the problem is not convex). Where the jerk rules the motion (its
    duration above :data:`SECOND_START` times the second-order law's) a second search
    starts from the second-order law with the joint accelerations capped at
    :data:`CAP_FRACTION` of the first motion's peak, and the faster law is returned (its
    message says so).

    Parameters
    ----------
    dynamics : PathDynamics
        The robot along the path (gravity and friction included).
    motors : MotorLimits, optional
        The limits (peak torque, speed, envelope, acceleration, jerk, torque rate).
    constraints : sequence of Constraint, optional
        The limits as constraint objects (instead of ``motors``); one of them must limit the
        torques, one the jerk or the torque rate.
    segments : int
        Fewest intervals of constant jerk of the first transcription (at least 16; more
        where the path's dynamics change fast, refined where the check needs). A mesh more
        than :data:`COARSE` times finer than the rows ask is reached from searches on
        coarser ones (the law's ``solves`` counts their programmes too).
    grid : int or ndarray, shape (N + 1,)
        The coefficient table along the path: a number of equal segments or its arc lengths
        (from 0 to the length; the second-order start law takes every few of them); a
        composite path's joints are added (:func:`with_joints`).
    tol, rate_tol : float
        Allowed relative excess of a torque, speed or acceleration (``tol``) and of a jerk
        or torque rate (``rate_tol``) over its limit on the check samples.
    units : Units, optional
        Only for the words of an error.

    Returns
    -------
    JerkLimitedLaw
        With ``status`` and ``message``.

    Raises
    ------
    InfeasibleError
        No motion within the limits exists (the second-order law on the whole grid finds
        none: it names the point, the motor and the user's limit).
    ParameterError
        No limits, no third-order limit, or bad ``segments`` or tolerances.
    """
    if constraints is not None:
        cons = tuple(constraints)
    elif motors is not None:
        cons = motor_constraints(motors)
    else:
        raise ParameterError("a jerk-limited law needs the motors' limits (or constraints)")
    check_whole(segments, 16, "segments")
    if not (0 < tol < 1 and 0 < rate_tol < 1):
        raise ParameterError(f"tolerances {tol!r}, {rate_tol!r} must be in (0, 1)")
    if not any(c.order == 3 for c in cons):
        raise ParameterError("a jerk-limited law needs a jerk or torque-rate limit")
    table = make_table(dynamics, with_joints(dynamics, grid))
    first = _solve(dynamics, table, cons, int(segments), tol, rate_tol, units)
    law = first.law
    if law.status != 0:
        return law
    if law.duration <= SECOND_START * first.T2:
        return _within_a_tighter_jerk(dynamics, table, cons, first, int(segments), tol,
                                      rate_tol, units)
    # the jerk rules the motion: a second search from a start whose joint accelerations are
    # capped below the first motion's peak (the second-order law's are far above a
    # jerk-limited motion's, and its filtered start leads the programmes to a slower motion)
    js = dynamics.samples(law, np.linspace(0.0, law.duration, CHECK_SAMPLES))
    if js.ddq is None:
        return law
    peak = CAP_FRACTION * np.abs(js.ddq).max(axis=0)
    peak = np.where(peak > 0.0, peak, np.inf)  # (a joint that stays still: not capped)
    cap = AccelerationLimit((float(peak[0]), float(peak[1])), kind=CAP_KIND)
    try:
        other = _solve(dynamics, table, (*cons, cap), int(segments), tol, rate_tol, units)
    except InfeasibleError:
        return law
    both = first.programmes + other.programmes
    if other.law.status == 0 and other.law.duration < law.duration:
        ratio, excess = check(dynamics, cons, other.law, tol, rate_tol)  # the user's alone
        if not np.any(excess > 0):
            # its words: the user's limits (the cap's kind and its tightening left out) and
            # the second-order law of the first search (the capped one's is slower)
            scales = {k: v for k, v in other.scales.items() if k != CAP_KIND}
            note = (f"; from a second start, the joint accelerations capped at "
                    f"{CAP_FRACTION:g} of the first motion's peak ({law.duration:.6g} s from "
                    f"the first)")
            return _verdict(replace(other.last, ratio=ratio, bad=excess > 0), scales, both,
                            first.T2, note)
    return _verdict(first.last, first.scales, both, first.T2,
                    f"; a second start, the joint accelerations capped at {CAP_FRACTION:g} "
                    f"of the peak, found no faster motion")


def _within_a_tighter_jerk(dynamics: PathDynamics, table: Table, cons: Sequence[Constraint],
                           first: _Search, segments: int, tol: float, rate_tol: float,
                           units: Units | None) -> JerkLimitedLaw:
    """``first``'s law, or where its third-order limits (jerk, torque rate) all stay far
    above what it uses (it uses less than :data:`LOOSE_JERK` of each), the faster of it and
    a second search's within :data:`JERK_MARGIN` times what it used of each (a law within
    them is within the limits)."""
    law = first.law
    third = [c for c in cons if c.order == 3]
    used = {c.kind: law.ratios.get(c.kind, 1.0) for c in third}
    if not third or not all(0.0 < r < LOOSE_JERK for r in used.values()):
        return law
    cap = tuple(c.scaled({c.kind: JERK_MARGIN * used[c.kind]}) for c in third)
    try:
        other = _solve(dynamics, table, (*cons, *cap), segments, tol, rate_tol, units)
    except InfeasibleError:  # pragma: no cover - the first search found a motion within it
        return law
    both = first.programmes + other.programmes
    words = ", ".join(f"{r:.3g} of the {k.replace('_', ' ')} limit" for k, r in used.items())
    if other.law.status == 0 and other.law.duration < law.duration * (1.0 - GAIN):
        ratio, excess = check(dynamics, cons, other.law, tol, rate_tol)  # the user's alone
        if not np.any(excess > 0):
            note = (f"; from a second search within {JERK_MARGIN:g} times what the first "
                    f"motion used ({law.duration:.6g} s, {words})")
            return _verdict(replace(other.last, ratio=ratio, bad=excess > 0), other.scales,
                            both, first.T2, note)
    return _verdict(first.last, first.scales, both, first.T2,
                    f"; a second search within {JERK_MARGIN:g} times what it used ({words}) "
                    f"found no faster motion")


#: Where a law uses less than this fraction of each of its third-order limits, a second
#: search within :data:`JERK_MARGIN` times what it used (the faster returned, by more than
#: :data:`GAIN`): with limits far above what a motion needs, the knots are placed for
#: sharper changes of acceleration than the motion makes, and the law came out slower the
#: higher the limit (a line with a jerk limit of 1e7 rad/s^3, 0.71 of it used: 0.017 % above
#: the second-order law; with 1e8, 1e10 and 1e15: 0.10 %, 1.4 % and 1.6 % above it).
LOOSE_JERK = 0.1
JERK_MARGIN = 2.0
GAIN = 1e-6


#: A second search (see :func:`solve_jerk_limited_law`) where the first motion's duration is
#: above this multiple of the second-order law's (the jerk rules it), from the second-order
#: law with the joint accelerations capped at :data:`CAP_FRACTION` of the first motion's peak
#: (on :data:`CHECK_SAMPLES` samples); the faster of the two is returned (the cap only ever
#: narrows the limits). Measured on 40 random blended corners (``bench_smooth.py blends``):
#: the first search alone 4.5 % above the best of five starts on average, up to 12.9 %; the
#: faster of the two 1.1 %, up to 4.3 % (caps at 0.3 and 0.5 of the peak: 27 % and 8.7 %).
SECOND_START = 1.2
CAP_FRACTION = 0.7
CHECK_SAMPLES = 2001
CAP_KIND = "second start's acceleration cap"


@dataclass(frozen=True)
class _Search:
    """A search's law (with its verdict) and what its verdict was made of."""

    law: JerkLimitedLaw
    last: _Round
    scales: dict[str, float]
    programmes: int
    T2: float


def _solve(dynamics: PathDynamics, table: Table, cons: Sequence[Constraint], segments: int,
           tol: float, rate_tol: float, units: Units | None,
           first: tuple[TimeOptimalLaw, Start] | None = None) -> _Search:
    """One search of :func:`solve_jerk_limited_law` on the table, from the second-order law
    within ``cons`` filtered (``first``: that law and its start, made already)."""
    second = [c for c in cons if c.order == 2]
    third = [c for c in cons if c.order == 3]
    length = float(dynamics.length)
    if first is None:
        base = _second_order(dynamics, table, second, units)
        # the start: the second-order law, slower where the path's own third-order terms
        # (a blend's curvature changing fast) would use much of their limits at its speeds
        start = _start(dynamics, table, second, third, base, units)
    else:
        base, start = first
    T2 = float(base.duration)
    coarse = _coarser(dynamics, table, cons, base, start, segments, tol, rate_tol, units)
    split = None if coarse is None else coarse.split
    placed: RowModel | None = None
    if split is None:
        start, mesh, J, Tk, placed = _placed(start, table, cons, int(segments), length)
        placed_T = start.T  # (the duration of the motion the knots were placed for)
    else:  # its motion on its mesh split (the same motion), its duration brought within the
        # rows and the trust region of a motion near the answer
        mesh, J, Tk = split.mesh, split.run.J, split.run.Tk
        placed_T = float(split.law.duration)
    log.debug("%d knots; the path's joints at %s, pinned at knots %s", mesh.M + 1,
              table.joints, mesh.pins)
    scales = dict.fromkeys((c.kind for c in cons), 1.0)
    refined = tightened = stretched = retimed = 0
    programmes = 0 if coarse is None else coarse.search.programmes
    delta = START_DELTA if split is None else SPLIT_DELTA
    shares: dict[float, float] = {} if split is None else dict(split.run.shares)
    fresh = split is not None  # a new start: its duration brought within the rows first
    # (the split motion, where it passes the check, is the law to beat)
    best: _Round | None = split if split is not None and not split.bad.any() else None
    while True:
        model = placed if placed is not None else RowModel(
            mesh, table, [c.scaled(scales) for c in second],
            [c.scaled(scales) for c in third], length)
        placed = None  # (the start's rows, kept by time_scaled: the first programme's)
        if fresh:
            Tk = time_scaled(model, J, Tk)
            fresh = False
        run = slp(model, J, Tk, MAX_PROGRAMMES if retimed == MAX_RETIME else FIRST_PROGRAMMES,
                  delta, shares)
        shares = run.shares  # (the pinned knots' shares of the trust region: the next run's)
        if run.worst > FEAS_TOL:  # the programmes left a limit exceeded: slower instead
            run = replace(run, Tk=time_scaled(model, run.J, run.Tk, keep=False))
        delta = RESTART_DELTA
        programmes += run.programmes
        J, Tk = run.J, run.Tk
        law = _law(run, mesh, length, base)
        ratio, excess = check(dynamics, cons, law, tol, rate_tol)
        bad = excess > 0
        log.debug("check %s bad %d intervals %d T %.9g converged %s",
                  {k: round(v, 5) for k, v in ratio.items()}, int(bad.sum()), mesh.M,
                  law.duration,
                  run.converged)
        if not bad.any():
            if best is None or law.duration < best.law.duration:
                best = _Round(law, ratio, bad, mesh, run, refined, stretched)
            again = (without_idle(law, always=not run.converged) if retimed < MAX_RETIME
                     else None)
            asked = None
            if again is None and retimed < MAX_RETIME and law.duration * REMESH < placed_T:
                # settled, on knots placed for a slower motion than the one reached: again
                # on the knots its own rows ask, where they are many more
                own = without_idle(law, always=True)
                assert own is not None
                asked = fractions(own, table, cons, int(segments), KNOT_TOL)
                if len(asked) - 1 > REMESH * mesh.M:
                    log.debug("settled on %d intervals, its motion asks %d: again", mesh.M,
                              len(asked) - 1)
                    again = own
            if again is None:
                break
            # the motion stops somewhere (it reached a pinned knot early) or waits at the
            # end, or the programmes had not settled: again from it, with that time cut out
            # and the knots placed anew (denser where its rows change fast)
            retimed += 1
            if asked is None:
                asked = fractions(again, table, cons, int(segments), KNOT_TOL)
            mesh = pinned(asked, again, table.joints)
            J, Tk = start_jerks(again, mesh, length), np.full(mesh.M, again.T)
            placed_T = again.T
            log.debug("re-timed: %d knots, %.9g s", mesh.M + 1, again.T)
            fresh, delta, refined = True, START_DELTA, 0
            continue
        if refined < MAX_REFINE:
            # split the intervals where a limit is exceeded, into as many pieces as bring
            # an excess that falls with the square of the interval to a quarter of its
            # tolerance (the same motion: each piece keeps its interval's jerk)
            refined += 1
            pieces = np.where(bad, np.clip(np.ceil(np.sqrt(4 * excess)), 2, 8), 1).astype(int)
            mesh, J, Tk = _split(mesh, J, Tk, pieces)
            continue
        if tightened < MAX_TIGHTEN:
            tightened += 1
            for k, r in ratio.items():
                kt = rate_tol if k in RATE_KINDS else tol
                if r > 1 + kt:
                    scales[k] *= (1 + 0.25 * kt) / r
            continue
        # last: the same motion, slower, until the check passes (a motion within the limits
        # exists wherever holding still fits them)
        while bad.any() and stretched < MAX_STRETCH:
            stretched += 1
            factor = max((r / (1 + 0.5 * (rate_tol if k in RATE_KINDS else tol)))
                         ** (1 / _POWERS.get(k, 1.0)) for k, r in ratio.items())
            Tk = Tk * max(factor, 1.0 + tol)
            law = _law(replace(run, Tk=Tk), mesh, length, base)
            ratio, excess = check(dynamics, cons, law, tol, rate_tol)
            bad = excess > 0
        break
    last = _Round(law, ratio, bad, mesh, run, refined, stretched)
    if best is not None and (bad.any() or best.law.duration <= law.duration):
        last = best
    return _Search(_verdict(last, scales, programmes, T2), last, scales, programmes, T2)


#: A mesh asked far finer than the start's rows ask (``segments`` above this many times the
#: intervals :func:`.start.fractions` places for the start at :data:`SEGMENTS`) is reached
#: from a search on one this many times coarser (itself reached so where it is still that
#: fine), each of its intervals split into this many (the same motion), and the programmes
#: go on from that motion with the trust region :data:`SPLIT_DELTA` (mesh refinement, as in
#: direct transcription: Betts, *Practical Methods for Optimal Control Using Nonlinear
#: Programming*, 2nd ed., SIAM 2010, ch. 4). From the start placed on the fine mesh the
#: programmes move each switch of the jerk by a knot an interior-point iteration. Measured
#: on the five-line blended chain of ``bench_smooth.py scaling`` (medians of three meshes
#: about 2000 and 8000 intervals): 1.47 and 4.98 s CPU, M^0.88 (3.38 and 28.38 s, M^1.55,
#: from the fine start), the six motions 0.9425 s on average (0.9500); with 8 times coarser
#: 1.53 and 6.96 s (2408 and 8280 intervals, M^1.23); at once from the rows' own mesh
#: (about 150 intervals) 2.25 and 17.2 s, 0.9476 s. The benchmark's line, whose start is
#: near its answer on any mesh, pays for the coarser searches: 0.06, 0.24 and 1.10 s at
#: 1000, 4000 and 16000 intervals (0.04, 0.17 and 0.75 s), the same motion to 3e-5. 80
#: random corners at 800 intervals: half the CPU time, the motions 0.35 and 0.76 % slower
#: on average (two seeds; -2.9 to +6.8 %, the local search's spread: one corner planned
#: directly at 100 to 3200 intervals lands between 0.378 and 0.413 s), both 1.0 and 1.8 %
#: faster than at 32.
COARSE = 4
#: The trust region of the first programme on the split mesh (a fraction of the largest knot
#: acceleration, as :data:`.slp.START_DELTA`): the coarser motion is near the answer, and a
#: first programme at :data:`.slp.RESTART_DELTA` (0.1) was turned down on the chain's finest
#: meshes (the merit rising 90 times the reduction predicted). On the chain: medians 1.49
#: and 7.27 s with 0.1 (M^1.15), 1.28 and 5.27 s with 0.01; the line at 16000 intervals 0.96
#: s with 0.1.
SPLIT_DELTA = 0.03


@dataclass(frozen=True)
class _Coarser:
    """A search on a coarser mesh, and its motion on that mesh split with its check (None
    where the search's motion is outside the limits)."""

    search: _Search
    split: _Round | None


def _coarser(dynamics: PathDynamics, table: Table, cons: Sequence[Constraint],
             base: TimeOptimalLaw, start: Start, segments: int, tol: float, rate_tol: float,
             units: Units | None) -> _Coarser | None:
    """The search on a mesh :data:`COARSE` times coarser from ``base`` and ``start``, and
    its motion with its intervals split, where ``segments`` asks a mesh that fine (see
    :data:`COARSE`); None otherwise."""
    if segments <= COARSE * SEGMENTS or segments <= COARSE * (
            len(fractions(start, table, cons, SEGMENTS, KNOT_TOL)) - 1):
        return None
    search = _solve(dynamics, table, cons, -(-segments // COARSE), tol, rate_tol, units,
                    (base, start))
    r = search.last
    if r.bad.any():  # (outside the limits: from the start on the fine mesh instead)
        return _Coarser(search, None)
    Tk = np.diff(r.law.knots_t) / r.mesh.h  # (the law's own: a stretched one's too)
    mesh, J, Tk = _split(r.mesh, r.law.jerk * Tk**3, Tk, np.full(r.mesh.M, COARSE))
    run = replace(r.run, J=J, Tk=Tk)
    law = _law(run, mesh, float(dynamics.length), base)
    ratio, excess = check(dynamics, cons, law, tol, rate_tol)  # (the finer samples')
    return _Coarser(search, _Round(law, ratio, excess > 0, mesh, run, r.refined,
                                   r.stretched))


def _placed(start: Start, table: Table, cons: Sequence[Constraint], segments: int,
            length: float) -> tuple[Start, Mesh, Array, Array, RowModel]:
    """The start, its mesh, its jerks and their durations brought within the rows
    (:func:`.slp.time_scaled`, which keeps the last rows in the model returned). A start
    whose rows ask its whole time stretched :data:`STRETCH_GATE` times or more is slowed
    instead where it passes the speed cap of the path's own third-order terms
    (:func:`.start.slowed_to_cap`) and placed again."""
    second = [c for c in cons if c.order == 2]
    third = [c for c in cons if c.order == 3]
    for i in range(START_ROUNDS):  # (one slowing brings it within the cap, as measured)
        mesh = pinned(fractions(start, table, cons, segments, KNOT_TOL), start, table.joints)
        J = start_jerks(start, mesh, length)
        model = RowModel(mesh, table, second, third, length)
        Tk = time_scaled(model, J, np.full(mesh.M, start.T))
        if Tk[0] < STRETCH_GATE * start.T or i == START_ROUNDS - 1:
            break  # (the last round's start is the one its knots were placed for)
        slowed = slowed_to_cap(start, table.s, np.sqrt(third_order_cap(table, third)),
                               START_SLACK)
        if slowed is start:
            break
        log.debug("the start's rows ask its time stretched %.3g times: slowed to the cap",
                  float(Tk[0] / start.T))
        start = slowed
    return start, mesh, J, Tk, model


#: A path's joint closer than this fraction of its length to a grid point is that point.
JOINT_GAP = 1e-9


def with_joints(dynamics: PathDynamics, grid: int | Array) -> Array:
    """The table's grid (``grid`` equal segments, or the arc lengths given) with the path's
    joints added: where its pieces meet (a composite path's ``starts``: the ends of a
    blend), the curvature's derivative, and so the joints' third derivatives, jump. Between
    two grid points the table's columns are linear, so a jump inside a segment would become
    a ramp as steep as the segment is short, and the rows of a point crossing it would jump
    with the smallest change of the motion (the programmes' linear models then wrong at any
    trust region: 2 to 5 times the duration found, or no answer). A program's grids have
    them already (:func:`dextar.program.plan.chain_grid`)."""
    length = float(dynamics.length)
    pts = grid_points(grid, length)
    starts = getattr(getattr(dynamics, "path", None), "starts", None)
    if starts is None:
        return pts
    inner = np.asarray(starts, float)[1:-1]
    gap = JOINT_GAP * length
    near = np.abs(inner[:, None] - pts[None, :]).min(axis=1, initial=np.inf) <= gap
    new = np.unique(inner[(inner > gap) & (inner < length - gap) & ~near])
    return np.sort(np.concatenate([pts, new])) if new.size else pts


#: A start's second-order law on the coarse grid that slows below this fraction of its
#: largest speed at an inner grid point stops there (a time-optimal law never stops inside
#: a path whose limits leave it any speed): the whole grid instead. Measured on a blended
#: spiral of 112 lines (``bench_smooth.py length``), whose coarse grid of 40 segments spans
#: two or three of its lines each: the law on it stopped dead at inner points and took
#: 5.38 s, against 3.96 s on the whole grid of 10357 points (10 ms of CPU time for that
#: law); with the second search's acceleration cap (in a run with the pinned knots' shares
#: of :data:`.slp.RHO_SHARE`, before this test) the coarse law took 5.6e6 s, against 8.49 s
#: on the whole grid, and that search planned on it for 70 s of CPU time to no answer.
COARSE_STOP = 1e-3


def stops_inside(law: TimeOptimalLaw, below: float) -> bool:
    """Whether a second-order law's speed at an inner grid point is at most ``below`` of its
    largest."""
    v = np.asarray(law.knots_v)
    return bool(v[1:-1].min(initial=np.inf) <= below * v.max())


def _second_order(dynamics: PathDynamics, table: Table, second: Sequence[Constraint],
                  units: Units | None) -> TimeOptimalLaw:
    """The second-order time-optimal law of the start, on a coarse grid (every few points of
    the table's), or on the whole grid where the coarse one finds no motion or stops inside
    the path (a speed at an inner grid point below :data:`COARSE_STOP` of the largest): a
    coarse grid can step over a short stretch of fast-changing dynamics (a blend) and see a
    false impossibility there, or a false stop; the whole grid's verdict stands (its error
    names the user's limit). Not checked between the grid points (a start: the programmes'
    rows hold the limits; the check, 0.25 ms of a move's 0.9 here, tightened 1 of 794
    starts of 80 corners by more than its 5 %)."""
    pts = table.s
    step = max(1, int(np.ceil((len(pts) - 1) / START_GRID)))
    coarse = np.unique(np.concatenate([pts[::step], pts[-1:]]))
    cached = CachedDynamics(dynamics, table)
    if len(coarse) > 11 and len(coarse) < len(pts):
        try:
            law = solve_time_optimal_law(cached, constraints=second, grid=coarse,
                                         units=units, check=False)
            if not stops_inside(law, COARSE_STOP):
                return law
            log.debug("the start's coarse grid stops inside the path: the whole grid")
        except InfeasibleError as exc:
            log.debug("the start's coarse grid found no motion (%s): the whole grid", exc)
    return solve_time_optimal_law(cached, constraints=second, grid=pts, units=units,
                                  check=False)


def _start(dynamics: PathDynamics, table: Table, second: Sequence[Constraint],
           third: Sequence[Constraint], base: TimeOptimalLaw, units: Units | None) -> Start:
    """The start motion: the second-order law filtered (:func:`.start.filtered`); where the
    path's own third-order terms cap the speed (:func:`.start.third_order_cap`), the
    second-order law within that cap, and where its filtered version still passes faster
    (the filter averages the speed over its width, and a steep deceleration into a blend is
    shorter), the cap lowered there by the excess, a few rounds."""
    cap = third_order_cap(table, third)
    ok = np.sqrt(cap)
    law = base
    start = None
    for _ in range(START_ROUNDS):
        if law is base and not np.any(base.knots_v ** 2 > np.interp(base.knots_s, table.s,
                                                                    cap)):
            break  # the cap does not bind: the second-order law as it is
        law = _second_order(dynamics, table, [*second, CapConstraint(table.s, cap)], units)
        rho = min(ramp(law, table, third), 4.0 * float(law.duration))
        start = filtered(law, rho, float(table.s[-1]))
        over = np.interp(table.s, start.s, start.v) / ok
        if over.max() <= 1.0 + START_SLACK:
            return start
        cap = np.where(over > 1.0, cap / np.maximum(over, 1.0) ** 2, cap)
    if start is None:
        rho = min(ramp(law, table, third), 4.0 * float(law.duration))
        start = filtered(law, rho, float(table.s[-1]))
    return start


def _split(mesh: Mesh, J: Array, Tk: Array, pieces: Array) -> tuple[Mesh, Array, Array]:
    """The mesh with interval ``k`` split into ``pieces[k]`` equal ones, and the same motion
    (each piece keeps its interval's jerk and duration)."""
    f = split_segments(mesh.f, pieces)
    return (make_mesh(f, mesh.f[mesh.pins], mesh.pin_s), np.repeat(J, pieces),
            np.repeat(Tk, pieces))


def _law(run: Run, mesh: Mesh, length: float, base: TimeOptimalLaw) -> JerkLimitedLaw:
    """The law of a run's normalised jerks and duration."""
    dt = mesh.h * run.Tk
    jerk = run.J / run.Tk**3
    a, v, s = integrate(dt, jerk)
    t = np.concatenate([[0.0], np.cumsum(dt)])
    s[0], v[0], a[0] = 0.0, 0.0, 0.0
    s[-1], v[-1], a[-1] = length, 0.0, 0.0
    return JerkLimitedLaw(length, float(t[-1]), t, s, v, a, jerk,
                          base.torque_limit, base.speed_limit, {}, float(base.duration), 0,
                          "", 0)


@dataclass(frozen=True)
class _Round:
    """A law the solve found, with its check and how it came."""

    law: JerkLimitedLaw
    ratio: dict[str, float]
    bad: Array
    mesh: Mesh
    run: Run
    refined: int
    stretched: int


def _verdict(r: _Round, scales: dict[str, float], programmes: int, T2: float, note: str = ""
             ) -> JerkLimitedLaw:
    """The law with its ratios, status and message (``note`` at its end); ``T2`` the
    second-order law's duration it is compared with."""
    law, ratio, bad, mesh, run = r.law, r.ratio, r.bad, r.mesh, r.run
    refined, stretched = r.refined, r.stretched
    ok = not bad.any()
    T = law.duration
    words = ", ".join(f"{k} ratio {r:.5f}" for k, r in ratio.items())
    margin = "" if all(v == 1.0 for v in scales.values()) else (
        "; limits tightened by " + " and ".join(f"{1 - v:.2%} ({k})" for k, v in scales.items()
                                                 if v != 1.0)
        + " so that they hold between the knots")
    if stretched:
        margin += f"; stretched in time {stretched} time(s) so that they hold"
    how = (f"{mesh.M} intervals of constant jerk"
           + (f" ({refined} refinement(s))" if refined else "")
           + f", {programmes} linear programmes")
    rel = T / T2 - 1
    against = (f"{max(rel, 0.0):+.2%} against the second-order law on the start's grid"
               if rel > -5e-5  # (below by less than the last digit printed: +0.00 %)
               else f"{-rel:.2%} below the second-order law, which is computed on the "
               f"start's grid, coarser than these intervals")
    if ok:
        msg = (f"jerk-limited time-optimal within the limits: {words} on the check samples "
               f"({how}; {against}){margin}")
    else:
        msg = f"limits exceeded on the check samples ({how}): {words}"
    if not run.converged:
        msg += "; the linear programmes did not settle"
    return replace(law, ratios=ratio, status=0 if ok else 1, message=msg + note,
                   solves=programmes, second_order_duration=T2)


def _build(r: Any) -> Law:
    """The registered ``time-optimal`` builder: the second-order law (TOPP-RA) within the
    motors' torque, speed and acceleration limits, or this jerk-limited one when the motors
    have a jerk or torque-rate limit."""
    from ...errors import ConfigError

    p = r.params
    motors = r.motors
    if p.get("torque_limit") is not None:
        own = MotorLimits.of(p["torque_limit"], p.get("speed_limit_deg_s"))
        motors = own if motors is None else replace(
            own, max_acceleration=motors.max_acceleration, max_jerk=motors.max_jerk,
            max_torque_rate=motors.max_torque_rate)
    elif motors is None:
        raise ConfigError("config key [law].torque_limit is required for a time-optimal law "
                          "(or a [motors] table with peak_torque)")
    cons = motor_constraints(motors)
    if p.get("torque_limit") is None and p.get("speed_limit_deg_s") is not None:
        # the law's speed limit with the motors' limits: the lower of the two holds (it was
        # left out unless [law].torque_limit was given)
        law_speed = MotorLimits.of(motors.peak_torque, p["speed_limit_deg_s"]).max_speed
        cons = (*cons, SpeedLimit(law_speed))
    if motors.third_order:
        return solve_jerk_limited_law(r.dynamics, constraints=cons, grid=p["grid"],
                                      units=r.units)
    return solve_time_optimal_law(r.dynamics, constraints=cons, grid=p["grid"], units=r.units)


def _register() -> None:
    from ..registry import LAW_TYPES, LawType, register_law

    second = LAW_TYPES["time-optimal"]
    register_law(LawType(
        "time-optimal", second.params, _build,
        "the fastest rest-to-rest motion within the motors' limits: torque and speed "
        "(TOPP-RA), and with a jerk or torque-rate limit third order (zero acceleration at "
        "both ends; sequential linear programming)", needs_dynamics=True))


_register()
