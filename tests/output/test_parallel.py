"""Rendering shared with a forked child: the same results as in turn, errors raised here."""

import os
import sys

import pytest

from dextar.errors import ParameterError
from dextar.output.parallel import render

fork_only = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="fork on Linux")


def _jobs():
    # each job says where it ran: the shared run must use two processes and agree otherwise
    # (each takes 50 ms, so that the child, started a few ms later, finds jobs left)
    import time

    return {f"j{k}": (lambda k=k: (time.sleep(0.05), (k * k, os.getpid()))[1],
                      float(k % 3 + 1)) for k in range(7)}


@fork_only
def test_two_processes_give_what_one_gives_in_the_jobs_order():
    one = render(_jobs(), workers=1)
    two = render(_jobs(), workers=2)
    assert list(two) == list(_jobs()) == list(one)
    assert {k: v[0] for k, v in two.items()} == {k: v[0] for k, v in one.items()}
    assert {pid for _, pid in one.values()} == {os.getpid()}
    assert len({pid for _, pid in two.values()}) == 2  # shared with a child


@fork_only
def test_the_processes_share_the_jobs_as_they_come_free():
    """Jobs taken from one queue, the costliest first: a job slower than its cost says (here
    the first, 0.6 s against costs that call the others as slow) keeps its process while the
    other takes the rest, so the run takes about the longest job, not the sum of a fixed
    half."""
    import time

    def sleep(s):
        return lambda: (time.sleep(s), os.getpid())[1]

    jobs = {"slow": (sleep(0.6), 3.0), **{f"j{k}": (sleep(0.1), 2.0) for k in range(5)}}
    t0 = time.perf_counter()
    out = render(jobs, workers=2)
    took = time.perf_counter() - t0
    assert list(out) == list(jobs)
    assert len(set(out.values())) == 2  # both processes worked
    assert sum(pid == out["slow"] for pid in out.values()) <= 2  # the slow one's process
    assert took < 1.0  # the sum is 1.1 s, a split by cost (3 + 2 | 2 + 2 + 2) 0.8 s


@fork_only
def test_a_job_failing_in_the_child_raises_its_error_here():
    calls = []

    def bad():
        calls.append(os.getpid())
        raise ParameterError("job 'bad' cannot be drawn")

    def slow():
        import time

        time.sleep(0.3)  # this process is busy with it while the child takes "bad"
        return 0

    jobs = {"slow": (slow, 10.0), "bad": (bad, 5.0)}
    with pytest.raises(ParameterError, match="job 'bad' cannot be drawn"):
        render(jobs, workers=2)
    assert calls == [os.getpid()]  # the child's failure is redone (and raised) here


@fork_only
def test_a_child_that_dies_is_replaced_by_this_process():
    import time

    def dies():
        if os.getpid() != parent:
            os._exit(3)  # a child killed mid-job
        return "drawn here"

    def slow():
        time.sleep(0.3)  # this process is busy with it while the child takes "dies"
        return 1

    parent = os.getpid()
    jobs = {"slow": (slow, 10.0), "dies": (dies, 5.0)}
    assert render(jobs, workers=2) == {"slow": 1, "dies": "drawn here"}


@fork_only
def test_an_interrupt_held_by_the_fork_ends_the_child(monkeypatch):
    """An interrupt that comes while the child is forked waits until the fork is done, is
    raised here, and the child is ended with this process's work (none left running)."""
    import multiprocessing
    import os
    import signal
    import time
    from multiprocessing.process import BaseProcess

    start = BaseProcess.start

    def start_then_interrupt(self):
        start(self)
        os.kill(os.getpid(), signal.SIGINT)  # held: the mask is on while forking

    monkeypatch.setattr(BaseProcess, "start", start_then_interrupt)

    def slow():
        time.sleep(3)
        return 1

    before = {p.pid for p in multiprocessing.active_children()}  # (other tests' clusters)
    with pytest.raises(KeyboardInterrupt):
        render({"a": (slow, 1.0), "b": (slow, 1.0)}, workers=2)
    assert {p.pid for p in multiprocessing.active_children()} <= before


@fork_only
def test_forked_work_runs_in_a_child_while_this_process_goes_on():
    import time

    from dextar.output.parallel import Forked

    t0 = time.perf_counter()
    with Forked(lambda: (time.sleep(1.0), os.getpid())[1], enabled=True) as child:
        here = time.perf_counter() - t0  # the block goes on at once
        pid = child.result()
        assert child.result() == pid  # computed once
    assert here < 0.6
    assert pid != os.getpid()
    with Forked(os.getpid, enabled=False) as inline:  # no child: the work runs at result()
        assert inline.result() == os.getpid()


@fork_only
def test_forked_work_that_fails_in_the_child_is_redone_and_raised_here():
    from dextar.output.parallel import Forked

    calls = []

    def bad():
        calls.append(os.getpid())
        raise ParameterError("validation failed at t = 0.5 s")

    with Forked(bad) as child, pytest.raises(ParameterError, match="t = 0.5 s"):
        child.result()
    assert calls == [os.getpid()]  # (the child's own call is in the child's memory)


@fork_only
def test_leaving_the_block_early_ends_the_child():
    import multiprocessing
    import time

    from dextar.output.parallel import Forked

    before = {p.pid for p in multiprocessing.active_children()}
    with pytest.raises(RuntimeError, match="this process failed"):
        with Forked(lambda: time.sleep(30)):
            raise RuntimeError("this process failed")
    assert {p.pid for p in multiprocessing.active_children()} <= before


@fork_only
def test_what_the_child_finished_before_a_job_failed_is_kept():
    """The child stops at a failing job (here its second: every job fails in the child
    after its first); that job and the rest run here, where an error would be raised, and
    the job the child finished is neither lost nor run twice."""
    import time

    ran = []  # each process's own list: the jobs it ran

    def job(k):
        def run():
            time.sleep(0.05)
            if os.getpid() != parent and ran:
                raise ParameterError(f"job {k} failed in the child")
            ran.append(k)
            return (k, os.getpid())
        return run

    parent = os.getpid()
    jobs = {f"j{k}": (job(k), 10.0 - k) for k in range(8)}
    out = render(jobs, workers=2)
    assert [v[0] for v in out.values()] == list(range(8))
    theirs = [k for k, pid in out.values() if pid != parent]
    assert len(theirs) == 1  # the one the child finished, kept
    assert sorted(ran) == sorted(set(range(8)) - set(theirs))  # the rest, each once here


@fork_only
def test_no_fork_to_be_had_runs_the_work_here(monkeypatch):
    from multiprocessing.process import BaseProcess

    from dextar.output.parallel import Forked

    def cannot(self):
        raise OSError(11, "Resource temporarily unavailable")

    monkeypatch.setattr(BaseProcess, "start", cannot)
    with Forked(os.getpid, enabled=True) as f:
        assert f.result() == os.getpid()
    assert render({"a": (lambda: 1, 1.0), "b": (lambda: 2, 2.0)}, workers=2) == {"a": 1, "b": 2}
