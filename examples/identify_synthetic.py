"""Identify a robot's masses, inertias and friction from its motion, checking itself.

The "measured" data come from dextar's exact model of a robot heavier than the config says,
with torque noise and a 17-bit encoder; the identified model must find the truth within its
own standard deviations and predict another motion better than the config's model.

Run: python examples/identify_synthetic.py   (SI: m, kg, s, N m)
"""

from pathlib import Path

import numpy as np

from dextar.config import load_scenario
from dextar.dynamics import Model, inverse_dynamics
from dextar.dynamics.regressor import regressor, standard_parameters
from dextar.identification.base import base_parameters
from dextar.identification.data import MotionData
from dextar.identification.excite import design_excitation
from dextar.identification.fit import identify, validate

sc = load_scenario(Path(__file__).with_name("pick_place.toml"))
prior = sc.si_model  # the config's robot: DexTAR, light rods, a gripper and its part
true = Model(prior.robot, prior.inertia.scaled_masses(1.3).with_(viscous=(0.012, 0.008)))

# 1. the tau = Y theta model and its base parameters (combinations the torques determine)
base = base_parameters(prior)
print(f"{base.size} base parameters:", ", ".join(base.names))
rng = np.random.default_rng(0)
q = np.radians([[60.0, 120.0], [50.0, 110.0]])
dq, ddq = rng.normal(size=(2, 2)), rng.normal(size=(2, 2))
Y = regressor(true, q, dq, ddq)  # (2, 2, 15)
assert np.allclose(Y @ standard_parameters(true.inertia), inverse_dynamics(true, q, dq, ddq))

# 2. an exciting trajectory: 2 periods of 5 s, within the servo's torque and speed
ex = design_excitation(prior, sc.mode, duration=10.0, motors=sc.si_motors)
print(f"exciting trajectory: condition number {ex.condition_number:.3g}")

# 3. "measure" it: the true robot's torques + 5 mN m noise, angles quantised to 2^17 counts
t = np.arange(10001) / 1000.0  # s, 1 kHz
q, dq, ddq = ex.trajectory.evaluate(t)
count = 2 * np.pi / 2**17
data = MotionData(t, np.round(q / count) * count,
                  inverse_dynamics(true, q, dq, ddq) + rng.normal(scale=0.005, size=q.shape))

# 4. identify: filtered, parallel-filtered, weighted least squares, a physical parameter set
res = identify(data, prior, mode=sc.mode, base=base)
z = (res.beta - base.of(standard_parameters(true.inertia))) / res.std
for name, value, std, zi in zip(base.names, res.beta, res.std, z, strict=True):
    print(f"  {name:6s} = {value: .5g} +- {std:.2g}   (error {zi:+.2f} std)")
assert np.abs(z).max() < 4, "the truth lies within the identified deviations"
print(f"verdict: {res.status_text}; fit quality {100 * res.fit_quality[0]:.2f} % / "
      f"{100 * res.fit_quality[1]:.2f} % of the RMS torques; the data hardly pin "
      f"{', '.join(res.poorly_determined) or 'nothing'} (relative std above 50 %)")
assert res.status == 0 and (res.fit_quality < 0.2).all()

# 4b. the same data with gravity left out of the prior: the verdict is a poor fit
flat = Model(prior.robot, prior.inertia.with_(gravity=(0.0, 0.0)))
poor = identify(data, flat, mode=sc.mode)
print(f"gravity left out: {poor.status_text} (fit quality {100 * poor.fit_quality.max():.0f} %)")
assert poor.status == 3 and "gravity" in poor.message

# 5. predict a motion not used in the fit: a faster exciting trajectory
t2 = np.arange(2001) / 1000.0
q2, dq2, ddq2 = ex.trajectory.evaluate(t2 * 2.5)
dq2, ddq2 = 2.5 * dq2, 6.25 * ddq2
measured = inverse_dynamics(true, q2, dq2, ddq2)
err_id = np.abs(inverse_dynamics(Model(prior.robot, res.inertia), q2, dq2, ddq2) - measured)
err_prior = np.abs(inverse_dynamics(prior, q2, dq2, ddq2) - measured)
print(f"prediction error: identified {err_id.max():.2e} N m, config's model "
      f"{err_prior.max():.2e} N m")
assert err_id.max() < 0.1 * err_prior.max()

# 6. the same through validate(): the data conditioned with the identification's filters, the
# rows whose friction sign they tell, and whether the motion stays in the excited region
# (a faster motion does not: its speeds are beyond the excitation's)
t3 = np.arange(2001) / 1000.0
other = MotionData(t3, np.round(q2 / count) * count, measured)
v = validate(res, other, prior, mode=sc.mode)
print(f"validate: error {100 * v.error[0]:.2f} % / {100 * v.error[1]:.2f} % (prior "
      f"{100 * v.error_prior[0]:.1f} % / {100 * v.error_prior[1]:.1f} %); "
      f"{100 * v.coverage.fraction:.0f} % of it inside the excited region")
assert (v.error < 0.1 * v.error_prior).all() and v.coverage.fraction < 1 and v.warnings
print("identification checks passed")
