"""``random_start=True``: every episode starts from a seeded random pose that does not
recognize yet and from which the recognizable region is reachable."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import sensorplan_gym  # noqa: F401

IDS = ["sensorplan/Navigate-v0", "sensorplan/Recognize-v0"]


@pytest.mark.parametrize("env_id", IDS)
def test_random_starts_are_seeded_valid_and_varied(env_id):
    env = gym.make(env_id, scene="lab", random_start=True)
    w = env.unwrapped.world
    poses = []
    for seed in range(8):
        env.reset(seed=seed)
        x, y, psi = env.unwrapped.pose
        assert w.in_free_space(x, y) and not w.recognizing(x, y, psi)
        assert not w.reachable_region((x, y)).is_empty
        poses.append((x, y, psi))
    assert len(set(poses)) == len(poses)
    again = gym.make(env_id, scene="lab", random_start=True)
    again.reset(seed=3)
    assert again.unwrapped.pose == poses[3]


@pytest.mark.parametrize("env_id", IDS)
def test_random_start_passes_check_env(env_id):
    check_env(gym.make(env_id, scene="edr", random_start=True).unwrapped, skip_render_check=True)


def test_default_start_is_the_scenes():
    env = gym.make("sensorplan/Navigate-v0", scene="lab")
    env.reset(seed=1)
    assert np.allclose(env.unwrapped.pose, env.unwrapped.world.scene.start)


def test_random_start_must_be_a_bool():
    with pytest.raises(ValueError, match="random_start"):
        gym.make("sensorplan/Navigate-v0", scene="lab", random_start="yes")
