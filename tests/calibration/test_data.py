"""Reading measured poses: every bad input is named with its row or column."""

import numpy as np
import pytest

from dextar.calibration import read_poses_csv
from dextar.calibration.data import PoseData, poses_from_arrays
from dextar.errors import ConfigError, ParameterError
from dextar.output.calibration import poses_csv

HEAD = "phi_deg,psi_deg,x_mm,y_mm,mode,assembly,sigma_mm\n"


def _write(tmp_path, text, name="m.csv"):
    p = tmp_path / name
    p.write_text(text)
    return p


def test_a_poses_file_reads_back_in_si(tmp_path, four_modes):
    p = _write(tmp_path, poses_csv(four_modes))
    d = read_poses_csv(p)
    np.testing.assert_allclose(d.readings, four_modes.readings, atol=1e-15)
    np.testing.assert_allclose(d.points, four_modes.points, atol=1e-15)
    assert d.modes == four_modes.modes
    assert (d.assembly == 1).all() and d.sigma is None
    assert d.rows.tolist() == list(range(2, len(four_modes) + 2))


def test_optional_columns_aliases_and_blank_assembly(tmp_path):
    p = _write(tmp_path, HEAD + "60,120,0,120,pm,,0.02\n50,110,1,119,--,down,0.03\n")
    d = read_poses_csv(p)
    assert d.modes == ("+-", "--")
    assert d.assembly.tolist() == [0, -1]
    np.testing.assert_allclose(d.sigma, [2e-5, 3e-5])
    p = _write(tmp_path, "phi_deg,psi_deg,x_mm,y_mm\n60,120,0,120\n")
    assert read_poses_csv(p, working_mode="mp").modes == ("-+",)


@pytest.mark.parametrize("text, error, words", [
    ("phi_deg,x_mm\n1,2\n", ConfigError, "lacks the columns psi_deg, y_mm"),
    ("phi_deg,psi_deg,x_mm,y_mm\n1,2,3,4\n", ConfigError, "no mode column"),
    (HEAD + "60,120,0,120,+-,up,0.02\n60,nan,0,120,+-,up,0.02\n1,2,inf,4,+-,up,0.02\n",
     ParameterError, "NaN or infinite at row 3"),
    (HEAD + "60,120,0,120,+-,up,0.02\n60,120,x,120,+-,up,0.02\n", ParameterError,
     "row 3, column x_mm: 'x' is not a number"),
    (HEAD + "60,120,0,120,+x,up,0.02\n", ParameterError, "row 2, column mode: '\\+x'"),
    (HEAD + "60,120,0,120,+-,left,0.02\n", ParameterError, "row 2, column assembly"),
    (HEAD + "60,120,0,120,+-,up,0\n", ParameterError, "sigma_mm must be positive.*row 2"),
    (HEAD + "60,120,0,120,+-,up\n", ParameterError, "row 2 has 6 fields"),
    (HEAD, ParameterError, "no poses"),
    ("", ConfigError, "is empty"),
])
def test_bad_files_are_named(tmp_path, text, error, words):
    with pytest.raises(error, match=words):
        read_poses_csv(_write(tmp_path, text))


def test_nan_rows_all_listed_and_missing_file(tmp_path):
    rows = ["60,120,0,120,+-,up,0.02"] * 9 + ["nan,1,1,1,+-,up,0.02"] * 7
    with pytest.raises(ParameterError, match=r"row 11, 12, 13, 14, 15 and 2 more"):
        read_poses_csv(_write(tmp_path, HEAD + "\n".join(rows) + "\n"))
    with pytest.raises(ConfigError, match="cannot be read"):
        read_poses_csv(tmp_path / "none.csv")


def test_arrays_in_file_units_and_subsets():
    d = poses_from_arrays([[60, 120], [50, 110]], [[0, 120], [1, 119]], "+-",
                          assembly=["up", "down"], sigma_mm=0.02)
    assert d.assembly.tolist() == [1, -1]
    np.testing.assert_allclose(d.points, [[0, 0.12], [0.001, 0.119]])
    s = d.subset(np.array([False, True]))
    assert len(s) == 1 and s.rows.tolist() == [3]
    with pytest.raises(ParameterError, match="2 working modes for 3 poses"):
        PoseData(np.zeros((3, 2)), np.zeros((3, 2)), ("+-", "+-"), 0)
