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

from . import _libm
from . import visindex as _visindex
from ._domain import TAU, Domain, domain_from_geometry
from ._shapes import cross


class RayEscapeError(RuntimeError):
    """A visibility ray from a viewpoint well inside the domain met no boundary segment:
    the domain's boundary is not closed (a bug in the caller's domain, never bad input)."""


__all__ = [
    "Domain",
    "Gaps",
    "RingSet",
    "domain_from_geometry",
    "gaps_from",
    "gaps_many",
    "gaps_many_rings",
    "polygon_from_gaps",
    "visibility_polygon",
]


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

    def part(self, a: int, b: int) -> Gaps:
        """Gaps ``a:b`` of a flat result of one viewpoint (see :func:`gaps_many`)."""
        return Gaps(
            q=self.q[a],
            lo=self.lo[a:b],
            hi=self.hi[a:b],
            seg=self.seg[a:b],
            p0=self.p0[a:b],
            p1=self.p1[a:b],
        )

    q: np.ndarray
    lo: np.ndarray
    hi: np.ndarray
    seg: np.ndarray
    p0: np.ndarray
    p1: np.ndarray

    @property
    def width(self) -> np.ndarray:
        return self.hi - self.lo


_cross = cross  # the package's one cross product (geometry._shapes)


def gaps_from(
    dom: Domain,
    q: np.ndarray,
    *,
    sector: tuple[float, float] | None = None,
    extra: np.ndarray | None = None,
) -> Gaps:
    """Angular gaps of the visibility of ``q`` in ``dom``.

    Parameters
    ----------
    q : viewpoint (x, y), world frame.  It may lie on the boundary: directions that
        enter an obstacle right at ``q`` are blocked (``seg == -1``).
    sector : optional ``(start, width)`` in radians; only directions inside it are
        resolved (the gaps cover exactly the sector).
    extra : additional critical directions (radians) to split gaps at.
    """
    q = np.asarray(q, dtype=float)[None, :]
    ex = None if extra is None else np.asarray(extra, dtype=float).reshape(1, -1)
    sec = None if sector is None else np.asarray([sector], dtype=float)
    return gaps_many(dom, q, sectors=sec, extra=ex)[0]


def _blocking(dom: Domain, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Local obstruction at viewpoints on the boundary: for each of the (n, 2) points,
    the free wedges ``(start, width)`` of up to two domain vertices it coincides with
    (NaN rows when none) and the direction of a segment whose interior contains it
    (NaN when none).  Directions outside a wedge, or to the right of such a segment,
    enter an obstacle at once."""
    if _visindex.available():
        return _visindex.blocking(dom, q)
    tol = 1e-12 * dom.scale
    n = len(q)
    near = np.abs(dom.vert[None, :, :] - q[:, None, :]).max(axis=2) <= tol
    w1 = np.full((n, 2), np.nan)
    w2 = np.full((n, 2), np.nan)
    rows, cols = np.nonzero(near)
    if len(rows):
        wedge = dom.vert_wedge
        first = np.concatenate([[True], rows[1:] != rows[:-1]])
        w1[rows[first]] = wedge[cols[first]]
        second = ~first & np.concatenate([[False], first[:-1]])
        w2[rows[second]] = wedge[cols[second]]
    e = dom.seg[:, 2:] - dom.seg[:, :2]
    L = np.hypot(e[:, 0], e[:, 1])
    a = q[:, None, :] - dom.seg[None, :, :2]
    dist = np.abs(e[None, :, 0] * a[..., 1] - e[None, :, 1] * a[..., 0]) / np.maximum(L, 1e-300)
    t = (a[..., 0] * e[None, :, 0] + a[..., 1] * e[None, :, 1]) / np.maximum(L * L, 1e-300)
    on = (dist <= tol) & (t * L > tol) & ((1 - t) * L > tol)
    along = np.full((n, 2), np.nan)
    r2, c2 = np.nonzero(on)
    along[r2] = e[c2]
    return w1, w2, along


def _sector_bounds(sectors: np.ndarray | None, n: int) -> tuple[np.ndarray, np.ndarray]:
    """``start, width`` (n,) radians of the sectors of :func:`gaps_many` (a NaN row, or
    no ``sectors``, is the full circle ``(0, 2 pi)``; widths capped at 2 pi)."""
    start = np.zeros(n)
    width = np.full(n, TAU)
    if sectors is not None:
        has = ~np.isnan(sectors[:, 0])
        start[has] = sectors[has, 0]
        width[has] = np.minimum(sectors[has, 1], TAU)
    return start, width


def _blocking_crit(w1: np.ndarray, w2: np.ndarray, along: np.ndarray) -> np.ndarray:
    """(n, 6) critical directions (radians, NaN where none) of the local obstruction of
    :func:`_blocking`: the sides of both wedges and both directions along the segment."""
    return np.stack(
        [
            w1[:, 0],
            w1[:, 0] + w1[:, 1],
            w2[:, 0],
            w2[:, 0] + w2[:, 1],
            _libm.atan2(along[:, 1], along[:, 0]),
            _libm.atan2(-along[:, 1], -along[:, 0]),
        ],
        axis=1,
    )


def _unblocked(
    mid: np.ndarray, owner: np.ndarray, w1: np.ndarray, w2: np.ndarray, along: np.ndarray
) -> np.ndarray:
    """True for the gaps whose middle direction ``mid`` (radians) leaves viewpoint
    ``owner`` into free space: inside both wedges of :func:`_blocking` (where present)
    and not to the right of the segment the viewpoint lies on."""
    open_ = np.ones(len(mid), dtype=bool)
    # only the gaps of viewpoints with a wedge (or a segment) are tested: the others are
    # open whatever the test says (the sine and cosine of every gap were most of the time)
    for w in (w1, w2):
        w0 = w[owner, 0]
        k = np.flatnonzero(~np.isnan(w0))
        if len(k):
            open_[k] &= ((mid[k] - w0[k]) % TAU) < w[owner[k], 1]
    ax = along[owner, 0]
    k = np.flatnonzero(~np.isnan(ax))
    if len(k):
        m = mid[k]
        open_[k] &= ax[k] * _libm.sin(m) - along[owner[k], 1] * _libm.cos(m) >= 0
    return open_


def gaps_many(
    dom: Domain,
    q: np.ndarray,
    *,
    sectors: np.ndarray | None = None,
    extra: np.ndarray | None = None,
    flat: bool = False,
    interior: bool = False,
    ends: bool = True,
) -> list[Gaps] | tuple[Gaps, np.ndarray]:
    """:func:`gaps_from` for many viewpoints at once (one vectorised ray cast).

    ``q`` is (n, 2); ``sectors`` is an (n, 2) array of ``(start, width)`` (a NaN
    row means the full circle); ``extra`` is (n, k) extra critical directions (NaN
    entries ignored).

    ``interior=True`` promises that no viewpoint lies on the boundary (it skips
    the local-obstruction test).  ``ends=False``: the caller needs no boundary points,
    ``p0`` and ``p1`` are NaN (the ray-segment intersections are not computed).

    Returns one :class:`Gaps` per viewpoint, or with ``flat=True`` all gaps in
    one :class:`Gaps` (``q`` then holds one row per gap) plus the (n+1,) offsets
    of each viewpoint's gaps.
    """
    q = np.asarray(q, dtype=float).reshape(-1, 2)
    n = len(q)
    tol = 1e-12 * dom.scale
    start, width = _sector_bounds(sectors, n)
    if interior:
        w1 = w2 = along = np.full((n, 2), np.nan)
    else:
        w1, w2, along = _blocking(dom, q)
    cols = [] if extra is None else [extra]
    cols.append(_blocking_crit(w1, w2, along))
    crit = np.concatenate(cols, axis=1)
    if _visindex.available():
        owner, lo, hi = _visindex.sorted_gaps(q, start, width, dom.vert, crit, tol, interior, dom)
    else:
        owner, lo, hi = _sorted_gaps(q, start, width, dom.vert, crit, tol, interior)
    mid = 0.5 * (lo + hi)
    # an interior viewpoint has no blocking wedge: every gap is open (the test's NaN rows)
    open_ = np.ones(len(mid), dtype=bool) if interior else _unblocked(mid, owner, w1, w2, along)
    qo = q[owner]
    seg = np.full(len(mid), -1, dtype=np.int64)
    idx = np.flatnonzero(open_)
    for c in range(0, len(idx), 2048):
        part = idx[c : c + 2048]
        seg[part] = _first_hits(dom, qo[part], mid[part])
    if not ends:
        p0 = p1 = np.full_like(qo, np.nan)
    else:
        p0 = qo.copy()
        p1 = qo.copy()
    ok = seg >= 0
    if ends and ok.any():
        sg = dom.seg[seg[ok]]
        p0[ok] = _ray_line(qo[ok], lo[ok], sg)
        p1[ok] = _ray_line(qo[ok], hi[ok], sg)
    if flat:
        return Gaps(q=qo, lo=lo, hi=hi, seg=seg, p0=p0, p1=p1), np.searchsorted(
            owner, np.arange(n + 1)
        )
    cuts = np.searchsorted(owner, np.arange(1, n))
    return [
        Gaps(q=q[i], lo=l_, hi=h_, seg=s_, p0=a_, p1=b_)
        for i, (l_, h_, s_, a_, b_) in enumerate(
            zip(*(np.split(x, cuts) for x in (lo, hi, seg, p0, p1)), strict=False)
        )
    ]


def _sorted_gaps(
    q: np.ndarray,
    start: np.ndarray,
    width: np.ndarray,
    vert: np.ndarray,
    crit: np.ndarray,
    tol: float,
    interior: bool,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Gaps of every viewpoint ``q[i]``: the directions to all vertices (those within
    ``tol`` of ``q[i]`` dropped unless ``interior``) and the critical directions
    ``crit[i]`` (NaN ignored), relative to ``start[i]``, inside ``(0, width[i])``,
    sorted; consecutive ones more than 1e-13 apart bound a gap.  Returns ``owner, lo,
    hi`` (flat, radians).  :func:`geometry.visindex.sorted_gaps` is the compiled twin."""
    n = len(q)
    d = vert[None, :, :] - q[:, None, :]
    a = _libm.atan2(d[..., 1], d[..., 0])
    if not interior:
        a = np.where(np.abs(d).max(axis=2) > tol, a, np.nan)
    ang = np.concatenate([a, crit], axis=1)
    rel = (ang - start[:, None]) % TAU
    rel = np.where(np.isnan(rel) | (rel >= width[:, None]) | (rel <= 0.0), np.inf, rel)
    rel = np.sort(np.concatenate([np.zeros((n, 1)), rel, width[:, None]], axis=1), axis=1)
    lo_r, hi_r = rel[:, :-1], rel[:, 1:]
    with np.errstate(invalid="ignore"):
        good = np.isfinite(hi_r) & (hi_r - lo_r > 1e-13)
    owner, col = np.nonzero(good)
    return owner, start[owner] + lo_r[owner, col], start[owner] + hi_r[owner, col]


def _first_hits(dom: Domain, q: np.ndarray, phi: np.ndarray, *, brute: bool = False) -> np.ndarray:
    """Index of the first segment hit by rays from ``q`` (one point or one per
    ray) at angles ``phi``.

    With ray ``q + t d`` and segment ``a + s e``: ``den = d x e``,
    ``t = ((a - q) x e) / den``, ``s = ((a - q) x d) / den``; each numerator is a
    small matrix product over (rays x 3) and (3 x segments).

    With numba installed (and ``brute`` False) the per-domain grid of
    :mod:`geometry.visindex` runs the same hit test on the segments along each ray
    only; the rare rays it finds no hit for go to the brute force below.
    """
    if not brute and _visindex.available():
        j = _visindex.first_hits(dom, q, phi)
        lost = j < 0
        if lost.any():
            qb = np.broadcast_to(q, (len(phi), 2))
            j[lost] = _first_hits(dom, qb[lost], phi[lost], brute=True)
        return j
    q = np.broadcast_to(q, (len(phi), 2))
    dx, dy = _libm.cos(phi), _libm.sin(phi)
    x0, y0 = dom.seg[:, 0], dom.seg[:, 1]
    ex, ey = dom.seg[:, 2] - x0, dom.seg[:, 3] - y0
    ones = np.ones_like(dx)
    den = np.stack([dx, dy], axis=1) @ np.stack([ey, -ex])
    t_num = np.stack([ones, -q[:, 0], q[:, 1]], axis=1) @ np.stack([x0 * ey - y0 * ex, ey, ex])
    s_num = np.stack([dy, -dx, q[:, 1] * dx - q[:, 0] * dy], axis=1) @ np.stack(
        [x0, y0, np.ones_like(x0)]
    )
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / den
        t = t_num * inv
        s_ = s_num * inv
    tmin = 1e-11 * dom.scale
    t[~((t > tmin) & (s_ >= -1e-12) & (s_ <= 1.0 + 1e-12))] = np.inf
    j = np.argmin(t, axis=1)
    lost = ~np.isfinite(t[np.arange(len(j)), j])
    if lost.any():
        # A viewpoint within tmin of a segment it is not on (e.g. an obstacle vertex 1e-11
        # off a wall it lies flush on) sees that segment at t < tmin: the ray leaves the
        # domain at once, so the direction is blocked.  Anything else is a real escape.
        ql = q[lost]
        a = ql[:, None, :] - dom.seg[None, :, :2]
        e = dom.seg[None, :, 2:] - dom.seg[None, :, :2]
        ll = np.maximum((e * e).sum(axis=2), 1e-300)
        tt = np.clip((a * e).sum(axis=2) / ll, 0.0, 1.0)
        dist = np.hypot(*(a - tt[..., None] * e).transpose(2, 0, 1)).min(axis=1)
        if np.any(dist > 10.0 * tmin):
            raise RayEscapeError("visibility ray escaped the domain: the boundary is not closed")
        j[lost] = -1
    return j


def _ray_line(q: np.ndarray, phi: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Points where rays from ``q`` at angles ``phi`` meet the lines of segments ``s``."""
    d = np.stack([_libm.cos(phi), _libm.sin(phi)], axis=1)
    a = s[:, :2] - q
    e = s[:, 2:] - s[:, :2]
    den = _cross(d, e)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = _cross(a, e) / den
    out = q + d * t[:, None]
    bad = ~np.isfinite(out).all(axis=1)
    if bad.any():
        # a bounding ray along the segment's own line (the viewpoint on that line, within
        # rounding): the boundary point on that ray is the segment's nearer end
        a0, a1 = s[bad, :2], s[bad, 2:]
        qb = q[bad] if q.ndim == 2 and len(q) == len(s) else np.broadcast_to(q, a0.shape)
        near0 = np.hypot(*(a0 - qb).T) <= np.hypot(*(a1 - qb).T)
        out[bad] = np.where(near0[:, None], a0, a1)
    return out


def polygon_from_gaps(g: Gaps) -> shapely.Geometry:
    """The star polygon swept by the open gaps of ``g`` (blocked gaps contribute
    the viewpoint itself)."""
    if not (g.seg >= 0).any():
        return shapely.Polygon()
    # consecutive gaps on the same segment continue one straight edge: keep only the
    # run's first and last points (fewer vertices for the boolean operations downstream)
    same = (g.seg[1:] == g.seg[:-1]) & (g.seg[1:] >= 0)
    keep0 = np.concatenate([[True], ~same])
    keep1 = np.concatenate([~same, [True]])
    pts = np.empty((2 * len(g.p0), 2))
    pts[0::2] = g.p0
    pts[1::2] = g.p1
    keep = np.empty(2 * len(g.p0), dtype=bool)
    keep[0::2] = keep0
    keep[1::2] = keep1
    pts = pts[keep]
    return clean_polygon(pts, 1e-10 * float(np.abs(pts - g.q).max()))


def clean_polygon(pts: np.ndarray, tol: float) -> shapely.Geometry:
    """Polygon through ``pts`` without near-duplicate consecutive points.

    Float noise can leave zero-width spikes where two gap rays meet one
    vertex; dropping points closer than ``tol`` to their successor removes
    them.  If the ring is still invalid it is repaired (polygonal parts kept).
    """
    step = np.abs(np.diff(pts, axis=0, append=pts[:1])).max(axis=1)
    pts = pts[step > tol]
    if len(pts) < 3:
        return shapely.Polygon()
    poly = shapely.Polygon(pts)
    if not poly.is_valid:
        fixed = shapely.make_valid(poly)
        parts = shapely.get_parts(fixed)
        parts = parts[np.isin(shapely.get_type_id(parts), (3, 6))]
        poly = shapely.union_all(parts) if len(parts) else shapely.Polygon()
    return poly


def visibility_polygon(dom: Domain, q: np.ndarray) -> shapely.Polygon:
    """Visibility polygon V(q) of a point in the domain (world frame)."""
    return polygon_from_gaps(gaps_from(dom, q))


@dataclass(frozen=True)
class RingSet:
    """One base domain and several rings, each of which extends it as
    :meth:`Domain.with_ring` does (``doms[r]``): the per-ring arrays padded (NaN) to the
    longest ring, for :func:`gaps_many_rings`."""

    base: Domain
    doms: list
    seg: np.ndarray  # (R, K, 4)
    vert: np.ndarray  # (R, K, 2)
    wedge: np.ndarray  # (R, K, 2): Domain.vert_wedge of the ring's vertices
    n: np.ndarray  # (R,) vertices (= segments) per ring

    @staticmethod
    def of(base: Domain, doms: list) -> RingSet:
        """The ring set of domains ``doms``, each ``base.with_ring(...)``."""
        nb = len(base.seg)
        n = np.array([len(d.seg) - nb for d in doms], dtype=np.int64)
        k = max(1, int(n.max(initial=0)))
        seg = np.full((len(doms), k, 4), np.nan)
        vert = np.full((len(doms), k, 2), np.nan)
        wedge = np.full((len(doms), k, 2), np.nan)
        for r, d in enumerate(doms):
            seg[r, : n[r]] = d.seg[nb:]
            vert[r, : n[r]] = d.vert[nb:]
            wedge[r, : n[r]] = _wedge(d.vert[nb:], d.vert_prev[nb:], d.vert_next[nb:])
        return RingSet(base, list(doms), seg, vert, wedge, n)


def _wedge(vert: np.ndarray, prev: np.ndarray, nxt: np.ndarray) -> np.ndarray:
    """:attr:`Domain.vert_wedge` of the vertices ``vert`` (the same expression, row by
    row)."""
    a = _libm.atan2(nxt[:, 1] - vert[:, 1], nxt[:, 0] - vert[:, 0])
    b = _libm.atan2(prev[:, 1] - vert[:, 1], prev[:, 0] - vert[:, 0])
    w = (b - a) % TAU
    return np.stack([a, np.where(w == 0.0, TAU, w)], axis=1)


def _blocking_rings(rs: RingSet, dom_of: np.ndarray, q: np.ndarray) -> tuple:
    """:func:`geometry.visindex.blocking` of each viewpoint ``q[i]`` in its own domain
    ``rs.doms[dom_of[i]]``, for all at once (the same pairs, in the same order, and the
    same expressions row by row)."""
    base = rs.base
    nb = len(base.seg)
    tol = 1e-12 * base.scale
    rows, cols = _visindex.near_pairs(base, q, 2.0 * tol)
    # the rings' segments, by brute force (as near_pairs does for an extended domain)
    ex = rs.seg[dom_of]  # (n, K, 4)
    a = q[:, None, :] - ex[:, :, :2]
    e = ex[:, :, 2:] - ex[:, :, :2]
    L2 = np.maximum((e * e).sum(axis=2), 1e-300)
    with np.errstate(invalid="ignore"):
        t = np.clip((a * e).sum(axis=2) / L2, 0.0, 1.0)
        d = a - t[..., None] * e
        r2, c2 = np.nonzero((d * d).sum(axis=2) <= (2.0 * tol) * (2.0 * tol))
    rows = np.concatenate([rows, r2])
    cols = np.concatenate([cols, c2 + nb])
    order = np.lexsort((cols, rows))
    rows, cols = rows[order], cols[order]
    ring = cols >= nb
    k = np.where(ring, cols - nb, 0)
    own = dom_of[rows]
    vert = np.where(ring[:, None], rs.vert[own, k], base.vert[np.where(ring, 0, cols)])
    segs = np.where(ring[:, None], rs.seg[own, k], base.seg[np.where(ring, 0, cols)])

    def wedge_of(m: np.ndarray) -> np.ndarray:
        rv = ring[m]
        env_wedge = _base_wedge(base)
        return np.where(rv[:, None], rs.wedge[own[m], k[m]], env_wedge[np.where(rv, 0, cols[m])])

    return _visindex.blocking_from_pairs(q, rows, vert, segs, wedge_of, tol)


def _base_wedge(base: Domain) -> np.ndarray:
    """``base.vert_wedge``, kept on the domain."""
    got = getattr(base, "_wedge_cache", None)
    if got is None:
        got = base.vert_wedge
        object.__setattr__(base, "_wedge_cache", got)
    return got


def gaps_many_rings(
    rs: RingSet,
    dom_of: np.ndarray,
    q: np.ndarray,
    *,
    sectors: np.ndarray | None = None,
    extra: np.ndarray | None = None,
) -> tuple[Gaps, np.ndarray]:
    """:func:`gaps_many` (``flat=True``) for viewpoints in different domains: ``q[i]`` is
    seen in ``rs.doms[dom_of[i]]`` (the base domain extended by one ring).  Segment
    indices are each domain's own.  The answers are bit for bit those of
    :func:`gaps_many` on each domain: the base's vertices are sorted by the compiled
    kernel as there, and a ring's vertices join as critical directions computed by the
    same expressions (:func:`geometry._libm.atan2`, the same tolerance drop); the first
    hits come from :func:`geometry.visindex.first_hits_rings`.  Needs the compiled index
    (:func:`geometry.visindex.available`)."""
    base = rs.base
    nb = len(base.seg)
    q = np.asarray(q, dtype=float).reshape(-1, 2)
    dom_of = np.asarray(dom_of, dtype=np.int64)
    n = len(q)
    tol = 1e-12 * base.scale
    start, width = _sector_bounds(sectors, n)
    w1, w2, along = _blocking_rings(rs, dom_of, q)
    cols = [] if extra is None else [extra]
    cols.append(_blocking_crit(w1, w2, along))
    # the ring's vertices: directions as the kernel computes them for a domain's vertex
    rv = rs.vert[dom_of]  # (n, K, 2)
    dx = rv[..., 0] - q[:, None, 0]
    dy = rv[..., 1] - q[:, None, 1]
    with np.errstate(invalid="ignore"):
        ang = _libm.atan2(dy, dx)
        ang[~(np.maximum(np.abs(dx), np.abs(dy)) > tol)] = np.nan  # near q, or padding
    cols.append(ang)
    crit = np.concatenate(cols, axis=1)
    owner, lo, hi = _visindex.sorted_gaps(q, start, width, base.vert, crit, tol, False, base)
    mid = 0.5 * (lo + hi)
    open_ = _unblocked(mid, owner, w1, w2, along)
    qo = q[owner]
    do = dom_of[owner]
    seg = np.full(len(mid), -1, dtype=np.int64)
    idx = np.flatnonzero(open_)
    if len(idx):
        j = _visindex.first_hits_rings(base, rs.seg, rs.n, do[idx], qo[idx], mid[idx])
        lost = np.flatnonzero(j < 0)
        for r in np.unique(do[idx[lost]]):  # as _first_hits does: brute force, per domain
            sel = lost[do[idx[lost]] == r]
            j[sel] = _first_hits(rs.doms[r], qo[idx[sel]], mid[idx[sel]], brute=True)
        seg[idx] = j
    p0 = qo.copy()
    p1 = qo.copy()
    ok = seg >= 0
    if ok.any():
        s_ok, d_ok = seg[ok], do[ok]
        ring = s_ok >= nb
        sg = np.where(
            ring[:, None],
            rs.seg[d_ok, np.where(ring, s_ok - nb, 0)],
            base.seg[np.where(ring, 0, s_ok)],
        )
        p0[ok] = _ray_line(qo[ok], lo[ok], sg)
        p1[ok] = _ray_line(qo[ok], hi[ok], sg)
    return Gaps(q=qo, lo=lo, hi=hi, seg=seg, p0=p0, p1=p1), np.searchsorted(owner, np.arange(n + 1))
