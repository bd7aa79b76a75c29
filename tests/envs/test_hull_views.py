"""Placement's ``hull_views`` grid channels: the free space seen from every corner of K_G and
of K_H, checked pixel by pixel against CGAL's visibility polygons (tests/oracle.py)."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
import shapely
from gymnasium.utils.env_checker import check_env

import sensorplan_gym  # noqa: F401
from sensorplan_gym.envs.placement import PlacementBatch

KW = {"obs_type": "grid", "grid_views": True, "self_features": True}


def test_channels_and_order():
    plain = gym.make("sensorplan/Placement-v0", scene="lab", **KW)
    env = gym.make("sensorplan/Placement-v0", scene="lab", hull_views=True, **KW)
    check_env(env.unwrapped, skip_render_check=True)
    a, _ = plain.reset(seed=0)
    b, _ = env.reset(seed=0)
    assert a.shape[0] == 7 and b.shape[0] == 9 and env.observation_space.shape[0] == 9
    assert np.array_equal(b[:5], a[:5]) and np.array_equal(b[7:], a[5:])  # views, hulls, self
    world = env.unwrapped.batch.source.world
    assert np.array_equal(b[5:7], world.hull_view_raster(b.shape[1]))
    assert set(np.unique(b[5:7])) <= {0, 255} and b[5:7].any()


def test_pixels_see_every_corner_against_cgal():
    pytest.importorskip("pyvispoly")
    try:
        from tests.oracle import VisOracle
    except ImportError:  # pragma: no cover
        from oracle import VisOracle

    batch = PlacementBatch(1, scene="warehouse", hull_views=True, **KW)
    world = batch.source.world
    size = 64
    got = world.hull_view_raster(size)
    scale, ox, oy = world.grid_transform(size)
    ij = np.arange(size) + 0.5
    X, Y = np.meshgrid(ox + ij / scale, oy + (size - ij) / scale)
    oracle = VisOracle(world.free_space)
    for k, hull in enumerate(world.must_see):
        views = []
        for v in hull + 1e-9 * (hull.mean(axis=0) - hull):
            vis = oracle.visibility(v)  # empty for a corner outside the free space: left out
            if not vis.is_empty:
                views.append(vis.buffer(1e-9 * world.diameter))
        assert views
        want = np.ones((size, size), dtype=bool)
        for vis in views:
            want &= shapely.contains_xy(vis, X, Y)
        for h in world.must_see:  # outside both hulls only
            want &= ~shapely.contains_xy(shapely.Polygon(h), X, Y)
        near = np.zeros_like(want)  # pixel centres on a view's edge: rounding decides
        for vis in views:
            d = shapely.distance(vis.boundary, shapely.points(X, Y))
            near |= d < 1e-6 * world.diameter
        assert np.array_equal((got[k] > 0)[~near], want[~near])
        assert want.sum() > 50 and (~want).sum() > 50  # both kinds of pixel checked


def test_hull_views_need_placements_grid():
    with pytest.raises(ValueError, match="hull_views=True needs obs_type='grid' in Placement"):
        PlacementBatch(1, scene="edr", hull_views=True)
    with pytest.raises(ValueError, match="hull_views"):
        gym.make("sensorplan/Navigate-v0", scene="edr", hull_views=True)
    with pytest.raises(ValueError, match="hull_views must be True or False"):
        PlacementBatch(1, scene="edr", obs_type="grid", hull_views="yes")
