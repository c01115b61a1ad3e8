"""A gate of the library's own: every ``type: ignore`` says why. (ruff and mypy --strict run
in .ci/run beside the tests, as the README says.)"""

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_type_ignores_are_justified():
    """Every ``type: ignore`` left in the library says why, in a comment on its line."""
    bare = []
    for p in (ROOT / "src").rglob("*.py"):
        for i, line in enumerate(p.read_text().splitlines(), 1):
            if "type: ignore" in line and line.rstrip().endswith("]"):
                bare.append(f"{p.name}:{i}")
    assert bare == []


def test_no_assert_isinstance_narrowing_in_the_library():
    """Narrowing is done by typed accessors, not ``assert isinstance``."""
    found = [f"{p.name}:{i}" for p in (ROOT / "src").rglob("*.py")
             for i, line in enumerate(p.read_text().splitlines(), 1)
             if "assert isinstance" in line]
    assert found == []


def test_the_import_contract_covers_every_package_and_module():
    """Every package and module of dextar is a layer of the import contract that
    ``lint-imports`` checks (a new package cannot escape it), in the pipeline's order."""
    import tomllib

    contract = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["importlinter"]
    layers = [{name.strip() for name in layer.split("|")}
              for layer in contract["contracts"][0]["layers"]]
    named = set().union(*layers)
    src = ROOT / "src" / "dextar"
    present = {f"dextar.{p.stem}" for p in src.glob("*.py") if p.stem not in ("__init__",
                                                                              "__main__")}
    present |= {f"dextar.{p.parent.name}" for p in src.glob("*/__init__.py")}
    assert present - named == set(), "not in the import contract's layers"
    assert named - present == set(), "layers of no module"
    order = [next(i for i, layer in enumerate(layers) if f"dextar.{m}" in layer)
             for m in ("cli", "commands", "jobs", "config", "output", "analysis", "design",
                       "program", "simulation", "dynamics", "trajectory", "laws", "paths",
                       "kinematics", "geometry", "errors")]
    assert order == sorted(order)
    # every package has its __init__.py (a namespace package is invisible to the contract)
    assert [p.name for p in src.iterdir() if p.is_dir() and p.name != "__pycache__"
            and not (p / "__init__.py").exists()] == []
