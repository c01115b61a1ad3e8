"""Balance the shaking force of a DexTAR with counterweights, and see what it costs.

Run: python examples/balancing.py

The pick-and-place gripper of examples/pick_place.toml (0.08 kg and a 0.05 kg part on rods
of 0.03 and 0.02 kg) on a 0.3 s semicircle of 40 mm. Three robots: as built; with the
counterweights on the proximal rods of the closed form (condition (a) of
dextar.dynamics.balancing: what the proximal rods alone can do); with the distal rods'
masses redistributed first (counterweights behind the elbows, condition (b)) and then the
proximal counterweights: the force fully balanced. For each: the moving mass, the peak
shaking force and moment, the peak motor torque, and how far the centre of mass moves. The
script checks its own results.
"""

import numpy as np

import dextar as dx
from dextar.dynamics import Inertia, Model, inverse_dynamics
from dextar.dynamics.balancing import balance_force, distal_counterweights, mass_center, shaking
from dextar.laws import MinimumJerkLaw
from dextar.paths import Arc
from dextar.trajectory import sample_trajectory

robot = dx.DEXTAR_MM.scaled(1e-3)  # SI: m, kg, s
built = Inertia.uniform(robot, proximal_mass=0.03, distal_mass=0.02, effector_mass=0.08,
                        payload=0.05)
path = Arc(0.04, 0.0, np.pi, center=(0.0, 0.11))
tr = sample_trajectory(robot, path, MinimumJerkLaw(path.length, 0.3), mode="+-", samples=601)

proximal_only = balance_force(robot, built, 0.03)  # 30 mm behind the motor axes
redistributed, distal = distal_counterweights(robot, built, 0.03)  # 30 mm behind the elbows
full = balance_force(robot, redistributed, 0.03)

print(f"{'robot':<26}{'mass kg':>9}{'force N':>10}{'moment N m':>12}{'torque N m':>12}"
      f"{'G moves mm':>12}")
results = {}
for name, inertia in (("as built", built), ("proximal counterweights", proximal_only.inertia),
                      ("fully balanced", full.inertia)):
    model = Model(robot, inertia)
    s = shaking(model, tr.q, tr.dq, tr.ddq, P=tr.P)
    tau = inverse_dynamics(model, tr.q, tr.dq, tr.ddq)
    moves = 1e3 * np.ptp(mass_center(model, tr.q), axis=0).max()
    results[name] = (s.mass, s.force_magnitude.max(), np.abs(s.moment).max(),
                     np.abs(tau).max(), moves)
    print(f"{name:<26}{s.mass:>9.3f}{results[name][1]:>10.4g}{results[name][2]:>12.4g}"
          f"{results[name][3]:>12.4g}{moves:>12.3g}")
c = proximal_only.counterweights[0]
print(f"proximal counterweights alone: {c.mass * 1e3:.1f} g at 30 mm; the mass lumped at P, "
      f"{proximal_only.residual_mass * 1e3:.1f} g, still shakes the frame")
print(f"full balance: {distal[0].mass * 1e3:.1f} g behind each elbow, then "
      f"{full.counterweights[0].mass * 1e3:.1f} g behind each motor axis")

# the checks: the balanced robot's centre of mass stays put, its shaking force vanishes;
# the proximal counterweights alone leave the force of the mass at P
assert full.full and results["fully balanced"][4] < 1e-9
assert results["fully balanced"][1] < 1e-12 * results["as built"][1]
assert 0 < results["proximal counterweights"][1] < results["as built"][1]
assert results["fully balanced"][3] > results["as built"][3]  # balance costs torque
print("balancing checks passed")
