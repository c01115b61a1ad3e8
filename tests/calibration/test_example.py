"""The calibration example tells its story and checks itself."""

import runpy
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.mark.slow
def test_calibration_script_runs(capsys):
    runpy.run_path(str(EXAMPLES / "calibrate_synthetic.py"), run_name="__main__")
    assert "calibration checks passed" in capsys.readouterr().out
