"""Segment arrays: the environment's edges (walls, obstacles, the hidden target) as the
range sensor, the collision sweep and the clearance queries consume them.

A segment set is six arrays ``x0, y0, ex, ey, nx, ny`` (start point, edge vector
``end - start`` and unit normal, scene units and the world frame) of shape ``(M,)`` for one
set or ``(N, M)`` for one set per sub-environment of a batch.  Sets of different sizes are
padded with zero-length segments far outside every scene: a ray, a sweep or a distance query
never meets them, so padding changes no answer.
"""

from __future__ import annotations

import math

import numpy as np
import shapely

__all__ = [
    "PAD",
    "SegmentRows",
    "Segments",
    "boundary_segments",
    "pad_segments",
    "segment_normals",
]

#: coordinate of the padding segments (zero length, far from any scene)
PAD = 1e15
_FIELDS = ("x0", "y0", "ex", "ey", "nx", "ny")


def _ring_segments(coords: np.ndarray) -> np.ndarray:
    c = np.asarray(coords, dtype=np.float64)
    if len(c) and np.allclose(c[0], c[-1]):
        c = c[:-1]
    return np.concatenate([c, np.roll(c, -1, axis=0)], axis=1)


def boundary_segments(geom: shapely.Geometry) -> np.ndarray:
    """All boundary edges of a (Multi)Polygon as an ``(S, 4)`` array ``x0, y0, x1, y1``."""
    parts = []
    for poly in getattr(geom, "geoms", [geom]):
        if poly.is_empty or poly.geom_type != "Polygon":
            continue
        parts.append(_ring_segments(np.asarray(poly.exterior.coords)))
        parts.extend(_ring_segments(np.asarray(r.coords)) for r in poly.interiors)
    if not parts:
        return np.zeros((0, 4))
    return np.concatenate(parts, axis=0)


def segment_normals(segs: np.ndarray) -> np.ndarray:
    """Unit normals ``(S, 2)`` (the edge vector turned a quarter to the left)."""
    d = segs[:, 2:] - segs[:, :2]
    n = np.stack([-d[:, 1], d[:, 0]], axis=1)
    L = np.hypot(n[:, 0], n[:, 1])
    L[L == 0] = 1.0
    return n / L[:, None]


def pad_segments(segs: np.ndarray, normals: np.ndarray, m: int) -> np.ndarray:
    """``(6, m)`` rows ``x0, y0, ex, ey, nx, ny`` of ``segs`` padded to ``m`` segments."""
    segs = np.asarray(segs, dtype=np.float64).reshape(-1, 4)
    k = segs.shape[0]
    if k > m:
        raise ValueError(f"{k} segments do not fit in {m}")
    out = np.zeros((6, m))
    out[0, k:] = out[1, k:] = PAD
    out[0, :k], out[1, :k] = segs[:, 0], segs[:, 1]
    out[2, :k], out[3, :k] = segs[:, 2] - segs[:, 0], segs[:, 3] - segs[:, 1]
    out[4:, :k] = np.asarray(normals, dtype=np.float64).reshape(-1, 2).T
    return out


class Segments:
    """One segment set as ``(M,)`` arrays (see the module docstring)."""

    __slots__ = ("segs", "x0", "y0", "ex", "ey", "nx", "ny", "L2", "inv_L2", "n", "N")

    def __init__(self, segs: np.ndarray, normals: np.ndarray | None = None) -> None:
        segs = np.ascontiguousarray(segs, dtype=np.float64).reshape(-1, 4)
        self.segs = segs
        self.n = segs.shape[0]
        self.x0 = segs[:, 0].copy()
        self.y0 = segs[:, 1].copy()
        self.ex = segs[:, 2] - segs[:, 0]
        self.ey = segs[:, 3] - segs[:, 1]
        self.L2 = self.ex * self.ex + self.ey * self.ey
        self.inv_L2 = 1.0 / np.where(self.L2 > 0, self.L2, 1.0)
        if normals is None:
            normals = segment_normals(segs) if self.n else np.zeros((0, 2))
        self.N = np.ascontiguousarray(normals, dtype=np.float64).reshape(-1, 2)
        self.nx = self.N[:, 0].copy()
        self.ny = self.N[:, 1].copy()

    def __getstate__(self):
        return {"segs": self.segs, "normals": self.N}

    def __setstate__(self, st):
        self.__init__(st["segs"], st["normals"])

    def __add__(self, other: Segments) -> Segments:
        return Segments(np.concatenate([self.segs, other.segs]), np.concatenate([self.N, other.N]))

    def clearance(self, x: float, y: float) -> float:
        """Distance from ``(x, y)`` to the nearest segment (``inf`` if there are none)."""
        if not self.n:
            return math.inf
        return float(point_segment_distance(np.array([x]), np.array([y]), self)[0])


class SegmentRows:
    """``(N, M)`` segment arrays, one row per sub-environment, written at its reset; grows
    (re-padding every row) when a set needs more than ``M`` segments."""

    def __init__(self, n: int, m: int = 1) -> None:
        self.data = np.zeros((6, n, m))
        self.data[0] = self.data[1] = PAD
        self._views()

    def _views(self) -> None:
        for k, name in enumerate(_FIELDS):
            setattr(self, name, self.data[k])

    @property
    def m(self) -> int:
        return self.data.shape[2]

    def reserve(self, m: int) -> None:
        """Room for ``m`` segments per row (grows, re-padding, when needed)."""
        if m > self.m:
            grow = np.zeros((6, self.data.shape[1], m - self.m))
            grow[0] = grow[1] = PAD
            self.data = np.concatenate([self.data, grow], axis=2)
            self._views()

    def set_row(self, i: int, rows: np.ndarray) -> None:
        """Row ``i`` := the ``(6, k)`` padded arrays ``rows`` (see :func:`pad_segments`)."""
        k = rows.shape[1]
        if k > self.m:
            grow = np.zeros((6, self.data.shape[1], k - self.m))
            grow[0] = grow[1] = PAD
            self.data = np.concatenate([self.data, grow], axis=2)
            self._views()
        self.data[:, i, :k] = rows
        self.data[:, i, k:] = 0.0
        self.data[0:2, i, k:] = PAD

    def __getstate__(self):
        return {"data": self.data}

    def __setstate__(self, st):
        self.data = st["data"]
        self._views()


def point_segment_distance(px: np.ndarray, py: np.ndarray, S) -> np.ndarray:
    """Distance ``(N,)`` from points ``(px[i], py[i])`` to the nearest segment of ``S`` (a
    :class:`Segments` shared by all points, or ``(N, M)`` rows, one set per point); ``inf``
    when there are none."""
    from .kernels import seg_distance

    rows = [a if a.ndim == 2 else a[None, :] for a in (S.x0, S.y0, S.ex, S.ey)]
    return seg_distance(np.asarray(px, dtype=np.float64), np.asarray(py, dtype=np.float64), *rows)


__all__ += ["point_segment_distance"]
