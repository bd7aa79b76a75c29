"""Swept partial visibility of a target that is not star-shaped (issue 25).

The sweep of :mod:`geometry.sweep` runs over the boundary of the region G only, which
is enough when the target A is star-shaped with respect to a point of its kernel
(docs/DESIGN.md, "Boundary traversal suffices").  For a general simple polygon A this
module replaces A by its convex hull, which *is* star-shaped:

**Whole outline wanted (``partial_region(target_in=...)``): exact.**  No obstacle
meets K = CH(A (+) G) (the paper's assumption, checked by :class:`~geometry.Scene`).
A placement p outside K sees into K through windows that do not depend on q, and a ray
that enters K meets nothing but the target inside K.  The directions in which a ray
from p hits the connected set A_q form one angular interval, and its two ends are
tangent directions to A_q, which are the tangent directions to CH(A_q): the interval
is that of CH(A_q).  So p sees some of A_q (in a set of directions of positive
measure) iff it sees some of CH(A_q).  A placement inside K and outside A_q sees the
nearest point of A_q (nothing blocks inside K), and so sees the hull too, or lies in
it.  Hence the shadows S(q) of A_q and of CH(A_q) agree outside CH(A_q), and the
placements in CH(A_q) - A_q (inside K) are never in the shadow of A_q: the answer
``free - (A (+) G) - U_q S_hull(q)`` is the exact region.  (With ``eps_aim > 0`` the
dropped visibility polygons are those of the hull, whose anchors are the hull's
vertices: the aim model of paper section 4 applied to what the sensor can see of the
target from outside K.)

**Part of the outline wanted (paper 5.2 and the mixed G/H case): certified inner
region.**  There the first point hit inside a pocket of A may be wanted or not, which
the hull does not know.  The hull ring is kept with its vertices at the vertices of A
on the hull's boundary (in A's order, which is the hull's order for a simple polygon);
a hull edge that is an edge of A keeps that edge's strip (its wanted pieces are A's),
a *lid* (a hull edge that bridges a pocket) is wholly unwanted.  A ray from p outside
CH(A_q) that first meets the hull at a wanted point x of an edge of A meets A first at
x, so "p sees a wanted point of the hull target" implies "p sees a wanted point of
A_q"; the converse fails only for rays through a lid.  Placements inside CH(A) (+) G
(the pockets swept through G) are dropped: there the hull target does not model what
is seen.  So the returned region is contained in the exact one (up to the sweep's
``tol``, which ``conservative=True`` covers as for star-shaped targets).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely

from ._common import minkowski_sum
from ._shapes import cross as _cross
from .sweep import star_center

__all__ = ["HullTarget", "hull_target", "is_star_shaped", "pocket_area"]


@dataclass(frozen=True)
class HullTarget:
    """The convex-hull stand-in of a non-star-shaped target (see the module docstring).

    Attributes
    ----------
    ring : (k, 2) counter-clockwise hull ring, reference point at the origin (the
        target's frame, scene units); its vertices are vertices of the target.
    strips : per hull edge, the strip of unwanted places (shapely geometry), or
        ``None`` when the whole outline is wanted.
    exact : True when the swept region of the hull equals that of the target (whole
        outline wanted); False when it is a certified inner region.
    """

    ring: np.ndarray
    strips: list[shapely.Geometry] | None
    exact: bool


def is_star_shaped(ring: np.ndarray) -> bool:
    """True when the counter-clockwise polygon ``ring`` has a kernel of positive area
    (the test of :func:`geometry.sweep.star_center`, which the sweep needs)."""
    return star_center(np.asarray(ring, dtype=float)) is not None


def hull_target(
    target: np.ndarray,
    strips: list[shapely.Geometry] | None,
    region: shapely.Geometry,
) -> HullTarget:
    """The hull stand-in of ``target`` ((m, 2) counter-clockwise ring, reference point at
    the origin) translating through ``region`` (Point or Polygon, same frame as the
    strips).  ``strips``: per edge of ``target`` the unwanted strip (paper 5.2), or
    ``None`` for the whole outline.  See the module docstring for what is exact."""
    target = np.asarray(target, dtype=float)
    m = len(target)
    hull = shapely.convex_hull(shapely.multipoints(target))
    scale = float(np.ptp(target, axis=0).max())
    d = shapely.distance(hull.exterior, shapely.points(target))
    on = np.flatnonzero(d <= 1e-12 * scale)
    if strips is None:
        # the whole hull is wanted: its own vertices, without collinear ones
        ring = np.asarray(shapely.orient_polygons(hull, exterior_cw=False).exterior.coords)[:-1]
        return HullTarget(ring, None, True)
    ring = target[on]  # collinear ones kept: every hull edge is one edge of A or a lid
    lid = _lid_strip(target, region)
    out: list[shapely.Geometry] = []
    for k in range(len(on)):
        i, j = int(on[k]), int(on[(k + 1) % len(on)])
        out.append(strips[i] if j == (i + 1) % m else lid)
    if _cross(ring - ring.mean(axis=0), np.roll(ring, -1, axis=0) - ring).sum() <= 0:
        raise ValueError("hull_target: the target's hull vertices are not counter-clockwise")
    return HullTarget(ring, out, False)


def _lid_strip(target: np.ndarray, region: shapely.Geometry) -> shapely.Geometry:
    """A box that holds every lid of the target at every reference point of ``region``
    with room to spare: its edges never cut a lid, so a lid is unwanted throughout."""
    x0, y0, x1, y1 = shapely.bounds(region)
    tx0, ty0 = target.min(axis=0)
    tx1, ty1 = target.max(axis=0)
    size = max(x1 - x0 + tx1 - tx0, y1 - y0 + ty1 - ty0)
    pad = size + 1.0 * max(size, 1e-300)
    return shapely.box(x0 + tx0 - pad, y0 + ty0 - pad, x1 + tx1 + pad, y1 + ty1 + pad)


def pocket_area(target: np.ndarray, region: shapely.Geometry) -> shapely.Geometry:
    """CH(A) (+) region (scene units, the region's frame): the placements that the
    certified (strips) answer drops, where the hull target does not model what is seen."""
    hull = shapely.convex_hull(shapely.multipoints(np.asarray(target, dtype=float)))
    return minkowski_sum(hull, region)
