"""Memory and preprocessing for learned baselines: frame stacking, observation
normalization (VecNormalize), sb3-contrib's RecurrentPPO and QR-DQN, stochastic evaluation.

The key property: a model trained behind ``VecFrameStack(VecNormalize(...))`` and loaded by
:func:`agents.learning.policies.load_policy` acts on a plain single env exactly as it did behind the
training-time wrappers.
"""

from __future__ import annotations

import pickle
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("stable_baselines3")
pytest.importorskip("yaml")

import gymnasium as gym  # noqa: E402
import yaml  # noqa: E402
from stable_baselines3.common.vec_env import DummyVecEnv, VecFrameStack  # noqa: E402

import sensorplan_gym  # noqa: E402,F401
from agents.evaluation.evaluate import evaluate, run_episodes  # noqa: E402
from agents.learning.policies import ModelPolicy, load_policy, vecnormalize_path  # noqa: E402
from agents.learning.train import train  # noqa: E402

REC = "sensorplan/Recognize-v0"
NAV = "sensorplan/Navigate-v0"
PLACE = "sensorplan/Placement-v0"
REC_KW = {"scene": "lab", "map_ranges": True, "map_evidence": True, "declare_hold": 3}


def _train(tmp: Path, env_id: str, algo: str, section: dict, **kw) -> dict:
    cfg = tmp / f"{algo}.yaml"
    cfg.write_text(yaml.safe_dump({env_id: section}))
    return train(
        env_id,
        algo,
        config=cfg,
        out=tmp / "run",
        progress_bar=False,
        tensorboard=False,
        verbose=0,
        **kw,
    )


@pytest.fixture(scope="module")
def stacked_run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("fs")
    section = {
        "n_envs": 4,
        "frame_stack": 3,
        "normalize": True,
        "env_kwargs": {**REC_KW, "shaping": 4.0, "random_start": True},
        "n_steps": 64,
        "batch_size": 64,
        "n_epochs": 1,
        "policy_kwargs": {"net_arch": [16, 16], "activation_fn": "tanh"},
    }
    return _train(tmp, REC, "ppo", section, timesteps=512, seed=0, eval_freq=256, eval_episodes=1)


def test_stacked_normalized_run_records_and_saves_its_preprocessing(stacked_run):
    out = Path(stacked_run["out"])
    cfg = yaml.safe_load((out / "best_model.yaml").read_text())
    assert cfg["frame_stack"] == 3
    assert cfg["normalize"] is True and cfg["normalize_kwargs"] == {}
    for name in ("best_model", "final_model"):
        stats = vecnormalize_path(out / f"{name}.zip")
        assert stats == out / f"{name}_vecnormalize.pkl" and stats.is_file()
    env = gym.make(REC, **REC_KW)
    policy = load_policy(stacked_run["best_model"], env)
    assert isinstance(policy, ModelPolicy)
    assert policy.frame_stack == 3 and policy.vecnormalize is not None
    single = env.observation_space.shape[0]
    assert policy.model.observation_space.shape == (3 * single,)


def test_loaded_policy_acts_as_behind_the_training_wrappers(stacked_run):
    """ModelPolicy on gym.make == the model behind VecFrameStack(VecNormalize(DummyVecEnv))
    with the saved statistics, step by step over whole episodes."""
    path = Path(stacked_run["best_model"])
    kw = {**REC_KW, "random_start": True}
    env = gym.make(REC, **kw)
    policy = load_policy(str(path), env)
    with open(vecnormalize_path(path), "rb") as f:
        vn = pickle.load(f)
    ref_env = DummyVecEnv([lambda: gym.make(REC, **kw)])
    vn.set_venv(ref_env)
    vn.training, vn.norm_reward = False, False
    ref = VecFrameStack(vn, 3)
    steps = 0
    for seed in (11, 12):
        obs, _ = env.reset(seed=seed)
        ref.seed(seed)
        robs = ref.reset()
        start, done = True, False
        while not done:
            a, _ = policy.predict(obs, episode_start=np.array([start]), deterministic=True)
            ra, _ = policy.model.predict(robs, deterministic=True)
            np.testing.assert_array_equal(a, ra[0])
            obs, _, term, trunc, _ = env.step(a)
            robs, _, rdone, _ = ref.step(ra)
            done, start = term or trunc, False
            assert bool(rdone[0]) == done
            steps += 1
    assert steps > 4  # more than one stacked frame was compared


def test_plain_predict_loop_notices_new_episodes(stacked_run):
    """``policy.predict(obs)`` in a plain loop, as a user writes it (no ``episode_start``),
    plays exactly as with ``episode_start``: the policy bound to its env starts a new frame
    stack at each reset, and keeps stacking within an episode.  Unbound, it refuses."""
    kw = {**REC_KW, "random_start": True}
    actions = []
    for plain in (False, True):
        env = gym.make(REC, **kw)
        policy = load_policy(stacked_run["best_model"], env)
        acts = []
        for seed in (21, 22, 23):
            obs, _ = env.reset(seed=seed)
            start, done = True, False
            while not done:
                if plain:
                    a, _ = policy.predict(obs, deterministic=True)
                else:
                    a, _ = policy.predict(obs, episode_start=np.array([start]), deterministic=True)
                acts.append(np.asarray(a).copy())
                obs, _, term, trunc, _ = env.step(a)
                done, start = term or trunc, False
        actions.append(np.stack(acts))
    np.testing.assert_array_equal(actions[0], actions[1])
    assert len(actions[0]) > 6
    env = gym.make(REC, **kw)
    bound = load_policy(stacked_run["best_model"], env)
    unbound = ModelPolicy(bound.model, env.observation_space, frame_stack=3)
    obs, _ = env.reset(seed=0)
    with pytest.raises(ValueError, match="pass episode_start"):
        unbound.predict(obs)
    unbound.predict(obs, episode_start=np.array([True]))  # given: fine


def test_missing_normalization_statistics_fail_clearly(stacked_run, tmp_path):
    out = Path(stacked_run["out"])
    for suffix in (".zip", ".yaml"):
        (tmp_path / f"m{suffix}").write_bytes((out / f"best_model{suffix}").read_bytes())
    env = gym.make(REC, **REC_KW)
    with pytest.raises(FileNotFoundError, match="statistics"):
        load_policy(str(tmp_path / "m.zip"), env)


def test_stochastic_evaluation_is_seeded_and_recorded(stacked_run, tmp_path):
    kw = {**REC_KW, "random_start": True}
    runs = [
        evaluate(
            REC,
            [stacked_run["best_model"]],
            episodes=3,
            seed=5,
            env_kwargs=kw,
            out=tmp_path / f"e{i}",
            plot=False,
            verbose=False,
            deterministic=False,
        )
        for i in range(2)
    ]
    assert runs[0]["deterministic"] is False and runs[0]["independent_episodes"] is True
    a, b = (r["policies"][0]["per_episode"] for r in runs)
    assert a == b


def test_fixed_start_episodes_are_marked_dependent(tmp_path):
    r = evaluate(NAV, ["random"], episodes=2, env_kwargs={"scene": "lab"}, out=False, verbose=False)
    assert r["independent_episodes"] is False
    r = evaluate(
        NAV,
        ["random"],
        episodes=2,
        env_kwargs={"scene": "lab", "random_start": True},
        out=False,
        verbose=False,
    )
    assert r["independent_episodes"] is True


def test_recurrent_ppo_trains_and_plays(tmp_path):
    pytest.importorskip("sb3_contrib")
    section = {
        "n_envs": 4,
        "policy": "MlpLstmPolicy",
        "env_kwargs": {"scene": "lab", "shaping": 4.0},
        "n_steps": 32,
        "batch_size": 64,
        "n_epochs": 1,
        "policy_kwargs": {"net_arch": [16], "lstm_hidden_size": 8},
    }
    rec = _train(tmp_path, NAV, "recurrentppo", section, timesteps=256, seed=0, eval_freq=10**6)
    env = gym.make(NAV, scene="lab", max_steps=20)
    policy = load_policy(rec["best_model"], env)
    assert type(policy).__name__ == "RecurrentPPO"
    ep = run_episodes(env, policy, [1, 2])
    assert ep["steps"][0] >= 1 and len(ep["success"]) == 2


def test_qrdqn_trains_on_discrete_actions(tmp_path):
    pytest.importorskip("sb3_contrib")
    section = {
        "n_envs": 2,
        "env_kwargs": {"scene": "lab", "action_type": "discrete"},
        "learning_starts": 32,
        "buffer_size": 1000,
        "batch_size": 16,
        "policy_kwargs": {"net_arch": [16], "n_quantiles": 5},
    }
    rec = _train(tmp_path, PLACE, "qrdqn", section, timesteps=128, seed=0, eval_freq=10**6)
    env = gym.make(PLACE, scene="lab", action_type="discrete")
    policy = load_policy(rec["best_model"], env)
    assert type(policy).__name__ == "QRDQN"
    a, _ = policy.predict(env.reset(seed=0)[0], deterministic=True)
    assert env.action_space.contains(int(a))
    (tmp_path / "c").mkdir()
    with pytest.raises(ValueError, match="Discrete"):
        _train(tmp_path / "c", PLACE, "qrdqn", {"env_kwargs": {"scene": "lab"}}, timesteps=8)
