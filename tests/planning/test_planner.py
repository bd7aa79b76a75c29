"""Oracle planner (agents.planning.planner): placement, shortest paths, shrinking, aim.

Small hand-checked scenes; every expected number below is computed by hand in the comments.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from shapely.geometry import LineString, Point, Polygon, box

from agents.planning.planner import (
    PLAN_QUAD_SEGS,
    Path,
    best_aim,
    choose_placement,
    grow_free_space,
    shortest_path,
    shrink_region,
)
from geometry import Scene, complete_region, recognizable_region

OUTER = 1.0 / math.cos(math.pi / (4 * PLAN_QUAD_SEGS))


def rect(x0: float, y0: float, x1: float, y1: float) -> list[list[float]]:
    return [[x0, y0], [x1, y0], [x1, y1], [x0, y1]]


SMALL = rect(-0.1, -0.1, 0.1, 0.1)


@pytest.fixture
def open_room() -> Scene:
    """10 x 10 room, one obstacle in the lower half, point G and H."""
    return Scene.from_dict(
        {
            "name": "open",
            "bounds": rect(0, 0, 10, 10),
            "obstacles": [rect(4, 1, 5, 2)],
            "target": SMALL,
            "goal": [[8, 8]],
            "failure": [[2, 8]],
        }
    )


@pytest.fixture
def l_corridor() -> Scene:
    """An L-shaped corridor: horizontal arm y in [0, 2], vertical arm x in [8, 10].

    The only reflex vertex of the free space is the inner corner (8, 2).
    """
    return Scene.from_dict(
        {
            "name": "L",
            "bounds": [[0, 0], [10, 0], [10, 10], [8, 10], [8, 2], [0, 2]],
            "obstacles": [],
            "target": SMALL,
            "goal": [[9, 5]],
            "failure": [[5, 1]],
        }
    )


@pytest.fixture
def boxed() -> Scene:
    """G sealed inside a closed box of walls; H outside.  Free space has two components."""
    return Scene.from_dict(
        {
            "name": "boxed",
            "bounds": rect(0, 0, 10, 10),
            "obstacles": [
                rect(3.8, 3.8, 4, 6.2),
                rect(6, 3.8, 6.2, 6.2),
                rect(4, 3.8, 6, 4),
                rect(4, 6, 6, 6.2),
            ],
            "target": rect(-0.2, -0.2, 0.2, 0.2),
            "goal": [[5, 5]],
            "failure": [[1.5, 1.5]],
        }
    )


def _inside(space, path: Path, tol: float = 1e-7) -> bool:
    return bool(space.buffer(tol).covers(path.as_linestring()))


# ---------------------------------------------------------------------------------------------
# one-step motion (paper 6.2)
# ---------------------------------------------------------------------------------------------


def test_one_step_nearest_point_straight_line(open_room):
    region = box(6, 4, 8, 6)
    # the start (1, 5) sees the region; nearest point is (6, 5), distance 5
    pl = choose_placement(open_room, region, (1, 5))
    assert pl.status == "ok" and pl.ok
    assert pl.one_step
    np.testing.assert_allclose(pl.point, [6, 5], atol=1e-12)
    assert pl.length == pytest.approx(5.0, abs=1e-12)
    assert pl.path.points.shape == (2, 2)
    np.testing.assert_allclose(pl.path.points[0], [1, 5])
    assert "one-step" in pl.reason


def test_one_step_is_euclidean_nearest_point(open_room):
    region = Polygon([(7, 3), (9, 4), (8, 7)])
    start = np.array([6.0, 9.0])
    path = shortest_path(open_room, start, region)
    near = np.asarray(shapely.shortest_line(Point(start), region).coords)[1]
    assert path.one_step
    np.testing.assert_allclose(path.end, near, atol=1e-12)
    assert path.length == pytest.approx(float(np.hypot(*(near - start))), abs=1e-12)


def test_start_inside_region_needs_no_motion(open_room):
    pl = choose_placement(open_room, box(6, 4, 8, 6), (7, 5))
    assert pl.ok and pl.length == 0.0 and pl.one_step
    np.testing.assert_allclose(pl.point, [7, 5])
    assert pl.path.points.shape == (2, 2)


def test_one_step_on_complete_region(open_room):
    region = complete_region(open_room, target_in="goal")
    pl = choose_placement(open_room, region, (1, 1), margin=0.1)
    assert pl.ok
    assert pl.region.buffer(1e-9).covers(Point(pl.point))
    assert region.buffer(1e-9).covers(Point(pl.point).buffer(0.1 * 0.999))
    assert _inside(open_room.free_space, pl.path)


# ---------------------------------------------------------------------------------------------
# around a corner
# ---------------------------------------------------------------------------------------------


def test_only_reachable_around_a_corner(l_corridor):
    region = box(8.5, 8, 9.5, 9)
    start = (1.0, 1.0)
    # no straight segment from (1, 1) to a point with y >= 8 and x <= 9.5 clears the corner
    # (it crosses y = 2 at x <= 1 + 8.5 / 7 < 8).  Shortest path: (1,1) -> (8,2) -> (8.5,8):
    # the nearest region point from the corner is the region's corner (8.5, 8).
    expected = math.hypot(7, 1) + math.hypot(0.5, 6)
    pl = choose_placement(l_corridor, region, start)
    assert pl.ok and not pl.one_step
    assert pl.path.n_segments >= 2
    np.testing.assert_allclose(pl.path.points, [[1, 1], [8, 2], [8.5, 8]], atol=1e-12)
    assert pl.length == pytest.approx(expected, abs=1e-9)
    assert pl.path.length == pytest.approx(expected, abs=1e-9)
    assert _inside(l_corridor.free_space, pl.path)
    assert "corner" in pl.reason


def test_corner_with_robot_radius(l_corridor):
    r = 0.3
    region = box(8.5, 8, 9.5, 9)
    start = np.array([1.0, 1.0])
    cspace = grow_free_space(l_corridor, r)
    pl = choose_placement(l_corridor, region, start, robot_radius=r)
    assert pl.ok and pl.path.n_segments >= 2
    assert _inside(cspace, pl.path)
    # the robot body never leaves the free space
    assert l_corridor.free_space.buffer(1e-7).covers(pl.path.as_linestring().buffer(r * 0.999))
    # exact length: tangent from S to the circle C=(8,2), radius r, the arc, tangent to Q=(8.5,8)
    c = np.array([8.0, 2.0])
    q = np.array([8.5, 8.0])

    def tangent(p: np.ndarray) -> tuple[float, float]:
        v = p - c
        dd = float(np.hypot(*v))
        return math.sqrt(dd * dd - r * r), math.atan2(v[1], v[0]), dd

    ls, a_s, ds = tangent(start)
    lq, a_q, dq = tangent(q)
    # the path passes below/right of the corner: touch angles rotate away from the obstacle
    t_s = a_s + math.acos(r / ds)
    t_q = a_q - math.acos(r / dq)
    arc = r * ((t_q - t_s) % (2 * math.pi))  # counter-clockwise around C
    exact = ls + arc + lq
    assert exact - 1e-9 <= pl.length <= exact + r * (OUTER - 1) * 4 + 1e-9


def test_shortest_path_goes_around_obstacle(open_room):
    # obstacle [4,5]x[1,2]; start (3, 1.5) and region: the segment x = 6, y in [1.2, 1.8]
    # shortest path bends at (4,2) and (5,2) and ends at (6,1.8) (or symmetrically below):
    # length hypot(1, 0.5) + 1 + hypot(1, 0.2)
    region = LineString([(6, 1.2), (6, 1.8)])
    path = shortest_path(open_room, (3, 1.5), region)
    assert path is not None and path.n_segments == 3
    assert path.length == pytest.approx(math.hypot(1, 0.5) + 1 + math.hypot(1, 0.2), abs=1e-9)
    assert _inside(open_room.free_space, path)


# ---------------------------------------------------------------------------------------------
# no placement / unreachable
# ---------------------------------------------------------------------------------------------


def test_no_placement_target_boxed_in(boxed):
    region = recognizable_region(boxed)  # G seen only from inside the box, H only outside
    assert region.is_empty
    pl = choose_placement(boxed, region, (1, 8))
    assert pl.status == "no_placement" and not pl.ok
    assert pl.point is None and pl.path is None and pl.length == math.inf
    assert "no placement" in pl.reason


@pytest.mark.parametrize("what", ["empty", "thin", "radius"])
def test_no_placement_after_shrinking(open_room, what):
    if what == "empty":
        pl = choose_placement(open_room, Polygon(), (1, 1))
    elif what == "thin":
        pl = choose_placement(open_room, box(6, 5, 9, 5.15), (1, 1), margin=0.1)
    else:  # the region hugs the wall closer than the robot's radius
        pl = choose_placement(open_room, box(9.8, 3, 10, 6), (1, 1), robot_radius=0.3)
    assert pl.status == "no_placement"
    assert pl.point is None and pl.reason


def test_unreachable_sealed_room(boxed):
    region = complete_region(boxed, target_in="goal")  # inside the sealed box
    assert not region.is_empty
    pl = choose_placement(boxed, region, (1, 8))
    assert pl.status == "unreachable"
    assert pl.point is None and pl.path is None
    assert shortest_path(boxed, (1, 8), region) is None
    # from inside the box it is fine
    assert choose_placement(boxed, region, (4.5, 4.5)).ok


def test_unreachable_start_in_collision(open_room):
    pl = choose_placement(open_room, box(6, 4, 8, 6), (0.1, 5), robot_radius=0.3)
    assert pl.status == "unreachable" and "start" in pl.reason


# ---------------------------------------------------------------------------------------------
# configuration space and shrinking are conservative
# ---------------------------------------------------------------------------------------------


def test_grow_free_space_conservative(open_room):
    r = 0.4
    cs = grow_free_space(open_room, r)
    pts = shapely.points(shapely.get_coordinates(cs))
    obstacles_and_walls = shapely.union(open_room.obstacle_union, open_room.bounds_geom.exterior)
    d = shapely.distance(pts, obstacles_and_walls)
    assert d.min() >= r - 1e-9
    assert cs.area <= open_room.free_space.buffer(-r).area + 1e-9
    assert cs.area == pytest.approx(open_room.free_space.buffer(-r, quad_segs=64).area, rel=1e-3)
    assert grow_free_space(open_room, 0.0).equals(open_room.free_space)


def test_shrink_region_conservative():
    region = Polygon([(0, 0), (4, 0), (4, 1), (1, 1), (1, 4), (0, 4)])  # L with a concave corner
    m = 0.3
    sh = shrink_region(region, m)
    d = shapely.distance(shapely.points(shapely.get_coordinates(sh)), region.exterior)
    assert d.min() >= m - 1e-9
    assert region.covers(sh)
    assert sh.area == pytest.approx(region.buffer(-m, quad_segs=64).area, rel=1e-3)
    assert shrink_region(region, 0.0) is region
    assert shrink_region(region, 0.6).is_empty
    assert shrink_region(Point(1, 1), 0.1).is_empty
    with pytest.raises(ValueError):
        shrink_region(region, -1)


# ---------------------------------------------------------------------------------------------
# aim (paper 6.3)
# ---------------------------------------------------------------------------------------------


def test_best_aim_symmetric():
    fov, eps = math.radians(60), math.radians(5)
    psi, margin = best_aim((0, 0), [(2, -1), (2, 1), (3, -1), (3, 1)], fov, eps)
    assert psi == pytest.approx(0.0, abs=1e-12)
    # extent = 2 atan(1/2) (the near edge), margin = 30 - 5 - atan(1/2) degrees
    assert margin == pytest.approx(fov / 2 - eps - math.atan(0.5), abs=1e-12)


def test_best_aim_bisects_extent_not_centroid():
    pts = [
        (math.cos(math.radians(a)) * r, math.sin(math.radians(a)) * r)
        for a, r in [(10, 1.0), (50, 5.0), (30, 3.0), (10, 6.0)]
    ]
    psi, margin = best_aim((0, 0), pts, math.radians(90))
    assert math.degrees(psi) == pytest.approx(30.0, abs=1e-9)
    assert math.degrees(margin) == pytest.approx(45 - 20, abs=1e-9)
    # shapely geometry input, seen from elsewhere (translation invariance)
    poly = shapely.affinity.translate(shapely.MultiPoint(pts).convex_hull, 3, -2)
    psi2, margin2 = best_aim((3, -2), poly, math.radians(90))
    assert psi2 == pytest.approx(psi, abs=1e-9) and margin2 == pytest.approx(margin, abs=1e-9)


def test_best_aim_wraps_around_pi():
    pts = [(-5, 5 * math.tan(math.radians(10))), (-5, -5 * math.tan(math.radians(10)))]
    psi, margin = best_aim((0, 0), pts, math.radians(40))
    assert abs(abs(psi) - math.pi) < 1e-12
    assert math.degrees(margin) == pytest.approx(20 - 10, abs=1e-9)


def test_best_aim_impossible_and_360():
    pts = box(2, -2, 3, 2)
    _, margin = best_aim((0, 0), pts, math.radians(30))
    assert margin < 0  # extent 2*atan(1) = 90 deg > 30 deg
    psi, margin = best_aim((0, 0), pts, 2 * math.pi, eps_aim=math.radians(10))
    assert psi == pytest.approx(0.0, abs=1e-12)  # toward the centroid (2.5, 0)
    assert margin == pytest.approx(math.pi - math.atan(1.0), abs=1e-12)
    _, margin_in = best_aim((2.5, 0), pts, math.radians(300))
    assert margin_in < 0  # inside the set: extent 2 pi
    _, margin_in = best_aim((2.5, 0), pts, 2 * math.pi)
    assert margin_in == pytest.approx(0.0)


def test_choose_placement_aims(open_room):
    hull = open_room.swept_hull("goal")
    pl = choose_placement(
        open_room,
        box(6, 4, 8, 6),
        (1, 5),
        aim_at=hull,
        fov=math.radians(60),
        eps_aim=math.radians(2),
    )
    psi, margin = best_aim(pl.point, hull, math.radians(60), math.radians(2))
    assert pl.aim == pytest.approx(psi) and pl.aim_margin == pytest.approx(margin)
    assert margin > 0


def test_keep_out_is_avoided_by_the_robot_body(open_room):
    r = 0.2
    keep_out = box(5.5, 4, 6.5, 6)  # e.g. the target's swept area, in front of the region
    pl = choose_placement(open_room, box(6, 4, 8, 6), (1, 5), robot_radius=r, keep_out=keep_out)
    assert pl.ok
    assert pl.point[0] >= 6.5 + r - 1e-9  # the body does not overlap the keep-out area
    assert pl.path.as_linestring().distance(keep_out) >= r - 1e-9
    assert not pl.one_step  # the straight line through the keep-out area is not allowed


def _square(cx: float, cy: float, h: float = 0.5) -> np.ndarray:
    return np.array([[cx - h, cy - h], [cx + h, cy - h], [cx + h, cy + h], [cx - h, cy + h]])


def test_best_joint_aim_sees_two_sets_from_between_them():
    """From between K_G and K_H (inside the hull of both) a 229-degree sensor sees both:
    best_aim on the hull says no aim works, best_joint_aim finds the aim (the oracle's
    failed Placement-v0 episode of the hard level)."""
    from agents.planning.planner import best_joint_aim

    g, h = _square(5.0, 0.0), _square(-5.0, 0.5)
    fov = math.radians(229.0)
    assert best_aim((0.0, 0.0), np.vstack([g, h]), fov)[1] < 0
    psi, margin = best_joint_aim((0.0, 0.0), [g, h], fov)
    assert margin > 0
    for k in (g, h):  # every vertex within fov / 2 - margin of the aim
        d = np.arctan2(k[:, 1], k[:, 0]) - psi
        off = np.abs((d + math.pi) % (2 * math.pi) - math.pi)
        assert off.max() <= fov / 2 - margin + 1e-9
    # a 150-degree sensor cannot (the two sets span about 186 degrees)
    assert best_joint_aim((0.0, 0.0), [g, h], math.radians(150.0))[1] < 0
    # one set, or both on one side: the same as best_aim on their union
    p = (0.0, -10.0)
    a1, m1 = best_joint_aim(p, [g, h], fov)
    a2, m2 = best_aim(p, np.vstack([g, h]), fov)
    assert m1 == pytest.approx(m2, abs=1e-9)
    assert math.cos(a1 - a2) == pytest.approx(1.0)
    # inside one of them: no aim keeps it in view
    assert best_joint_aim((5.0, 0.0), [g, h], fov)[1] < 0


def test_path_field_paths_are_optimal_on_a_real_map():
    """One :class:`PathField` asked from many starts: every path is collision-free, ends in the
    goal, is no shorter than the straight line, and is optimal by its own sub-paths (the path
    from its first bend is the field's path from there, and the rest of it) -- and a second
    field of the same space answers identically, and a fresh ``shortest_path`` too."""
    import gymnasium as gym

    import sensorplan_gym  # noqa: F401
    from agents.planning.planner import PathField, VisibilityGraph

    w = gym.make("sensorplan/Navigate-v0", scene="real/willow_south").unwrapped.world
    cs = grow_free_space(w.scene, 1e-4 * w.diameter)
    graph = VisibilityGraph(cs)
    field = PathField(graph, w.region)
    other = PathField(graph, w.region)
    rng = np.random.default_rng(0)
    x0, y0, x1, y1 = cs.bounds
    pts = np.column_stack([rng.uniform(x0, x1, 400), rng.uniform(y0, y1, 400)])
    pts = pts[shapely.contains_xy(cs, pts[:, 0], pts[:, 1])][:25]
    bends = 0
    for p in pts:
        path = field.path(p)
        assert path is not None
        assert shapely.covers(field.cover, shapely.LineString(path.points))
        assert shapely.distance(shapely.Point(path.end), field.target) <= 1e-9 * w.diameter
        assert path.length >= shapely.distance(shapely.Point(p), field.target) - 1e-9
        assert other.path(p).length == path.length
        assert shortest_path(cs, p, w.region).length == pytest.approx(path.length, rel=1e-12)
        if len(path.points) > 2:  # sub-path optimality from the first bend
            bends += 1
            rest = field.path(path.points[1])
            first = float(np.hypot(*(path.points[1] - path.points[0])))
            assert rest.length == pytest.approx(path.length - first, rel=1e-9, abs=1e-9)
    assert bends >= 5
