"""Calibrate a five-bar's kinematics from measured poses, checking itself.

The "real" robot is the DexTAR off by 0.5 mm in every length and 0.5 deg in both encoder
offsets, measured by an instrument (a laser tracker, say) whose frame is shifted and turned
arbitrarily, to 0.02 mm per axis, with 17-bit encoders off by up to a count. The calibration
must find it within its standard deviations, bring the error on poses it never saw down to
the instrument's noise, and give readings that put the real robot where it is asked to go.

Run: python examples/calibrate_synthetic.py   (SI in Python: m, rad; files in mm, deg)
"""

import math
import tempfile
from pathlib import Path

import numpy as np

import dextar as dx
import dextar.calibration as cal
from dextar.calibration.fit import validation_errors
from dextar.calibration.poses import candidates
from dextar.output.calibration import poses_csv

nominal = cal.KinematicModel(dx.DEXTAR_MM.scaled(1e-3))      # the config's robot, in m
rng = np.random.default_rng(2026)
signs = rng.choice([-1.0, 1.0], 7)
lengths = np.array([0.072, 0.072, 0.087, 0.087, 0.060]) + 0.5e-3 * signs[:5]
true = cal.KinematicModel(dx.FiveBar(*lengths), *np.radians(0.5 * signs[5:]),
                          x0=1.2, y0=-0.4, theta0=math.radians(130.0))
sigma, count = 0.02e-3, 2 * math.pi / 2**17                  # instrument, one encoder count

# 1. where to measure: 60 poses in all four working modes maximising O1 (D-optimal), away
#    from both singularity types, in an order the robot can visit
four = cal.select_poses(nominal, 60)
one = cal.select_poses(nominal, 60, modes=("+-",))
print(f"poses: {four.message}")
print(f"       one working mode only: O1 {one.observability.o1:.3g}, O3 "
      f"{one.observability.o3:.3g}")

# 2. measure them (here: the true robot plus noise) and write the file a user would write
data = cal.measure(true, four.readings, 1, rng, point_std=sigma, count=count)
with tempfile.TemporaryDirectory() as tmp:
    path = Path(tmp) / "measured.csv"
    lines = ["phi_deg,psi_deg,x_mm,y_mm,mode"] + [
        f"{float(a)!r},{float(b)!r},{float(x)!r},{float(y)!r},{m}" for (a, b), (x, y), m in
        zip(np.degrees(data.readings), 1e3 * data.points, data.modes, strict=True)]
    path.write_text("\n".join(lines) + "\n")
    data = cal.read_poses_csv(path)                            # assembly: inferred per row
    assert poses_csv(four).startswith("mode,assembly,phi_deg,psi_deg,x_mm,y_mm")

# 3. calibrate, validating on 40 other poses drawn at random over the four modes' workspace
_, cand = candidates(nominal, dx.geometry.WORKING_MODES, 1, margin=0.2, closure_slack=4e-3,
                     resolution=61, rng=rng)
pick = rng.choice(len(cand.q), 40, replace=False)
held = cal.measure(true, cand.q[pick], 1, rng, point_std=sigma, count=count)
res = cal.calibrate(data, nominal, validation=held)
print(f"calibrate: {res.message}; identifiable: {', '.join(res.identifiable)}")
z = []
for p, t in zip(res.parameters, true.vector(), strict=True):
    unit, nom, val, std = p.in_file_units()
    err = math.remainder(p.value - t, 2 * math.pi) if p.name == "theta0" else p.value - t
    z.append(err / p.std)
    print(f"  {p.name:10s} nominal {nom:10.4f}  fitted {val:10.4f} +- {std:.2g} {unit:3s} "
          f"(true {cal.model.to_file_units(p.name, t):10.4f}: {z[-1]:+.2f} std)")
assert np.abs(z).max() < 3.5, "the truth lies within the standard deviations"

# 4. the error on held-out poses, against the instrument's own floor: the error the true
#    robot itself makes on those measurements
floor = validation_errors(held, true, true).rms_after
v = res.validation
assert v is not None
print(f"held-out RMS error: {1e3 * v.rms_before:.3f} mm before, {1e3 * v.rms_after:.4f} mm "
      f"after; noise floor {1e3 * floor:.4f} mm ({v.rms_after / floor:.2f} x)")
assert v.rms_after < 1.3 * floor and v.rms_before > 10 * floor

# 5. the inverse use: readings that put the real robot at targets of the instrument's frame
targets = true.to_instrument(np.array([[0.0, 0.12], [-0.05, 0.10], [0.04, 0.14]]))
readings = np.round(res.calibrated.readings_for_measured(targets, "+-") / count) * count
miss = np.hypot(*(true.predict(readings, 1) - targets).T)
print(f"targets reached by the real robot within {1e3 * miss.max():.4f} mm")
assert miss.max() < 2 * floor

# 6. how accurate the calibrated robot is over its workspace (accuracy.png)
acc = cal.accuracy_map(res.calibrated, res.identifiable, res.covariance, "+-",
                       reading_std=cal.encoder_std(2**17))
print(f"predicted position uncertainty (mode +-): median {1e6 * acc.median:.2f} um, worst "
      f"{1e6 * acc.worst:.1f} um")

# 7. the wrong model is caught: offsets frozen at zero leave residuals far above the noise
frozen = cal.calibrate(data, nominal, point_std=sigma, reading_std=count / math.sqrt(3),
                       fit=[n for n in cal.NAMES if not n.endswith("offset")])
print(f"offsets frozen: status {frozen.status}: {frozen.message}")
assert frozen.status == 2 and frozen.rms_error_after > 10 * floor

# 8. one working mode against four, on the same held-out poses
data1 = cal.measure(true, one.readings, 1, rng, point_std=sigma, count=count)
res1 = cal.calibrate(data1, nominal, validation=held)
assert res1.validation is not None
print(f"one mode: held-out RMS {1e3 * res1.validation.rms_after:.4f} mm "
      f"({res1.validation.rms_after / floor:.2f} x the floor) against "
      f"{v.rms_after / floor:.2f} x in four modes")
assert four.observability.o1 > one.observability.o1
print("calibration checks passed")
