"""The suite's order for the xdist workers: ``--dist loadfile`` (pyproject) sends whole files
to the workers in collection order (``--no-loadscope-reorder`` keeps that order), and
pytest-randomly shuffles it. The files go out by their share of tests marked ``slow``, the
largest first (a file of slow tests only, then one with some, the files without any last):
longest-processing-time scheduling with the lengths read from the marks, so that no long
file starts last while the other worker idles. Nothing here is kept by hand: marking a test
slow moves its file. Within a rank the random order stands."""

from collections import Counter

import pytest


def _file(item: pytest.Item) -> str:
    return item.nodeid.split("::")[0]


@pytest.hookimpl(trylast=True)  # after pytest-randomly's shuffle and -m's deselection
def pytest_collection_modifyitems(items):
    tests = Counter(_file(item) for item in items)
    slow = Counter(_file(item) for item in items if item.get_closest_marker("slow"))
    items.sort(key=lambda item: -slow[_file(item)] / tests[_file(item)])  # stable
