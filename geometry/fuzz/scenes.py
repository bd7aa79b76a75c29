"""The fuzzer's scenes: valid-looking scene dictionaries full of the contacts that exact
geometry gets wrong (:func:`fuzz_scene`; the families are listed in :mod:`geometry.fuzz`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import shapely

from ..scene import Scene, SceneError


def _star(rng: np.random.Generator, n: int, r0: float, r1: float) -> np.ndarray:
    ang = np.sort(rng.uniform(0, 2 * math.pi, n))
    ang += np.linspace(0, 2 * math.pi, n, endpoint=False) - ang  # keep them spread
    ang += rng.uniform(-0.3, 0.3, n) * (2 * math.pi / n)
    rad = rng.uniform(r0, r1, n)
    return np.column_stack([rad * np.cos(ang), rad * np.sin(ang)])


def _convex(rng: np.random.Generator, c: np.ndarray, size: float) -> np.ndarray:
    pts = c + rng.uniform(-size, size, (int(rng.integers(3, 8)), 2))
    hull = shapely.convex_hull(shapely.multipoints(pts))
    if hull.geom_type != "Polygon":
        return c + size * np.array([[0, 0], [1, 0], [0, 1.0]])
    return np.asarray(hull.exterior.coords)[:-1]


def _bounds(rng: np.random.Generator) -> np.ndarray:
    kind = rng.integers(4)
    if kind == 0:  # rectangle
        w, h = rng.uniform(6, 14, 2)
        return np.array([[0, 0], [w, 0], [w, h], [0, h]])
    if kind == 1:  # star-shaped, non-convex
        return _star(rng, int(rng.integers(5, 13)), 3.5, 7.0) + 7.0
    if kind == 2:  # L-shape
        w, h = rng.uniform(8, 14, 2)
        a, b = rng.uniform(0.3, 0.7, 2)
        return np.array([[0, 0], [w, 0], [w, b * h], [a * w, b * h], [a * w, h], [0, h]])
    # U-shape
    w, h = rng.uniform(9, 14, 2)
    a, b, c = w * 0.35, w * 0.65, h * rng.uniform(0.3, 0.6)
    return np.array([[0, 0], [w, 0], [w, h], [b, h], [b, c], [a, c], [a, h], [0, h]])


def _on_segment(rng: np.random.Generator, a: np.ndarray, b: np.ndarray) -> tuple:
    t0, t1 = np.sort(rng.uniform(0.1, 0.9, 2))
    if t1 - t0 < 0.05:
        t1 = min(t0 + 0.1, 0.95)
    return a + t0 * (b - a), a + t1 * (b - a)


def _inward(ring: np.ndarray, i: int) -> np.ndarray:
    """Unit normal of edge i of a CCW ring pointing into the polygon."""
    e = ring[(i + 1) % len(ring)] - ring[i]
    n = np.array([-e[1], e[0]])
    return n / np.hypot(*n)


def _outward(ring: np.ndarray, i: int) -> np.ndarray:
    return -_inward(ring, i)


def _ccw(p: np.ndarray) -> np.ndarray:
    x, y = p[:, 0], p[:, 1]
    area = np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y)
    return p if area > 0 else p[::-1]


@dataclass
class _Draft:
    bounds: np.ndarray
    obstacles: list[np.ndarray] = field(default_factory=list)
    features: list[str] = field(default_factory=list)

    def edges(self) -> int:
        return len(self.bounds) + sum(len(o) for o in self.obstacles)


def _add_obstacle(rng: np.random.Generator, dr: _Draft, size: float) -> None:
    b = _ccw(dr.bounds)
    kind = rng.choice(
        [
            "convex",
            "rect",
            "flush_wall",
            "shared_edge",
            "shared_vertex",
            "t_junction",
            "collinear",
            "sliver",
            "vertex_on_wall",
        ]  # fmt: skip
    )
    if kind in ("shared_edge", "shared_vertex", "t_junction", "collinear") and not dr.obstacles:
        kind = "convex"
    if kind == "convex":
        c = _sample_point(rng, dr.bounds)
        dr.obstacles.append(_convex(rng, c, size * rng.uniform(0.3, 1.0)))
    elif kind == "rect":
        c = _sample_point(rng, dr.bounds)
        w, h = size * rng.uniform(0.2, 1.0, 2)
        dr.obstacles.append(c + np.array([[0, 0], [w, 0], [w, h], [0, h]]))
    elif kind in ("flush_wall", "vertex_on_wall"):
        i = int(rng.integers(len(b)))
        p0, p1 = _on_segment(rng, b[i], b[(i + 1) % len(b)])
        n = _inward(b, i) * size * rng.uniform(0.2, 0.8)
        if kind == "flush_wall":
            dr.obstacles.append(np.array([p0, p1, p1 + n, p0 + n]))
        else:
            m = 0.5 * (p0 + p1)
            dr.obstacles.append(np.array([m, m + n + (p1 - p0) * 0.5, m + n - (p1 - p0) * 0.5]))
    elif kind != "sliver":
        o = _ccw(dr.obstacles[int(rng.integers(len(dr.obstacles)))])
        i = int(rng.integers(len(o)))
        a, c = o[i], o[(i + 1) % len(o)]
        n = _outward(o, i) * size * rng.uniform(0.2, 0.8)
        if kind == "shared_edge":
            dr.obstacles.append(np.array([c, a, a + n, c + n]))
        elif kind == "shared_vertex":
            d = (c - a) / max(np.hypot(*(c - a)), 1e-300) * size * 0.5
            dr.obstacles.append(np.array([c, c + n + d, c + d * 1.5]))
        elif kind == "t_junction":
            m = a + rng.uniform(0.2, 0.8) * (c - a)
            d = (c - a) * 0.2
            dr.obstacles.append(np.array([m, m + n + d, m + n - d]))
        else:  # collinear: same line as edge (a, c), beyond c
            d = c - a
            p0 = c + d * rng.uniform(0.3, 1.0)
            p1 = p0 + d * rng.uniform(0.2, 0.6)
            dr.obstacles.append(np.array([p0, p1, p1 + n, p0 + n]))
    if kind == "sliver":
        c = _sample_point(rng, dr.bounds)
        phi = rng.uniform(0, math.pi)
        ln = size * rng.uniform(0.5, 1.5)
        th = ln * 10.0 ** rng.uniform(-7, -3)
        u = np.array([math.cos(phi), math.sin(phi)])
        v = np.array([-u[1], u[0]])
        dr.obstacles.append(np.array([c, c + ln * u, c + ln * u + th * v, c + th * v]))
    dr.features.append(str(kind))


def _sample_point(rng: np.random.Generator, ring: np.ndarray) -> np.ndarray:
    poly = shapely.Polygon(ring)
    x0, y0, x1, y1 = poly.bounds
    for _ in range(200):
        p = rng.uniform([x0, y0], [x1, y1])
        if shapely.contains_xy(poly, *p):
            return p
    return np.asarray(poly.representative_point().coords[0])


def _target(rng: np.random.Generator, r: float) -> np.ndarray:
    kind = rng.integers(3)
    if kind == 0:  # regular polygon (symmetric)
        n = int(rng.integers(3, 9))
        a = np.linspace(0, 2 * math.pi, n, endpoint=False) + rng.uniform(0, 1) * (kind == 0)
        return r * np.column_stack([np.cos(a), np.sin(a)])
    if kind == 1:  # convex
        t = _convex(rng, np.zeros(2), r)
        return t - np.asarray(shapely.Polygon(t).centroid.coords[0])
    return _star(rng, int(rng.integers(5, 12)), 0.4 * r, r)  # star-shaped, non-convex


def _nonstar(rng: np.random.Generator, r: float) -> np.ndarray:
    """A target with an empty kernel (radius about ``r``, counter-clockwise, centred):
    a U, a comb with 2-4 teeth or a hook, at a random orientation."""
    kind = int(rng.integers(3))
    depth = rng.uniform(0.5, 0.9)
    if kind == 0:  # U
        w = rng.uniform(0.2, 0.6)
        t = [[-1, -1], [1, -1], [1, 1], [w, 1], [w, 1 - 2 * depth], [-w, 1 - 2 * depth],
             [-w, 1], [-1, 1]]  # fmt: skip
    elif kind == 1:  # comb: teeth up from a base
        n = int(rng.integers(2, 5))
        xs = np.linspace(-1.0, 1.0, 2 * n)
        t = [[-1.0, -1.0], [1.0, -1.0]]  # then right to left: tooth k spans xs[2k..2k+1]
        for k in range(n - 1, -1, -1):
            x0, x1 = xs[2 * k], xs[2 * k + 1]
            t += [[x1, 1.0], [x0, 1.0]]
            if k > 0:
                t += [[x0, 1 - 2 * depth], [xs[2 * k - 1], 1 - 2 * depth]]
    else:  # hook: a slot cut in from the right
        h = rng.uniform(0.1, 0.4)
        y = rng.uniform(-0.4, 0.4)
        t = [[-1, -1], [1, -1], [1, y - h], [1 - 2 * depth, y - h], [1 - 2 * depth, y + h],
             [1, y + h], [1, 1], [-1, 1]]  # fmt: skip
    a = rng.uniform(0, 2 * math.pi)
    rot = np.array([[math.cos(a), math.sin(a)], [-math.sin(a), math.cos(a)]])
    out = np.asarray(t, dtype=float) @ rot * (r / math.sqrt(2.0))
    return out - np.asarray(shapely.Polygon(out).centroid.coords[0])


def _place(rng: np.random.Generator, free: shapely.Geometry, clear: float) -> np.ndarray | None:
    inner = free.buffer(-clear)
    if inner.is_empty:
        return None
    x0, y0, x1, y1 = inner.bounds
    for _ in range(100):
        p = rng.uniform([x0, y0], [x1, y1])
        if shapely.contains_xy(inner, *p):
            return p
    return None


def _region(
    rng: np.random.Generator, c: np.ndarray, size: float, point: bool = False
) -> list[list[float]]:
    kind = rng.integers(3)
    if kind == 0 or point:
        return [c.tolist()]
    if kind == 1:
        s = size
        return (c + np.array([[-s, -s], [s, -s], [s, s], [-s, s]])).tolist()
    return (c + _star(rng, int(rng.integers(4, 7)), 0.5 * size, size)).tolist()


def _snap(v: Any, grid: float) -> Any:
    if isinstance(v, list):
        return [_snap(x, grid) for x in v]
    return float(np.round(v / grid) * grid)


def fuzz_scene(
    seed: int, *, max_edges: int = 60, contacts: bool = False, nonstar: bool = False
) -> dict[str, Any] | None:
    """A random degenerate scene dictionary (or ``None`` when the draw failed to give a
    valid scene after a few tries).  ``"features"`` (not a scene key; removed before
    use) lists the degeneracies drawn.  ``contacts=True`` adds the families issue 26
    found the generator blind to: near-duplicate target vertices (1e-9 of the target
    apart), flush obstacles covering both ends of a target edge, a target flush under an
    opening between two obstacles, and a second obstacle sharing the flush one's edge.
    ``nonstar=True`` (issue 25) makes 60 % of the targets non-star-shaped (a U, a comb
    or a hook; feature ``"nonstar"``).  Either flag leaves the draws of the other
    scenes as they were: ``fuzz_scene(s) == fuzz_scene(s, nonstar=False)``."""
    rng = np.random.default_rng(seed)
    for _ in range(8):
        d = _draft_scene(rng, max_edges, contacts, nonstar)
        if d is None:
            continue
        try:
            Scene.from_dict({k: v for k, v in d.items() if k != "features"})
        except SceneError:
            continue
        return d
    return None


def _draft_scene(
    rng: np.random.Generator, max_edges: int, contacts: bool = False, nonstar: bool = False
) -> dict[str, Any] | None:
    dr = _Draft(_bounds(rng))
    diam = float(np.hypot(*np.ptp(dr.bounds, axis=0)))
    for _ in range(int(rng.integers(0, 8))):
        if dr.edges() > max_edges - 12:
            break
        _add_obstacle(rng, dr, diam * rng.uniform(0.05, 0.2))
    bpoly = shapely.Polygon(dr.bounds)
    obs = [shapely.Polygon(o) for o in dr.obstacles]
    obs = [o for o in obs if o.is_valid and o.area > 0 and bpoly.buffer(1e-9 * diam).covers(o)]
    dr.obstacles = [np.asarray(o.exterior.coords)[:-1] for o in obs]
    free = bpoly.difference(shapely.union_all(obs)) if obs else bpoly
    r = diam * rng.uniform(0.01, 0.05)
    target = _target(rng, r)
    if nonstar and rng.random() < 0.6:
        target = _nonstar(rng, r)
        dr.features.append("nonstar")
    if rng.random() < 0.2:  # reference point on the outline or outside the target
        if rng.random() < 0.5:
            target = target - target[int(rng.integers(len(target)))]
        else:
            target = target + rng.uniform(-1.5 * r, 1.5 * r, 2)
        dr.features.append("reference_off")
    if contacts and rng.random() < 0.3:
        # near-duplicate target vertex: a copy of vertex i, 1e-9 D along its next edge
        t = _ccw(target)
        i = int(rng.integers(len(t)))
        e = t[(i + 1) % len(t)] - t[i]
        dup = t[i] + e * (1e-9 * diam / max(float(np.hypot(*e)), 1e-300))
        target = np.insert(t, i + 1, dup, axis=0)
        dr.features.append("near_dup_target")
    size = r * rng.uniform(0.5, 3.0)
    pg = _place(rng, free, 1.2 * r + 1.5 * size)
    if pg is None:
        return None
    goal = _region(rng, pg, size, point=contacts and rng.random() < 0.4)
    gpoly = shapely.Polygon(goal) if len(goal) > 1 else shapely.Point(goal[0])
    pf = _place(rng, free.difference(gpoly.buffer(2 * r + 2 * size)), 1.2 * r + 1.5 * size)
    if pf is None:
        return None
    failure = _region(rng, pf, size)
    if rng.random() < (0.15 if contacts else 0.3) and len(goal) == 1:
        # touch_hull: a triangle touching the target at G at a vertex or flush on an edge
        a = _ccw(target + np.asarray(goal[0]))
        i = int(rng.integers(len(a)))
        p, q = a[i], a[(i + 1) % len(a)]
        n = _outward(a, i) * r
        if rng.random() < 0.5:
            tri = np.array([q, p, p + n])  # flush on the edge
        else:
            tri = np.array([p, p + n + (q - p) * 0.5, p + n - (q - p) * 0.5])
        dr.obstacles.append(tri)
        dr.features.append("touch_hull")
    elif contacts and len(goal) == 1 and rng.random() < 0.85:
        _contact_family(rng, dr, _ccw(target + np.asarray(goal[0])), r)
    d: dict[str, Any] = {
        "name": "fuzz",
        "bounds": dr.bounds.tolist(),
        "obstacles": [o.tolist() for o in dr.obstacles],
        "target": target.tolist(),
        "goal": goal,
        "failure": failure,
    }
    if rng.random() < 0.3:
        for k in ("bounds", "obstacles", "target", "goal", "failure"):
            d[k] = _snap(d[k], 1e-6)  # coordinates written to 6 decimals
        dr.features.append("rounded")
    scale = 10.0 ** float(rng.choice([0.0, 0.0, rng.uniform(-6, 6)]))
    if scale != 1.0:
        dr.features.append("scaled")
    grid = math.ldexp(1.0, math.ceil(math.log2(diam * scale)) - 32)
    for k in ("bounds", "goal", "failure", "obstacles"):
        d[k] = _snap(_scaled(d[k], scale), grid)
    d["target"] = _snap(_scaled(d["target"], scale), grid)
    d["name"] = "fuzz"
    d["features"] = dr.features
    return d


def _contact_family(rng: np.random.Generator, dr: _Draft, a: np.ndarray, r: float) -> None:
    """Obstacles flush on an edge ``p -> q`` of the placed target ``a`` (CCW)."""
    i = int(rng.integers(len(a)))
    p, q = a[i], a[(i + 1) % len(a)]
    e = q - p
    n = _outward(a, i) * r * rng.uniform(0.3, 1.0)
    kind = rng.choice(["flush_both_ends", "under_opening", "shared_flush"])
    if kind == "flush_both_ends":
        # two boxes flush on the edge, over its ends, the middle exposed
        s0, s1 = rng.uniform(0.15, 0.4), rng.uniform(0.6, 0.85)
        over = e * rng.uniform(0.05, 0.3)
        dr.obstacles.append(np.array([p + e * s0, p - over, p - over + n, p + e * s0 + n]))
        dr.obstacles.append(np.array([q + over, p + e * s1, p + e * s1 + n, q + over + n]))
    elif kind == "under_opening":
        # two boxes beyond the ends of the edge, flush with its line: an opening above it
        w = e * rng.uniform(0.3, 1.0)
        g = e * rng.uniform(0.0, 0.2)
        dr.obstacles.append(np.array([p - g, p - g - w, p - g - w + n, p - g + n]))
        dr.obstacles.append(np.array([q + g + w, q + g, q + g + n, q + g + w + n]))
    else:
        # a box flush on the whole edge and a second one sharing its outer edge
        dr.obstacles.append(np.array([q, p, p + n, q + n]))
        dr.obstacles.append(np.array([q + n, p + n, p + 2 * n, q + 2 * n]))
    dr.features.append(str(kind))


def _scaled(v: Any, k: float) -> Any:
    if isinstance(v, list):
        return [_scaled(x, k) for x in v]
    return v * k
