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

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
import shapely

from ._common import (
    OUTER,
    QUAD_SEGS,
    Budget,
    as_scene,
    check_aim,
    check_eps,
    check_eps_pos,
    check_pose,
    check_theta,
    polygonal,
    scene_domain,
    shrink_for_position,
    target_spec,
)
from ._frame import world_messages
from ._vis import TAU, Domain, Gaps, clean_polygon, gaps_many
from .sweep import swept_shadows

if TYPE_CHECKING:  # pragma: no cover
    from .scene import Scene

__all__ = ["partial_region", "weak_visibility"]

#: Segment tags inside the visibility domain.
ENV, WANTED, UNWANTED = 0, 1, 2

ROTATING_PARTIAL = (
    "the partial-visibility model for a target of unknown orientation (theta=None) is not "
    "given by the paper (its conclusion leaves it to future work); use model='complete' "
    "or a fixed theta"
)


def partial_region(
    scene: Scene,
    *,
    target_at: tuple[float, float, float] | None = None,
    target_in: str | shapely.Geometry | None = None,
    theta: float | None = 0.0,
    eps_pos: float = 0.0,
    eps_aim: float = 0.0,
    tol: float | None = None,
    conservative: bool = False,
    timeout: float | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> shapely.Geometry:
    """Sensor placements from which some point of the target is visible.

    Parameters
    ----------
    target_at : ``(x, y, theta)`` of a stationary target (world frame, radians).
    target_in : ``"goal"``, ``"failure"`` or a shapely Polygon/Point: the target
        translates through this region at orientation ``theta`` and the answer is
        the placements that see some point of it *wherever* it is there (the
        complement of the swept shadows, paper 3.2.2-3.2.3, :mod:`geometry.sweep`).
    theta : orientation (radians) of a target given by ``target_in``; ``None``
        (any orientation) is not supported in the partial model.
    eps_pos : worst-case placement error (scene units): shadows grown by the disc.
    eps_aim : worst-case aim error (radians): visibility polygons whose apex angle
        at their anchor vertex is below ``eps_aim`` are dropped (paper section 4).
        With ``target_in`` it shapes the shadows at the sample configurations; the
        traces between samples are validated by the exact (aim-free) point test, so
        shadow edges that exist only because of ``eps_aim`` are not traced between
        samples (the answer may keep placements that the construction would drop
        at an intermediate configuration).
    tol : only with ``target_in``: the shadow boundaries traced by free vertices
        (lines and conics) are emitted as polylines whose chords stay within
        ``tol`` (scene units) of the curves; default ``1e-4 * scene.diameter``.
    timeout : only with ``target_in``: a time limit in seconds; past it the query
        raises :class:`~geometry.sweep.QueryTimeout` (a ``TimeoutError``) naming
        the edges of the region's boundary left to sweep.  ``None``: no limit.
    progress : only with ``target_in``: ``progress(done, total)`` is called after
        every swept edge of the region's boundary.
    conservative : only with ``target_in``: grow the shadows by ``tol``, so that
        the answer lies inside the exact region as long as the sweep misses no
        shadow deeper than ``tol`` (none deeper than 0.003 ``tol`` was measured;
        see docs/DESIGN.md, "What is and is not guaranteed").

    Returns
    -------
    A shapely Polygon/MultiPolygon (possibly empty) in world coordinates: the
    placements inside the bounds, outside obstacles and outside the target (for
    ``target_in``: outside the area the target sweeps).  Computed in the scene's local
    frame (see :func:`~geometry.complete_region`); ``scene`` may be a scene dictionary.
    """
    scene = as_scene(scene)
    theta = check_theta(theta)
    target_at = check_pose(target_at)
    eps_pos = check_eps_pos(scene, eps_pos)
    eps_aim = check_aim(eps_aim)
    if tol is not None:
        tol = check_eps("tol", tol)
        if tol <= 0:
            raise ValueError(f"tol must be > 0, got {tol!r}")
    budget = Budget.make(timeout, progress, "partial_region(target_in=...)")
    if target_in is None and (timeout is not None or progress is not None):
        raise ValueError("timeout and progress apply to a moving target (target_in=...) only")
    fr = scene.frame
    with world_messages(fr):
        out = _partial_region(
            scene.local,
            fr.pose(target_at),
            fr.region(target_in),
            theta,
            fr.length(eps_pos),
            eps_aim,
            fr.length(tol),
            conservative,
            budget,
        )
    return fr.to_world(out)


def _partial_region(
    scene: Scene,
    target_at: tuple[float, float, float] | None,
    target_in: str | shapely.Geometry | None,
    theta: float | None,
    eps_pos: float,
    eps_aim: float,
    tol: float | None,
    conservative: bool,
    budget: Budget | None = None,
) -> shapely.Geometry:
    """:func:`partial_region` on a scene in its local frame (arguments checked)."""
    if target_in is not None:
        if target_at is not None:
            raise ValueError("give exactly one of target_at=(x, y, theta) or target_in=<region>")
        return _swept_region(
            scene, target_in, theta, eps_pos, eps_aim, tol, conservative, budget=budget
        )
    if tol is not None or conservative:
        raise ValueError("tol and conservative apply to a moving target (target_in=...) only")
    if target_at is None:
        raise ValueError("give target_at=(x, y, theta)")
    spec = target_spec(scene, target_at, None, theta)
    ring = _hole_ring(spec.area)
    region = weak_visibility(scene_domain(scene), ring, np.ones(len(ring), dtype=bool), eps_aim)
    # clipped to the free space: an anchor on a target edge that lies flush against an
    # obstacle (touching within the scene's tolerance) may be inside that obstacle by
    # rounding, and its fan then fills the obstacle (issue 10, fuzz seed 223)
    allowed = shapely.difference(scene.free_space, spec.area)
    region = polygonal(shapely.intersection(region, allowed))
    if eps_pos > 0:
        region = shrink_for_position(region, allowed, eps_pos)
    return region


def _swept_region(
    scene: Scene,
    target_in: str | shapely.Geometry,
    theta: float | None,
    eps_pos: float,
    eps_aim: float,
    tol: float | None,
    conservative: bool,
    strips: list[shapely.Geometry] | None = None,
    budget: Budget | None = None,
) -> shapely.Geometry:
    """The partial region of a target translating through ``target_in``."""
    budget = budget or Budget()
    if theta is None:
        raise NotImplementedError(ROTATING_PARTIAL)
    tol = swept_tol(scene, tol)
    spec = target_spec(scene, None, target_in, float(theta))
    region = scene.region(target_in) if isinstance(target_in, str) else target_in
    target = _ccw_ring(scene.target_at(0.0, 0.0, float(theta)))
    shadows, _ = swept_shadows(
        scene_domain(scene),
        scene.free_space,
        target,
        region,
        strips=strips,
        eps_aim=eps_aim,
        tol=tol,
        deadline=budget.deadline,
        progress=budget.report if budget.progress is not None else None,
        what=budget.what,
    )
    if conservative:
        shadows = shapely.buffer(shadows, tol * OUTER, quad_segs=QUAD_SEGS)
    allowed = shapely.difference(scene.free_space, spec.area)
    out = polygonal(shapely.difference(allowed, shadows))
    if eps_pos > 0:
        out = shrink_for_position(out, allowed, eps_pos)
    return out


def swept_tol(scene: Scene, tol: float | None) -> float:
    """Validate ``tol`` (scene units, > 0); ``None`` gives 1e-4 of the scene diameter."""
    if tol is None:
        return 1e-4 * scene.diameter
    t = check_eps("tol", tol)
    if t <= 0:
        raise ValueError(f"tol must be > 0, got {tol!r}")
    return t


def _ccw_ring(poly: shapely.Polygon) -> np.ndarray:
    return np.asarray(shapely.orient_polygons(poly, exterior_cw=False).exterior.coords)[:-1, :2]


def _hole_ring(poly: shapely.Polygon) -> np.ndarray:
    """Exterior of ``poly`` clockwise (free space on the left), no closing vertex."""
    c = np.asarray(shapely.orient_polygons(poly, exterior_cw=True).exterior.coords)[:-1, :2]
    return c


def weak_visibility(
    env: Domain, ring: np.ndarray, wanted: np.ndarray, eps_aim: float = 0.0
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

    Returns
    -------
    Union of the visibility triangles (shapely geometry, world frame), not yet
    clipped against the target itself.
    """
    dom = env.with_ring(ring, UNWANTED, np.where(wanted, WANTED, UNWANTED))
    fans: list[shapely.Geometry] = []
    # 1. anchors on the target: endpoints of wanted pieces, seen from the front
    #    of a wanted edge at that vertex
    edge = np.roll(ring, -1, axis=0) - ring
    inc = np.stack([wanted, np.roll(wanted, 1)], axis=1)  # outgoing, incoming edge wanted
    anchors = np.flatnonzero(inc.any(axis=1))
    if len(anchors):
        e_out, e_in = edge[anchors], np.roll(edge, 1, axis=0)[anchors]
        dirs = np.stack([e_out, e_in], axis=1)  # (k, 2, 2)
        ang = np.arctan2(dirs[..., 1], dirs[..., 0])
        extra = np.concatenate([ang + np.pi, ang], axis=1)
        for gi, i in zip(gaps_many(dom, ring[anchors], extra=extra), anchors, strict=False):
            mid = 0.5 * (gi.lo + gi.hi)
            d = np.stack([np.cos(mid), np.sin(mid)], axis=1)
            front = np.zeros(len(mid), dtype=bool)
            for e, use in ((edge[i], wanted[i]), (edge[i - 1], wanted[i - 1])):
                if use:
                    front |= e[0] * d[:, 1] - e[1] * d[:, 0] > 0
            fans += _fans(gi, front & (gi.seg >= 0), dom, eps_aim)
    n_direct = len(fans)
    # 2. grazing anchors: reflex vertices v of the free space around the target;
    #    first the directions in which v sees a wanted piece ...
    v = dom.vert[dom.reflex]
    if len(v):
        rel = np.arctan2(ring[None, :, 1] - v[:, None, 1], ring[None, :, 0] - v[:, None, 0])
        centre = ring.mean(axis=0)
        base = np.arctan2(centre[1] - v[:, 1], centre[0] - v[:, 0])
        rel = (rel - base[:, None] + np.pi) % TAU - np.pi
        on_target = np.abs(ring[None, :, :] - v[:, None, :]).max(axis=2) <= 1e-12 * dom.scale
        lo = np.where(on_target, np.inf, rel).min(axis=1)
        hi = np.where(on_target, -np.inf, rel).max(axis=1)
        ok = hi - lo > 1e-12
        v, sectors = v[ok], np.stack([base[ok] + lo[ok], hi[ok] - lo[ok]], axis=1)
        g, off = gaps_many(dom, v, sectors=sectors, flat=True)
        sees = (g.seg >= 0) & (dom.seg_tag[np.maximum(g.seg, 0)] == WANTED)
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
    if not fans:
        return shapely.Polygon()
    return _union(fans, n_first=n_direct)


def _union(polys: list[shapely.Geometry], n_first: int) -> shapely.Geometry:
    """Union of polygons; the later ones are first tested (vectorised) against the
    union of the first ``n_first`` and dropped when already covered by it."""
    first = shapely.union_all(polys[:n_first]) if n_first else shapely.Polygon()
    rest = np.asarray(polys[n_first:], dtype=object)
    if len(rest) and not first.is_empty:
        shapely.prepare(first)
        rest = rest[~shapely.covers(first, rest)]
    if len(rest) == 0:
        return first
    return shapely.union_all(np.concatenate([[first], rest]))


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
