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

__all__ = ["aim_ok_batch", "in_region_batch", "region_distance_batch"]

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
