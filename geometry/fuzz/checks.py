"""The checks of one fuzzed scene (:func:`check_scene`): every query type, and the violations
(the kinds are listed in :mod:`geometry.fuzz`)."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
import shapely

from ..certify import swept_bounds
from ..complete import complete_region
from ..partial import partial_region
from ..recognize import recognizable_region
from ..scene import Scene, SceneError
from .findings import HANG_S, Finding, _timed
from .frames import _check_frames, _sample_configs


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
