"""Scene loading and everything the environments derive from a scene.

A :class:`World` bundles one validated :class:`geometry.Scene` with one
configuration (visibility model, target motion, uncertainty, sensor limits,
robot radius) and precomputes, once, everything that does not change during an
episode:

* the exact recognizable region R(G) n R(H) - C(G, H) from
  :func:`geometry.recognizable_region`, prepared for fast point queries, and its
  boundary as a segment array (numpy point-to-region distance);
* the part of that region the robot can reach from its start;
* the environment's edges (walls and merged obstacles) as an ``(S, 4)`` array
  with unit normals, used by the range sensor and the collision sweep;
* the convex "must-see" sets K_G = CH(target swept over G) and K_H used by the
  aim check (:meth:`World.aim_ok`).

Worlds are cached in a module-level LRU keyed by the scene's JSON and the
configuration, so resetting an environment on a bundled scene costs nothing.

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
the geometry does not support (``"rotating"`` with the partial model, or a point
G with a polygonal H in the partial model) raise ``NotImplementedError``
carrying the geometry's message.
"""

from __future__ import annotations

import json
import math
from collections import OrderedDict
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import shapely
import shapely.geometry.polygon
from shapely.geometry import Point

from geometry import Scene, SceneError, recognizable_region

from .sensor import Segments

_UNIT = np.array([[1.0, 0.0]])

__all__ = [
    "BUNDLED_SCENES",
    "MODELS",
    "MOTIONS",
    "World",
    "WorldConfig",
    "bundled_scene_path",
    "get_world",
    "load_scene",
    "sweep",
]

SCENE_DIR = Path(__file__).resolve().parent.parent / "scenes"
BUNDLED_SCENES = tuple(sorted(p.stem for p in SCENE_DIR.glob("*.json")))
MODELS = ("complete", "partial")
MOTIONS = ("stationary", "translating", "rotating")
_CACHE_SIZE = 64
_CACHE: OrderedDict[tuple, World] = OrderedDict()


def bundled_scene_path(name: str) -> Path:
    return SCENE_DIR / f"{name}.json"


def load_scene(spec: str | Path | Scene | dict) -> Scene:
    """A bundled scene name, a path to a scene JSON, a Scene or a scene dict."""
    if isinstance(spec, Scene):
        return spec
    if isinstance(spec, dict):
        return Scene.from_dict(spec)
    s = str(spec)
    if s in BUNDLED_SCENES:
        return Scene.load(bundled_scene_path(s))
    p = Path(s)
    if p.suffix == ".json" or p.exists():
        if not p.exists():
            raise FileNotFoundError(f"scene file not found: {p}")
        return Scene.load(p)
    raise ValueError(
        f"unknown scene {s!r}: use a bundled name ({', '.join(BUNDLED_SCENES)}), "
        "a path to a scene JSON file, or 'random'"
    )


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

    def validate(self) -> WorldConfig:
        if self.model not in MODELS:
            raise ValueError(f"model must be one of {MODELS}, got {self.model!r}")
        if self.motion not in MOTIONS:
            raise ValueError(f"motion must be one of {MOTIONS}, got {self.motion!r}")
        for name in ("eps_pos", "eps_aim", "fov", "max_range"):
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
    d = segs[:, 2:] - segs[:, :2]
    n = np.stack([-d[:, 1], d[:, 0]], axis=1)
    L = np.hypot(n[:, 0], n[:, 1])
    L[L == 0] = 1.0
    return n / L[:, None]


def sweep(p, d, S: Segments, radius: float, skin: float) -> float:
    """Largest fraction ``t`` in [0, 1] of the motion ``p -> p + d`` that keeps a disc of
    ``radius`` at ``p`` from crossing into any segment of ``S`` (a capsule sweep), backed off
    by ``skin`` measured along the contact normal.  ``radius=0`` is a point robot.
    Vectorised over segments; a disc already touching a segment cannot move further into
    it."""
    dx, dy = float(d[0]), float(d[1])
    if not S.n or (dx == 0.0 and dy == 0.0):
        return 1.0
    if radius == 0.0:  # a point: one ray p + t d, t in [0, 1], against every segment
        ax = S.x0 - p[0]
        ay = S.y0 - p[1]
        den = dx * S.ey - dy * S.ex
        par = den == 0.0  # parallel (or collinear): no crossing
        inv = np.divide(1.0, den, out=np.zeros_like(den), where=~par)
        t = (ax * S.ey - ay * S.ex) * inv
        u = (ax * dy - ay * dx) * inv
        t[par | ~((t >= 0.0) & (u >= 0.0) & (u <= 1.0))] = np.inf
        i = int(t.argmin())
        if not t[i] <= 1.0:
            return 1.0
        rate = abs(float(S.nx[i]) * dx + float(S.ny[i]) * dy)  # approach speed
        return max(0.0, float(t[i]) - skin / max(rate, 1e-300))
    ax = p[0] - S.x0
    ay = p[1] - S.y0
    L = np.sqrt(S.L2)
    nx, ny = -S.ey / L, S.ex / L
    s0 = nx * ax + ny * ay  # signed distance to the line
    sd = nx * dx + ny * dy  # its rate of change
    toward = s0 * sd < 0
    on = np.abs(s0) <= radius
    toward |= on & (sd != 0) & ((s0 == 0) | toward)
    with np.errstate(divide="ignore", invalid="ignore"):
        t_line = np.where(on, 0.0, (np.sign(s0) * radius - s0) / sd)
        u = ((ax + t_line * dx) * S.ex + (ay + t_line * dy) * S.ey) * S.inv_L2
    ok = toward & (t_line >= 0) & (t_line <= 1) & (u >= 0) & (u <= 1)
    t_best = 1.0
    back = np.inf
    if ok.any():
        i = np.argmin(np.where(ok, t_line, np.inf))
        t_best = float(t_line[i])
        back = skin / abs(float(sd[i]))
    if radius > 0:
        dd = dx * dx + dy * dy
        for px, py in ((ax, ay), (p[0] - (S.x0 + S.ex), p[1] - (S.y0 + S.ey))):
            b = px * dx + py * dy
            c = px * px + py * py - radius * radius
            disc = b * b - dd * c
            with np.errstate(invalid="ignore"):
                t = (-b - np.sqrt(np.maximum(disc, 0.0))) / dd
            t = np.where(c <= 0, 0.0, t)
            hit = (disc >= 0) & (b < 0) & (t >= 0) & (t <= 1)
            if hit.any():
                j = np.argmin(np.where(hit, t, np.inf))
                if t[j] < t_best:
                    t_best = float(t[j])
                    qx, qy = px[j] + t_best * dx, py[j] + t_best * dy
                    rate = abs(qx * dx + qy * dy) / max(radius, 1e-300)
                    back = skin / max(rate, 1e-300)
    if t_best >= 1.0:
        return 1.0
    return max(0.0, t_best - back)


class World:
    """One scene under one configuration (see the module docstring).  Treat as immutable."""

    def __init__(self, scene: Scene, cfg: WorldConfig) -> None:
        cfg.validate()
        self.cfg = cfg
        sensor = scene.sensor
        self.model = cfg.model
        self.motion = cfg.motion
        if cfg.motion == "stationary":
            scene = scene.replace(
                goal=[list(_anchor(scene.goal_geom))], failure=[list(_anchor(scene.failure_geom))]
            )
        self.scene = scene
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

        try:
            region = recognizable_region(
                scene, model=cfg.model, theta=self.theta, eps_pos=self.eps_pos, eps_aim=self.eps_aim
            )
        except NotImplementedError as e:
            raise NotImplementedError(
                f"scene {scene.name!r} with model={cfg.model!r}, motion={cfg.motion!r}: {e}"
            ) from e
        self.region = region
        shapely.prepare(self.region)
        self.region_segs = boundary_segments(region)

        self.free_space = scene.free_space
        self.segs = boundary_segments(self.free_space)
        self.seg_normals = segment_normals(self.segs)
        self.seg_set = Segments(self.segs, self.seg_normals)
        self._region_fast = _FastDistance(self.region_segs)
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
    def clearance_at(self, x: float, y: float) -> float:
        """A lower bound on the distance from ``(x, y)`` to the nearest wall or obstacle edge,
        from a lazily built 64 x 64 distance field (cell-centre distance minus half the cell
        diagonal); 0 outside the bounding box."""
        f = self._cache.get("field")
        if f is None:
            f = self._cache["field"] = self._clearance_field(64)
        F, ox, oy, inv_h = f
        i = int((x - ox) * inv_h)
        j = int((y - oy) * inv_h)
        if 0 <= i < len(F) and 0 <= j < len(F[0]) and x >= ox and y >= oy:
            return F[i][j]
        return 0.0

    def _clearance_field(self, k: int):
        span = self.hi - self.lo
        h = float(max(span)) / k
        nx = int(math.ceil(span[0] / h))
        ny = int(math.ceil(span[1] / h))
        cx = self.lo[0] + (np.arange(nx) + 0.5) * h
        cy = self.lo[1] + (np.arange(ny) + 0.5) * h
        X, Y = np.meshgrid(cx, cy, indexing="ij")
        P = np.stack([X.ravel(), Y.ravel()], axis=1)
        S = self.seg_set
        px = P[:, 0:1] - S.x0
        py = P[:, 1:2] - S.y0
        t = np.clip((px * S.ex + py * S.ey) * S.inv_L2, 0.0, 1.0)
        d = np.sqrt(np.min((px - t * S.ex) ** 2 + (py - t * S.ey) ** 2, axis=1))
        d = np.maximum(d - h * math.sqrt(0.5) * 1.0001, 0.0).reshape(nx, ny)
        return d.tolist(), float(self.lo[0]), float(self.lo[1]), 1.0 / h

    def in_region(self, x: float, y: float) -> bool:
        return bool(_contains_xy(self.region, x, y))

    def in_free_space(self, x: float, y: float) -> bool:
        return bool(_contains_xy(self.robot_space, x, y))

    def distance_to_region(self, x: float, y: float) -> float:
        """Euclidean distance from ``(x, y)`` to the recognizable region (0 inside it);
        ``inf`` when the region is empty."""
        if not self.region_segs.shape[0]:
            return math.inf
        if _contains_xy(self.region, x, y):
            return 0.0
        return self._region_fast(x, y)

    def aim_ok(self, x: float, y: float, psi: float) -> bool:
        """Whether aim ``psi`` from ``(x, y)`` keeps K_G and K_H (the swept hulls) inside the
        field of view for every aim in ``psi +- eps_aim`` and every placement within
        ``eps_pos`` (the angular margin grows by ``asin(eps_pos / dist(p, K))``), and within
        ``max_range`` (farthest hull vertex + ``eps_pos``)."""
        full = self.fov >= 2 * math.pi - 1e-12
        if full and math.isinf(self.max_range):
            return True
        half = 0.5 * self.fov
        for K in self.must_see:
            dv = K - (x, y)
            dist = np.hypot(dv[:, 0], dv[:, 1])
            if dist.max() + self.eps_pos > self.max_range:
                return False
            if full:
                continue
            # p strictly outside convex K (CCW): some edge has p on its right
            e = np.roll(K, -1, axis=0) - K
            cr = e[:, 0] * (-dv[:, 1]) - e[:, 1] * (-dv[:, 0])
            if np.all(cr >= 0):
                return False  # p inside K: K surrounds the sensor
            c = K.mean(axis=0)
            base = math.atan2(c[1] - y, c[0] - x)
            rel = np.arctan2(dv[:, 1], dv[:, 0]) - base
            rel = (rel + math.pi) % (2 * math.pi) - math.pi
            off = (base - psi + math.pi) % (2 * math.pi) - math.pi
            margin = self.eps_aim
            if self.eps_pos > 0:
                L2 = np.maximum((e * e).sum(axis=1), 1e-300)
                t = np.clip((dv[:, 0] * -e[:, 0] + dv[:, 1] * -e[:, 1]) / L2, 0, 1)
                dmin = float(np.min(np.hypot(-dv[:, 0] - t * e[:, 0], -dv[:, 1] - t * e[:, 1])))
                margin += math.asin(min(1.0, self.eps_pos / max(dmin, 1e-300)))
            if off + rel.min() < -half + margin or off + rel.max() > half - margin:
                return False
        return True

    def query(self, x: float, y: float, psi: float) -> tuple[bool, float]:
        """``(recognizing, distance_to_region)`` with one point-in-region test."""
        if not self.region_segs.shape[0]:
            return False, math.inf
        if _contains_xy(self.region, x, y):
            return self.aim_ok(x, y, psi), 0.0
        return False, self._region_fast(x, y)

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
            scale, ox, oy = self.grid_transform(size)
            ij = np.arange(size) + 0.5
            X, Y = np.meshgrid(ox + ij / scale, oy + (size - ij) / scale)
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

    def grid_transform(self, size: int) -> tuple[float, float, float]:
        span = float(max(self.hi - self.lo))
        scale = size / span
        ox = float(self.lo[0]) - 0.5 * (span - float(self.hi[0] - self.lo[0]))
        oy = float(self.lo[1]) - 0.5 * (span - float(self.hi[1] - self.lo[1]))
        return scale, ox, oy

    def to_cell(self, size: int, x, y):
        scale, ox, oy = self.grid_transform(size)
        j = np.clip(((np.asarray(x) - ox) * scale).astype(int), 0, size - 1)
        i = np.clip((size - (np.asarray(y) - oy) * scale).astype(int), 0, size - 1)
        return i, j


try:  # the ufunc without shapely's argument handling: ~2x faster for one point
    from shapely.lib import contains_xy as _contains_xy
except ImportError:  # pragma: no cover
    _contains_xy = shapely.contains_xy


class _FastDistance:
    """Exact point-to-segments distance.  After 50 queries a 32 x 32 grid over the segments'
    bounding box (grown by 10%) is built that lists, per cell, the only segments that can be
    nearest to a point of that cell (distance at the cell centre within the nearest one's
    plus a cell diagonal), so a query is a short Python loop; queries outside the grid check
    every segment.  (Lazy, so short-lived worlds such as random scenes pay nothing.)"""

    def __init__(self, segs: np.ndarray) -> None:
        self.segs = segs
        self.rows = [
            (
                float(x0),
                float(y0),
                float(x1 - x0),
                float(y1 - y0),
                1.0 / ((x1 - x0) ** 2 + (y1 - y0) ** 2) if (x1 - x0) or (y1 - y0) else 0.0,
            )
            for x0, y0, x1, y1 in segs
        ]
        self.grid = None
        self.calls = 0

    def __getstate__(self):
        return {"segs": self.segs}

    def __setstate__(self, st):
        self.__init__(st["segs"])

    def _build(self, k: int = 32) -> None:
        segs = self.segs
        lo = np.minimum(segs[:, :2], segs[:, 2:]).min(axis=0)
        hi = np.maximum(segs[:, :2], segs[:, 2:]).max(axis=0)
        pad = 0.05 * (hi - lo) + 1e-9
        lo, hi = lo - pad, hi + pad
        h = float(max(hi - lo)) / k
        nx = max(1, int(math.ceil((hi[0] - lo[0]) / h)))
        ny = max(1, int(math.ceil((hi[1] - lo[1]) / h)))
        cx = lo[0] + (np.arange(nx) + 0.5) * h
        cy = lo[1] + (np.arange(ny) + 0.5) * h
        X, Y = np.meshgrid(cx, cy, indexing="ij")
        S = Segments(segs)
        px = X.reshape(-1, 1) - S.x0
        py = Y.reshape(-1, 1) - S.y0
        t = np.clip((px * S.ex + py * S.ey) * S.inv_L2, 0.0, 1.0)
        d = np.sqrt((px - t * S.ex) ** 2 + (py - t * S.ey) ** 2)
        cand = d <= d.min(axis=1, keepdims=True) + 2 * h * math.sqrt(0.5) * 1.0001 + 1e-12
        rows = self.rows
        ci, sj = np.nonzero(cand)
        cells: list[list] = [[] for _ in range(cand.shape[0])]
        for i, j in zip(ci.tolist(), sj.tolist(), strict=True):
            cells[i].append(rows[j])
        self.grid = (
            [cells[i * ny : (i + 1) * ny] for i in range(nx)],
            float(lo[0]),
            float(lo[1]),
            1.0 / h,
            nx,
            ny,
        )

    def __call__(self, x: float, y: float) -> float:
        if not self.rows:
            return math.inf
        if self.grid is None:
            self.calls += 1
            if len(self.rows) <= 8:
                self.grid = False
            elif self.calls > 50:
                self._build()
        rows = self.rows
        if self.grid:
            G, ox, oy, inv_h, nx, ny = self.grid
            fi = (x - ox) * inv_h
            fj = (y - oy) * inv_h
            if 0.0 <= fi < nx and 0.0 <= fj < ny:
                rows = G[int(fi)][int(fj)]
        best = math.inf
        for x0, y0, ex, ey, il2 in rows:
            px, py = x - x0, y - y0
            t = (px * ex + py * ey) * il2
            if t < 0.0:
                t = 0.0
            elif t > 1.0:
                t = 1.0
            qx, qy = px - t * ex, py - t * ey
            d2 = qx * qx + qy * qy
            if d2 < best:
                best = d2
        return math.sqrt(best)


def _anchor(g: shapely.Geometry) -> tuple[float, float]:
    """Centroid of G/H, or a representative interior point if the centroid lies outside."""
    if g.geom_type == "Point":
        return (float(g.x), float(g.y))
    c = g.centroid
    if not g.contains(c):
        c = g.representative_point()
    return (float(c.x), float(c.y))


def _key(scene: Scene, cfg: WorldConfig, data: dict | None = None) -> tuple:
    return (json.dumps(scene.to_dict() if data is None else data, sort_keys=True), cfg)


def get_world(scene: Scene, cfg: WorldConfig, data: dict | None = None) -> World:
    """The cached :class:`World` for ``(scene, cfg)`` (LRU of 64 entries).  ``data``: the
    scene's JSON dict when the caller has it (saves a deep copy)."""
    key = _key(scene, cfg, data)
    w = _CACHE.get(key)
    if w is not None:
        _CACHE.move_to_end(key)
        return w
    w = World(scene, cfg)
    _CACHE[key] = w
    if len(_CACHE) > _CACHE_SIZE:
        _CACHE.popitem(last=False)
    return w


def clear_cache() -> None:
    _CACHE.clear()


__all__ += ["SceneError", "Segments", "boundary_segments", "clear_cache", "segment_normals"]
