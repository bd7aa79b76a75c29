"""Recognition from range readings (agents.planning.recognition, paper 6.4 on range data).

Readings are simulated by an exact ray caster below (walls, obstacles and, optionally, the
target or another object), with the static map's readings computed the same way without them.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from shapely.geometry import Point, Polygon, box

from agents.planning.recognition import classify, fractional_distance, match_distance, target_points
from geometry import Scene


def rect(x0: float, y0: float, x1: float, y1: float) -> list[list[float]]:
    return [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]


#: An asymmetric pentagon (reference point (0, 0) inside); radius ~0.354.
TARGET = [[0.3, 0.0], [0.15, 0.25], [-0.25, 0.25], [-0.25, -0.25], [0.15, -0.25]]
SENSOR = np.array([5.0, 4.0])


def make_scene(goal=None, failure=None) -> Scene:
    return Scene.from_dict(
        {
            "name": "rec",
            "bounds": rect(0, 0, 10, 10),
            "obstacles": [rect(7, 1, 8, 2)],
            "target": TARGET,
            "goal": goal if goal is not None else [[3, 7]],
            "failure": failure if failure is not None else [[7, 7]],
        }
    )


def _segments(polys) -> tuple[np.ndarray, np.ndarray]:
    a, b = [], []
    for p in polys:
        for ring in [p.exterior, *p.interiors]:
            c = np.asarray(ring.coords)[:, :2]
            a.append(c[:-1])
            b.append(c[1:])
    return np.concatenate(a), np.concatenate(b)


def cast(scene: Scene, origin, n_beams: int, extra=(), noise: float = 0.0, seed: int = 0):
    """End points of ``n_beams`` rays (full circle) from ``origin``; ``extra``: more polygons."""
    a, b = _segments([scene.bounds_geom, *scene.obstacle_geoms, *extra])
    phi = np.linspace(0, 2 * np.pi, n_beams, endpoint=False)
    d = np.column_stack([np.cos(phi), np.sin(phi)])  # (n, 2)
    o = np.asarray(origin, dtype=float)
    e = b - a  # (s, 2)
    den = d[:, None, 0] * e[None, :, 1] - d[:, None, 1] * e[None, :, 0]  # cross(d, e)
    w = a - o
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (w[None, :, 0] * e[None, :, 1] - w[None, :, 1] * e[None, :, 0]) / den
        u = (w[None, :, 0] * d[:, None, 1] - w[None, :, 1] * d[:, None, 0]) / den
    ok = (np.abs(den) > 1e-15) & (t > 1e-12) & (u >= 0) & (u <= 1)
    r = np.where(ok, t, np.inf).min(axis=1)
    if noise:
        r = r + np.random.default_rng(seed).normal(0, noise, size=r.shape)
    return o + r[:, None] * d


def scan(scene: Scene, pose=None, obj: Polygon | None = None, n_beams=1440, noise=0.003, seed=0):
    """(readings, static end points) with the target at ``pose`` and/or another object."""
    extra = []
    if pose is not None:
        extra.append(scene.target_at(*pose))
    if obj is not None:
        extra.append(obj)
    readings = cast(scene, SENSOR, n_beams, extra, noise=noise, seed=seed)
    static = cast(scene, SENSOR, n_beams)
    return readings, static


# ---------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def scene() -> Scene:
    return make_scene()


def test_target_in_g(scene):
    readings, static = scan(scene, (3, 7, 0))
    dec = classify(readings, static, scene)
    assert dec.label == "G" and dec.seen
    assert dec.n_points >= 20
    assert dec.d_G < 0.02 < dec.tau < dec.d_H
    assert dec.pose == dec.pose_G == pytest.approx((3, 7, 0))


def test_target_in_h(scene):
    readings, static = scan(scene, (7, 7, 0))
    dec = classify(readings, static, scene)
    assert dec.label == "H"
    assert dec.d_H < 0.02 and dec.d_G > dec.tau
    assert dec.pose == pytest.approx((7, 7, 0))


def test_nothing_differs_is_not_seen(scene):
    readings, static = scan(scene, None)
    dec = classify(readings, static, scene)
    assert dec.label == "not_seen" and not dec.seen
    assert dec.n_points == 0 and math.isinf(dec.d_G) and math.isinf(dec.d_H)
    assert "not in view" in dec.reason


def test_too_few_points_is_not_seen(scene):
    readings, static = scan(scene, (3, 7, 0))
    pts = target_points(readings, static, tol=0.01)
    dec = classify(pts[:2], None, scene)
    assert dec.label == "not_seen" and dec.n_points == 2


def test_mask_and_expected_endpoints_agree(scene):
    readings, static = scan(scene, (3, 7, 0))
    mask = np.hypot(*(readings - static).T) > 0.01
    d1 = classify(readings, static, scene, static_tol=0.01)
    d2 = classify(readings, mask, scene)
    assert d1.label == d2.label == "G"
    assert d1.n_points == d2.n_points == int(mask.sum())
    assert d1.d_G == pytest.approx(d2.d_G) and d1.d_H == pytest.approx(d2.d_H)


def test_outliers_do_not_flip_with_frac_below_one(scene):
    readings, static = scan(scene, (3, 7, 0))
    pts = target_points(readings, static, tol=0.01)
    n = len(pts)
    rng = np.random.default_rng(1)
    k = max(2, n // 8)  # ~12% outliers, some of them right on the H outline
    out = np.vstack([rng.uniform(1, 9, size=(k - 2, 2)), [[7.3, 7.0], [6.75, 7.1]]])
    noisy = np.vstack([pts, out])
    dec = classify(noisy, None, scene, frac=0.8)
    assert dec.label == "G", dec.reason
    # the plain (frac = 1) directed Hausdorff distance is ruined by the outliers
    strict = classify(noisy, None, scene, frac=1.0)
    assert strict.label == "not_seen"
    assert strict.d_G > strict.tau


def test_other_object_in_g_is_not_the_target(scene):
    board = box(2.2, 6.95, 3.8, 7.05)  # a long thin object where the target would be
    readings, static = scan(scene, None, obj=board)
    dec = classify(readings, static, scene)
    assert dec.n_points >= 20
    assert dec.label == "not_seen", dec.reason
    assert "neither" in dec.reason


def test_polygonal_goal_region():
    sc = make_scene(goal=rect(2.5, 6.5, 3.5, 7.5), failure=rect(6.5, 6.5, 7.5, 7.5))
    for pose, want in [((3.23, 6.81, 0), "G"), ((6.9, 7.33, 0), "H")]:
        readings, static = scan(sc, pose)
        dec = classify(readings, static, sc)
        assert dec.label == want, dec.reason
        assert dec.pose[:2] == pytest.approx(pose[:2], abs=0.02)
        assert min(dec.d_G, dec.d_H) < 0.02


def test_ambiguous_when_hypotheses_look_alike():
    sc = make_scene(goal=[[3, 7]], failure=[[3.01, 7]])
    readings, static = scan(sc, (3, 7, 0))
    dec = classify(readings, static, sc)
    assert dec.label == "not_seen"
    assert "ambiguous" in dec.reason


def test_unknown_orientation_is_searched(scene):
    readings, static = scan(scene, (3, 7, 2.0))
    assert classify(readings, static, scene, theta=0.0).label == "not_seen"
    dec = classify(readings, static, scene, theta=None)
    assert dec.label == "G"
    assert dec.pose_G[2] == pytest.approx(2.0, abs=0.05)


def test_explicit_geometries_without_scene(scene):
    readings, static = scan(scene, (7, 7, 0))
    dec = classify(
        readings, static, target=Polygon(TARGET), goal=Point(3, 7), failure=Point(7, 7), tau=0.05
    )
    assert dec.label == "H" and dec.tau == 0.05
    with pytest.raises(ValueError):
        classify(readings, static)


def test_fractional_distance_rank():
    pts = np.array([[0, 0], [1, 0], [2, 0], [3, 0], [4, 0]], dtype=float)
    geom = Point(0, 0)
    assert fractional_distance(pts, geom, 0.6) == pytest.approx(2.0)
    assert fractional_distance(pts, geom, 1.0) == pytest.approx(4.0)
    assert fractional_distance(pts, geom, 0.01) == pytest.approx(0.0)
    assert math.isinf(fractional_distance(np.zeros((0, 2)), geom))
    inside = fractional_distance(pts, box(-1, -1, 5, 1), 1.0)
    assert inside == 0.0
    with pytest.raises(ValueError):
        fractional_distance(pts, geom, 0.0)


def test_match_distance_exact_pose():
    a = shapely.affinity.translate(Polygon(TARGET), 1.3, -0.4)
    pts = shapely.get_coordinates(shapely.segmentize(a.exterior, 0.05))
    d, pose = match_distance(pts, TARGET, box(0, -1, 2, 1), resolution=0.05)
    assert d < 0.05 / 4 * 1.5
    assert pose[:2] == pytest.approx((1.3, -0.4), abs=0.03)
    assert match_distance(np.zeros((0, 2)), TARGET, Point(0, 0)) == (math.inf, None)
