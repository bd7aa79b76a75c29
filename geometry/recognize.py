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
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
import shapely

from ._common import (
    _triangles,
    as_scene,
    check_aim,
    check_eps,
    check_eps_pos,
    check_theta,
    polygonal,
    scene_domain,
    shrink_for_position,
    target_spec,
)
from ._frame import world_messages
from .complete import complete_region
from .partial import ROTATING_PARTIAL, _ccw_ring, _swept_region, swept_tol, weak_visibility

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

    tol, conservative : partial model with polygonal G and H (paper 5.2) only:
        the polyline tolerance of the swept shadows (default 1e-4 of the scene
        diameter) and whether to grow the shadows by it so that the answer lies
        inside the exact region (see :func:`partial_region`).

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
    if tol is not None:
        tol = check_eps("tol", tol)
        if tol <= 0:
            raise ValueError(f"tol must be > 0, got {tol!r}")
    fr = scene.frame
    with world_messages(fr):
        out = _recognizable_region(
            scene.local, model, theta, fr.length(eps_pos), eps_aim, fr.length(tol), conservative
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
    if g.geom_type != h.geom_type:
        raise NotImplementedError(
            "recognizable_region(model='partial') needs G and H of the same kind: both points "
            "(paper 5.1) or both polygons (paper 5.2); this scene mixes a point and a polygon"
        )
    if g.geom_type == "Polygon":
        return _swept_recognizable(scene, th, eps_pos, eps_aim, swept_tol(scene, tol), conservative)
    if tol is not None or conservative:
        raise ValueError("tol and conservative apply to polygonal G and H only")
    regions = []
    for me, other in ((g, h), (h, g)):
        spec = target_spec(scene, (me.x, me.y, th), None, None)
        ring, wanted = _split_ring(
            _ccw(spec.area),
            _cuts(_ccw(spec.area), _ccw(scene.target_at(other.x, other.y, th)), scene.diameter),
        )
        ring_cw, wanted_cw = ring[::-1], np.roll(wanted[::-1], -1)
        reg = weak_visibility(scene_domain(scene), ring_cw, wanted_cw, eps_aim)
        reg = polygonal(shapely.difference(reg, spec.area))
        if eps_pos > 0:
            reg = shrink_for_position(reg, shapely.difference(scene.free_space, spec.area), eps_pos)
        regions.append(reg)
    return polygonal(shapely.intersection(*regions))


def _swept_recognizable(
    scene: Scene, theta: float, eps_pos: float, eps_aim: float, tol: float, conservative: bool
) -> shapely.Geometry:
    """Paper 5.2: the non-overlap part A'(q) of the target swept through G and
    through H; the two partial regions intersected."""
    target = _ccw_ring(scene.target_at(0.0, 0.0, theta))
    regions = [
        _swept_region(
            scene,
            me,
            theta,
            eps_pos,
            eps_aim,
            tol,
            conservative,
            strips=overlap_strips(target, scene.region(other)),
        )
        for me, other in (("goal", "failure"), ("failure", "goal"))
    ]
    return polygonal(shapely.intersection(*regions))


def overlap_strips(target: np.ndarray, other: shapely.Polygon) -> list[shapely.Geometry]:
    """Per edge i of ``target`` (counter-clockwise, reference point at the
    origin): U_i = union of e_j (+) X over the edges j with the same direction,
    X the *other* region.  A piece of edge i of A_q (q in this region) inside
    U_i coincides with an edge of A_q' for some q' in X: the overlap O(e_i, e_j)
    of paper 5.2, which cannot tell the two regions apart."""
    e = np.roll(target, -1, axis=0) - target
    u = e / np.hypot(e[:, 0], e[:, 1])[:, None]
    tri = _triangles(other)
    out: list[shapely.Geometry] = []
    for i in range(len(target)):
        same = np.flatnonzero((u @ u[i]) > 1 - 1e-12)
        parts = []
        for j in same:
            a, b = target[j], target[(j + 1) % len(target)]
            pts = np.concatenate([tri + a, tri + b], axis=1)  # (T, 6, 2)
            parts.append(shapely.convex_hull(shapely.multipoints(pts)))
        out.append(shapely.union_all(np.concatenate(parts)))
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
        for i, t0, t1 in _cuts(ag, ah, scene.diameter)
    ]


def _ccw(poly: shapely.Polygon) -> np.ndarray:
    return np.asarray(shapely.orient_polygons(poly, exterior_cw=False).exterior.coords)[:-1, :2]


def _cuts(a: np.ndarray, b: np.ndarray, scale: float) -> list[tuple[int, float, float]]:
    """Overlaps of the CCW edges of ``a`` with same-direction collinear edges of ``b``:
    ``(edge index in a, t0, t1)`` with 0 <= t0 < t1 <= 1 along that edge."""
    tol = 1e-9 * scale
    ea = np.roll(a, -1, axis=0) - a
    eb = np.roll(b, -1, axis=0) - b
    la = np.hypot(ea[:, 0], ea[:, 1])
    lb = np.hypot(eb[:, 0], eb[:, 1])
    ua = ea / la[:, None]
    ub = eb / lb[:, None]
    same = (ua[:, None, :] * ub[None, :, :]).sum(-1) > 1 - 1e-12
    off = b[None, :, :] - a[:, None, :]
    collinear = np.abs(ua[:, None, 0] * off[..., 1] - ua[:, None, 1] * off[..., 0]) <= tol
    out = []
    for i, j in zip(*np.nonzero(same & collinear), strict=False):
        s0 = float(off[i, j] @ ua[i]) / la[i]
        s1 = s0 + lb[j] / la[i]
        t0, t1 = max(0.0, s0), min(1.0, s1)
        if (t1 - t0) * la[i] > tol:
            out.append((int(i), t0, t1))
    return out


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
    between a point of G and a point of H.
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
    tol = 1e-9 * max(scene.diameter, 1.0)
    s = math.hypot(*c)
    base = math.atan2(pts[0, 1], pts[0, 0])
    for i in range(1, len(pts)):
        if abs(r[i] - r[0]) > tol:
            continue
        phi = (math.atan2(pts[i, 1], pts[i, 0]) - base) % (2 * math.pi)
        rot = shapely.affinity.rotate(a, phi, origin=tuple(c), use_radians=True)
        if shapely.symmetric_difference(rot, a).area <= 1e-9 * a.area:
            rho = 2 * s * math.sin(phi / 2)
            if dmin - tol <= rho <= dmax + tol:
                return True
    return False
