"""The robustness harness, shared by the test suite and ``benchmarks/fuzz.py``.

A case is a config (a dict of TOML tables, written to a file) and a command line. It is run
in-process through :func:`dextar.cli.main` under a time bound, and classified:

* ``"ok"``: exit 0, the output file complete and every number in it finite;
* ``"refused"``: exit 2 with exactly one line on stderr, no output file left behind;
* anything else is a defect: ``"traceback"`` (an internal error or an exception escaping),
  ``"nan"`` (a non-finite number in an output), ``"hang"`` (past the time bound),
  ``"partial"`` (a half-written or leftover staging file), ``"bad-exit"`` (another exit
  status or a refusal without its one line).
"""

from __future__ import annotations

import contextlib
import io
import json
import math
import re
import signal
import tempfile
from pathlib import Path
from typing import Any

from dextar.cli import main

#: Seconds a single case may take (each command is bounded well below this).
TIME_BOUND = 60.0
DEFECTS = ("traceback", "nan", "hang", "partial", "bad-exit")


class Hang(BaseException):
    """Raised by the alarm when a case runs past its bound (not an Exception: the CLI's
    catch-all must not swallow it)."""


def toml_value(v: Any) -> str:
    """A Python value as TOML (nan and inf included)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f'"{k}" = {toml_value(x)}' for k, x in v.items()) + "}"
    raise TypeError(type(v))


def toml_text(doc: dict[str, Any]) -> str:
    """A config dict as TOML text: top-level plain values first, then one table each, then
    the arrays of tables (``[[move]]``)."""
    def is_array_of_tables(v: Any) -> bool:
        return isinstance(v, list) and bool(v) and all(isinstance(x, dict) for x in v)

    lines = [f'"{k}" = {toml_value(v)}' for k, v in doc.items()
             if not isinstance(v, dict) and not is_array_of_tables(v) and v != []]
    for name, table in doc.items():
        if isinstance(table, dict):
            lines.append(f'["{name}"]')
            lines += [f'"{k}" = {toml_value(v)}' for k, v in table.items()]
    for name, tables in doc.items():
        if is_array_of_tables(tables):
            for table in tables:
                lines.append(f'[["{name}"]]')
                lines += [f'"{k}" = {toml_value(v)}' for k, v in table.items()]
    return "\n".join(lines) + "\n"


def _finite_csv(text: str) -> bool:
    body = text.splitlines()[1:]
    if not body:
        return False
    for row in body:
        for cell in row.split(","):
            if not math.isfinite(float(cell)):
                return False
    return True


def _complete(out: Path) -> bool:
    """A CSV with finite numbers, or a JSON summary that reads back."""
    if out.suffix == ".json":
        try:
            json.loads(out.read_text(), parse_constant=lambda c: float("nan"))
        except ValueError:
            return False
        return "NaN" not in out.read_text()
    return _finite_csv(out.read_text())


def run_case(argv: list[str], workdir: Path, out: Path | None,
             bound: float = TIME_BOUND, allow_exceeds: bool = False) -> tuple[str, str]:
    """Run one command line; returns ``(outcome, detail)`` (see the module doc)."""
    err, std = io.StringIO(), io.StringIO()

    def alarm(signum: int, frame: object) -> None:
        raise Hang

    old = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, bound)
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(std):
            code = main(argv)
    except Hang:
        return "hang", " ".join(argv)
    except BaseException as exc:  # noqa: BLE001 - anything escaping main is a defect
        return "traceback", f"{type(exc).__name__}: {exc}"
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    if code == 130:  # interrupted (Ctrl-C or SIGTERM): stop the whole run
        raise KeyboardInterrupt
    msg = err.getvalue()
    leftovers = [p.name for p in workdir.rglob("*") if p.name.startswith(".")]
    if leftovers:
        return "partial", f"leftover files {leftovers}"
    if "Traceback" in msg or "internal error" in msg:
        return "traceback", msg.strip()
    if code == 2:
        if msg.count("\n") != 1 or not msg.startswith("dextar"):
            return "bad-exit", f"refusal without one line on stderr: {msg!r}"
        if out is not None and out.exists():
            return "partial", f"output written on a refusal: {msg.strip()}"
        return "refused", msg.strip()
    if code == 1 and allow_exceeds:
        if out is None or not out.exists() or not _complete(out):
            return "partial", "exit 1 without its complete files"
        return "exceeds", msg.strip()[:200]
    if code != 0:
        return "bad-exit", f"exit {code}: {msg.strip()}"
    if out is not None:
        if not out.exists():
            return "bad-exit", "exit 0 without the output file"
        if out.suffix == ".csv" and not _finite_csv(out.read_text()):
            return "nan", f"non-finite value in {out.name}"
        if out.suffix == ".xml" and not out.read_text().rstrip().endswith("</mujoco>"):
            return "partial", "incomplete XML"
        if out.suffix == ".xml" and ("nan" in out.read_text() or "inf" in out.read_text()):
            return "nan", "non-finite value in the MJCF"
    if re.search(r"\b(nan|inf|infinity)\b", std.getvalue(), re.IGNORECASE):
        return "nan", f"non-finite number printed: {std.getvalue()[:200]}"
    return "ok", ""


def run_config_case(doc: dict[str, Any], command: str) -> tuple[str, str]:
    """Write ``doc`` as a config in a fresh folder and run ``command`` on it."""
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        cfg = work / "case.toml"
        cfg.write_text(toml_text(doc))
        if command == "simulate":  # a plant that leaves the motion is a result: exit 1
            return run_case(["simulate", str(cfg), "--out", str(work / "sim"), "--quiet"],
                            work, work / "sim" / "tracking.csv", allow_exceeds=True)
        out = work / ("out.xml" if command == "export" else "out.csv")
        argv = [command, "mjcf"] if command == "export" else [command]
        return run_case([*argv, str(cfg), "--out", str(out)], work, out)


def run_program_case(doc: dict[str, Any]) -> tuple[str, str]:
    """Write ``doc`` as a task file and run ``dextar program`` on it (exit 1, a program that
    exceeds its motors with its files written, is an outcome of its own: ``exceeds``)."""
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        cfg = work / "task.toml"
        cfg.write_text(toml_text(doc))
        out = work / "out"
        return run_case(["program", str(cfg), "--out", str(out), "--quiet"], work,
                        out / "setpoints.csv", allow_exceeds=True)


def run_argv_case(argv: list[str]) -> tuple[str, str]:
    """Run a kinematics command line in a fresh folder (a workspace map writes a PNG there)."""
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        out = None
        if argv[0] == "workspace":
            out = work / "ws.png"
            argv = [*argv, "--out", str(out)]
        return run_case(argv, work, out)


def run_identify_case(text: str, options: list[str], config: str | None) -> tuple[str, str]:
    """Write ``text`` as a data file and run ``dextar identify`` on it."""
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        data = work / "data.csv"
        data.write_text(text)
        out = work / "out"
        argv = ["identify", str(data), "--out", str(out), "--quiet", *options]
        if config:
            argv += ["--config", config]
        # a poor fit is a result: exit 1 with its files written
        return run_case(argv, work, out / "summary.json", allow_exceeds=True)


def run_run_case(doc: dict[str, Any]) -> tuple[str, str]:
    """Write ``doc`` as a config and run ``dextar run`` on it (exit 1, a physics check that
    failed with its files written, is an outcome of its own: ``exceeds``)."""
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        cfg = work / "case.toml"
        cfg.write_text(toml_text(doc))
        out = work / "out"
        return run_case(["run", str(cfg), "--out", str(out), "--quiet"], work,
                        out / "summary.json", allow_exceeds=True)


def run_robot_config_case(doc: dict[str, Any], command: str) -> tuple[str, str]:
    """Write ``doc`` as a config and run a command that reads its robot only (``ik``, ``fk``,
    ``workspace``, ``poses``) or ``excite`` on it, with arguments of the DexTAR's size."""
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        cfg = work / "case.toml"
        cfg.write_text(toml_text(doc))
        out: Path | None = None
        if command == "ik":
            argv = ["ik", "0", "120", "--robot", str(cfg)]
        elif command == "fk":
            argv = ["fk", "60", "120", "--robot", str(cfg)]
        elif command == "workspace":
            out = work / "ws.png"
            argv = ["workspace", "--robot", str(cfg), "--resolution", "41", "--out", str(out)]
        elif command == "poses":  # (text columns: the file is checked here, not as numbers)
            poses = work / "poses.csv"
            outcome, detail = run_case(["poses", str(cfg), "--count", "20", "--out", str(poses),
                                        "--quiet"], work, None)
            written = poses.exists() and len(poses.read_text().splitlines()) == 21
            if outcome == "bad-exit" and detail.startswith("exit 1") and written:
                return "exceeds", detail  # a working mode with no pose: exit 1, named
            if outcome == "ok" and not written:
                return "bad-exit", "exit 0 without the 20 poses"
            return outcome, detail
        elif command == "excite":  # below its coverage floors is a result: exit 1, written
            out = work / "excite.csv"
            return run_case(["excite", str(cfg), "--duration", "5", "--harmonics", "2", "--out",
                             str(out), "--quiet"], work, out, allow_exceeds=True)
        else:
            raise ValueError(f"not a robot-config command: {command}")
        return run_case(argv, work, out)
