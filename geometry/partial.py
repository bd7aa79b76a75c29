"""Partial visibility (paper 3.2.1) with aim uncertainty (paper section 4).

A placement p partially sees the target when some point of the target's
boundary is visible.  Sweep the directions in which p sees a wanted part P of
the boundary: an extreme direction of that set either hits an endpoint of P
(a target vertex, or the end of a wanted piece) or grazes a vertex v of the
domain (a convex obstacle corner or a convex target corner: a *reflex* vertex
of the free space around the target) and then runs on to P.  So the region is
the union of *visibility triangles* anchored at

* every endpoint a of P: the points that see a from the front of a wanted edge;
* every reflex vertex v: the points p that see v such that the ray from p
  through v, continued past v, hits P first.

Both families are fans of exact triangles from :mod:`geometry._vis`: the second
is the visibility of v restricted to the directions opposite to those in which
v sees P.  Grouping adjacent triangles of one anchor that end on the same
polygon gives the paper's *visibility polygons*; with aim uncertainty
``eps_aim`` those whose apex angle is below ``eps_aim`` are dropped.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import shapely

from ._common import check_eps, polygonal, scene_domain, shrink_for_position, target_spec
from ._vis import TAU, Domain, Gaps, gaps_from

if TYPE_CHECKING:  # pragma: no cover
    from .scene import Scene

__all__ = ["partial_region", "weak_visibility"]

#: Segment tags inside the visibility domain.
ENV, WANTED, UNWANTED = 0, 1, 2

SWEEP_TOPIC = (
    "partial visibility of a target moving through a region (paper 3.2.2-3.2.3, swept shadows; "
    "issue 'Partial visibility of a translating target and confusability for polygonal G and H')"
)


def partial_region(
    scene: Scene,
    *,
    target_at: tuple[float, float, float] | None = None,
    target_in: str | shapely.Geometry | None = None,
    theta: float | None = 0.0,
    eps_pos: float = 0.0,
    eps_aim: float = 0.0,
) -> shapely.Geometry:
    """Sensor placements from which some point of the target is visible.

    Parameters
    ----------
    target_at : ``(x, y, theta)`` of a stationary target (world frame, radians).
    target_in : a region the target moves through -- not implemented yet: raises
        ``NotImplementedError`` (swept shadows, paper 3.2.2-3.2.3).
    eps_pos : worst-case placement error (scene units): shadows grown by the disc.
    eps_aim : worst-case aim error (radians): visibility polygons whose apex angle
        at their anchor vertex is below ``eps_aim`` are dropped (paper section 4).

    Returns
    -------
    A shapely Polygon/MultiPolygon (possibly empty) in world coordinates: the
    placements inside the bounds, outside obstacles and outside the target.
    """
    eps_pos = check_eps("eps_pos", eps_pos)
    eps_aim = check_eps("eps_aim", eps_aim)
    if target_in is not None:
        raise NotImplementedError(f"partial_region(target_in=...) is not implemented yet: {SWEEP_TOPIC}")
    if target_at is None:
        raise ValueError("give target_at=(x, y, theta)")
    spec = target_spec(scene, target_at, None, theta)
    ring = _hole_ring(spec.area)
    region = weak_visibility(scene_domain(scene), ring, np.ones(len(ring), dtype=bool), eps_aim)
    region = polygonal(shapely.difference(region, spec.area))
    if eps_pos > 0:
        allowed = shapely.difference(scene.free_space, spec.area)
        region = shrink_for_position(region, allowed, eps_pos)
    return region


def _hole_ring(poly: shapely.Polygon) -> np.ndarray:
    """Exterior of ``poly`` clockwise (free space on the left), no closing vertex."""
    c = np.asarray(shapely.orient_polygons(poly, exterior_cw=True).exterior.coords)[:-1, :2]
    return c


def weak_visibility(env: Domain, ring: np.ndarray, wanted: np.ndarray, eps_aim: float = 0.0) -> shapely.Geometry:
    """Placements that see some wanted piece of a target boundary.

    Parameters
    ----------
    env : the free space as a visibility domain (without the target).
    ring : (m, 2) target boundary, clockwise (it becomes a hole of the domain
        and occludes); pieces to be seen must start and end at ring vertices
        (insert the cut points first).
    wanted : (m,) bool, True where segment ``ring[i] -> ring[i+1]`` is wanted.
    eps_aim : drop anchor fans narrower than this (radians).

    Returns
    -------
    Union of the visibility triangles (shapely geometry, world frame), not yet
    clipped against the target itself.
    """
    m = len(ring)
    dom = env.with_ring(ring, UNWANTED, np.where(wanted, WANTED, UNWANTED))
    fans: list[shapely.Geometry] = []
    # anchors on the target: endpoints of wanted pieces
    edge = np.roll(ring, -1, axis=0) - ring
    for i in range(m):
        inc = [j for j in (i, (i - 1) % m) if wanted[j]]
        if not inc:
            continue
        dirs = edge[inc]
        extra = np.arctan2(dirs[:, 1], dirs[:, 0]) + np.pi
        g = gaps_from(dom, ring[i], extra=np.concatenate([extra, extra - np.pi]), wedge=True)
        mid = 0.5 * (g.lo + g.hi)
        d = np.stack([np.cos(mid), np.sin(mid)], axis=1)
        front = ((dirs[None, :, 0] * d[:, None, 1] - dirs[None, :, 1] * d[:, None, 0]) > 0).any(axis=1)
        fans += _fans(g, front & (g.seg >= 0), dom, eps_aim)
    # grazing anchors: reflex vertices of the free space around the target
    centre = ring.mean(axis=0)
    for v in dom.vert[dom.reflex]:
        rel = np.arctan2(ring[:, 1] - v[1], ring[:, 0] - v[0])
        base = np.arctan2(centre[1] - v[1], centre[0] - v[0])
        rel = (rel - base + np.pi) % TAU - np.pi
        near = np.abs(ring - v).max(axis=1) <= 1e-12 * dom.scale
        rel = rel[~near]
        lo, hi = rel.min(), rel.max()
        if hi - lo <= 1e-12:
            continue
        g = gaps_from(dom, v, sector=(base + lo, hi - lo), wedge=True)
        sees = (g.seg >= 0) & (dom.seg_tag[np.maximum(g.seg, 0)] == WANTED)
        for run in _runs(g, sees):
            back = gaps_from(dom, v, sector=(g.lo[run[0]] + np.pi, _width(g, run)), wedge=True)
            fans += _fans(back, back.seg >= 0, dom, eps_aim)
    if not fans:
        return shapely.Polygon()
    return shapely.union_all(fans)


def _runs(g: Gaps, mask: np.ndarray) -> list[np.ndarray]:
    """Maximal runs of adjacent gaps where ``mask`` holds, as index arrays in
    angular order (a run may wrap through angle 0 when the gaps close a circle)."""
    idx = np.flatnonzero(mask)
    if len(idx) == 0:
        return []
    adjacent = np.abs(g.lo[idx[1:]] - g.hi[idx[:-1]]) <= 1e-12
    parts = np.split(idx, np.flatnonzero(~adjacent) + 1)
    closed = abs(g.hi[-1] - g.lo[0] - TAU) <= 1e-12
    if len(parts) > 1 and closed and mask[0] and mask[-1]:
        parts[0] = np.concatenate([parts.pop(), parts[0]])
    return parts


def _width(g: Gaps, run: np.ndarray) -> float:
    return float((g.hi[run[-1]] - g.lo[run[0]]) % TAU or TAU)


def _fans(g: Gaps, mask: np.ndarray, dom: Domain, eps_aim: float) -> list[shapely.Geometry]:
    """Visibility polygons anchored at ``g.q``: runs of adjacent gaps in ``mask``
    that end on the same polygon (ring), as shapely Polygons; runs whose apex
    angle is below ``eps_aim`` are dropped."""
    ring_of = np.where(g.seg >= 0, dom.seg_ring[np.maximum(g.seg, 0)], -1)
    out: list[shapely.Geometry] = []
    for run in _runs(g, mask):
        r = ring_of[run]
        for piece in np.split(run, np.flatnonzero(r[1:] != r[:-1]) + 1):
            if eps_aim > 0 and _width(g, piece) < eps_aim:
                continue
            pts = np.empty((2 * len(piece) + 1, 2))
            pts[0] = g.q
            pts[1::2] = g.p0[piece]
            pts[2::2] = g.p1[piece]
            out.append(_clean_polygon(pts, 1e-10 * dom.scale))
    return out


def _clean_polygon(pts: np.ndarray, tol: float) -> shapely.Geometry:
    """Polygon through ``pts`` without near-duplicate consecutive points; float
    noise that still makes it invalid is repaired (polygonal parts kept)."""
    step = np.abs(np.diff(pts, axis=0, append=pts[:1])).max(axis=1)
    pts = pts[step > tol]
    if len(pts) < 3:
        return shapely.Polygon()
    poly = shapely.Polygon(pts)
    if not poly.is_valid:
        poly = polygonal(shapely.make_valid(poly))
    return poly
