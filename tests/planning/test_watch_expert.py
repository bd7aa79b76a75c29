"""The watch oracle as a teacher (issue 22 item 4): as a controller it declares right and
watches as the oracle does; its answer depends on the state, not on its own history."""

from __future__ import annotations

import numpy as np
import pytest

from agents.planning.watch_expert import WatchExpert
from agents.planning.watch_oracle import WatchOracle
from sensorplan_gym import watch_v0

SEEDS = [1_000_000 + i for i in range(6)]


def _play(env, policy, seed):
    obs, _ = env.reset(seed=seed)
    if isinstance(policy, WatchOracle):
        policy.reset()
    while env.agents:
        obs, _, _, _, info = env.step(policy.act(obs))
    return [i["is_success"] for i in info.values()], [i["visible_fraction"] for i in info.values()]


@pytest.mark.parametrize("placement", ["oracle", "both"])
def test_expert_declares_right_and_watches(placement):
    env = watch_v0.parallel_env(scene="lab", n_watchers=2, evidence=True)
    ex = WatchExpert(env, placement=placement)
    orc = WatchOracle(watch_v0.parallel_env(scene="lab", n_watchers=2, evidence=True))
    ok, vis, ovis = [], [], []
    for s in SEEDS:
        r, v = _play(env, ex, s)
        ok += r
        vis += v
        ovis += _play(orc.env, orc, s)[1]
    assert all(ok), ok
    if placement == "oracle":  # the oracle's placement, replanned every step: the same view
        assert np.mean(vis) == pytest.approx(np.mean(ovis), abs=0.03), (vis, ovis)
    else:  # each watcher sees A anywhere in G u H: more steps in view than a G/H split
        assert np.mean(vis) > np.mean(ovis) + 0.05, (vis, ovis)


def test_expert_is_a_function_of_the_state():
    """Two experts, one fresh, answer the same from the same state mid-episode."""
    env = watch_v0.parallel_env(scene="lab", n_watchers=2, evidence=True)
    ex = WatchExpert(env)
    obs, _ = env.reset(seed=SEEDS[0])
    rng = np.random.default_rng(0)
    for _ in range(60):  # random driving: states the oracle would never visit
        obs, *_ = env.step({a: rng.uniform(-1, 1, 4).astype(np.float32) for a in env.agents})
        a1 = ex.act(obs)
    a2 = WatchExpert(env).act(obs)
    for k in a1:
        np.testing.assert_array_equal(a1[k], a2[k])
        assert a1[k].shape == (4,) and np.all(np.abs(a1[k]) <= 1)


def test_expert_bad_input():
    with pytest.raises(ValueError, match="evidence=True"):
        WatchExpert(watch_v0.parallel_env(scene="lab"))
    env = watch_v0.parallel_env(scene="lab", evidence=True)
    with pytest.raises(ValueError, match="placement"):
        WatchExpert(env, placement="near")
    with pytest.raises(ValueError, match="decide_window"):
        WatchExpert(env, decide_window=0)
