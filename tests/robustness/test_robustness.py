"""Robustness: random configs and command lines end in exit 0 with finite outputs or in
exit 2 with one line on stderr naming the key or the place; never a traceback, a NaN in a
file, a hang past a bound or a half-written file. ``benchmarks/fuzz.py --cases 10000`` runs
the long version."""

from __future__ import annotations

import re
import tempfile
from pathlib import Path

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from .harness import (
    DEFECTS,
    run_argv_case,
    run_case,
    run_config_case,
    run_identify_case,
    run_program_case,
    toml_text,
)
from .strategies import COMMANDS, configs, kinematics_argv, motion_files, programs

SETTINGS = settings(max_examples=100, deadline=None, derandomize=True,
                    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])


@SETTINGS
@given(doc=configs(), command=COMMANDS)
def test_random_configs_never_crash(doc, command):
    outcome, detail = run_config_case(doc, command)
    assert outcome not in DEFECTS, f"{outcome}: {detail}\nconfig:\n{toml_text(doc)}"
    if outcome == "refused":
        # the one line names a config key, a table, a point, a time, a leg or the solver
        assert re.search(r"\[\w+\]|point|leg|t = |p = |motor|law|path|expression|"
                         r"singularity|config|geometry|mode|--out", detail), detail


@SETTINGS
@given(argv=kinematics_argv())
def test_random_command_lines_never_crash(argv):
    outcome, detail = run_argv_case(argv)
    assert outcome not in DEFECTS, f"{outcome}: {detail}\nargv: {argv}"


@settings(max_examples=25, deadline=None, derandomize=True)
@given(text=st.text(max_size=60))
def test_arbitrary_bytes_as_config(text):
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        cfg = work / "case.toml"
        cfg.write_text(text)
        out = work / "out.csv"
        outcome, detail = run_case(["plan", str(cfg), "--out", str(out)], work, out)
    assert outcome not in DEFECTS, f"{outcome}: {detail}\ntext: {text!r}"


@settings(max_examples=40, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(doc=programs())
def test_random_programs_never_crash(doc):
    outcome, detail = run_program_case(doc)
    assert outcome not in DEFECTS, f"{outcome}: {detail}\ntask:\n{toml_text(doc)}"


@settings(max_examples=12, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(case=motion_files())
def test_random_measured_data_never_crash(case):
    text, options = case
    outcome, detail = run_identify_case(text, options, None)
    assert outcome not in DEFECTS, f"{outcome}: {detail}\noptions {options}\n{text[:500]}"
