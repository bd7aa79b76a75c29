"""A :class:`World`: one validated :class:`geometry.Scene` under one configuration (visibility
model, target motion, uncertainty, sensor limits, robot radius), with everything that does not
change during an episode computed once:

* the exact recognizable region R(G) n R(H) - C(G, H) from
  :func:`geometry.recognizable_region`, prepared for exact point queries, and its boundary as
  a segment array (point-to-region distance);
* the environment's edges (walls and merged obstacles) with unit normals, used by the range
  sensor and the collision sweep, and a conservative clearance field that lets the sweep be
  skipped far from every edge;
* the convex "must-see" sets K_G = CH(target swept over G) and K_H used by the aim check;
* :meth:`World.batch_rows`: all of the above as padded arrays, the form in which the batched
  core (:mod:`sensorplan_gym.core.sim`) copies a world into a sub-environment's row.

Worlds are cached by :func:`sensorplan_gym.core.cache.get_world` (the cache sits above this
module: it builds worlds, a world never reaches the cache).  The region of a world built with
``disk_cache=`` (scene pools do) is read from, or stored to, an on-disk cache
(:mod:`sensorplan_gym.core.diskcache`).

Target motion (``motion``)
--------------------------
``"stationary"``  the target sits at the centroid of G (resp. H): G and H are
                  replaced by those points (a representative interior point when
                  the centroid falls outside a non-convex region).
``"translating"`` the target is anywhere in G (resp. H) at orientation 0
                  (``theta=0.0`` in the geometry).
``"rotating"``    anywhere in G/H at any orientation (``theta=None``).
With ``model="partial"`` and polygonal G/H the region is the paper's 5.2
construction (swept shadows of the non-confusable part of the target, built
once per scene and configuration: about 1 s on a bundled scene).  Combinations
the geometry does not support (``"rotating"`` with the partial model) raise
``NotImplementedError`` carrying the geometry's message; a point G with a
polygonal H (or the reverse) is supported (``geometry.mixed``).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import shapely
import shapely.geometry.polygon
from shapely.geometry import Point

from geometry import Scene, SceneError, recognizable_region

from .collision import sweep
from .diskcache import RegionCache
from .queries import aim_ok_batch, region_distance_batch
from .scenes import BUNDLED_SCENES, bundled_scene_path, load_scene
from .segments import (
    Segments,
    boundary_segments,
    pad_segments,
    point_segment_distance,
    segment_normals,
)

__all__ = [
    "BUNDLED_SCENES",
    "FIELD_SIZE",
    "MODELS",
    "MOTIONS",
    "SceneError",
    "Segments",
    "World",
    "WorldConfig",
    "boundary_segments",
    "bundled_scene_path",
    "load_scene",
    "segment_normals",
    "sweep",
]

MODELS = ("complete", "partial")
MOTIONS = ("stationary", "translating", "rotating")
#: cells along the longer side of the clearance field
FIELD_SIZE = 64
#: pixels along the side of the ``view_hint`` field's square (:meth:`World.hint_field`)
HINT_SIZE = 128
#: grid steps from a pixel to its ``view_hint`` waypoints, farthest first (:meth:`World.hint_field`)
HINT_AHEAD = (6, 3, 1)


@dataclass(frozen=True)
class WorldConfig:
    """Configuration overrides; ``None`` means "take it from the scene's sensor spec".

    ``max_range=math.inf`` forces an unlimited range even if the scene sets one.
    ``eps_aim`` and ``fov`` are radians here (the env kwargs ``fov_deg``/``eps_aim``
    are converted by the env).
    """

    model: str = "complete"
    motion: str = "translating"
    eps_pos: float | None = None
    eps_aim: float | None = None
    fov: float | None = None
    max_range: float | None = None
    robot_radius: float = 0.0
    #: the range accuracy the simulated sensor needs (scene units): the region is computed for
    #: a sensor no more accurate than this (``None``: the scene's ``sensor.range_acc``)
    range_acc: float | None = None

    def validate(self) -> WorldConfig:
        if self.model not in MODELS:
            raise ValueError(f"model must be one of {MODELS}, got {self.model!r}")
        if self.motion not in MOTIONS:
            raise ValueError(f"motion must be one of {MOTIONS}, got {self.motion!r}")
        for name in ("eps_pos", "eps_aim", "fov", "max_range", "range_acc"):
            v = getattr(self, name)
            if v is not None and (not isinstance(v, (int, float)) or math.isnan(v) or v < 0):
                raise ValueError(f"{name} must be a non-negative number or None, got {v!r}")
        if self.fov is not None and not (0 < self.fov <= 2 * math.pi + 1e-12):
            raise ValueError(f"fov_deg must be in (0, 360], got {math.degrees(self.fov)!r}")
        if self.max_range is not None and self.max_range == 0:
            raise ValueError("max_range must be positive")
        r = self.robot_radius
        if not isinstance(r, (int, float)) or not math.isfinite(r) or r < 0:
            raise ValueError(f"robot_radius must be a finite non-negative number, got {r!r}")
        return self


class World:
    """One scene under one configuration (see the module docstring).  Treat as immutable."""

    def __init__(
        self, scene: Scene, cfg: WorldConfig, *, disk_cache: RegionCache | None = None
    ) -> None:
        """``disk_cache``: where the recognizable region is looked up before it is computed
        (and stored after; :mod:`.diskcache`); ``None``: always computed."""
        cfg.validate()
        self.cfg = cfg
        sensor = scene.sensor
        self.model = cfg.model
        self.motion = cfg.motion
        if cfg.motion == "stationary":
            scene = scene.replace(
                goal=[list(_anchor(scene.goal_geom))], failure=[list(_anchor(scene.failure_geom))]
            )
        if cfg.range_acc is not None and cfg.range_acc > scene.range_acc:
            # the readings are only this accurate: confusability is judged with that bound
            scene = scene.replace(sensor=dataclasses.replace(scene.sensor, range_acc=cfg.range_acc))
        self.scene = scene
        self.range_acc = float(scene.range_acc)
        self.theta: float | None = None if cfg.motion == "rotating" else 0.0
        self.eps_pos = float(sensor.eps_pos if cfg.eps_pos is None else cfg.eps_pos)
        self.eps_aim = float(sensor.eps_aim if cfg.eps_aim is None else cfg.eps_aim)
        self.fov = float(sensor.fov if cfg.fov is None else cfg.fov)
        mr = sensor.max_range if cfg.max_range is None else cfg.max_range
        self.max_range = math.inf if mr is None else float(mr)
        self.robot_radius = float(cfg.robot_radius)

        lo = scene.bounds.min(axis=0)
        hi = scene.bounds.max(axis=0)
        self.lo, self.hi = lo.astype(np.float64), hi.astype(np.float64)
        self.diameter = float(scene.diameter)
        self.skin = 1e-7 * self.diameter
        # the sensor's effective reach: beams never travel farther than the room's diagonal
        self.reach = min(self.max_range, self.diameter)

        args = {
            "model": cfg.model,
            "theta": self.theta,
            "eps_pos": self.eps_pos,
            "eps_aim": self.eps_aim,
        }
        try:
            if disk_cache is None:
                region = recognizable_region(scene, **args)
            else:
                region = disk_cache.region(
                    scene, functools.partial(recognizable_region, scene, **args), **args
                )
        except NotImplementedError as e:
            raise NotImplementedError(
                f"scene {scene.name!r} with model={cfg.model!r}, motion={cfg.motion!r}: {e}"
            ) from e
        self.region = region
        shapely.prepare(self.region)
        self.region_segs = boundary_segments(region)

        self.free_space = scene.free_space
        # exteriors counter-clockwise, holes clockwise: every edge's left normal points into
        # the free space (the range sensor skips edges whose free side faces away)
        self.segs = boundary_segments(shapely.orient_polygons(self.free_space))
        self.seg_normals = segment_normals(self.segs)
        self.seg_set = Segments(self.segs, self.seg_normals)
        self.region_rows = Segments(self.region_segs)
        # free space for the robot's centre
        r = self.robot_radius
        self.robot_space = self.free_space.buffer(-r) if r > 0 else self.free_space
        shapely.prepare(self.robot_space)

        self.goal_geom = scene.goal_geom
        self.failure_geom = scene.failure_geom
        self.goal_center = np.array(_anchor(self.goal_geom))
        self.failure_center = np.array(_anchor(self.failure_geom))
        self.target = np.asarray(scene.target, dtype=np.float64)
        self.target_radius = float(scene.target_radius)
        self.must_see = (self._swept_hull(self.goal_geom), self._swept_hull(self.failure_geom))
        self._cache: dict[str, Any] = {}

    # ---- pickling: shapely's "prepared" flag is not pickled ------------------------------
    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        shapely.prepare(self.region)
        shapely.prepare(self.robot_space)

    # ---- derived sets ----------------------------------------------------------------------
    def _swept_hull(self, g: shapely.Geometry) -> np.ndarray:
        """Vertices (CCW) of the convex hull of the target swept over region ``g``: what must be
        inside the field of view.  For a rotating target the swept disc of radius r_A is
        replaced by a circumscribed 32-gon (conservative)."""
        gpts = np.asarray(shapely.get_coordinates(g.convex_hull))
        if self.theta is None:
            k = 32
            ang = np.arange(k) * (2 * math.pi / k)
            rr = self.target_radius / math.cos(math.pi / k)
            tpts = np.stack([rr * np.cos(ang), rr * np.sin(ang)], axis=1)
        else:
            tpts = self.target
        pts = (gpts[:, None, :] + tpts[None, :, :]).reshape(-1, 2)
        hull = shapely.geometry.polygon.orient(shapely.MultiPoint(pts).convex_hull, 1.0)
        c = np.asarray(hull.exterior.coords)[:-1]  # counter-clockwise
        return c

    def reachable_region(self, start_xy: tuple[float, float]) -> shapely.Geometry:
        """The recognizable placements in the robot's free-space component containing
        ``start_xy`` (robot centre positions)."""
        key = ("reach", round(start_xy[0], 9), round(start_xy[1], 9))
        if key not in self._cache:
            comps = getattr(self.robot_space, "geoms", [self.robot_space])
            pt = Point(start_xy)
            comp = next((c for c in comps if c.intersects(pt)), None)
            self._cache[key] = shapely.Polygon() if comp is None else self.region.intersection(comp)
        return self._cache[key]

    def triangles(self, which: str) -> tuple[np.ndarray, np.ndarray]:
        """Triangulation of G or H for uniform sampling: ``(T, 3, 2)`` vertices and the
        cumulative area weights."""
        key = "tri_" + which
        if key not in self._cache:
            g = self.goal_geom if which == "goal" else self.failure_geom
            tris = shapely.constrained_delaunay_triangles(g)
            arr = np.array([np.asarray(t.exterior.coords)[:3] for t in tris.geoms])
            u, v = arr[:, 1] - arr[:, 0], arr[:, 2] - arr[:, 0]
            areas = np.abs(u[:, 0] * v[:, 1] - u[:, 1] * v[:, 0]) / 2.0
            self._cache[key] = (arr, np.cumsum(areas) / areas.sum())
        return self._cache[key]

    def sample_in(self, which: str, rng: np.random.Generator) -> np.ndarray:
        """A uniform random point of G (``which="goal"``) or H; the point itself if it is one."""
        g = self.goal_geom if which == "goal" else self.failure_geom
        if g.geom_type == "Point":
            return np.array([g.x, g.y])
        arr, cum = self.triangles(which)
        i = int(np.searchsorted(cum, rng.random(), side="right"))
        i = min(i, len(arr) - 1)
        u, v = rng.random(2)
        if u + v > 1:
            u, v = 1 - u, 1 - v
        t = arr[i]
        return t[0] + u * (t[1] - t[0]) + v * (t[2] - t[0])

    # ---- per-step queries (no shapely geometry construction) -------------------------------
    def clearance_field(self) -> tuple[np.ndarray, float, float, float]:
        """``(F, ox, oy, inv_h)``: a ``FIELD_SIZE x FIELD_SIZE`` grid over the bounding box
        (cell ``[i, j]`` covers ``x in ox + [i, i+1) / inv_h``, ``y`` likewise) holding a
        lower bound on the distance from any point of the cell to the nearest wall or
        obstacle edge (cell-centre distance minus half the cell diagonal; 0 in cells
        outside the box)."""
        f = self._cache.get("field")
        if f is None:
            k = FIELD_SIZE
            span = self.hi - self.lo
            h = float(max(span)) / k
            nx = min(k, int(math.ceil(span[0] / h)))
            ny = min(k, int(math.ceil(span[1] / h)))
            cx = self.lo[0] + (np.arange(nx) + 0.5) * h
            cy = self.lo[1] + (np.arange(ny) + 0.5) * h
            X, Y = np.meshgrid(cx, cy, indexing="ij")
            d = point_segment_distance(X.ravel(), Y.ravel(), self.seg_set)
            F = np.zeros((k, k))
            F[:nx, :ny] = np.maximum(d - h * math.sqrt(0.5) * 1.0001, 0.0).reshape(nx, ny)
            f = self._cache["field"] = (F, float(self.lo[0]), float(self.lo[1]), 1.0 / h)
        return f

    def clearance_at(self, x: float, y: float) -> float:
        """A lower bound on the distance from ``(x, y)`` to the nearest wall or obstacle edge
        (from :meth:`clearance_field`; 0 outside the bounding box)."""
        F, ox, oy, inv_h = self.clearance_field()
        return float(field_lookup(F, ox, oy, inv_h, np.array([x]), np.array([y]))[0])

    def in_region(self, x: float, y: float) -> bool:
        return bool(shapely.contains_xy(self.region, x, y))

    def in_free_space(self, x: float, y: float) -> bool:
        return bool(shapely.contains_xy(self.robot_space, x, y))

    def distance_to_region(self, x: float, y: float) -> float:
        """Euclidean distance from ``(x, y)`` to the recognizable region (0 inside it);
        ``inf`` when the region is empty."""
        if not self.region_segs.shape[0]:
            return math.inf
        inside = np.array([self.in_region(x, y)])
        return float(
            region_distance_batch(self.region_rows, np.array([x]), np.array([y]), inside)[0]
        )

    def aim_ok(self, x: float, y: float, psi: float) -> bool:
        """Whether aim ``psi`` from ``(x, y)`` keeps K_G and K_H (the swept hulls) inside the
        field of view for every aim in ``psi +- eps_aim`` and every placement within
        ``eps_pos``, and within ``max_range`` (:func:`.queries.aim_ok_batch` for one pose)."""
        return bool(self.aim_ok_many(np.array([x]), np.array([y]), np.array([psi]))[0])

    def aim_ok_many(self, x: np.ndarray, y: np.ndarray, psi: np.ndarray) -> np.ndarray:
        """:meth:`aim_ok` of many poses ``(N,)`` (world frame, radians): ``(N,)`` bool."""
        r = self.batch_rows()
        return aim_ok_batch(
            np.asarray(x, dtype=np.float64),
            np.asarray(y, dtype=np.float64),
            np.asarray(psi, dtype=np.float64),
            r["hulls"][None],
            r["centers"][None],
            fov=self.fov,
            eps_aim=self.eps_aim,
            eps_pos=self.eps_pos,
            max_range=self.max_range,
        )

    def query(self, x: float, y: float, psi: float) -> tuple[bool, float]:
        """``(recognizing, distance_to_region)``."""
        return self.recognizing(x, y, psi), self.distance_to_region(x, y)

    def batch_rows(self) -> dict[str, Any]:
        """This world as the batched core reads it (computed once): ``segs`` ``(6, S)`` edge
        arrays (:func:`.segments.pad_segments`), ``region_segs`` ``(6, R)`` region boundary,
        ``region_xy`` ``(4, R)`` the same segments' end points (exact vertices, for the
        compiled region test), ``space_xy`` ``(4, F)`` the robot's free space likewise,
        ``hulls`` ``(2, K, 2)`` K_G and K_H padded by repeating their
        last vertex, ``centers`` ``(2, 2)`` their vertex means, ``field``
        (:meth:`clearance_field`)."""
        r = self._cache.get("rows")
        if r is None:
            k = max(len(h) for h in self.must_see)
            hulls = np.stack(
                [np.concatenate([h, np.repeat(h[-1:], k - len(h), 0)]) for h in self.must_see]
            )
            r = self._cache["rows"] = {
                "segs": pad_segments(self.segs, self.seg_normals, self.segs.shape[0]),
                "region_segs": pad_segments(
                    self.region_segs, segment_normals(self.region_segs), self.region_segs.shape[0]
                ),
                "region_xy": np.ascontiguousarray(self.region_segs.T, dtype=np.float64),
                "space_xy": np.ascontiguousarray(
                    boundary_segments(self.robot_space).T, dtype=np.float64
                ),
                "hulls": hulls,
                "centers": np.stack([h.mean(axis=0) for h in self.must_see]),
                "field": self.clearance_field(),
            }
        return r

    def recognizing(self, x: float, y: float, psi: float) -> bool:
        """The pose tells G from H: placement in the recognizable region and aim OK."""
        return self.in_region(x, y) and self.aim_ok(x, y, psi)

    def best_aim(self, x: float, y: float) -> float:
        """The aim pointing at the middle of the directions to K_G and K_H (a convenience for
        oracles and tests; not used by the envs' rewards)."""
        dirs = []
        for K in self.must_see:
            c = K.mean(axis=0)
            dirs.append(math.atan2(c[1] - y, c[0] - x))
        a, b = dirs
        return a + 0.5 * (((b - a) + math.pi) % (2 * math.pi) - math.pi)

    # ---- scene raster (lazy, for grid observations) ----------------------------------------
    def raster(self, size: int) -> np.ndarray:
        """``(3, size, size)`` uint8 channels: not-free (walls/obstacles/outside), G, H.  The
        scene's bounding box is fit into the square grid (aspect kept, centred); row 0 is the
        top (max y)."""
        key = f"raster{size}"
        if key not in self._cache:
            X, Y = self.pixel_centres(size)
            out = np.zeros((3, size, size), dtype=np.uint8)
            out[0] = np.where(shapely.contains_xy(self.free_space, X, Y), 0, 255)
            for k, g in ((1, self.goal_geom), (2, self.failure_geom)):
                if g.geom_type == "Point":
                    i, j = self.to_cell(size, g.x, g.y)
                    out[k, i, j] = 255
                else:
                    m = shapely.contains_xy(g, X, Y)
                    if not m.any():  # thin region: mark its centre
                        i, j = self.to_cell(size, *_anchor(g))
                        m[i, j] = True
                    out[k] = np.where(m, 255, 0)
            self._cache[key] = out
        return self._cache[key]

    def view_raster(self, size: int) -> np.ndarray:
        """``(2, size, size)`` uint8 on :meth:`raster`'s grid: 255 where a pixel's centre lies
        in the visibility polygon of G's / H's anchor point (the free space seen from there, the
        raster twin of the vector observation's two scans), else 0."""
        key = f"views{size}"
        if key not in self._cache:
            anchors = [
                np.asarray([c], dtype=np.float64) for c in (self.goal_center, self.failure_center)
            ]
            self._cache[key] = self._seen_from_all(size, anchors)
        return self._cache[key]

    def hull_view_raster(self, size: int) -> np.ndarray:
        """``(2, size, size)`` uint8 on :meth:`raster`'s grid: 255 where a pixel's centre lies
        in the visibility polygon of *every* vertex of K_G (channel 0) / K_H (channel 1), the
        hulls the sensor must see, and outside both hulls (where the target may stand), else 0:
        where all of a hull's corners are in view from outside.  Each vertex is moved 1e-9 of
        the way towards its hull's centre first; one still outside the free space (a corner on
        a wall) is left out; a hull with none left gives 0."""
        key = f"hullviews{size}"
        if key not in self._cache:
            corners = [h + 1e-9 * (h.mean(axis=0) - h) for h in self.must_see]
            out = self._seen_from_all(size, corners)
            X, Y = self.pixel_centres(size)
            for h in self.must_see:
                out[:, shapely.contains_xy(shapely.Polygon(h), X, Y)] = 0
            self._cache[key] = out
        return self._cache[key]

    def aim_raster(self, size: int, aims: int) -> np.ndarray:
        """``(aims, size, size)`` uint8 on :meth:`raster`'s grid: 255 where the sensor at a
        pixel's centre, aimed at ``-pi + 2 pi k / aims`` radians (channel ``k``: the pixel
        action's aim ``k``), passes the aim test of the reward (:meth:`aim_ok`: K_G and K_H
        inside the field of view with the ``eps_aim`` / ``eps_pos`` margins, and within
        ``max_range``), else 0.  Occlusion is not part of it (:meth:`hull_view_raster`)."""
        key = f"aims{size}_{aims}"
        if key not in self._cache:
            X, Y = self.pixel_centres(size)
            psi = math.pi * (-1.0 + 2.0 * np.arange(aims) / aims)
            ok = self.aim_ok_many(
                np.tile(X.ravel(), aims), np.tile(Y.ravel(), aims), np.repeat(psi, size * size)
            )
            self._cache[key] = np.where(ok.reshape(aims, size, size), 255, 0).astype(np.uint8)
        return self._cache[key]

    def hint_field(self, size: int = HINT_SIZE, aim: bool = True) -> tuple[np.ndarray, np.ndarray]:
        """The ``view_hint`` field on :meth:`raster`'s grid of ``size`` pixels: ``(ahead,
        dist)``.  ``dist`` ``(size, size)``: the length (scene units) of the cheapest
        8-connected grid path from a pixel to the nearest *target pixel*, ``inf`` where none
        can be reached; a step costs its length times ``1 + 4 (1 - c / 3)`` within 3 pixels
        of the robot space's edge (``c`` the clearance in pixels), so paths keep off walls.
        ``ahead`` ``(len(HINT_AHEAD), size, size, 2)``: waypoints on that path (world frame),
        the pixels :data:`HINT_AHEAD` steps of steepest descent further on (the target pixel
        itself near the end; the pixel's own centre where none can be reached).

        Target pixels: centres in the robot's free space that see every corner of K_G and of
        K_H (:meth:`hull_view_raster`), admit an aim that passes the aim test
        (:meth:`aim_raster`, 16 aims) and lie outside K_G and K_H: map geometry alone, not the
        recognizable region.  ``aim=False`` drops the aim test for the range test alone
        (every hull vertex within ``max_range``, less ``eps_pos``): poses for a robot that
        turns to each hull in turn, as Recognize-v0 allows.  Paths run over pixels whose
        centres are in the robot's free space; a pixel outside it takes the values of the
        nearest one inside."""
        key = f"hint{size}" if aim else f"hint{size}noaim"
        got = self._cache.get(key)
        if got is not None:
            return got
        from scipy import ndimage
        from scipy.sparse import coo_matrix
        from scipy.sparse.csgraph import dijkstra

        X, Y = self.pixel_centres(size)
        space = shapely.contains_xy(self.robot_space, X, Y)
        hv = self.hull_view_raster(size)
        goal = space & (hv[0] > 0) & (hv[1] > 0)
        if aim:
            goal &= (self.aim_raster(size, 16) > 0).any(axis=0)
        elif math.isfinite(self.max_range):
            far = np.zeros_like(X)
            for h in self.must_see:
                far = np.maximum(
                    far, np.hypot(X[..., None] - h[:, 0], Y[..., None] - h[:, 1]).max(-1)
                )
            goal &= far + self.eps_pos <= self.max_range
        dist = np.full(size * size, np.inf)
        nxt = np.arange(size * size)  # steepest-descent successor (flat pixel index)
        if goal.any():
            flat = np.arange(size * size).reshape(size, size)
            free = np.flatnonzero(space)
            cost = 1.0 + 4.0 * np.clip(1.0 - ndimage.distance_transform_edt(space) / 3.0, 0, 1)
            # a step joins two pixels only where its segment stays in the robot's space: a
            # wall thinner than a pixel holds no pixel centre, and must still block the path
            pix = 1.0 / self.grid_transform(size)[0]
            shapely.prepare(self.robot_space)
            clear = self.hint_clearance(size).ravel()
            rows, cols, w = [], [], []
            step = {}  # (di, dj) -> where a pixel may step to its neighbour at that offset
            for di, dj in ((0, 1), (1, 0), (1, 1), (1, -1)):
                a = flat[: size - di, max(0, -dj) : size - max(0, dj)]
                b = flat[di:, max(0, dj) : size + min(0, dj)]
                ok = (
                    space[: size - di, max(0, -dj) : size - max(0, dj)]
                    & space[di:, max(0, dj) : size + min(0, dj)]
                )
                near = ok & (clear[a] < math.hypot(di, dj) * pix)  # else the step is clear
                if near.any():
                    ia, ib = a[near], b[near]
                    seg = shapely.linestrings(
                        np.stack(
                            [
                                np.column_stack([X.ravel()[ia], Y.ravel()[ia]]),
                                np.column_stack([X.ravel()[ib], Y.ravel()[ib]]),
                            ],
                            axis=1,
                        )
                    )
                    ok[near] = shapely.covers(self.robot_space, seg)
                fwd = np.zeros((size, size), dtype=bool)
                fwd[: size - di, max(0, -dj) : size - max(0, dj)] = ok
                back = np.zeros((size, size), dtype=bool)
                back[di:, max(0, dj) : size + min(0, dj)] = ok
                step[(di, dj)], step[(-di, -dj)] = fwd, back
                rows.append(a[ok])
                cols.append(b[ok])
                ca = cost[: size - di, max(0, -dj) : size - max(0, dj)][ok]
                cb = cost[di:, max(0, dj) : size + min(0, dj)][ok]
                w.append(0.5 * (ca + cb) * math.hypot(di, dj) / self.grid_transform(size)[0])
            pos = np.full(size * size, -1)
            pos[free] = np.arange(len(free))
            g = coo_matrix(
                (np.concatenate(w), (pos[np.concatenate(rows)], pos[np.concatenate(cols)])),
                shape=(len(free), len(free)),
            ).tocsr()
            dist[free] = dijkstra(g, directed=False, indices=pos[flat[goal]], min_only=True)
            d2 = dist.reshape(size, size)
            pad = np.pad(d2, 1, constant_values=np.inf)
            best = d2.copy()
            succ = flat.copy()
            for di in (-1, 0, 1):
                for dj in (-1, 0, 1):
                    if di == dj == 0:
                        continue
                    nb = pad[1 + di : 1 + di + size, 1 + dj : 1 + dj + size]
                    better = (nb < best) & step[(di, dj)]  # along the graph's edges only
                    best = np.where(better, nb, best)
                    succ = np.where(better, np.roll(np.roll(flat, -di, 0), -dj, 1), succ)
            nxt = succ.ravel()
        ways = []
        for k in HINT_AHEAD:
            ahead = np.arange(size * size)
            for _ in range(k):
                ahead = nxt[ahead]
            ways.append(np.stack([X.ravel()[ahead], Y.ravel()[ahead]], axis=1))
        way = np.stack(ways).reshape(len(HINT_AHEAD), size, size, 2)
        dist = dist.reshape(size, size)
        inside = np.isfinite(dist)
        if inside.any() and not inside.all():  # outside the robot's space: the nearest
            near = ndimage.distance_transform_edt(
                ~inside, return_distances=False, return_indices=True
            )
            dist = dist[near[0], near[1]]
            way = way[:, near[0], near[1]]
        got = self._cache[key] = (way, dist)
        return got

    def _seen_from_all(self, size: int, groups: list[np.ndarray]) -> np.ndarray:
        """``(len(groups), size, size)`` uint8: 255 where a pixel's centre lies in the
        visibility polygon of every point of group k that is in the free space (the others
        are left out; a group with none left gives 0)."""
        from geometry._vis import domain_from_geometry, visibility_polygon

        X, Y = self.pixel_centres(size)
        dom = domain_from_geometry(self.free_space)
        out = np.zeros((len(groups), size, size), dtype=np.uint8)
        for k, pts in enumerate(groups):
            pts = pts[shapely.contains_xy(self.free_space, pts[:, 0], pts[:, 1])]
            seen = np.full((size, size), len(pts) > 0)
            for v in pts:
                seen &= shapely.contains_xy(visibility_polygon(dom, v), X, Y)
            out[k] = np.where(seen, 255, 0)
        return out

    def pixel_centres(self, size: int) -> tuple[np.ndarray, np.ndarray]:
        """``(X, Y)`` ``(size, size)``: the world coordinates of the centres of :meth:`raster`'s
        pixels (row 0 at the top); cached, read-only."""
        key = f"centres{size}"
        got = self._cache.get(key)
        if got is None:
            scale, ox, oy = self.grid_transform(size)
            ij = np.arange(size) + 0.5
            got = tuple(np.meshgrid(ox + ij / scale, oy + (size - ij) / scale))
            for a in got:
                a.setflags(write=False)
            self._cache[key] = got
        return got

    def grid_transform(self, size: int) -> tuple[float, float, float]:
        span = float(max(self.hi - self.lo))
        scale = size / span
        ox = float(self.lo[0]) - 0.5 * (span - float(self.hi[0] - self.lo[0]))
        oy = float(self.lo[1]) - 0.5 * (span - float(self.hi[1] - self.lo[1]))
        return scale, ox, oy

    def hint_clearance(self, size: int = HINT_SIZE) -> np.ndarray:
        """``(size, size)``: the exact distance from each pixel centre of :meth:`raster`'s grid
        to the robot space's boundary (scene units), 0 for centres outside the space (cached)."""
        key = f"hintclear{size}"
        got = self._cache.get(key)
        if got is None:
            X, Y = self.pixel_centres(size)
            got = np.zeros((size, size))
            inside = shapely.contains_xy(self.robot_space, X, Y)
            got[inside] = shapely.distance(
                self.robot_space.boundary, shapely.points(X[inside], Y[inside])
            )
            got = self._cache[key] = got
        return got

    def hint_cells(
        self, x, y, size: int = HINT_SIZE, aim: bool = True
    ) -> tuple[np.ndarray, np.ndarray]:
        """The pixels ``(i, j)`` of :meth:`hint_field`'s grid whose paths poses ``(x, y)``
        (world frame) follow: the pixel holding the point when the segment from the point to
        its centre lies in the robot's space (so no wall between them), else
        :meth:`hint_search`'s pixel.  A wall thinner than a pixel holds no pixel centre, so
        the holding pixel, or the nearest one inside the space whose values it takes, can
        lie behind it."""
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        i, j = self.to_cell(size, x, y)
        X, Y = self.pixel_centres(size)
        clear = self.hint_clearance(size)[i, j]
        space = np.full(len(x), self.robot_space, dtype=object)
        bad = hint_blocked(x, y, X[i, j], Y[i, j], clear, space)
        if bad.any():
            i[bad], j[bad] = self.hint_search(x[bad], y[bad], i[bad], j[bad], size, aim)
        return i, j

    def hint_search(
        self, x, y, i, j, size: int = HINT_SIZE, aim: bool = True
    ) -> tuple[np.ndarray, np.ndarray]:
        """For poses ``(x, y)`` held by pixels ``(i, j)`` behind a wall: the pixel of the
        5 x 5 around each in the robot's space whose centre the pose sees and whose way on
        (the segment plus its path; :meth:`hint_field` with ``aim``) is shortest; the holding
        pixel where there is none."""
        i, j = np.array(i), np.array(j)
        dist = self.hint_field(size, aim)[1]
        X, Y = self.pixel_centres(size)
        inside = self.hint_clearance(size) > 0.0
        shapely.prepare(self.robot_space)
        off = np.arange(-2, 3)
        di, dj = (a.ravel() for a in np.meshgrid(off, off, indexing="ij"))
        ci = np.clip(i[:, None] + di, 0, size - 1)  # (m, 25)
        cj = np.clip(j[:, None] + dj, 0, size - 1)
        cx, cy = X[ci, cj], Y[ci, cj]
        px, py = np.broadcast_to(x[:, None], cx.shape), np.broadcast_to(y[:, None], cx.shape)
        ok = inside[ci, cj] & np.isfinite(dist[ci, cj])
        seg = shapely.linestrings(
            np.stack([np.stack([px, py], -1), np.stack([cx, cy], -1)], axis=-2)[ok]
        )
        seen = np.zeros_like(ok)
        seen[ok] = shapely.covers(self.robot_space, seg)
        way = np.where(seen, np.hypot(cx - px, cy - py) + dist[ci, cj], np.inf)
        best = np.argmin(way, axis=1)
        found = np.isfinite(way[np.arange(len(i)), best])
        i[found] = ci[found, best[found]]
        j[found] = cj[found, best[found]]
        return i, j

    def to_cell(self, size: int, x, y):
        """The pixel ``(i, j)`` (row, column) of :meth:`raster`'s grid holding world points."""
        return pixel_of(self.grid_transform(size), size, x, y)


def pixel_of(transform, size: int, x, y) -> tuple[np.ndarray, np.ndarray]:
    """The pixels ``(i, j)`` (row, column) of a ``size`` grid holding world points ``(x, y)``,
    clipped to the grid; ``transform`` = ``(scale, ox, oy)`` (:meth:`World.grid_transform`),
    or an array of them ``(k, 3)``, one per point (per row of ``(k, B)`` points)."""
    scale, ox, oy = np.asarray(transform, dtype=float).T
    if np.ndim(x) == 2:
        scale, ox, oy = scale[:, None], ox[:, None], oy[:, None]
    j = np.clip(((np.asarray(x) - ox) * scale).astype(int), 0, size - 1)
    i = np.clip((size - (np.asarray(y) - oy) * scale).astype(int), 0, size - 1)
    return i, j


def hint_blocked(x, y, cx, cy, clear, space) -> np.ndarray:
    """Where the segment from each pose ``(x, y)`` to its pixel centre ``(cx, cy)`` (clearance
    ``clear``, 0 outside the robot's space; world frame) leaves the robot's ``space`` (an
    array of geometries, one per pose).  The segment lies in the disc of its length around
    the centre, so only where that disc reaches the boundary is there something to test."""
    bad = ~(clear > np.hypot(x - cx, y - cy))
    test = np.flatnonzero(bad & (clear > 0.0))
    if len(test):
        seg = shapely.linestrings(
            np.stack(
                [np.column_stack([x[test], y[test]]), np.column_stack([cx[test], cy[test]])],
                axis=1,
            )
        )
        bad[test] = ~shapely.covers(space[test], seg)
    return bad


def _anchor(g: shapely.Geometry) -> tuple[float, float]:
    """Centroid of G/H, or a representative interior point if the centroid lies outside."""
    if g.geom_type == "Point":
        return (float(g.x), float(g.y))
    c = g.centroid
    if not g.contains(c):
        c = g.representative_point()
    return (float(c.x), float(c.y))


def field_lookup(
    F: np.ndarray, ox, oy, inv_h, x: np.ndarray, y: np.ndarray, rows: np.ndarray | None = None
) -> np.ndarray:
    """Values of clearance fields at points ``(x, y)``: ``F`` ``(k, k)`` for all points, or
    ``(N, k, k)`` with point ``p`` read from field ``rows[p]``; origins ``ox, oy`` and scales
    ``inv_h`` scalars or per point; 0 outside the field."""
    fi = (x - ox) * inv_h
    fj = (y - oy) * inv_h
    k = F.shape[-1]
    inside = (fi >= 0) & (fj >= 0) & (fi < k) & (fj < k)
    i = np.where(inside, fi, 0).astype(np.intp)
    j = np.where(inside, fj, 0).astype(np.intp)
    v = F[i, j] if F.ndim == 2 else F[rows, i, j]
    return np.where(inside, v, 0.0)


__all__ += ["field_lookup"]
