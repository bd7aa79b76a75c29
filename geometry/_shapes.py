"""Shared low-level helpers of the geometry package (no imports from it): the one
cross product, the one counter-clockwise ring, and the one rule for keeping the areal
part of a shapely result.  Every module uses these (issue 10: three ``_polygonal``
variants with different rules had grown apart)."""

from __future__ import annotations

import numpy as np
import shapely

__all__ = ["areal", "ccw_ring", "cross", "polygonal"]

#: A part whose area is below this times its squared perimeter is float noise (a
#: 1e-16-wide strip along an edge left by a boolean operation).
SLIVER = 1e-10


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
