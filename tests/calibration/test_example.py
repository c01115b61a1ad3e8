"""The calibration example tells its story and checks itself."""

import runpy
from pathlib import Path

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


def test_calibration_script_runs(capsys):
    runpy.run_path(str(EXAMPLES / "calibrate_synthetic.py"), run_name="__main__")
    assert "calibration checks passed" in capsys.readouterr().out
