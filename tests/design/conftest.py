"""One local Dask cluster (two worker processes) for the design tests of a test session;
the tests that need a cluster of their own (one that loses a worker, the `dask` command line,
one worker) start it themselves."""

import pytest

distributed = pytest.importorskip("distributed")


@pytest.fixture(scope="session")
def scheduler():
    """The address of the session's cluster."""
    cluster = distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                       dashboard_address=":0")
    try:
        yield cluster.scheduler_address
    finally:
        cluster.close()
