"""The config, command-line and API references, generated from the code.

Nothing here is written by hand: the config tables come from :data:`dextar.config.TABLES`
(each key a :class:`dextar.params.Param`), the path types, laws and move types from
:data:`dextar.paths.PATH_TYPES`, :data:`dextar.laws.LAW_TYPES` and
:data:`dextar.program.MOVE_TYPES`, the commands from :data:`dextar.commands.COMMANDS` and
their arguments from :func:`dextar.cli.build_parser`. A law, path type, move type, table or
command that a plugin registers appears like a built-in one. The API reference's pages
(:func:`api_pages`) list every public module of the package, found by walking it.

This module imports no Sphinx (``tests/test_docs.py`` calls it without the docs extra);
``dextar_docs`` turns its text into pages.
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import math
import re
from collections.abc import Iterator, Mapping
from pathlib import Path
from typing import Any

_INLINE = re.compile(r"([\\*`|_])")


def text(s: str) -> str:
    """Plain words as reStructuredText: inline markup characters escaped (a help line such
    as ``Int |rdot|^2`` is not a substitution)."""
    return _INLINE.sub(r"\\\1", " ".join(s.split()))


def literal(s: object) -> str:
    """``s`` as an inline literal."""
    return f"``{s}``" if str(s) else ""


def _number(x: float) -> str:
    """A number as a person writes it: ``400``, ``0.01``, ``1e9``, ``1e-6``."""
    if isinstance(x, bool):
        return "true" if x else "false"
    if math.isfinite(x) and x == int(x) and abs(x) < 1e6:
        return str(int(x))
    mantissa, _, exponent = f"{x:g}".partition("e")
    return f"{mantissa}e{int(exponent)}" if exponent else mantissa


def toml_value(v: object) -> str:
    """A default as a TOML file writes it."""
    if isinstance(v, str):
        return f'"{v}"'
    if isinstance(v, (int, float)):
        return _number(v)
    if isinstance(v, (tuple, list)):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    return str(v)


def kind_text(p: Any) -> str:
    """What a key holds, in words."""
    if p.kind == "choice":
        return "one of " + ", ".join(f'``"{c}"``' for c in p.choices)
    return {"number": "number", "integer": "integer", "text": "text", "point": "[x, y]",
            "points": "[[x, y], ...]", "pair": "number, or [A, D]"}.get(p.kind,
                                                                                  p.kind)


def default_text(p: Any) -> str:
    """The default of a key: a value, *required* or *none* (the key may be left out)."""
    if p.required:
        return "*required*"
    if p.default is None:
        return "*none*"
    return literal(toml_value(p.default))


def bounds_text(p: Any) -> str:
    """The bounds a key's numbers are checked against."""
    out = []
    if p.positive:
        out.append("> 0")
    if p.minimum is not None:
        out.append(f">= {_number(p.minimum)}")
    if p.maximum is not None:
        out.append(f"<= {_number(p.maximum)}")
    return ", ".join(out)


def _indent(lines: list[str], n: int = 3) -> list[str]:
    return [(" " * n + ln) if ln else "" for ln in lines]


def keys_table(params: Mapping[str, Any], table: str) -> list[str]:
    """A list-table of declared keys: key, value, unit, default, bounds and help."""
    if not params:
        return ["This table has no keys of its own.", ""]
    out = [".. list-table::", "   :header-rows: 1", "   :widths: 18 20 8 12 12 30",
           f"   :class: dextar-keys dextar-keys-{re.sub(r'[^a-z0-9]+', '-', table)}", "",
           "   * - key", "     - value", "     - unit", "     - default", "     - bounds",
           "     - meaning"]
    for key, p in params.items():
        out += [f"   * - ``{key}``", f"     - {kind_text(p)}",
                f"     - {literal(p.unit) if p.unit else ''}", f"     - {default_text(p)}",
                f"     - {text(bounds_text(p))}", f"     - {text(p.help)}"]
    return out + [""]


def _doc(obj: object) -> list[str]:
    doc = inspect.getdoc(obj) or ""
    return [*doc.splitlines(), ""] if doc else []


def _section(title: str, char: str, label: str | None = None) -> list[str]:
    out = [f".. _{label}:", ""] if label else []
    return [*out, title, char * len(title), ""]


def _typed_subsections(table: str, registry: Mapping[str, Any], default: str) -> list[str]:
    """``[path]`` and ``[law]``: the ``type`` key, then each registered type's keys."""
    names = ", ".join(f'``"{n}"``' for n in registry)
    out = [f"``type``: one of {names} (default ``\"{default}\"``). The other keys depend on "
           "the type:", ""]
    for name, item in registry.items():
        out += _section(f'type = "{name}"', "~", f"config-{table}-{name}")
        out += [text(getattr(item, "help", "")), ""] if getattr(item, "help", "") else []
        out += keys_table(item.params, f"{table}-{name}")
    return out


def _move_section() -> list[str]:
    from dextar.config.program import BLEND_PARAM
    from dextar.config.tables import LawTable  # noqa: F401  (the law table's registry)
    from dextar.laws import LAW_TYPES
    from dextar.program import MOVE_TYPES

    out = _section("[[move]]", "-", "config-move")
    out += ["An array of tables in a program's task file (``dextar program``), one per move, "
            "in order. ``type`` is one of "
            + ", ".join(f'``"{n}"``' for n in MOVE_TYPES) + ". A move with a law also "
            "takes ``law`` (one of " + ", ".join(f'``"{n}"``' for n in LAW_TYPES)
            + "; default ``[program].law``), ``duration`` (s, or ``\"fit\"``: the shortest "
            "within the motors, for a law with a duration) and the law's own keys (see "
            ":ref:`config-law`); a move along a path also takes ``blend`` ("
            + text(BLEND_PARAM.help) + ").", ""]
    for name, mt in MOVE_TYPES.items():
        out += _section(f'type = "{name}"', "~", f"config-move-{name}")
        extra = [w for w, on in (("a law", mt.has_law), ("a blend", mt.path is not None))
                 if on]
        out += [text(mt.help) + (f" (takes {' and '.join(extra)})" if extra else
                                 " (no law, no blend)") + ".", ""]
        out += keys_table(mt.params, f"move-{name}")
    return out


def config_tables() -> Iterator[tuple[str, Any]]:
    """The registered config tables, by name (every module that registers one imported)."""
    import dextar.config.design  # noqa: F401  (tables registered by their modules)
    import dextar.config.program  # noqa: F401
    from dextar.config import TABLES

    yield from TABLES.items()


def config_reference() -> str:
    """The config reference: every registered table and its keys, the path types, laws and
    move types with theirs; reStructuredText."""
    from dextar.config.tables import LawTable, PathTable
    from dextar.laws import LAW_TYPES
    from dextar.params import MAX_MM, MIN_MM
    from dextar.paths import PATH_TYPES

    out = ["Every key a config file may hold, generated from the registries when the docs are "
           f"built. Lengths in mm are within {_number(MAX_MM)} mm and, when positive, at least "
           f"{_number(MIN_MM)} mm. A key left out takes its default; *none* means that the key "
           "is optional and absent unless given. A value ``[A, D]`` is one per motor (or leg), "
           "the one at A first; a number means both.", ""]
    for name, cls in config_tables():
        out += _section(f"[{name}]", "-", f"config-{name}")
        out += _doc(cls)
        if cls is PathTable:
            out += _typed_subsections("path", PATH_TYPES, PathTable.type)
        elif cls is LawTable:
            out += _typed_subsections("law", LAW_TYPES, LawTable.type)
        else:
            out += keys_table(cls.PARAMS, name)
        if name == "program":
            out += _move_section()
    return "\n".join(out) + "\n"


def _invocation(action: argparse.Action, formatter: argparse.HelpFormatter) -> str:
    return formatter._format_action_invocation(action)  # the words --help uses


def command_parsers() -> Iterator[tuple[str, argparse.ArgumentParser]]:
    """Every registered command and its parser, with all of its arguments."""
    from dextar.cli import build_parser
    from dextar.commands import COMMANDS

    top = build_parser()
    sub = next(a for a in top._actions if isinstance(a, argparse._SubParsersAction))
    for name in COMMANDS:
        yield name, sub.choices[name]


def arguments(parser: argparse.ArgumentParser) -> Iterator[tuple[str, str]]:
    """A command's arguments: the invocation (``--out OUT``) and the help with its
    default and choices, as ``--help`` says them."""
    formatter = parser._get_formatter()
    for action in parser._actions:
        if isinstance(action, argparse._HelpAction):
            continue
        words = formatter._expand_help(action) if action.help else ""
        if action.choices is not None and "{" not in _invocation(action, formatter):
            words += f" (one of {', '.join(map(str, action.choices))})"
        if action.required and action.option_strings:
            words += " (required)"
        yield _invocation(action, formatter), words


def cli_reference() -> str:
    """The command-line reference: ``dextar``'s commands, each with its usage and every
    argument, from the parser; reStructuredText."""
    from dextar.cli import build_parser

    top = build_parser()
    parsers = dict(command_parsers())
    out = ["Generated from the parser when the docs are built: what ``dextar COMMAND "
           "--help`` prints, every command on one page.", "",
           ".. list-table::", "   :header-rows: 1", "   :widths: 20 80", "",
           "   * - command", "     - what it does"]
    for name, parser in parsers.items():
        out += [f"   * - :ref:`dextar {name} <cli-{name}>`",
                f"     - {text(parser.description or '')}"]
    out += ["", "Options of ``dextar`` itself:", "", ".. code-block:: text", "",
            *_indent(top.format_usage().strip().splitlines()), ""]
    for name, parser in parsers.items():
        out += _section(f"dextar {name}", "-", f"cli-{name}")
        out += [text(parser.description or ""), "", ".. code-block:: text", "",
                *_indent(parser.format_usage().strip().splitlines()), ""]
        for invocation, words in arguments(parser):
            out += [f"``{invocation}``", *_indent([text(words) or "(no help)"]), ""]
        if getattr(parser, "registries", False):
            out += ["The config's tables, path types, laws and move types are in the "
                    ":doc:`config reference <config>`.", ""]
    return "\n".join(out) + "\n"


# -- the API reference's pages ------------------------------------------------------------

#: The order of the pipeline (geometry -> ... -> cli) where ``pyproject.toml`` has no layers
#: contract (:func:`pipeline`); a module in neither comes after, by name, so that a new one
#: appears without an edit here.
PIPELINE = ("errors", "units", "params", "registry", "geometry", "motors", "kinematics",
            "paths", "laws", "trajectory", "dynamics", "simulation", "program",
            "identification", "calibration", "design", "analysis", "output", "config",
            "commands", "cli")


def pipeline() -> tuple[str, ...]:
    """The top-level modules in the pipeline's order, lowest first: the layers of the
    import contract in ``pyproject.toml`` (``[tool.importlinter]``, ``type = "layers"``,
    listed highest first), else :data:`PIPELINE`."""
    import tomllib

    pyproject = Path(__file__).resolve().parents[2] / "pyproject.toml"
    config = tomllib.loads(pyproject.read_text()) if pyproject.exists() else {}
    for contract in config.get("tool", {}).get("importlinter", {}).get("contracts", []):
        if contract.get("type") == "layers":
            names = [n.strip() for layer in reversed(contract["layers"])
                     for n in layer.split("|")]
            return tuple(n.removeprefix("dextar.") for n in names if n.startswith("dextar."))
    return PIPELINE


def _public_modules(package: Any) -> list[tuple[str, bool]]:
    """The public modules of a package, by name: (dotted name, is a package). A folder of
    modules is a package with or without an ``__init__.py`` (``pkgutil`` sees only those
    with one)."""
    found: dict[str, bool] = {}
    for folder in map(Path, getattr(package, "__path__", ())):
        for entry in folder.iterdir():
            if entry.name.startswith(("_", ".")):
                continue
            if entry.is_file() and entry.suffix == ".py":
                found[entry.stem] = False
            elif entry.is_dir() and any(entry.glob("*.py")):
                found[entry.name] = True
    return [(f"{package.__name__}.{name}", found[name]) for name in sorted(found)]


def _first_line(module_name: str) -> str:
    """The first paragraph of a module's docstring, on one line (reStructuredText as the
    docstring writes it)."""
    module = importlib.import_module(module_name)
    doc = inspect.getdoc(module) or ""
    if not doc and hasattr(module, "__path__"):  # a folder of modules without __init__.py
        return "Its modules: " + ", ".join(f":mod:`{m}`" for m, _ in _public_modules(module))
    return " ".join(doc.split("\n\n")[0].split())


def _automodule(name: str) -> list[str]:
    return [f".. automodule:: {name}", "   :members:", "   :show-inheritance:",
            "   :ignore-module-all:", ""]


def _private_exports(package: Any) -> list[str]:
    """The names a package exports that are defined in its private modules
    (``dextar.jobs.run`` from ``dextar.jobs._run``): documented in the package itself."""
    out = []
    for name in getattr(package, "__all__", ()):
        mod = getattr(getattr(package, name, None), "__module__", "") or ""
        if mod.startswith(f"{package.__name__}._"):
            out.append(name)
    return out


def _private_export_directives(package: Any) -> list[str]:
    out = []
    for name in _private_exports(package):
        obj = getattr(package, name)
        full = f"{package.__name__}.{name}"
        if inspect.isclass(obj):
            out += [f".. autoclass:: {full}", "   :members:", "   :show-inheritance:", ""]
        elif callable(obj):
            out += [f".. autofunction:: {full}", ""]
        else:
            out += [f".. autodata:: {full}", ""]
    return out


def _defined_in(package: Any, name: str) -> str | None:
    """Where a name a package exports is documented (for its link)."""
    obj = getattr(package, name, None)
    mod = getattr(obj, "__module__", None)
    if name in _private_exports(package):
        return f"{package.__name__}.{name}"
    if inspect.isclass(obj) or inspect.isfunction(obj):
        return f"{mod}.{obj.__qualname__}" if mod else None
    for sub, _ in _public_modules(package):
        source = inspect.getsource(importlib.import_module(sub))
        if f"\n{name}:" in source or f"\n{name} =" in source:
            return f"{sub}.{name}"
    return None


def _package_page(name: str) -> list[str]:
    package = importlib.import_module(name)
    title = f"``{name}``"
    out = [f".. _api-{name}:", "", title, "=" * len(title), "", *_automodule(name),
           *_private_export_directives(package)]
    exported = [n for n in getattr(package, "__all__", ()) if not n.startswith("_")]
    if exported:
        links = []
        for n in exported:
            target = _defined_in(package, n)
            links.append(f":obj:`{n} <{target}>`" if target else f"``{n}``")
        out += [f"Importable from ``{name}``: " + ", ".join(links) + ".", ""]
    modules = _public_modules(package)
    if modules:
        out += [".. list-table::", "   :header-rows: 1", "   :widths: 30 70", "",
                "   * - module", "     - what it holds"]
        for m, _ in modules:
            out += [f"   * - :mod:`{m}`",
                    f"     - {_first_line(m)}"]
        out += [""]
    for sub, _ in modules:
        out += _section_page(sub, 1)
    return out


def _section_page(name: str, depth: int) -> list[str]:
    """A module's section (and, for a package, its modules' sections after it)."""
    title = f"``{name}``"
    out = [title, "-~^\""[min(depth, 4) - 1] * len(title), "", *_automodule(name)]
    for sub, _ in _public_modules(importlib.import_module(name)):
        out += _section_page(sub, depth + 1)
    return out


def documented_modules(pages: Mapping[str, str]) -> set[str]:
    """The modules the API pages document (their ``automodule`` directives)."""
    return {m for page in pages.values()
            for m in re.findall(r"^\.\. automodule:: (\S+)$", page, re.M)}


def api_pages() -> dict[str, str]:
    """The API reference's pages: ``index`` and one per top-level module or package."""
    import dextar

    found = dict(_public_modules(dextar))
    order = [f"dextar.{n}" for n in pipeline() if f"dextar.{n}" in found]
    order += sorted(n for n in found if n not in order)
    pages = {name: "\n".join(_package_page(name)) + "\n" for name in order}
    index = ["API reference", "=============", "",
             "Generated from the docstrings when the docs are built: one page per package of "
             "``dextar``, in the order of the pipeline (a module imports only from the ones "
             "above it). The Python API speaks SI (m, kg, s, N m, rad) unless a function "
             "says it takes the paper's units; every error derives from "
             ":class:`dextar.errors.DextarError`.", "",
             ".. list-table::", "   :header-rows: 1", "   :widths: 25 75", "",
             "   * - module", "     - what it holds"]
    for name in order:
        index += [f"   * - :doc:`{name} <{name}>`",
                  f"     - {_first_line(name)}"]
    index += ["", ".. toctree::", "   :hidden:", "", *[f"   {n}" for n in order], ""]
    pages["index"] = "\n".join(index) + "\n"
    return pages
