"""Scene families: named parameter ranges that procedural scenes are drawn from.

A :class:`SceneFamily` is a small declarative description of a distribution of scenes:

* the sensor's field of view (degrees, 45--360) and, optionally, a maximum range (as a
  fraction of the scene's diameter, drawn with probability ``range_limited``);
* the room's shape class (:data:`ROOM_SHAPES`): ``rectangle``, ``corridor`` (a long
  rectangle), ``L`` (one corner cut out), ``U`` (a notch cut into one side) and ``rooms``
  (a multi-room floor: partition walls with doorways, built as thin slits cut into the
  outline so the walls stay one simple polygon, after :mod:`benchmarks.make_office_floor`);
* the clutter density (obstacle area / room area);
* point or polygonal G and H, a convex or non-convex target, the scene's diameter.

:meth:`SceneFamily.sample` draws a valid :class:`geometry.Scene` (re-drawing a bounded number
of times, then raising ``RuntimeError`` naming the family); :func:`scene_parameters` measures
the same parameters on any scene and :meth:`SceneFamily.contains` says whether they lie in
the family's support, so a hand-made scene can be placed inside (or outside) a family.

Benchmark levels :data:`DIFFICULTIES` (``easy`` / ``medium`` / ``hard``) are families plus a
``min_start_distance`` (fraction of the scene's diameter between the robot's start and the
recognizable region).  Polygonal G/H are only in ``hard`` (the bundled scenes have them);
with ``model="partial"`` their regions are slow to build (issue 25), so for partial-model
pools use ``dataclasses.replace(HARD, region_kinds=("point",))``.

Everything is deterministic in the numpy ``Generator``.  Pure numpy + shapely; the
scenes satisfy the paper's assumption for a rotating target (walls and obstacles stay off
CH(G (+) disc(r)) and CH(H (+) disc(r)), r the target's radius), as
:func:`geometry.generate.random_scene` does.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import shapely
from shapely.geometry import Point, Polygon

from .generate import _coords, _region, _round, random_polygon
from .scene import Scene, SceneError

__all__ = [
    "ROOM_SHAPES",
    "REGION_KINDS",
    "SceneFamily",
    "Difficulty",
    "EASY",
    "MEDIUM",
    "HARD",
    "FAMILIES",
    "DIFFICULTIES",
    "get_family",
    "get_difficulty",
    "scene_parameters",
]

#: Room shape classes, as :func:`scene_parameters` classifies an outline by its reflex corners
#: (0: ``rectangle``, or ``corridor`` when its aspect ratio is at least :data:`CORRIDOR_ASPECT`
#: -- any convex outline counts as one of these two; 1: ``L``; 2: ``U``; 3 or more: ``rooms``).
ROOM_SHAPES = ("rectangle", "corridor", "L", "U", "rooms")
#: Kinds of G and H.
REGION_KINDS = ("point", "polygon")
#: Aspect ratio (long side / short side of the minimum rotated rectangle) from which a convex
#: outline is a corridor.
CORRIDOR_ASPECT = 3.0
#: Slack allowed when a measured parameter is compared with a range (rounding of coordinates).
_SLACK = 1e-6
WALL = 0.15  # partition wall thickness of ``rooms`` floors (scene units)


def _range(name: str, v: Any, lo: float, hi: float) -> tuple[float, float]:
    if not (isinstance(v, (tuple, list)) and len(v) == 2):
        raise ValueError(f"SceneFamily.{name} must be a (low, high) pair, got {v!r}")
    a, b = float(v[0]), float(v[1])
    if not (lo <= a <= b <= hi):
        raise ValueError(f"SceneFamily.{name} must satisfy {lo} <= low <= high <= {hi}, got {v!r}")
    return a, b


@dataclass(frozen=True)
class SceneFamily:
    """A distribution of procedural scenes, given by parameter ranges (its *support*).

    Attributes
    ----------
    name : the family's name (also the scenes' name prefix).
    fov_deg : ``(low, high)`` field of view in degrees, within ``(0, 360]``; drawn uniformly.
    max_range : ``(low, high)`` maximum sensing range as a fraction of the scene's diameter,
        or ``None`` (always unlimited).
    range_limited : probability that a scene's sensor has a maximum range (needs
        ``max_range``); 1 means every scene's sensor is range-limited.
    shapes : room shape classes of :data:`ROOM_SHAPES`, drawn uniformly.
    clutter : ``(low, high)`` obstacle area as a fraction of the room's area.
    region_kinds : kinds of G and H (``"point"``, ``"polygon"``), drawn uniformly.
    mixed_regions : draw G's and H's kinds independently; ``False`` (default): one kind for
        both (the default keeps the families' draws as they were; the partial model answers
        mixed kinds since issue 25, :mod:`geometry.mixed`).
    target_convex : allowed target convexities (``True``: convex, ``False``: not).
    target_vertices : ``(low, high)`` inclusive vertex count of the target.
    diameter : ``(low, high)`` scene diameter (bounding-box diagonal, scene units).
    max_tries : draws before :meth:`sample` gives up with ``RuntimeError``.
    """

    name: str
    fov_deg: tuple[float, float] = (360.0, 360.0)
    max_range: tuple[float, float] | None = None
    range_limited: float = 0.0
    shapes: tuple[str, ...] = ("rectangle",)
    clutter: tuple[float, float] = (0.0, 0.1)
    region_kinds: tuple[str, ...] = ("point",)
    mixed_regions: bool = False
    target_convex: tuple[bool, ...] = (True, False)
    target_vertices: tuple[int, int] = (3, 7)
    diameter: tuple[float, float] = (9.0, 16.0)
    max_tries: int = 100

    def __post_init__(self) -> None:
        def bad(name: str, need: str) -> ValueError:
            return ValueError(f"SceneFamily.{name} must be {need}, got {getattr(self, name)!r}")

        _range("fov_deg", self.fov_deg, 0.0, 360.0)
        if self.fov_deg[0] <= 0:
            raise bad("fov_deg", "> 0")
        if self.max_range is not None:
            _range("max_range", self.max_range, 1e-9, 10.0)
        if not 0.0 <= float(self.range_limited) <= 1.0:
            raise bad("range_limited", "in [0, 1]")
        if self.range_limited > 0 and self.max_range is None:
            raise bad("max_range", "a (low, high) pair when range_limited > 0")
        if not self.shapes or any(s not in ROOM_SHAPES for s in self.shapes):
            raise bad("shapes", f"a non-empty subset of {ROOM_SHAPES}")
        _range("clutter", self.clutter, 0.0, 0.6)
        if not self.region_kinds or any(k not in REGION_KINDS for k in self.region_kinds):
            raise bad("region_kinds", f"a non-empty subset of {REGION_KINDS}")
        if not self.target_convex or any(not isinstance(c, bool) for c in self.target_convex):
            raise bad("target_convex", "a non-empty tuple of bools")
        lo, hi = _range("target_vertices", self.target_vertices, 3, 64)
        if False in self.target_convex and hi < 4:
            raise bad("target_vertices", "able to reach 4 for a non-convex target")
        _range("diameter", self.diameter, 4.0, 1e6)
        if not isinstance(self.mixed_regions, bool):
            raise bad("mixed_regions", "True or False")
        if not isinstance(self.max_tries, int) or self.max_tries < 1:
            raise bad("max_tries", "a positive integer")

    # ---- sampling ---------------------------------------------------------------------
    def sample_dict(self, rng: np.random.Generator) -> dict[str, Any]:
        """A scene dict in the pinned JSON format (validated by :class:`geometry.Scene`),
        a deterministic function of ``rng``'s state.  Raises ``RuntimeError`` after
        ``max_tries`` failed draws."""
        last = "no draw"
        for _ in range(self.max_tries):
            d, why = _try_family(self, rng)
            if d is None:
                last = why
                continue
            try:
                Scene.from_dict(d)
            except SceneError as e:  # pragma: no cover - the construction avoids it
                last = f"invalid scene: {e}"
                continue
            return d
        raise RuntimeError(
            f"SceneFamily {self.name!r}: no valid scene in {self.max_tries} draws "
            f"(last failure: {last}); widen the ranges (diameter, clutter) or raise max_tries"
        )

    def sample(self, rng: np.random.Generator) -> Scene:
        """A valid :class:`geometry.Scene` of this family (see :meth:`sample_dict`)."""
        return Scene.from_dict(self.sample_dict(rng))

    # ---- support ----------------------------------------------------------------------
    def violations(self, params: dict[str, Any]) -> list[str]:
        """Which of ``params`` (from :func:`scene_parameters`) lie outside this family's
        support, one message each (empty: inside)."""
        out = []

        def rng_ok(key: str, lo: float, hi: float) -> None:
            v = params[key]
            if not (lo - _SLACK * max(1.0, abs(lo)) <= v <= hi + _SLACK * max(1.0, abs(hi))):
                out.append(f"{key}={v:.6g} not in [{lo:g}, {hi:g}]")

        rng_ok("fov_deg", *self.fov_deg)
        if params["max_range_rel"] is None:
            if self.range_limited >= 1.0:
                out.append("max_range=None but the family's sensors are always range-limited")
        elif self.max_range is None or self.range_limited == 0:
            out.append(
                f"max_range_rel={params['max_range_rel']:.6g}: the family has no range limit"
            )
        else:
            rng_ok("max_range_rel", *self.max_range)
        if params["room_shape"] not in self.shapes:
            out.append(f"room_shape={params['room_shape']!r} not in {self.shapes}")
        rng_ok("clutter", *self.clutter)
        for key in ("goal_kind", "failure_kind"):
            if params[key] not in self.region_kinds:
                out.append(f"{key}={params[key]!r} not in {self.region_kinds}")
        if not self.mixed_regions and params["goal_kind"] != params["failure_kind"]:
            out.append("G and H of different kinds (the family has mixed_regions=False)")
        if params["target_convex"] not in self.target_convex:
            out.append(f"target_convex={params['target_convex']} not in {self.target_convex}")
        rng_ok("target_vertices", *self.target_vertices)
        rng_ok("diameter", *self.diameter)
        return out

    def contains(self, params: dict[str, Any]) -> bool:
        """Whether scene parameters (from :func:`scene_parameters`) lie in the support."""
        return not self.violations(params)


@dataclass(frozen=True)
class Difficulty:
    """A benchmark level: a family and the robot's ``min_start_distance`` (fraction of the
    scene's diameter between the start and the recognizable region)."""

    family: SceneFamily
    min_start_distance: float


EASY = SceneFamily(
    "easy",
    shapes=("rectangle",),
    clutter=(0.0, 0.06),
    diameter=(9.0, 14.0),
)
MEDIUM = SceneFamily(
    "medium",
    fov_deg=(90.0, 360.0),
    shapes=("rectangle", "corridor", "L"),
    clutter=(0.0, 0.12),
    diameter=(9.0, 20.0),
)
HARD = SceneFamily(
    "hard",
    fov_deg=(45.0, 360.0),
    max_range=(0.3, 1.0),
    range_limited=0.3,
    shapes=ROOM_SHAPES,
    clutter=(0.0, 0.3),
    region_kinds=REGION_KINDS,
    target_vertices=(3, 8),
    diameter=(9.0, 40.0),
)
#: Named families (``family=`` of the envs).
FAMILIES: dict[str, SceneFamily] = {f.name: f for f in (EASY, MEDIUM, HARD)}
#: Benchmark levels (``difficulty=`` of the envs).
DIFFICULTIES: dict[str, Difficulty] = {
    "easy": Difficulty(EASY, 0.0),
    "medium": Difficulty(MEDIUM, 0.2),
    "hard": Difficulty(HARD, 0.35),
}


def get_family(family: str | SceneFamily) -> SceneFamily:
    """The family named ``family`` (:data:`FAMILIES`), or ``family`` itself."""
    if isinstance(family, SceneFamily):
        return family
    if isinstance(family, str) and family in FAMILIES:
        return FAMILIES[family]
    raise ValueError(f"unknown scene family {family!r}: use {sorted(FAMILIES)} or a SceneFamily")


def get_difficulty(name: str) -> Difficulty:
    """The benchmark level ``name`` (:data:`DIFFICULTIES`)."""
    if isinstance(name, str) and name in DIFFICULTIES:
        return DIFFICULTIES[name]
    raise ValueError(f"unknown difficulty {name!r}: use one of {sorted(DIFFICULTIES)}")


# ---------------------------------------------------------------------------------------------
# measuring a scene
# ---------------------------------------------------------------------------------------------


def _reflex_corners(ring: np.ndarray) -> int:
    """Reflex corners of a counter-clockwise ring ``(n, 2)`` (collinear ones not counted)."""
    a, b, c = np.roll(ring, 1, axis=0), ring, np.roll(ring, -1, axis=0)
    cross = (b[:, 0] - a[:, 0]) * (c[:, 1] - b[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - b[:, 0])
    scale = float(np.ptp(ring, axis=0).max()) ** 2
    return int(np.count_nonzero(cross < -1e-12 * scale))


def scene_parameters(scene: Scene) -> dict[str, Any]:
    """The family parameters of ``scene``, measured.

    Returns a dict with ``fov_deg`` (degrees), ``max_range`` (scene units or ``None``),
    ``max_range_rel`` (``max_range / diameter`` or ``None``), ``room_shape`` (a class of
    :data:`ROOM_SHAPES`) and the measures defining it (``wall_vertices``, ``reflex_corners``,
    ``aspect``: long / short side of the outline's minimum rotated rectangle), ``clutter``
    (area of the obstacles inside the walls / area inside the walls), ``n_obstacles``,
    ``goal_kind`` and ``failure_kind`` (``"point"`` / ``"polygon"``), ``target_convex``,
    ``target_vertices``, ``target_radius`` (scene units), ``room_area`` (scene units squared)
    and ``diameter`` (bounding-box diagonal, scene units).
    """
    room = scene.bounds_geom
    diameter = scene.diameter
    reflex = _reflex_corners(np.asarray(scene.bounds))
    rect = np.asarray(shapely.minimum_rotated_rectangle(room).exterior.coords)[:4]
    sides = np.hypot(*(np.roll(rect, -1, axis=0) - rect).T)
    aspect = float(sides.max() / max(sides.min(), 1e-300))
    if reflex == 0:
        shape = "corridor" if aspect >= CORRIDOR_ASPECT else "rectangle"
    else:
        shape = {1: "L", 2: "U"}.get(reflex, "rooms")
    obs = scene.obstacle_union
    clutter = float(obs.intersection(room).area / room.area) if not obs.is_empty else 0.0
    t = Polygon(scene.target)
    mr = scene.sensor.max_range
    return {
        "fov_deg": float(scene.sensor.fov_deg),
        "max_range": None if mr is None else float(mr),
        "max_range_rel": None if mr is None else float(mr) / diameter,
        "room_shape": shape,
        "wall_vertices": len(scene.bounds),
        "reflex_corners": reflex,
        "aspect": aspect,
        "clutter": clutter,
        "n_obstacles": len(scene.obstacles),
        "goal_kind": "point" if len(scene.goal) == 1 else "polygon",
        "failure_kind": "point" if len(scene.failure) == 1 else "polygon",
        "target_convex": bool(t.convex_hull.area - t.area <= 1e-9 * t.convex_hull.area),
        "target_vertices": len(scene.target),
        "target_radius": float(scene.target_radius),
        "room_area": float(room.area),
        "diameter": diameter,
    }


# ---------------------------------------------------------------------------------------------
# drawing a scene
# ---------------------------------------------------------------------------------------------


def _clean(room: Any) -> Polygon | None:
    """A simple CCW polygon with rounded coordinates and no repeated/collinear vertices."""
    if not isinstance(room, Polygon) or room.interiors or not room.is_valid:
        return None
    room = shapely.orient_polygons(room, exterior_cw=False)
    pts = np.asarray(_round(np.asarray(room.exterior.coords)[:-1]))
    keep, n = [], len(pts)
    for i in range(n):
        a, b, c = pts[i - 1], pts[i], pts[(i + 1) % n]
        cross = (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0])
        if np.allclose(a, b) or abs(cross) < 1e-12:
            continue
        keep.append(b)
    p = Polygon(keep)
    return p if p.is_valid else None


def _room(shape: str, rng: np.random.Generator, diameter: float) -> Polygon | None:
    """A room outline of class ``shape`` whose bounding-box diagonal is ``diameter``."""
    if shape == "corridor":
        aspect = rng.uniform(CORRIDOR_ASPECT + 0.2, 5.0)
    elif shape == "rooms":
        aspect = rng.uniform(1.6, 2.4)
    else:
        aspect = rng.uniform(1.0, 1.8)
    w = diameter / math.sqrt(1 + 1 / aspect**2)
    h = w / aspect
    if rng.random() < 0.5:
        w, h = h, w
    box = shapely.box(0.0, 0.0, w, h)
    if shape in ("rectangle", "corridor"):
        return _clean(box)
    if shape == "L":
        fx, fy = rng.uniform(0.35, 0.6, 2)
        k = int(rng.integers(4))
        x0 = 0.0 if k in (0, 3) else w * (1 - fx)
        y0 = 0.0 if k in (0, 1) else h * (1 - fy)
        return _clean(box.difference(shapely.box(x0, y0, x0 + w * fx, y0 + h * fy)))
    if shape == "U":
        a, b = sorted(rng.uniform(0.3, 0.7, 2))
        if b - a < 0.2:
            a, b = 0.5 - 0.12, 0.5 + 0.12
        depth = h * rng.uniform(0.35, 0.6)
        top = bool(rng.random() < 0.5)
        y0 = h - depth if top else 0.0
        return _clean(box.difference(shapely.box(w * a, y0, w * b, y0 + depth)))
    # rooms: partition walls across the long side, each with a doorway (slits in the outline)
    long_x = w >= h
    L, S = (w, h) if long_x else (h, w)
    n_rooms = int(rng.integers(2, 4))
    cuts = []
    for k in range(1, n_rooms):
        x = L * k / n_rooms + rng.uniform(-0.08, 0.08) * L / n_rooms
        door = rng.uniform(1.0, 1.6)
        d0 = rng.uniform(0.15 * S, S - door - 0.15 * S) if S - door > 0.3 * S else (S - door) / 2
        for y0, y1 in ((0.0, d0), (d0 + door, S)):
            if y1 - y0 > 1e-6:
                cuts.append((x - WALL / 2, y0, x + WALL / 2, y1))
    if not long_x:
        cuts = [(y0, x0, y1, x1) for x0, y0, x1, y1 in cuts]
    room = box
    for c in cuts:
        room = room.difference(shapely.box(*c))
    return _clean(room)


def _try_family(fam: SceneFamily, rng: np.random.Generator) -> tuple[dict | None, str]:
    """One draw: ``(scene dict, "")`` or ``(None, why it failed)``."""
    margin = 0.05
    shape = fam.shapes[int(rng.integers(len(fam.shapes)))]
    diameter = float(rng.uniform(*fam.diameter))
    room = _room(shape, rng, diameter)
    if room is None:
        return None, f"room {shape!r} degenerate"
    # target
    convex = fam.target_convex[int(rng.integers(len(fam.target_convex)))]
    lo_v, hi_v = fam.target_vertices
    m = int(rng.integers(max(lo_v, 3 if convex else 4), hi_v + 1))
    r_t = float(rng.uniform(0.3, 0.8))
    target = np.asarray(_round(random_polygon(rng, m, r_t, convex=convex)))
    tpoly = Polygon(target)
    if not tpoly.is_valid or not tpoly.contains(Point(0, 0)):
        return None, "invalid target"
    is_convex = tpoly.convex_hull.area - tpoly.area <= 1e-9 * tpoly.convex_hull.area
    if is_convex != convex:
        return None, "target convexity"
    r = float(np.hypot(target[:, 0], target[:, 1]).max())
    # G and H inside the room, their hulls (any orientation) clear of the walls
    inner = room.buffer(-(r + margin + 0.3))
    if inner.is_empty:
        return None, "room too small for the target"

    def sample_in(poly: Any) -> np.ndarray | None:
        x0, y0, x1, y1 = poly.bounds
        for _ in range(200):
            p = rng.uniform((x0, y0), (x1, y1))
            if poly.contains(Point(p)):
                return p
        return None

    regions = []
    kind = fam.region_kinds[int(rng.integers(len(fam.region_kinds)))]
    for _ in range(2):
        c = sample_in(inner)
        if c is None:
            return None, "no room for G/H"
        if fam.mixed_regions and regions:
            kind = fam.region_kinds[int(rng.integers(len(fam.region_kinds)))]
        X = _region(rng, c, kind, float(rng.uniform(0.3, 0.8)))
        X = Polygon(_round(_coords(X))) if isinstance(X, Polygon) else Point(_round(_coords(X))[0])
        regions.append(X)
    G, H = regions
    if not G.is_valid or not H.is_valid or G.distance(H) < 1e-3:
        return None, "G and H overlap"
    hulls = shapely.union(
        shapely.convex_hull(G).buffer(r * 1.01, quad_segs=32),
        shapely.convex_hull(H).buffer(r * 1.01, quad_segs=32),
    )
    keep_out = hulls.buffer(margin)
    walls_in = room.buffer(-margin)
    if not walls_in.contains(keep_out):
        return None, "G/H hull meets a wall"
    # clutter: obstacles until their area fraction reaches a drawn value in the range
    c_lo, c_hi = fam.clutter
    goal_area = float(rng.uniform(c_lo, c_hi)) * room.area
    x0, y0, x1, y1 = room.bounds
    obstacles: list[np.ndarray] = []
    placed = shapely.Polygon()
    total, fails = 0.0, 0
    while total < goal_area and fails < 80:
        k = int(rng.integers(3, 9))
        pts = random_polygon(rng, k, float(rng.uniform(0.3, 1.1)), convex=bool(rng.random() < 0.5))
        pts = np.asarray(_round(pts + rng.uniform((x0, y0), (x1, y1))))
        op = Polygon(pts)
        ok = (
            op.is_valid
            and op.area > 1e-3
            and total + op.area <= c_hi * room.area
            and walls_in.contains(op)
            and not op.intersects(keep_out)
            and (placed.is_empty or op.distance(placed) >= margin)
        )
        if not ok:
            fails += 1
            continue
        obstacles.append(pts)
        placed = shapely.union(placed, op)
        total += op.area
    if total < c_lo * room.area - 1e-9:
        return None, "clutter below the range"
    # sensor
    sensor: dict[str, Any] = {"fov_deg": round(float(rng.uniform(*fam.fov_deg)), 3)}
    if fam.range_limited > 0 and rng.random() < fam.range_limited:
        d_real = float(np.hypot(*np.ptp(np.asarray(room.exterior.coords), axis=0)))
        sensor["max_range"] = round(float(rng.uniform(*fam.max_range)) * d_real, 4)
        lo_r, hi_r = fam.max_range
        sensor["max_range"] = min(max(sensor["max_range"], lo_r * d_real), hi_r * d_real)
    d = {
        "name": f"{fam.name}-{shape}",
        "bounds": _round(np.asarray(room.exterior.coords)[:-1]),
        "obstacles": [_round(o) for o in obstacles],
        "target": _round(target),
        "goal": _round(_coords(G)),
        "failure": _round(_coords(H)),
        "sensor": sensor,
    }
    return d, ""
