"""Partial-model recognizability with one point-sized and one polygonal region (paper 5).

A placement is recognizable when, wherever the target is in G and wherever it is in H,
it sees (partially) the part of the target that cannot be confused with the target in
the other region: A'(q) = A(q) minus the union over q' in the other region of the
pieces of A(q) that read like pieces of A(q') (same outward normal, within the sensor's
accuracy; paper 5.1-5.2, :func:`geometry.recognize.overlap_strips`).  With G a point g
and H a polygon (or the other way round):

* the point side g: the stationary weak visibility of A(g) with the pieces of its edge
  i inside U_i = (union of e_j (+) H over the edges j of the same direction, grown by
  ``rho``) cut out -- exact for any simple target (no sweep);
* the polygon side H: the swept query of A through H with the strips
  U_i = (union of e_j + g over the same-direction edges j, grown by ``rho``): the
  segments of A(g) themselves, since the other region is one point.  The growth is a
  rectangle around each segment (square caps, mitred), which contains the ``rho``
  neighbourhood (conservative: more is cut).  A target that is not star-shaped sweeps
  as its hull (:mod:`geometry.nonstar`: a certified inner region for this side).

The answer is the intersection of the two.
"""

from __future__ import annotations

import dataclasses
from typing import TYPE_CHECKING

import numpy as np
import shapely

from ._common import (
    Budget,
    polygonal,
    scene_domain,
    shrink_for_position,
    target_spec,
)
from ._shapes import ccw_ring, snapped, union_all
from ._shapes import cross as _cross
from .partial import _swept_region
from .weak import weak_visibility

if TYPE_CHECKING:  # pragma: no cover
    from .scene import Scene

__all__ = ["cut_by_strips", "mixed_recognizable", "point_strips"]


def point_strips(
    target: np.ndarray, point: shapely.Point, rho: float, cos_max: float = 1.0 - 1e-12
) -> list[shapely.Geometry]:
    """Per edge i of ``target`` ((m, 2) counter-clockwise, reference point at the
    origin): U_i = the union of the edges j of A at ``point`` whose direction is within
    ``acos(cos_max)`` of edge i's, each grown to a rectangle ``rho`` wider on every side
    (contains the ``rho`` neighbourhood).  The point-region case of
    :func:`geometry.recognize.overlap_strips`; ``rho`` must be > 0."""
    if not rho > 0:
        raise ValueError(f"point_strips needs rho > 0, got {rho!r}")
    a = np.asarray(target, dtype=float) + np.array([point.x, point.y])
    b = np.roll(a, -1, axis=0)
    e = b - a
    u = e / np.hypot(e[:, 0], e[:, 1])[:, None]
    segs = shapely.linestrings(np.stack([a, b], axis=1))
    grown = shapely.buffer(segs, rho, cap_style="square", join_style="mitre")
    return [union_all(grown[np.flatnonzero((u @ u[i]) >= cos_max)]) for i in range(len(a))]


def cut_by_strips(
    ring: np.ndarray, strips: list[shapely.Geometry]
) -> tuple[np.ndarray, np.ndarray]:
    """The counter-clockwise ``ring`` (m, 2) with the crossings of edge i with the
    boundary of ``strips[i]`` inserted; returns (new ring, wanted flag per new edge:
    False where the piece lies inside its strip)."""
    ring = np.asarray(ring, dtype=float)
    m = len(ring)
    pts, wanted = [], []
    for i in range(m):
        a, e = ring[i], ring[(i + 1) % m] - ring[i]
        strip = strips[i]
        us = [0.0, 1.0]
        if strip is not None and not strip.is_empty:
            segs = [np.zeros((0, 4))]
            for r in shapely.get_parts(shapely.boundary(strip)):  # one ring at a time
                rc = shapely.get_coordinates(r)
                segs.append(np.hstack([rc[:-1], rc[1:]]))
            s = np.vstack(segs)
            c0, d = s[:, :2], s[:, 2:] - s[:, :2]
            den = _cross(e[None, :], d)
            with np.errstate(divide="ignore", invalid="ignore"):
                uu = _cross(c0 - a, d) / den
                ww = _cross(c0 - a, e[None, :]) / den
            ok = np.isfinite(uu) & (uu > 0) & (uu < 1) & (ww >= 0) & (ww <= 1)
            us += uu[ok].tolist()
        us = np.unique(np.asarray(us))
        mids = a + e * (0.5 * (us[:-1] + us[1:]))[:, None]
        if strip is not None and not strip.is_empty:
            inside = shapely.contains_xy(strip, mids[:, 0], mids[:, 1])
        else:
            inside = np.zeros(len(mids), dtype=bool)
        pts.append(a + us[:-1, None] * e)
        wanted.append(~inside)
    return np.vstack(pts), np.concatenate(wanted)


def _point_side(
    scene: Scene,
    point: shapely.Point,
    theta: float,
    strips: list[shapely.Geometry],
    eps_pos: float,
    eps_aim: float,
) -> shapely.Geometry:
    """Placements that see a non-confusable point of A at ``point`` (stationary, exact):
    the weak visibility of its outline minus the pieces inside their strips, clipped to
    the free space minus the target as in the point-point branch."""
    spec = target_spec(scene, (point.x, point.y, theta), None, None)
    target = ccw_ring(scene.target_at(0.0, 0.0, theta))
    ring, wanted = cut_by_strips(target + np.array([point.x, point.y]), strips)
    if not wanted.any():
        return shapely.Polygon()
    ring_cw, wanted_cw = ring[::-1], np.roll(wanted[::-1], -1)
    reg = weak_visibility(scene_domain(scene), ring_cw, wanted_cw, eps_aim)
    allowed = snapped(shapely.difference, scene.free_space, spec.area, scene.snap)
    reg = polygonal(snapped(shapely.intersection, reg, allowed, scene.snap))
    if eps_pos > 0:
        reg = shrink_for_position(reg, shapely.difference(scene.free_space, spec.area), eps_pos)
    return reg


def mixed_recognizable(
    scene: Scene,
    theta: float,
    eps_pos: float,
    eps_aim: float,
    tol: float,
    conservative: bool,
    budget: Budget,
    strips_vs_polygon: list[shapely.Geometry],
    rho: float,
    cos_max: float,
) -> shapely.Geometry:
    """The partial-model recognizable region (local frame, arguments checked) of a scene
    whose G and H are one point and one polygon.  ``strips_vs_polygon``: the overlap
    strips of the target against the polygonal region
    (:func:`geometry.recognize.overlap_strips`); ``rho``, ``cos_max``: the sensor's
    accuracy (:func:`geometry.recognize._accuracy`).  ``tol``, ``conservative`` and
    ``budget`` (its progress counts the edges of the polygonal region) apply to the
    polygon side's sweep; the point side is exact.  Returns a Polygon/MultiPolygon."""
    names = ("goal", "failure")
    pt_name = next(w for w in names if scene.region(w).geom_type == "Point")
    poly_name = next(w for w in names if w != pt_name)
    point = scene.region(pt_name)
    target = ccw_ring(scene.target_at(0.0, 0.0, theta))
    n_poly = len(shapely.get_coordinates(scene.region(poly_name).boundary)) - 1
    swept = _swept_region(
        scene,
        poly_name,
        theta,
        eps_pos,
        eps_aim,
        tol,
        conservative,
        strips=point_strips(target, point, rho, cos_max),
        budget=dataclasses.replace(budget, offset=0, total=n_poly),
    )
    if swept.is_empty:
        return swept
    still = _point_side(scene, point, theta, strips_vs_polygon, eps_pos, eps_aim)
    return polygonal(shapely.intersection(swept, still))
