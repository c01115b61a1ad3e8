"""The suite's order for two xdist workers: ``--dist loadfile`` (pyproject) sends whole files
to the workers in collection order, and pytest-randomly shuffles that order; the longest
files go first (longest-processing-time scheduling), so that no long file starts last while
the other worker idles. Within each rank the random order stands."""

import pytest

#: The longest files, longest first (seconds on a 2-core machine, 2026-12-02: design 45,
#: identification CLI 20, robustness 18, traps 11, run 9, examples 6, MuJoCo 6, calibration
#: CLI 5, program 5, identify 5).
LONGEST = ("tests/design/test_design.py", "tests/cli/test_cli_identification.py",
           "tests/robustness/test_robustness.py", "tests/cli/test_traps.py",
           "tests/test_run.py", "tests/test_examples.py",
           "tests/identification/test_mujoco_identification.py",
           "tests/cli/test_cli_calibration.py", "tests/program/test_program.py",
           "tests/identification/test_identify.py")


@pytest.hookimpl(trylast=True)  # after pytest-randomly's shuffle
def pytest_collection_modifyitems(items):
    rank = {name: i for i, name in enumerate(LONGEST)}

    def key(item):
        return rank.get(item.nodeid.split("::")[0], len(LONGEST))

    items.sort(key=key)  # stable: the shuffle stands within a rank
