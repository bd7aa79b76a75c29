"""A model is played with the observation kwargs of its resolved training config."""

from pathlib import Path

import pytest

pytest.importorskip("stable_baselines3")
pytest.importorskip("yaml")

from agents.evaluation.evaluate import evaluate  # noqa: E402
from agents.learning.policies import model_config, play_env_kwargs  # noqa: E402

PRETRAINED = Path(__file__).resolve().parents[2] / "agents" / "pretrained"
RECOGNIZE = PRETRAINED / "ppo_recognize_random.zip"


def test_play_kwargs_take_observation_kwargs_and_user_overrides():
    cfg = {
        "env_kwargs": {
            "scene": "random",
            "map_ranges": True,
            "declare_hold": 3,
            "shaping": 4.0,
            "random_start": True,
            "min_start_distance": 0.2,
        }
    }
    kw = play_env_kwargs(cfg, {"scene": "corridor", "declare_hold": 2})
    assert kw == {"map_ranges": True, "declare_hold": 2, "scene": "corridor"}
    assert play_env_kwargs(None, {"scene": "lab"}) == {"scene": "lab"}
    with pytest.raises(ValueError, match="env_kwargs"):
        play_env_kwargs({"env_kwargs": [1]}, {})


def test_shipped_recognize_policy_plays_on_another_scene(tmp_path):
    cfg = model_config(RECOGNIZE)
    assert cfg["env_kwargs"]["map_ranges"] and cfg["frame_stack"] > 1
    res = evaluate(
        "sensorplan/Recognize-v0",
        [str(RECOGNIZE)],
        episodes=3,
        env_kwargs={"scene": "corridor"},
        out=tmp_path,
        verbose=False,
    )
    (p,) = res["policies"]
    assert p["play_env_kwargs"]["scene"] == "corridor"
    assert p["play_env_kwargs"]["map_ranges"] is True
    assert p["play_env_kwargs"]["declare_hold"] == cfg["env_kwargs"]["declare_hold"]
    assert 0.0 <= p["success_rate"] <= 1.0
