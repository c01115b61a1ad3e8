"""Work on two cores: the figures of a command are independent of each other and matplotlib
draws one at a time, so :func:`render` shares them between this process and one forked child;
:class:`Forked` runs one piece of work (a run's validation) in a child while this process goes
on with the rest.

A forked child starts at once with everything imported and computed (nothing is pickled on
the way in); it only computes and sends its result back through a pipe. Without ``fork``
(Windows, macOS), when the process may use one CPU only (``taskset``, a container's limit) or
with ``workers=1``, the work runs here in turn: the same results either way. Work that fails
in the child runs again here, so its error is raised as if there were no child.
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import sys
from collections.abc import Callable, Mapping
from types import TracebackType
from typing import Any, Generic, TypeVar

R = TypeVar("R")

#: A job: a callable and its cost (any unit: only the split between the processes uses it).
Job = tuple[Callable[[], R], float]


def cpus() -> int:
    """The CPUs this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


def can_fork() -> bool:
    """Whether work may go to a forked child: ``fork`` is safe here (Linux) and two CPUs are
    allowed."""
    return sys.platform.startswith("linux") and cpus() >= 2


def render(jobs: Mapping[str, Job[R]], *, workers: int | None = None) -> dict[str, R]:
    """Run ``jobs`` (name -> (callable, cost)), shared between this process and one forked
    child when two CPUs are free to use (``workers`` None: 2 where :func:`can_fork`, else 1).
    Returns name -> result, in the jobs' order.

    The two processes take the jobs from one queue, the costliest first, each the next one
    when it is free: a job slower than its cost said (a busy machine, a first use of a font)
    delays the one process it runs on, not the split. The child stops at a job that fails;
    that job and any it did not finish (it died) run here, so that an error is raised here;
    what it finished is kept."""
    if workers is None:
        workers = 2 if can_fork() else 1
    if workers < 2 or len(jobs) < 2 or len(jobs) > 255:
        return {n: jobs[n][0]() for n in jobs}
    order = sorted(jobs, key=lambda n: -jobs[n][1])
    try:  # the queue: a pipe of job numbers, one byte each, read a byte at a time by both
        head, tail = os.pipe()
    except OSError:  # no file descriptor left: in turn
        return {n: jobs[n][0]() for n in jobs}
    try:
        os.write(tail, bytes(range(len(order))))
        os.close(tail)

        def take(child: bool) -> dict[str, R]:
            done: dict[str, R] = {}
            while k := os.read(head, 1):
                name = order[k[0]]
                try:
                    done[name] = jobs[name][0]()
                except Exception:
                    if not child:
                        raise
                    break  # (raised again here, where it runs once more)
            return done

        # (workers says to fork: the decision is not made again)
        with Forked(lambda: take(True), enabled=True) as other:
            results = take(False)
            results.update(other.result())  # (where the child failed, take() finds none left)
    finally:
        os.close(head)
    results.update({n: jobs[n][0]() for n in order if n not in results})  # the child's lost
    return {n: results[n] for n in jobs}


#: The signals held while forking.
_INTERRUPTS = {signal.SIGINT, signal.SIGTERM}


class Forked(Generic[R]):
    """``fn()`` computed in a forked child while this process goes on, as a context manager::

        with Forked(check) as checked:
            ...                    # this process's own work
            value = checked.result()

    :meth:`result` waits for the child's result; where the child fails or dies, or was not
    forked (``enabled`` False; None: where :func:`can_fork`; no fork to be had), ``fn``
    runs here, so that its error is raised here. Leaving the block ends a child that is
    still running (this process failed or was interrupted)."""

    def __init__(self, fn: Callable[[], R], *, enabled: bool | None = None) -> None:
        """Fork on entering the block (only where ``enabled``)."""
        self.fn = fn
        self.enabled = can_fork() if enabled is None else enabled
        self._child: Any = None
        self._receive: Any = None
        self._result: tuple[R] | None = None

    def __enter__(self) -> Forked[R]:
        if not self.enabled:
            return self
        ctx = multiprocessing.get_context("fork")
        for stream in (sys.stdout, sys.stderr):  # nothing buffered to be written twice
            stream.flush()
        try:
            self._receive, send = ctx.Pipe(duplex=False)
        except OSError:  # no file descriptor left: the work runs here
            return self
        self._child = ctx.Process(target=_child, args=(self.fn, send), daemon=True)
        # no interrupt inside the fork (its handlers, logging's and ours, would swallow it):
        # one that comes is held until the child exists, then raised here, where the child
        # is ended with this process's work (the block's exit)
        held = signal.pthread_sigmask(signal.SIG_BLOCK, _INTERRUPTS)
        try:
            try:
                self._child.start()
            except OSError:  # no fork to be had (no memory, too many processes): here
                self._child = None
            finally:
                send.close()
            signal.pthread_sigmask(signal.SIG_SETMASK, held)  # a held interrupt comes here
        except BaseException:
            signal.pthread_sigmask(signal.SIG_SETMASK, held)
            self.close()  # (the block is not entered: its exit would not end the child)
            raise
        return self

    def result(self) -> R:
        """The child's result (waited for), or ``fn()`` computed here; the same on every
        call."""
        if self._result is None:
            self._result = (self._compute(),)
        return self._result[0]

    def _compute(self) -> R:
        if self._child is None:
            return self.fn()
        try:
            ok, value = self._receive.recv()
        except EOFError:  # the child died without a word
            ok, value = False, None
        self._child.join()  # (it exits once its word is sent)
        if not ok:
            return self.fn()
        result: R = value
        return result

    def __exit__(self, kind: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()

    def close(self) -> None:
        """End the child if it still runs (its work is moot: this process failed or was
        interrupted) and let its pipe go."""
        if self._receive is not None:
            self._receive.close()
            self._receive = None
        child, self._child = self._child, None
        if child is not None and child.pid is not None:
            if child.is_alive():
                child.terminate()
            child.join()


def _child(fn: Callable[[], Any], send: Any) -> None:
    """The child's work: ``fn``'s result, or word that it failed (the parent redoes it).
    Ended by the parent (SIGTERM) quietly; an interrupt at the terminal (SIGINT, sent to the
    whole group) is the parent's to handle, which then ends the child."""
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    result: tuple[bool, Any]
    try:
        signal.pthread_sigmask(signal.SIG_UNBLOCK, _INTERRUPTS)  # held by the fork
        result = (True, fn())
    except BaseException:  # anything: the parent decides
        result = (False, None)
    try:
        send.send(result)
    except BaseException:  # a result that does not pickle, or the parent gone
        try:
            send.send((False, None))
        except BaseException:
            pass
    finally:
        send.close()
