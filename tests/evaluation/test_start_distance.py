"""Random starts honour ``min_start_distance`` (measured over episodes)."""

import gymnasium as gym
import numpy as np
import pytest

import sensorplan_gym  # noqa: F401


@pytest.mark.parametrize("env_id", ["sensorplan/Recognize-v0", "sensorplan/Navigate-v0"])
def test_random_starts_keep_min_start_distance(env_id):
    d = 0.35
    env = gym.make(
        env_id, scene="random", random_start=True, min_start_distance=d, max_scene_tries=200
    )
    ds = []
    for s in range(12):
        _, info = env.reset(seed=1000 + s)
        ds.append(info["distance_to_region"] / env.unwrapped.world.diameter)
    env.close()
    assert min(ds) >= d - 1e-9, ds
    assert np.mean(ds) >= d
