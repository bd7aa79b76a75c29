"""The point-and-shoot range sensor of the paper (section 2), vectorised.

A sensor at pose ``(x, y, psi)`` casts a fan of ``n_beams`` beams spread evenly
over the field of view ``fov`` (radians) centred on ``psi``; with a full 360-degree
field of view the beams are ``2 pi / n`` apart and none is duplicated.  Each beam
returns the distance to the first segment it hits -- walls, obstacles and, when
present, the target's edges -- and the unit surface normal there, turned to face
the sensor.  A beam that hits nothing within ``max_range`` returns
``max_range`` and a zero normal.  The sensor does not say *what* it hit.

Optional Gaussian noise (standard deviation ``noise``, scene units) is added to
the hit distances, which are then clipped to ``[0, max_range]``; normals are
noise-free.  All work is one broadcast over beams x segments (no per-beam Python
loop): about 15 numpy operations on ``(n_beams, n_segments)`` arrays.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["RangeSensor", "Segments", "cast_rays"]


class Segments:
    """An ``(S, 4)`` segment array with the per-segment constants that the ray cast, the
    collision sweep and the clearance query use, laid out for a few matrix products."""

    __slots__ = ("segs", "x0", "y0", "ex", "ey", "nx", "ny", "L2", "inv_L2", "n", "M", "Q", "N")

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
            L = np.sqrt(np.where(self.L2 > 0, self.L2, 1.0))
            normals = np.stack([-self.ey / L, self.ex / L], axis=1)
        self.N = np.ascontiguousarray(normals, dtype=np.float64).reshape(-1, 2)
        self.nx = self.N[:, 0].copy()
        self.ny = self.N[:, 1].copy()
        x0, y0, ex, ey, n = self.x0, self.y0, self.ex, self.ey, self.n
        # [dx, dy, dx*oy - dy*ox] @ M = [cross(d, e) | cross(a - o, d)]
        M = np.zeros((3, 2 * n))
        M[0, :n], M[0, n:] = ey, -y0
        M[1, :n], M[1, n:] = -ex, x0
        M[2, n:] = 1.0
        self.M = M
        # [1, ox, oy] @ Q = [cross(a - o, e) | n . (o - a)]
        Q = np.empty((3, 2 * n))
        Q[0, :n], Q[0, n:] = x0 * ey - y0 * ex, -(self.nx * x0 + self.ny * y0)
        Q[1, :n], Q[1, n:] = -ey, self.nx
        Q[2, :n], Q[2, n:] = ex, self.ny
        self.Q = Q

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
        px = x - self.x0
        py = y - self.y0
        t = (px * self.ex + py * self.ey) * self.inv_L2
        np.minimum(t, 1.0, out=t)
        np.maximum(t, 0.0, out=t)
        px -= t * self.ex
        py -= t * self.ey
        return math.sqrt(float(np.min(px * px + py * py)))


_ERR = {"divide": "ignore", "invalid": "ignore", "over": "ignore"}


def cast_rays(
    ox: float, oy: float, psi: float, dirs: np.ndarray, S: Segments, max_range: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """First hits of the rays from ``(ox, oy)`` with directions ``dirs`` (``(n, 2)`` unit
    vectors in the sensor frame) turned by ``psi``, against the segments ``S``.

    Returns ``dist (n,)``, ``normal (n, 2)`` (facing the ray origin; zero where nothing was
    hit) and ``hit (n,)`` (bool).  Hits are clipped at ``max_range``.  About 20 numpy calls
    on ``(n, S)`` arrays (three of them small matrix products)."""
    n = dirs.shape[0]
    S_n = S.n
    if not S_n:
        return np.full(n, max_range), np.zeros((n, 2)), np.zeros(n, dtype=bool)
    c, s = math.cos(psi), math.sin(psi)
    R3 = np.array([[c, s, c * oy - s * ox], [-s, c, -s * oy - c * ox]])
    DM = (dirs @ R3) @ S.M  # (n, 2S): denominators | u-numerators
    V = np.array([1.0, ox, oy]) @ S.Q  # (2S,): t-numerators | side of each segment
    with np.errstate(**_ERR):
        inv = 1.0 / DM[:, :S_n]
        t = V[:S_n] * inv
        u = DM[:, S_n:] * inv
    w = np.minimum(u, 1.0 - u)
    np.minimum(w, t, out=w)
    t[~(w >= 0.0)] = np.inf  # also NaN (collinear ray and segment)
    idx = t.argmin(axis=1)
    dist = t[_rows(n), idx]
    hit = dist <= max_range
    np.minimum(dist, max_range, out=dist)
    sgn = np.sign(V[S_n:][idx]) * hit
    return dist, S.N[idx] * sgn[:, None], hit


_ROWS: dict[int, np.ndarray] = {}


def _rows(n: int) -> np.ndarray:
    r = _ROWS.get(n)
    if r is None:
        r = _ROWS[n] = np.arange(n)
    return r


class RangeSensor:
    """A fan of ``n_beams`` range beams over ``fov`` radians, reach ``max_range``."""

    def __init__(self, n_beams: int, fov: float, max_range: float, noise: float = 0.0) -> None:
        if not isinstance(n_beams, (int, np.integer)) or n_beams < 1:
            raise ValueError(f"n_beams must be a positive integer, got {n_beams!r}")
        if not (math.isfinite(max_range) and max_range > 0):
            raise ValueError(f"max_range must be finite and positive here, got {max_range!r}")
        if not (math.isfinite(noise) and noise >= 0):
            raise ValueError(f"noise must be a finite non-negative std, got {noise!r}")
        self.n_beams = int(n_beams)
        self.fov = float(fov)
        self.max_range = float(max_range)
        self.noise = float(noise)
        if self.fov >= 2 * math.pi - 1e-12:
            self.offsets = np.arange(self.n_beams) * (2 * math.pi / self.n_beams) - math.pi
        elif self.n_beams == 1:
            self.offsets = np.zeros(1)
        else:
            self.offsets = np.linspace(-self.fov / 2, self.fov / 2, self.n_beams)
        self.dirs = np.stack([np.cos(self.offsets), np.sin(self.offsets)], axis=1)

    def beam_angles(self, psi: float) -> np.ndarray:
        return psi + self.offsets

    def read(
        self,
        pose: tuple[float, float, float],
        segs: Segments,
        rng: np.random.Generator | None = None,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """``(dist, normal, hit, angles)`` for the beams at ``pose``; noise from ``rng``."""
        dist, nrm, hit = cast_rays(pose[0], pose[1], pose[2], self.dirs, segs, self.max_range)
        ang = self.offsets + pose[2]
        if self.noise > 0 and rng is not None:
            dist = np.clip(
                dist + np.where(hit, rng.normal(0.0, self.noise, dist.shape), 0.0),
                0.0,
                self.max_range,
            )
        return dist, nrm, hit, ang
