import pytest

#: Test files that share a costly module or session fixture: each group runs on one xdist
#: worker (``--dist loadgroup``), so the fixture is computed once.
GROUPS = {"tests/test_run.py": "run", "tests/cli/test_cli_identification.py": "excite",
          "tests/cli/test_traps.py": "excite", "tests/program/test_drive_limits.py": "drive",
          "tests/program/test_program.py": "program",
          "tests/cli/test_cli_calibration.py": "calibration"}


def pytest_collection_modifyitems(items):
    for item in items:
        path = str(item.fspath).replace("\\", "/")
        for suffix, group in GROUPS.items():
            if path.endswith(suffix):
                item.add_marker(pytest.mark.xdist_group(group))
