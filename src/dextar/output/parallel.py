"""Rendering on two cores: the figures of a command are independent of each other and
matplotlib draws one at a time, so :func:`render` shares them between this process and one
forked child.

A forked child starts at once with everything imported and computed (nothing is pickled on
the way in); it only renders and sends the files' bytes back through a pipe. Without
``fork`` (Windows, macOS), when the process may use one CPU only (``taskset``, a container's
limit) or with ``workers=1``, the jobs run here in turn: the same files either way. A job
that fails in the child runs again here, so its error is raised as if there were no child.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import sys
from collections.abc import Callable, Mapping
from typing import Any, TypeVar

R = TypeVar("R")

#: A job: a callable and its cost (any unit: only the split between the processes uses it).
Job = tuple[Callable[[], R], float]


def cpus() -> int:
    """The CPUs this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


def render(jobs: Mapping[str, Job[R]], *, workers: int | None = None) -> dict[str, R]:
    """Run ``jobs`` (name -> (callable, cost)), shared between this process and one forked
    child when two CPUs are free to use (``workers`` None: 2 where ``fork`` is safe and two
    CPUs are allowed, else 1). Returns name -> result, in the jobs' order."""
    if workers is None:
        workers = 2 if sys.platform.startswith("linux") and cpus() >= 2 else 1
    here, there = _split(jobs, 2 if workers >= 2 and len(jobs) >= 2 else 1)
    results: dict[str, R] = {}
    if there:
        results.update(_forked(jobs, there, lambda: {n: jobs[n][0]() for n in here}))
    else:
        results.update({n: jobs[n][0]() for n in here})
    return {n: results[n] for n in jobs}


#: The signals held while forking.
_INTERRUPTS = {signal.SIGINT, signal.SIGTERM}


def _split(jobs: Mapping[str, Job[Any]], parts: int) -> tuple[list[str], list[str]]:
    """The jobs of this process and of the child: the costliest first, each to the lighter
    side (the child's side gets no more than this one's)."""
    if parts == 1:
        return list(jobs), []
    sides: tuple[list[str], list[str]] = ([], [])
    load = [0.0, 0.0]
    for name in sorted(jobs, key=lambda n: -jobs[n][1]):
        k = 0 if load[0] <= load[1] else 1
        sides[k].append(name)
        load[k] += jobs[name][1]
    return sides


def _forked(jobs: Mapping[str, Job[R]], names: list[str],
            mine: Callable[[], dict[str, R]]) -> dict[str, R]:
    """Run ``names`` in a forked child while ``mine`` runs here; the child's jobs run here
    when it fails (the error then raised here) or dies."""
    ctx = multiprocessing.get_context("fork")
    for stream in (sys.stdout, sys.stderr):  # nothing buffered to be written twice
        stream.flush()
    receive, send = ctx.Pipe(duplex=False)
    child = ctx.Process(target=_child, args=(jobs, names, send), daemon=True)
    # no interrupt inside the fork (its handlers, logging's and ours, would swallow it):
    # one that comes is held until the child exists, then raised here, where the child is
    # ended with this process's work
    held = signal.pthread_sigmask(signal.SIG_BLOCK, _INTERRUPTS)
    masked = True
    try:
        child.start()
        send.close()
        masked = False
        signal.pthread_sigmask(signal.SIG_SETMASK, held)
        out = mine()
        try:
            ok, theirs = receive.recv()
        except EOFError:  # the child died without a word
            ok, theirs = False, None
        child.join()  # (it exits once its word is sent)
        if not ok:
            theirs = {n: jobs[n][0]() for n in names}
        out.update(theirs)
        return out
    finally:
        if masked:  # the fork itself failed
            signal.pthread_sigmask(signal.SIG_SETMASK, held)
        receive.close()
        if child.pid is not None:
            if child.is_alive():  # this process failed or was interrupted: the child's
                child.terminate()  # work is moot
            child.join()


def _child(jobs: Mapping[str, Job[Any]], names: list[str], send: Any) -> None:
    """The child's work: its jobs' results, or word that it failed (the parent redoes them)."""
    signal.signal(signal.SIGTERM, signal.SIG_DFL)  # ended by the parent: quietly
    signal.pthread_sigmask(signal.SIG_UNBLOCK, _INTERRUPTS)  # held by the fork
    result: tuple[bool, dict[str, Any] | None]
    try:
        result = (True, {n: jobs[n][0]() for n in names})
    except BaseException:  # anything, interrupts included: the parent decides
        result = (False, None)
    try:
        send.send(result)
    except OSError:  # the parent is gone
        pass
    finally:
        send.close()
