"""The console command's exit (dextar.cli.entry): the process ends without taking the
interpreter apart, after the exit handlers and with every byte of output written."""

import os
import subprocess
import sys
import textwrap

import pytest


def _entry(argv, before="", **kw):
    code = textwrap.dedent(f"""
        import sys
        {before}
        sys.argv = ["dextar", *{argv!r}]
        from dextar.cli import entry
        entry()
        print("not reached")
        """)
    return subprocess.run([sys.executable, "-c", code], text=True, timeout=60,
                          **({"capture_output": True} | kw))


@pytest.mark.slow
def test_the_exit_status_the_output_and_the_exit_handlers():
    r = _entry(["ik", "0", "120"], "import atexit; atexit.register(print, 'exit handler ran')")
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith("phi = 60.511785 deg") and "exit handler ran" in r.stdout
    assert "not reached" not in r.stdout and r.stderr == ""
    bad = _entry(["ik", "0", "1200"])
    assert bad.returncode == 2 and "out of reach" in bad.stderr and bad.stdout == ""


@pytest.mark.slow
def test_a_large_output_is_written_whole():
    r = _entry(["plan", "--out", "-"])  # 0.3 MB: more than a pipe holds
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert len(r.stdout) > 2**18 and len(lines) == 1002 and lines[-1].startswith("1.0,")


@pytest.mark.slow
def test_a_thread_of_a_library_still_running_is_waited_for():
    r = _entry(["ik", "0", "120"], "import threading, time; threading.Thread(target=lambda: "
               "(time.sleep(0.5), print('thread done', flush=True))).start()")
    assert r.returncode == 0, r.stderr
    assert "thread done" in r.stdout


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="no /dev/full here")
def test_output_that_cannot_be_written_is_an_error():
    """A full disk when the output is flushed at the end (buffered, as when stdout is a file):
    one line on stderr and exit status 2, not a silent 0."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"}
    with open("/dev/full", "w") as full:
        r = _entry(["ik", "0", "120"], capture_output=False, stdout=full,
                   stderr=subprocess.PIPE, env=env)
    assert r.returncode == 2
    assert r.stderr.strip().splitlines() == [
        "dextar: error: the output could not be written: No space left on device"]
