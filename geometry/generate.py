"""Procedural scenes that satisfy the paper's assumptions (Briggs & Donald 3.1).

:func:`random_scene` draws a room (a rectangle, or a rectangle with notches cut
from its corners), a star-shaped target polygon with its reference point
``(0, 0)`` inside, a goal G and a failure region H (points or small polygons,
disjoint, inside the free space), and random non-overlapping obstacles (some
convex, some not).  No obstacle or wall meets the convex hull of the target's
swept area over G or over H -- by default not even for a rotating target, i.e.
CH(G (+) disc(r)) and CH(H (+) disc(r)) with r the target radius, which
contains CH(A_theta (+) G) for every orientation theta.

:func:`scene_with_edges` builds scenes with a prescribed total number of
environment edges (walls plus obstacle edges) for benchmarks.

Everything is deterministic given the numpy ``Generator`` (or seed); failed
draws are re-sampled.  The result is a plain dict in the pinned JSON scene
format, loadable with :meth:`geometry.Scene.from_dict`.  Pure numpy + shapely.
"""

from __future__ import annotations

import math
from typing import Any, Literal

import numpy as np
import shapely
from shapely.geometry import Point, Polygon

__all__ = ["random_scene", "scene_with_edges", "random_polygon"]

#: Coordinates are rounded to this many decimals (readable JSON, exact round trip).
DECIMALS = 6


def _round(pts: np.ndarray) -> list[list[float]]:
    return [[round(float(x), DECIMALS), round(float(y), DECIMALS)] for x, y in pts]


def random_polygon(
    rng: np.random.Generator,
    n_vertices: int,
    radius: float,
    *,
    convex: bool,
    min_radius_frac: float = 0.45,
) -> np.ndarray:
    """A random simple polygon around the origin, counter-clockwise, ``(n, 2)``.

    Vertices are at sorted random angles (gaps bounded away from zero and below
    pi), so the polygon is star-shaped from the origin and the origin is strictly
    inside.  ``convex=True`` puts the vertices on an ellipse (a convex polygon);
    otherwise the radii vary in ``[min_radius_frac * radius, radius]``, which
    gives a (generically) non-convex star-shaped polygon.
    """
    if n_vertices < 3:
        raise ValueError("a polygon needs at least 3 vertices")
    # angular gaps: Dirichlet-like, each gap in [0.25, 1.75] * mean, so < pi for n >= 3
    w = rng.uniform(0.25, 1.75, n_vertices)
    gaps = w / w.sum() * 2 * math.pi
    while gaps.max() >= 0.95 * math.pi:  # only possible for n == 3
        w = rng.uniform(0.5, 1.5, n_vertices)
        gaps = w / w.sum() * 2 * math.pi
    ang = rng.uniform(0, 2 * math.pi) + np.concatenate([[0.0], np.cumsum(gaps[:-1])])
    if convex:
        a, b = radius, radius * rng.uniform(0.55, 1.0)
        phi = rng.uniform(0, math.pi)
        x, y = a * np.cos(ang), b * np.sin(ang)
        c, s = math.cos(phi), math.sin(phi)
        pts = np.column_stack([c * x - s * y, s * x + c * y])
    else:
        r = radius * rng.uniform(min_radius_frac, 1.0, n_vertices)
        # make sure at least one vertex dips (clearly non-convex for n >= 4)
        if n_vertices >= 4:
            r[rng.integers(n_vertices)] = radius * min_radius_frac
        pts = np.column_stack([r * np.cos(ang), r * np.sin(ang)])
    return pts


def _room(
    rng: np.random.Generator,
    width: float,
    height: float,
    notches: int,
    notch_size: tuple[float, float] = (0.12, 0.3),
) -> Polygon | None:
    """A ``width x height`` rectangle with ``notches`` rectangular corner cut-outs, each
    ``notch_size`` (a range of fractions of the width and of the height) large; ``None``
    when the cut-outs split the room."""
    room = shapely.box(0.0, 0.0, width, height)
    corners = rng.permutation(4)[:notches]
    lo, hi = notch_size
    for k in corners:
        w = width * rng.uniform(lo, hi)
        h = height * rng.uniform(lo, hi)
        x0 = 0.0 if k in (0, 3) else width - w
        y0 = 0.0 if k in (0, 1) else height - h
        room = room.difference(shapely.box(x0, y0, x0 + w, y0 + h))
    if not isinstance(room, Polygon) or room.interiors:
        return None
    room = shapely.orient_polygons(room, exterior_cw=False)
    pts = np.asarray(_round(np.asarray(room.exterior.coords)[:-1]))
    keep = []
    n = len(pts)
    for i in range(n):  # drop repeated and collinear vertices
        a, b, c = pts[i - 1], pts[i], pts[(i + 1) % n]
        if (
            np.allclose(a, b)
            or abs((b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0])) < 1e-12
        ):
            continue
        keep.append(b)
    return Polygon(keep)


def _region(
    rng: np.random.Generator, center: np.ndarray, kind: str, size: float
) -> Polygon | Point:
    if kind == "point":
        return Point(center)
    n = int(rng.integers(3, 7))
    pts = random_polygon(rng, n, size, convex=bool(rng.random() < 0.6), min_radius_frac=0.5)
    return Polygon(pts + center)


def _coords(g: Polygon | Point) -> np.ndarray:
    if isinstance(g, Point):
        return np.array([[g.x, g.y]])
    return np.asarray(g.exterior.coords)[:-1]


def random_scene(
    rng: np.random.Generator,
    *,
    n_obstacles: int | None = None,
    target_edges: int | None = None,
    goal: Literal["point", "polygon"] = "point",
    failure: Literal["point", "polygon"] | None = None,
    obstacle_vertices: tuple[int, int] = (3, 8),
    obstacle_sizes: list[int] | None = None,
    room_size: tuple[float, float] | None = None,
    notches: int | None = None,
    convex_fraction: float = 0.5,
    target_radius: float | None = None,
    rotation_clear: bool = True,
    overlap: bool = False,
    margin: float = 0.05,
    name: str = "random",
    max_tries: int = 200,
    fov_deg: float | tuple[float, float] | None = None,
    notch_size: tuple[float, float] = (0.12, 0.3),
) -> dict[str, Any]:
    """A random scene dict in the pinned JSON format.

    Parameters
    ----------
    rng : numpy Generator; the result is a deterministic function of its state.
    n_obstacles : number of obstacles (default: 2..7 at random).
    target_edges : number of target vertices (default: 3..7 at random).
    goal, failure : ``"point"`` or ``"polygon"`` for G and H (failure defaults to goal's kind).
    obstacle_vertices : inclusive range of vertex counts per obstacle.
    obstacle_sizes : explicit vertex count per obstacle (overrides the two above).
    room_size : ``(width, height)``; default grows with the number of obstacles.
    notches : corner cut-outs of the room (0 = rectangle; default 0..2 at random).
    notch_size : range of a cut-out's width and height as fractions of the room's (default
        ``(0.12, 0.3)``; up to 0.75 makes L-shaped rooms and corridors around a corner).
    convex_fraction : probability that an obstacle is convex.
    target_radius : scale of the target (default random in [0.3, 0.8]).
    rotation_clear : keep obstacles and walls off CH(G (+) disc(r)) and CH(H (+) disc(r))
        (valid for every target orientation and for ``theta=None`` queries); otherwise
        only off CH(A_0 (+) G) and CH(A_0 (+) H), the minimum the paper assumes.
    overlap : for point G and H, place H so that A at H has edges collinear with and
        overlapping edges of A at G (paper 5.1 overlap segments).
    margin : clearance (scene units) kept between obstacles, walls and the hulls.
    name : the scene's ``name``.
    max_tries : re-sampling budget before giving up with ``RuntimeError``.
    fov_deg : the sensor's field of view in degrees, written as ``sensor.fov_deg``: a number,
        or ``(low, high)`` to draw it uniformly (one draw from ``rng`` after the geometry,
        so the geometry is the same as without it).  ``None`` (default): no ``sensor`` key
        (the 360-degree default sensor).

    Returns
    -------
    dict with keys ``name, bounds, obstacles, target, goal, failure`` (and ``sensor`` when
    ``fov_deg`` is given).
    """
    if not (len(notch_size) == 2 and 0 < notch_size[0] <= notch_size[1] < 1):
        raise ValueError(f"notch_size must be a (low, high) pair in (0, 1), got {notch_size!r}")
    if fov_deg is not None:
        lo_hi = (fov_deg, fov_deg) if np.isscalar(fov_deg) else tuple(fov_deg)
        if len(lo_hi) != 2 or not all(0 < float(v) <= 360 for v in lo_hi) or lo_hi[0] > lo_hi[1]:
            raise ValueError(
                "fov_deg must be a number in (0, 360] or a (low, high) pair of them, "
                f"got {fov_deg!r}"
            )
    failure = failure or goal
    for _ in range(max_tries):
        d = _try_scene(
            rng,
            n_obstacles=n_obstacles,
            target_edges=target_edges,
            goal=goal,
            failure=failure,
            obstacle_vertices=obstacle_vertices,
            obstacle_sizes=obstacle_sizes,
            room_size=room_size,
            notches=notches,
            convex_fraction=convex_fraction,
            target_radius=target_radius,
            rotation_clear=rotation_clear,
            overlap=overlap,
            margin=margin,
            name=name,
            notch_size=notch_size,
        )
        if d is not None:
            if fov_deg is not None:
                lo, hi = (float(v) for v in lo_hi)
                d["sensor"] = {"fov_deg": lo if lo == hi else float(rng.uniform(lo, hi))}
            return d
    raise RuntimeError("random_scene: could not place the scene; relax the parameters")


def _try_scene(
    rng: np.random.Generator,
    *,
    n_obstacles,
    target_edges,
    goal,
    failure,
    obstacle_vertices,
    obstacle_sizes,
    room_size,
    notches,
    convex_fraction,
    target_radius,
    rotation_clear,
    overlap,
    margin,
    name,
    notch_size=(0.12, 0.3),
) -> dict[str, Any] | None:
    if obstacle_sizes is None:
        n_obs = int(rng.integers(2, 8)) if n_obstacles is None else int(n_obstacles)
        lo, hi = obstacle_vertices
        obstacle_sizes = [int(k) for k in rng.integers(lo, hi + 1, n_obs)]
    n_obs = len(obstacle_sizes)
    m = int(rng.integers(3, 8)) if target_edges is None else int(target_edges)
    r_t = float(rng.uniform(0.3, 0.8)) if target_radius is None else float(target_radius)
    if room_size is None:
        area = 40.0 + 9.0 * n_obs
        aspect = rng.uniform(0.7, 1.4)
        room_size = (math.sqrt(area * aspect), math.sqrt(area / aspect))
    width, height = room_size
    k_notch = int(rng.integers(0, 3)) if notches is None else int(notches)
    room = _room(rng, width, height, k_notch, notch_size)
    if room is None:
        return None

    target = random_polygon(rng, m, r_t, convex=bool(rng.random() < 0.5))
    target = np.asarray(_round(target))
    tpoly = Polygon(target)
    if not tpoly.is_valid or not tpoly.contains(Point(0, 0)):
        return None
    r = float(np.hypot(target[:, 0], target[:, 1]).max())

    inner = room.buffer(-(r + margin + 0.3))
    if inner.is_empty:
        return None

    def sample_in(poly: Polygon) -> np.ndarray:
        x0, y0, x1, y1 = poly.bounds
        for _ in range(1000):
            p = rng.uniform((x0, y0), (x1, y1))
            if poly.contains(Point(p)):
                return p
        raise RuntimeError("sampling failed")

    try:
        cg = sample_in(inner)
    except RuntimeError:
        return None
    size_g = float(rng.uniform(0.3, 1.0))
    G = _region(rng, cg, goal, size_g)
    if overlap and goal == "point" and failure == "point":
        # shift along a target edge by less than the edge length: that edge's line is shared
        i = int(rng.integers(m))
        e = target[(i + 1) % m] - target[i]
        shift = e * rng.uniform(0.3, 0.7)
        H = Point(cg + shift)
    else:
        try:
            ch = sample_in(inner)
        except RuntimeError:
            return None
        H = _region(rng, ch, failure, float(rng.uniform(0.3, 1.0)))
    G = Polygon(_round(_coords(G))) if isinstance(G, Polygon) else Point(_round(_coords(G))[0])
    H = Polygon(_round(_coords(H))) if isinstance(H, Polygon) else Point(_round(_coords(H))[0])
    if not G.is_valid or not H.is_valid or G.distance(H) < 1e-3:
        return None

    def hull(X: Polygon | Point) -> Polygon:
        if rotation_clear:
            return shapely.convex_hull(X).buffer(r * 1.01, quad_segs=32)
        sums = (target[:, None, :] + _coords(X)[None, :, :]).reshape(-1, 2)
        return shapely.MultiPoint(sums).convex_hull

    hulls = shapely.union(hull(G), hull(H))
    keep_out = hulls.buffer(margin)
    if not room.buffer(-margin).contains(keep_out):
        return None

    walls_in = room.buffer(-margin)
    obstacles: list[np.ndarray] = []
    placed = shapely.Polygon()
    for k in obstacle_sizes:
        ok = False
        for _ in range(60):
            rad = float(rng.uniform(0.4, 1.2))
            pts = random_polygon(rng, k, rad, convex=bool(rng.random() < convex_fraction))
            c = rng.uniform((0, 0), (width, height))
            pts = np.asarray(_round(pts + c))
            op = Polygon(pts)
            if not op.is_valid or op.area < 1e-3:
                continue
            if not walls_in.contains(op) or op.intersects(keep_out):
                continue
            if not placed.is_empty and op.distance(placed) < margin:
                continue
            obstacles.append(pts)
            placed = shapely.union(placed, op)
            ok = True
            break
        if not ok:
            return None

    bounds = np.asarray(room.exterior.coords)[:-1]
    d: dict[str, Any] = {
        "name": name,
        "bounds": _round(bounds),
        "obstacles": [_round(o) for o in obstacles],
        "target": _round(target),
        "goal": _round(_coords(G)),
        "failure": _round(_coords(H)),
    }
    return d


def scene_with_edges(
    n_edges: int, seed: int, *, goal: Literal["point", "polygon"] = "polygon"
) -> dict[str, Any]:
    """A benchmark scene whose walls plus obstacles have about ``n_edges`` edges.

    A rectangular room (4 walls) or, for ``n_edges >= 40``, an L-shaped room
    (6 walls) plus obstacles of 3..10 vertices whose counts add up to the rest,
    half convex and half not, placed without overlap around polygonal (default)
    or point-sized G and H.  A 6-vertex target.  Deterministic in ``seed``.
    """
    if n_edges < 7:
        raise ValueError("n_edges must be at least 7 (4 walls + a triangle)")
    rng = np.random.default_rng(seed)
    notches = 1 if n_edges >= 40 else 0
    walls = 4 + 2 * notches
    rest = n_edges - walls
    sizes: list[int] = []
    while rest > 0:
        k = int(rng.integers(3, 11))
        if rest - k < 3 and rest - k != 0:
            k = rest if rest <= 10 else rest - 3
        sizes.append(k)
        rest -= k
    n_obs = len(sizes)
    area = 60.0 + 10.0 * n_obs
    room_size = (math.sqrt(area * 1.2), math.sqrt(area / 1.2))
    return random_scene(
        rng,
        obstacle_sizes=sizes,
        target_edges=6,
        goal=goal,
        room_size=room_size,
        notches=notches,
        target_radius=0.6,
        name=f"bench-{n_edges}-edges-seed{seed}",
        max_tries=500,
    )
