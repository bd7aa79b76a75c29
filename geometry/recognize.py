"""Recognizability for error detection and recovery (paper sections 2 and 5).

``recognizable_region`` = R(G) n R(H) - C(G, H): placements from which the
target is detected whether it ended in the goal G or in the failure region H,
and from which those two outcomes cannot be confused.

* Complete model: the sensor sees the whole outline of the target, and an
  outline determines the target's translation, so with G and H disjoint nothing
  is confusable for a translating target: the answer is R(G) n R(H).  With any
  orientation (``theta=None``) a target with rotational symmetry can look the
  same at a configuration in G and one in H; if such a pair exists the answer is
  empty (every placement is confusable), otherwise again R(G) n R(H).
* Partial model, point G and H (5.1): pairs of target edges with the same
  orientation that are collinear and overlap, one on A in G and one on A in H,
  give identical readings (distance and normal).  Those overlap segments are
  removed from the target; what is left is one-sided (the target still occludes)
  and the partial-visibility region of the rest is computed for A in G and for
  A in H and intersected.
* Partial model, polygonal G and H (5.2): the same with strips swept through the
  regions; one point and one polygon: :mod:`geometry.mixed`.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np
import shapely

from ._common import (
    Budget,
    _triangles,
    as_scene,
    check_aim,
    check_eps_pos,
    check_theta,
    check_tol,
    polygonal,
    scene_domain,
    shrink_for_position,
    target_spec,
)
from ._frame import world_messages
from ._shapes import ccw_ring, snapped, union_all
from .complete import complete_region
from .mixed import mixed_recognizable
from .partial import ROTATING_PARTIAL, _swept_region, swept_tol
from .weak import weak_visibility

if TYPE_CHECKING:  # pragma: no cover
    from .scene import Scene

__all__ = ["overlap_segments", "recognizable_region"]


def recognizable_region(
    scene: Scene,
    *,
    model: str = "complete",
    theta: float | None = 0.0,
    eps_pos: float = 0.0,
    eps_aim: float = 0.0,
    tol: float | None = None,
    conservative: bool = False,
    timeout: float | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> shapely.Geometry:
    """Placements from which "target in G" and "target in H" are told apart.

    Parameters
    ----------
    model : ``"complete"`` (the whole target must be visible) or ``"partial"``
        (some non-confusable part of it must be visible).
    theta : target orientation in radians; ``None`` means any orientation
        (complete model only).
    eps_pos : worst-case placement error (scene units), paper section 4.
    eps_aim : worst-case aim error (radians); it shapes the partial model (narrow
        visibility polygons are dropped).  In the complete model it does not
        change *where* to stand; the aim itself is checked against the field of
        view by the caller.

    timeout, progress : partial model with a polygonal G or H (paper 5.2, or one point and
        one polygon) only: a time limit in seconds (:class:`~geometry.sweep.QueryTimeout`
        past it, naming what was left) and a ``progress(done, total)`` callback after
        every swept edge of G and then of H (of the polygonal one when the other is a
        point; see :func:`partial_region`).
    tol, conservative : partial model with a polygonal G or H only: the polyline
        tolerance of the swept shadows (default 1e-4 of the scene diameter) and whether
        to grow the shadows by it so that the answer lies inside the exact region (see
        :func:`partial_region`).  With one point and one polygon
        (:mod:`geometry.mixed`) the point's side is stationary and exact.  A target
        that is not star-shaped sweeps as its convex hull (:mod:`geometry.nonstar`):
        with the overlap strips of this query that gives a certified region *inside*
        the exact one (the pockets swept through G and H are dropped).

    Returns
    -------
    A shapely Polygon/MultiPolygon in world coordinates, possibly empty.  Computed in
    the scene's local frame (see :func:`~geometry.complete_region`); ``scene`` may be a
    scene dictionary.
    """
    if model not in ("complete", "partial"):
        raise ValueError(f"model must be 'complete' or 'partial', got {model!r}")
    scene = as_scene(scene)
    theta = check_theta(theta)
    eps_pos = check_eps_pos(scene, eps_pos)
    eps_aim = check_aim(eps_aim)
    tol = check_tol(tol)
    budget = Budget.make(timeout, progress, "recognizable_region(model='partial')")
    fr = scene.frame
    with world_messages(fr):
        out = _recognizable_region(
            scene.local,
            model,
            theta,
            fr.length(eps_pos),
            eps_aim,
            fr.length(tol),
            conservative,
            budget,
        )
    return fr.to_world(out)


def _recognizable_region(
    scene: Scene,
    model: str,
    theta: float | None,
    eps_pos: float,
    eps_aim: float,
    tol: float | None,
    conservative: bool,
    budget: Budget | None = None,
) -> shapely.Geometry:
    """:func:`recognizable_region` on a scene in its local frame (arguments checked)."""
    if model == "complete":
        if theta is None and symmetric_confusion(scene):
            return shapely.Polygon()
        rg = complete_region(scene, target_in="goal", theta=theta, eps_pos=eps_pos)
        rh = complete_region(scene, target_in="failure", theta=theta, eps_pos=eps_pos)
        return polygonal(shapely.intersection(rg, rh))
    if theta is None:
        raise NotImplementedError(ROTATING_PARTIAL)
    g, h = scene.goal_geom, scene.failure_geom
    th = float(theta)
    if g.geom_type != h.geom_type:  # one point, one polygon: geometry/mixed.py
        poly = g if g.geom_type == "Polygon" else h
        target = ccw_ring(scene.target_at(0.0, 0.0, th))
        acc = _accuracy(scene)
        return mixed_recognizable(
            scene, th, eps_pos, eps_aim, swept_tol(scene, tol), conservative,
            budget or Budget(), overlap_strips(target, poly, *acc), *acc,
        )  # fmt: skip
    if g.geom_type == "Polygon":
        return _swept_recognizable(
            scene, th, eps_pos, eps_aim, swept_tol(scene, tol), conservative, budget or Budget()
        )
    if tol is not None or conservative:
        raise ValueError("tol and conservative apply to polygonal G and H only")
    regions = []
    for me, other in ((g, h), (h, g)):
        spec = target_spec(scene, (me.x, me.y, th), None, None)
        ring, wanted = _split_ring(
            _ccw(spec.area),
            _cuts(_ccw(spec.area), _ccw(scene.target_at(other.x, other.y, th)), *_accuracy(scene)),
        )
        ring_cw, wanted_cw = ring[::-1], np.roll(wanted[::-1], -1)
        reg = weak_visibility(scene_domain(scene), ring_cw, wanted_cw, eps_aim)
        # clipped to the free space (see partial._partial_region)
        allowed = snapped(shapely.difference, scene.free_space, spec.area, scene.snap)
        reg = polygonal(snapped(shapely.intersection, reg, allowed, scene.snap))
        if eps_pos > 0:
            reg = shrink_for_position(reg, shapely.difference(scene.free_space, spec.area), eps_pos)
        regions.append(reg)
    return polygonal(shapely.intersection(*regions))


def _swept_recognizable(
    scene: Scene,
    theta: float,
    eps_pos: float,
    eps_aim: float,
    tol: float,
    conservative: bool,
    budget: Budget,
) -> shapely.Geometry:
    """Paper 5.2: the non-overlap part A'(q) of the target swept through G and
    through H; the two partial regions intersected."""
    target = ccw_ring(scene.target_at(0.0, 0.0, theta))
    n_g, n_h = (
        len(shapely.get_coordinates(scene.region(w).boundary)) - 1 for w in ("goal", "failure")
    )
    regions = [
        _swept_region(
            scene,
            me,
            theta,
            eps_pos,
            eps_aim,
            tol,
            conservative,
            strips=overlap_strips(target, scene.region(other), *_accuracy(scene)),
            budget=dataclasses.replace(budget, offset=off, total=n_g + n_h),
        )
        for (me, other), off in ((("goal", "failure"), 0), (("failure", "goal"), n_g))
    ]
    return polygonal(shapely.intersection(*regions))


def _accuracy(scene: Scene) -> tuple[float, float]:
    """``(rho, cos_max)`` of the confusability test (docs/DESIGN.md, "Sensor accuracy"):
    two readings can agree when their distances differ by at most 2 ``range_acc`` and
    their normals by at most 2 ``normal_acc``; ``rho`` is never below the scene's
    tolerance (1e-9 of its diameter) and ``cos_max`` never above 1 - 1e-12."""
    rho = max(2.0 * scene.range_acc, 1e-9 * scene.diameter)
    cos_max = min(math.cos(min(2.0 * scene.sensor.normal_acc, math.pi / 2)), 1.0 - 1e-12)
    return rho, cos_max


def overlap_strips(
    target: np.ndarray, other: shapely.Polygon, rho: float = 0.0, cos_max: float = 1.0 - 1e-12
) -> list[shapely.Geometry]:
    """Per edge i of ``target`` (counter-clockwise, reference point at the
    origin): U_i = (union of e_j (+) X over the edges j whose direction is within
    ``acos(cos_max)`` of edge i's) grown by ``rho``, X the *other* region.  A piece
    of edge i of A_q (q in this region) outside U_i is farther than ``rho`` from
    every edge of every A_q' (q' in X) whose normal is that close to its own, so no
    reading of it can agree with one of A_q' (the overlap O(e_i, e_j) of paper 5.2,
    widened by the sensor's accuracy).  The growth is a mitred buffer, which
    contains the round one (conservative)."""
    e = np.roll(target, -1, axis=0) - target
    u = e / np.hypot(e[:, 0], e[:, 1])[:, None]
    tri = _triangles(other)
    out: list[shapely.Geometry] = []
    for i in range(len(target)):
        same = np.flatnonzero((u @ u[i]) >= cos_max)
        parts = []
        for j in same:
            a, b = target[j], target[(j + 1) % len(target)]
            pts = np.concatenate([tri + a, tri + b], axis=1)  # (T, 6, 2)
            parts.append(shapely.convex_hull(shapely.multipoints(pts)))
        strip = union_all(np.concatenate(parts))
        if rho > 0:
            strip = shapely.buffer(strip, rho, join_style="mitre", mitre_limit=2.0)
        out.append(strip)
    return out


def overlap_segments(scene: Scene, theta: float = 0.0) -> list[shapely.LineString]:
    """Overlap segments O(e_i, e_j) of point-sized G and H (paper 5.1), world frame.

    Each is a piece of an edge of A in G that coincides, with the same outward
    direction, with a piece of an edge of A in H: readings there cannot tell G
    from H.  Raises ``ValueError`` unless G and H are points.
    """
    scene = as_scene(scene)
    theta = check_theta(theta, allow_none=False)
    g, h = scene.goal_geom, scene.failure_geom
    if g.geom_type != "Point" or h.geom_type != "Point":
        raise ValueError("overlap_segments needs point-sized goal and failure regions")
    fr = scene.frame
    return [fr.to_world(s) for s in _overlap_segments(scene.local, theta)]


def _overlap_segments(scene: Scene, theta: float) -> list[shapely.LineString]:
    g, h = scene.goal_geom, scene.failure_geom
    ag = _ccw(scene.target_at(g.x, g.y, theta))
    ah = _ccw(scene.target_at(h.x, h.y, theta))
    e = np.roll(ag, -1, axis=0) - ag
    return [
        shapely.LineString([ag[i] + t0 * e[i], ag[i] + t1 * e[i]])
        for i, t0, t1 in _cuts(ag, ah, *_accuracy(scene))
    ]


def _ccw(poly: shapely.Polygon) -> np.ndarray:
    return ccw_ring(poly)


def _cuts(
    a: np.ndarray, b: np.ndarray, rho: float, cos_max: float
) -> list[tuple[int, float, float]]:
    """Confusable pieces of the CCW edges of ``a`` against the CCW edges of ``b``:
    ``(edge index in a, t0, t1)`` with 0 <= t0 < t1 <= 1 along that edge, for every
    edge j of ``b`` whose direction is within ``acos(cos_max)`` of edge i's (same
    outward side) -- the points of edge i within ``rho`` of edge j.  That set is one
    interval (the distance to a segment is convex along a line); it is the union of
    the line's intersections with the slab of j and the discs at j's ends."""
    ea = np.roll(a, -1, axis=0) - a
    eb = np.roll(b, -1, axis=0) - b
    la = np.hypot(ea[:, 0], ea[:, 1])
    lb = np.hypot(eb[:, 0], eb[:, 1])
    ua = ea / la[:, None]
    ub = eb / lb[:, None]
    same = (ua[:, None, :] * ub[None, :, :]).sum(-1) >= cos_max
    out = []
    for i, j in zip(*np.nonzero(same), strict=False):
        lo, hi = _near_interval(a[i], ea[i], b[j], ub[j], lb[j], rho)
        t0, t1 = max(0.0, lo), min(1.0, hi)
        if (t1 - t0) * la[i] > 1e-12 * max(la[i], rho):
            out.append((int(i), t0, t1))
    return out


def _near_interval(
    a: np.ndarray, e: np.ndarray, b: np.ndarray, u: np.ndarray, length: float, rho: float
) -> tuple[float, float]:
    """Parameters t (unbounded) of the points a + t e within ``rho`` of the segment
    b -> b + length u, as (lo, hi); lo > hi when there are none."""
    lo, hi = math.inf, -math.inf
    # the slab |(x - b) x u| <= rho, 0 <= (x - b) . u <= length
    w = a - b
    n = np.array([-u[1], u[0]])
    s_lo, s_hi = -math.inf, math.inf
    for c0, c1, bound_lo, bound_hi in (
        (float(w @ n), float(e @ n), -rho, rho),
        (float(w @ u), float(e @ u), 0.0, length),
    ):
        if abs(c1) <= 1e-300:
            if not bound_lo <= c0 <= bound_hi:
                s_lo, s_hi = math.inf, -math.inf
            continue
        r0, r1 = sorted(((bound_lo - c0) / c1, (bound_hi - c0) / c1))
        s_lo, s_hi = max(s_lo, r0), min(s_hi, r1)
    if s_lo <= s_hi:
        lo, hi = min(lo, s_lo), max(hi, s_hi)
    # the discs of radius rho at both ends: |w' + t e|^2 <= rho^2
    ee = float(e @ e)
    for end in (b, b + length * u):
        wq = a - end
        bq = float(wq @ e)
        cq = float(wq @ wq) - rho * rho
        disc = bq * bq - ee * cq
        if disc >= 0 and ee > 0:
            r = math.sqrt(disc)
            lo, hi = min(lo, (-bq - r) / ee), max(hi, (-bq + r) / ee)
    return lo, hi


def _split_ring(
    ring: np.ndarray, cuts: list[tuple[int, float, float]]
) -> tuple[np.ndarray, np.ndarray]:
    """Insert the cut points into a CCW ring; returns (new ring, wanted flag per edge)."""
    pts, wanted = [], []
    e = np.roll(ring, -1, axis=0) - ring
    for i in range(len(ring)):
        marks = {0.0: True, 1.0: True}
        spans = sorted((t0, t1) for k, t0, t1 in cuts if k == i)
        for t0, t1 in spans:
            marks.setdefault(t0, True)
            marks.setdefault(t1, True)
        ts = sorted(marks)
        for a, b in zip(ts[:-1], ts[1:], strict=False):
            mid = 0.5 * (a + b)
            covered = any(t0 <= mid <= t1 for t0, t1 in spans)
            pts.append(ring[i] + a * e[i])
            wanted.append(not covered)
    return np.asarray(pts), np.asarray(wanted)


def symmetric_confusion(scene: Scene) -> bool:
    """True when a target of unknown orientation in G can look exactly like one in H.

    A rotational symmetry of the target by angle phi about its centroid s makes
    the configurations (g, t) and (g + (I - R_phi) R_t s, t + phi) produce the same
    outline; over all t the second reference point runs on a circle of radius
    2 |s| sin(phi / 2) about g.  Confusion exists iff that distance is attained
    between a point of G and a point of H.  With the sensor's accuracy, "the same
    outline" means within Hausdorff distance ``rho`` (2 ``range_acc``, at least the
    scene tolerance) and the distance test is widened by ``rho`` too (conservative:
    more scenes are declared confusable).
    """
    a = scene.target_at(0.0, 0.0, 0.0)
    c = np.asarray(a.centroid.coords[0])
    pts = _ccw(a) - c
    r = np.hypot(pts[:, 0], pts[:, 1])
    g, h = scene.goal_geom, scene.failure_geom
    dmin = g.distance(h)
    gp = shapely.get_coordinates(g.boundary if g.geom_type == "Polygon" else g)
    hp = shapely.get_coordinates(h.boundary if h.geom_type == "Polygon" else h)
    dmax = float(np.max(np.hypot(*(gp[:, None, :] - hp[None, :, :]).transpose(2, 0, 1))))
    tol = _accuracy(scene)[0]
    s = math.hypot(*c)
    base = math.atan2(pts[0, 1], pts[0, 0])
    for i in range(1, len(pts)):
        if abs(r[i] - r[0]) > tol:
            continue
        phi = (math.atan2(pts[i, 1], pts[i, 0]) - base) % (2 * math.pi)
        rot = shapely.affinity.rotate(a, phi, origin=tuple(c), use_radians=True)
        if shapely.hausdorff_distance(rot, a) <= tol:
            rho = 2 * s * math.sin(phi / 2)
            if dmin - tol <= rho <= dmax + tol:
                return True
    return False
