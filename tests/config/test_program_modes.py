"""``working_mode`` in a task file: "auto" or a mode for [program], joint, line and arc moves;
anything else refused naming the key."""

from pathlib import Path

import pytest

from dextar.config import load_scenario
from dextar.errors import ConfigError

BASE = (Path(__file__).resolve().parents[2] / "examples" / "auto_modes.toml").read_text()
FIRST = 'type = "line"\nto = [0.0, 20.0]'


@pytest.mark.parametrize(("text", "words"), [
    (BASE.replace('working_mode = "auto"      #', 'working_mode = "autox"     #'),
     "config key [program].working_mode: working mode 'autox'"),
    (BASE.replace(FIRST, FIRST + '\nworking_mode = "x+"', 1),
     "config key [[move]] 0 (line): working_mode: working mode 'x+'"),
    (BASE.replace(FIRST, 'type = "joint"\nto_deg = [10.0, 20.0]\nworking_mode = "auto"', 1),
     "config key [[move]] 0 (joint): working_mode = \"auto\" needs a target point 'to'"),
])
def test_a_bad_working_mode_is_named(tmp_path, text, words):
    cfg = tmp_path / "task.toml"
    cfg.write_text(text)
    with pytest.raises(ConfigError, match=None) as err:
        load_scenario(cfg).program_request()
    assert words in str(err.value)


def test_auto_and_modes_are_read(tmp_path):
    cfg = tmp_path / "task.toml"
    cfg.write_text(BASE.replace(FIRST, FIRST + '\nworking_mode = "pm"', 1)
                   .replace('to = [0.0, 60.0]', 'to = [0.0, 60.0]\nworking_mode = "auto"'))
    req = load_scenario(cfg).program_request()
    assert req.working_mode == "auto"
    assert [m.get("working_mode") for m in req.moves if m.type == "line"][:5] == [
        "pm", None, None, "auto", None]
