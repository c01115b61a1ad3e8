"""A new law is one file plus its tests: a toy law registered from outside the package,
through the public registry, plans from a config, and the docs and help list it."""

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

from dextar.config import scenario_from_dict
from dextar.laws import LAW_TYPES, Law, LawType, Param, register_law
from dextar.paths import PATH_TYPES


@dataclass(frozen=True)
class ConstantAcceleration(Law):
    """Accelerate at a constant rate over the whole path: s = S (t / T)^2 (not rest to
    rest: the toy of the registry test)."""

    distance: float
    duration: float
    name: str = field(default="const-accel", init=False)

    def _evaluate(self, t: np.ndarray) -> np.ndarray:
        S, T = self.distance, self.duration
        return np.stack([S * (t / T) ** 2, 2 * S * t / T**2, np.full_like(t, 2 * S / T**2),
                         np.zeros_like(t)])


@pytest.fixture
def toy_law():
    kind = register_law(LawType(
        "const-accel", {"duration": Param("number", "s", 1.0, "motion time", positive=True)},
        lambda req: ConstantAcceleration(req.path.length, req.params["duration"]),
        "constant acceleration from rest"))
    yield kind
    LAW_TYPES.pop("const-accel")


def test_a_toy_law_registered_from_outside_plans_from_a_config(toy_law):
    sc = scenario_from_dict({"law": {"type": "const-accel", "duration": 0.5},
                             "output": {"units": "si", "samples": 101}})
    law = sc.law()
    assert isinstance(law, ConstantAcceleration) and law.duration == 0.5
    tr = sc.trajectory(law)
    assert tr.t[-1] == 0.5 and np.allclose(tr.dds, 2 * sc.path.length / 0.25)
    # its keys are checked like any other's
    with pytest.raises(Exception, match=r"\[law\]\.duration must be positive"):
        scenario_from_dict({"law": {"type": "const-accel", "duration": -1.0}})


def test_the_command_line_plans_with_it_and_its_help_lists_it(toy_law, tmp_path, capsys):
    from dextar.cli import build_parser, main

    cfg = tmp_path / "c.toml"
    cfg.write_text('[law]\ntype = "const-accel"\nduration = 0.4\n[output]\nunits = "si"\n')
    assert main(["plan", str(cfg), "--out", str(tmp_path / "p.csv"), "--json"]) == 0
    assert '"law": "const-accel"' in capsys.readouterr().out
    helptext = build_parser().format_help() + "".join(
        a.choices["plan"].format_help() for a in build_parser()._subparsers._group_actions)
    assert "const-accel" in helptext


def test_the_docs_list_every_registered_path_and_law_a_new_one_too(toy_law):
    """The docs' config reference (generated from the registries when the docs are built)
    names every path type and law, the one registered from outside included."""
    import importlib.util
    from pathlib import Path

    source = Path(__file__).resolve().parents[2] / "docs" / "_ext" / "dextar_reference.py"
    spec = importlib.util.spec_from_file_location("dextar_reference_for_laws", source)
    reference = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(reference)
    text = reference.config_reference()
    for name in [*PATH_TYPES, *LAW_TYPES]:
        assert f'type = "{name}"' in text and f'``"{name}"``' in text, name
    assert "const-accel" in LAW_TYPES and "constant acceleration from rest" in text


def test_a_limit_registered_from_outside_is_planned_within():
    """A new limit is a Constraint and one registration: a power-supply cap that halves each
    motor's peak torque, registered as a constraint type, makes the time-optimal move slower
    (gravity takes part of the torque: 1.73x measured) and as slow as with motors of half
    the peak (the check fails when motor_constraints ignores the registry), and the written torques stay
    within the halved limit; removed, the move is as before."""
    from dextar.config import load_scenario
    from dextar.dynamics import Model, RobotAlongPath
    from dextar.laws import solve_time_optimal_law
    from dextar.laws.constraints import CONSTRAINT_TYPES, ConstraintType, TorqueLimit
    from dextar.motors import MotorLimits
    from dextar.paths import Line

    assert list(CONSTRAINT_TYPES)[:2] == ["torque", "speed"]
    m = load_scenario(Path(__file__).parents[2] / "examples" / "pick_place.toml").si_model
    along = RobotAlongPath(Model(m.robot, m.inertia, "up"), Line((-0.04, 0.09), (0.04, 0.12)), "+-",
                           checked=True)
    motors = MotorLimits((0.6, 0.6))
    before = solve_time_optimal_law(along, motors=motors)
    CONSTRAINT_TYPES.register(ConstraintType(
        "supply", lambda m: TorqueLimit(tuple(0.5 * np.asarray(m.peak_torque))),
        "half the peak torque"))
    try:
        capped = solve_time_optimal_law(along, motors=motors)
    finally:
        CONSTRAINT_TYPES.pop("supply")
    assert before.success and capped.success
    half = solve_time_optimal_law(along, motors=MotorLimits((0.3, 0.3)))
    assert capped.duration > 1.3 * before.duration, (before.duration, capped.duration)
    assert capped.duration == pytest.approx(half.duration, rel=1e-3)
    tau = along.samples(capped, np.linspace(0, capped.duration, 501)).tau
    assert np.abs(tau).max() <= 0.3 * (1 + 1e-3)
    assert solve_time_optimal_law(along, motors=motors).duration == pytest.approx(
        before.duration, rel=1e-9)
