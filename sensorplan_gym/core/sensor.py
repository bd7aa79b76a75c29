"""The point-and-shoot range sensor of the paper (section 2), batched.

A sensor at pose ``(x, y, psi)`` casts a fan of ``n_beams`` beams spread evenly
over the field of view ``fov`` (radians) centred on ``psi``; with a full 360-degree
field of view the beams are ``2 pi / n`` apart and none is duplicated.  Each beam
returns the distance to the first segment it hits -- walls, obstacles and, when
present, the target's edges -- and the unit surface normal there, turned to face
the sensor.  A beam that hits nothing within ``max_range`` returns
``max_range`` and a zero normal.  The sensor does not say *what* it hit.

Optional Gaussian noise (standard deviation ``noise``, scene units, truncated at
``NOISE_BOUND = 3`` standard deviations, so a reading is accurate to within ``3 noise``) is
added to the hit distances, which are then clipped to ``[0, max_range]``; normals are
noise-free.  The environments compute their regions for a sensor whose range accuracy is at
most that bound (``WorldConfig.range_acc``; the scene's ``sensor.range_acc`` when larger).

:func:`cast_batch` is the one implementation: N sensors x B beams x M segments, the inner
loop in :func:`.kernels.cast` (compiled with numba when the ``fast`` extra is
installed, else one numpy broadcast over ``(N, B, M)``; the answers are identical); the
one-sensor helpers :func:`cast_rays` and :meth:`RangeSensor.read` call it with N = 1.
"""

from __future__ import annotations

import math

import numpy as np

from .kernels import cast
from .segments import Segments

__all__ = ["RangeSensor", "Segments", "cast_batch", "cast_rays"]

_ERR = {"divide": "ignore", "invalid": "ignore", "over": "ignore"}


def cast_batch(
    ox: np.ndarray, oy: np.ndarray, ang: np.ndarray, S, max_range, cull: bool = False
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """First hits of N fans of rays against segment sets.

    ``ox, oy``: ``(N,)`` ray origins (world frame); ``ang``: ``(N, B)`` ray directions
    (radians, world frame); ``S``: a :class:`~.segments.Segments` shared by all N, or
    :class:`~.segments.SegmentRows`-like ``(N, M)`` arrays, one set per origin;
    ``max_range``: scalar or ``(N,)``; ``cull=True`` when every normal points into the
    free space and every origin is a free point: the segments facing away are skipped
    (same answers, about half the work).

    Returns ``dist (N, B)`` (scene units, clipped at ``max_range``), ``normal (N, B, 2)``
    (unit, world frame, facing the ray origin; zero where nothing was hit) and
    ``hit (N, B)`` (bool)."""
    ox = np.asarray(ox, dtype=np.float64)
    oy = np.asarray(oy, dtype=np.float64)
    n, b = ang.shape
    mr = np.asarray(max_range, dtype=np.float64)
    if mr.ndim == 0:
        mr = np.full(n, float(mr))
    if S.x0.shape[-1] == 0:
        return np.repeat(mr[:, None], b, 1), np.zeros((n, b, 2)), np.zeros((n, b), bool)
    dist, hit, gx, gy = cast(
        ox,
        oy,
        np.cos(ang),
        np.sin(ang),
        *(_2d(v) for v in (S.x0, S.y0, S.ex, S.ey, S.nx, S.ny)),
        mr,
        cull,
    )
    nrm = np.empty((n, b, 2))
    nrm[:, :, 0] = gx
    nrm[:, :, 1] = gy
    return dist, nrm, hit


def _2d(a: np.ndarray) -> np.ndarray:
    return a if a.ndim == 2 else a[None, :]


def cast_rays(
    ox: float, oy: float, psi: float, dirs: np.ndarray, S: Segments, max_range: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One sensor: rays from ``(ox, oy)`` with directions ``dirs`` (``(n, 2)`` unit vectors
    in the sensor frame) turned by ``psi``.  Returns ``dist (n,)``, ``normal (n, 2)``,
    ``hit (n,)`` as :func:`cast_batch` for N = 1."""
    ang = (np.arctan2(dirs[:, 1], dirs[:, 0]) + psi)[None, :]
    d, nrm, hit = cast_batch(np.array([ox]), np.array([oy]), ang, S, max_range)
    return d[0], nrm[0], hit[0]


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
        self.offsets = beam_offsets(self.n_beams, self.fov)
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
        ang = self.offsets + pose[2]
        dist, nrm, hit = cast_batch(
            np.array([pose[0]]), np.array([pose[1]]), ang[None, :], segs, self.max_range
        )
        dist, nrm, hit = dist[0], nrm[0], hit[0]
        if self.noise > 0 and rng is not None:
            z = rng.standard_normal(dist.shape)
            dist = add_noise(dist, hit, z, self.noise, self.max_range)
        return dist, nrm, hit, ang


def beam_offsets(n_beams: int, fov: float) -> np.ndarray:
    """Beam angles relative to the aim (radians): evenly over ``fov``, or ``2 pi / n``
    apart (none duplicated) for a full circle."""
    if fov >= 2 * math.pi - 1e-12:
        return np.arange(n_beams) * (2 * math.pi / n_beams) - math.pi
    if n_beams == 1:
        return np.zeros(1)
    return np.linspace(-fov / 2, fov / 2, n_beams)


#: range noise is a Gaussian truncated at this many standard deviations: a reading is within
#: ``NOISE_BOUND * noise`` of the true distance (the paper's sensor is accurate to a known bound)
NOISE_BOUND = 3.0


def add_noise(dist, hit, z, noise, max_range):
    """``dist + noise * z`` on the beams that hit, ``z`` truncated to ``+-NOISE_BOUND``,
    clipped to ``[0, max_range]``."""
    mr = np.asarray(max_range)
    if mr.ndim:
        mr = mr[:, None]
    z = np.clip(z, -NOISE_BOUND, NOISE_BOUND)
    return np.clip(dist + np.where(hit, noise * z, 0.0), 0.0, mr)


__all__ += ["NOISE_BOUND", "add_noise", "beam_offsets"]
