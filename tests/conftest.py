"""The suite's order for the xdist workers: ``--dist loadfile`` (pyproject) sends whole files
to the workers in collection order (``--no-loadscope-reorder`` keeps that order), and
pytest-randomly shuffles it. The files that hold tests marked ``slow`` go first, so that no
long file starts last while the other worker idles (longest-processing-time scheduling, the
lengths read from the marks: nothing here is kept by hand; a test marked slow moves its
file). Within each rank the random order stands."""

import pytest


def _file(item: pytest.Item) -> str:
    return item.nodeid.split("::")[0]


@pytest.hookimpl(trylast=True)  # after pytest-randomly's shuffle and -m's deselection
def pytest_collection_modifyitems(items):
    slow = {_file(item) for item in items if item.get_closest_marker("slow")}
    items.sort(key=lambda item: _file(item) not in slow)  # stable: the shuffle stands
