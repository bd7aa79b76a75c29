"""Training tooling: hyperparameter overrides, several seeds, checkpoints and resume."""

from __future__ import annotations

import pytest

pytest.importorskip("stable_baselines3")

from agents.cli import _hp_overrides, main  # noqa: E402


def test_hp_overrides_parse_yaml_values():
    assert _hp_overrides(["n_steps=64", "learning_rate=1e-4", "policy_kwargs={net_arch: [8]}"]) == {
        "n_steps": 64,
        "learning_rate": 1e-4,
        "policy_kwargs": {"net_arch": [8]},
    }
    with pytest.raises(ValueError, match="KEY=VALUE"):
        _hp_overrides(["n_steps"])


def test_seeds_checkpoints_and_resume(tmp_path, capsys):
    import yaml
    from stable_baselines3 import PPO

    common = [
        "--env",
        "sensorplan/Navigate-v0",
        "--algo",
        "ppo",
        "--no-progress",
        "--no-tensorboard",
        "--hp",
        "n_steps=32",
        "batch_size=32",
    ]
    assert (
        main(
            [
                "train",
                *common,
                "--timesteps",
                "128",
                "--seeds",
                "3",
                "4",
                "--checkpoint-freq",
                "64",
                "--out",
                str(tmp_path / "run"),
            ]
        )
        == 0
    )
    for s in (3, 4):
        d = tmp_path / f"run_s{s}"
        rec = yaml.safe_load((d / "final_model.yaml").read_text())
        assert rec["seed"] == s and rec["hyperparams"]["n_steps"] == 32
        assert sorted(p.name for p in (d / "checkpoints").iterdir()) == [
            "ppo_128_steps.zip",
            "ppo_64_steps.zip",
        ]
    assert (
        main(
            [
                "train",
                *common,
                "--timesteps",
                "64",
                "--resume",
                str(tmp_path / "run_s3" / "final_model.zip"),
                "--out",
                str(tmp_path / "res"),
            ]
        )
        == 0
    )
    assert PPO.load(tmp_path / "res" / "final_model.zip").num_timesteps == 128 + 64
    assert main(["train", *common, "--resume", str(tmp_path / "nope.zip")]) == 2
    assert "no saved model" in capsys.readouterr().err


def test_best_model_selected_on_a_validation_pool_and_config_round_trips(tmp_path):
    import yaml

    from agents.learning.train import load_hyperparams, train

    kw = dict(
        timesteps=64,
        env_kwargs={"scene": "random", "scene_pool_size": 4},
        progress_bar=False,
        tensorboard=False,
        verbose=0,
        eval_freq=64,
        eval_episodes=2,
    )
    hp = {"n_steps": 32, "batch_size": 32, "n_envs": 2, "frame_stack": 2}
    # the evaluation env really is built with eval_env_kwargs: a bad one fails there
    with pytest.raises(TypeError, match="bogus"):
        train(
            "sensorplan/Placement-v0",
            "ppo",
            out=tmp_path / "bad",
            hp_overrides={**hp, "eval_env_kwargs": {"bogus": 1}},
            **kw,
        )
    res = train(
        "sensorplan/Placement-v0",
        "ppo",
        out=tmp_path / "val",
        hp_overrides={**hp, "eval_env_kwargs": {"scene_pool_seed": 2}},
        **kw,
    )
    rec = yaml.safe_load((tmp_path / "val" / "final_model.yaml").read_text())
    assert rec["eval"]["env_kwargs"] == {"scene_pool_seed": 2}
    assert rec["env_kwargs"]["scene_pool_size"] == 4 and "scene_pool_seed" not in rec["env_kwargs"]
    # a resolved config gives back the meta keys training recorded outside ``hyperparams``
    section = load_hyperparams("ppo", "sensorplan/Placement-v0", res["out"] + "/final_model.yaml")
    assert section["eval_env_kwargs"] == {"scene_pool_seed": 2}
    assert section["frame_stack"] == 2 and "normalize" not in section
