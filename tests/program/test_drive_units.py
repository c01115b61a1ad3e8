"""The drive files say only what a drive can run: PVT points at the drive's period to the
end, whole numbers where a drive or a reader expects them, and a torque feedforward above the
rated torque named (a warning), beyond the drive's own limit a program that does not fit.

The pick-and-place example with the XH430's gearbox: its peak torque feedforward is 0.00549
N m at motor D, 477 per-mille of a rated torque of 0.0115 N m and 1568 per-mille of 0.0035."""

import json
from dataclasses import replace

import numpy as np
import pytest

from dextar.cli import main
from dextar.config import load_scenario
from dextar.program.drive import DriveUnits, hermite, pvt_points, torque_checks

from .test_drive_limits import DRIVE, columns, task


@pytest.fixture(scope="session")
def planned(tmp_path_factory):
    d = tmp_path_factory.mktemp("drive_units")
    cfg = d / "pp.toml"
    cfg.write_text(task("", DRIVE))
    sc = load_scenario(str(cfg))
    return sc.program_request().plan(), sc.drive()


def test_pvt_points_keep_the_period_to_the_end(planned):
    """The cycle ends at 1.705 s: the last interval was 5 ms of the 10 ms period; now a
    point at 1.71 s holds the final pose at rest, as the setpoints hold it."""
    res, drive = planned
    pvt = pvt_points(res, drive)
    assert np.allclose(np.diff(pvt.t), 0.01, rtol=0, atol=1e-12)
    assert pvt.t[-1] >= res.t[-1] and pvt.t[-1] - res.t[-1] < 0.01
    assert (pvt.pos[-1] == np.round(drive.counts(res.q[-1:]))[0]).all()
    assert (pvt.vel[-1] == 0).all() and np.abs(res.dq[-1]).max() == 0
    # the reported error covers every tick, the held ones included
    tick = res.t[1] - res.t[0]
    ts = np.arange(int(round(pvt.t[-1] / tick)) + 1) * tick
    plan = drive.counts(res.q[np.minimum(np.arange(len(ts)), len(res.t) - 1)])
    err = np.abs(hermite(ts, pvt.t, pvt.pos, pvt.vel) - plan).max()
    assert err == pytest.approx(pvt.max_error_counts, rel=1e-9)


def test_a_period_that_is_not_whole_ticks_is_refused(planned):
    """2.5 ms at a 1 ms servo tick was written as points every 2 ms."""
    res, drive = planned
    from dextar.errors import ParameterError

    with pytest.raises(ParameterError, match=r"PVT period 2.5 ms is not a whole number of "
                                             r"servo ticks \(1 ms\).*e\.g\. 2 ms"):
        pvt_points(res, replace(drive, pvt_period=0.0025))
    assert np.allclose(np.diff(pvt_points(res, replace(drive, pvt_period=0.002)).t), 0.002)


def test_torque_above_the_rating_is_named_beyond_the_drive_limit_a_violation(planned):
    res, drive = planned
    assert torque_checks(res, drive) == ([], [])          # 477 per-mille: nothing to say
    weak = replace(drive, rated_torque=(0.0035, 0.0035))
    over, notes = torque_checks(res, weak)
    assert over == [] and len(notes) == 2                  # A 1066, D 1568 per-mille
    assert "motor D's torque feedforward reaches 1568 per-mille of its rated torque 0.0035 " \
           "N m" in notes[1] and "above its rating (1000 per-mille)" in notes[1]
    over, notes = torque_checks(res, replace(weak, max_torque_permille=(1200.0, 1200.0)))
    assert [(v.motor, v.value, v.limit) for v in over] == [("D", 1568.0, 1200.0)]
    assert len(notes) == 1 and "within the drive's 1200" in notes[0]
    over, _ = torque_checks(res, replace(weak, max_torque_permille=(1600.0, 1600.0)))
    assert over == []


def _run(tmp_path, capsys, drive, name="o", extra=("--quiet",)):
    cfg = tmp_path / "pp.toml"
    cfg.write_text(task("", drive))
    out = tmp_path / name
    code = main(["program", "--no-figures", str(cfg), "--out", str(out), *extra])
    text = capsys.readouterr()
    return code, text.err + text.out, out


def test_the_program_exits_1_beyond_the_drive_limit(tmp_path, capsys):
    """A feedforward of 1568 per-mille passed without a word, exit 0, "fits"."""
    weak = DRIVE.replace("0.0115", "0.0035")
    code, err, out = _run(tmp_path, capsys, weak + "max_torque_permille = 1200\n")
    s = json.loads((out / "summary.json").read_text())
    assert code == 1 and s["status"] == "exceeds", err
    assert s["violations"][0]["motor"] == "D" and s["violations"][0]["value"] == 1568
    assert "motor D torque feedforward (per-mille of the rated torque 0.0035 N m) 1568 " \
           "above the drive's limit 1200 ([drive].max_torque_permille)" in err
    assert s["drive"]["motors"][1]["max_torque_permille"] == 1200
    assert (out / "csp.csv").exists() and (out / "pvt.csv").exists()
    # the headline said "exceeds the motors": the motors' own limits hold, the drive's does not
    code, said, _ = _run(tmp_path, capsys, weak + "max_torque_permille = 1200\n", "o3", ())
    assert code == 1 and "exceeds the drives" in said and "exceeds the motors" not in said
    # within the rating and without a limit: exit 0, a warning only above the rating
    code, err, _ = _run(tmp_path, capsys, weak, "o2")
    assert code == 0 and "warning: motor D's torque feedforward reaches 1568 per-mille" in err
    code, said, _ = _run(tmp_path, capsys, weak, "o4", ())
    assert code == 0 and "fits the motors and the drives" in said


def test_whole_numbers_are_written_as_whole_numbers(tmp_path, capsys):
    """setpoints.csv's move was written 0.0, 1.0, ...; counts and per-mille stay whole."""
    code, err, out = _run(tmp_path, capsys, DRIVE)
    assert code == 0, err
    for name, whole in (("setpoints", ("move",)),
                        ("csp", ("pos1_counts", "pos2_counts", "torque1_permille",
                                 "torque2_permille")),
                        ("pvt", ("pos1_counts", "pos2_counts"))):
        lines = (out / f"{name}.csv").read_text().splitlines()
        head = lines[0].split(",")
        for col in whole:
            i = head.index(col)
            cells = [line.split(",")[i] for line in lines[1:]]
            assert all(c.lstrip("-").isdigit() for c in cells), (name, col, cells[:3])
    moves = columns(out / "setpoints.csv")["move"]
    assert moves[0] == 0 and moves[-1] == 7 and np.all(np.diff(moves) >= 0)


@pytest.mark.parametrize("period_ms", [7, 3, 10])
def test_pvt_times_are_whole_periods_as_written(tmp_path, capsys, period_ms):
    """Review 28 finding 14: the last PVT time was the sum of rounded times (1.7080000000000002
    s at a 7 ms period, 1.7069999999999999 at 3 ms); every time is now its whole number of
    servo ticks over the servo rate, as the setpoints' are: each written time, read as a
    decimal, is a whole number of periods, the points one period apart, the last at or after
    the cycle's last tick."""
    from decimal import Decimal

    code, err, out = _run(tmp_path, capsys,
                          DRIVE.replace("pvt_period_ms = 10", f"pvt_period_ms = {period_ms}"))
    assert code == 0, err
    lines = (out / "pvt.csv").read_text().splitlines()
    i = lines[0].split(",").index("t_s")
    written = [Decimal(line.split(",")[i]) for line in lines[1:]]
    period = Decimal(period_ms) / 1000
    assert [t / period for t in written] == list(range(len(written)))
    last = Decimal(repr(float(columns(out / "setpoints.csv")["t_s"][-1])))
    assert written[-1] >= last > written[-1] - period


@pytest.mark.parametrize("drive, words", [
    (DRIVE.replace("rated_torque_Nm = 0.0115\n", "") + "max_torque_permille = 1200\n",
     "[drive].max_torque_permille needs [drive].rated_torque_Nm"),
    (DRIVE + "max_torque_permille = 0\n", "[drive].max_torque_permille must be positive"),
    (DRIVE.replace("pvt_period_ms = 10", "pvt_period_ms = 2.5"),
     "PVT period 2.5 ms is not a whole number of servo ticks"),
])
def test_bad_drive_input_exit_2(tmp_path, capsys, drive, words):
    code, err, out = _run(tmp_path, capsys, drive)
    assert code == 2 and err.count("\n") == 1 and words in err, err
    assert not out.exists()


def test_drive_units_refuse_a_limit_without_a_rating():
    from dextar.errors import ParameterError

    with pytest.raises(ParameterError, match="needs the rated torque"):
        DriveUnits(max_torque_permille=(1200.0, 1200.0))
