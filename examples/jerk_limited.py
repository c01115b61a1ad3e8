"""A jerk-limited time-optimal motion through the Python API (SI: m, kg, s, rad, N m), on a
robot of your own, checking itself on the way.

Run: python examples/jerk_limited.py
"""

import numpy as np

from dextar.dynamics import Inertia, Model, RobotAlongPath, Rod, kinetic_energy
from dextar.geometry import FiveBar
from dextar.laws import solve_jerk_limited_law, solve_time_optimal_law
from dextar.motors import MotorLimits
from dextar.paths import Line, blended
from dextar.trajectory import sample_trajectory

# a five-bar of 130 mm and 190 mm arms, 90 mm apart, lying flat (no gravity), 0.3 kg at the
# end-effector; uniform rods of 60 g and 40 g, 2e-5 kg m^2 at each rotor
robot = FiveBar(l1=0.13, l2=0.13, L1=0.19, L2=0.19, d=0.09)
inertia = Inertia(proximal=(Rod.uniform(0.06, 0.13),) * 2,
                  distal=(Rod.uniform(0.04, 0.19),) * 2,
                  effector_mass=0.3, rotor=(2e-5, 2e-5))
model = Model(robot, inertia)

# two lines through a corner rounded within 8 mm: one motion, no stop at the corner
path, _ = blended((Line((-0.04, 0.20), (0.0, 0.24)), Line((0.0, 0.24), (0.04, 0.20))),
                  (0.008,))
along = RobotAlongPath(model, path, "+-")
motors = MotorLimits(peak_torque=(1.0, 1.0), max_jerk=(5000.0, 5000.0))  # N m, rad/s^3
law = solve_jerk_limited_law(along, motors=motors)
second = solve_time_optimal_law(along, motors=MotorLimits(peak_torque=(1.0, 1.0)))
print(f"{law.duration:.4f} s ({law.duration / second.duration:.3f} x the law without a "
      f"jerk limit, {second.duration:.4f} s)")
print(law.message)
assert law.success and law.duration > second.duration

# the joint motion and the torques at 20 kHz
t = np.linspace(0.0, law.duration, 20001)
js = along.samples(law, t)  # torques (N m), joint speeds (rad/s) and accelerations
jerk = np.diff(js.ddq, axis=0) / np.diff(t)[:, None]
print("peak jerk / limit:", (np.abs(jerk).max(axis=0) / 5000.0).round(4))
print("peak torque / limit:", np.abs(js.tau).max(axis=0).round(5))
assert np.abs(jerk).max() <= 5000.0 * 1.01  # the jerk within 1 % of its limit
assert np.abs(js.tau).max() <= 1.0 * 1.001  # the torques within 0.1 %
assert np.abs(js.ddq[[0, -1]]).max() < 1e-9  # at rest with zero acceleration at both ends

# physics check: the motors' power is the rate of change of the kinetic energy
tr = sample_trajectory(robot, path, law, mode="+-", times=t)
energy = kinetic_energy(model, tr.q, tr.dq)
power = np.sum(js.tau * js.dq, axis=1)
miss = np.abs(power - np.gradient(energy, t))[5:-5].max() / np.abs(power).max()
print(f"power against the kinetic energy's rate: {miss:.1e} of the peak power")
assert miss < 1e-3  # (measured 1.1e-4: the finite difference's error where the jerk jumps)
print("checks passed")
