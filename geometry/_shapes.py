"""Shared low-level helpers of the geometry package (no imports from it): the one
cross product, the one counter-clockwise ring, and the one rule for keeping the areal
part of a shapely result.  Every module uses these (issue 10: three ``_polygonal``
variants with different rules had grown apart)."""

from __future__ import annotations

import math

import numpy as np
import shapely
import shapely.errors

__all__ = [
    "DISC_SIDES",
    "areal",
    "ccw_ring",
    "cross",
    "disc_sum",
    "polygonal",
    "snap_grid",
    "union_all",
]

#: Sides of the polygon that stands for a disc (circumscribed: it contains the disc and its
#: boundary lies within R (1/cos(pi/DISC_SIDES) - 1) = 0.0012 R of the circle).
DISC_SIDES = 64

#: A part whose area is below this times its squared perimeter is float noise (a
#: 1e-16-wide strip along an edge left by a boolean operation).
SLIVER = 1e-10


#: Grid (relative to the scale of the geometry) of the snap-rounded fallback of
#: :func:`union_all`: far below the tolerance ``TOL_REL = 1e-9`` of the answers.
SNAP_REL = 1e-13


def snap_grid(pts: np.ndarray) -> float:
    """The snap-rounding grid of a scene whose vertices are ``pts``: ``SNAP_REL`` times the
    diameter of their box, but never below 2**-50 of the largest coordinate (so that
    coordinate / grid stays exact in a double, e.g. at UTM offsets)."""
    p = np.asarray(pts, dtype=float)
    lo, hi = p.min(axis=0), p.max(axis=0)
    diam = float(np.hypot(*(hi - lo)))
    big = float(np.abs(p).max())
    return max(SNAP_REL * diam, math.ldexp(big, -50), 1e-300)


def snapped(op: object, a: shapely.Geometry, b: shapely.Geometry, grid: float) -> shapely.Geometry:
    """``op(a, b)`` (``shapely.intersection``, ``shapely.difference`` or ``shapely.union``) of
    the areal parts,
    snap-rounded on ``grid`` (docs/DESIGN.md, "Contacts").  Snap-rounding can still raise on
    an input GEOS finds invalid ("Ring edge missing", contact fuzz seed 1672): then the
    floating overlay, then the floating overlay of the repaired inputs."""
    a, b = areal(a), areal(b)
    try:
        return op(a, b, grid_size=grid)  # type: ignore[operator]
    except shapely.errors.GEOSException:
        pass
    try:
        return op(a, b)  # type: ignore[operator]
    except shapely.errors.GEOSException:
        return op(areal(shapely.make_valid(a)), areal(shapely.make_valid(b)))  # type: ignore[operator]


def union_all(
    geoms: object, scale: float = 1.0, grid_size: float | None = None
) -> shapely.Geometry:
    """``shapely.union_all`` that does not raise on near-coincident edges.

    GEOS's floating overlay can fail ("TopologyException: side location conflict") on
    valid input whose edges cross at angles below the doubles' resolution (issue 26
    item 8: eleven valid visibility fans anchored at one contact vertex).  The fallback
    is GEOS's snap-rounding overlay (OverlayNG with a fixed grid), which is robust by
    construction; its grid ``SNAP_REL * scale`` moves every vertex by at most half of
    it, far below the answers' tolerance.  ``scale``: the geometry's size (the local
    frame's scenes have scale about 1).  With ``grid_size`` the snap-rounding overlay is
    used directly."""
    if grid_size is not None:
        try:
            return shapely.union_all(geoms, grid_size=grid_size)
        except shapely.errors.GEOSException:  # "Ring edge missing" (as in :func:`snapped`)
            try:
                return shapely.union_all(geoms)
            except shapely.errors.GEOSException:
                return shapely.union_all(shapely.make_valid(np.asarray(geoms, dtype=object)))
    try:
        return shapely.union_all(geoms)
    except shapely.errors.GEOSException:
        return shapely.union_all(geoms, grid_size=SNAP_REL * scale)


def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """2-D cross product ``a x b`` over the last axis (broadcasting)."""
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def ccw_ring(poly: shapely.Geometry, *, clockwise: bool = False) -> np.ndarray:
    """Exterior ring of a Polygon as an (n, 2) array without the closing vertex,
    counter-clockwise (``clockwise=True``: clockwise, e.g. the target as a hole with the
    free space on its left)."""
    o = shapely.orient_polygons(poly, exterior_cw=clockwise)
    return np.asarray(o.exterior.coords)[:-1, :2]


def areal(g: shapely.Geometry) -> shapely.Geometry:
    """The areal parts of a shapely result (points and lines dropped) as one Polygon
    or MultiPolygon, unioned only when there are several; empty -> ``Polygon()``."""
    return polygonal(g, slivers=False)


def polygonal(g: shapely.Geometry, *, slivers: bool = True) -> shapely.Geometry:
    """Keep the areal parts of a boolean result, dropping points and lines and, with
    ``slivers=True``, parts whose area is below ``SLIVER`` times their squared perimeter
    (float noise).  An answer with nothing left is an empty Polygon; several parts are
    returned as a MultiPolygon (they come from one overlay, so they do not overlap)."""
    if g is None or g.is_empty:
        return shapely.Polygon()
    if g.geom_type in ("Polygon", "MultiPolygon") and not slivers:
        return g
    parts = shapely.get_parts(g)
    parts = parts[np.isin(shapely.get_type_id(parts), (3, 6))]
    if len(parts) and (shapely.get_type_id(parts) == 6).any():
        parts = shapely.get_parts(parts)
    if slivers and len(parts):
        parts = parts[shapely.area(parts) > SLIVER * shapely.length(parts) ** 2]
    if len(parts) == 0:
        return shapely.Polygon()
    if len(parts) == 1:
        return parts[0]
    return shapely.multipolygons(parts)


def disc_sum(g: shapely.Geometry, radius: float) -> shapely.Geometry:
    """A polygon containing the Minkowski sum ``g (+) disc(radius)`` and within
    ``0.0012 radius`` of it: ``g`` united with, for every boundary segment, the convex
    hull of two regular ``DISC_SIDES``-gons circumscribing the discs at its ends.

    Unlike ``shapely.buffer`` (GEOS simplifies the input by up to 1 % of the distance and
    places its arc vertices *on* the circle, so its chords cut into the disc: 0.1 % of the
    radius was measured), every point within ``radius`` of ``g`` is inside the result."""
    if radius <= 0 or g.is_empty:
        return g
    k = np.arange(DISC_SIDES)
    ang = 2.0 * np.pi * (k + 0.5) / DISC_SIDES
    disc = (radius / np.cos(np.pi / DISC_SIDES)) * np.column_stack([np.cos(ang), np.sin(ang)])
    segs = []
    for part in shapely.get_parts(g):
        if part.geom_type == "Polygon":
            rings = [part.exterior, *part.interiors]
        elif part.geom_type in ("LineString", "LinearRing"):
            rings = [part]
        else:  # points
            rings = []
            for c in shapely.get_coordinates(part):
                segs.append(np.stack([c, c]))
        for ring in rings:
            c = np.asarray(ring.coords)[:, :2]
            if len(c) == 1:
                c = np.vstack([c, c])
            segs.extend(np.stack([c[:-1], c[1:]], axis=1))
    if not segs:
        return g
    ends = np.asarray(segs)  # (S, 2, 2)
    pts = (ends[:, :, None, :] + disc[None, None, :, :]).reshape(len(ends), 2 * DISC_SIDES, 2)
    hulls = shapely.convex_hull(shapely.multipoints(pts))
    pieces = [hulls]
    if g.geom_type in ("Polygon", "MultiPolygon"):
        pieces.append(np.asarray([g], dtype=object))
    return areal(shapely.union_all(np.concatenate(pieces)))
