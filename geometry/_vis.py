"""Exact visibility polygons in a polygonal domain, by angular gaps.

The domain is a set of directed boundary segments with the free region on the
*left* of every segment (shapely exterior rings counter-clockwise, holes
clockwise).  Seen from a point ``q``, sort the directions to every domain vertex
(plus any extra directions the caller needs): between two consecutive such
directions -- a *gap* -- no vertex is crossed, so the first segment a ray meets
is the same for the whole gap.  One ray at the gap's middle finds it, and the
visibility polygon's boundary over that gap is the piece of that segment between
the gap's two bounding rays.  Every output vertex is therefore either a domain
vertex or the intersection of a ray through a vertex with a segment: the result
is exact up to floating point (no sampling, no epsilon-rays).

All work is vectorised over gaps x segments with numpy; no Python loop runs
per ray.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import shapely

TAU = 2.0 * np.pi

__all__ = ["Domain", "Gaps", "gaps_from", "polygon_from_gaps", "visibility_polygon"]


@dataclass(frozen=True)
class Domain:
    """Boundary segments of a free region (free side on the left of each segment).

    Attributes
    ----------
    seg : (E, 4) float array of ``x0, y0, x1, y1`` per directed segment.
    seg_ring : (E,) int ring index of each segment.
    seg_tag : (E,) int caller's tag of each segment (e.g. 0 environment, 1 target).
    vert : (V, 2) float array of ring vertices (each vertex once per ring).
    vert_prev, vert_next : (V, 2) neighbouring vertices along the ring.
    vert_ring : (V,) ring index of each vertex.
    reflex : (V,) bool, True where the free region's interior angle exceeds pi.
    scale : float, the diagonal of the domain's bounding box (tolerances are relative to it).
    """

    seg: np.ndarray
    seg_ring: np.ndarray
    seg_tag: np.ndarray
    vert: np.ndarray
    vert_prev: np.ndarray
    vert_next: np.ndarray
    vert_ring: np.ndarray
    reflex: np.ndarray
    scale: float

    @staticmethod
    def from_rings(rings: list[np.ndarray], tags: list[int]) -> Domain:
        """Build a domain from closed rings (without repeated closing vertex).

        Each ring must already be oriented with the free region on its left.
        """
        segs, sring, stag, verts, prevs, nexts, vring = [], [], [], [], [], [], []
        for r_i, (ring, tag) in enumerate(zip(rings, tags)):
            ring = np.asarray(ring, dtype=float)
            nxt = np.roll(ring, -1, axis=0)
            prv = np.roll(ring, 1, axis=0)
            segs.append(np.hstack([ring, nxt]))
            sring.append(np.full(len(ring), r_i))
            stag.append(np.full(len(ring), tag))
            verts.append(ring)
            prevs.append(prv)
            nexts.append(nxt)
            vring.append(np.full(len(ring), r_i))
        vert = np.vstack(verts)
        vprev = np.vstack(prevs)
        vnext = np.vstack(nexts)
        turn = _cross(vert - vprev, vnext - vert)
        lo = vert.min(axis=0)
        hi = vert.max(axis=0)
        return Domain(
            seg=np.vstack(segs),
            seg_ring=np.concatenate(sring),
            seg_tag=np.concatenate(stag),
            vert=vert,
            vert_prev=vprev,
            vert_next=vnext,
            vert_ring=np.concatenate(vring),
            reflex=turn < 0.0,
            scale=float(np.hypot(*(hi - lo))),
        )

    def with_ring(self, ring: np.ndarray, tag: int, tags: np.ndarray | None = None) -> Domain:
        """Return a copy with one more ring (e.g. the target as a hole).

        ``tags`` optionally gives a tag per segment of the new ring.
        """
        ring = np.asarray(ring, dtype=float)
        nxt = np.roll(ring, -1, axis=0)
        prv = np.roll(ring, 1, axis=0)
        r_i = int(self.seg_ring.max()) + 1 if len(self.seg_ring) else 0
        seg_tags = np.full(len(ring), tag) if tags is None else np.asarray(tags)
        turn = _cross(ring - prv, nxt - ring)
        return Domain(
            seg=np.vstack([self.seg, np.hstack([ring, nxt])]),
            seg_ring=np.concatenate([self.seg_ring, np.full(len(ring), r_i)]),
            seg_tag=np.concatenate([self.seg_tag, seg_tags]),
            vert=np.vstack([self.vert, ring]),
            vert_prev=np.vstack([self.vert_prev, prv]),
            vert_next=np.vstack([self.vert_next, nxt]),
            vert_ring=np.concatenate([self.vert_ring, np.full(len(ring), r_i)]),
            reflex=np.concatenate([self.reflex, turn < 0.0]),
            scale=self.scale,
        )


def domain_from_geometry(geom: shapely.Geometry, tag: int = 0) -> Domain:
    """Domain of a shapely Polygon/MultiPolygon (free region = its interior)."""
    geom = shapely.orient_polygons(geom, exterior_cw=False)
    rings: list[np.ndarray] = []
    for poly in getattr(geom, "geoms", [geom]):
        if poly.is_empty:
            continue
        for ring in [poly.exterior, *poly.interiors]:
            rings.append(_ring_coords(ring))
    return Domain.from_rings(rings, [tag] * len(rings))


def _ring_coords(ring: shapely.LinearRing) -> np.ndarray:
    c = np.asarray(ring.coords)[:-1, :2]
    # drop consecutive duplicates and collinear points are kept (harmless)
    keep = np.any(np.abs(c - np.roll(c, 1, axis=0)) > 0.0, axis=1)
    return c[keep]


@dataclass(frozen=True)
class Gaps:
    """Angular gaps around a viewpoint ``q``.

    ``lo[i] < hi[i]`` are the bounding directions (radians, increasing, ``hi`` may
    exceed ``lo[0] + 2 pi`` only for the wrapping gap); ``seg[i]`` the index of
    the first segment hit inside the gap, or -1 when the gap is blocked (points
    into the boundary at ``q``, or lies outside the requested sector);
    ``p0[i]``, ``p1[i]`` the visible boundary points on the rays ``lo[i]`` and
    ``hi[i]`` (equal to ``q`` for blocked gaps).
    """

    q: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    seg: np.ndarray
    p0: np.ndarray
    p1: np.ndarray

    @property
    def width(self) -> np.ndarray:
        return self.hi - self.lo


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def local_wedge(dom: Domain, q: np.ndarray) -> tuple[float, float] | None:
    """Free wedge ``(start, width)`` at ``q`` if ``q`` is a domain vertex, else None.

    The free directions at a boundary vertex run counter-clockwise from the
    direction of the next vertex to the direction of the previous one.
    """
    tol = 1e-12 * dom.scale
    hit = np.flatnonzero(np.abs(dom.vert - q).max(axis=1) <= tol)
    if len(hit) == 0:
        return None
    i = hit[0]
    a = np.arctan2(*(dom.vert_next[i] - q)[::-1])
    b = np.arctan2(*(dom.vert_prev[i] - q)[::-1])
    width = (b - a) % TAU
    if width == 0.0:
        width = TAU
    return float(a), float(width)


def gaps_from(
    dom: Domain,
    q: np.ndarray,
    *,
    sector: tuple[float, float] | None = None,
    extra: np.ndarray | None = None,
    wedge: tuple[float, float] | None | bool = True,
) -> Gaps:
    """Angular gaps of the visibility of ``q`` in ``dom``.

    Parameters
    ----------
    q : viewpoint (x, y), world frame.
    sector : optional ``(start, width)`` in radians; only directions inside it are
        resolved, the others are reported as blocked (``seg == -1``).
    extra : additional critical directions (radians) to split gaps at.
    wedge : ``True`` to detect whether ``q`` is a domain vertex and block the
        directions that point into the boundary there; an explicit
        ``(start, width)`` free wedge; or ``None``/``False`` for an interior point.
    """
    q = np.asarray(q, dtype=float)
    tol = 1e-12 * dom.scale
    if wedge is True:
        wedge = local_wedge(dom, q)
    elif wedge is False:
        wedge = None
    d = dom.vert - q
    far = np.abs(d).max(axis=1) > tol
    ang = [np.arctan2(d[far, 1], d[far, 0])]
    if extra is not None:
        ang.append(np.asarray(extra, dtype=float).ravel())
    if wedge is not None:
        ang.append(np.array([wedge[0], wedge[0] + wedge[1]]))
    if sector is not None:
        ang.append(np.array([sector[0], sector[0] + sector[1]]))
    ang = np.concatenate(ang) % TAU
    if sector is not None:
        rel = (ang - sector[0]) % TAU
        eps = 1e-13
        inside = (rel <= sector[1] + eps) | (rel >= TAU - eps)
        ang = ang[inside]
        base = sector[0] % TAU
        ang = np.sort(base + (ang - base) % TAU)
        # make the sector's end exact
        ang = np.unique(np.concatenate([[base], ang[ang <= base + sector[1]], [base + sector[1]]]))
        lo, hi = ang[:-1], ang[1:]
    else:
        ang = np.unique(ang)
        lo = ang
        hi = np.append(ang[1:], ang[0] + TAU)
    keep = (hi - lo) > 1e-13
    lo, hi = lo[keep], hi[keep]
    mid = 0.5 * (lo + hi)
    open_ = np.ones(len(mid), dtype=bool)
    if wedge is not None:
        rel = (mid - wedge[0]) % TAU
        open_ &= rel < wedge[1]
    seg = np.full(len(mid), -1, dtype=np.int64)
    if open_.any():
        seg[open_] = _first_hits(dom, q, mid[open_])
    p0 = np.broadcast_to(q, (len(mid), 2)).copy()
    p1 = p0.copy()
    ok = seg >= 0
    if ok.any():
        s = dom.seg[seg[ok]]
        p0[ok] = _ray_line(q, lo[ok], s)
        p1[ok] = _ray_line(q, hi[ok], s)
    return Gaps(q=q, lo=lo, hi=hi, seg=seg, p0=p0, p1=p1)


def _first_hits(dom: Domain, q: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """Index of the first segment hit by rays from ``q`` at angles ``phi``."""
    dx = np.cos(phi)[:, None]
    dy = np.sin(phi)[:, None]
    a = dom.seg[None, :, :2] - q
    ex = (dom.seg[:, 2] - dom.seg[:, 0])[None, :]
    ey = (dom.seg[:, 3] - dom.seg[:, 1])[None, :]
    den = dx * ey - dy * ex
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (a[..., 0] * ey - a[..., 1] * ex) / den
        s = (a[..., 0] * dy - a[..., 1] * dx) / den
    tmin = 1e-11 * dom.scale
    valid = (t > tmin) & (s >= -1e-12) & (s <= 1.0 + 1e-12)
    t = np.where(valid, t, np.inf)
    j = np.argmin(t, axis=1)
    if not np.all(np.isfinite(t[np.arange(len(j)), j])):
        raise RuntimeError("visibility ray escaped the domain: the boundary is not closed")
    return j


def _ray_line(q: np.ndarray, phi: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Points where rays from ``q`` at angles ``phi`` meet the lines of segments ``s``."""
    d = np.stack([np.cos(phi), np.sin(phi)], axis=1)
    a = s[:, :2] - q
    e = s[:, 2:] - s[:, :2]
    den = _cross(d, e)
    t = _cross(a, e) / den
    return q + d * t[:, None]


def polygon_from_gaps(g: Gaps, mask: np.ndarray | None = None) -> shapely.Polygon:
    """The star polygon swept by the gaps (those in ``mask``, all by default).

    Blocked or masked-out gaps contribute the viewpoint itself, so a masked
    result is a fan of triangles anchored at ``q``.
    """
    use = g.seg >= 0
    if mask is not None:
        use = use & mask
    if not use.any():
        return shapely.Polygon()
    p0 = np.where(use[:, None], g.p0, g.q)
    p1 = np.where(use[:, None], g.p1, g.q)
    pts = np.empty((2 * len(p0), 2))
    pts[0::2] = p0
    pts[1::2] = p1
    poly = shapely.Polygon(pts)
    if not poly.is_valid:
        poly = shapely.make_valid(poly)
        poly = shapely.union_all(shapely.get_parts(poly)[shapely.get_type_id(shapely.get_parts(poly)) >= 3])
    return poly


def visibility_polygon(dom: Domain, q: np.ndarray) -> shapely.Polygon:
    """Visibility polygon V(q) of a point in the domain (world frame)."""
    return polygon_from_gaps(gaps_from(dom, q))
