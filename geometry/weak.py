"""Weak visibility of a target outline: the placements that see some wanted piece of
it (paper 3.2.1, with the aim uncertainty of section 4), as a union of exact visibility
triangles anchored at the ends of wanted pieces and at reflex vertices of the free space.
The algorithm and its proof: :mod:`geometry.partial` and docs/DESIGN.md.

Imports run one way: ``_vis -> weak -> sweep -> partial -> recognize``.
"""

from __future__ import annotations

import numpy as np
import shapely

from . import visindex as _visindex
from ._shapes import SNAP_REL, cross, union_all
from ._vis import TAU, Domain, Gaps, RingSet, clean_polygon, gaps_many, gaps_many_rings
from .scene import NEAR_REL

__all__ = ["CONTACT_REL", "ENV", "UNWANTED", "WANTED", "snap_to_boundary", "weak_visibility"]

#: Segment tags inside the visibility domain.
ENV, WANTED, UNWANTED = 0, 1, 2

#: A target vertex within this distance (times the domain's scale: ``TOL_REL`` of the
#: scene's diameter in the local frame) of the free space's boundary *touches* it and is
#: moved onto it (docs/DESIGN.md, "Contacts").
CONTACT_REL = 1e-9


def weak_visibility(
    env: Domain,
    ring: np.ndarray,
    wanted: np.ndarray,
    eps_aim: float = 0.0,
    grazing: np.ndarray | None = None,
) -> shapely.Geometry:
    """Placements that see some wanted piece of a target boundary.

    Parameters
    ----------
    env : the free space as a visibility domain (without the target).
    ring : (m, 2) target boundary, clockwise (it becomes a hole of the domain
        and occludes); pieces to be seen must start and end at ring vertices
        (insert the cut points first).
    wanted : (m,) bool, True where segment ``ring[i] -> ring[i+1]`` is wanted.
    eps_aim : drop anchor fans narrower than this (radians).
    grazing : optional (len(env.vert),) bool: the reflex vertices of ``env`` that may be
        grazing anchors (the target's own vertices always may).  A caller that knows
        that the other vertices see no point of the target (e.g. none of a region that
        holds it) skips their ray casts; the answer is the same.

    Returns
    -------
    Union of the visibility triangles (shapely geometry, world frame), not yet
    clipped against the target itself.
    """
    ring, wanted = snap_to_boundary(env, ring, wanted)
    dom = env.with_ring(ring, UNWANTED, np.where(wanted, WANTED, UNWANTED))
    fans: list[shapely.Geometry] = []
    # 1. anchors on the target: endpoints of wanted pieces, seen from the front
    #    of a wanted edge at that vertex
    edge, anchors, extra, arcs = _target_anchors(ring, wanted, dom, len(env.vert))
    if len(anchors):
        for k, (gi, i) in enumerate(
            zip(gaps_many(dom, ring[anchors], extra=extra), anchors, strict=False)
        ):
            front = _front(gi, edge, wanted, i, None if arcs is None else arcs[k])
            fans += _fans(gi, front & (gi.seg >= 0), dom, eps_aim)
    n_direct = len(fans)
    # 2. grazing anchors: reflex vertices v of the free space around the target;
    #    first the directions in which v sees a wanted piece ...
    grz = _grazing_anchors(ring, dom, grazing, len(env.vert))
    if grz is not None:
        v, sectors, extra, arcs, _ = grz
        g, off = gaps_many(dom, v, sectors=sectors, extra=extra, flat=True)
        sees = _sees_wanted(dom, g.seg, g.lo, g.hi, off, arcs)
        back_q, back_sec = [], []
        for k in np.unique(np.searchsorted(off, np.flatnonzero(sees), side="right") - 1):
            gk = g.part(off[k], off[k + 1])
            for run in _runs(gk, sees[off[k] : off[k + 1]]):
                back_q.append(v[k])
                back_sec.append((gk.lo[run[0]] + np.pi, _width(gk, run)))
        # ... then the placements on the opposite side of v
        if back_q:
            backs = gaps_many(dom, np.asarray(back_q), sectors=np.asarray(back_sec))
            for gb in backs:
                fans += _fans(gb, gb.seg >= 0, dom, eps_aim)
    # fans narrower than the contact tolerance (a sliver anchored at a vertex within tol
    # of a contact, area ~1e-20) are noise, and GEOS's floating union of such slivers
    # can fill a pocket that no fan covers (fuzz contact seed 100375, scaled frame)
    arr = np.asarray(fans, dtype=object)
    thick = shapely.area(arr) > CONTACT_REL * dom.scale * shapely.length(arr)
    n_direct = int(thick[:n_direct].sum())
    fans = list(arr[thick])
    if not fans:
        return shapely.Polygon()
    return _union(fans, n_first=n_direct, grid=SNAP_REL * dom.scale)


def _target_anchors(
    ring: np.ndarray, wanted: np.ndarray, dom: Domain, nv: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, np.ndarray | None]:
    """Step 1 of :func:`weak_visibility`: the anchors on the target (indices into
    ``ring`` of the endpoints of wanted pieces), with ``edge`` (the (m, 2) edge vectors
    ``ring[i+1] - ring[i]``), the extra critical directions of each anchor (radians:
    along and against both edges at it, and the sides of its pinch arcs) and the pinch
    arcs (or None).  ``dom`` is the domain with the target as a hole after the ``nv``
    vertices of the free space.  ``extra`` is None when there are no anchors."""
    edge = np.roll(ring, -1, axis=0) - ring
    inc = np.stack([wanted, np.roll(wanted, 1)], axis=1)  # outgoing, incoming edge wanted
    anchors = np.flatnonzero(inc.any(axis=1))
    if not len(anchors):
        return edge, anchors, None, None
    e_out, e_in = edge[anchors], np.roll(edge, 1, axis=0)[anchors]
    dirs = np.stack([e_out, e_in], axis=1)  # (k, 2, 2)
    ang = np.arctan2(dirs[..., 1], dirs[..., 0])
    extra = np.concatenate([ang + np.pi, ang], axis=1)
    # an anchor where an obstacle touches the target (a pinch) sees the edge beside it
    # only where no touching polygon lies between the line of sight and the edge
    arcs = _pinch_arcs(dom, nv + anchors)
    if arcs is not None:
        extra = np.concatenate([extra, arcs[..., 0], arcs[..., 0] + arcs[..., 1]], axis=1)
    return edge, anchors, extra, arcs


def _front(
    gi: Gaps, edge: np.ndarray, wanted: np.ndarray, i: int, arcs: np.ndarray | None
) -> np.ndarray:
    """The gaps of anchor ``ring[i]`` that look out of the front of a wanted edge at it
    (bool per gap); ``arcs``: the anchor's pinch arcs (radians) or None."""
    mid = 0.5 * (gi.lo + gi.hi)
    d = np.stack([np.cos(mid), np.sin(mid)], axis=1)
    front = np.zeros(len(mid), dtype=bool)
    # the edge out of i runs along ``edge[i]``, the edge into i back along -edge[i-1]
    for e, along, use in (
        (edge[i], edge[i], wanted[i]),
        (edge[i - 1], -edge[i - 1], wanted[i - 1]),
    ):
        if use:
            f = e[0] * d[:, 1] - e[1] * d[:, 0] > 0
            if arcs is not None:
                f &= ~_between(arcs, mid, float(np.arctan2(along[1], along[0])))
            front |= f
    return front


def corners_seeing(env: Domain, ring: np.ndarray) -> np.ndarray:
    """(len(env.vert),) bool: the reflex vertices of ``env`` (convex obstacle corners) that
    see a point of the target outline ``ring`` (clockwise, every edge wanted) under a
    positive angle: the candidates of :func:`weak_visibility`'s step 2 whose rays, cast in
    their sector towards the target (the target a hole that occludes), first hit it in
    some gap.  A corner that sees a target held by this one (``A_q`` inside the region
    ``ring`` bounds, obstacle-free) under a positive angle sees this one so too: the rays
    that reach ``A_q`` first enter the region.  So these are the only corners that can be
    grazing anchors of such a target (``weak_visibility``'s ``grazing``), found without
    building the region's fans and their union."""
    out = np.zeros(len(env.vert), dtype=bool)
    wanted = np.ones(len(ring), dtype=bool)
    ring, wanted = snap_to_boundary(env, ring, wanted)
    dom = env.with_ring(ring, UNWANTED, np.where(wanted, WANTED, UNWANTED))
    nv = len(env.vert)
    grz = _grazing_anchors(ring, dom, None, nv)
    if grz is None:
        return out
    v, sectors, extra, arcs, idx = grz
    g, off = gaps_many(dom, v, sectors=sectors, extra=extra, flat=True, ends=False)
    sees = _sees_wanted(dom, g.seg, g.lo, g.hi, off, arcs)
    owner = np.searchsorted(off, np.arange(len(g.lo)), side="right") - 1
    sel = idx[np.bincount(owner[sees], minlength=len(v)) > 0]
    out[sel[sel < nv]] = True
    return out


def _grazing_anchors(
    ring: np.ndarray, dom: Domain, grazing: np.ndarray | None, nv: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray | None, np.ndarray | None, np.ndarray] | None:
    """Step 2 of :func:`weak_visibility`: the grazing anchors (reflex vertices of ``dom``,
    those of the free space's ``nv`` first ones filtered by ``grazing``) whose sector
    towards the target has a positive angle, with their sectors ``(start, width)``
    (radians), the extra critical directions of their pinch arcs (or None), the arcs
    (or None) and their indices into ``dom.vert``.  None when ``dom`` has no candidate
    vertex at all."""
    v_idx = np.flatnonzero(dom.reflex)
    if grazing is not None:
        v_idx = v_idx[(v_idx >= nv) | grazing[np.minimum(v_idx, nv - 1)]]
    v = dom.vert[v_idx]
    if not len(v):
        return None
    rel = np.arctan2(ring[None, :, 1] - v[:, None, 1], ring[None, :, 0] - v[:, None, 0])
    centre = ring.mean(axis=0)
    base = np.arctan2(centre[1] - v[:, 1], centre[0] - v[:, 0])
    rel = (rel - base[:, None] + np.pi) % TAU - np.pi
    on_target = np.abs(ring[None, :, :] - v[:, None, :]).max(axis=2) <= 1e-12 * dom.scale
    lo = np.where(on_target, np.inf, rel).min(axis=1)
    hi = np.where(on_target, -np.inf, rel).max(axis=1)
    ok = hi - lo > 1e-12
    v, sectors = v[ok], np.stack([base[ok] + lo[ok], hi[ok] - lo[ok]], axis=1)
    # a line through a pinch (polygons touching at v) passes between them: blocked
    arcs = _pinch_arcs(dom, v_idx[ok])
    extra = None
    if arcs is not None:  # split the gaps where a line through v starts to separate
        a0, a1 = arcs[..., 0], arcs[..., 0] + arcs[..., 1]
        extra = np.concatenate([a0, a1, a0 - np.pi, a1 - np.pi], axis=1)
    return v, sectors, extra, arcs, v_idx[ok]


def _pinch_arcs(dom: Domain, idx: np.ndarray) -> np.ndarray | None:
    """At each domain vertex ``dom.vert[idx]`` where two or more domain vertices coincide
    (a *pinch*: two obstacles, or the target and an obstacle, touching at a vertex), the
    arcs of directions that enter one of them, as (n, K, 2) ``(start, width)`` (NaN rows
    and padding elsewhere); ``None`` when none of them is a pinch."""
    if len(idx) == 0:
        return None
    # groups of equal vertices (as np.unique(axis=0) numbers them, by a lexicographic
    # sort: only equality and the counts matter here)
    order = np.lexsort((dom.vert[:, 1], dom.vert[:, 0]))
    sv = dom.vert[order]
    new = np.concatenate([[True], (sv[1:] != sv[:-1]).any(axis=1)])
    inv = np.empty(len(order), dtype=np.int64)
    inv[order] = np.cumsum(new) - 1
    cnt = np.bincount(inv)
    group = inv[idx]
    hit = np.flatnonzero(cnt[group] >= 2)
    if len(hit) == 0:
        return None
    wedge = dom.vert_wedge
    out = np.full((len(idx), int(cnt.max()), 2), np.nan)
    for r in hit:  # pinches only (contacts are few)
        w = wedge[inv == group[r]]
        out[r, : len(w), 0] = w[:, 0] + w[:, 1]
        out[r, : len(w), 1] = TAU - w[:, 1]
    return out


def _between(arcs: np.ndarray, phi: np.ndarray, a: float) -> np.ndarray:
    """Per direction ``phi`` (n,): does one of the ``arcs`` (K, 2) ``(start, width)`` (NaN
    rows ignored) overlap the open sector swept from ``phi`` to ``a`` the short way?  A
    line of sight from ``phi`` to the edge along ``a`` at a pinch then passes that polygon
    (docs/DESIGN.md, "Contacts")."""
    eps = 1e-12
    delta = (a - phi + np.pi) % TAU - np.pi
    s0 = np.where(delta >= 0, phi, phi + delta)[:, None]
    w0 = np.abs(delta)[:, None]
    s1, w1 = arcs[None, :, 0], arcs[None, :, 1]
    with np.errstate(invalid="ignore"):
        hit = (((s1 - s0) % TAU) < w0 - eps) | (((s0 - s1) % TAU) < w1 - eps)
    return (hit & ~np.isnan(s1)).any(axis=1)


def _sees_wanted(
    dom: Domain,
    seg: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    off: np.ndarray,
    arcs: np.ndarray | None,
) -> np.ndarray:
    """Per gap of the grazing anchors' flat gaps (segment hit ``seg``, directions ``lo``,
    ``hi``; anchor k owns gaps ``off[k] : off[k + 1]``): does the anchor see a wanted piece
    of the target there, past its pinch arcs (``arcs``, :func:`_pinch_arcs`, or None)?"""
    sees = (seg >= 0) & (dom.seg_tag[np.maximum(seg, 0)] == WANTED)
    if arcs is not None:
        owner = np.searchsorted(off, np.arange(len(lo)), side="right") - 1
        sees &= _grazes(arcs[owner], 0.5 * (lo + hi))
    return sees


def _grazes(arcs: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """Does the line through a pinch at direction ``phi`` (n,) leave all the touching
    polygons' arcs ``arcs`` (n, K, 2) on one side?  A line with polygons on both sides
    passes between them through their contact point only: a gap of zero width, which
    blocks (docs/DESIGN.md, "Contacts").  Rows without arcs (NaN) pass."""
    start, width = arcs[..., 0], arcs[..., 1]
    eps = 1e-12
    with np.errstate(invalid="ignore"):
        left = ((start - phi[:, None]) % TAU) + width <= np.pi + eps
        right = ((start - phi[:, None] - np.pi) % TAU) + width <= np.pi + eps
    none = np.isnan(start)
    return (left | none).all(axis=1) | (right | none).all(axis=1)


def snap_to_boundary(
    env: Domain, ring: np.ndarray, wanted: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The target ``ring`` with its contacts with the free space's boundary made exact
    (docs/DESIGN.md, "Contacts"); ``wanted`` (one flag per segment ``ring[i] ->
    ring[i+1]``) follows.  Touching means within ``tol = CONTACT_REL * env.scale``:

    1. a ring vertex that touches a boundary vertex is moved onto it; else one that
       touches a boundary segment is moved onto the foot of its perpendicular;
    2. a boundary vertex that touches the interior of a ring segment is inserted into the
       ring (the segment is split there, both halves keep its flag);
    3. the parts of the ring's segments that touch the boundary (an obstacle or a wall
       lies on them, flush or at a contact point) are covered: the segment is cut at
       their ends and they are not wanted.

    Segments that collapse to a point are dropped.

    Why: a target placed flush against an obstacle or a wall lands up to ~1e-11 of the
    scene inside it or outside it, as the rounding of the pose and of the frame falls
    (issue 26 items 2, 5, 9).  A fan anchored at a vertex inside an obstacle is empty
    (every ray toward the free side meets the obstacle's edge at once), so the placements
    that see the exposed middle of an edge whose two ends are flush were lost; a vertex
    just outside saw, through the sub-tolerance gap, a whole half-plane in front of the
    covered edge.  After 1-3 every contact is decided by exact coincidence: the fans of
    vertices on the boundary obey the rules for viewpoints on it
    (:func:`geometry._vis.gaps_many`: the free wedge at a vertex, the free side of a
    segment), and a covered edge is seen by no one, whichever side the rounding put it
    on.  The moves are at most ``tol``, below the tolerance of every answer.
    """
    tol = CONTACT_REL * env.scale
    ring = np.asarray(ring, dtype=float)
    wanted = wanted0 = np.asarray(wanted, dtype=bool)
    if len(env.seg) == 0 or len(ring) < 3:
        return ring, wanted
    # only the boundary within reach can touch: every test below is within tol of the ring
    # (50 tol for step 1's vertices, which move the ring by no more), and keeps its order
    vert, seg = _within_reach(env, ring, (NEAR_REL + 2.0) * tol)
    if len(seg) == 0:
        return ring, wanted
    out = ring.copy()
    rows = np.arange(len(out))
    # 1. vertices onto the boundary (a boundary vertex first, else a segment's foot)
    #    A ring vertex and a boundary vertex closer than ``NEAR_REL / 2`` tolerances
    #    (5e-8 D) are one point: at one tol the fuzzer's contacts (a needle's tip 1.0-1.2 tol
    #    from the target's corner) were snapped or inserted as rounding fell, frame by frame
    #    (seed 108386).  Half of the target's own merge distance, so two ring vertices never
    #    land on one boundary vertex; each boundary vertex takes its nearest ring vertex.
    if len(vert):
        dv = np.hypot(*(vert[None, :, :] - out[:, None, :]).transpose(2, 0, 1))
        jv = np.argmin(dv, axis=1)
        on_v = dv[rows, jv] <= 0.5 * NEAR_REL * tol
        if on_v.sum() > 1:
            nearest = np.argmin(np.where(on_v[:, None], dv, np.inf), axis=0)  # per vertex
            on_v &= nearest[jv] == rows
    else:
        jv, on_v = np.zeros(len(out), dtype=np.int64), np.zeros(len(out), dtype=bool)
    foot, ds = _feet(seg, out)
    js = np.argmin(ds, axis=1)
    on_s = ~on_v & (ds[rows, js] <= tol)
    out[on_v] = vert[jv[on_v]]
    out[on_s] = foot[rows[on_s], js[on_s]]
    # 2. boundary vertices on the ring's segments.  One that touches both segments at a
    #    ring vertex (1.7 tol from it, within tol of both lines) touches the corner: the
    #    vertex moves onto it, else it was inserted on both sides and the ring got a spike
    #    1e-9 long whose fans were decided by rounding (fuzz contact seed 104657)
    on_seg = _on_segments(vert, out, tol)
    corner = on_seg & np.roll(on_seg, -1, axis=0)  # [i, j]: on the segments into and out of i+1
    if corner.any():
        ci, cj = np.nonzero(corner)
        _, first = np.unique((ci + 1) % len(out), return_index=True)
        out[(ci[first] + 1) % len(out)] = vert[cj[first]]
        on_v[(ci[first] + 1) % len(out)] = True
        on_seg = _on_segments(vert, out, tol)
    seg_i, vert_j = np.nonzero(on_seg)
    if not (on_v | on_s).any() and len(seg_i) == 0:
        return ring, wanted
    p0 = out
    e = np.roll(out, -1, axis=0) - p0
    t = ((vert[None, :, :] - p0[:, None, :]) * e[:, None, :]).sum(axis=2) / np.maximum(
        (e * e).sum(axis=1), 1e-300
    )[:, None]
    if len(seg_i):
        # merge: original vertex i sorts at (i, -1), an inserted one at (i, t)
        key_i = np.concatenate([rows, seg_i])
        key_t = np.concatenate([np.full(len(rows), -1.0), t[seg_i, vert_j]])
        pts = np.concatenate([out, vert[vert_j]])
        flags = np.concatenate([wanted, wanted[seg_i]])
        order = np.lexsort((key_t, key_i))
        out, wanted = pts[order], flags[order]
    keep = np.any(out != np.roll(out, -1, axis=0), axis=1)
    out, wanted = out[keep], wanted[keep]
    if len(out) < 3:  # pragma: no cover - a target thinner than tol (rejected at load)
        return ring, np.asarray(wanted0, dtype=bool)
    # 3. the covered parts of the ring's segments (within tol of the boundary): cut there,
    #    not wanted
    return _cut_covered(seg, out, wanted, tol)


def _within_reach(env: Domain, ring: np.ndarray, reach: float) -> tuple[np.ndarray, np.ndarray]:
    """The boundary vertices and segments of ``env`` (in their order) whose bounding boxes
    come within ``reach`` (max-norm) of the bounding box of ``ring``: every one that can be
    within ``reach`` of a point of the ring."""
    lo, hi = ring.min(axis=0) - reach, ring.max(axis=0) + reach
    v, s = env.vert, env.seg
    near_v = (v >= lo).all(axis=1) & (v <= hi).all(axis=1)
    s_lo = np.minimum(s[:, :2], s[:, 2:])
    s_hi = np.maximum(s[:, :2], s[:, 2:])
    near_s = (s_hi >= lo).all(axis=1) & (s_lo <= hi).all(axis=1)
    return v[near_v], s[near_s]


def _on_segments(vert: np.ndarray, ring: np.ndarray, tol: float) -> np.ndarray:
    """(m, V) bool: boundary vertex ``vert[j]`` touches the interior of ring segment ``i``
    (within ``tol`` of its line, more than ``tol`` from both ends)."""
    e = np.roll(ring, -1, axis=0) - ring
    ll = np.maximum((e * e).sum(axis=1), 1e-300)
    w = vert[None, :, :] - ring[:, None, :]  # (m, V, 2)
    t = (w * e[:, None, :]).sum(axis=2) / ll[:, None]
    length = np.sqrt(ll)[:, None]
    off = np.abs(e[:, None, 0] * w[..., 1] - e[:, None, 1] * w[..., 0]) / length
    return (off <= tol) & (t * length > tol) & ((1.0 - t) * length > tol)


def _cut_covered(
    seg: np.ndarray, ring: np.ndarray, wanted: np.ndarray, tol: float
) -> tuple[np.ndarray, np.ndarray]:
    """``ring`` with every segment cut where its points come within ``tol`` of a boundary
    segment (``seg``, (E, 4)) or leave that band; the pieces inside the band are not
    wanted.  The band around a segment is a capsule, so each (ring segment, boundary
    segment) pair gives one interval of the ring segment's parameter: the hull of its
    intersections with the slab and with the two end discs (closed form)."""
    p0 = ring
    e = np.roll(ring, -1, axis=0) - ring  # (m, 2)
    a = seg[None, :, :2]
    d = seg[None, :, 2:] - a
    ln = np.maximum(np.hypot(d[..., 0], d[..., 1]), 1e-300)
    u = d / ln[..., None]  # (1, E, 2)
    w = p0[:, None, :] - a  # (m, E, 2)
    ee = e[:, None, :]
    lo = np.full(w.shape[:2], np.inf)
    hi = np.full(w.shape[:2], -np.inf)
    # the slab: |u x (w + s e)| <= tol and 0 <= u . (w + s e) <= |d|
    s_lo = np.full(w.shape[:2], -np.inf)
    s_hi = np.full(w.shape[:2], np.inf)
    for c0, c1, b0, b1 in (
        (cross(u, w), cross(u, ee), -tol, tol),
        ((u * w).sum(axis=2), (u * ee).sum(axis=2), 0.0, ln),
    ):
        c0, c1 = np.broadcast_arrays(c0, c1)
        b1 = np.broadcast_to(b1, c0.shape)
        flat = np.abs(c1) <= 1e-300
        with np.errstate(divide="ignore", invalid="ignore"):
            r0 = (b0 - c0) / c1
            r1 = (b1 - c0) / c1
        inside = (c0 >= b0) & (c0 <= b1)  # a segment parallel to the band: all or nothing
        r_lo = np.where(flat, np.where(inside, -np.inf, np.inf), np.minimum(r0, r1))
        r_hi = np.where(flat, np.where(inside, np.inf, -np.inf), np.maximum(r0, r1))
        s_lo, s_hi = np.maximum(s_lo, r_lo), np.minimum(s_hi, r_hi)
    ok = s_lo <= s_hi
    lo, hi = np.where(ok, s_lo, lo), np.where(ok, s_hi, hi)
    # the discs at both ends: |w' + s e|^2 <= tol^2
    e2 = np.maximum((e * e).sum(axis=1), 1e-300)[:, None]
    for wq in (w, w - d):
        bq = (wq * ee).sum(axis=2)
        disc = bq * bq - e2 * ((wq * wq).sum(axis=2) - tol * tol)
        r = np.sqrt(np.maximum(disc, 0.0))
        has = disc >= 0
        lo = np.where(has, np.minimum(lo, (-bq - r) / e2), lo)
        hi = np.where(has, np.maximum(hi, (-bq + r) / e2), hi)
    lo, hi = np.clip(lo, 0.0, 1.0), np.clip(hi, 0.0, 1.0)
    length = np.sqrt(e2[:, 0])
    hit = (hi - lo) * length[:, None] > tol  # a covered piece longer than tol
    if not hit.any():
        return ring, wanted
    pts, flags = [], []
    for i in range(len(ring)):
        js = np.flatnonzero(hit[i])
        if len(js) == 0:
            pts.append(ring[i : i + 1])
            flags.append(wanted[i : i + 1])
            continue
        iv = sorted(zip(lo[i, js], hi[i, js], strict=True))
        merged = [list(iv[0])]
        for l0, h0 in iv[1:]:
            if l0 <= merged[-1][1]:
                merged[-1][1] = max(merged[-1][1], h0)
            else:
                merged.append([l0, h0])
        cuts = np.unique(np.clip(np.asarray(merged).ravel(), 0.0, 1.0))
        step = tol / length[i]
        cuts = cuts[(cuts > step) & (cuts < 1.0 - step)]
        cuts = cuts[np.concatenate([[True], np.diff(cuts) > step])] if len(cuts) else cuts
        ss = np.concatenate([[0.0], cuts])
        mids = 0.5 * (ss + np.concatenate([cuts, [1.0]]))
        covered = np.zeros(len(mids), dtype=bool)
        for l0, h0 in merged:
            covered |= (mids >= l0) & (mids <= h0)
        piece = ring[i] + ss[:, None] * e[i]
        piece[0] = ring[i]
        pts.append(piece)
        flags.append(wanted[i] & ~covered)
    return np.concatenate(pts), np.concatenate(flags)


def _feet(seg: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For points ``p`` (n, 2) and segments ``seg`` (E, 4): the nearest point of every
    segment to every point, (n, E, 2), and its distance, (n, E)."""
    a = seg[:, :2]
    e = seg[:, 2:] - a
    ll = np.maximum((e * e).sum(axis=1), 1e-300)
    d = p[:, None, :] - a[None, :, :]
    t = np.clip((d * e[None]).sum(axis=2) / ll, 0.0, 1.0)
    foot = a[None] + t[..., None] * e[None]
    return foot, np.hypot(*(p[:, None, :] - foot).transpose(2, 0, 1))


def _union(polys: list[shapely.Geometry], n_first: int, grid: float) -> shapely.Geometry:
    """Union of polygons; the later ones are first tested (vectorised) against the
    union of the first ``n_first`` and dropped when already covered by it.

    Snap-rounded on ``grid``: GEOS's floating overlay can fill a pocket that no fan
    covers when a fan's edge runs within rounding of a hole's edge of the union so far
    (fuzz seed 205614, a hole of 1e-3 D^2 closed in the frame scaled by 1e-3); the
    snap-rounding overlay is robust by construction and moves no vertex by more than
    half the grid.  Normalized (GEOS's normal form): the snap-rounded union's ring order
    depends on the order of its inputs, which the batched and the one-by-one fans do not
    share (:func:`weak_visibility_many` gives the same coordinates in the same order; the
    rounding can give -0.0 in one where the other has 0.0)."""
    first = union_all(polys[:n_first], grid_size=grid) if n_first else shapely.Polygon()
    rest = np.asarray(polys[n_first:], dtype=object)
    if len(rest) and not first.is_empty:
        shapely.prepare(first)
        rest = rest[~shapely.covers(first, rest)]
    if len(rest) == 0:
        return shapely.normalize(first)
    return shapely.normalize(union_all(np.concatenate([[first], rest]), grid_size=grid))


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
    whose far side lies on one connected stretch of one polygon's boundary, as
    shapely Polygons; with ``eps_aim > 0`` those whose apex angle is below
    ``eps_aim`` are dropped (with ``eps_aim == 0`` runs are not split)."""
    ring_of = np.where(g.seg >= 0, dom.seg_ring[np.maximum(g.seg, 0)], -1)
    out: list[shapely.Geometry] = []
    for run in _runs(g, mask):
        if eps_aim > 0:
            # split where the far side jumps to another polygon or another
            # stretch of boundary (a depth discontinuity)
            r = ring_of[run]
            jump = np.abs(g.p0[run[1:]] - g.p1[run[:-1]]).max(axis=1) > 1e-9 * dom.scale
            pieces = np.split(run, np.flatnonzero((r[1:] != r[:-1]) | jump) + 1)
        else:
            pieces = [run]
        for piece in pieces:
            if eps_aim > 0 and _width(g, piece) < eps_aim:
                continue
            pts = np.empty((2 * len(piece) + 1, 2))
            pts[0] = g.q
            pts[1::2] = g.p0[piece]
            pts[2::2] = g.p1[piece]
            # adjacent gaps ending on the same segment continue one straight edge: keep
            # only the ends of such runs (fewer vertices for the union, same polygon)
            same = g.seg[piece[1:]] == g.seg[piece[:-1]]
            keep = np.ones(len(pts), dtype=bool)
            keep[2:-1:2] = ~same
            keep[3::2] = ~same
            out.append(clean_polygon(pts[keep], 1e-10 * dom.scale))
    return out


def weak_visibility_many(
    env: Domain,
    rings: list[np.ndarray],
    wanted: list[np.ndarray],
    eps_aim: float = 0.0,
    grazing: np.ndarray | None = None,
) -> list[shapely.Geometry]:
    """:func:`weak_visibility` of several target outlines in one free space: the same
    answers, bit for bit, with the ray casting of all targets done together.

    Each target is a hole of its own domain (it occludes only itself), so the viewpoints
    of all targets are cast at once by :func:`geometry._vis.gaps_many_rings` (one call
    per kind of anchor instead of one per target); the rest is :func:`weak_visibility`'s
    code, target by target.  ``rings[i]``, ``wanted[i]``: as ``ring`` and ``wanted`` of
    :func:`weak_visibility`.  Without the compiled index
    (:func:`geometry.visindex.available`), or for a domain that is itself extended, the
    targets are done one by one."""
    if not (_visindex.available() and getattr(env, "_parent", None) is None) or not rings:
        return [
            weak_visibility(env, r, w, eps_aim, grazing) for r, w in zip(rings, wanted, strict=True)
        ]
    nv = len(env.vert)
    snapped = [snap_to_boundary(env, r, w) for r, w in zip(rings, wanted, strict=True)]
    rings = [r for r, _ in snapped]
    wanted = [w for _, w in snapped]
    doms = [
        env.with_ring(r, UNWANTED, np.where(w, WANTED, UNWANTED))
        for r, w in zip(rings, wanted, strict=True)
    ]
    rs = RingSet.of(env, doms)
    fans: list[list] = [[] for _ in rings]
    # 1. anchors on the targets (weak_visibility, step 1)
    q1, e1, own1, meta1 = [], [], [], []
    for r, (ring, wnt, dom) in enumerate(zip(rings, wanted, doms, strict=True)):
        edge, anchors, extra, arcs = _target_anchors(ring, wnt, dom, nv)
        if not len(anchors):
            meta1.append(None)
            continue
        q1.append(ring[anchors])
        e1.append(extra)
        own1.append(np.full(len(anchors), r))
        meta1.append((edge, anchors, arcs))
    g1 = off1 = None
    if q1:
        g1, off1 = gaps_many_rings(rs, np.concatenate(own1), np.concatenate(q1), extra=_padded(e1))
    row = 0
    qs1 = np.concatenate(q1) if q1 else np.zeros((0, 2))
    flat = eps_aim == 0  # the fans of all viewpoints at once (_fans_flat)
    masks = []
    for r, (wnt, dom) in enumerate(zip(wanted, doms, strict=True)):
        if meta1[r] is None:
            continue
        edge, anchors, arcs = meta1[r]
        for k, i in enumerate(anchors):
            gi = _slice(g1, off1[row], off1[row + 1], qs1[row])
            row += 1
            front = _front(gi, edge, wnt, i, None if arcs is None else arcs[k])
            if flat:
                masks.append(front & (gi.seg >= 0))
            else:
                fans[r] += _fans(gi, front & (gi.seg >= 0), dom, eps_aim)
    if flat and masks:
        got, view = _fans_flat(g1, off1, qs1, np.concatenate(masks), 1e-10 * env.scale)
        own = np.concatenate(own1)[view]
        for f, r in zip(got, own.tolist(), strict=True):
            fans[r].append(f)
    n_direct = [len(f) for f in fans]
    # 2. grazing anchors (weak_visibility, step 2): the directions that see a wanted piece
    q2, s2, e2, own2, meta2 = [], [], [], [], []
    for r, (ring, dom) in enumerate(zip(rings, doms, strict=True)):
        grz = _grazing_anchors(ring, dom, grazing, nv)
        if grz is None:
            meta2.append(None)
            continue
        v, sectors, extra, arcs, _ = grz
        q2.append(v)
        s2.append(sectors)
        e2.append(extra if extra is not None else np.zeros((len(v), 0)))
        own2.append(np.full(len(v), r))
        meta2.append((v, arcs))
    back_q, back_sec, back_own = [], [], []
    if q2:
        g, off = gaps_many_rings(
            rs, np.concatenate(own2), np.concatenate(q2), sectors=np.concatenate(s2),
            extra=_padded(e2),
        )  # fmt: skip
        at = np.cumsum([0] + [len(x) for x in q2])
        sees = np.zeros(len(g.lo), dtype=bool)
        for b, r in enumerate(np.concatenate(own2)[at[:-1]]):
            v, arcs = meta2[r]
            lo_v, hi_v = at[b], at[b + 1]
            if off[hi_v] == off[lo_v]:
                continue
            g0, g1_ = off[lo_v], off[hi_v]
            sees[g0:g1_] = _sees_wanted(
                doms[r], g.seg[g0:g1_], g.lo[g0:g1_], g.hi[g0:g1_], off[lo_v : hi_v + 1] - g0, arcs
            )
        gi, bounds = _runs_flat(g, off, sees)
        if len(bounds) > 1:
            first, last = gi[bounds[:-1]], gi[bounds[1:] - 1]
            view = np.searchsorted(off, first, side="right") - 1
            width = (g.hi[last] - g.lo[first]) % TAU
            width = np.where(width == 0.0, TAU, width)  # _width
            vs, owns = np.concatenate(q2), np.concatenate(own2)
            back_q = list(vs[view])
            back_sec = list(zip((g.lo[first] + np.pi).tolist(), width.tolist(), strict=True))
            back_own = owns[view].tolist()
    # ... then the placements on the opposite side of v
    if back_q:
        g, off = gaps_many_rings(
            rs, np.asarray(back_own), np.asarray(back_q), sectors=np.asarray(back_sec)
        )
        if flat:
            got, view = _fans_flat(g, off, np.asarray(back_q), g.seg >= 0, 1e-10 * env.scale)
            for f, r in zip(got, np.asarray(back_own)[view].tolist(), strict=True):
                fans[r].append(f)
        else:
            for b, r in enumerate(back_own):
                gb = _slice(g, off[b], off[b + 1], np.asarray(back_q[b]))
                fans[r] += _fans(gb, gb.seg >= 0, doms[r], eps_aim)
    out = []
    for r, dom in enumerate(doms):
        arr = np.asarray(fans[r], dtype=object)
        if not len(arr):
            out.append(shapely.Polygon())
            continue
        thick = shapely.area(arr) > CONTACT_REL * dom.scale * shapely.length(arr)
        nd = int(thick[: n_direct[r]].sum())
        kept = list(arr[thick])
        grid = SNAP_REL * dom.scale
        out.append(_union(kept, n_first=nd, grid=grid) if kept else shapely.Polygon())
    return out


def _padded(cols: list[np.ndarray]) -> np.ndarray | None:
    """Row blocks of different widths stacked, NaN-padded (None when all are empty)."""
    k = max(c.shape[1] for c in cols)
    if k == 0:
        return None
    out = np.full((sum(len(c) for c in cols), k), np.nan)
    at = 0
    for c in cols:
        out[at : at + len(c), : c.shape[1]] = c
        at += len(c)
    return out


def _slice(g: Gaps, a: int, b: int, q: np.ndarray) -> Gaps:
    """Gaps ``a:b`` of a flat result, with ``q`` (the viewpoint, or one row per gap as in a
    flat result)."""
    return Gaps(q=q, lo=g.lo[a:b], hi=g.hi[a:b], seg=g.seg[a:b], p0=g.p0[a:b], p1=g.p1[a:b])


def _runs_flat(g: Gaps, off: np.ndarray, mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_runs` of every viewpoint of a flat result at once (viewpoint ``v`` owns gaps
    ``off[v]:off[v + 1]``): the gap indices of all runs, run after run in the order
    :func:`_runs` lists them viewpoint by viewpoint, and the (R + 1,) offsets of the
    runs in that array."""
    idx = np.flatnonzero(mask)
    if len(idx) == 0:
        return idx, np.zeros(1, dtype=np.int64)
    n_v = len(off) - 1
    owner = np.repeat(np.arange(n_v), np.diff(off))
    o = owner[idx]
    new = np.ones(len(idx), dtype=bool)
    new[1:] = (o[1:] != o[:-1]) | ~(np.abs(g.lo[idx[1:]] - g.hi[idx[:-1]]) <= 1e-12)
    run = np.cumsum(new) - 1
    n_runs = np.bincount(o, weights=new, minlength=n_v).astype(np.int64)
    # a viewpoint whose gaps close the circle, masked at both ends, with several runs:
    # its last run continues into its first (listed first, last run's gaps before)
    has = np.diff(off) > 0
    first = np.where(has, off[:-1], 0)
    last = np.where(has, off[1:] - 1, 0)
    closed = has & (np.abs(g.hi[last] - g.lo[first] - TAU) <= 1e-12)
    merge = closed & mask[first] & mask[last] & (n_runs > 1)
    starts = np.flatnonzero(new)
    rv = o[starts]  # viewpoint of each run
    run_first = np.full(n_v, -1, dtype=np.int64)
    run_last = np.full(n_v, -1, dtype=np.int64)
    u, at = np.unique(rv, return_index=True)  # runs are in viewpoint order
    run_first[u] = at
    run_last[u] = np.concatenate([at[1:], [len(rv)]]) - 1
    in_last = merge[o] & (run == run_last[o])
    label = np.where(in_last, run_first[o], run)
    order = np.lexsort((np.arange(len(idx)), ~in_last, o))
    label = label[order]
    bounds = np.flatnonzero(np.concatenate([[True], label[1:] != label[:-1], [True]]))
    return idx[order], bounds


def _fans_flat(g: Gaps, off: np.ndarray, q: np.ndarray, mask: np.ndarray, tol: float) -> tuple:
    """:func:`_fans` with ``eps_aim == 0`` for every viewpoint of a flat result at once
    (viewpoint ``v``, at ``q[v]``, owns gaps ``off[v]:off[v + 1]``): the fans, in the
    order :func:`_fans` gives them viewpoint by viewpoint, and the viewpoint of each.
    The same points are kept and :func:`geometry._vis.clean_polygon`'s rule is applied
    to each ring (``tol``: its tolerance), so every polygon is the one :func:`_fans`
    builds."""
    gi, bounds = _runs_flat(g, off, mask)
    n_runs = len(bounds) - 1
    if n_runs == 0:
        return [], np.zeros(0, dtype=np.int64)
    owner = np.repeat(np.arange(len(off) - 1), np.diff(off))
    ln = np.diff(bounds)
    rid = np.repeat(np.arange(n_runs), ln)
    m = np.arange(len(gi)) - bounds[rid]
    seg = g.seg[gi]
    same_next = np.zeros(len(gi), dtype=bool)
    same_next[:-1] = seg[1:] == seg[:-1]
    same_next &= m < ln[rid] - 1
    same_prev = np.zeros(len(gi), dtype=bool)
    same_prev[1:] = seg[1:] == seg[:-1]
    same_prev &= m > 0
    # per run: the viewpoint, then p0 and p1 of each gap
    base = np.arange(n_runs) + 2 * bounds[:-1]
    total = n_runs + 2 * len(gi)
    pts = np.empty((total, 2))
    keep = np.empty(total, dtype=bool)
    ring = np.empty(total, dtype=np.int64)
    view = owner[gi[bounds[:-1]]]
    pts[base] = q[view]
    keep[base] = True
    ring[base] = np.arange(n_runs)
    at0 = base[rid] + 1 + 2 * m
    pts[at0], keep[at0], ring[at0] = g.p0[gi], ~same_prev, rid
    pts[at0 + 1], keep[at0 + 1], ring[at0 + 1] = g.p1[gi], ~same_next, rid
    pts, ring = pts[keep], ring[keep]
    # clean_polygon: drop the points within tol of their successor (around the ring)
    cnt = np.bincount(ring, minlength=n_runs)
    start = np.concatenate([[0], np.cumsum(cnt)])
    nxt = np.arange(1, len(pts) + 1)
    ends = start[1:] - 1
    nxt[ends[cnt > 0]] = start[:-1][cnt > 0]
    step = np.abs(pts[nxt] - pts).max(axis=1)
    ok = step > tol
    pts, ring = pts[ok], ring[ok]
    cnt = np.bincount(ring, minlength=n_runs)
    out = np.empty(n_runs, dtype=object)
    small = cnt < 3
    out[small] = [shapely.Polygon() for _ in range(int(small.sum()))]
    big = np.flatnonzero(~small)
    if len(big):
        sel = ~small[ring]
        renum = np.cumsum(~small) - 1
        rings = shapely.linearrings(pts[sel], indices=renum[ring[sel]])
        polys = shapely.polygons(rings)
        bad = ~shapely.is_valid(polys)
        for b in np.flatnonzero(bad):  # clean_polygon's repair
            parts = shapely.get_parts(shapely.make_valid(polys[b]))
            parts = parts[np.isin(shapely.get_type_id(parts), (3, 6))]
            polys[b] = shapely.union_all(parts) if len(parts) else shapely.Polygon()
        out[big] = polys
    return list(out), view
