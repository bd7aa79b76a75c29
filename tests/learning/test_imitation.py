"""Issue 22 item 2: oracle demonstrations as Minari datasets, behaviour cloning and DAgger."""

from __future__ import annotations

import time

import gymnasium as gym
import numpy as np
import pytest

pytest.importorskip("stable_baselines3")
torch = pytest.importorskip("torch")

from stable_baselines3 import PPO, SAC  # noqa: E402

from agents.learning.imitation import (  # noqa: E402
    collect,
    dagger,
    fit,
    success_rate,
    train_imitation,
)
from agents.learning.vecenv import BatchedVecEnv  # noqa: E402
from agents.planning.oracle import OraclePolicy  # noqa: E402

NAV = "sensorplan/Navigate-v0"
# four procedural scenes, each with its own fixed start: four deterministic episodes (the
# commanded pose evolves exactly and Navigate ends when it recognizes), so a success rate over
# them is a fraction of 4 with no sampling error
TINY = {"scene": "random", "scene_pool_size": 4, "random_start": False}


def _ppo(venv, net=(64, 64)) -> PPO:
    torch.set_num_threads(1)
    return PPO(
        "MlpPolicy",
        BatchedVecEnv(venv),
        seed=0,
        device="cpu",
        policy_kwargs={"net_arch": list(net)},
    )


def test_dagger_on_a_tiny_pool_reaches_the_oracle_quickly():
    t0 = time.process_time()  # CPU time: what the machine's other load does not change
    venv = gym.make_vec(NAV, num_envs=8, **TINY)
    model = _ppo(venv)
    before = success_rate(model.policy, NAV, TINY, 32, n_envs=8)
    res = dagger(venv, model.policy, iterations=6, steps=40, epochs=20, seed=0)
    learner = success_rate(model.policy, NAV, TINY, 32, n_envs=8)
    oracle = success_rate(None, NAV, TINY, 32, n_envs=8)
    assert oracle == 1.0
    # deterministic episodes: the learner must solve all four, exactly as the oracle does
    assert learner == oracle, (before, learner, res.history)
    assert before < 1.0  # the untrained policy does not (the test can fail)
    assert [h["beta"] for h in res.history] == [0.5**i for i in range(6)]
    assert res.history[-1]["expert_fraction"] < 0.2
    assert time.process_time() - t0 < 45  # about 10 s of CPU measured


def test_collect_records_oracle_labels_of_the_states_the_learner_visits():
    venv = gym.make_vec(NAV, num_envs=4, **TINY)
    model = _ppo(venv)
    oracle = OraclePolicy(venv)
    x, y, _, stats = collect(venv, oracle, model.policy, 30, beta=0.0, rng=np.random.default_rng(0))
    assert x.shape[1:] == venv.single_observation_space.shape
    assert y.shape == (len(x), *venv.single_action_space.shape)
    assert stats["expert_fraction"] == 0.0
    assert np.all(np.abs(y) <= 1.0 + 1e-6)
    with pytest.raises(ValueError, match="beta"):
        collect(venv, oracle, model.policy, 1, beta=1.5)


@pytest.mark.parametrize("algo", ["ppo", "sac"])
def test_behaviour_cloning_fits_oracle_actions(algo):
    venv = gym.make_vec(NAV, num_envs=8, **TINY)
    x, y, _, _ = collect(venv, OraclePolicy(venv), None, 40, beta=1.0)
    torch.set_num_threads(1)
    if algo == "ppo":
        policy = _ppo(venv).policy
    else:
        policy = SAC(
            "MlpPolicy",
            BatchedVecEnv(venv),
            seed=0,
            device="cpu",
            policy_kwargs={"net_arch": [64, 64]},
        ).policy
    losses = fit(policy, x, y, epochs=40, batch_size=128, seed=0)
    assert losses[-1] < 0.25 * losses[0]
    pred, _ = policy.predict(x[:64], deterministic=True)
    assert np.mean(np.abs(pred - y[:64])) < 0.25


def test_nll_loss_trains_the_ppo_distribution_and_is_refused_for_sac():
    venv = gym.make_vec(NAV, num_envs=4, **TINY)
    x, y, _, _ = collect(venv, OraclePolicy(venv), None, 20, beta=1.0)
    losses = fit(_ppo(venv).policy, x, y, epochs=15, loss="nll")
    assert losses[-1] < losses[0]
    sac = SAC("MlpPolicy", BatchedVecEnv(venv), device="cpu")
    with pytest.raises(TypeError, match="ActorCriticPolicy"):
        fit(sac.policy, x, y, loss="nll")
    with pytest.raises(ValueError, match="loss"):
        fit(sac.policy, x, y, loss="l1")


def test_train_imitation_dagger_then_ppo_writes_a_loadable_ppo_model(tmp_path):
    rec = train_imitation(
        NAV,
        "dagger+ppo",
        out=tmp_path,
        overrides={
            "n_envs": 4,
            "env_kwargs": TINY,
            "eval_env_kwargs": {},
            "eval": {"episodes": 8},
            "dagger": {"iterations": 2, "steps": 16, "epochs": 2},
            "finetune": {"timesteps": 256, "log_std": -1.0},
            "ppo": {"n_steps": 32, "batch_size": 64, "n_epochs": 1},
        },
        verbose=0,
    )
    assert len(rec["imitation"]) == 2 and rec["ppo_timesteps"] >= 256
    model = PPO.load(tmp_path / "final_model.zip", device="cpu")
    assert (tmp_path / "best_model.yaml").is_file()
    obs = np.zeros((1, *model.observation_space.shape), dtype=np.float32)
    assert model.predict(obs, deterministic=True)[0].shape == (1, 3)
    with pytest.raises(ValueError, match="method"):
        train_imitation(NAV, "gail", out=tmp_path)


def test_minari_round_trip(tmp_path):
    pytest.importorskip("minari")
    from agents.learning.dataset import load_dataset, record_dataset, transitions

    kw = {"scene": "lab", "random_start": True, "map_ranges": True}
    record_dataset(
        "sensorplan/Recognize-v0",
        "sensorplan/rec-lab-oracle-v0",
        3,
        env_kwargs=kw,
        seed=5,
        data_path=tmp_path,
    )
    ds = load_dataset("sensorplan/rec-lab-oracle-v0", tmp_path)
    env = gym.make("sensorplan/Recognize-v0", **kw)
    assert ds.total_episodes == 3
    assert ds.observation_space == env.observation_space
    assert ds.action_space == env.action_space
    for ep in ds.iterate_episodes():
        t = len(ep.actions)
        assert ep.observations.shape == (t + 1, *env.observation_space.shape)
        assert ep.actions.shape == (t, *env.action_space.shape)
        assert ep.rewards.shape == (t,) and ep.terminations[-1]  # the oracle declares
    x, y = transitions(ds)
    assert len(x) == len(y) == ds.total_steps
    # the recorded first observation is the env's at the recorded seed
    first = next(iter(ds.iterate_episodes()))
    np.testing.assert_array_equal(first.observations[0], env.reset(seed=5)[0])
    assert ds.recover_environment().spec.kwargs == kw
    with pytest.raises(ValueError, match="exists"):
        record_dataset(
            "sensorplan/Recognize-v0",
            "sensorplan/rec-lab-oracle-v0",
            1,
            env_kwargs=kw,
            data_path=tmp_path,
        )
    with pytest.raises(ValueError, match="name-v0"):
        record_dataset("sensorplan/Recognize-v0", "no_version", 1, data_path=tmp_path)


def test_cli_dataset_record_and_imitate_entry(tmp_path, capsys):
    pytest.importorskip("minari")
    from agents.cli import main

    rc = main(
        [
            "dataset",
            "record",
            "--env",
            NAV,
            "--episodes",
            "2",
            "--dataset-id",
            "sensorplan/nav-lab-v0",
            "--data-path",
            str(tmp_path),
        ]
    )
    assert rc == 0 and "2 episodes" in capsys.readouterr().out
    rc = main(
        [
            "dataset",
            "record",
            "--env",
            NAV,
            "--episodes",
            "1",
            "--dataset-id",
            "sensorplan/nav-lab-v0",
            "--data-path",
            str(tmp_path),
        ]
    )
    assert rc == 2 and "exists" in capsys.readouterr().err
    rc = main(
        [
            "imitate",
            "--env",
            NAV,
            "--method",
            "bc",
            "--out",
            str(tmp_path / "bc"),
            "--overrides",
            '{"n_envs": 2, "env_kwargs": {"scene": "lab"}, "eval": {},'
            ' "bc": {"steps": 8, "epochs": 1}}',
        ]
    )
    assert rc == 0 and (tmp_path / "bc" / "final_model.zip").is_file()
    # saved with a narrow spread: SB3's sampling predict stays near the imitated mean
    from stable_baselines3 import PPO

    from agents.learning.imitation import IMITATED_LOG_STD

    model = PPO.load(tmp_path / "bc" / "final_model.zip", device="cpu")
    assert np.all(model.policy.log_std.detach().numpy() == np.float32(IMITATED_LOG_STD))


def test_dagger_from_the_hint_rule_fits_the_rule_labels():
    """``expert="hint-rule"``: the labels are the rule's actions on the visited observations
    (a function of the observation), and the fitted policy reproduces them; an unknown
    expert is refused by name."""
    from agents.learning.imitation import make_expert
    from agents.planning.hint_rule import ENV_KWARGS, HintRulePolicy

    kw = {**TINY, **ENV_KWARGS}
    venv = gym.make_vec(NAV, num_envs=4, **kw)
    assert isinstance(make_expert("hint-rule", venv), HintRulePolicy)
    with pytest.raises(ValueError, match="expert must be 'oracle' or one of hint-rule"):
        make_expert("teacher", venv)
    model = _ppo(venv)
    res = dagger(venv, model.policy, iterations=2, steps=24, epochs=30, seed=0, expert="hint-rule")
    rule = HintRulePolicy(venv)
    np.testing.assert_allclose(res.acts, rule.predict(res.obs)[0], atol=1e-6)
    with torch.no_grad():
        mine = model.policy._predict(torch.as_tensor(res.obs, dtype=torch.float32), True).numpy()
    err = np.abs(np.clip(mine, -1, 1) - res.acts).mean()
    untrained = np.abs(
        np.clip(_ppo(venv).policy.predict(res.obs, deterministic=True)[0], -1, 1) - res.acts
    ).mean()
    assert err < 0.5 * untrained, (err, untrained)
    venv.close()
