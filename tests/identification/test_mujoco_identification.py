"""Identification from data that no part of our dynamics produced: MuJoCo simulates the
exported robot (friction, gravity, payload, rotors, masses unlike the prior's) tracking a
stored exciting trajectory under a stiff PD loop with the prior's feedforward
(tests/identification/mujoco_harness.py); we identify from its recorded angles (a 17-bit
encoder) and applied torques and predict the torques of a different motion (the paper's
semicircle), where the prior misses by 4-8 %."""

import numpy as np
import pytest

from dextar.config import load_toml
from dextar.config.scenario import scenario_from_dict
from dextar.errors import ParameterError
from dextar.identification.data import MotionData
from dextar.identification.fit import identify, validate

from ..program.test_program import EXAMPLES
from .excitations import EXCITATIONS

pytestmark = pytest.mark.slow

mujoco = pytest.importorskip("mujoco")
H = pytest.importorskip("tests.identification.mujoco_harness")

COUNT = 2 * np.pi / 2**17


def measured(run):
    """What the drive records: the angles through a 17-bit encoder, the torques applied."""
    return MotionData(run.t, np.round(run.q / COUNT) * COUNT, run.tau)


def semicircle_motion():
    """The paper's semicircle on the pick-and-place robot, a 1 s optimal law at 10 kHz."""
    doc = {k: v for k, v in load_toml(EXAMPLES / "pick_place.toml").items()
           if k in ("robot", "inertia", "friction", "gravity")}
    doc.update({"law": {"type": "optimal", "duration": 1.0}, "output": {"units": "si"}})
    tr = scenario_from_dict(doc).trajectory(samples=10001)

    def motion(tt):
        i = np.clip(np.round(tt * 10000).astype(int), 0, len(tr.t) - 1)
        return tr.q[i], tr.dq[i], tr.ddq[i]

    return motion, float(tr.t[-1])


@pytest.fixture(scope="session")
def runs(prior):
    model = prior[0]
    true = H.true_robot(model)
    semi, duration = semicircle_motion()
    return (H.track(true, model, EXCITATIONS[0].evaluate, 10.0),
            H.track(true, model, semi, duration))


def test_the_harness_tracks_within_a_degree_in_one_assembly_mode(prior, runs):
    """A 100 Hz loop at the 10 kHz inner rate: 0.0027 deg on the excitation, 0.002 deg on the
    semicircle (measured; bound 1 deg), MuJoCo's end-effector within 2e-5 mm of the model's
    assembly mode. The check can fail: a 4 Hz loop lags 1.4-1.7 deg on the stored
    excitations; a 2 Hz loop drifts 36-51 deg, crosses a parallel singularity and changes
    assembly mode (174 mm apart), and identify refuses those data by row."""
    for run in runs:
        assert run.tracking_error_deg < 1.0, run.tracking_error_deg
        assert run.assembly_gap_mm < 1e-3 and run.type2_sign_changes == 0
    model, mode, _ = prior
    soft = pytest.MonkeyPatch()
    soft.setattr(H, "BANDWIDTH_HZ", 2.0)
    try:
        lost = H.track(H.true_robot(model), model, EXCITATIONS[0].evaluate, 10.0)
    finally:
        soft.undo()
    assert lost.tracking_error_deg > 1.0 and lost.type2_sign_changes >= 1
    assert lost.assembly_gap_mm > 10.0
    with pytest.raises(ParameterError, match=r"row \d+ \(t = [\d.]+ s\): the motion (crosses a "
                                             r"parallel|comes within [\d.e-]+ of a parallel)"):
        identify(measured(lost), model, mode=mode)


def test_identified_model_predicts_mujoco_torques_of_another_motion(prior, runs, base):
    """Prediction error on the semicircle 0.046 / 0.104 % (motor A / D; the three stored
    excitations 0.038-0.056 / 0.083-0.128 %, 20 designed ones in
    benchmarks/bench_identify_mujoco.py at most 0.063 / 0.139 %): the bound 0.6 % is 5.8x
    above this one and 4.3x above the worst; the prior misses by 4.05 / 8.0 %, and fails
    it."""
    model, mode, _ = prior
    excite, semi = runs
    res = identify(measured(excite), model, mode=mode, base=base)
    assert res.success, res.message
    assert (res.fit_quality < 0.01).all(), res.fit_quality  # measured 0.065 / 0.092 %
    v = validate(res, measured(semi), model, mode=mode)
    assert (v.error < 0.006).all(), v.error
    assert (v.error_prior > 0.006).all(), v.error_prior  # the check tells a wrong model
    # the semicircle sweeps poses far from the excitation's: the prediction extrapolates and
    # the validation says so (its rigid-body part is exact, so it still predicts well)
    assert v.coverage.fraction < 0.5 and v.warnings


def test_the_filters_keep_the_stick_phases_of_a_soft_loop_out(prior, runs, base):
    """A 10 Hz loop (0.18 deg of tracking) on the former design's slower excitation: dry
    friction holds the joints longer at each reversal. Prediction error on the semicircle
    0.064 / 0.136 % (measured; with a 5 Hz loop on six such excitations 0.062-0.066 /
    0.135-0.153 %), 4.4x below the bound 0.6 %. The former conditioning (one 5 Hz filter,
    the rows below 5 % of the peak speed left out) reached 1.21 / 0.58 % on these data, up to
    3.4 % with the 5 Hz loop."""
    model, mode, _ = prior
    soft = pytest.MonkeyPatch()
    soft.setattr(H, "BANDWIDTH_HZ", 10.0)
    try:
        run = H.track(H.true_robot(model), model, EXCITATIONS["slow"].evaluate, 10.0)
    finally:
        soft.undo()
    assert run.tracking_error_deg < 1.0 and run.type2_sign_changes == 0
    res = identify(measured(run), model, mode=mode, base=base)
    assert res.success, res.message
    v = validate(res, measured(runs[1]), model, mode=mode)
    assert (v.error < 0.006).all(), v.error
