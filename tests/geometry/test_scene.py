"""Tests for geometry.scene: the pinned JSON format, validation messages, derived geometry."""

from __future__ import annotations

import copy
import json
import math
import pickle

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from shapely.geometry import MultiPolygon, Point, Polygon, box

from geometry.scene import PAPER_ASSUMPTION, Scene, SceneError, SensorSpec


def build(base: dict, **changes) -> Scene:
    d = copy.deepcopy(base)
    for k, v in changes.items():
        if v is ...:
            d.pop(k, None)
        else:
            d[k] = v
    return Scene.from_dict(d)


# ---------------------------------------------------------------------------------------------
# round trips
# ---------------------------------------------------------------------------------------------


def test_round_trip_minimal(lab_dict):
    s = Scene.from_dict(lab_dict)
    assert s.to_dict() == lab_dict
    assert "sensor" not in s.to_dict() and "start" not in s.to_dict()
    assert s.sensor == SensorSpec()
    assert s.start is None


def test_round_trip_optional_keys_present(lab_dict):
    lab_dict["sensor"] = {"fov_deg": 90, "max_range": None, "eps_pos": 0.25, "eps_aim_deg": 5}
    lab_dict["start"] = [1, 8, 0.5]
    s = Scene.from_dict(lab_dict)
    assert s.to_dict() == lab_dict
    assert s.sensor.fov == pytest.approx(math.pi / 2)
    assert s.sensor.eps_aim == pytest.approx(math.radians(5))
    assert s.sensor.eps_pos == 0.25
    assert s.start == (1.0, 8.0, 0.5)


def test_round_trip_partial_sensor_keeps_caller_keys(lab_dict):
    lab_dict["sensor"] = {"max_range": 4.5}
    s = Scene.from_dict(lab_dict)
    assert s.to_dict() == lab_dict
    assert s.sensor == SensorSpec(max_range=4.5)


def test_round_trip_keeps_numbers_and_vertex_order(lab_dict):
    # clockwise bounds, int and float numbers: to_dict gives them back unchanged
    lab_dict["bounds"] = [[0, 0], [0, 10.0], [10, 10], [10.0, 0]]
    s = Scene.from_dict(lab_dict)
    out = s.to_dict()
    assert out == lab_dict
    assert out["bounds"][1][1] == 10.0 and isinstance(out["bounds"][1][1], float)
    assert isinstance(out["bounds"][2][0], int)
    # the internal arrays are counter-clockwise copies
    assert shapely.is_ccw(shapely.LinearRing(s.bounds))
    assert not s.bounds.flags.writeable


def test_to_dict_is_a_copy(lab_scene, lab_dict):
    out = lab_scene.to_dict()
    out["bounds"][0][0] = 99
    out["name"] = "changed"
    assert lab_scene.to_dict() == lab_dict


def test_save_load_round_trip(tmp_path, lab_dict):
    lab_dict["start"] = [1.5, 1.5, -0.25]
    s = Scene.from_dict(lab_dict)
    path = tmp_path / "lab.json"
    s.save(path)
    assert json.loads(path.read_text()) == lab_dict
    t = Scene.load(path)
    assert t == s
    assert t.to_dict() == lab_dict


def test_load_prefixes_file_name(tmp_path, lab_dict):
    lab_dict["obstcles"] = []
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(lab_dict))
    with pytest.raises(SceneError, match=r"bad\.json: unknown key 'obstcles'"):
        Scene.load(path)
    path.write_text("{not json")
    with pytest.raises(SceneError, match="invalid JSON"):
        Scene.load(path)


def test_keyword_constructor_accepts_arrays(lab_dict):
    s = Scene(
        name="lab",
        bounds=np.array(lab_dict["bounds"], dtype=float),
        obstacles=[np.array(o) for o in lab_dict["obstacles"]],
        target=lab_dict["target"],
        goal=lab_dict["goal"],
        failure=[(5.0, 2.0)],
        sensor=SensorSpec(fov_deg=180),
        start=(1.0, 1.0, 0.0),
    )
    d = s.to_dict()
    assert d["sensor"]["fov_deg"] == 180.0
    assert d["failure"] == [[5.0, 2.0]]
    assert Scene.from_dict(d) == s
    json.dumps(d)  # JSON-serialisable


def test_replace(lab_scene):
    extra = [[4.0, 8.0], [5.0, 8.0], [5.0, 9.0]]
    s2 = lab_scene.replace(obstacles=lab_scene.to_dict()["obstacles"] + [extra])
    assert len(s2.obstacles) == 3
    assert s2.free_space.area == pytest.approx(lab_scene.free_space.area - 0.5)
    assert lab_scene.replace(start=[1, 1, 0]).replace(start=None) == lab_scene


# ---------------------------------------------------------------------------------------------
# derived geometry
# ---------------------------------------------------------------------------------------------


def test_touching_and_overlapping_obstacles_merge(lab_dict):
    # LAB's two obstacles share an edge: one merged polygon
    s = Scene.from_dict(lab_dict)
    assert isinstance(s.obstacle_union, Polygon)
    assert s.obstacle_union.area == pytest.approx(5.0)
    assert s.free_space.area == pytest.approx(95.0)
    # overlapping obstacles: union area, not the sum
    lab_dict["obstacles"].append([[7, 7], [8.5, 7], [8.5, 8.5], [7, 8.5]])
    s = Scene.from_dict(lab_dict)
    expected = shapely.union_all([Polygon(o) for o in lab_dict["obstacles"]]).area
    assert s.obstacle_union.area == pytest.approx(expected)
    assert s.free_space.area == pytest.approx(100 - expected)
    # obstacles touching at a single vertex
    lab_dict["obstacles"] = [[[6, 6], [7, 6], [7, 7], [6, 7]], [[7, 7], [8, 7], [8, 8], [7, 8]]]
    s = Scene.from_dict(lab_dict)
    assert s.obstacle_union.area == pytest.approx(2.0)
    assert s.free_space.area == pytest.approx(98.0)


def test_no_obstacles(lab_dict):
    lab_dict["obstacles"] = []
    s = Scene.from_dict(lab_dict)
    assert s.obstacle_union.is_empty
    assert s.free_space.equals(box(0, 0, 10, 10))


def test_free_space_multipolygon(lab_dict):
    # a wall-to-wall obstacle splits the room
    lab_dict["obstacles"] = [[[0, 5], [10, 5], [10, 6], [0, 6]]]
    s = Scene.from_dict(lab_dict)
    assert isinstance(s.free_space, MultiPolygon)
    assert s.free_space.area == pytest.approx(90.0)


def test_obstacle_touching_wall_is_valid(lab_dict):
    lab_dict["obstacles"] = [[[9, 4], [10, 4], [10, 5], [9, 5]]]
    s = Scene.from_dict(lab_dict)
    assert s.free_space.area == pytest.approx(99.0)


def test_nonconvex_bounds(lab_dict):
    lab_dict["bounds"] = [[0, 0], [10, 0], [10, 10], [5, 10], [5, 5], [0, 5]]
    lab_dict["obstacles"] = [[[7, 7], [8, 7], [8, 8]]]
    s = Scene.from_dict(lab_dict)
    assert s.free_space.area == pytest.approx(75 - 0.5)


def test_point_goal_and_failure(lab_dict):
    lab_dict["goal"] = [[2.5, 2.5]]
    s = Scene.from_dict(lab_dict)
    assert s.goal.shape == (1, 2)
    assert isinstance(s.goal_geom, Point) and isinstance(s.failure_geom, Point)
    assert s.region("goal").equals(Point(2.5, 2.5))
    assert s.region("failure").equals(Point(5, 2))
    assert s.to_dict() == lab_dict


def test_region_passthrough_and_error(lab_scene):
    p = box(1, 1, 2, 2)
    assert lab_scene.region(p) is p
    assert isinstance(lab_scene.region("goal"), Polygon)
    with pytest.raises(SceneError, match="region: expected 'goal', 'failure'"):
        lab_scene.region("start")


def test_target_frame_and_target_at(lab_dict):
    lab_dict["target"] = [[-1, -0.5], [2, -0.5], [2, 0.5], [-1, 0.5]]
    lab_dict["goal"] = [[3, 3], [4, 3], [4, 4], [3, 4]]
    s = Scene.from_dict(lab_dict)
    assert s.target_radius == pytest.approx(math.hypot(2, 0.5))
    a0 = s.target_at(0, 0, 0)
    assert a0.equals(Polygon(lab_dict["target"]))
    a = s.target_at(5, 1, math.pi / 2)
    # rotated CCW by 90 degrees about the reference point, then translated
    assert a.equals(Polygon([[5.5, 0], [5.5, 3], [4.5, 3], [4.5, 0]]))
    assert a.area == pytest.approx(3.0)


def test_diameter_tol(lab_scene):
    assert lab_scene.diameter == pytest.approx(math.hypot(10, 10))
    assert lab_scene.tol == pytest.approx(1e-9 * math.hypot(10, 10))


def test_swept_hull(lab_scene):
    h = lab_scene.swept_hull("goal", 0.0)
    assert h.equals(box(1.5, 1.5, 3.5, 3.5))
    h = lab_scene.swept_hull("failure", math.pi / 4)
    r = math.sqrt(0.5)
    assert h.area == pytest.approx(1.0)
    assert h.bounds == pytest.approx((5 - r, 2 - r, 5 + r, 2 + r))


def test_sensor_spec_units():
    s = SensorSpec(fov_deg=180, eps_aim_deg=90)
    assert s.fov == pytest.approx(math.pi)
    assert s.eps_aim == pytest.approx(math.pi / 2)
    with pytest.raises(AttributeError):
        s.fov_deg = 10  # frozen


# ---------------------------------------------------------------------------------------------
# check_clear
# ---------------------------------------------------------------------------------------------


def test_check_clear(lab_scene):
    lab_scene.check_clear(box(1, 1, 3, 3), "q")
    # touching an obstacle or a wall is fine
    lab_scene.check_clear(box(4, 6, 6, 7), "touch")
    lab_scene.check_clear(box(0, 0, 1, 1), "corner")
    lab_scene.check_clear(Point(6, 6), "point on an obstacle corner")
    with pytest.raises(SceneError, match=r"q: meets obstacles\[0\] at .*paper's assumption"):
        lab_scene.check_clear(box(5, 5, 6.5, 6.5), "q")
    with pytest.raises(SceneError, match=r"q: meets obstacles\[1\]"):
        lab_scene.check_clear(box(8.5, 6.2, 8.8, 6.8), "q")
    with pytest.raises(SceneError, match=r"w: meets the bounds \(walls\).*Briggs & Donald 3\.1\.1"):
        lab_scene.check_clear(box(-1, 1, 1, 2), "w")
    # a convex hull that swallows an obstacle whole
    with pytest.raises(SceneError, match=r"obstacles\[0\]"):
        lab_scene.check_clear(box(5, 5, 9.5, 9.5), "big")


def test_check_clear_tolerance_scales(lab_scene):
    eps = 1e-12
    lab_scene.check_clear(box(4, 6, 6 + eps, 7), "within tol")
    with pytest.raises(SceneError):
        lab_scene.check_clear(box(4, 6, 6 + 1e-6, 7), "beyond tol")


# ---------------------------------------------------------------------------------------------
# validation errors
# ---------------------------------------------------------------------------------------------


def test_not_a_dict():
    with pytest.raises(SceneError, match="scene: expected a JSON object"):
        Scene.from_dict([1, 2])  # type: ignore[arg-type]


def test_unknown_key(lab_dict):
    with pytest.raises(SceneError, match=r"unknown key 'obstcles' \(allowed: name, bounds"):
        build(lab_dict, obstcles=[])


@pytest.mark.parametrize("key", ["name", "bounds", "obstacles", "target", "goal", "failure"])
def test_missing_key(lab_dict, key):
    with pytest.raises(SceneError, match=f"missing required key '{key}'"):
        build(lab_dict, **{key: ...})


@pytest.mark.parametrize(
    ("changes", "pattern"),
    [
        ({"name": 3}, r"name: expected a string"),
        ({"bounds": "square"}, r"bounds: expected a list of \[x, y\] vertices"),
        ({"obstacles": {"a": 1}}, r"obstacles: expected a list of polygons"),
        ({"target": [[0, 0, 1], [1, 0], [0, 1]]}, r"target\[0\]: expected an \[x, y\] pair"),
        ({"goal": [[2, 2], [3, "2"], [3, 3]]}, r"goal\[1\]: coordinates must be numbers"),
        ({"goal": [[2, 2], [3, True], [3, 3]]}, r"goal\[1\]: coordinates must be numbers"),
        ({"failure": [5, 2]}, r"failure\[0\]: expected an \[x, y\] pair"),
        ({"start": [1, 1]}, r"start: expected \[x, y, theta\] \(theta in radians\)"),
        ({"start": "origin"}, r"start: expected \[x, y, theta\]"),
        ({"sensor": [360]}, r"sensor: expected an object"),
        ({"sensor": {"fov": 90}}, r"sensor: unknown key 'fov' \(allowed: fov_deg"),
        ({"sensor": {"fov_deg": "wide"}}, r"sensor\.fov_deg: must be a number"),
        ({"sensor": {"eps_pos": None}}, r"sensor\.eps_pos: must be a number"),
    ],
)
def test_wrong_types(lab_dict, changes, pattern):
    with pytest.raises(SceneError, match=pattern):
        build(lab_dict, **changes)


@pytest.mark.parametrize(
    ("sensor", "pattern"),
    [
        ({"fov_deg": 400}, r"sensor\.fov_deg: must be in \(0, 360\], got 400"),
        ({"fov_deg": 0}, r"sensor\.fov_deg: must be in \(0, 360\], got 0"),
        ({"max_range": 0}, r"sensor\.max_range: must be > 0 or null"),
        ({"max_range": float("inf")}, r"sensor\.max_range: must be finite"),
        ({"eps_pos": -0.1}, r"sensor\.eps_pos: must be >= 0"),
        ({"eps_aim_deg": 360}, r"sensor\.eps_aim_deg: must be in \[0, 180\)"),
        ({"eps_aim_deg": 200}, r"sensor\.eps_aim_deg: must be in \[0, 180\)"),
        ({"eps_aim_deg": float("nan")}, r"sensor\.eps_aim_deg: must be finite"),
    ],
)
def test_sensor_values(lab_dict, sensor, pattern):
    with pytest.raises(SceneError, match=pattern):
        build(lab_dict, sensor=sensor)
    with pytest.raises(SceneError, match=pattern):
        SensorSpec(**sensor)


def test_scene_error_is_value_error():
    assert issubclass(SceneError, ValueError)


@pytest.mark.parametrize("bad", [float("nan"), float("inf"), -float("inf")])
def test_non_finite_coordinates(lab_dict, bad):
    lab_dict["obstacles"][1][2] = [9, bad]
    with pytest.raises(SceneError, match=r"obstacles\[1\]\[2\]: non-finite coordinate"):
        Scene.from_dict(lab_dict)
    with pytest.raises(SceneError, match=r"start: non-finite value"):
        build(lab_dict, obstacles=[], start=[1, bad, 0])


def test_non_finite_from_json_text(tmp_path, lab_dict):
    text = json.dumps(lab_dict).replace('"target": [[-0.5', '"target": [[NaN')
    path = tmp_path / "nan.json"
    path.write_text(text)
    with pytest.raises(SceneError, match=r"target\[0\]: non-finite coordinate nan"):
        Scene.load(path)


@pytest.mark.parametrize(
    ("key", "value", "pattern"),
    [
        ("bounds", [[0, 0], [10, 0]], r"bounds: a polygon needs at least 3 vertices; got 2"),
        ("obstacles", [[[6, 6]]], r"obstacles\[0\]: a polygon needs at least 3 vertices"),
        ("goal", [[2, 2], [3, 3]], r"goal: a polygon needs at least 3 vertices, or a single point"),
        ("goal", [], r"goal: a polygon needs at least 3 vertices, or a single point"),
        ("target", [[0, 0], [1, 1], [2, 2]], r"target: zero-area polygon"),
        ("obstacles", [[[6, 6], [7, 6], [8, 6], [7, 6]]], r"obstacles\[0\]: zero-area polygon"),
        (
            "obstacles",
            [[[6, 6], [7, 6], [7, 6], [7, 7]]],
            r"obstacles\[0\]: repeated consecutive vertices \[1\] and \[2\] at \(7, 6\)",
        ),
        (
            "goal",
            [[2, 2], [3, 2], [3, 3], [2, 2]],
            r"goal: the last vertex repeats the first at \(2, 2\) \(do not close the ring\)",
        ),
        (
            "obstacles",
            [[[6, 6], [8, 6], [8, 8], [6, 8]], [[6, 6], [8, 8], [8, 6], [6, 8]]],
            r"obstacles\[1\]: self-intersecting polygon at \(7, 7\)",
        ),
        ("bounds", [[0, 0], [10, 10], [10, 0], [0, 10]], r"bounds: self-intersecting polygon"),
    ],
)
def test_degenerate_polygons(lab_dict, key, value, pattern):
    with pytest.raises(SceneError, match=pattern):
        build(lab_dict, **{key: value})


def test_obstacle_outside_bounds(lab_dict):
    lab_dict["obstacles"].append([[9, 8], [11, 8], [11, 9], [9, 9]])
    with pytest.raises(SceneError, match=r"obstacles\[2\]: lies \(partly\) outside the bounds"):
        Scene.from_dict(lab_dict)
    lab_dict["obstacles"][2] = [[20, 20], [21, 20], [21, 21]]
    with pytest.raises(SceneError, match=r"obstacles\[2\]: lies \(partly\) outside the bounds"):
        Scene.from_dict(lab_dict)


def test_target_reference_point(lab_dict):
    # issue 10: the reference point may lie outside the target or on its outline
    s = build(lab_dict, target=[[1, 1], [2, 1], [2, 2]])
    assert s.target_radius == pytest.approx(math.hypot(2, 2))
    build(lab_dict, target=[[0, 0], [1, 0], [0, 1]])
    # ... but the swept hull must still be clear
    with pytest.raises(SceneError, match=r"goal: CH\(A ⊕ G\).*meets obstacles\[0\]"):
        build(lab_dict, target=[[4, 4], [5, 4], [5, 5]])


@pytest.mark.parametrize("which", ["goal", "failure"])
def test_region_outside_free_space(lab_dict, which):
    other = "failure" if which == "goal" else "goal"
    lab_dict[other] = [[1, 9]]
    inside_obstacle = [[6.5, 6.5], [7.5, 6.5], [7.5, 7.5]]
    pattern = (
        rf"{which}: not inside the free space \(bounds minus obstacles\): meets obstacles\[0\]"
    )
    with pytest.raises(SceneError, match=pattern):
        build(lab_dict, **{which: inside_obstacle})
    with pytest.raises(SceneError, match=rf"{which}: not inside the free space"):
        build(lab_dict, **{which: [[7, 7]]})
    with pytest.raises(SceneError, match=rf"{which}: not inside the free space.*bounds \(walls\)"):
        build(lab_dict, **{which: [[11, 5]]})


@pytest.mark.parametrize(
    ("goal", "failure"),
    [
        ([[2, 2], [3, 2], [3, 3], [2, 3]], [[2.5, 2.5], [4, 2.5], [4, 4]]),  # polygons overlap
        ([[2, 2], [3, 2], [3, 3], [2, 3]], [[2.5, 2.5]]),  # point inside polygon
        ([[2, 2], [3, 2], [3, 3], [2, 3]], [[3, 2.5]]),  # point on its boundary
        ([[4, 4]], [[4, 4]]),  # the same point
    ],
)
def test_goal_failure_overlap(lab_dict, goal, failure):
    pattern = r"goal and failure overlap at .*recognition is impossible"
    with pytest.raises(SceneError, match=pattern):
        build(lab_dict, goal=goal, failure=failure)
    with pytest.raises(SceneError, match=r"goal and failure overlap"):
        build(lab_dict, goal=failure, failure=goal)


def test_goal_failure_touching_polygons_are_valid(lab_dict):
    s = build(lab_dict, failure=[[3, 2], [4, 2], [4, 3], [3, 3]])
    assert s.goal_geom.touches(s.failure_geom)


@pytest.mark.parametrize(
    ("changes", "pattern"),
    [
        # the obstacle does not meet G itself, but it meets CH(A ⊕ G) = [1.5, 3.5]^2
        (
            {"obstacles": [[[3.2, 2], [4, 2], [4, 3], [3.2, 3]]]},
            r"goal: CH\(A ⊕ G\) .*meets obstacles\[0\] at",
        ),
        ({"goal": [[0.2, 2], [1, 2], [1, 3]]}, r"goal: CH\(A ⊕ G\) .*meets the bounds \(walls\)"),
        ({"failure": [[9.8, 2]]}, r"failure: CH\(A ⊕ H\) .*meets the bounds \(walls\)"),
        ({"failure": [[5.6, 6.5]]}, r"failure: CH\(A ⊕ H\) .*meets obstacles\[0\]"),
        # the hull of a non-convex goal reaches an obstacle in the goal's notch
        (
            {
                "goal": [[1, 1], [5, 1], [5, 5], [4, 5], [4, 2], [2, 2], [2, 5], [1, 5]],
                "failure": [[8, 2]],
                "obstacles": [[[2.8, 3.5], [3.2, 3.5], [3.2, 4]]],
            },
            r"goal: CH\(A ⊕ G\) .*meets obstacles\[0\]",
        ),
    ],
)
def test_paper_assumption(lab_dict, changes, pattern):
    with pytest.raises(SceneError, match=pattern) as info:
        build(lab_dict, **changes)
    msg = str(info.value)
    assert "paper's assumption" in msg and "Briggs & Donald 3.1.1" in msg
    assert PAPER_ASSUMPTION in msg


def test_paper_assumption_touching_is_valid(lab_dict):
    # CH(A ⊕ G) = [1.5, 3.5]^2 touches the obstacle and the wall exactly
    s = build(
        lab_dict,
        goal=[[0.5, 2], [3, 2], [3, 3], [0.5, 3]],
        obstacles=[[[3.5, 2], [4, 2], [4, 3], [3.5, 3]]],
    )
    assert s.obstacle_union.area == pytest.approx(0.5)


def test_start_pose(lab_dict):
    s = build(lab_dict, start=[6, 6, 0])  # on an obstacle corner: still free space
    assert s.start == (6.0, 6.0, 0.0)
    with pytest.raises(SceneError, match=r"start: \(7, 7\) is not in the free space"):
        build(lab_dict, start=[7, 7, 0])
    with pytest.raises(SceneError, match=r"start: \(-1, 5\) is not in the free space"):
        build(lab_dict, start=[-1, 5, 0])


# ---------------------------------------------------------------------------------------------
# immutability, equality, pickling
# ---------------------------------------------------------------------------------------------


def test_read_only(lab_scene):
    with pytest.raises(AttributeError, match="read-only"):
        lab_scene.name = "x"
    with pytest.raises(ValueError):
        lab_scene.bounds[0, 0] = 5.0
    with pytest.raises(ValueError):
        lab_scene.obstacles[0][0, 0] = 5.0


def test_equality_and_hash(lab_dict):
    a, b = Scene.from_dict(lab_dict), Scene.from_dict(copy.deepcopy(lab_dict))
    assert a == b and hash(a) == hash(b)
    assert a != build(lab_dict, name="other")
    assert len({a, b}) == 1


def test_pickle(lab_dict):
    lab_dict["sensor"] = {"fov_deg": 120, "eps_pos": 0.1}
    s = Scene.from_dict(lab_dict)
    _ = s.free_space, s.obstacle_union  # populate the caches (prepared geometries too)
    s.check_clear(box(1, 1, 2, 2), "warm")
    t = pickle.loads(pickle.dumps(s))
    assert t == s
    assert t.to_dict() == lab_dict
    assert t.free_space.equals(s.free_space)
    assert t.sensor == s.sensor
    np.testing.assert_array_equal(t.obstacles[1], s.obstacles[1])
    with pytest.raises(SceneError):
        t.check_clear(box(5, 5, 7, 7), "after unpickle")


# ---------------------------------------------------------------------------------------------
# properties
# ---------------------------------------------------------------------------------------------

coord = st.floats(min_value=-50, max_value=50, allow_nan=False, allow_infinity=False)


# the fixtures are only read, never mutated, so reusing them across examples is fine
reuse_fixture = settings(suppress_health_check=[HealthCheck.function_scoped_fixture])


@reuse_fixture
@given(
    dx=coord,
    dy=coord,
    scale=st.floats(min_value=0.01, max_value=100),
    flip=st.booleans(),
)
def test_round_trip_property(lab_dict, dx, dy, scale, flip):
    """Affine copies of LAB (optionally mirrored, i.e. clockwise) round-trip exactly."""

    def tr(pts):
        out = [[x * scale + dx, y * scale + dy] for x, y in pts]
        return [[-x, y] for x, y in out] if flip else out

    d = {
        "name": "affine",
        "bounds": tr(lab_dict["bounds"]),
        "obstacles": [tr(o) for o in lab_dict["obstacles"]],
        "target": [[x * scale * (-1 if flip else 1), y * scale] for x, y in lab_dict["target"]],
        "goal": tr(lab_dict["goal"]),
        "failure": tr(lab_dict["failure"]),
    }
    s = Scene.from_dict(d)
    assert s.to_dict() == d
    assert s.free_space.area == pytest.approx(95.0 * scale * scale, rel=1e-9)
    for arr in (s.bounds, s.target, s.goal, *s.obstacles):
        assert shapely.is_ccw(shapely.LinearRing(arr))


@reuse_fixture
@given(
    x=st.floats(min_value=-5, max_value=5),
    y=st.floats(min_value=-5, max_value=5),
    theta=st.floats(min_value=-10, max_value=10),
)
def test_target_at_property(lab_scene, x, y, theta):
    a = lab_scene.target_at(x, y, theta)
    assert a.area == pytest.approx(1.0)
    assert a.centroid.x == pytest.approx(x, abs=1e-9)
    assert a.centroid.y == pytest.approx(y, abs=1e-9)
    assert a.is_valid
    assert shapely.is_ccw(a.exterior)


def test_check_clear_sees_needles(lab_dict):
    """An obstacle thinner than 2 tol vanishes when shrunk, yet it meets a hull its tip
    runs deep into (fuzz contact seed 101082); lying flush along the hull it touches."""
    lab_dict["obstacles"].append([[0.5, 8.5], [2.0, 8.5 + 5e-10], [0.5, 8.5 + 1e-9]])
    s = Scene.from_dict(lab_dict)
    n = len(lab_dict["obstacles"]) - 1
    with pytest.raises(SceneError, match=rf"needle: meets obstacles\[{n}\] at \(2, 8\.5"):
        s.check_clear(box(1.5, 7.5, 2.5, 9.5), "needle")
    s.check_clear(box(1.0, 8.5 + 1e-9, 1.8, 9.5), "flush along the needle")
    s.check_clear(box(2.0, 8.0, 3.0, 9.0), "the needle's tip on an edge")
