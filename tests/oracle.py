"""Independent visibility oracle for the tests (CGAL via ``pyvispoly``).

Test-only: ``pyvispoly`` is GPL; the ``geometry`` package never imports this module.

The oracle answers point queries exactly in CGAL's arithmetic and converts the
visibility polygon V(p) to a shapely Polygon (float coordinates):

* :class:`VisOracle` -- built once from a free-space geometry (bounds minus
  obstacles, optionally minus extra occluders such as the target at G), answers
  ``visibility(p)`` for placements p in that free space;
* :func:`sees_completely` -- the target (or swept area) is a subset of V(p);
* :func:`sees_partially` -- the target meets V(p) in positive area;
* :func:`visible_length` -- length of the part of some boundary segments that
  lies in V(p) (for one-sided target edges, paper 5.1);
* :func:`minkowski_sum`, :func:`overlap_segments`, :func:`non_overlap_segments`
  -- the small amount of plain geometry the referee needs, written here
  independently of the package.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any

import numpy as np
import pyvispoly as pv
import shapely
import shapely.affinity
from shapely.geometry import LineString, MultiLineString, Point, Polygon

__all__ = [
    "VisOracle",
    "free_space",
    "minkowski_sum",
    "non_overlap_segments",
    "overlap_segments",
    "sees_completely",
    "sees_partially",
    "visible_length",
]

#: Relative area tolerance of the complete/partial tests.
AREA_REL = 1e-9


def free_space(scene_or_geom: Any, occluders: Iterable[shapely.Geometry] = ()) -> shapely.Geometry:
    """The free space (bounds minus obstacles) of a Scene, minus extra occluders."""
    g = getattr(scene_or_geom, "free_space", scene_or_geom)
    for o in occluders:
        g = g.difference(o)
    return g


def _ring_points(coords: np.ndarray, ccw: bool) -> list[pv.Point]:
    c = np.asarray(coords)[:-1, :2]
    area2 = np.sum(c[:, 0] * np.roll(c[:, 1], -1) - np.roll(c[:, 0], -1) * c[:, 1])
    if (area2 > 0) != ccw:
        c = c[::-1]
    return [pv.Point(float(x), float(y)) for x, y in c]


def _to_cgal(poly: Polygon) -> pv.PolygonWithHoles:
    outer = pv.Polygon(_ring_points(np.asarray(poly.exterior.coords), ccw=True))
    holes = [pv.Polygon(_ring_points(np.asarray(r.coords), ccw=False)) for r in poly.interiors]
    return pv.PolygonWithHoles(outer, holes)


def _from_cgal(vp: pv.Polygon) -> Polygon:
    pts = [(float(q.x()), float(q.y())) for q in vp.boundary()]
    if len(pts) < 3:
        return Polygon()
    poly = Polygon(pts)
    if not poly.is_valid:  # needles / touching pieces from grazing rays
        fixed = shapely.make_valid(poly)
        parts = [g for g in shapely.get_parts(fixed) if g.geom_type in ("Polygon", "MultiPolygon")]
        poly = shapely.union_all(parts) if parts else Polygon()
    return poly


class VisOracle:
    """Visibility polygons V(p) in a polygonal free space (CGAL, via pyvispoly).

    Parameters
    ----------
    space : a Scene (its ``free_space`` is used) or a shapely Polygon/MultiPolygon.
    occluders : extra polygons removed from the space (they block sight), e.g. the
        target placed at G in the recognizability tests.  The target itself is NOT
        an occluder for complete/partial visibility of that same target.
    """

    def __init__(self, space: Any, occluders: Iterable[shapely.Geometry] = ()) -> None:
        geom = free_space(space, occluders)
        self.geom = geom
        comps = [g for g in shapely.get_parts(geom) if g.geom_type == "Polygon" and g.area > 0]
        self._comps = [(c, pv.VisibilityPolygonCalculator(_to_cgal(c))) for c in comps]
        for c, _ in self._comps:
            shapely.prepare(c)

    def visibility(self, p: Sequence[float]) -> Polygon:
        """V(p) as a shapely Polygon; empty if p is not in the interior of the space."""
        pt = Point(float(p[0]), float(p[1]))
        for comp, calc in self._comps:
            if comp.contains(pt):
                q = pv.Point(float(p[0]), float(p[1]))
                if not calc.is_feasible_query_point(q):
                    return Polygon()
                return _from_cgal(calc.compute_visibility_polygon(q))
        return Polygon()


def _as_oracle(o: Any) -> VisOracle:
    return o if isinstance(o, VisOracle) else VisOracle(o)


def sees_completely(
    space: Any, p: Sequence[float], target: shapely.Geometry, vis: Polygon | None = None
) -> bool:
    """True iff every point of ``target`` is visible from ``p`` (target subset of V(p)).

    ``space`` is a :class:`VisOracle`, a Scene or a free-space geometry (the target
    must not be removed from it).  Tolerance: the uncovered area is below
    ``AREA_REL * target.area``.  ``vis`` may pass a precomputed V(p).
    """
    v = _as_oracle(space).visibility(p) if vis is None else vis
    if v.is_empty:
        return False
    return shapely.difference(target, v).area <= AREA_REL * target.area


def sees_partially(
    space: Any, p: Sequence[float], target: shapely.Geometry, vis: Polygon | None = None
) -> bool:
    """True iff ``target`` meets V(p) in positive area (above ``AREA_REL * target.area``)."""
    v = _as_oracle(space).visibility(p) if vis is None else vis
    if v.is_empty:
        return False
    return shapely.intersection(target, v).area > AREA_REL * target.area


def visible_length(
    space: Any,
    p: Sequence[float],
    segments: shapely.Geometry,
    tol: float,
    vis: Polygon | None = None,
) -> float:
    """Length of the part of ``segments`` (lines on occluder boundaries) inside V(p).

    V(p) is grown by ``tol`` first, since the segments lie on its boundary.
    """
    v = _as_oracle(space).visibility(p) if vis is None else vis
    if v.is_empty or segments.is_empty:
        return 0.0
    return shapely.intersection(segments, v.buffer(tol, quad_segs=2)).length


# -- plain geometry used by the referee ------------------------------------------------------


def _triangles(poly: Polygon) -> list[np.ndarray]:
    tri = shapely.constrained_delaunay_triangles(poly)
    return [np.asarray(t.exterior.coords)[:3] for t in shapely.get_parts(tri)]


def minkowski_sum(a: Polygon, b: Polygon | Point) -> shapely.Geometry:
    """A (+) B for polygons (B may be a Point): union over triangle pairs of conv(t_a + t_b)."""
    if b.geom_type == "Point":
        return shapely.affinity.translate(a, b.x, b.y)
    parts = []
    for ta in _triangles(a):
        for tb in _triangles(b):
            parts.append(
                shapely.MultiPoint((ta[:, None, :] + tb[None, :, :]).reshape(-1, 2)).convex_hull
            )
    return shapely.union_all(parts)


def _ccw_coords(poly: Polygon) -> np.ndarray:
    return np.asarray(shapely.orient_polygons(poly, exterior_cw=False).exterior.coords)[:-1]


def overlap_segments(
    a_g: Polygon, a_h: Polygon, tol: float = 1e-9
) -> list[tuple[np.ndarray, np.ndarray, int]]:
    """Overlap segments of A at G with A at H (paper 5.1, point-sized G and H).

    Pairs of edges (counter-clockwise, so same direction = same outward normal)
    that are collinear and overlap; returns ``(start, end, edge_index_in_a_g)``
    for each overlapping piece, on A at G.
    """
    cg, ch = _ccw_coords(a_g), _ccw_coords(a_h)
    out = []
    for i in range(len(cg)):
        p0, p1 = cg[i], cg[(i + 1) % len(cg)]
        d = p1 - p0
        L = float(np.hypot(*d))
        u = d / L
        nrm = np.array([-u[1], u[0]])
        for j in range(len(ch)):
            q0, q1 = ch[j], ch[(j + 1) % len(ch)]
            e = q1 - q0
            le = float(np.hypot(*e))
            if np.hypot(*(e / le - u)) > 1e-9:
                continue  # not the same direction
            if abs(np.dot(q0 - p0, nrm)) > tol or abs(np.dot(q1 - p0, nrm)) > tol:
                continue  # not collinear
            s0, s1 = sorted((float(np.dot(q0 - p0, u)), float(np.dot(q1 - p0, u))))
            lo, hi = max(0.0, s0), min(L, s1)
            if hi - lo > tol:
                out.append((p0 + lo * u, p0 + hi * u, i))
    return out


def non_overlap_segments(a_g: Polygon, a_h: Polygon, tol: float = 1e-9) -> MultiLineString:
    """The boundary of A at G minus its overlap segments with A at H, as lines."""
    cg = _ccw_coords(a_g)
    ov = overlap_segments(a_g, a_h, tol)
    pieces = []
    for i in range(len(cg)):
        p0, p1 = cg[i], cg[(i + 1) % len(cg)]
        d = p1 - p0
        L = float(np.hypot(*d))
        u = d / L
        cuts = sorted(
            (float(np.dot(s - p0, u)), float(np.dot(e - p0, u))) for s, e, k in ov if k == i
        )
        t = 0.0
        for lo, hi in cuts:
            if lo > t + tol:
                pieces.append(LineString([p0 + t * u, p0 + lo * u]))
            t = max(t, hi)
        if L > t + tol:
            pieces.append(LineString([p0 + t * u, p1]))
    return MultiLineString(pieces)
