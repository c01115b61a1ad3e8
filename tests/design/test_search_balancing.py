"""Issue 32's two halves together: an nsga2 search over the counterweights and the catalogue's
motor and ratio (motor_choice = "search"), by the design job on the session's workers: the rows
carry every variable (whole-number motor and ratio indices, the motor they name), designs.csv
resumes on every column (a resumed row whose counterweight differs from the design the search
proposes is refused), best.toml names the chosen motor and counterweights."""

import tomllib
from pathlib import Path

import numpy as np
import pytest

from dextar.config import load_scenario
from dextar.design.space import COUNTERWEIGHTS, MOTOR_COLUMNS
from dextar.errors import ConfigError
from dextar.output.design import DESIGN_FILES, DesignsFile, parse_line
from dextar.output.files import OutputDir

pytest.importorskip("distributed")
pytest.importorskip("pymoo")

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
CATALOGUE = EXAMPLES / "catalogue" / "servo_motors.toml"


def search_task(folder: Path) -> Path:
    """examples/design_motors.toml as a small search: 8 designs (population 4), the motor
    and ratio as variables, two ratios, a coarse grid, the geometry fixed but for d."""
    text = (EXAMPLES / "design_motors.toml").read_text()
    text = text.replace('"catalogue/servo_motors.toml"', f'"{CATALOGUE.as_posix()}"')
    text = text.replace('motor_choice = "lightest"', 'motor_choice = "search"')
    text = text.replace("ratios = [5, 10, 20, 40]", "ratios = [20, 40]")
    text = text.replace("grid = 40", "grid = 20")
    text = text.replace("samples = 64",
                        'search = "nsga2"\npopulation = 4\nevaluations = 8')
    for line in ("l = [60.0, 110.0]", "L = [80.0, 140.0]"):
        text = "\n".join(x for x in text.splitlines() if not x.startswith(line)) + "\n"
    path = folder / "search_motors.toml"
    path.write_text(text)
    return path


def searched(sweep, out: Path, scheduler: str, *, resume: bool):
    """The design job on ``out``'s designs.csv as the command runs it (without the figures,
    most of a command's time here)."""
    from dextar import jobs

    with OutputDir(out, keep=resume, produces=DESIGN_FILES) as od:
        store = DesignsFile(od, None, sweep.signature, resume=resume, label=str(out),
                            variables=sweep.space.columns)
        return jobs.design(sweep, scheduler=scheduler, store=store)


@pytest.mark.slow
def test_a_search_over_counterweights_and_motors(tmp_path, scheduler):
    from dextar import jobs

    sweep = jobs.design_sweep(load_scenario(search_task(tmp_path)))
    variables = sweep.space.columns
    assert sweep.search is not None and variables[5:] == COUNTERWEIGHTS + MOTOR_COLUMNS
    out = tmp_path / "out"
    res = searched(sweep, out, scheduler, resume=False)
    lines = (out / "designs.csv").read_text().splitlines(keepends=True)
    assert lines[0].startswith("design,l1_mm,l2_mm,L1_mm,L2_mm,d_mm,counterweight_mass1_kg,")
    rows = [parse_line(x, variables) for x in lines[1:]]
    assert rows == res.rows and [r["design"] for r in rows] == list(range(8))
    catalogue = sweep.task.catalogue
    idx = np.array([[r["motor_index"], r["ratio_index"]] for r in rows])
    assert np.all(idx == np.floor(idx)) and idx[:, 0].max() < len(catalogue.motors)
    planned = [r for r in rows if r["motor"]]  # a design planned names its motor
    assert len(planned) >= 4, [r["reason"] for r in rows]
    for r in planned:  # the motor a row names is the one its index picks
        assert r["motor"] == catalogue.motors[int(r["motor_index"])].name
        assert r["gear_ratio"] == catalogue.ratios[int(r["ratio_index"])]
    for r in rows:
        assert 0.0 <= r["counterweight_mass1"] <= 0.15 and \
            10.0 <= r["counterweight_distance1"] <= 40.0
    # the search proposes over the counterweights (tied: one range for both rods)
    assert len({r["counterweight_mass1"] for r in rows}) == 8

    # a resume of the finished search evaluates nothing and writes the same file
    before = (out / "designs.csv").read_bytes()
    again = searched(sweep, out, scheduler, resume=True)
    assert again.stats.evaluated == 0 and (out / "designs.csv").read_bytes() == before

    # a row whose counterweight is not the proposed design's is refused on resume
    cells = lines[3].split(",")
    cells[6] = repr(float(cells[6]) + 0.01)
    (out / "designs.csv").write_text("".join(lines[:3]) + ",".join(cells)
                                     + "".join(lines[4:]))
    with pytest.raises(ConfigError, match="design 2 in .* is not the design this search"):
        searched(sweep, out, scheduler, resume=True)

    best = res.best
    if best is not None:  # best.toml names the motor and the counterweights it chose
        assert f"# motors: {best['motor']} on both joints" in res.best_toml
        written = tomllib.loads(res.best_toml)
        assert written["inertia"]["counterweight_mass"][0] == pytest.approx(
            best["counterweight_mass1"])
