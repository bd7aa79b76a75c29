"""The compiled inner loops (numba, the ``fast`` extra) give bitwise the numpy answers."""

from __future__ import annotations

import numpy as np
import pytest

from sensorplan_gym.core import kernels


def _segments(rng, rows, m):
    x0, y0 = rng.uniform(0, 10, (2, rows, m))
    ex, ey = rng.normal(0, 1, (2, rows, m))
    ex[:, :2] = ey[:, :2] = 0.0  # padding segments: never hit
    x0[:, :2] = y0[:, :2] = 1e15
    ex[:, 2], ey[:, 2] = 1.0, 0.0  # axis-parallel segments: parallel rays exist
    L = np.hypot(ex, ey)
    L[L == 0] = 1.0
    return x0, y0, ex, ey, -ey / L, ex / L


@pytest.mark.parametrize("shape", [(1, 16, 5), (37, 16, 47), (8, 33, 200)])
@pytest.mark.parametrize("shared", [False, True])
def test_compiled_equals_numpy(shape, shared):
    if not kernels.HAVE_NUMBA:
        pytest.skip("numba not installed (the 'fast' extra)")
    n, b, m = shape
    rng = np.random.default_rng(n * m)
    seg = _segments(rng, 1 if shared else n, m)
    ox, oy = rng.uniform(0, 10, (2, n))
    ang = rng.uniform(-np.pi, np.pi, (n, b))
    ang[:, 0] = 0.0
    mr = rng.uniform(2, 20, n)
    for cull in (False, True):
        a = kernels.cast(ox, oy, np.cos(ang), np.sin(ang), *seg, mr, cull)
        c = kernels.cast_numpy(ox, oy, np.cos(ang), np.sin(ang), *seg, mr, cull)
        assert all(np.array_equal(x, y) for x, y in zip(a, c, strict=True))
        assert all(x.tobytes() == y.tobytes() for x, y in zip(a, c, strict=True))  # +-0 too
        assert a[1].any() and not a[1].all()  # both hits and misses were compared
    d = rng.normal(0, 10, (2, n))
    d[:, -1] = 0.0  # no motion
    skin = np.full(n, 1e-7)
    s1 = kernels.point_sweep(ox, oy, d[0], d[1], *seg, skin)
    s2 = kernels.point_sweep_numpy(ox, oy, d[0], d[1], *seg, skin)
    assert np.array_equal(s1, s2) and s1[-1] == 1.0
    assert n == 1 or (s1 < 1).any()


def test_seg_distance_compiled_equals_numpy():
    if not kernels.HAVE_NUMBA:
        pytest.skip("numba not installed (the 'fast' extra)")
    rng = np.random.default_rng(5)
    for rows in (1, 40):
        x0, y0, ex, ey, _, _ = _segments(rng, rows, 30)
        px, py = rng.uniform(-2, 12, (2, 40))
        a = kernels.seg_distance(px, py, x0, y0, ex, ey)
        b = kernels.seg_distance_numpy(px, py, x0, y0, ex, ey)
        assert np.array_equal(a, b) and np.isfinite(a).all()


@pytest.mark.parametrize("scene", ["lab", "edr", "corridor", "warehouse"])
def test_culling_changes_no_reading(scene):
    """World edges point into the free space: skipping the edges that face away from a free
    origin gives exactly the full cast, on every bundled scene (with the target in it)."""
    import gymnasium as gym
    from shapely import Polygon, contains_xy

    from sensorplan_gym.core.sensor import cast_batch

    env = gym.make("sensorplan/Recognize-v0", scene=scene, n_beams=90)
    env.reset(seed=1)
    b = env.unwrapped.batch
    w = b.worlds[0]
    rng = np.random.default_rng(0)
    pts = rng.uniform(w.lo, w.hi, (4000, 2))
    free = w.robot_space.difference(Polygon(b.target_polys[0]))  # the target is not free
    pts = pts[contains_xy(free, pts[:, 0], pts[:, 1])][:300]
    rows = b._rows(b.segs, np.zeros(len(pts), dtype=np.intp))
    ang = rng.uniform(-np.pi, np.pi, (len(pts), 90))
    full = cast_batch(pts[:, 0], pts[:, 1], ang, rows, w.reach)
    culled = cast_batch(pts[:, 0], pts[:, 1], ang, rows, w.reach, cull=True)
    assert all(np.array_equal(x, y) for x, y in zip(full, culled, strict=True))
    assert full[2].all()  # closed rooms: every beam hits something
