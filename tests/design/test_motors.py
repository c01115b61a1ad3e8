"""Motors and gearboxes from a catalogue: the file read (or refused by name), each design
planned with the lightest motor that fits and its best ratio (checked against plans made
apart with every lighter motor, which do not fit), the reflected rotor inertia and the
motor-side speed in the plan, counterweights and shaking metrics in the rows, the motor as a
design variable, best.toml naming the motor and ratio."""

import math
import re
import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from dextar.cli import main
from dextar.config import load_scenario
from dextar.config.catalogue import catalogue_from_dict, read_catalogue
from dextar.design.evaluate import counterweights_of, design_values, evaluate_design, inertia_of
from dextar.errors import ConfigError, InfeasibleError
from dextar.geometry import FiveBar
from dextar.motors import Catalogue, Gearmotor, MotorLimits
from dextar.program import ProgramRequest, sizing

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
TASK_FILE = EXAMPLES / "design_motors.toml"
CATALOGUE = EXAMPLES / "catalogue" / "servo_motors.toml"


@pytest.fixture(scope="module")
def example():
    sc = load_scenario(TASK_FILE)
    task, space = sc.design_task()
    return sc, task, space


def test_the_example_catalogue_reads_in_si():
    cat = read_catalogue(CATALOGUE, (5.0, 10.0))
    assert [m.name for m in cat.motors][:2] == ["BL22-15W", "BL32-40W"]
    m = cat.motor("BL42-80W")
    assert m.rotor_inertia == pytest.approx(4.8e-6) and m.max_speed == pytest.approx(
        6000 * 2 * math.pi / 60) and m.knee_speed == pytest.approx(4500 * 2 * math.pi / 60)
    assert cat.currency == "EUR" and cat.ratios == (5.0, 10.0)
    assert [x.name for x in cat.ordered("cheapest")][0] == "BL22-15W"
    gm = Gearmotor(m, 20.0)
    lim = gm.limits(MotorLimits((1.0, 1.0), max_jerk=(5e4, 5e4)))
    assert lim.peak_torque == (20 * 0.45, 20 * 0.45)
    assert lim.max_speed[0] == pytest.approx(m.max_speed / 20)
    assert lim.max_jerk == (5e4, 5e4)  # the drive's own limits kept
    assert gm.reflected_inertia == pytest.approx(400 * 4.8e-6) and gm.rms_torque == 20 * 0.12


@pytest.mark.parametrize("doc, message", [
    ({"motor": [{"name": "a", "rated_torque": 0.1, "peak_torque": 0.3, "max_speed_rpm": 3000,
                 "rotor_inertia": 1.0, "mass": 0.2}]},
     r"motor catalogue 'c.toml': key \[\[motor\]\] 1 \(a\).price is required"),
    ({"motor": [{"name": "a", "rated_torque": 0.1, "peak_torque": 0.3, "max_speed_rpm": 3000,
                 "rotor_inertia": 1.0, "mass": 0.2, "price": 1, "knee_speed_rpm": 4000}]},
     r"\[\[motor\]\] 1 \(a\).knee_speed_rpm 4000 must be below max_speed_rpm 3000"),
    ({"motor": [{"name": "a", "rated_torque": 0.5, "peak_torque": 0.3, "max_speed_rpm": 3000,
                 "rotor_inertia": 1.0, "mass": 0.2, "price": 1}]},
     r"\[\[motor\]\] 1: motor 'a': peak torque 0.3 N m is below its rated torque 0.5"),
    ({"motor": [{"name": "a", "rated_torque": 0.1, "peak_torque": 0.3, "max_speed_rpm": 3000,
                 "rotor_inertia": 1.0, "mass": 0.2, "price": 1}] * 2},
     "motor name 'a' is listed twice"),
    ({"motors": []}, "'motors' is not known"),
    ({}, "lists no motor"),
])
def test_bad_catalogues_are_named(doc, message):
    with pytest.raises(ConfigError, match=message):
        catalogue_from_dict(doc, (1.0,), "motor catalogue 'c.toml'")


@pytest.mark.slow
def test_every_design_gets_the_lightest_motor_that_fits(example):
    """For a design of the example: the chosen motor and ratio fit (a plan made apart,
    with the limits and the reflected inertia written out by hand, gives the same cycle and
    fits), every lighter motor fails at every ratio, and no other ratio of the chosen motor
    fits with a shorter cycle."""
    sc, task, space = example
    design = space.designs()[2]
    ordered = task.catalogue.ordered("lightest")
    row = evaluate_design(task, design)
    assert row["feasible"], row["reason"]
    x = design_values(task, design)
    robot = FiveBar(*(x[k] for k in ("l1", "l2", "L1", "L2", "d"))).scaled(1e-3)
    base = inertia_of(task, robot, x)

    def plan(motor, ratio):
        inertia = base.with_(rotor=tuple(r + ratio**2 * motor.rotor_inertia
                                         for r in base.rotor))
        limits = MotorLimits((ratio * motor.peak_torque,) * 2, (motor.max_speed / ratio,) * 2,
                             None if motor.knee_speed is None else
                             (motor.knee_speed / ratio,) * 2)
        rms = ratio * motor.rated_torque
        try:
            res = ProgramRequest(robot, inertia, task.moves, task.start, task.working_mode,
                                 task.assembly, limits, (rms, rms), 500.0, task.grid,
                                 task.tolerances).plan()
        except InfeasibleError:
            return None, False
        return res, sizing(res).fits

    chosen = task.catalogue.motor(row["motor"])
    res, fits = plan(chosen, row["gear_ratio"])
    assert fits and res.cycle_time_s == pytest.approx(row["cycle_time_s"], rel=1e-12)
    assert row["motor_mass_kg"] == 2 * chosen.mass and row["motor_price"] == 2 * chosen.price
    for other in task.catalogue.ratios:
        if other != row["gear_ratio"]:
            r2, f2 = plan(chosen, other)
            assert not (f2 and r2.cycle_time_s < row["cycle_time_s"])
    lighter = ordered[:ordered.index(chosen)]
    assert len(lighter) >= 1  # measured: BL42-80W, after two lighter motors
    for motor in lighter:
        for ratio in task.catalogue.ratios:
            assert not plan(motor, ratio)[1], (motor.name, ratio)
    # the counterweights of the design are in the model, the shaking metrics are there
    assert counterweights_of(task, x)[0].mass == pytest.approx(x["counterweight_mass1"])
    assert row["shaking_force_N"] > row["rms_shaking_force_N"] > 0


@pytest.mark.slow
def test_a_cycle_fitted_to_the_ratings_takes_a_lighter_motor(example):
    """``[program].cycle = "fit-rms"`` reaches the sweep: each gearmotor's cycle is stretched
    to its RMS rating, so a lighter motor fits than under time-optimal moves as planned, and
    its RMS torque is within its rating."""
    sc, task, space = example
    design = space.designs()[2]
    planned = evaluate_design(task, design)
    fitted = evaluate_design(replace(task, cycle="fit-rms"), design)
    assert fitted["feasible"], fitted["reason"]
    light = task.catalogue.motor(fitted["motor"])
    assert light.mass < task.catalogue.motor(planned["motor"]).mass  # measured BL22 < BL42
    rating = fitted["gear_ratio"] * light.rated_torque
    assert max(fitted["rms_torque_A_Nm"], fitted["rms_torque_D_Nm"]) <= rating * (1 + 1e-3)
    assert fitted["cycle_time_s"] > planned["cycle_time_s"]  # the price: a slower cycle


def test_a_catalogue_with_no_motor_that_fits(example):
    """The smallest motor alone, direct drive: every design is refused, its reason naming
    the catalogue and the closest motor, the row still carrying its metrics."""
    sc, task, space = example
    small = Catalogue((task.catalogue.motors[0],), (1.0, 2.0), "the small catalogue")
    row = evaluate_design(replace(task, catalogue=small), space.designs()[1])
    assert not row["feasible"]
    assert re.search(r"no motor of the small catalogue (fits at any ratio; the closest, "
                     r"BL22-15W, ratio [12]|moves the task within its limits)", row["reason"]),\
        row["reason"]


def test_the_motor_as_a_design_variable(tmp_path):
    text = TASK_FILE.read_text().replace('motor_choice = "lightest"',
                                         'motor_choice = "search"')
    text = text.replace('"catalogue/servo_motors.toml"', f'"{CATALOGUE.as_posix()}"')
    path = tmp_path / "search.toml"
    path.write_text(text)
    task, space = load_scenario(path).design_task()
    assert space.columns[-2:] == ("motor_index", "ratio_index")
    designs = space.designs()
    idx = designs[:, -2:]
    assert np.all(idx == np.floor(idx)) and idx[:, 0].max() <= 4 and idx[:, 1].max() <= 3
    assert len(set(idx[:, 0])) > 2  # the sampling spreads over the catalogue
    row = evaluate_design(task, designs[3])
    assert row["motor"] == task.catalogue.motors[int(idx[3, 0])].name
    assert row["gear_ratio"] == task.catalogue.ratios[int(idx[3, 1])]


def run_design(tmp_path, task_text, capsys):
    path = tmp_path / "t.toml"
    path.write_text(task_text)
    code = main(["design", str(path), "--out", str(tmp_path / "o"), "--workers", "1"])
    return code, capsys.readouterr().err.strip()


@pytest.mark.parametrize("change, message", [
    (('motors = "catalogue/servo_motors.toml"', 'motors = "nowhere.toml"'),
     r"config file '.*nowhere.toml' does not exist"),
    (('motors = "catalogue/servo_motors.toml"\n', ''),
     r"\[design\].ratios needs \[design\].motors"),
    (('ratios = [5, 10, 20, 40]', 'ratios = [5, 0]'), r"\[design\].ratios: 0 must be a positive number"),
    (('motor_choice = "lightest"', 'motor_choice = "best"'),
     r"\[design\].motor_choice must be one of lightest, cheapest, search"),
    (('counterweight_distance = [10.0, 40.0] # mm behind the motor axes\n', ''), None),
])
def test_bad_motor_and_counterweight_keys_exit_2(tmp_path, capsys, change, message):
    text = TASK_FILE.read_text().replace(*change)
    text = text.replace('"catalogue/servo_motors.toml"', f'"{CATALOGUE.as_posix()}"')
    if message is None:  # the task's own distance is used: a valid task
        text = text.replace("samples = 64", "samples = 1")
        path = tmp_path / "ok.toml"
        path.write_text(text)
        task, space = load_scenario(path).design_task()
        assert space.fixed[7] == 20.0 and "counterweight_distance" not in [d[0] for d in space.dims]
        # and without the task's distance either, the mass range is refused by name
        text = text.replace("counterweight_distance = 20.0   # mm behind the motor axes\n", "")
        text = text.replace("counterweight_mass = 0.02  # kg: the task's own counterweights\n",
                            "")
        message = r"\[design\].counterweight_mass needs a distance"
    code, err = run_design(tmp_path, text, capsys)
    assert code == 2 and len(err.splitlines()) == 1 and re.search(message, err), err
    assert not (tmp_path / "o").exists()


def test_objectives_on_motors_need_a_catalogue(tmp_path, capsys):
    from .test_design import TASK

    text = TASK.replace("samples = 32", 'objectives = ["motor_price"]\nsamples = 4')
    code, err = run_design(tmp_path, text, capsys)
    assert code == 2 and "'motor_price' needs a motor catalogue ([design].motors)" in err


@pytest.mark.slow
def test_the_example_sweeps_and_best_toml_names_the_motor(tmp_path, scheduler):
    """The design job on the example (4 designs varying d and the counterweights' mass, two
    of its ratios, a coarser grid; the job without the command's figures, which take most
    of a command's time here): the rows carry the counterweights, the motor and the shaking
    metrics and go through designs.csv's lines unchanged; best.toml holds the chosen motor's
    joint limits, its ratio and its reflected rotor inertia, and loads as a config whose
    model is the design's."""
    import json

    from dextar import jobs
    from dextar.output.design import header, parse_line, row_line

    text = TASK_FILE.read_text().replace("ratios = [5, 10, 20, 40]", "ratios = [20, 40]")
    text = text.replace("grid = 40", "grid = 20").replace("samples = 64", "samples = 4")
    text = text.replace('"catalogue/servo_motors.toml"', f'"{CATALOGUE.as_posix()}"')
    for line in ("l = [60.0, 110.0]", "L = [80.0, 140.0]", "counterweight_distance = [10.0"):
        text = "\n".join(x for x in text.splitlines() if not x.startswith(line)) + "\n"
    path = tmp_path / "t.toml"
    path.write_text(text)
    sweep = jobs.design_sweep(load_scenario(path))
    res = jobs.design(sweep, scheduler=scheduler)
    variables = sweep.space.columns
    assert variables[5:] == ("counterweight_mass1", "counterweight_mass2",
                             "counterweight_distance1", "counterweight_distance2")
    assert header(variables).startswith("design,l1_mm,l2_mm,L1_mm,L2_mm,d_mm,"
                                        "counterweight_mass1_kg,counterweight_mass2_kg,"
                                        "counterweight_distance1_mm,")
    for r in res.rows:
        assert parse_line(row_line(r), variables) == r
    feasible = [r for r in res.rows if r["feasible"]]
    assert feasible and all(r["motor"] and r["shaking_force_N"] > 0 for r in feasible)
    best = res.best
    assert best is not None and res.best_toml is not None
    out = tmp_path / "best.toml"
    out.write_text(res.best_toml)
    written = tomllib.loads(res.best_toml)
    motor = read_catalogue(CATALOGUE).motor(best["motor"])
    n = best["gear_ratio"]
    assert f"# motors: {motor.name} on both joints, gear ratio {n:g}" in res.best_toml
    assert written["drive"]["gear_ratio"] == n
    assert written["motors"]["peak_torque"] == pytest.approx(n * motor.peak_torque)
    assert written["motors"]["max_speed_rpm"] == pytest.approx(
        motor.max_speed / n * 60 / (2 * math.pi))
    assert written["inertia"]["rotor_inertia"][0] == pytest.approx(
        n * n * motor.rotor_inertia * 1e6)
    assert written["inertia"]["counterweight_mass"][0] == pytest.approx(
        best["counterweight_mass1"])
    sc = load_scenario(out)
    assert sc.si_model.inertia.counterweights[0].distance == pytest.approx(0.02)
    assert best["counterweight_distance1"] == 20.0  # the task's, not varied here
    assert sc.si_motors.peak_torque[0] == pytest.approx(n * motor.peak_torque)
    json.dumps(best, allow_nan=False)  # the summary's best row is JSON


def test_random_counterweight_and_motor_tables_are_read_or_refused_by_name(tmp_path):
    """40 random [design] tables of counterweight and motor keys (a seeded draw, most of
    them valid): each gives a design space whose first design evaluates to a row that goes
    through its CSV line unchanged, or is refused with a ConfigError naming the key; both
    happen (counted)."""
    import random

    from dextar.design.evaluate import evaluate_chunk
    from dextar.output.design import parse_line, row_line

    from ..robustness.harness import toml_text
    from .test_design import TASK

    base = {k: v for k, v in tomllib.loads(TASK).items() if k != "design"}
    good = [[0.0, 0.1], [0.01, 0.05], [5.0, 30.0], [0.0, 40.0]]
    bad = [[0.1, 0.0], [-1.0, 1.0], [0.5, 0.5], [float("nan"), 1.0], "x"]
    rng = random.Random(7)

    def draw_range():
        return rng.choice(bad) if rng.random() < 0.1 else rng.choice(good)

    outcomes = {"read": 0, "refused": 0, "evaluated": 0}
    for case in range(40):
        table = {"l": [60.0, 90.0], "samples": 2}
        kind = rng.choices(["none", "both", "legs", "lone", "twice"], [3, 6, 3, 1, 1])[0]
        if kind in ("both", "twice"):
            table.update(counterweight_mass=draw_range(), counterweight_distance=draw_range())
        if kind == "twice":  # a leg's range beside both legs' range: refused
            table["counterweight_mass1"] = draw_range()
        if kind == "legs":
            table.update(counterweight_mass1=draw_range(), counterweight_distance=draw_range())
        if kind == "lone":  # a mass with no distance anywhere: refused
            table["counterweight_mass2"] = draw_range()
        motors = rng.random() < 0.6
        if motors:
            table["motors"] = rng.choice([CATALOGUE.as_posix()] * 6 + ["nowhere.toml"])
        if rng.random() < (0.6 if motors else 0.1):
            table["ratios"] = rng.choice([[5, 10], [1], [20.0, 40.0], [5, 10], [0], [2, 2]])
        if rng.random() < (0.6 if motors else 0.1):
            table["motor_choice"] = rng.choice(["search", "search", "lightest", "best"])
        path = tmp_path / f"t{case}.toml"
        path.write_text(toml_text({**base, "design": table}))
        try:
            task, space = load_scenario(path).design_task()
        except ConfigError as exc:
            assert re.search(r"\[design\]|catalogue|config file", str(exc)), exc
            outcomes["refused"] += 1
            continue
        outcomes["read"] += 1
        designs = space.designs()
        assert designs.shape == (2, len(space.columns)) and np.isfinite(designs).all()
        if task.catalogue is not None and task.motor_choice != "search":
            continue  # up to 20 plans a design: the example's tests cover them
        for row in evaluate_chunk(task, designs[:1], 0):
            assert parse_line(row_line(row), space.columns) == row
            assert not row["reason"].startswith("internal error"), row["reason"]
            outcomes["evaluated"] += 1
    assert min(outcomes.values()) >= 5, outcomes
