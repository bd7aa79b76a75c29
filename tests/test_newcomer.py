"""What a new user runs into first: missing extras, help texts (issue 12, newcomer pass)."""

from __future__ import annotations

import sys

import pytest

from agents.cli import main


@pytest.mark.parametrize("module", ["yaml", "stable_baselines3", "torch"])
def test_train_without_rl_extra_names_the_extra(module, monkeypatch, capsys, tmp_path):
    monkeypatch.setitem(sys.modules, module, None)  # import of it now raises ImportError
    for name in [m for m in sys.modules if m == "agents.train"]:
        monkeypatch.delitem(sys.modules, name)
    rc = main(
        ["train", "--env", "sensorplan/Navigate-v0", "--algo", "ppo", "--timesteps", "8",
         "--out", str(tmp_path / "run"), "--no-progress", "--no-tensorboard"]
    )  # fmt: skip
    err = capsys.readouterr().err
    assert rc == 2
    assert repr(module) in err
    assert 'pip install -e ".[rl]"' in err


def test_missing_module_outside_the_extras_is_not_swallowed():
    from agents.cli import _missing_extra_message

    err = ModuleNotFoundError("No module named 'nosuchthing'", name="nosuchthing")
    assert _missing_extra_message("train", err) is None
    err = ModuleNotFoundError("No module named 'yaml'", name="yaml")
    assert '".[rl]"' in _missing_extra_message("train", err)


def test_demo_help_is_plain_text(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["demo", "--help"])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    assert "``" not in out and ":func:" not in out
    assert 'pip install -e ".[rl]"' in out
    assert "Recognize-v0" in out
