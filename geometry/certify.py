"""Certified swept answers (issue 25 item 2): an inner and an outer region around the
exact answer of a swept query, and the Hausdorff distance between them.

Swept queries: :func:`geometry.partial_region` with ``target_in=`` (paper 3.2.2) and
:func:`geometry.recognizable_region` with ``model="partial"`` and a polygonal G or H
(paper 5.2, also mixed point/polygon).  Their exact answer is

    E = allowed - U_{q in G} S(q),   allowed = free space - (A (+) G),

S(q) the stationary shadow (placements blind to every wanted point of A_q).

* ``inner`` is what ``conservative=True`` returns with the sweep's previous, denser
  sampling rules (:data:`geometry.sweep.LAZY_SAMPLES` False; within 2 tol of the lazy
  answer): the traced shadow union grown by ``tol + grid``.  ``inner`` is inside E *as
  long as the sweep misses no shadow deeper than tol* (docs/DESIGN.md, "What is and is
  not guaranteed": not proven; checked empirically, ``tests/geometry/test_swept_bounds.py``).
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
from ._domain import Domain, domain_from_geometry
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
#: The proven inner bound over cells covering G (:func:`proven_inner`) starts from
#: triangles with sides of at most this fraction of the target's size ...
CELL_SIZE = 0.25
#: ... within a budget of this many cells (times ``4**densify``), splits included.
MAX_CELLS = 256


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
        (:func:`proven_inner`; world frame) for every swept query without aim error: the
        whole outline or 5.2's wanted pieces, point/polygon/mixed G and H, star-shaped or
        not.  ``None`` with ``eps_aim`` > 0 (the argument does not cover the dropped
        narrow fans) or when a cell of G stays wider than the target (a target much
        thinner than G is wide).  Usually looser than ``inner``; ``densify`` tightens it.
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
        spaced, for the outer bound (tighter, one stationary query each); the proven
        inner bound's pieces are cut there too, and its cells over G (5.2, non-star
        targets) are halved ``densify`` more times (see :func:`proven_inner`).

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
            inner, outer, n, proven = _recognizable_bounds(local, *args)
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
        sink=sink, extra_samples=densify, lazy=False,
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
    if eps_aim == 0.0:
        # an inner bound that needs no claim about the tracing (docs/DESIGN.md, "Certified
        # swept answers"): over the boundary of G for a star-shaped target with the whole
        # outline wanted, else over cells covering G
        proven = proven_inner(
            scene, sink["region"], theta, [q for q, _ in samples], allowed, grid,
            strips=strips, boundary=strips is None and stand_in is None, refine=densify,
        )  # fmt: skip
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
    strips: list[shapely.Geometry] | None = None,
    boundary: bool | None = None,
    refine: int = 0,
) -> shapely.Geometry | None:
    """A proven inner bound of a swept partial region, local frame, or ``None``.

    ``region`` (a polygon, G) is covered by *cells* C: with ``boundary`` (the default
    for a star-shaped target with the whole outline wanted, where the boundary of G
    suffices) the pieces sigma = [q_a, q_b] into which the reference points ``qs`` and
    the region's vertices cut its boundary; otherwise the triangles of a constrained
    Delaunay triangulation of the whole region.  For every q in a cell C the target A_q
    contains B_C = the points of A covered at every position of C (A at a vertex of C
    minus the sets e (+) C that its edges e sweep over C: a point leaves A_q along a
    path in C only by crossing an edge), so a placement p outside A (+) G that sees a
    point b of B_C sees A_q: the segment p -> b enters A_q at a first point y, which p
    sees.  With overlap ``strips`` (5.2: U_i, the unwanted part of edge i, a fixed set)
    y must also be wanted: y lies on an edge e_i of A_q, hence in e_i (+) C, so when the
    segment avoids O_C = the union of (e_i (+) C) n U_i, y is outside U_i.  O_C becomes
    an obstacle (grown by ``1e-7`` of the scene's size, B_C shrunk by twice that, so
    that they do not touch).  Hence the union of the shadows S(q) over the region lies
    in the union of the exact stationary shadows of the largest part of each B_C (among
    the obstacles and O_C), and ``allowed`` minus the latter is inside the exact region.
    The triangles start with sides of at most :data:`CELL_SIZE` times the target's size,
    halved ``refine`` more times (smaller cells, smaller O_C: a tighter bound, one
    stationary query per cell), while they number at most a quarter of the budget of
    ``MAX_CELLS * 4**refine`` cells.  A cell whose B_C is still empty (wider than the
    target) is halved (a triangle: quartered), up to ``max_split`` times; ``None`` if one
    stays empty or the triangles pass the budget (a target much thinner than G is wide).
    Snap-rounded on ``grid`` like the outer bound.
    No claim about the sweep's tracing enters.
    """
    if region.geom_type != "Polygon":
        return None
    if boundary is None:
        boundary = strips is None
    if region.interiors:  # the pieces follow the outer ring only: cover a holed G by cells
        boundary = False
    budget = None
    if boundary:
        cells = _boundary_cells(region, qs)
    else:
        budget = MAX_CELLS * 4**refine
        size = CELL_SIZE * _diag(scene.target_at(0.0, 0.0, theta)) / 2**refine
        cells = _region_cells(region, size, budget // 4)
    dom = scene_domain(scene)
    delta = 1e-7 * max(_diag(allowed), 1e-300)
    shadows = []
    while cells:
        if budget is not None and len(shadows) + len(cells) > budget:
            return None  # a target too thin for cells of G: no bound in reasonable time
        cell, depth = cells.pop()
        a = scene.target_at(float(cell[0, 0]), float(cell[0, 1]), theta)
        core, swept = _covered(a, cell - cell[0])
        if core is not None and strips is not None:
            core, env = _among_strips(scene, core, swept, strips, delta)
        else:
            env = dom
        if core is None:
            if depth >= max_split:
                return None
            cells += [(c, depth + 1) for c in _split(cell)]
            continue
        hole = _hole_ring(core)
        seen = weak_visibility(env, hole, np.ones(len(hole), dtype=bool))
        shadows.append(polygonal(shapely.difference(allowed, seen)))
    union = union_all(shadows, grid_size=grid) if shadows else shapely.Polygon()
    return polygonal(shapely.difference(allowed, union))


def _boundary_cells(region: shapely.Polygon, qs: list[np.ndarray]) -> list:
    """The pieces [q_a, q_b] of the region's boundary cut at its vertices and at ``qs``
    ((2, 2) arrays, depth 0)."""
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
    out = []
    for a, b in zip(stops[:-1], stops[1:], strict=True):
        if b - a > 1e-12:
            qa = np.asarray(ring.interpolate(a % length).coords[0])
            qb = np.asarray(ring.interpolate(b % length).coords[0])
            out.append((np.stack([qa, qb]), 0))
    return out


def _region_cells(region: shapely.Polygon, size: float, cap: int) -> list:
    """Triangles ((3, 2) arrays, depth 0) covering the region, holes excluded: a
    constrained Delaunay triangulation, quartered level by level until every side is at
    most ``size`` long or another level would pass ``cap`` triangles."""
    tris = shapely.get_parts(shapely.constrained_delaunay_triangles(region))
    cells = [np.asarray(t.exterior.coords)[:3] for t in tris if t.area > 0.0]
    while 4 * len(cells) <= cap:
        side = max(float(np.hypot(*(c - np.roll(c, 1, axis=0)).T).max()) for c in cells)
        if side <= size:
            break
        cells = [t for c in cells for t in _split(c)]
    return [(c, 0) for c in cells]


def _split(cell: np.ndarray) -> list[np.ndarray]:
    """A segment halved, a triangle quartered (they cover the cell)."""
    if len(cell) == 2:
        m = 0.5 * (cell[0] + cell[1])
        return [np.stack([cell[0], m]), np.stack([m, cell[1]])]
    a, b, c = cell
    ab, bc, ca = 0.5 * (a + b), 0.5 * (b + c), 0.5 * (c + a)
    return [np.stack(t) for t in ((a, ab, ca), (ab, b, bc), (ca, bc, c), (ab, bc, ca))]


def _covered(a: shapely.Polygon, d: np.ndarray) -> tuple[shapely.Polygon | None, np.ndarray]:
    """The largest part of the points of ``a`` that stay in ``a + v`` for every ``v`` in
    the convex hull of the offsets ``d`` ((k, 2), ``d[0] = 0``): ``a`` minus the sets
    e (+) conv(d) its edges e sweep (each the convex hull of the edge's ends moved by
    every offset), or ``None``; and those swept sets per edge of ``a`` (an array of
    geometries in the order of :func:`ccw_ring`, empty where an edge is parallel to a
    segment cell)."""
    r = ccw_ring(a)  # edge i from vertex i: the order of the strips U_i
    ends = np.stack([r, np.roll(r, -1, axis=0)], axis=1)  # (E, 2, 2)
    pts = (ends[:, :, None, :] + d[None, None, :, :]).reshape(len(ends), -1, 2)
    swept = shapely.convex_hull(shapely.multipoints(pts))
    swept = np.where(shapely.area(swept) > 0.0, swept, shapely.Polygon())
    real = swept[shapely.area(swept) > 0.0]
    core = a if len(real) == 0 else shapely.difference(a, union_all(real))
    parts = [g for g in shapely.get_parts(polygonal(core)) if g.area > 0.0]
    if not parts:
        return None, swept
    return max(parts, key=lambda g: g.area), swept


def _among_strips(
    scene: Scene,
    core: shapely.Polygon,
    swept: np.ndarray,
    strips: list[shapely.Geometry],
    delta: float,
) -> tuple[shapely.Polygon | None, Domain]:
    """``core`` shrunk by ``2 delta`` and the free space with O_C = the union of
    (edge i's swept set) n U_i grown by ``delta`` as an obstacle (:func:`proven_inner`);
    ``(None, ...)`` when nothing of ``core`` is left."""
    blocks = shapely.intersection(swept, np.asarray(strips, dtype=object))
    blocks = blocks[shapely.area(blocks) > 0.0]
    if len(blocks) == 0:
        return core, scene_domain(scene)
    obstacle = shapely.buffer(union_all(blocks), delta, join_style="mitre")
    free = polygonal(shapely.difference(scene.free_space, obstacle))
    shrunk = shapely.buffer(core, -2 * delta, join_style="mitre")
    left = polygonal(shapely.difference(shrunk, obstacle))
    parts = [g for g in shapely.get_parts(left) if g.area > 0.0]
    if not parts:
        return None, scene_domain(scene)
    return max(parts, key=lambda g: g.area), domain_from_geometry(free)


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
) -> tuple[shapely.Geometry, shapely.Geometry, int, shapely.Geometry | None]:
    """(inner, outer, samples, proven inner or None) of the partial-model recognizable
    region, local frame."""
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
        inner, outer, n, proven = _side(
            scene, poly_name, theta, eps_pos, eps_aim, tol, budget, densify,
            strips=point_strips(target, point, *acc),
        )  # fmt: skip
        vs_poly = overlap_strips(target, poly, *acc)
        still = _point_side(scene, point, theta, vs_poly, eps_pos, eps_aim)  # exact
        return (
            polygonal(shapely.intersection(inner, still)),
            polygonal(shapely.intersection(outer, still)),
            n,
            None if proven is None else polygonal(shapely.intersection(proven, still)),
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
    proven = (
        None
        if sides[0][3] is None or sides[1][3] is None
        else polygonal(shapely.intersection(sides[0][3], sides[1][3]))
    )
    return (
        polygonal(shapely.intersection(sides[0][0], sides[1][0])),
        polygonal(shapely.intersection(sides[0][1], sides[1][1])),
        sides[0][2] + sides[1][2],
        proven,
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
