"""Jerk-limited time-optimal law of motion along a path: the fastest rest-to-rest motion,
starting and ending with zero acceleration, within the limits of the robot's dynamics
(torque with friction, speed, torque-speed envelope, joint acceleration) and within the
third-order limits (joint jerk, torque rate).

Method: direct transcription in normalised time with piecewise-constant jerk, solved by
sequential linear programming (SLP) with a trust region, the duration a variable of every
programme; the start is the second-order time-optimal law passed through a moving-average
filter; the transcription is refined where the output check finds a limit exceeded. Where the
jerk rules the motion, a second search starts from the second-order law with the joint
accelerations capped below the first motion's peak, and the faster law is kept. The
modules, in the order of the solve:

* :mod:`.table`: the path's coefficients on the grid and their slopes along the path.
* :mod:`.start`: the second-order law filtered by a moving average of width ``rho`` (the
  time the steepest acceleration switch needs at the jerk or torque-rate limits), and the
  knots, denser where the rows change fast along it.
* :mod:`.mesh`: ``M`` intervals of constant jerk at fixed fractions ``f`` of the duration
  ``T``. In normalised time ``tau = t / T`` the normalised jerks ``J_k = T^3 sdddot`` give
  the knots' arc length ``sigma``, speed ``w = T sdot`` and acceleration
  ``alpha = T^2 sddot`` by the exact integration of a constant jerk, knot to knot (a banded
  recurrence), so the ends (``sigma = S``, ``w = alpha = 0``) do not involve ``T`` and the
  motion between the knots is exact.
* :mod:`.rows`: every limit as a row ``r <= 0`` at the inner knots and in the middle of
  every interval, a second-order one also at its quarters where it is near its limit and
  bends above the chord of its neighbours (the third-order limits at both ends and the
  middle of every interval, where the jerk is constant): the second-order constraint objects' rows
  ``pu u + px x <= ph`` (:mod:`dextar.laws.constraints`) become ``pu alpha + px w^2 - ph
  T^2 <= 0``, the speed cap ``w <= sqrt(cap) T``, the joint jerk ``q' J + 3 q'' w alpha +
  q''' w^3 <= j_max T^3``, the torque rate ``a J + (a' + 2 b) w alpha + b' w^3 + g' w T^2 +
  f_qdot (q' alpha + q'' w^2) T <= r_max T^3``, each normalised by its limit, linearised
  about the current motion in every variable (the states, the arc length at which the
  coefficients are taken, and ``T``); built compiled where the install built it
  (``_rows.c``, its numpy code's arithmetic in the same order).
* :mod:`.slp`: each linear programme minimises ``T`` plus an exact penalty on the rows
  within a trust region; its variables are the states at the knots, ``T`` and the slack,
  its equalities the exact integration, so it is banded.
* :mod:`.banded`: the programmes' solver, a primal-dual interior point whose Newton systems
  are a band bordered by one column: memory and work linear in the knots; compiled where
  the install built it (``_ipm.c``), numpy and LAPACK's banded LU otherwise.
* :mod:`.check`: the law sampled (nine points in every interval) through the exact model;
  an interval in which a limit is exceeded by more than its tolerance (``tol``: torque,
  speed, acceleration; ``rate_tol``: jerk and torque rate, whose ratio is a finite
  difference) is split (the same motion) and the SLP runs again; after a few rounds a kind
  still exceeded is tightened by its excess, and last the motion is stretched in time.
* :mod:`.solve`: the whole, and the registered ``time-optimal`` builder.

No false "impossible": the only error that says no motion exists is the second-order law's
on the whole grid (a coarse start grid that finds none is retried on the whole grid); where
the programmes end beyond a limit, the motion is slowed until its rows hold, and where the
check still fails after refinement and tightening, stretched in time until it passes.

For the kinematic limits alone (a joint move with speed, acceleration and jerk limits) the
rows are exact at the knots and between them, so the law is never faster than the continuous
optimum (Ruckig's profile, Berscheid & Kroeger, "Jerk-limited real-time trajectory generation
with arbitrary target states", RSS 2021) and within the loss of the fixed knots (below 1e-3
on the tested moves); as the jerk limit grows it tends to the second-order law. The third-order
structure of the problem is as in Pham & Pham, "On the structure of the time-optimal path
parameterization problem with third-order constraints", ICRA 2017; SLP for path following
with nonconvex constraints as in Debrouwere et al., IEEE T-RO 29(6), 2013.

Development: ``logging.getLogger("dextar.laws.smooth").setLevel(logging.DEBUG)`` (with a
handler) shows every programme and check.
"""

from .law import JerkLimitedLaw
from .solve import solve_jerk_limited_law

__all__ = ["JerkLimitedLaw", "solve_jerk_limited_law"]
