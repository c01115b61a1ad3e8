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
