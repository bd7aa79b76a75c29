"""Certified swept answers (issue 25 item 2): an inner and an outer region around the
exact answer of a swept query, and the Hausdorff distance between them.

Swept queries: :func:`geometry.partial_region` with ``target_in=`` (paper 3.2.2) and
:func:`geometry.recognizable_region` with ``model="partial"`` and a polygonal G or H
(paper 5.2, also mixed point/polygon).  Their exact answer is

    E = allowed - U_{q in G} S(q),   allowed = free space - (A (+) G),

S(q) the stationary shadow (placements blind to every wanted point of A_q).

* ``inner`` is what ``conservative=True`` returns: the traced shadow union grown by
  ``tol + grid``.  ``inner`` is inside E *as long as the sweep misses no shadow
  deeper than tol* (docs/DESIGN.md, "What is and is not guaranteed": not proven;
  checked empirically, ``tests/geometry/test_swept_bounds.py``).
* ``outer`` is ``allowed`` minus the union of the *sampled* stationary shadows S(q_k)
  (q_k on the boundary of G, so in G).  Each S(q_k) is an exact stationary shadow, so
  it is a subset of the exact union and ``E ⊆ outer``.  This needs no claim about the
  tracing between samples: it is proven given the stationary shadow (paper 3.2.1), up
  to the snap-rounding of the shadows' overlays (boundaries move by less than the
  ~1e-12 D grid; a lit sliver narrower than it collapses into the shadow).
  For a non-star-shaped target with overlap strips (the certified stand-in of
  :mod:`geometry.nonstar`) the stand-in's shadows are not subsets of the exact ones;
  there the sampled shadows are the real outline's whole-outline stationary shadows
  (blind to the whole outline implies blind to its wanted part).

See docs/DESIGN.md, "Certified swept answers".
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import shapely

from ._common import (
    Budget,
    as_scene,
    check_aim,
    check_eps_pos,
    check_theta,
    check_tol,
    polygonal,
    scene_domain,
    shrink_for_position,
)
from ._frame import world_messages
from ._shapes import ccw_ring, union_all
from .mixed import _point_side, point_strips
from .partial import _hole_ring, _partial_region, _swept_region, swept_tol
from .recognize import _accuracy, overlap_strips
from .sweep import QueryTimeout
from .weak import weak_visibility

if TYPE_CHECKING:  # pragma: no cover
    from .scene import Scene

__all__ = ["SweptBounds", "hausdorff_bounds", "proven_inner", "swept_bounds"]

#: The Hausdorff distance is bounded on cells refined from a grid of this many along the
#: longer side of the gap's bounding box (:func:`hausdorff_bounds`) ...
HAUSDORFF_CELLS = 64
#: ... until the upper and lower bounds agree to this fraction of the upper one.
HAUSDORFF_REL = 0.05


@dataclass(frozen=True)
class SweptBounds:
    """Inner and outer bound of a swept query's exact answer E: ``inner ⊆ E ⊆ outer``.

    Attributes
    ----------
    inner : the placements certified to see (shapely Polygon/MultiPolygon, world frame):
        the query's ``conservative=True`` answer.
    outer : every placement of E is in it (world frame); outside it a sampled
        configuration of the target blinds the placement.
    hausdorff : an upper bound on the Hausdorff distance between ``inner`` and
        ``outer`` (scene units), within ``hausdorff - hausdorff_lower`` of the true
        value; ``inf`` when ``inner`` is empty and ``outer`` is not.
    hausdorff_lower : a lower bound on it (scene units).
    samples : how many exact stationary shadows make up the outer bound.
    proven_inner : an inner bound proven without any claim about the sweep's tracing
        (:func:`proven_inner`; world frame), or ``None`` where that argument does not apply
        (5.2 and mixed G/H, a target that is not star-shaped, ``eps_aim`` > 0).  Looser than
        ``inner``; ``densify`` tightens it.
    proven_hausdorff : the upper Hausdorff bound between ``proven_inner`` and ``outer``
        (``None`` with it).
    """

    inner: shapely.Geometry
    outer: shapely.Geometry
    hausdorff: float
    hausdorff_lower: float
    samples: int
    proven_inner: shapely.Geometry | None = None
    proven_hausdorff: float | None = None


def swept_bounds(
    scene: Scene,
    *,
    target_in: str | shapely.Geometry | None = None,
    recognizable: bool = False,
    theta: float = 0.0,
    eps_pos: float = 0.0,
    eps_aim: float = 0.0,
    tol: float | None = None,
    timeout: float | None = None,
    progress: Callable[[int, int], None] | None = None,
    densify: int = 0,
) -> SweptBounds:
    """Inner and outer bound of a swept query (see the module docstring).

    Parameters
    ----------
    target_in : the swept partial region ``partial_region(scene, target_in=...)``:
        ``"goal"``, ``"failure"`` or a shapely Polygon/Point (world frame).
    recognizable : instead, ``recognizable_region(scene, model="partial", theta=...)``
        of a scene whose G or H is a polygon (paper 5.2, mixed point/polygon).
    theta, eps_pos, eps_aim, tol, timeout, progress : as in those queries.
    densify : extra exact stationary shadows per edge of G's (H's) boundary, evenly
        spaced, for the outer bound only (tighter, one stationary query each).

    Returns
    -------
    :class:`SweptBounds` in world coordinates (scene units); ``inner`` equals the
    query's ``conservative=True`` answer.
    """
    scene = as_scene(scene)
    if (target_in is None) == (not recognizable):
        raise ValueError("give exactly one of target_in=<region> or recognizable=True")
    theta = check_theta(theta)
    if theta is None:
        raise NotImplementedError("swept_bounds needs a fixed orientation theta")
    eps_pos = check_eps_pos(scene, eps_pos)
    eps_aim = check_aim(eps_aim)
    tol = check_tol(tol)
    what = "swept_bounds(recognizable=True)" if recognizable else "swept_bounds(target_in=...)"
    budget = Budget.make(timeout, progress, what)
    fr = scene.frame
    with world_messages(fr):
        local = scene.local
        if isinstance(densify, bool) or not isinstance(densify, int) or densify < 0:
            raise ValueError(f"densify must be an int >= 0, got {densify!r}")
        args = (
            float(theta), fr.length(eps_pos), eps_aim, swept_tol(local, fr.length(tol)), budget,
            densify,
        )  # fmt: skip
        if recognizable:
            inner, outer, n = _recognizable_bounds(local, *args)
            proven = None
        else:
            inner, outer, n, proven = _side(local, fr.region(target_in), *args)
    inner, outer = fr.to_world(inner), fr.to_world(outer)
    hi, lo = hausdorff_bounds(inner, outer)
    if proven is None:
        return SweptBounds(inner, outer, hi, lo, n)
    proven = fr.to_world(proven)
    return SweptBounds(inner, outer, hi, lo, n, proven, hausdorff_bounds(proven, outer)[0])


def _side(
    scene: Scene,
    target_in: str | shapely.Geometry,
    theta: float,
    eps_pos: float,
    eps_aim: float,
    tol: float,
    budget: Budget,
    densify: int = 0,
    strips: list[shapely.Geometry] | None = None,
) -> tuple[shapely.Geometry, shapely.Geometry, int, shapely.Geometry | None]:
    """(inner, outer, number of sampled shadows, proven inner or None) of one swept partial
    region, local frame."""
    sink: dict = {}
    inner = _swept_region(
        scene, target_in, theta, eps_pos, eps_aim, tol, True, strips=strips, budget=budget,
        sink=sink, extra_samples=densify,
    )  # fmt: skip
    samples = sink["samples"]
    stand_in = sink["stand_in"]
    if stand_in is not None and not stand_in.exact:
        # the hull stand-in's shadows are not inside the real ones: use the real outline's
        # whole-outline stationary shadows (blind to all of A_q => blind to its wanted part)
        shadows = []
        for q, _ in samples:
            if budget.deadline is not None and time.monotonic() > budget.deadline:
                raise QueryTimeout(
                    f"{budget.what} ran past its timeout while computing the outer bound's "
                    f"shadows ({len(samples) - len(shadows)} of {len(samples)} left); raise "
                    "timeout= or give timeout=None"
                )
            shadows.append(_whole_shadow(scene, q, theta, eps_aim))
    else:
        shadows = [s for _, s in samples]
    grid = sink["grid"]
    union = union_all(shadows, grid_size=grid) if shadows else shapely.Polygon()
    allowed = sink["allowed"]
    outer = polygonal(shapely.difference(allowed, union))
    proven = None
    if strips is None and stand_in is None and eps_aim == 0.0:
        # star-shaped target, whole outline: an inner bound that needs no claim about
        # the tracing (docs/DESIGN.md, "Certified swept answers")
        proven = proven_inner(scene, sink["region"], theta, [q for q, _ in samples], allowed, grid)
        if proven is not None and eps_pos > 0:
            proven = shrink_for_position(proven, allowed, eps_pos)
    if eps_pos > 0:
        # shrink_for_position grows by a circumscribed polygon of radius r + 2 delta
        # (delta = 1e-9 * diag): keep that inside the eps disc, so outer stays outside E
        delta = 1e-9 * max(_diag(allowed), 1.0)
        r = eps_pos * math.cos(math.pi / 64) * (1 - 1e-9) - 2 * delta
        if r > 0:
            outer = shrink_for_position(outer, allowed, r)
    return inner, outer, len(shadows), proven


def proven_inner(
    scene: Scene,
    region: shapely.Geometry,
    theta: float,
    qs: list[np.ndarray],
    allowed: shapely.Geometry,
    grid: float,
    max_split: int = 6,
) -> shapely.Geometry | None:
    """A proven inner bound of the swept partial region (whole outline wanted), local frame.

    The reference points ``qs`` (on the boundary of the polygon ``region``) and the
    region's vertices cut its boundary into pieces sigma = [q_a, q_b].  For every q on
    sigma the target A_q contains B_sigma = the points of A covered at every position of
    sigma (A_{q_a} minus the parallelograms its edges sweep along sigma), so a placement
    outside A (+) G blind to A_q is blind to B_sigma: the segment to a visible point of
    B_sigma enters A_q at a visible point first.  Hence the union of the shadows over
    the boundary lies in the union of the exact stationary shadows S(B_sigma) of the
    largest part of each B_sigma, and ``allowed`` minus the latter is inside the exact
    region (given that the boundary of G suffices: star-shaped target).  A piece whose
    B_sigma is empty (longer than the target is wide) is halved, up to ``max_split``
    times; ``None`` if one stays empty.  Snap-rounded on ``grid`` like the outer bound.
    """
    if region.geom_type != "Polygon":
        return None
    ring = region.exterior
    length = ring.length
    verts = np.asarray(ring.coords)[:-1]
    pos = np.concatenate(
        [
            shapely.line_locate_point(ring, shapely.points(verts)),
            shapely.line_locate_point(ring, shapely.points(np.asarray(qs).reshape(-1, 2)))
            if len(qs)
            else np.empty(0),
        ]
    )
    pos = np.unique(np.clip(pos, 0.0, length))
    stops = np.append(pos, pos[0] + length)
    pieces = [(a, b, 0) for a, b in zip(stops[:-1], stops[1:], strict=True) if b - a > 1e-12]
    dom = scene_domain(scene)
    shadows = []
    while pieces:
        a, b, depth = pieces.pop()
        qa = np.asarray(ring.interpolate(a % length).coords[0])
        qb = np.asarray(ring.interpolate(b % length).coords[0])
        core = _covered(scene.target_at(float(qa[0]), float(qa[1]), theta), qb - qa)
        if core is None:
            if depth >= max_split:
                return None
            mid = 0.5 * (a + b)
            pieces += [(a, mid, depth + 1), (mid, b, depth + 1)]
            continue
        hole = _hole_ring(core)
        seen = weak_visibility(dom, hole, np.ones(len(hole), dtype=bool))
        shadows.append(polygonal(shapely.difference(allowed, seen)))
    union = union_all(shadows, grid_size=grid) if shadows else shapely.Polygon()
    return polygonal(shapely.difference(allowed, union))


def _covered(a: shapely.Polygon, d: np.ndarray) -> shapely.Polygon | None:
    """The largest part of the points of ``a`` that stay in ``a + t d`` for all t in
    [0, 1] (``a`` minus the parallelograms its edges sweep along ``d``), or ``None``."""
    c = np.asarray(a.exterior.coords)
    e = c[1:] - c[:-1]
    swept = np.abs(e[:, 0] * d[1] - e[:, 1] * d[0]) > 0.0
    quads = np.stack([c[:-1], c[1:], c[1:] + d, c[:-1] + d], axis=1)[swept]
    core = a if len(quads) == 0 else shapely.difference(a, union_all(shapely.polygons(quads)))
    parts = [g for g in shapely.get_parts(polygonal(core)) if g.area > 0.0]
    if not parts:
        return None
    return max(parts, key=lambda g: g.area)


def _whole_shadow(scene: Scene, q: np.ndarray, theta: float, eps_aim: float) -> shapely.Geometry:
    """The real target's stationary shadow at ``q`` (whole outline wanted), local frame."""
    pose = (float(q[0]), float(q[1]), theta)
    seen = _partial_region(scene, pose, None, theta, 0.0, eps_aim, None, False)
    area = scene.target_at(*pose)
    return polygonal(shapely.difference(shapely.difference(scene.free_space, area), seen))


def _recognizable_bounds(
    scene: Scene,
    theta: float,
    eps_pos: float,
    eps_aim: float,
    tol: float,
    budget: Budget,
    densify: int,
) -> tuple[shapely.Geometry, shapely.Geometry, int]:
    """(inner, outer, samples) of the partial-model recognizable region, local frame."""
    g, h = scene.goal_geom, scene.failure_geom
    if g.geom_type == "Point" and h.geom_type == "Point":
        raise ValueError(
            "swept_bounds(recognizable=True) needs a polygonal goal or failure region: with "
            "two points the recognizable region is stationary (exact, nothing to bound)"
        )
    target = ccw_ring(scene.target_at(0.0, 0.0, theta))
    acc = _accuracy(scene)
    if g.geom_type != h.geom_type:  # geometry/mixed.py
        names = ("goal", "failure")
        pt_name = next(w for w in names if scene.region(w).geom_type == "Point")
        poly_name = next(w for w in names if w != pt_name)
        point, poly = scene.region(pt_name), scene.region(poly_name)
        inner, outer, n, _ = _side(
            scene, poly_name, theta, eps_pos, eps_aim, tol, budget, densify,
            strips=point_strips(target, point, *acc),
        )  # fmt: skip
        vs_poly = overlap_strips(target, poly, *acc)
        still = _point_side(scene, point, theta, vs_poly, eps_pos, eps_aim)
        return (
            polygonal(shapely.intersection(inner, still)),
            polygonal(shapely.intersection(outer, still)),
            n,
        )
    n_g, n_h = (
        len(shapely.get_coordinates(scene.region(w).boundary)) - 1 for w in ("goal", "failure")
    )
    sides = [
        _side(
            scene,
            me,
            theta,
            eps_pos,
            eps_aim,
            tol,
            dataclasses.replace(budget, offset=off, total=n_g + n_h),
            densify,
            strips=overlap_strips(target, scene.region(other), *acc),
        )  # fmt: skip
        for (me, other), off in ((("goal", "failure"), 0), (("failure", "goal"), n_g))
    ]
    return (
        polygonal(shapely.intersection(sides[0][0], sides[1][0])),
        polygonal(shapely.intersection(sides[0][1], sides[1][1])),
        sides[0][2] + sides[1][2],
    )


def hausdorff_bounds(
    inner: shapely.Geometry,
    outer: shapely.Geometry,
    rel: float = HAUSDORFF_REL,
    max_cells: int = 200_000,
) -> tuple[float, float]:
    """(upper, lower) bounds on sup_{x in outer} dist(x, inner), the Hausdorff distance
    of ``inner ⊆ outer`` (same units as the input).

    The distance to ``inner`` is 1-Lipschitz.  Square cells (centre c, half-diagonal r)
    cover the gap ``outer - inner``; a cell whose centre is farther than r from the gap
    holds none of it, and the others bound the distance in them by dist(c, inner) + r
    (upper).  Centres inside the gap and densified vertices of the gap give the lower
    bound.  Cells that cannot beat the lower bound are dropped, the rest split in four,
    until upper - lower <= ``rel`` * upper (or ``max_cells``, or 12 levels).  ``(inf,
    inf)`` when ``inner`` is empty and ``outer`` is not."""
    gap = polygonal(shapely.difference(outer, inner))
    if gap.is_empty or gap.area == 0.0:
        return 0.0, 0.0
    if inner.is_empty:
        return math.inf, math.inf
    x0, y0, x1, y1 = gap.bounds
    h = max(x1 - x0, y1 - y0) / HAUSDORFF_CELLS
    xs = np.arange(x0 + h / 2, x1 + h, h)
    ys = np.arange(y0 + h / 2, y1 + h, h)
    c = np.column_stack([a.ravel() for a in np.meshgrid(xs, ys)])
    verts = shapely.get_coordinates(shapely.segmentize(gap, h / 4))
    lower = float(_dist(inner, verts).max(initial=0.0))
    upper = math.inf
    for _ in range(12):
        r = h / math.sqrt(2.0)
        dg = _dist(gap, c)
        c, dg = c[dg <= r], dg[dg <= r]
        di = _dist(inner, c)
        lower = max(lower, float(di[dg == 0.0].max(initial=0.0)))
        bound = di + r
        upper = max(lower, float(bound.max(initial=0.0)))
        if upper - lower <= rel * upper or 4 * len(c) > max_cells:
            break
        c = c[bound > lower]
        h /= 2
        q = h / 2
        c = (c[:, None, :] + np.array([[-q, -q], [q, -q], [-q, q], [q, q]])[None]).reshape(-1, 2)
    return upper, lower


def _dist(region: shapely.Geometry, pts: np.ndarray) -> np.ndarray:
    """Distance from each point (n, 2) to the polygonal ``region`` (0 inside), indexed."""
    if len(pts) == 0:
        return np.zeros(0)
    rings = [r for p in shapely.get_parts(region) for r in (p.exterior, *p.interiors)]
    coords = [np.asarray(r.coords)[:, :2] for r in rings]
    segs = shapely.linestrings(np.concatenate([np.stack([c[:-1], c[1:]], axis=1) for c in coords]))
    tree = shapely.STRtree(segs)
    points = shapely.points(pts)
    (_, _), d = tree.query_nearest(points, return_distance=True, all_matches=False)
    shapely.prepare(region)
    inside = shapely.contains_xy(region, pts[:, 0], pts[:, 1])
    return np.where(inside, 0.0, d)


def _diag(g: shapely.Geometry) -> float:
    x0, y0, x1, y1 = g.bounds
    return math.hypot(x1 - x0, y1 - y0)
