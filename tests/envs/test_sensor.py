"""The vectorised range sensor and the collision sweep against shapely brute force."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely

from geometry import Scene
from sensorplan_gym.core.cache import get_world
from sensorplan_gym.core.sensor import RangeSensor, Segments, cast_rays
from sensorplan_gym.core.world import (
    WorldConfig,
    boundary_segments,
    bundled_scene_path,
    sweep,
)


@pytest.fixture(scope="module")
def lab():
    return get_world(Scene.load(bundled_scene_path("lab")), WorldConfig())


def _free_point(w, rng):
    while True:
        x, y = rng.uniform(w.lo, w.hi)
        if w.free_space.contains(shapely.Point(x, y)):
            return x, y


def test_cast_matches_shapely(lab):
    w = lab
    sensor = RangeSensor(24, 2 * math.pi, w.reach)
    rng = np.random.default_rng(0)
    boundary = w.free_space.boundary
    for _ in range(40):
        x, y = _free_point(w, rng)
        psi = rng.uniform(-math.pi, math.pi)
        dist, nrm, hit, ang = sensor.read((x, y, psi), w.seg_set)
        assert hit.all()
        for k, a in enumerate(ang):
            ray = shapely.LineString([(x, y), (x + 100 * math.cos(a), y + 100 * math.sin(a))])
            want = shapely.Point(x, y).distance(ray.intersection(boundary))
            assert dist[k] == pytest.approx(want, abs=1e-9)
            assert abs(np.hypot(*nrm[k]) - 1) < 1e-12
            assert nrm[k] @ (math.cos(a), math.sin(a)) <= 1e-12  # faces the sensor


def test_fov_max_range_and_noise(lab):
    w = lab
    s = RangeSensor(5, math.radians(90), 1.0)
    assert s.offsets[0] == pytest.approx(-math.pi / 4) and s.offsets[-1] == pytest.approx(
        math.pi / 4
    )
    d, n, h, _ = s.read((6.0, 4.0, 0.0), w.seg_set)
    assert (d <= 1.0).all()
    assert np.all(n[~h] == 0) and np.all(d[~h] == 1.0)
    noisy = RangeSensor(16, 2 * math.pi, w.reach, noise=0.05)
    rng = np.random.default_rng(1)
    d1 = noisy.read((6.0, 4.0, 0.0), w.seg_set, rng)[0]
    d0 = RangeSensor(16, 2 * math.pi, w.reach).read((6.0, 4.0, 0.0), w.seg_set)[0]
    assert not np.allclose(d0, d1) and np.abs(d1 - d0).max() < 0.5
    assert (d1 >= 0).all() and (d1 <= w.reach).all()


def test_empty_and_parallel_segments():
    S = Segments(np.array([[0.0, 1.0, 2.0, 1.0], [1.0, 0.0, 2.0, 0.0]]))
    d, n, h = cast_rays(0.0, 0.0, 0.0, np.array([[1.0, 0.0], [0.0, 1.0]]), S, 10.0)
    assert not h[0] and d[0] == 10.0  # collinear/parallel: no hit
    assert h[1] and d[1] == pytest.approx(1.0) and n[1] == pytest.approx([0.0, -1.0])
    d, n, h = cast_rays(0.0, 0.0, 0.0, np.array([[1.0, 0.0]]), Segments(np.zeros((0, 4))), 3.0)
    assert d[0] == 3.0 and not h[0]


@pytest.mark.parametrize("radius", [0.0, 0.3])
def test_sweep_stops_at_contact(lab, radius):
    w = lab
    rng = np.random.default_rng(2)
    space = w.free_space.buffer(-radius) if radius else w.free_space
    n_hits = 0
    for _ in range(300):
        x, y = _free_point(w, rng)
        if radius and not space.contains(shapely.Point(x, y)):
            continue
        d = rng.uniform(-3, 3, 2)
        t = sweep((x, y), d, w.seg_set, radius, w.skin)
        assert 0 <= t <= 1
        path = shapely.LineString([(x, y), (x + t * d[0], y + t * d[1])])
        assert space.buffer(1e-9).covers(path)
        if t < 1:
            n_hits += 1
            # contact: a little further would leave the free space
            q = shapely.Point(x + min(1, t + 1e-3) * d[0], y + min(1, t + 1e-3) * d[1])
            assert space.distance(q) > 0 or not space.contains(q) or t == 0
    assert n_hits > 10


def test_boundary_segments_closed():
    sq = shapely.box(0, 0, 1, 1).difference(shapely.box(0.4, 0.4, 0.6, 0.6))
    segs = boundary_segments(sq)
    assert segs.shape == (8, 4)
    assert np.isclose(np.hypot(segs[:, 2] - segs[:, 0], segs[:, 3] - segs[:, 1]).sum(), 4.8)
