"""``sensorplan record``: the CLI on top hands the viewer's recorder (which imports no agent)
the policy to play."""

from __future__ import annotations

import pytest

from agents.cli import main
from sensorplan_gym.viewer.replay import FORMAT, load_rollout, record_rollout


@pytest.mark.parametrize("policy", ["oracle", "random"])
def test_record_writes_a_rollout(policy, tmp_path, capsys):
    out = tmp_path / "ep.json"
    rc = main(
        ["record", "--policy", policy, "--scene", "lab", "--max-steps", "4", "--out", str(out)]
    )
    assert rc == 0
    assert f"wrote {out}" in capsys.readouterr().out
    ro = load_rollout(out)
    assert ro["format"] == FORMAT and ro["policy"] == policy
    assert ro["env_id"] == "sensorplan/Recognize-v0" and 2 <= len(ro["steps"]) <= 5


def test_record_rollout_takes_a_policy_factory():
    from agents import OraclePolicy

    made = []

    def factory(env):
        made.append(env)
        return OraclePolicy(env)

    ro = record_rollout("sensorplan/Navigate-v0", policy=factory, seed=1, max_steps=3, scene="lab")
    assert len(made) == 1 and ro["policy"] == "factory"
    with pytest.raises(ValueError, match="callable env -> policy"):
        record_rollout("sensorplan/Navigate-v0", policy="oracle", scene="lab")


def test_record_names_a_missing_model(tmp_path, capsys):
    rc = main(["record", "--policy", str(tmp_path / "none.zip"), "--out", str(tmp_path / "x.json")])
    assert rc == 2
    assert "none.zip" in capsys.readouterr().err
    assert not (tmp_path / "x.json").exists()
