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
    y-components; zeros where nothing was hit).  With ``map_ranges=True``, ``n_beams``
    more values: the range each beam would read on the static map (walls and obstacles,
    no target, no noise) from the commanded pose, divided by the reach -- what a robot
    carrying the map predicts (length ``8 + 4 * n_beams``).  With ``map_evidence=True``,
    ``2 * n_beams`` more 0/1 values (G's beams, then H's): the beam read noticeably shorter
    than the map predicts and its end point lies in the hull of the target swept over G
    (resp. H) -- the robot's own readings interpreted with the map (:func:`map_evidence`).
    With ``sensor_fov=True``, one more value last: the sensor's field of view divided by
    360 degrees (in (0, 1]) -- the robot knows its own sensor, and on scenes whose field of
    view varies it tells how far apart G and H may lie in one view.
    With ``self_features=True``, two more values last: the field of view divided by 360
    degrees and the sensor's reach (its maximum range, at most the scene's diameter) divided
    by the scene's diameter (1: unlimited), both in (0, 1] -- what the robot knows about its
    own sensor, so one policy can serve scene families whose sensors differ.
    With ``aim_features=True``, ten more values last (:func:`aim_features`): for the shortest
    arc of directions covering both K_G and K_H (the hulls of the target swept over G and
    over H), then for K_G's and K_H's own arcs, the cosine and sine of the arc's centre
    relative to the heading and its width divided by 360 degrees (1 where the robot stands
    in a hull); then the distance to the farthest vertex of K_G and K_H divided by the
    sensor's reach, clipped to 1 -- geometry of the map relative to the robot's pose, the
    quantities an aim must satisfy (a narrow field of view needs the joint width below it),
    not the recognizable region.

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
import shapely
from gymnasium import spaces

from . import fused
from .kernels import libm
from .queries import hull_arcs, joint_arc
from .sensor import RangeSensor
from .world import HINT_AHEAD, HINT_SIZE, hint_blocked, pixel_of

if TYPE_CHECKING:  # pragma: no cover
    from .sim import BatchSim
    from .world import World

__all__ = [
    "OBS_TYPES",
    "grid_cells",
    "PlacementGridObs",
    "PlacementVectorObs",
    "RobotGridObs",
    "RobotVectorObs",
    "make_observation",
]

OBS_TYPES = ("vector", "grid")


def grid_cells(sim: BatchSim, idx: np.ndarray, size: int, x, y) -> tuple[np.ndarray, np.ndarray]:
    """Row and column of points ``(x, y)`` (``(k,)`` or ``(k, B)``) in the ``size`` grid of
    each sub-environment's world (:meth:`World.grid_transform`), clipped to the grid."""
    lo, hi = sim.lo[idx], sim.hi[idx]
    span = (hi - lo).max(axis=1)
    scale = size / span
    ox = lo[:, 0] - 0.5 * (span - (hi[:, 0] - lo[:, 0]))
    oy = lo[:, 1] - 0.5 * (span - (hi[:, 1] - lo[:, 1]))
    return pixel_of(np.column_stack([scale, ox, oy]), size, x, y)


def _scaled(world: World, x: float, y: float) -> tuple[float, float]:
    span = world.hi - world.lo
    return (2 * (x - world.lo[0]) / span[0] - 1, 2 * (y - world.lo[1]) / span[1] - 1)


class RobotVectorObs:
    def __init__(
        self,
        n_beams: int,
        grid_size: int = 64,
        map_ranges: bool = False,
        map_evidence: bool = False,
        sensor_fov: bool = False,
        self_features: bool = False,
        aim_features: bool = False,
        view_hint: bool = False,
        hint_aim: bool = True,
    ) -> None:
        self.n = n_beams
        self.hint_aim = hint_aim
        n = n_beams
        self.aim_features = aim_features
        self.view_hint = view_hint
        self.map_ranges = map_ranges
        self.map_evidence = map_evidence
        self.sensor_fov = sensor_fov
        self.self_features = self_features
        m = (n if map_ranges else 0) + (2 * n if map_evidence else 0) + (1 if sensor_fov else 0)
        m += 2 if self_features else 0
        low = np.concatenate([-np.ones(8), np.zeros(n), -np.ones(2 * n), np.zeros(m)])
        if aim_features:
            low = np.concatenate([low, np.tile([-1.0, -1.0, 0.0], 3), [0.0]])
        if view_hint:
            low = np.concatenate([low, [-1.0, -1.0, 0.0]])
        self.space = spaces.Box(
            low.astype(np.float32), np.ones(len(low), dtype=np.float32), dtype=np.float32
        )

    @property
    def head(self) -> int:
        """Entries the compiled kernel writes: pose, G and H, the scan (and map ranges)."""
        return 8 + (4 if self.map_ranges else 3) * self.n

    def __call__(self, sim: BatchSim, idx: np.ndarray) -> np.ndarray:
        """Observations ``(k, D)`` float32 of sub-environments ``idx``."""
        if sim.fused:
            out = np.empty((len(idx), self.space.shape[0]), dtype=np.float32)
            fused.obs_kernel(
                idx, sim.P, sim.obs_consts, sim.scan_dist, sim.scan_normal, sim.map_dist,
                sim.params, out,
            )  # fmt: skip
            if self.head < out.shape[1]:
                sel = sim.sel(idx)
                out[:, self.head :] = self.tail(sim, sel, sim.x[sel], sim.y[sel], sim.psi[sel])
            return out
        return self._numpy(sim, idx)

    def tail(self, sim: BatchSim, sel, x, y, psi) -> np.ndarray:
        """The entries after :attr:`head` ``(k, D - head)`` float64: ``map_evidence``'s
        flags, then ``sensor_fov``, then ``self_features``, then ``aim_features``, then
        ``view_hint``.  A new entry goes here (and in the space's bounds)."""
        parts = []
        if self.map_evidence:
            parts.append(map_evidence(sim, sel, x, y, psi).reshape(len(x), 2 * self.n))
        if self.sensor_fov:
            parts.append((sim.fov[sel] / (2.0 * math.pi))[:, None])
        if self.self_features:  # fov / 360 degrees, reach / diameter (obs_consts[4] = 1/diameter)
            fov = sim.fov[sel] / (2.0 * math.pi)
            reach = np.minimum(sim.reach[sel] * sim.obs_consts[sel, 4], 1.0)
            parts.append(np.column_stack([fov, reach]))
        if self.aim_features:
            parts.append(aim_features(sim.hulls[sel], sim.reach[sel], x, y, psi))
        if self.view_hint:
            parts.append(view_hint(sim.worlds[sel], x, y, psi, self.hint_aim))
        return np.concatenate(parts, axis=1)

    def _numpy(self, sim: BatchSim, idx: np.ndarray) -> np.ndarray:
        sel = sim.sel(idx)
        x, y, psi = sim.x[sel], sim.y[sel], sim.psi[sel]
        K = sim.obs_consts[sel]  # lo, 2 / span, 1 / diameter, 1 / reach, G, H centres
        c, s = libm(math.cos, psi), libm(math.sin, psi)
        n = self.n
        out = np.empty((len(x), self.space.shape[0]))
        out[:, 0] = (x - K[:, 0]) * K[:, 2] - 1.0
        out[:, 1] = (y - K[:, 1]) * K[:, 3] - 1.0
        np.clip(out[:, :2], -1.0, 1.0, out=out[:, :2])
        out[:, 2] = c
        out[:, 3] = s
        c1, s1 = c[:, None], s[:, None]
        gx = K[:, 6::2] - x[:, None]  # to G and to H, world frame
        gy = K[:, 7::2] - y[:, None]
        out[:, 4:8:2] = (c1 * gx + s1 * gy) * K[:, 4:5]  # robot frame / diameter
        out[:, 5:8:2] = (c1 * gy - s1 * gx) * K[:, 4:5]
        out[:, 8 : 8 + n] = sim.scan_dist[sel] * K[:, 5:6]
        nrm = sim.scan_normal[sel]  # robot-frame x's, then y's
        out[:, 8 + n : 8 + 2 * n] = c1 * nrm[..., 0] + s1 * nrm[..., 1]
        out[:, 8 + 2 * n : 8 + 3 * n] = c1 * nrm[..., 1] - s1 * nrm[..., 0]
        if self.map_ranges:
            out[:, 8 + 3 * n : 8 + 4 * n] = sim.map_dist[sel] * K[:, 5:6]
        if self.head < out.shape[1]:
            out[:, self.head :] = self.tail(sim, sel, x, y, psi)
        # every entry is within its bounds up to rounding of order 1e-16, which the float32
        # conversion absorbs (values within 2**-25 of +-1 round to +-1)
        return out.astype(np.float32)


class RobotGridObs:
    channels = 5

    def __init__(self, n_beams: int, grid_size: int = 64) -> None:
        if grid_size < 36:
            raise ValueError(f"grid_size must be >= 36 (CnnPolicy's NatureCNN), got {grid_size}")
        self.size = int(grid_size)
        self.space = spaces.Box(0, 255, (self.channels, self.size, self.size), dtype=np.uint8)

    def __call__(self, sim: BatchSim, idx: np.ndarray) -> np.ndarray:
        size, k = self.size, len(idx)
        out = np.zeros((k, self.channels, size, size), dtype=np.uint8)
        out[:, :3] = _rasters(sim, idx, size)
        x, y, psi = sim.x[idx], sim.y[idx], sim.psi[idx]
        cell = size / (sim.hi[idx] - sim.lo[idx]).max(axis=1)
        rows = np.arange(k)
        i, j = grid_cells(sim, idx, size, x, y)
        hi_, hj = grid_cells(sim, idx, size, x + 2 * np.cos(psi) / cell, y + 2 * np.sin(psi) / cell)
        out[rows, 3, hi_, hj] = 128
        out[rows, 3, i, j] = 255
        hit = sim.scan_hit[idx]
        if hit.any():
            d, ang = sim.scan_dist[idx], sim.scan_ang[idx]
            ii, jj = grid_cells(
                sim, idx, size, x[:, None] + d * np.cos(ang), y[:, None] + d * np.sin(ang)
            )
            r = np.broadcast_to(rows[:, None], hit.shape)
            out[r[hit], 4, ii[hit], jj[hit]] = 255
        return out


def map_evidence(sim: BatchSim, sel, x, y, psi) -> np.ndarray:
    """``(k, 2, B)`` 0/1: beam ``b`` read noticeably shorter than the static map predicts
    (by more than ``3 noise + 1e-3 reach``) and its end point, placed from the commanded pose,
    lies in K_G (row 0) or K_H (row 1), the hulls of the target swept over G and H -- map
    knowledge applied to the robot's own readings, never the target's hidden location."""
    d = sim.scan_dist[sel]
    tol = 3.0 * sim.noise + 1e-3 * sim.reach[sel][:, None]
    short = d < sim.map_dist[sel] - tol
    ang = sim.offsets[sel] + psi[:, None]
    px = x[:, None] + d * np.cos(ang)  # (k, B)
    py = y[:, None] + d * np.sin(ang)
    H = sim.hulls[sel]  # (k, 2, K, 2), counter-clockwise
    ex = np.roll(H[..., 0], -1, axis=2) - H[..., 0]
    ey = np.roll(H[..., 1], -1, axis=2) - H[..., 1]
    # cross(e, p - v) >= 0 for every edge: inside (zero-length padding edges give 0)
    cr = ex[:, :, None, :] * (py[:, None, :, None] - H[:, :, None, :, 1]) - ey[:, :, None, :] * (
        px[:, None, :, None] - H[:, :, None, :, 0]
    )
    inside = (cr >= -1e-9 * sim.diameter[sel][:, None, None, None] ** 2).all(axis=3)
    return (inside & short[:, None, :]).astype(np.float64)


def aim_features(hulls: np.ndarray, reach: np.ndarray, x, y, psi) -> np.ndarray:
    """``(k, 10)`` float64: the ``aim_features`` of poses ``(x, y, psi)`` (world frame,
    radians) with K_G and K_H ``hulls`` ``(k, 2, K, 2)`` and the sensor's ``reach``
    ``(k,)``: ``cos, sin`` of the centre of the arc covering both hulls relative to the
    heading, its width / 2 pi, the same for K_G's and for K_H's arc
    (:func:`.queries.hull_arcs`, :func:`.queries.joint_arc`), then the farthest hull
    vertex's distance / reach clipped to ``[0, 1]``."""
    start, width = hull_arcs(hulls, x, y)
    js, jw = joint_arc(start, width)
    s = np.column_stack([js, start])  # (k, 3): joint, G, H
    w = np.column_stack([jw, width])
    rel = s + 0.5 * w - psi[:, None]
    out = np.empty((len(x), 10))
    out[:, 0:9:3] = np.cos(rel)
    out[:, 1:9:3] = np.sin(rel)
    out[:, 2:9:3] = w / (2.0 * math.pi)
    far = np.hypot(hulls[..., 0] - x[:, None, None], hulls[..., 1] - y[:, None, None])
    out[:, 9] = np.clip(far.max(axis=(1, 2)) / reach, 0.0, 1.0)
    return out


def view_hint(worlds: list[World], x, y, psi, aim: bool = True) -> np.ndarray:
    """``(k, 3)`` float64: the ``view_hint`` of poses ``(x, y, psi)`` (world frame, radians)
    in ``worlds`` (one per pose): the way to the nearest pixel that sees every corner of K_G
    and K_H with a passing aim, along the shortest grid path in the robot's free space
    (:meth:`World.hint_field`, followed from the pixel of :meth:`World.hint_cells`): the unit
    vector toward the farthest of the path's waypoints a few pixels ahead that is in plain
    sight, in the robot's frame (zero on it, and where no such pixel is reachable), then the length
    of the way there, straight to the waypoint and on along the path, / diameter clipped to
    ``[0, 1]`` (0 at a target pixel's centre, 1 where none is reachable)."""
    k = len(x)
    groups: dict[int, list[int]] = {}
    for r, w in enumerate(worlds):
        groups.setdefault(id(w), []).append(r)
    levels = len(HINT_AHEAD)
    ways = np.empty((levels, k, 2))
    rest = np.empty(k)  # the path's length on from each waypoint (no waypoint: inf)
    space = np.empty(k, dtype=object)
    size = np.empty(k)
    centre = np.empty((k, 2))  # the centre of the pixel whose path the pose follows
    clear = np.empty(k)  # its clearance
    grid = np.empty((k, 3))  # each pose's world's grid transform (scale, ox, oy)
    for rows in groups.values():
        grid[rows] = worlds[rows[0]].grid_transform(HINT_SIZE)
    ci, cj = pixel_of(grid, HINT_SIZE, x, y)
    cells = {}
    for rows in groups.values():
        w = worlds[rows[0]]
        i, j = ci[rows], cj[rows]
        X, Y = w.pixel_centres(HINT_SIZE)
        centre[rows] = np.column_stack([X[i, j], Y[i, j]])
        clear[rows] = w.hint_clearance(HINT_SIZE)[i, j]
        space[rows] = w.robot_space
        size[rows] = w.diameter
        cells[id(w)] = (i, j)
    # a pose behind a wall from its pixel's centre follows a pixel it sees (World.hint_cells)
    bad = hint_blocked(x, y, centre[:, 0], centre[:, 1], clear, space)
    for rows in groups.values():
        w = worlds[rows[0]]
        i, j = cells[id(w)]
        b = bad[rows]
        if b.any():
            r = np.asarray(rows)[b]
            i[b], j[b] = w.hint_search(x[r], y[r], i[b], j[b], HINT_SIZE, aim)
            X, Y = w.pixel_centres(HINT_SIZE)
            centre[r] = np.column_stack([X[i[b], j[b]], Y[i[b], j[b]]])
            clear[r] = w.hint_clearance(HINT_SIZE)[i[b], j[b]]
        ways[:, rows] = w.hint_field(HINT_SIZE, aim)[0][:, i, j]
    xy = np.column_stack([x, y])
    # the farthest waypoint in plain sight; the nearest, or failing that the pixel's own
    # centre (in sight, unless no pixel nearby is), when none is.  The segment to the
    # nearest lies in the disc around the centre that holds both its ends: tested only where
    # that disc reaches the boundary
    reach = np.maximum(np.hypot(*(xy - centre).T), np.hypot(*(ways[-1] - centre).T))
    near = clear > reach
    test = np.flatnonzero(~near)
    if len(test):
        near[test] = shapely.covers(
            space[test], shapely.linestrings(np.stack([xy[test], ways[-1][test]], axis=1))
        )
    way = np.where(near[:, None], ways[-1], centre)
    for far in ways[-2::-1]:
        free = shapely.covers(space, shapely.linestrings(np.stack([xy, far], axis=1)))
        way = np.where(free[:, None], far, way)
    wi, wj = pixel_of(grid, HINT_SIZE, way[:, 0], way[:, 1])
    for rows in groups.values():
        rest[rows] = worlds[rows[0]].hint_field(HINT_SIZE, aim)[1][wi[rows], wj[rows]]
    dx, dy = way[:, 0] - x, way[:, 1] - y
    n = np.hypot(dx, dy)
    left = rest + n  # to the waypoint, then on along the path
    far = np.isfinite(left) & (n > 1e-9 * size)
    n = np.where(far, n, 1.0)
    dx, dy = np.where(far, dx / n, 0.0), np.where(far, dy / n, 0.0)
    c, s = libm(math.cos, psi), libm(math.sin, psi)
    out = np.empty((k, 3))
    out[:, 0] = c * dx + s * dy
    out[:, 1] = c * dy - s * dx
    out[:, 2] = np.minimum(left / size, 1.0)
    return out


def _rasters(sim: BatchSim, idx: np.ndarray, size: int) -> np.ndarray:
    if sim._one_world:
        return sim.worlds[0].raster(size)[None]
    return np.stack([sim.worlds[i].raster(size) for i in idx.tolist()])


class PlacementVectorObs:
    def __init__(self, n_beams: int, grid_size: int = 64, self_features: bool = False) -> None:
        self.n = n_beams
        self.self_features = self_features
        self._key = f"placement_vec{n_beams}" + ("_self" if self_features else "")
        m = 2 if self_features else 0
        low = np.concatenate([-np.ones(4), np.zeros(4 + 2 * n_beams + m)]).astype(np.float32)
        self.space = spaces.Box(
            low, np.ones(8 + 2 * n_beams + m, dtype=np.float32), dtype=np.float32
        )

    def __call__(self, sim: BatchSim, idx: np.ndarray) -> np.ndarray:
        if sim._one_world:
            out = np.empty((len(idx), self.space.shape[0]), dtype=np.float32)
            out[:] = self.of_world(sim.worlds[0])
            return out
        return np.stack([self.of_world(sim.worlds[i]) for i in idx.tolist()])

    def of_world(self, world: World) -> np.ndarray:
        """The (constant) observation of one world, computed once."""
        key = self._key
        cached = world._cache.get(key)
        if cached is not None:
            return cached
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
        if self.self_features:  # as the robot observations': fov / 360 degrees, reach / diameter
            out.extend([world.fov / (2.0 * math.pi), min(world.max_range / world.diameter, 1.0)])
        arr = np.clip(np.asarray(out), self.space.low, self.space.high).astype(np.float32)
        world._cache[key] = arr
        return arr


class PlacementGridObs:
    """``Box(uint8, (C, S, S))`` on the scene raster (:meth:`World.raster`): channels not
    free, G, H; with ``views`` two more, the free space seen from G's and from H's anchor
    (:meth:`World.view_raster`); with ``hull_views`` two more, the free space seen from every
    corner of K_G and of K_H (:meth:`World.hull_view_raster`); with ``aim_views`` (a number
    of aims A) A more, where aim ``k`` passes the reward's aim test (:meth:`World.aim_raster`);
    with ``self_features`` two constant planes, the field of view over 360 degrees and the
    reach over the diameter, times 255 (in that order)."""

    def __init__(
        self,
        n_beams: int,
        grid_size: int = 64,
        *,
        views: bool = False,
        self_features: bool = False,
        hull_views: bool = False,
        aim_views: int = 0,
    ) -> None:
        if grid_size < 36:
            raise ValueError(f"grid_size must be >= 36 (CnnPolicy's NatureCNN), got {grid_size}")
        self.size = int(grid_size)
        self.views = bool(views)
        self.hull_views = bool(hull_views)
        self.self_features = bool(self_features)
        self.aim_views = int(aim_views)
        self.channels = (
            3 + 2 * self.views + 2 * self.hull_views + self.aim_views + 2 * self.self_features
        )
        self.space = spaces.Box(0, 255, (self.channels, self.size, self.size), dtype=np.uint8)

    def __call__(self, sim: BatchSim, idx: np.ndarray) -> np.ndarray:
        if not (self.views or self.hull_views or self.aim_views or self.self_features):
            return np.broadcast_to(
                _rasters(sim, idx, self.size), (len(idx), *self.space.shape)
            ).copy()
        if sim._one_world:
            return np.broadcast_to(
                self.of_world(sim.worlds[0]), (len(idx), *self.space.shape)
            ).copy()
        return np.stack([self.of_world(sim.worlds[i]) for i in idx.tolist()])

    def of_world(self, world: World) -> np.ndarray:
        """The (constant) observation of one world, computed once."""
        flags = f"{int(self.views)}{int(self.hull_views)}{self.aim_views}{int(self.self_features)}"
        key = f"placement_grid{self.size}_{flags}"
        got = world._cache.get(key)
        if got is None:
            parts = [world.raster(self.size)]
            if self.views:
                parts.append(world.view_raster(self.size))
            if self.hull_views:
                parts.append(world.hull_view_raster(self.size))
            if self.aim_views:
                parts.append(world.aim_raster(self.size, self.aim_views))
            if self.self_features:
                fov = world.fov / (2.0 * math.pi)
                reach = min(world.max_range / world.diameter, 1.0)
                planes = np.empty((2, self.size, self.size), dtype=np.uint8)
                planes[0] = round(255 * min(fov, 1.0))
                planes[1] = round(255 * reach)
                parts.append(planes)
            got = world._cache[key] = np.concatenate(parts)
        return got


def make_observation(
    kind: str,
    obs_type: str,
    n_beams: int,
    grid_size: int,
    *,
    map_ranges: bool = False,
    map_evidence: bool = False,
    sensor_fov: bool = False,
    self_features: bool = False,
    aim_features: bool = False,
    grid_views: bool = False,
    hull_views: bool = False,
    aim_views: int = 0,
    view_hint: bool = False,
    hint_aim: bool = True,
):
    """The observation builder for env ``kind`` ("robot" or "placement") and ``obs_type``;
    ``map_ranges`` / ``map_evidence`` / ``sensor_fov`` / ``self_features``: robot vector
    observations carry the map-predicted ranges / the per-beam evidence flags / the field of
    view / the field of view and the reach too / the arcs of K_G and K_H (:func:`aim_features`)
    / the way to the poses that see both hulls (:func:`view_hint`; ``hint_aim=False``: with
    no joint aim asked of them);
    Placement's grid: ``grid_views`` / ``hull_views`` / ``aim_views`` (a number of aims) /
    ``self_features`` add channels (:class:`PlacementGridObs`)."""
    if obs_type not in OBS_TYPES:
        raise ValueError(f"obs_type must be one of {OBS_TYPES}, got {obs_type!r}")
    table = {
        ("robot", "vector"): RobotVectorObs,
        ("robot", "grid"): RobotGridObs,
        ("placement", "vector"): PlacementVectorObs,
        ("placement", "grid"): PlacementGridObs,
    }
    if kind == "placement" and obs_type == "grid":
        return PlacementGridObs(
            n_beams,
            grid_size,
            views=grid_views,
            self_features=self_features,
            hull_views=hull_views,
            aim_views=aim_views,
        )
    if grid_views or hull_views or aim_views:
        name = "grid_views" if grid_views else "hull_views" if hull_views else "aim_views"
        raise ValueError(f"{name}=True needs obs_type='grid' in Placement")
    if kind == "placement" and self_features:
        return PlacementVectorObs(n_beams, grid_size, self_features=True)
    if map_ranges or map_evidence or sensor_fov or self_features or aim_features or view_hint:
        return RobotVectorObs(
            n_beams,
            grid_size,
            map_ranges=map_ranges,
            map_evidence=map_evidence,
            sensor_fov=sensor_fov,
            self_features=self_features,
            aim_features=aim_features,
            view_hint=view_hint,
            hint_aim=hint_aim,
        )
    return table[(kind, obs_type)](n_beams, grid_size)
