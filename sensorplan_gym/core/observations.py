"""Observation types, chosen by the env kwarg ``obs_type``.

Every observation is built only from what the agent may know: the map (walls,
obstacles, G, H), its own pose, and its sensor readings.  The hidden target of
``Recognize-v0`` appears only through the beams it reflects.

``"vector"`` (``Box`` float32, for ``MlpPolicy``)
    Robot envs (Navigate, Recognize), length ``8 + 3 * n_beams``:
    ``[x, y]`` position scaled to [-1, 1] over the scene's bounding box,
    ``[cos psi, sin psi]``, the vectors to the centres of G and of H in the robot's
    frame divided by the scene diameter (2 + 2), then per beam the distance
    divided by the sensor's reach (``n_beams`` values in [0, 1]) and the surface
    normal in the robot's frame (``n_beams`` x-components, then ``n_beams``
    y-components; zeros where nothing was hit).

    Placement, length ``8 + 2 * n_beams``: centres of G and H scaled to [-1, 1],
    the width and height of G and H's bounding boxes divided by the scene's span,
    then two 360-degree scans of the empty scene (walls and obstacles only) taken
    from the centre of G and from the centre of H, distances divided by the scene
    diameter.  Constant for a fixed scene; it describes random scenes.

``"grid"`` (``Box`` uint8, channel-first, for ``CnnPolicy``)
    ``(C, grid_size, grid_size)``; the scene's bounding box is fit into the square
    (aspect kept), row 0 is the top.  Channels: 0 not-free (walls, obstacles,
    outside), 1 G, 2 H, and for robot envs 3 robot (255 at its cell, 128 at the
    cell two cells ahead along its heading) and 4 the current beam hit points.
    Placement has channels 0-2 only.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np
from gymnasium import spaces

from .sensor import RangeSensor

if TYPE_CHECKING:  # pragma: no cover
    from .world import World

__all__ = [
    "OBS_TYPES",
    "PlacementGridObs",
    "PlacementVectorObs",
    "RobotGridObs",
    "RobotVectorObs",
    "make_observation",
]

OBS_TYPES = ("vector", "grid")


def _scaled(world: World, x: float, y: float) -> tuple[float, float]:
    span = world.hi - world.lo
    return (2 * (x - world.lo[0]) / span[0] - 1, 2 * (y - world.lo[1]) / span[1] - 1)


class RobotVectorObs:
    def __init__(self, n_beams: int, grid_size: int = 64) -> None:
        self.n = n_beams
        n = n_beams
        low = np.concatenate([-np.ones(8), np.zeros(n), -np.ones(2 * n)]).astype(np.float32)
        high = np.ones(8 + 3 * n, dtype=np.float32)
        self.space = spaces.Box(low, high, dtype=np.float32)
        self._low, self._high = low, high

    def __call__(self, world: World, pose, scan) -> np.ndarray:
        x, y, psi = pose
        dist, nrm = scan[0], scan[1]
        c, s = math.cos(psi), math.sin(psi)
        k = world._cache.get("obs_consts")
        if k is None:
            k = world._cache["obs_consts"] = (
                float(world.lo[0]),
                float(world.lo[1]),
                2.0 / float(world.hi[0] - world.lo[0]),
                2.0 / float(world.hi[1] - world.lo[1]),
                1.0 / world.diameter,
                1.0 / world.reach,
                float(world.goal_center[0]),
                float(world.goal_center[1]),
                float(world.failure_center[0]),
                float(world.failure_center[1]),
            )
        lx, ly, sx, sy, inv, inv_reach, Gx, Gy, Hx, Hy = k
        gx, gy, hx, hy = Gx - x, Gy - y, Hx - x, Hy - y
        px = (x - lx) * sx - 1.0
        py = (y - ly) * sy - 1.0
        head = np.array(
            [
                -1.0 if px < -1.0 else (1.0 if px > 1.0 else px),
                -1.0 if py < -1.0 else (1.0 if py > 1.0 else py),
                c,
                s,
                (c * gx + s * gy) * inv,
                (-s * gx + c * gy) * inv,
                (c * hx + s * hy) * inv,
                (-s * hx + c * hy) * inv,
            ]
        )
        nr = (nrm @ np.array([[c, -s], [s, c]])).T.ravel()  # robot-frame x's, then y's
        # every entry is within its bounds up to rounding of order 1e-16, which the float32
        # conversion absorbs (values within 2**-25 of +-1 round to +-1)
        return np.concatenate([head, dist * inv_reach, nr]).astype(np.float32)


class RobotGridObs:
    channels = 5

    def __init__(self, n_beams: int, grid_size: int = 64) -> None:
        if grid_size < 36:
            raise ValueError(f"grid_size must be >= 36 (CnnPolicy's NatureCNN), got {grid_size}")
        self.size = int(grid_size)
        self.space = spaces.Box(0, 255, (self.channels, self.size, self.size), dtype=np.uint8)

    def __call__(self, world: World, pose, scan) -> np.ndarray:
        size = self.size
        out = np.zeros((self.channels, size, size), dtype=np.uint8)
        out[:3] = world.raster(size)
        x, y, psi = pose
        cell = size / float(max(world.hi - world.lo))
        i, j = world.to_cell(size, x, y)
        hx, hy = x + 2 * math.cos(psi) / cell, y + 2 * math.sin(psi) / cell
        hi_, hj = world.to_cell(size, hx, hy)
        out[3, hi_, hj] = 128
        out[3, i, j] = 255
        dist, hit = scan[0], scan[2]
        if hit.any():
            ang = scan[3][hit]
            px = x + dist[hit] * np.cos(ang)
            py = y + dist[hit] * np.sin(ang)
            ii, jj = world.to_cell(size, px, py)
            out[4, ii, jj] = 255
        return out


class PlacementVectorObs:
    def __init__(self, n_beams: int, grid_size: int = 64) -> None:
        self.n = n_beams
        self.scanner = RangeSensor(n_beams, 2 * math.pi, 1.0)
        low = np.concatenate([-np.ones(4), np.zeros(4 + 2 * n_beams)]).astype(np.float32)
        self.space = spaces.Box(low, np.ones(8 + 2 * n_beams, dtype=np.float32), dtype=np.float32)

    def __call__(self, world: World, pose=None, scan=None) -> np.ndarray:
        key = f"placement_vec{self.n}"
        cached = world._cache.get(key)
        if cached is not None:
            return cached.copy()
        span = world.hi - world.lo
        out = []
        for g in (world.goal_center, world.failure_center):
            out.extend(_scaled(world, g[0], g[1]))
        for geom in (world.goal_geom, world.failure_geom):
            b = geom.bounds
            out.extend([(b[2] - b[0]) / span[0], (b[3] - b[1]) / span[1]])
        sensor = RangeSensor(self.n, 2 * math.pi, world.diameter)
        for g in (world.goal_center, world.failure_center):
            d = sensor.read((g[0], g[1], 0.0), world.seg_set)[0]
            out.extend(d / world.diameter)
        arr = np.clip(np.asarray(out), self.space.low, self.space.high).astype(np.float32)
        world._cache[key] = arr
        return arr.copy()


class PlacementGridObs:
    channels = 3

    def __init__(self, n_beams: int, grid_size: int = 64) -> None:
        if grid_size < 36:
            raise ValueError(f"grid_size must be >= 36 (CnnPolicy's NatureCNN), got {grid_size}")
        self.size = int(grid_size)
        self.space = spaces.Box(0, 255, (self.channels, self.size, self.size), dtype=np.uint8)

    def __call__(self, world: World, pose=None, scan=None) -> np.ndarray:
        return world.raster(self.size).copy()


def make_observation(kind: str, obs_type: str, n_beams: int, grid_size: int):
    """The observation builder for env ``kind`` ("robot" or "placement") and ``obs_type``."""
    if obs_type not in OBS_TYPES:
        raise ValueError(f"obs_type must be one of {OBS_TYPES}, got {obs_type!r}")
    table = {
        ("robot", "vector"): RobotVectorObs,
        ("robot", "grid"): RobotGridObs,
        ("placement", "vector"): PlacementVectorObs,
        ("placement", "grid"): PlacementGridObs,
    }
    return table[(kind, obs_type)](n_beams, grid_size)
