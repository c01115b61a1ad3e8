"""The docs' references are generated from the code, and stay so: every registered table,
key, path type, law and move type is in the config reference, every command and option in
the command-line reference, every public module in the API reference; the reference pages
are the generated ones; the README's and getting started's code runs. (The generating
functions import no Sphinx: these tests need only the test extra.)"""

import argparse
import importlib.util
import re
import sys
from pathlib import Path

import pytest

import dextar
from dextar.cli import build_parser
from dextar.commands import COMMANDS
from dextar.laws import LAW_TYPES
from dextar.params import REQUIRED, Param
from dextar.paths import PATH_TYPES, Line, PathType, register_path
from dextar.program import MOVE_TYPES

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"


def _load_reference():
    spec = importlib.util.spec_from_file_location("dextar_reference",
                                                  DOCS / "_ext" / "dextar_reference.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules["dextar_reference"] = module
    spec.loader.exec_module(module)
    return module


ref = _load_reference()


def _sections(rst: str) -> dict[str, str]:
    """The text under each label (``.. _config-robot:``) up to the next label."""
    parts = re.split(r"^\.\. _([\w.-]+):$", rst, flags=re.M)
    return dict(zip(parts[1::2], parts[2::2], strict=True))


def _keys(section: str) -> set[str]:
    """The keys of a section's table: the first cell of each row."""
    return set(re.findall(r"^   \* - ``([^`]+)``$", section, re.M))


@pytest.fixture
def toy_path():
    """A path type registered from outside, as a plugin would."""
    kind = register_path(PathType(
        "zigzag-toy", {"teeth": Param("integer", "", REQUIRED, "number of teeth", minimum=1)},
        lambda v, u: Line((0.0, 0.1), (0.1, 0.1)), "a toy path type"))
    yield kind
    PATH_TYPES.pop("zigzag-toy")


def test_the_config_reference_lists_every_table_key_and_registered_type(toy_path):
    sections = _sections(ref.config_reference())
    tables = dict(ref.config_tables())
    assert {"robot", "law", "path", "motors", "program", "design", "drive"} <= set(tables)
    checked = 0
    for name, cls in tables.items():
        assert f"config-{name}" in sections, name
        if name not in ("path", "law"):
            assert _keys(sections[f"config-{name}"]) == set(cls.PARAMS), name
            checked += len(cls.PARAMS)
    for table, registry in (("path", PATH_TYPES), ("law", LAW_TYPES), ("move", MOVE_TYPES)):
        for kind, item in registry.items():
            section = sections[f"config-{table}-{kind}"]
            assert _keys(section) == set(item.params), (table, kind)
            checked += len(item.params)
    assert "config-path-zigzag-toy" in sections  # a plugin's type, listed like a built-in
    assert "``teeth``" in sections["config-path-zigzag-toy"]
    assert checked > 100  # every key of every table and type was compared


def test_the_config_reference_says_each_keys_unit_default_and_bounds():
    sections = _sections(ref.config_reference())
    robot = sections["config-robot"]
    row = robot[robot.index("``encoder_offset_deg``"):].split("   * -")[0]
    assert "``deg``" in row and "``[0, 0]``" in row and ">= -180, <= 180" in row
    assert "*required*" in sections["config-move-line"]  # a required key says so


def test_the_cli_reference_lists_every_command_and_option():
    sections = _sections(ref.cli_reference())
    top = build_parser()
    parsers = next(a for a in top._actions if isinstance(a, argparse._SubParsersAction)).choices
    assert set(COMMANDS) <= {s.removeprefix("cli-") for s in sections}
    checked = 0
    for name in COMMANDS:
        section = sections[f"cli-{name}"]
        for action in parsers[name]._actions:
            if isinstance(action, argparse._HelpAction):
                continue
            positional = action.metavar or (
                "{" + ",".join(map(str, action.choices)) + "}" if action.choices else action.dest)
            for word in action.option_strings or [positional]:
                assert f"``{word}" in section or f", {word}" in section, (name, word)
                checked += 1
    assert checked > 60  # every option of every command was looked for


def test_the_api_reference_documents_every_public_module():
    """Every module file and folder of modules (``design/`` has no ``__init__.py``)."""
    pages = ref.api_pages()
    base = Path(dextar.__file__).parent
    public = set()
    for path in base.rglob("*.py"):
        parts = path.relative_to(base).with_suffix("").parts
        for k in range(1, len(parts) + 1):  # the package of a private module is public
            if parts[k - 1].startswith("_"):
                break
            public.add(".".join(("dextar", *parts[:k])))
    assert len(public) > 80 and "dextar.design.sweep" in public
    assert ref.documented_modules(pages) == public
    index = pages["index"]
    for name in pages:
        if name != "index":
            assert f"   {name}\n" in index  # in the index's toctree


def test_the_reference_pages_are_the_generated_ones():
    """No hand-copied reference can come back: the pages hold the directives and no
    table of their own."""
    config = (DOCS / "reference" / "config.rst").read_text()
    cli = (DOCS / "reference" / "cli.rst").read_text()
    assert ".. dextar-config-reference::" in config and "list-table" not in config
    assert ".. dextar-cli-reference::" in cli and "--out" not in cli
    assert "reference/api/index" in (DOCS / "index.rst").read_text()


def test_the_readme_keeps_its_commands_and_the_docs_build_is_ci_s():
    readme = (ROOT / "README.md").read_text()
    assert len(readme.splitlines()) <= 150
    for command in (
            "python3 -m venv .venv && .venv/bin/pip install -e . && .venv/bin/dextar run",
            "python3 -m venv .venv && .venv/bin/pip install -e '.[test]' && "
            ".venv/bin/python -m pytest -n auto"):
        assert command in readme
    build = "-m sphinx -W --keep-going -b html docs docs/_build/html"
    assert build in readme and build in (ROOT / ".ci" / "run").read_text()


def _python_blocks(text: str) -> list[str]:
    blocks = re.findall(r"```python\n(.*?)```", text, re.S)
    blocks += [re.sub(r"^   ", "", b, flags=re.M) for b in
               re.findall(r"\.\. code-block:: python\n\n((?:   .*\n|\n)+)", text)]
    return blocks


@pytest.mark.parametrize("page", ["README.md", "docs/getting-started.rst"])
def test_the_first_python_sample_runs_and_says_what_it_says(page, capsys):
    """The README's and getting started's sample runs as printed (the paper's peak torque
    39.46 m L^2/T^2, which ``dextar run`` prints too)."""
    blocks = _python_blocks((ROOT / page).read_text())
    assert blocks
    exec(compile(blocks[0], page, "exec"), {})
    assert capsys.readouterr().out.startswith("39.46")
