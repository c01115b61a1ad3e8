"""dextar in one page: from a point to the motor torques, checking itself on the way.

Run: python examples/quickstart.py   (paper units: length L = 87 mm, mass m, time T)
"""

import numpy as np

import dextar as dx
from dextar.dynamics import Model, inverse_dynamics, kinetic_energy, paper_inertia
from dextar.laws import MinimumJerkLaw, law_cost, solve_optimal_law
from dextar.paths import Arc
from dextar.trajectory import sample_trajectory

# the DexTAR in millimetres: l = 72, L = 87, d = 60
robot_mm = dx.DEXTAR_MM
q = dx.inverse_kinematics(robot_mm, [0.0, 120.0], "+-")  # rad
print("IK at (0, 120) mm, mode +-:", np.degrees(q).round(4), "deg")
assert np.allclose(np.degrees(q), [60.5118, 119.4882], atol=1e-4)
assert np.allclose(dx.direct_kinematics(robot_mm, q, "up"), [0.0, 120.0], atol=1e-9)

# the paper's units: lengths in L = 87 mm, the end-effector mass m = 1, duration T = 1
robot = robot_mm.scaled(1 / 87)
path = Arc(radius=120 / 87, p0=0.0, p1=np.pi)  # the semicircle, p = polar angle
law = solve_optimal_law(path, duration=1.0, eta=0.1, mass=1.0)
print(f"optimal law: cost {law.cost:.6f} = kinetic {law.kinetic:.6f} + inertial "
      f"{law.inertial:.6f} (m L^2/T^2 x T)")
assert law.cost < sum(law_cost(MinimumJerkLaw(path.length, 1.0), path, 1.0, 0.1))

tr = sample_trajectory(robot, path, law, mode="+-", samples=1001)
model = Model(robot, paper_inertia(robot))  # distal rods 0.1 m, proximal 0.08 m, uniform
tau = inverse_dynamics(model, tr.q, tr.dq, tr.ddq)  # m L^2 / T^2
print("peak |tau| (motor A, motor D):", np.abs(tau).max(axis=0).round(4))

# physics check: the motors' power is the rate of change of kinetic energy
T = kinetic_energy(model, tr.q, tr.dq)
power = np.sum(tau * tr.dq, axis=1)
energy_rate = np.gradient(T, tr.t)
assert np.abs(power - energy_rate)[5:-5].max() < 1e-4 * np.abs(power).max()
# symmetry of the paper's case: tau1(t) = -tau2(T - t)
assert np.allclose(tau[:, 0], -tau[::-1, 1], atol=1e-9)
print("checks passed")
