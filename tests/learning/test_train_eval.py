"""Smoke tests of the SB3 training / evaluation pipeline and the ``sensorplan`` CLI.

Oracle-specific behaviour is tested elsewhere; here the oracle appears at most as a spec.
"""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("stable_baselines3")
pytest.importorskip("yaml")

import gymnasium as gym  # noqa: E402
import yaml  # noqa: E402

import sensorplan_gym  # noqa: E402,F401
from agents.cli import build_parser, main  # noqa: E402
from agents.evaluation.evaluate import EVAL_SEED_BASE, evaluate  # noqa: E402
from agents.learning.policies import RandomPolicy, load_policy, model_config  # noqa: E402
from agents.learning.train import CONFIG_DIR, EVAL_SEED_OFFSET, load_hyperparams, train  # noqa: E402

NAV = "sensorplan/Navigate-v0"
SHIPPED = Path(__file__).resolve().parents[2] / "agents" / "pretrained" / "ppo_navigate_lab.zip"

TINY_PPO = {
    "n_steps": 64,
    "batch_size": 32,
    "n_epochs": 1,
    "policy_kwargs": {"net_arch": [16, 16], "activation_fn": "tanh"},
    "env_kwargs": {"scene": "lab", "shaping": 1.0},
}


@pytest.fixture(scope="module")
def tiny_run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("train")
    cfg = tmp / "tiny.yaml"
    cfg.write_text(yaml.safe_dump({NAV: TINY_PPO}))
    rec = train(
        NAV,
        "ppo",
        timesteps=256,
        seed=3,
        n_envs=2,
        config=cfg,
        out=tmp / "run",
        eval_freq=128,
        eval_episodes=1,
        vec_env="dummy",
        progress_bar=False,
        tensorboard=False,
        verbose=0,
    )
    return rec


def test_train_writes_model_and_resolved_config(tiny_run):
    out = Path(tiny_run["out"])
    for name in ("best_model.zip", "best_model.yaml", "final_model.zip", "final_model.yaml"):
        assert (out / name).is_file(), name
    cfg = model_config(out / "best_model.zip")
    assert cfg["algo"] == "ppo" and cfg["env_id"] == NAV and cfg["seed"] == 3
    assert cfg["timesteps"] == 256 and cfg["n_envs"] == 2
    assert cfg["env_kwargs"] == {"scene": "lab", "shaping": 1.0}
    assert cfg["hyperparams"]["n_steps"] == 64
    assert cfg["eval"]["seed"] == 3 + EVAL_SEED_OFFSET
    assert "sensorplan-gym" in cfg["versions"]
    # the resolved config is itself a valid --config
    hp = load_hyperparams("ppo", NAV, out / "best_model.yaml")
    assert hp["n_steps"] == 64 and hp["env_kwargs"]["shaping"] == 1.0


def test_trained_model_loads_and_acts(tiny_run):
    env = gym.make(NAV, scene="lab")
    model = load_policy(tiny_run["best_model"], env)
    obs, _ = env.reset(seed=0)
    action, state = model.predict(obs, deterministic=True)
    assert env.action_space.contains(np.asarray(action, dtype=np.float32))
    env.step(action)
    env.close()


def test_load_policy_without_config_tries_algorithms(tiny_run, tmp_path):
    import shutil

    bare = tmp_path / "bare.zip"
    shutil.copyfile(tiny_run["best_model"], bare)
    assert model_config(bare) is None
    env = gym.make(NAV)
    assert hasattr(load_policy(str(bare), env), "predict")
    with pytest.raises(FileNotFoundError):
        load_policy(str(tmp_path / "missing.zip"), env)


def test_random_policy_batches_and_is_seeded():
    env = gym.make(NAV)
    p1 = RandomPolicy(env.action_space, seed=5, observation_space=env.observation_space)
    p2 = RandomPolicy(env.action_space, seed=5, observation_space=env.observation_space)
    obs, _ = env.reset(seed=0)
    a1, _ = p1.predict(obs)
    a2, _ = p2.predict(obs)
    assert a1.shape == (3,) and np.array_equal(a1, a2)
    batch, _ = p1.predict(np.stack([obs, obs, obs]))
    assert batch.shape == (3, 3)


def test_dqn_on_box_env_fails_clearly(tmp_path, capsys):
    with pytest.raises(ValueError, match=r"DQN needs a Discrete action space.*Box"):
        train(
            NAV,
            "dqn",
            timesteps=10,
            out=tmp_path / "dqn",
            env_kwargs={"action_type": "continuous"},
            progress_bar=False,
            tensorboard=False,
            verbose=0,
        )
    # the shipped DQN config makes the env with discrete actions
    rec = train(
        NAV,
        "dqn",
        timesteps=64,
        out=tmp_path / "dqn_ok",
        hp_overrides={"learning_starts": 16},
        progress_bar=False,
        tensorboard=False,
        verbose=0,
    )
    assert rec["env_kwargs"]["action_type"] == "discrete"
    rc = main(
        [
            "train",
            "--env",
            NAV,
            "--algo",
            "dqn",
            "--timesteps",
            "10",
            "--env-kwargs",
            '{"action_type": "continuous"}',
            "--out",
            str(tmp_path / "dqn2"),
            "--no-progress",
        ]
    )
    assert rc == 2
    err = capsys.readouterr().err
    assert "DQN needs a Discrete action space" in err and "Box" in err


def test_configs_cover_every_env():
    for env_id in sensorplan_gym.ENV_IDS:
        hp = load_hyperparams("ppo", env_id)
        assert hp["policy"] == "MlpPolicy"
    assert "n_timesteps" in load_hyperparams("sac", NAV)
    for f in CONFIG_DIR.glob("*.yaml"):
        assert isinstance(yaml.safe_load(f.read_text()), dict), f
    with pytest.raises(KeyError, match="no section"):
        load_hyperparams("td3", "sensorplan/Recognize-v0")


def test_cli_parses():
    p = build_parser()
    a = p.parse_args(
        [
            "train",
            "--env",
            NAV,
            "--algo",
            "sac",
            "--timesteps",
            "1000",
            "--seed",
            "2",
            "--n-envs",
            "2",
            "--env-kwargs",
            '{"scene": "edr"}',
            "--out",
            "x",
        ]
    )
    assert (a.command, a.algo, a.timesteps, a.seed, a.n_envs) == ("train", "sac", 1000, 2, 2)
    assert a.env_kwargs == {"scene": "edr"}
    a = p.parse_args(
        [
            "evaluate",
            "--env",
            NAV,
            "--policies",
            "oracle",
            "random",
            "m.zip",
            "--episodes",
            "7",
            "--seed",
            "1",
        ]
    )
    assert a.policies == ["oracle", "random", "m.zip"] and a.episodes == 7
    with pytest.raises(SystemExit):
        p.parse_args(["train", "--env", NAV, "--algo", "nope"])
    with pytest.raises(SystemExit):
        p.parse_args(["train", "--env", NAV, "--algo", "ppo", "--env-kwargs", "[1]"])


def test_shipped_model_is_small_and_documented():
    assert SHIPPED.is_file(), "agents/pretrained/ppo_navigate_lab.zip is missing"
    assert SHIPPED.stat().st_size < 1_000_000
    cfg = model_config(SHIPPED)
    assert cfg["algo"] == "ppo" and cfg["env_id"] == NAV
    assert cfg["env_kwargs"]["scene"] == "lab" and isinstance(cfg["seed"], int)


def test_evaluate_random_and_shipped_model(tmp_path, capsys):
    rc = main(
        [
            "evaluate",
            "--env",
            NAV,
            "--policies",
            "random",
            str(SHIPPED),
            str(SHIPPED),
            "--episodes",
            "3",
            "--seed",
            "4",
            "--out",
            str(tmp_path),
        ]
    )
    assert rc == 0
    printed = capsys.readouterr().out
    assert "random" in printed and "ppo_navigate_lab" in printed
    for name in ("results.json", "results.csv", "results.png"):
        assert (tmp_path / name).stat().st_size > 0, name
    res = json.loads((tmp_path / "results.json").read_text())
    assert res["episode_seeds"] == [EVAL_SEED_BASE + 4, EVAL_SEED_BASE + 6]
    names = [p["name"] for p in res["policies"]]
    assert names == ["random", "ppo_navigate_lab", "ppo_navigate_lab#2"]
    for p in res["policies"]:
        assert p["episodes"] == 3 and 0 <= p["success_ci95"][0] <= p["success_rate"]
        assert p["success_rate"] <= p["success_ci95"][1] <= 1
        assert p["mean_steps"] >= 1 and p["mean_path_length"] >= 0
        assert p["normalized_score"] is None  # no oracle in this call
    # same model twice, same training seed: no IQM across seeds
    assert res["iqm"] == {}
    rows = list(csv.DictReader(open(tmp_path / "results.csv")))
    assert [r["name"] for r in rows] == names


def test_evaluate_function_iqm_over_training_seeds(tiny_run, tmp_path):
    import shutil

    # two copies of the tiny model, recorded as different training seeds
    # and two more recorded as `sensorplan imitate` DAgger runs (the same algo and env
    # kwargs, another method): a config of their own, not a third and fourth PPO seed
    specs = []
    for s, method in ((11, None), (12, None), (11, "dagger"), (12, "dagger")):
        d = tmp_path / f"seed{s}{method or ''}"
        d.mkdir()
        shutil.copyfile(tiny_run["best_model"], d / "best_model.zip")
        cfg = model_config(tiny_run["best_model"])
        cfg["seed"] = s
        if method:
            cfg.update(method=method, config={"expert": "hint-rule"})
        (d / "best_model.yaml").write_text(yaml.safe_dump(cfg))
        specs.append(str(d / "best_model.zip"))
    res = evaluate(NAV, specs, episodes=2, seed=0, out=False, verbose=False)
    assert [p["train_seed"] for p in res["policies"]] == [11, 12, 11, 12]
    assert set(res["iqm"]) == {"ppo", "ppo+dagger+hint-rule"}
    for a in res["iqm"].values():
        assert a["n_runs"] == 2 and a["ci95"][0] <= a["iqm"] <= a["ci95"][1]
    assert res["files"] == {}


@pytest.mark.parametrize("command", ["evaluate", "train", "benchmark"])
def test_cli_names_an_env_kwarg_the_env_does_not_take(command, capsys):
    args = {
        "evaluate": ["evaluate", "--env", NAV, "--policies", "random", "--episodes", "1"],
        "train": ["train", "--env", NAV, "--algo", "ppo", "--timesteps", "8"],
        "benchmark": ["benchmark", "--env", NAV, "--policies", "random", "--episodes", "1"],
    }[command]
    assert main([*args, "--env-kwargs", '{"fov": 3}']) == 2
    err = capsys.readouterr().err
    assert "'fov'" in err and "Traceback" not in err
