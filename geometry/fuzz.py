"""Fuzzing the region functions on degenerate scenes (issue 10).

:func:`fuzz_scene` draws a *valid-looking* scene dictionary full of the contacts that
exact geometry gets wrong: obstacles flush on walls (vertices interpolated on the wall,
so off it by rounding), obstacles sharing edges or vertices, T-junctions (a vertex on
another polygon's edge), collinear edges, slivers (aspect ratio down to 1e-7), obstacles
touching the convex hull of the target at G (at a vertex or flush on an edge), non-convex
rooms, coordinates rounded to 6 decimals, and scales from 1e-6 to 1e6.  Coordinates are
snapped to a dyadic grid of ``2**-32`` of the scene's size so that translating the scene
by a multiple of its size (up to ~1e6 sizes) is *exact*: the translation check then
demands equality up to the output's rounding.

:func:`check_scene` runs every query type on one scene and returns the violations:

* ``crash``: an exception other than :class:`~geometry.SceneError` /
  ``NotImplementedError`` (``SceneError`` is the documented answer for a query that
  violates the paper's assumption, e.g. a rotated target whose hull meets an obstacle);
* ``invalid``: not a valid shapely Polygon/MultiPolygon;
* ``outside``: area outside the free space (or inside the target) above 1e-9 D^2;
* ``inclusion``: complete ⊆ partial, translating ⊆ stationary at every vertex of G, any
  orientation ⊆ fixed orientation, recognizable ⊆ both complete regions, swept partial
  (``conservative=True``) ⊆ stationary partial at the vertices of G and at three sampled
  configurations (two on its boundary, one inside), violated by more than 1e-8 D^2;
* ``unsafe``: a sampled member of a complete region that an independent segment test
  finds blind to part of the target (points within 1e-6 D of the region's boundary are
  skipped); a sampled member of the stationary partial region that sees no sampled point
  of the target's outline, contacts blocking (points within 1e-2 D skipped);
* ``missed``: a sampled non-member of the stationary partial region that sees a sampled
  outline point along a segment 1e-7 D clear of everything (issue 26 items 2, 5);
* ``translation``: the region of the scene translated by an exact offset (a multiple of a
  power of two near the scene's size, 10 to 1e5 sizes away), translated
  back, differs from the original by more than 1e-9 D^2;
* ``hang``: a query that took more than 10 s of CPU time (scenes of at most 60 edges).

* ``frame`` (``frames=True``, issue 26): the scene scaled by 1e-3 and 1e3 and moved to UTM
  coordinates (inexact maps: the inputs differ by rounding), regions mapped back, differ
  by more than 1e-7 D^2; with ``swept`` also the swept partial region and (polygonal G/H)
  the 5.2 recognizable region, up to their tracing tolerance (1e-4 D); and the 5.2 region
  ⊆ R(G), R(H) and ⊆ the stationary recognizable region of a vertex pair.

``contacts=True`` (``--contacts``) adds the scene families issue 26 found missing:
near-duplicate target vertices, flush obstacles over both ends of a target edge, a target
under an opening, a second obstacle sharing a flush one's edge.

``certify=True`` (``--certify``, with ``swept``; issue 25 item 2) also runs
:func:`geometry.swept_bounds` (no aim error) and demands (``inclusion``) proven inner ⊆
outer and inner ⊆ outer, the proven inner ⊆ the stationary partial region at the vertices
of G and the sampled configurations, and for polygonal or mixed G/H the 5.2 bounds' proven
inner ⊆ outer, ⊆ R(G) and ⊆ R(H) (a proven inner bound that is ``None``, for a target
too thin for the cells of G, is skipped).

``nonstar=True`` (``--nonstar``) draws targets with an empty kernel (U, comb, hook), and
with ``swept`` scenes that mix a point and a polygon also run the mixed recognizable
region (``⊆`` the partial regions of both; issue 25).

``python -m geometry.fuzz --n 10000 [--swept] [--contacts] [--frames] [--nonstar] [--jobs N]``
runs the long version and prints a table; ``tests/geometry/test_fuzz.py`` runs a fast one in the
default test run.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import shapely

from .certify import swept_bounds
from .complete import complete_region
from .partial import partial_region
from .recognize import recognizable_region
from .scene import Scene, SceneError

__all__ = ["Finding", "check_scene", "fuzz_scene", "main"]

#: A query slower than this (seconds) is a hang.
HANG_S = 10.0


# ---------------------------------------------------------------------------------------------
# scene generator
# ---------------------------------------------------------------------------------------------


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


# ---------------------------------------------------------------------------------------------
# checks
# ---------------------------------------------------------------------------------------------


@dataclass
class Finding:
    kind: str
    query: str
    detail: str


def _timed(
    fn: Callable[[], Any], name: str, out: list[Finding], times: dict, hang_s: float = HANG_S
) -> Any:
    t0 = time.process_time()  # CPU time: wall clock on a shared machine measures the load
    try:
        r = fn()
    except (SceneError, NotImplementedError):
        r = None
    except Exception as e:  # noqa: BLE001 -- the point of the fuzzer
        out.append(Finding("crash", name, f"{type(e).__name__}: {e}"))
        r = None
    dt = time.process_time() - t0
    times[name] = dt
    if dt > hang_s:
        out.append(Finding("hang", name, f"{dt:.1f} s"))
    return r


def _confirmed(pieces: shapely.Geometry, inside: shapely.Geometry, outside=None) -> float:
    """Area of the parts of an overlay result whose interior point lies in ``inside`` (and
    not in ``outside``), by point-in-polygon tests.  GEOS overlays of a valid polygon with a
    hole that touches its shell at a vertex sometimes return the whole hole (fuzz seeds
    100833, 2424114: point tests show the polygons do not overlap); the checker must not
    report those as violations, nor miss real ones."""
    total = 0.0
    for g in shapely.get_parts(pieces):
        if g.geom_type != "Polygon" or g.is_empty or g.area == 0.0:
            continue
        x, y = g.representative_point().coords[0]
        if not shapely.intersects_xy(inside, x, y):
            continue
        if outside is not None and shapely.contains_xy(outside, x, y):
            continue
        total += g.area
    return total


def _sees_whole(obs: shapely.Geometry, walls: shapely.Geometry, hull: np.ndarray, p) -> bool:
    ts = np.linspace(0, 1, 24, endpoint=False)
    ring = np.vstack([hull, hull[:1]])
    pts = (ring[:-1, None, :] + ts[None, :, None] * (ring[1:] - ring[:-1])[:, None, :]).reshape(
        -1, 2
    )
    lines = shapely.linestrings(np.stack([np.broadcast_to(p, pts.shape), pts], axis=1))
    if not obs.is_empty and shapely.intersects(lines, obs).any():
        return False
    return bool(shapely.covers(walls, lines).all())


def _clear_lines(
    p: np.ndarray,
    pts: np.ndarray,
    obs: shapely.Geometry,
    walls: shapely.Geometry,
    target: shapely.Geometry,
    back: float,
) -> np.ndarray:
    """Per target point ``pts[k]``: the segment from ``p`` to it, ending ``back`` short of
    it, lies in ``walls``, misses ``obs`` and misses ``target`` (self-occlusion)."""
    d = pts - p
    ln = np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-300)
    end = pts - d * (back / ln)[:, None]
    full = shapely.linestrings(np.stack([np.broadcast_to(p, pts.shape), pts], axis=1))
    short = shapely.linestrings(np.stack([np.broadcast_to(p, pts.shape), end], axis=1))
    ok = shapely.covers(walls, full)
    if not obs.is_empty:
        ok &= ~shapely.intersects(full, obs)
    return ok & ~shapely.intersects(short, target)


def _outline_points(poly: shapely.Polygon, per_edge: int = 64) -> np.ndarray:
    """Points along every edge of ``poly``'s outline, its vertices excluded."""
    c = np.asarray(poly.exterior.coords)[:, :2]
    f = (np.arange(per_edge) + 0.5) / per_edge
    return (c[:-1, None, :] + f[None, :, None] * (c[1:] - c[:-1])[:, None, :]).reshape(-1, 2)


def _gap_points(s: Scene, width: float) -> np.ndarray:
    """The midpoints of the scene's narrow gaps: for every pair of obstacles (and every
    obstacle and the walls) closer than ``width`` but farther apart than the tolerance,
    the midpoint of their shortest connecting segment.  A placement may see the target
    through such a gap along a sight line too thin for a sampled outline to find."""
    parts = list(shapely.get_parts(s.obstacle_union)) + [s.bounds_geom.exterior]
    geoms = np.asarray(parts, dtype=object)
    i, j = np.triu_indices(len(parts), 1)
    d = shapely.distance(geoms[i], geoms[j])
    keep = (d > s.tol) & (d < width)
    if not keep.any():
        return np.empty((0, 2))
    lines = shapely.shortest_line(geoms[i[keep]], geoms[j[keep]])
    return np.asarray(shapely.get_coordinates(lines)).reshape(-1, 2, 2).mean(axis=1)


def _through_gaps(p: np.ndarray, gaps: np.ndarray, tgt: shapely.Polygon) -> np.ndarray:
    """Per gap midpoint: the first point of ``tgt``'s outline on the ray from ``p``
    through it (rays that miss the target give nothing)."""
    if not len(gaps):
        return np.empty((0, 2))
    d = gaps - p
    far = (
        p
        + d
        * (4 * tgt.exterior.hausdorff_distance(shapely.Point(p)) + 1)
        / np.maximum(np.hypot(d[:, 0], d[:, 1]), 1e-300)[:, None]
    )
    rays = shapely.linestrings(np.stack([np.broadcast_to(p, gaps.shape), far], axis=1))
    hits = shapely.intersection(rays, tgt.exterior)
    out = []
    for h in hits:
        c = shapely.get_coordinates(h)
        if len(c):
            out.append(c[np.argmin(np.hypot(*(c - p).T))])
    return np.asarray(out).reshape(-1, 2)


def _check_partial_points(
    s: Scene, q_at: tuple, p_at: shapely.Geometry, rng: np.random.Generator, out: list
) -> None:
    """Independent point tests of the stationary partial region (issue 26 items 2, 5, 9):

    * ``unsafe``: a member (1e-2 D inside) from which no sampled point of the target's
      outline (nor a vertex farther than the tolerance from everything) is visible, a
      contact counting as a blocker (a segment that touches an obstacle, or leaves the
      walls, is blocked), nor along the sight line through the midpoint of any gap
      between obstacles narrower than the outline's sampling (``_gap_points``; fuzz seed
      300584 sees its target through a 1.5e-7 gap, nine times the tolerance, from a
      cone 4 units long): such a placement sees the target at most through a gap
      narrower than the scene's tolerance (``fuzz-variance-P_stat`` saw a whole
      half-plane through one);
    * ``missed``: a non-member (1e-6 D outside) that sees a sampled outline point along a
      segment clear of every obstacle and wall by 1e-7 D (``fuzz-disagree-P_stat-*``: the
      exposed middle of an edge whose two ends are flush)."""
    D = s.diameter
    tgt = s.target_at(*q_at)
    pts = _outline_points(tgt)
    raw_obs, raw_walls = s.obstacle_union, s.bounds_geom
    # the target's vertices too, but only those that touch nothing: a vertex seen through a
    # gap wider than the tolerance (6-decimal inputs leave 1e-8 D) is seen
    verts = np.asarray(tgt.exterior.coords)[:-1, :2]
    edge = shapely.union(shapely.boundary(raw_obs), raw_walls.exterior)
    free_v = verts[shapely.distance(shapely.points(verts), edge) > s.tol]
    look = np.vstack([pts, free_v])
    gaps = _gap_points(s, 1e-3 * D)
    for p in _sample(p_at, 8, rng, 1e-2 * D):
        if _clear_lines(p, look, raw_obs, raw_walls, tgt, 1e-9 * D).any():
            continue
        thin = _through_gaps(p, gaps, tgt)
        if not len(thin) or not _clear_lines(p, thin, raw_obs, raw_walls, tgt, 1e-9 * D).any():
            out.append(Finding("unsafe", "partial at", f"member {tuple(p)} sees no outline point"))
            break
    m = 1e-7 * D
    grown = s.obstacle_union.buffer(m) if not s.obstacle_union.is_empty else raw_obs
    inner = s.bounds_geom.buffer(-m, join_style="mitre")
    rest = shapely.difference(shapely.difference(s.free_space, tgt), p_at)
    for p in _sample(rest, 12, rng, 1e-6 * D):
        if _clear_lines(p, pts, grown, inner, tgt, m).any():
            out.append(Finding("missed", "partial at", f"{tuple(p)} sees the target, not in it"))
            break


def _sample(g: shapely.Geometry, n: int, rng: np.random.Generator, margin: float) -> np.ndarray:
    core = g.buffer(-margin)
    if core.is_empty:
        return np.empty((0, 2))
    x0, y0, x1, y1 = core.bounds
    p = rng.uniform([x0, y0], [x1, y1], (40 * n, 2))
    return p[shapely.contains_xy(core, p[:, 0], p[:, 1])][:n]


def _translated(d: dict, o: float) -> dict:
    out = dict(d)
    for k in ("bounds", "goal", "failure"):
        out[k] = [[x + o, y + o] for x, y in d[k]]
    out["obstacles"] = [[[x + o, y + o] for x, y in ob] for ob in d["obstacles"]]
    return out


def _check_bounds(b: Any, name: str, incl: Callable) -> None:
    """The certified bounds of one swept query: both inner bounds inside outer (a proven
    inner bound may be ``None``: a target too thin for the cells of G)."""
    incl(b.inner, b.outer, f"{name}: inner ⊆ outer")
    incl(b.proven_inner, b.outer, f"{name}: proven inner ⊆ outer")  # None: not available


def _certify_recognizable(
    s: Scene, theta: float, sides: list, incl: Callable, out: list[Finding], times: dict
) -> None:
    """The 5.2 (or mixed) bounds: :func:`_check_bounds`, and the proven inner bound inside
    the swept or stationary partial regions ``sides`` (R(G), R(H))."""
    b = _timed(
        lambda: swept_bounds(s, recognizable=True, theta=theta),
        "5.2 bounds",
        out,
        times,
        3 * HANG_S,
    )
    if b is None:
        return
    _check_bounds(b, "5.2 bounds", incl)
    for side in sides:
        incl(b.proven_inner, side, "5.2 proven inner ⊆ R(G), R(H)")


def check_scene(
    d: dict[str, Any],
    *,
    swept: bool = False,
    translate: bool = True,
    seed: int = 0,
    hang_s: float = HANG_S,
    frames: bool = False,
    certify: bool = False,
) -> tuple[list[Finding], dict[str, float]]:
    """Run every query type on the scene dictionary ``d`` (see the module docstring);
    returns the findings and the time of every query (seconds).  ``hang_s``: the
    time limit of one query (wall clock).  ``frames=True`` also maps the scene into
    the frames of issue 26 (scaled by 1e-3 and 1e3, moved to UTM-size coordinates;
    neither map is exact in binary) and demands the same regions mapped back
    (``frame``), and checks the 5.2 region against the stationary recognizable one.
    ``certify=True`` (with ``swept``) checks the certified bounds (module docstring)."""
    d = {k: v for k, v in d.items() if k != "features"}
    s = Scene.from_dict(d)
    rng = np.random.default_rng(seed)
    out: list[Finding] = []
    times: dict[str, float] = {}
    D = s.diameter
    area_tol = 1e-8 * D * D
    theta = float(rng.uniform(-math.pi, math.pi)) if rng.random() < 0.5 else 0.0
    q0 = (float(s.goal[0, 0]), float(s.goal[0, 1]), 0.0)
    point_gh = len(s.goal) == 1 and len(s.failure) == 1
    poly_gh = len(s.goal) > 1 and len(s.failure) > 1
    mixed_gh = not point_gh and not poly_gh

    def run(name: str, fn: Callable[[], Any]) -> Any:
        r = _timed(fn, name, out, times, hang_s)
        if r is None:
            return None
        if r.geom_type not in ("Polygon", "MultiPolygon") or not r.is_valid:
            out.append(Finding("invalid", name, f"{r.geom_type}, {shapely.is_valid_reason(r)}"))
            return None
        # measured as r ∩ obstacles plus r − bounds, each piece confirmed by a point test
        extra = _confirmed(shapely.intersection(r, s.obstacle_union), r) + _confirmed(
            shapely.difference(r, s.bounds_geom), r, s.bounds_geom
        )
        if extra > 1e-9 * D * D:
            out.append(Finding("outside", name, f"{extra / D**2:.3g} D^2 outside the free space"))
        return r

    def incl(a: Any, b: Any, what: str) -> None:
        if a is None or b is None:
            return
        diff = _confirmed(shapely.difference(a, b), a, b)
        if diff > area_tol:
            out.append(Finding("inclusion", what, f"{diff / D**2:.3g} D^2"))

    q_at = (q0[0], q0[1], theta)
    c_at = run("complete at", lambda: complete_region(s, target_at=q_at))
    p_at = run("partial at", lambda: partial_region(s, target_at=q_at))
    incl(c_at, p_at, "complete at ⊆ partial at")
    if c_at is not None:
        inside_t = shapely.intersection(c_at, s.target_at(*q_at)).area
        if inside_t > 1e-9 * D * D:
            out.append(Finding("outside", "complete at", f"{inside_t / D**2:.3g} D^2 in target"))
        obs = s.obstacle_union.buffer(-1e-9 * D, join_style="mitre")
        walls = s.bounds_geom.buffer(1e-9 * D, join_style="mitre")
        hull = np.asarray(s.target_at(*q_at).convex_hull.exterior.coords)[:-1]
        pts = _sample(c_at, 12, rng, 1e-6 * D)
        blind = sum(not _sees_whole(obs, walls, hull, p) for p in pts)
        if blind:
            out.append(Finding("unsafe", "complete at", f"{blind} of {len(pts)} members blind"))
    if p_at is not None:
        _check_partial_points(s, q_at, p_at, rng, out)
    c_in = run("complete in", lambda: complete_region(s, target_in="goal", theta=theta))
    c_any = run("complete any", lambda: complete_region(s, target_in="goal", theta=None))
    incl(c_any, c_in, "any orientation ⊆ fixed orientation")
    verts = s.goal if len(s.goal) > 1 else s.goal[:1]
    for v in verts[:4]:
        cv = _timed(
            lambda v=v: complete_region(s, target_at=(v[0], v[1], theta)), "complete at v", out, {}
        )
        incl(c_in, cv, "translating ⊆ stationary (complete)")
    rc = run("recognizable complete", lambda: recognizable_region(s, theta=theta))
    incl(rc, c_in, "recognizable ⊆ complete in G")
    if point_gh:
        rp = run("recognizable partial", lambda: recognizable_region(s, model="partial"))
        p0 = _timed(lambda: partial_region(s, target_at=q0), "partial at g", out, {})
        incl(rp, p0, "recognizable partial ⊆ partial at G")
    if swept:
        p_in = run(
            "partial in",
            lambda: partial_region(s, target_in="goal", theta=theta, conservative=True),
        )
        stationary = []  # the stationary partial regions at configurations of G
        for v in verts[:4]:
            pv = _timed(
                lambda v=v: partial_region(s, target_at=(v[0], v[1], theta)),
                "partial at v",
                out,
                {},
            )
            incl(p_in, pv, "translating ⊆ stationary (partial)")
            stationary.append(pv)
        if len(s.goal) > 1:
            # ... and at sampled configurations of G: on its boundary (where the sweep
            # runs, between its samples: issue 26.3) and inside it
            for qx, qy in _sample_configs(s.goal_geom, rng):
                pq = _timed(
                    lambda qx=qx, qy=qy: partial_region(s, target_at=(qx, qy, theta)),
                    "partial at sampled q",
                    out,
                    {},
                )
                incl(p_in, pq, "translating ⊆ stationary at sampled q (partial)")
                stationary.append(pq)
        if certify and len(s.goal) > 1:
            b = _timed(
                lambda: swept_bounds(s, target_in="goal", theta=theta),
                "swept bounds",
                out,
                times,
                3 * HANG_S,  # a sweep, its sampled shadows and the proven cells
            )
            if b is not None:
                _check_bounds(b, "swept bounds", incl)
                for st in stationary:
                    incl(b.proven_inner, st, "proven inner ⊆ stationary (partial)")
        if poly_gh:
            r52 = run(
                "recognizable partial 5.2",
                lambda: recognizable_region(s, model="partial", theta=theta, conservative=True),
            )
            # by definition a recognizable placement sees A wherever it is in G and in H
            p_h = _timed(
                lambda: partial_region(s, target_in="failure", theta=theta),
                "partial in H",
                out,
                {},
            )
            p_g = _timed(
                lambda: partial_region(s, target_in="goal", theta=theta), "partial in G", out, {}
            )
            incl(r52, p_g, "recognizable 5.2 ⊆ R(G)")
            incl(r52, p_h, "recognizable 5.2 ⊆ R(H)")
            if certify:
                _certify_recognizable(s, theta, [p_g, p_h], incl, out, times)
            if frames and r52 is not None and theta == 0.0:
                # ... and it is recognizable for every pose pair: G and H shrunk to one
                # vertex each gives the stationary recognizable region (issue 25 item 3)
                try:
                    st = s.replace(goal=s.goal[:1].tolist(), failure=s.failure[:1].tolist())
                except SceneError:
                    st = None
                if st is not None:
                    rs = _timed(
                        lambda: recognizable_region(st, model="partial"), "recog at g, h", out, {}
                    )
                    incl(r52, rs, "recognizable 5.2 ⊆ stationary recognizable")
        if mixed_gh:  # one point, one polygon (issue 25)
            rmx = run(
                "recognizable partial mixed",
                lambda: recognizable_region(s, model="partial", theta=theta, conservative=True),
            )
            sides = []
            for w, reg in (("G", s.goal), ("H", s.failure)):
                which = "goal" if w == "G" else "failure"
                if len(reg) == 1:
                    rw = _timed(
                        lambda reg=reg: partial_region(s, target_at=(*reg[0], theta)),
                        f"partial at {w}",
                        out,
                        {},
                    )
                else:
                    rw = _timed(
                        lambda which=which: partial_region(s, target_in=which, theta=theta),
                        f"partial in {w}",
                        out,
                        {},
                    )
                incl(rmx, rw, f"recognizable mixed ⊆ R({w})")
                sides.append(rw)
            if certify:
                _certify_recognizable(s, theta, sides, incl, out, times)
    if frames:
        _check_frames(s, d, q_at, theta, out, swept=swept, poly_gh=poly_gh)
    if translate:
        k = int(rng.integers(1, 6))
        unit = math.ldexp(1.0, math.ceil(math.log2(D)))
        o = float(10**k) * unit
        try:
            t = Scene.from_dict(_translated(d, o))
        except SceneError as e:
            out.append(Finding("translation", "validation", f"offset {o:g}: {e}"))
            return out, times
        for name, fn in (
            ("complete at", lambda sc, dx: complete_region(sc, target_at=(q_at[0] + dx, q_at[1] + dx, theta))),  # noqa: E501
            ("partial at", lambda sc, dx: partial_region(sc, target_at=(q_at[0] + dx, q_at[1] + dx, theta))),  # noqa: E501
            ("recognizable complete", lambda sc, dx: recognizable_region(sc, theta=theta)),
        ):  # fmt: skip
            try:
                a = fn(s, 0.0)
                b = shapely.affinity.translate(fn(t, o), -o, -o)
            except (SceneError, NotImplementedError):
                continue
            except Exception as e:  # noqa: BLE001
                out.append(Finding("crash", name + " (translated)", f"{type(e).__name__}: {e}"))
                continue
            diff = shapely.symmetric_difference(a, b).area
            if diff > 1e-9 * D * D:
                out.append(Finding("translation", name, f"offset {o:g}: {diff / D**2:.3g} D^2"))
    return out, times


#: The frames of :func:`_check_frames`: ``world = k * scene + (ox, oy)`` (for ``utm`` the
#: scene is first scaled by a power of two to a diameter of about 10).
FRAMES = {
    "scale1e-3": (1e-3, 0.0, 0.0),
    "scale1e3": (1e3, 0.0, 0.0),
    "utm": (1.0, 512345.0, 5412345.0),
}


def _mapped(d: dict, k: float, ox: float, oy: float) -> dict:
    out = dict(d)

    def f(pts: list) -> list:
        return [[k * x + ox, k * y + oy] for x, y in pts]

    for key in ("bounds", "goal", "failure"):
        out[key] = f(d[key])
    out["obstacles"] = [f(o) for o in d["obstacles"]]
    out["target"] = [[k * x, k * y] for x, y in d["target"]]
    if d.get("sensor"):
        sen = dict(d["sensor"])
        for key in ("range_acc", "max_range", "eps_pos"):
            if sen.get(key) is not None:
                sen[key] = sen[key] * k
        out["sensor"] = sen
    return out


def _sample_configs(g: shapely.Geometry, rng: np.random.Generator) -> list[tuple[float, float]]:
    """Two reference points on the boundary of the polygon ``g`` (not at a vertex) and
    one inside it."""
    b = g.exterior
    out = [b.interpolate(float(t), normalized=True) for t in rng.uniform(0.0, 1.0, 2)]
    out.append(g.representative_point())
    return [(float(p.x), float(p.y)) for p in out]


def _swept_differ(a: shapely.Geometry, b: shapely.Geometry, tol: float) -> float:
    """Area of ``a`` outside ``b`` grown by ``tol`` plus that of ``b`` outside ``a`` grown
    by ``tol``: two swept answers traced to within ``tol`` (each in its own frame, so
    their samples differ by rounding) agree up to that."""
    return (
        shapely.difference(a, shapely.buffer(b, tol)).area
        + shapely.difference(b, shapely.buffer(a, tol)).area
    )


def _check_frames(
    s: Scene,
    d: dict,
    q_at: tuple[float, float, float],
    theta: float,
    out: list[Finding],
    *,
    swept: bool = False,
    poly_gh: bool = False,
) -> None:
    """Issue 26 item 9: the regions of the scene mapped into another frame (inexactly:
    the inputs differ by rounding, ~1e-10 D), mapped back, equal the originals to
    1e-7 D^2 (findings ``frame``).  With ``swept`` also the swept partial region and
    (``poly_gh``) the 5.2 recognizable region (issue 25 item 7), compared up to their
    tracing tolerance ``tol`` (1e-4 D, :func:`_swept_differ`)."""
    D = s.diameter
    sw: list[tuple[str, Callable]] = []
    if swept and len(s.goal) > 1:
        sw.append(("partial in", lambda sc: partial_region(sc, target_in="goal", theta=theta)))
    if swept and poly_gh:
        sw.append(
            ("recognizable 5.2", lambda sc: recognizable_region(sc, model="partial", theta=theta))
        )
    base = {}
    for name, fn in sw:
        try:
            base[name] = fn(s)
        except (SceneError, NotImplementedError):
            continue
        except Exception as e:  # noqa: BLE001
            out.append(Finding("crash", name, f"{type(e).__name__}: {e}"))
    for fname, (k, ox, oy) in FRAMES.items():
        if fname == "utm":
            # a room of about 10 m first (an exact power-of-two scale): a 1e-6 m scene at
            # 5e6 m has no digits left, which is not the question
            k = math.ldexp(1.0, round(math.log2(10.0 / D)))
        try:
            t = Scene.from_dict(_mapped(d, k, ox, oy))
        except SceneError as e:
            out.append(Finding("frame", f"validation ({fname})", str(e)))
            continue
        qx, qy = q_at[0] * k + ox, q_at[1] * k + oy
        for name, fn in (
            ("complete at", lambda sc, x, y: complete_region(sc, target_at=(x, y, theta))),
            ("partial at", lambda sc, x, y: partial_region(sc, target_at=(x, y, theta))),
            ("complete in", lambda sc, x, y: complete_region(sc, target_in="goal", theta=theta)),
        ):
            try:
                a = fn(s, q_at[0], q_at[1])
                b = fn(t, qx, qy)
            except (SceneError, NotImplementedError):
                continue
            except Exception as e:  # noqa: BLE001
                out.append(Finding("crash", f"{name} ({fname})", f"{type(e).__name__}: {e}"))
                continue
            back = shapely.transform(b, lambda c, k=k, ox=ox, oy=oy: (c - [ox, oy]) / k)
            diff = shapely.symmetric_difference(a, back).area
            if diff > 1e-7 * D * D:
                out.append(Finding("frame", f"{name} ({fname})", f"{diff / D**2:.3g} D^2"))
        for name, fn in sw:
            if name not in base:
                continue
            try:
                b = fn(t)
            except (SceneError, NotImplementedError):
                continue
            except Exception as e:  # noqa: BLE001
                out.append(Finding("crash", f"{name} ({fname})", f"{type(e).__name__}: {e}"))
                continue
            back = shapely.transform(b, lambda c, k=k, ox=ox, oy=oy: (c - [ox, oy]) / k)
            diff = _swept_differ(base[name], back, 1e-4 * D)
            if diff > 1e-7 * D * D:
                out.append(Finding("frame", f"{name} ({fname})", f"{diff / D**2:.3g} D^2"))


# ---------------------------------------------------------------------------------------------
# command line
# ---------------------------------------------------------------------------------------------


def run_many(
    n: int,
    *,
    seed: int = 0,
    swept: bool = False,
    max_edges: int = 60,
    verbose: bool = False,
    contacts: bool = False,
    frames: bool = False,
    nonstar: bool = False,
    jobs: int = 1,
    certify: bool = False,
) -> dict[str, Any]:
    """Fuzz ``n`` scenes (seeds ``seed .. seed + n - 1``); returns a summary dictionary.

    ``jobs`` > 1 splits the seeds into that many contiguous chunks run in separate
    processes (the summary is the same as one process's, ``seconds`` is wall time)."""
    if not isinstance(jobs, int) or jobs < 1:
        raise ValueError(f"jobs must be a positive integer, got {jobs!r}")
    if jobs > 1 and n > 1:
        return _run_parallel(
            n, seed, jobs, dict(swept=swept, max_edges=max_edges, verbose=verbose,
                                contacts=contacts, frames=frames, nonstar=nonstar,
                                certify=certify),
        )  # fmt: skip
    kinds: Counter[str] = Counter()
    failing: list[dict[str, Any]] = []
    slowest: dict[str, float] = {}
    n_valid = 0
    t0 = time.perf_counter()
    for i in range(seed, seed + n):
        d = fuzz_scene(i, max_edges=max_edges, contacts=contacts, nonstar=nonstar)
        if d is None:
            continue
        n_valid += 1
        found, times = check_scene(d, swept=swept, seed=i, frames=frames, certify=certify)
        for k, v in times.items():
            slowest[k] = max(slowest.get(k, 0.0), v)
        for f in found:
            kinds[f.kind] += 1
        if found:
            failing.append(
                {"seed": i, "features": d.get("features"), "findings": [vars(f) for f in found]}
            )
            if verbose:
                print(i, d.get("features"), [vars(f) for f in found], file=sys.stderr)
    return {
        "scenes": n,
        "valid": n_valid,
        "violations": dict(kinds),
        "failing_scenes": failing,
        "slowest_query_s": {k: round(v, 3) for k, v in sorted(slowest.items())},
        "seconds": round(time.perf_counter() - t0, 1),
    }


def _run_parallel(n: int, seed: int, jobs: int, kw: dict[str, Any]) -> dict[str, Any]:
    from concurrent.futures import ProcessPoolExecutor

    t0 = time.perf_counter()
    per = -(-n // jobs)
    chunks = [(s0, min(per, seed + n - s0)) for s0 in range(seed, seed + n, per)]
    with ProcessPoolExecutor(len(chunks)) as ex:
        parts = list(ex.map(_run_chunk, [(c, kw) for c in chunks]))
    kinds: Counter[str] = Counter()
    slowest: dict[str, float] = {}
    for r in parts:
        kinds.update(r["violations"])
        for k, v in r["slowest_query_s"].items():
            slowest[k] = max(slowest.get(k, 0.0), v)
    return {
        "scenes": n,
        "valid": sum(r["valid"] for r in parts),
        "violations": dict(kinds),
        "failing_scenes": [f for r in parts for f in r["failing_scenes"]],
        "slowest_query_s": dict(sorted(slowest.items())),
        "seconds": round(time.perf_counter() - t0, 1),
    }


def _run_chunk(arg: tuple[tuple[int, int], dict[str, Any]]) -> dict[str, Any]:
    (s0, k), kw = arg
    return run_many(k, seed=s0, **kw)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m geometry.fuzz", description=__doc__.split("\n")[0])
    ap.add_argument("--n", type=int, default=200, help="number of seeds (default 200)")
    ap.add_argument("--seed", type=int, default=0, help="first seed")
    ap.add_argument(
        "--swept", action="store_true", help="also the swept (target_in) partial queries"
    )
    ap.add_argument("--max-edges", type=int, default=60)
    ap.add_argument(
        "--contacts", action="store_true", help="the contact families of issue 26 in the scenes"
    )
    ap.add_argument(
        "--frames", action="store_true", help="also scaled (1e-3, 1e3) and UTM frames (issue 26)"
    )
    ap.add_argument(
        "--nonstar", action="store_true", help="non-star-shaped targets (U, comb, hook; issue 25)"
    )
    ap.add_argument(
        "--certify",
        action="store_true",
        help="with --swept: also the certified bounds (swept_bounds; issue 25)",
    )
    ap.add_argument("--jobs", type=int, default=1, help="processes (default 1)")
    ap.add_argument("--json", help="write the summary (with failing seeds) to this file")
    ap.add_argument("-v", "--verbose", action="store_true")
    a = ap.parse_args(argv)
    res = run_many(
        a.n,
        seed=a.seed,
        swept=a.swept,
        max_edges=a.max_edges,
        verbose=a.verbose,
        contacts=a.contacts,
        frames=a.frames,
        nonstar=a.nonstar,
        jobs=a.jobs,
        certify=a.certify,
    )
    if a.json:
        with open(a.json, "w", encoding="utf-8") as f:
            json.dump(res, f, indent=1)
    print(f"seeds {a.seed}..{a.seed + a.n - 1}: {res['valid']} valid scenes, {res['seconds']} s")
    for k in ("crash", "invalid", "outside", "inclusion", "unsafe", "translation", "frame", "hang"):
        print(f"  {k:12s} {res['violations'].get(k, 0)}")
    print("  slowest query (s):", res["slowest_query_s"])
    return 1 if res["violations"] else 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
