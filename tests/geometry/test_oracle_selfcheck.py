"""The referee is checked first: hand-made scenes whose answers are obvious."""

from __future__ import annotations

import pytest

pytest.importorskip("pyvispoly")

import shapely  # noqa: E402
from shapely.geometry import Point, Polygon, box  # noqa: E402

try:  # rootdir on sys.path (python -m pytest) or tests/ itself (plain pytest)
    from tests.oracle import (  # noqa: E402
        VisOracle,
        minkowski_sum,
        non_overlap_segments,
        overlap_segments,
        sees_completely,
        sees_partially,
        visible_length,
    )
except ImportError:  # pragma: no cover
    from oracle import (  # type: ignore[no-redef]  # noqa: E402
        VisOracle,
        minkowski_sum,
        non_overlap_segments,
        overlap_segments,
        sees_completely,
        sees_partially,
        visible_length,
    )

ROOM = box(0, 0, 10, 10)
TARGET = box(6, 4.5, 7, 5.5)


def test_empty_room_sees_everything():
    o = VisOracle(ROOM)
    v = o.visibility((1, 1))
    assert v.area == pytest.approx(100.0)
    assert sees_completely(o, (1, 1), TARGET)
    assert sees_partially(o, (1, 1), TARGET)


def test_visibility_polygon_with_a_square_hole():
    space = ROOM.difference(box(4, 4, 6, 6))
    v = VisOracle(space).visibility((1, 5))
    # the hole's shadow is the trapezoid (4,4)-(10,2)-(10,8)-(4,6) plus the hole itself
    assert v.area == pytest.approx(76.0)
    assert not v.contains(Point(8, 5))
    assert v.contains(Point(8, 1))


def test_wall_hides_target_completely():
    space = ROOM.difference(box(3, 3, 3.2, 7))
    o = VisOracle(space)
    assert not sees_partially(o, (1, 5), TARGET)
    assert not sees_completely(o, (1, 5), TARGET)
    # from above the wall, everything is in view
    assert sees_completely(o, (1, 9.5), TARGET)


def test_wall_hides_target_partially():
    # the ray from (1, 5) over the wall's corner (3, 5.1) has slope 0.05
    space = ROOM.difference(box(3, 3, 3.2, 5.1))
    o = VisOracle(space)
    assert sees_partially(o, (1, 5), TARGET)
    assert not sees_completely(o, (1, 5), TARGET)
    v = o.visibility((1, 5))
    seen = shapely.intersection(TARGET, v).area
    # visible part: above y = 5 + 0.05 (x - 1) for x in [6, 7]: int (0.5 - 0.05 (x - 1)) dx
    assert seen == pytest.approx(0.5 - 0.05 * 5.5, rel=1e-9)


def test_thin_gap_is_detected():
    # two walls leave a gap: the target is visible only through it
    space = ROOM.difference(box(3, 0, 3.2, 4.95)).difference(box(3, 5.05, 3.2, 10))
    o = VisOracle(space)
    assert sees_partially(o, (1, 5), TARGET)
    assert not sees_completely(o, (1, 5), TARGET)
    assert not sees_partially(o, (1, 1), TARGET)


def test_target_does_not_occlude_itself_but_an_occluder_does():
    o = VisOracle(ROOM)
    assert sees_completely(o, (1, 5), TARGET)  # the far side counts: segments may cross A
    occ = VisOracle(ROOM, occluders=[TARGET])
    front = shapely.LineString([(6, 4.5), (6, 5.5)])
    back = shapely.LineString([(7, 4.5), (7, 5.5)])
    tol = 1e-9
    assert visible_length(occ, (1, 5), front, tol) == pytest.approx(1.0, rel=1e-6)
    assert visible_length(occ, (1, 5), back, tol) < 1e-6


def test_point_outside_free_space_sees_nothing():
    space = ROOM.difference(box(3, 3, 5, 5))
    o = VisOracle(space)
    assert o.visibility((4, 4)).is_empty
    assert o.visibility((11, 5)).is_empty
    assert not sees_partially(o, (4, 4), TARGET)


def test_disconnected_free_space():
    space = ROOM.difference(box(4.5, -1, 5, 11))  # wall splits the room
    o = VisOracle(space)
    assert not sees_partially(o, (1, 5), TARGET)
    assert sees_completely(o, (9, 1), TARGET)


def test_concave_room():
    room = Polygon([(0, 0), (10, 0), (10, 10), (5, 10), (5, 5), (0, 5)])  # L-shaped
    o = VisOracle(room)
    t = box(7, 8, 8, 9)
    assert not sees_partially(o, (1, 4), t)  # around the reflex corner (5, 5)
    assert sees_completely(o, (9, 1), t)


def test_minkowski_sum():
    assert minkowski_sum(box(0, 0, 1, 1), box(0, 0, 2, 2)).equals(box(0, 0, 3, 3))
    ell = Polygon([(0, 0), (4, 0), (4, 1), (1, 1), (1, 3), (0, 3)])
    d = 0.25
    got = minkowski_sum(ell, box(-d, -d, d, d))
    want = ell.buffer(d, join_style="mitre")
    assert got.symmetric_difference(want).area < 1e-9
    moved = minkowski_sum(ell, Point(2, 3))
    assert moved.equals(shapely.affinity.translate(ell, 2, 3))


def test_overlap_segments():
    a_g = box(-1, -0.5, 1, 0.5)
    a_h = box(0, -0.5, 2, 0.5)
    ov = overlap_segments(a_g, a_h)
    assert sum(float(((e - s) ** 2).sum() ** 0.5) for s, e, _ in ov) == pytest.approx(2.0)
    assert non_overlap_segments(a_g, a_h).length == pytest.approx(4.0)
    # opposite orientation (touching along an edge) is not an overlap
    assert overlap_segments(box(0, 0, 1, 1), box(0, 1, 1, 2)) == []
    # collinear but disjoint edges: no overlap
    assert overlap_segments(box(0, 0, 1, 1), box(2, 0, 3, 1)) == []
