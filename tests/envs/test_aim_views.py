"""Placement's ``aim_views`` grid channels: per aim of the pixel actions, where that aim passes
the reward's aim test.  Checked against the env's own ``aim_ok`` of every pixel action."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env

import sensorplan_gym  # noqa: F401
from sensorplan_gym.envs.placement import PlacementBatch

KW = {"obs_type": "grid", "grid_views": True, "hull_views": True, "self_features": True}


def test_channels_and_order():
    plain = gym.make("sensorplan/Placement-v0", scene="lab", **KW, placement_aims=12)
    env = gym.make("sensorplan/Placement-v0", scene="lab", aim_views=True, **KW, placement_aims=12)
    check_env(env.unwrapped, skip_render_check=True)
    a, _ = plain.reset(seed=0)
    b, _ = env.reset(seed=0)
    assert a.shape[0] == 9 and b.shape[0] == 21 == env.observation_space.shape[0]
    assert np.array_equal(b[:7], a[:7]) and np.array_equal(b[19:], a[7:])
    world = env.unwrapped.batch.source.world
    assert np.array_equal(b[7:19], world.aim_raster(b.shape[1], 12))


@pytest.mark.parametrize(("scene", "kw"), [
    ("lab", {"fov_deg": 60.0}),
    ("warehouse", {"fov_deg": 90.0, "eps_aim": 0.05, "eps_pos": 0.1}),
    ("corridor", {"fov_deg": 120.0, "max_range": 10.0}),
])  # fmt: skip
def test_channels_are_the_rewards_aim_test(scene, kw):
    batch = PlacementBatch(1, scene=scene, action_type="pixel", aim_views=True, **KW, **kw)
    world = batch.source.world
    size, aims = batch.obs.size, batch.obs.aim_views
    got = world.aim_raster(size, aims) > 0  # (A, S, S)
    tab = batch.actions.table
    idx = np.zeros(len(tab), dtype=np.int64)
    _, cols = batch.evaluate(batch.action_to_pose(batch.square_to_box(tab, idx), idx), idx)
    want = np.asarray(cols["aim_ok"][0]).reshape(size, size, aims).transpose(2, 0, 1)
    # pixels of the square's padding are clipped onto the bounding box by the action
    scale, ox, oy = world.grid_transform(size)
    c = ox + (np.arange(size) + 0.5) / scale
    r = oy + (size - np.arange(size) - 0.5) / scale
    inside = ((r >= world.lo[1]) & (r <= world.hi[1]))[:, None] & (
        (c >= world.lo[0]) & (c <= world.hi[0])
    )[None, :]
    assert np.array_equal(got[:, inside], want[:, inside])
    assert got[:, inside].any() and not got[:, inside].all()  # both kinds checked


def test_aim_views_need_placements_grid():
    with pytest.raises(ValueError, match="aim_views=True needs obs_type='grid' in Placement"):
        PlacementBatch(1, scene="edr", aim_views=True)
    with pytest.raises(ValueError, match="aim_views"):
        gym.make("sensorplan/Navigate-v0", scene="edr", aim_views=True)
    with pytest.raises(ValueError, match="aim_views must be True or False"):
        PlacementBatch(1, scene="edr", obs_type="grid", aim_views=1)
