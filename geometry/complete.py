"""Complete visibility (paper section 3.1): placements with an unobstructed view.

Let K be the convex hull of what must be seen (the target A_q, the swept area
A_theta (+) G of a translating target, or G (+) disc(r) of a target that also
rotates).  Under the paper's assumption that no obstacle meets K, a placement p
sees the whole target iff the triangle fan conv({p} u K) meets no obstacle.

Such a region is star-shaped from every point c of K, and (proof in
``docs/DESIGN.md``) its complement in the free space is the union of

* the points not visible from c, and
* for every convex obstacle corner u (a reflex vertex of the free space) the
  wedge W_u = u + cone(u - K) between the two inner tangents from u to K
  (paper step 1-2: "local inner tangents ... extended away from the vertex").

So the region is V(c) minus the wedges minus the target's area: one exact
visibility polygon plus a vectorised wedge construction; boundaries are
obstacle edges and tangent rays, nothing is sampled.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
import shapely

from ._common import (
    TargetSpec,
    check_eps,
    polygonal,
    scene_domain,
    shrink_for_position,
    target_spec,
)
from ._vis import visibility_polygon

if TYPE_CHECKING:  # pragma: no cover
    from .scene import Scene

__all__ = ["complete_region", "tangent_wedges"]


def complete_region(
    scene: Scene,
    *,
    target_at: tuple[float, float, float] | None = None,
    target_in: str | shapely.Geometry | None = None,
    theta: float | None = 0.0,
    eps_pos: float = 0.0,
) -> shapely.Geometry:
    """Sensor placements from which the target is completely visible.

    Parameters
    ----------
    scene : the environment.
    target_at : ``(x, y, theta)`` of a stationary target (world frame, radians).
    target_in : ``"goal"``, ``"failure"`` or a shapely Polygon/Point: the target's
        reference point may be anywhere in this region.
    theta : orientation (radians) of a translating target; ``None`` means any
        orientation (the swept goal region M(G, A) = G (+) disc(r), paper 3.1.2).
    eps_pos : worst-case placement error (scene units); shadows are grown by this
        disc (paper section 4).

    Returns
    -------
    A shapely Polygon/MultiPolygon in world coordinates (possibly empty): the
    placements inside the bounds, outside every obstacle and outside the
    target's (swept) area, from which every point of the target is visible for
    every admitted target configuration.
    """
    eps_pos = check_eps("eps_pos", eps_pos)
    spec = target_spec(scene, target_at, target_in, theta)
    region = _complete(scene, spec)
    if eps_pos > 0:
        allowed = shapely.difference(scene.free_space, spec.area)
        region = shrink_for_position(region, allowed, eps_pos)
    return region


def _complete(scene: Scene, spec: TargetSpec) -> shapely.Geometry:
    dom = scene_domain(scene)
    vis = visibility_polygon(dom, spec.center)
    u = dom.vert[dom.reflex]
    wedges, k_lo, k_hi = tangent_wedges(u, spec, dom.scale)
    if len(wedges):
        # A wedge side bounds the region only if the obstacle stays on one side of
        # it at u (otherwise the tangent enters the obstacle right at u).
        prev, nxt = dom.vert_prev[dom.reflex], dom.vert_next[dom.reflex]
        wedges = wedges[_grazes(u, k_lo, prev, nxt) | _grazes(u, k_hi, prev, nxt)]
    if len(wedges):
        shapely.prepare(vis)
        wedges = wedges[shapely.intersects(vis, wedges)]
    shadow = shapely.union_all(wedges) if len(wedges) else shapely.Polygon()
    blocked = shapely.union(shadow, spec.area)
    return polygonal(shapely.difference(vis, blocked))


def tangent_wedges(
    u: np.ndarray, spec: TargetSpec, scale: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Wedges u + cone(u - K) at points ``u``.

    Each wedge is bounded by the two tangents from ``u`` to the convex set K
    (hull vertices ``spec.hull_pts``, each grown by ``spec.radius``) and is
    clipped at distance ``scale`` from its apex (beyond the scene).

    Returns the wedges (array of shapely Polygons) and the two tangent points
    on K, ``(U, 2)`` arrays, of the wedge's clockwise and counter-clockwise sides.
    """
    if len(u) == 0:
        return np.empty(0, dtype=object), np.empty((0, 2)), np.empty((0, 2))
    k = spec.hull_pts
    base = np.arctan2(u[:, 1] - spec.center[1], u[:, 0] - spec.center[0])
    dx = u[:, None, 0] - k[None, :, 0]
    dy = u[:, None, 1] - k[None, :, 1]
    ang = np.arctan2(dy, dx)
    rel = (ang - base[:, None] + np.pi) % (2 * np.pi) - np.pi
    if spec.radius > 0:
        dist = np.hypot(dx, dy)
        spread = np.arcsin(np.clip(spec.radius / np.maximum(dist, 1e-300), 0.0, 1.0))
        i_lo = np.argmin(rel - spread, axis=1)
        i_hi = np.argmax(rel + spread, axis=1)
        rows = np.arange(len(u))
        lo = (rel - spread)[rows, i_lo]
        hi = (rel + spread)[rows, i_hi]
    else:
        i_lo = np.argmin(rel, axis=1)
        i_hi = np.argmax(rel, axis=1)
        rows = np.arange(len(u))
        lo = rel[rows, i_lo]
        hi = rel[rows, i_hi]
    half = 0.5 * (hi - lo)
    mid = base + 0.5 * (hi + lo)
    reach = 1.01 * scale
    far = reach / np.maximum(np.cos(np.minimum(half, np.pi / 2)), 1e-6)
    a_lo = base + lo
    a_hi = base + hi
    ring = np.stack(
        [
            u,
            u + reach * np.stack([np.cos(a_lo), np.sin(a_lo)], axis=1),
            u + far[:, None] * np.stack([np.cos(mid), np.sin(mid)], axis=1),
            u + reach * np.stack([np.cos(a_hi), np.sin(a_hi)], axis=1),
        ],
        axis=1,
    )
    k_lo = _tangent_point(u, a_lo, k[i_lo], spec.radius)
    k_hi = _tangent_point(u, a_hi, k[i_hi], spec.radius)
    return shapely.polygons(ring), k_lo, k_hi


def _tangent_point(u: np.ndarray, ang: np.ndarray, k: np.ndarray, radius: float) -> np.ndarray:
    """Where the line through ``u`` at angle ``ang`` touches K: the hull vertex
    ``k`` itself, or the foot of ``k`` on the line for discs of ``radius``."""
    if radius <= 0:
        return k
    e = np.stack([np.cos(ang), np.sin(ang)], axis=1)
    return u + ((k - u) * e).sum(axis=1)[:, None] * e


def _grazes(u: np.ndarray, k: np.ndarray, prev: np.ndarray, nxt: np.ndarray) -> np.ndarray:
    """True where the line through ``u`` and ``k`` has both ring neighbours of
    ``u`` on the same (closed) side."""
    d = k - u
    a = d[:, 0] * (prev - u)[:, 1] - d[:, 1] * (prev - u)[:, 0]
    b = d[:, 0] * (nxt - u)[:, 1] - d[:, 1] * (nxt - u)[:, 0]
    return a * b >= 0
