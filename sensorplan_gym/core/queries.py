"""Per-step queries for N poses at once: is the placement in the exact recognizable region,
how far is it from it, does the aim keep G and H in view.

Everything here reads arrays that :class:`~.world.World` precomputed once
(:meth:`World.batch_rows`); no shapely geometry is built per step.  The region test is
shapely's exact ``contains_xy`` on the (prepared) exact region -- vectorised over an array
of regions, one per sub-environment -- never a raster.
"""

from __future__ import annotations

import math

import numpy as np
import shapely

from .kernels import libm
from .segments import point_segment_distance

__all__ = ["aim_ok_batch", "hull_arcs", "in_region_batch", "joint_arc", "region_distance_batch"]

TWO_PI = 2 * math.pi


def _wrap(a):
    return (a + math.pi) % TWO_PI - math.pi


def in_region_batch(regions, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """``(N,)`` bool: point ``i`` lies in ``regions[i]`` (one geometry, or an object array of
    N prepared geometries), by shapely's exact ``contains_xy``."""
    return shapely.contains_xy(regions, x, y)


def region_distance_batch(rows, x: np.ndarray, y: np.ndarray, inside: np.ndarray) -> np.ndarray:
    """Euclidean distance ``(N,)`` from point ``i`` to the region of row ``i``: 0 where
    ``inside``, ``inf`` where the region is empty; ``rows``: boundary segments, one set for
    all or ``(N, R)`` rows (padding never nearest)."""
    d = point_segment_distance(x, y, rows)
    d[inside] = 0.0
    d[d >= 1e14] = np.inf  # only padding: the region is empty
    return d


def aim_ok_batch(
    x: np.ndarray,
    y: np.ndarray,
    psi: np.ndarray,
    hulls: np.ndarray,
    centers: np.ndarray,
    *,
    fov,
    eps_aim,
    eps_pos,
    max_range,
) -> np.ndarray:
    """``(N,)`` bool: aim ``psi`` (radians) from ``(x, y)`` keeps the convex hulls K_G and K_H
    inside the field of view for every aim in ``psi +- eps_aim`` and every placement within
    ``eps_pos`` (the angular margin grows by ``asin(eps_pos / dist(p, K))``), and within
    ``max_range`` (farthest hull vertex + ``eps_pos``).

    ``hulls``: ``(N, 2, K, 2)`` counter-clockwise hull vertices (world frame) padded by
    repeating the last vertex; ``centers``: ``(N, 2, 2)`` vertex means of the unpadded
    hulls; ``fov``, ``eps_aim``, ``eps_pos``, ``max_range``: scalars or ``(N,)``."""
    n = x.shape[0]
    fov, eps_aim, eps_pos, max_range = (
        np.broadcast_to(np.asarray(v, dtype=np.float64), (n,))
        for v in (fov, eps_aim, eps_pos, max_range)
    )
    full = fov >= TWO_PI - 1e-12
    ok = np.ones(n, dtype=bool)
    if full.all() and np.isinf(max_range).all():
        return ok
    dvx = hulls[..., 0] - x[:, None, None]  # (N, 2, K)
    dvy = hulls[..., 1] - y[:, None, None]
    # libm's atan2 / asin and sqrt(x^2 + y^2): the compiled kernel's expressions, bitwise
    dist = np.sqrt(dvx * dvx + dvy * dvy)
    ok &= ~(dist.max(axis=(1, 2)) + eps_pos > max_range)
    part = ~full & ok
    if not part.any():
        return ok
    # p strictly outside convex K (CCW): some edge has p on its right
    ex = np.roll(hulls[..., 0], -1, axis=2) - hulls[..., 0]
    ey = np.roll(hulls[..., 1], -1, axis=2) - hulls[..., 1]
    inside = np.all(ex * (-dvy) - ey * (-dvx) >= 0, axis=2).any(axis=1)
    base = libm(math.atan2, centers[..., 1] - y[:, None], centers[..., 0] - x[:, None])  # (N, 2)
    rel = _wrap(libm(math.atan2, dvy, dvx) - base[..., None])
    off = _wrap(base - psi[:, None])
    margin = np.broadcast_to(eps_aim[:, None], off.shape).copy()
    pos = eps_pos > 0
    if pos.any():
        L2 = np.maximum(ex * ex + ey * ey, 1e-300)
        t = np.clip((dvx * -ex + dvy * -ey) / L2, 0, 1)
        qx, qy = -dvx - t * ex, -dvy - t * ey
        dmin = np.min(np.sqrt(qx * qx + qy * qy), axis=2)
        extra = libm(math.asin, np.minimum(1.0, eps_pos[:, None] / np.maximum(dmin, 1e-300)))
        margin = margin + np.where(pos[:, None], extra, 0.0)
    half = 0.5 * fov[:, None]
    bad = (off + rel.min(axis=2) < -half + margin) | (off + rel.max(axis=2) > half - margin)
    ok &= ~(part & (inside | bad.any(axis=1)))
    return ok


def hull_arcs(
    hulls: np.ndarray, x: np.ndarray, y: np.ndarray, tol: np.ndarray | float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """The angular interval each convex hull covers as seen from point ``i``.

    ``hulls``: ``(N, M, K, 2)`` counter-clockwise vertices (world frame), padded by repeating
    a vertex; ``x``, ``y``: ``(N,)``; ``tol``: a point within ``tol`` (scene units, scalar
    or ``(N,)``) of a hull counts as inside it.  Returns ``(start, width)``, both ``(N, M)``
    radians in the world frame: hull ``m`` lies in the directions ``start .. start + width``
    counter-clockwise, ``width`` in ``[0, pi)`` for a point outside the hull and exactly
    ``2 pi`` (with ``start = 0``) for a point in it (every direction meets it).
    """
    dx = hulls[..., 0] - x[:, None, None]  # (N, M, K)
    dy = hulls[..., 1] - y[:, None, None]
    ex = np.roll(hulls[..., 0], -1, axis=2) - hulls[..., 0]
    ey = np.roll(hulls[..., 1], -1, axis=2) - hulls[..., 1]
    # signed distance of the point to each edge's line (left of a CCW edge: inside)
    le = np.hypot(ex, ey)
    cr = ex * -dy - ey * -dx  # cross(e, p - v)
    t = np.broadcast_to(np.asarray(tol, dtype=np.float64), x.shape)[:, None, None]
    inside = ((cr >= -t * le) | (le == 0)).all(axis=2)
    cx, cy = dx.mean(axis=2), dy.mean(axis=2)  # toward the vertices' mean: inside the hull
    ref = np.arctan2(cy, cx)
    rel = _wrap(np.arctan2(dy, dx) - ref[..., None])  # in (-pi, pi): the span is < pi
    lo, hi = rel.min(axis=2), rel.max(axis=2)
    start = np.where(inside, 0.0, (ref + lo) % TWO_PI)
    width = np.where(inside, TWO_PI, hi - lo)
    return start, width


def joint_arc(start: np.ndarray, width: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The shortest arc covering two arcs: ``start``, ``width`` ``(N, 2)`` radians as
    :func:`hull_arcs` returns them.  Returns ``(start, width)`` ``(N,)``: the circle minus
    the larger gap between the two arcs (width ``2 pi`` where they cover the circle or one
    of them is the whole circle)."""
    s1, s2 = start[:, 0], start[:, 1]
    w1, w2 = width[:, 0], width[:, 1]
    d12 = (s2 - s1) % TWO_PI  # where arc 2 starts, counter-clockwise from arc 1's start
    d21 = (s1 - s2) % TWO_PI
    # overlapping: one arc starts inside the other; the union runs from the earlier start
    ov1 = d12 <= w1  # arc 2 starts inside arc 1
    ov2 = ~ov1 & (d21 <= w2)
    g12 = d12 - w1  # the gaps when disjoint: after arc 1, after arc 2
    g21 = d21 - w2
    out_s = np.where(g12 >= g21, s2, s1)  # the covering arc starts where the larger gap ends
    out_w = TWO_PI - np.maximum(g12, g21)
    out_s = np.where(ov1, s1, np.where(ov2, s2, out_s))
    out_w = np.where(ov1, np.maximum(w1, d12 + w2), np.where(ov2, np.maximum(w2, d21 + w1), out_w))
    full = (out_w >= TWO_PI) | (w1 >= TWO_PI) | (w2 >= TWO_PI)
    return np.where(full, 0.0, out_s % TWO_PI), np.where(full, TWO_PI, out_w)
