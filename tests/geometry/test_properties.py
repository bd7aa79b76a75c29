"""Property tests (hypothesis) of the region functions on generated scenes.

* complete visibility implies partial visibility: complete region within partial region;
* positional (eps_pos) and aim (eps_aim) uncertainty only ever shrink a region, monotonically;
* adding an obstacle (away from the target's swept hull, possibly overlapping other
  obstacles) never grows a region;
* the translating-target region lies inside the stationary region at every sampled q in G;
* an empty answer is an empty polygonal geometry, not an exception.

Containment is checked up to a tiny area: ``area(X - Y) <= AREA_TOL * diameter**2``.
"""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from shapely.geometry import Point

from geometry import Scene, complete_region, partial_region, recognizable_region
from geometry.generate import random_scene

AREA_TOL = 1e-9
SETTINGS = settings(
    max_examples=12, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow]
)

seeds = st.integers(min_value=0, max_value=2**31 - 1)
kinds = st.sampled_from(["point", "polygon"])
angles = st.floats(min_value=0.0, max_value=2 * math.pi, allow_nan=False)


def _scene(seed: int, kind: str) -> Scene:
    return Scene.from_dict(random_scene(np.random.default_rng(seed), goal=kind))


def _pose_in_goal(scene: Scene, seed: int, theta: float) -> tuple[float, float, float]:
    g = scene.goal_geom
    if g.geom_type == "Point":
        return (g.x, g.y, theta)
    rng = np.random.default_rng(seed)
    x0, y0, x1, y1 = g.bounds
    while True:
        p = rng.uniform((x0, y0), (x1, y1))
        if g.contains(Point(p)):
            return (float(p[0]), float(p[1]), theta)


def _assert_within(small, big, scene: Scene, what: str) -> None:
    extra = shapely.difference(small, big).area
    assert extra <= AREA_TOL * scene.diameter**2, f"{what}: area {extra:g} outside"


def _polygonal(g) -> bool:
    return g.geom_type in ("Polygon", "MultiPolygon", "GeometryCollection") and (
        g.is_empty or g.geom_type != "GeometryCollection"
    )


@SETTINGS
@given(seed=seeds, kind=kinds, theta=angles)
def test_complete_within_partial(seed, kind, theta):
    sc = _scene(seed, kind)
    pose = _pose_in_goal(sc, seed, theta)
    c = complete_region(sc, target_at=pose)
    p = partial_region(sc, target_at=pose)
    _assert_within(c, p, sc, "complete - partial")
    assert c.area <= p.area + AREA_TOL * sc.diameter**2


@SETTINGS
@given(seed=seeds, kind=kinds, theta=angles, e1=st.floats(0.0, 0.05), e2=st.floats(0.0, 0.05))
def test_eps_pos_shrinks_monotonically(seed, kind, theta, e1, e2):
    sc = _scene(seed, kind)
    pose = _pose_in_goal(sc, seed, theta)
    lo, hi = sorted((e1 * sc.diameter, e2 * sc.diameter))
    for fn in (complete_region, partial_region):
        r0 = fn(sc, target_at=pose)
        r_lo = fn(sc, target_at=pose, eps_pos=lo)
        r_hi = fn(sc, target_at=pose, eps_pos=hi)
        _assert_within(r_lo, r0, sc, f"{fn.__name__}: eps {lo:g} vs 0")
        _assert_within(r_hi, r_lo, sc, f"{fn.__name__}: eps {hi:g} vs {lo:g}")
    rg0 = complete_region(sc, target_in="goal", theta=theta)
    rg = complete_region(sc, target_in="goal", theta=theta, eps_pos=hi)
    _assert_within(rg, rg0, sc, "translating, eps_pos")


@SETTINGS
@given(seed=seeds, kind=kinds, theta=angles, a1=st.floats(0.0, 0.6), a2=st.floats(0.0, 0.6))
def test_eps_aim_shrinks_monotonically(seed, kind, theta, a1, a2):
    sc = _scene(seed, kind)
    pose = _pose_in_goal(sc, seed, theta)
    lo, hi = sorted((a1, a2))
    r0 = partial_region(sc, target_at=pose)
    r_lo = partial_region(sc, target_at=pose, eps_aim=lo)
    r_hi = partial_region(sc, target_at=pose, eps_aim=hi)
    _assert_within(r_lo, r0, sc, f"eps_aim {lo:g} vs 0")
    _assert_within(r_hi, r_lo, sc, f"eps_aim {hi:g} vs {lo:g}")


def _with_extra_obstacle(d: dict, seed: int) -> dict | None:
    """``d`` plus a small square obstacle in the free space, clear of the swept hulls."""
    sc = Scene.from_dict(d)
    rng = np.random.default_rng(seed)
    r = sc.target_radius
    keep_out = shapely.union(
        shapely.convex_hull(sc.goal_geom).buffer(r * 1.05),
        shapely.convex_hull(sc.failure_geom).buffer(r * 1.05),
    )
    inner = sc.bounds_geom.buffer(-0.01)
    x0, y0, x1, y1 = sc.bounds_geom.bounds
    for _ in range(200):
        c = rng.uniform((x0, y0), (x1, y1))
        s = rng.uniform(0.05, 0.4)
        ang = rng.uniform(0, math.pi / 2) + np.arange(4) * math.pi / 2
        sq = c + s * np.column_stack([np.cos(ang), np.sin(ang)])
        ob = shapely.Polygon(sq)
        if not inner.contains(ob) or ob.intersects(keep_out):
            continue
        if not sc.free_space.intersects(ob):
            continue  # entirely inside another obstacle: not interesting
        new = copy.deepcopy(d)
        new["obstacles"].append([[float(x), float(y)] for x, y in sq])
        return new
    return None


@SETTINGS
@given(seed=seeds, kind=kinds, theta=angles)
def test_adding_an_obstacle_never_grows_a_region(seed, kind, theta):
    d = random_scene(np.random.default_rng(seed), goal=kind)
    d2 = _with_extra_obstacle(d, seed + 1)
    if d2 is None:
        pytest.skip("no room for an extra obstacle")
    sc, sc2 = Scene.from_dict(d), Scene.from_dict(d2)
    pose = _pose_in_goal(sc, seed, theta)
    pairs = [
        ("complete stationary", lambda s: complete_region(s, target_at=pose)),
        ("complete translating", lambda s: complete_region(s, target_in="goal", theta=theta)),
        ("complete rotating", lambda s: complete_region(s, target_in="failure", theta=None)),
        ("partial stationary", lambda s: partial_region(s, target_at=pose)),
        ("partial eps_aim", lambda s: partial_region(s, target_at=pose, eps_aim=0.1)),
        ("recognizable complete", lambda s: recognizable_region(s, model="complete", theta=theta)),
    ]
    if kind == "point":
        pairs.append(
            ("recognizable partial", lambda s: recognizable_region(s, model="partial", theta=theta))
        )
    for what, fn in pairs:
        _assert_within(fn(sc2), fn(sc), sc, what)


@SETTINGS
@given(seed=seeds, theta=angles, k=st.integers(0, 10_000))
def test_translating_within_stationary(seed, theta, k):
    sc = _scene(seed, "polygon")
    moving = complete_region(sc, target_in="goal", theta=theta)
    rng = np.random.default_rng(k)
    g = sc.goal_geom
    pts = [np.asarray(c) for c in g.exterior.coords[:-1]]  # the vertices of G ...
    x0, y0, x1, y1 = g.bounds
    while len(pts) < len(g.exterior.coords) + 3:  # ... and random interior points
        p = rng.uniform((x0, y0), (x1, y1))
        if g.contains(Point(p)):
            pts.append(p)
    for q in pts:
        still = complete_region(sc, target_at=(float(q[0]), float(q[1]), theta))
        _assert_within(moving, still, sc, f"translating vs stationary at {q}")
    rot = complete_region(sc, target_in="goal", theta=None)
    _assert_within(rot, moving, sc, "rotating vs translating")


def test_boxed_in_target_gives_empty_regions():
    # the target's pocket is exactly its convex hull: no placement can see it
    ring = [
        [[1.0, 1.0], [5.0, 1.0], [5.0, 2.0], [1.0, 2.0]],
        [[1.0, 4.0], [5.0, 4.0], [5.0, 5.0], [1.0, 5.0]],
        [[1.0, 1.0], [2.0, 1.0], [2.0, 5.0], [1.0, 5.0]],
        [[4.0, 1.0], [5.0, 1.0], [5.0, 5.0], [4.0, 5.0]],
    ]
    d = {
        "name": "boxed",
        "bounds": [[0, 0], [12, 0], [12, 8], [0, 8]],
        "obstacles": ring,
        "target": [[-1, -1], [1, -1], [1, 1], [-1, 1]],
        "goal": [[3, 3]],
        "failure": [[9, 4]],
    }
    sc = Scene.from_dict(d)
    results = [
        complete_region(sc, target_at=(3.0, 3.0, 0.0)),
        complete_region(sc, target_in="goal", theta=0.0),
        complete_region(sc, target_at=(3.0, 3.0, 0.0), eps_pos=0.1),
        partial_region(sc, target_at=(3.0, 3.0, 0.0)),
        partial_region(sc, target_at=(3.0, 3.0, 0.0), eps_aim=0.2, eps_pos=0.1),
        recognizable_region(sc, model="complete"),
        recognizable_region(sc, model="partial"),
    ]
    for r in results:
        assert r.is_empty and _polygonal(r), r
    # the same target in the open part of the room is seen from somewhere
    assert not complete_region(sc, target_at=(9.0, 4.0, 0.0)).is_empty
