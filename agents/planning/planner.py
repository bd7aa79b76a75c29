"""Placement, motion and aim for the analytic oracle (Briggs & Donald, section 6.2-6.3).

Frames and units
----------------
Everything is in the scene's **world frame** and the scene's length unit; angles are
**radians**, counter-clockwise from the world +x axis.  Regions are shapely geometries of
sensor (robot-centre) placements, as returned by :func:`geometry.complete_region`,
:func:`geometry.partial_region` and :func:`geometry.recognizable_region`.

What the paper does and what this module does
---------------------------------------------
Section 6.2 shrinks the visibility region for model and sensor uncertainty, discretises the
shrunk region's edges, sorts the samples by distance from the robot and returns the first one
reachable by a *one-step* (straight-line) motion; if none is, it gives up ("the robot would have
to move around corners").  Here:

* :func:`grow_free_space` builds the configuration space of a disc robot, so the robot's radius
  is handled exactly (up to a conservative polygonal arc approximation) instead of by shrinking
  the region;
* :func:`shrink_region` shrinks a region by a margin, conservatively;
* :func:`shortest_path` computes the *exact* shortest collision-free path from the robot to the
  nearest point of the region (nearest in path length, not in straight-line distance), on the
  visibility graph of the configuration space.  No discretisation: the end point is the region
  point nearest to the last bend of the path.  When the robot sees its nearest region point the
  answer is the paper's one-step motion to that point;
* :func:`choose_placement` puts this together and never raises for an empty region: "no
  placement exists" and "unreachable" are answers (:class:`Placement`);
* :func:`best_aim` (section 6.3) aims at the bisector of the target's angular extent rather than
  at the goal's centroid, which maximises the angular margin to the field of view's edges.
"""

from __future__ import annotations

import math
from collections import OrderedDict
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import shapely
from shapely.geometry.base import BaseGeometry

if TYPE_CHECKING:  # pragma: no cover
    from geometry import Scene

__all__ = [
    "PLAN_QUAD_SEGS",
    "Path",
    "PathField",
    "Placement",
    "VisibilityGraph",
    "best_aim",
    "best_joint_aim",
    "choose_placement",
    "grow_free_space",
    "shortest_path",
    "shrink_region",
]

#: Segments per quarter circle of the polygonal arcs used by :func:`grow_free_space` and
#: :func:`shrink_region`.  The polygons circumscribe the true discs (radius scaled by
#: ``1 / cos(pi / (4 * PLAN_QUAD_SEGS))``), so the results are *inside* the exact sets, by at most
#: ``radius * 0.0048`` with the default of 8.
PLAN_QUAD_SEGS = 8

#: Relative tolerance (times the size of the free space's bounding box) for "touching".
_TOL_REL = 1e-9
#: Visibility tests are done in batches of this many segments (lazy candidate evaluation).
_BATCH = 512


def _outer(quad_segs: int) -> float:
    """Radius factor making a ``quad_segs`` polygonal buffer contain the exact disc buffer."""
    return 1.0 / math.cos(math.pi / (4 * quad_segs))


def _polygonal(g: BaseGeometry) -> BaseGeometry:
    """Keep the 2-D parts of a boolean result (drop points and lines of touching)."""
    if g.is_empty:
        return shapely.Polygon()
    if g.geom_type in ("Polygon", "MultiPolygon"):
        return g
    parts = shapely.get_parts(g)
    parts = parts[np.isin(shapely.get_type_id(parts), (3, 6))]
    return shapely.union_all(parts) if len(parts) else shapely.Polygon()


def _size(g: BaseGeometry) -> float:
    x0, y0, x1, y1 = g.bounds
    return float(math.hypot(x1 - x0, y1 - y0)) if not g.is_empty else 0.0


# ---------------------------------------------------------------------------------------------
# configuration space and shrinking
# ---------------------------------------------------------------------------------------------


def grow_free_space(
    scene: Scene,
    robot_radius: float,
    *,
    keep_out: BaseGeometry | None = None,
    quad_segs: int = PLAN_QUAD_SEGS,
) -> BaseGeometry:
    """Configuration space of a disc robot: the robot-centre positions where it fits.

    Parameters
    ----------
    scene : the environment (its ``free_space``: bounds minus obstacles, world frame).
    robot_radius : robot radius in scene units (>= 0).  0 gives the free space itself.
    keep_out : optional extra areas (world frame) the robot's body must not overlap, e.g. the
        target's swept area A (+) G so that the robot does not park where the target will be.
    quad_segs : segments per quarter circle of the grown obstacles' rounded corners.

    Returns
    -------
    A shapely Polygon or MultiPolygon (one part per connected room), possibly empty: the free
    space eroded by the disc, i.e. the obstacles and walls grown by ``robot_radius``.  Straight
    parts are exact; the rounded corners of the grown obstacles are polygons that
    *circumscribe* the true arcs, so the result is a subset of the exact configuration space
    (conservative), within ``robot_radius * (1/cos(pi/(4 * quad_segs)) - 1)`` of it.  Note that
    ``free_space.buffer(-r)`` would *not* be conservative: shapely puts arc vertices on the exact
    circle, so its chords cut into the grown obstacles.
    """
    r = float(robot_radius)
    if not math.isfinite(r) or r < 0:
        raise ValueError(f"robot_radius must be finite and >= 0, got {robot_radius!r}")
    free: BaseGeometry = scene.free_space
    if keep_out is not None and not keep_out.is_empty:
        free = _polygonal(shapely.difference(free, keep_out))
    if r == 0 or free.is_empty:
        return free
    return _erode(free, r, quad_segs)


def shrink_region(
    region: BaseGeometry, margin: float, *, quad_segs: int = PLAN_QUAD_SEGS
) -> BaseGeometry:
    """The points of ``region`` at distance >= ``margin`` from its complement (paper 6.2).

    Use it to absorb model and sensor uncertainty (and, if you do not use
    :func:`grow_free_space`, the robot's radius): a robot that aims for a point of the shrunk
    region and ends up anywhere within ``margin`` of it is still inside ``region``.

    Parameters
    ----------
    region : shapely geometry of placements (world frame).
    margin : scene units, >= 0.  0 returns ``region`` unchanged.

    Returns
    -------
    A Polygon/MultiPolygon, possibly empty (a region thinner than ``2 * margin`` everywhere
    vanishes; a point or line region vanishes for any positive margin).  This is
    ``region.buffer(-margin)`` computed *conservatively*: the band removed along the boundary is
    exact along edges, and its rounded parts circumscribe the true circles, so the result lies
    inside the exact erosion, within ``margin * (1/cos(pi/(4 * quad_segs)) - 1)`` of it (plain
    ``buffer(-m)`` rounds the concave corners with chords that cut inside the circle, i.e. keeps
    points closer than ``margin`` to the boundary).
    """
    m = float(margin)
    if not math.isfinite(m) or m < 0:
        raise ValueError(f"margin must be finite and >= 0, got {margin!r}")
    if m == 0:
        return region
    region = _polygonal(region)
    if region.is_empty:
        return region
    return _erode(region, m, quad_segs)


def _erode(poly: BaseGeometry, dist: float, quad_segs: int) -> BaseGeometry:
    """Conservative erosion: ``poly`` minus the ``dist``-neighbourhood of its boundary.

    The neighbourhood is the union of the exact flat band along the edges (shapely's buffer
    of the boundary: its straight offsets are exact) and, at each reflex vertex (where the
    erosion's boundary is a circular arc), a regular polygon circumscribing the disc of radius
    ``dist``.  The result is inside the exact erosion, within ``dist * (1/cos(pi/(4 *
    quad_segs)) - 1)`` of it near those arcs and exact elsewhere.
    """
    band = shapely.buffer(poly.boundary, dist, quad_segs=quad_segs)
    rv, _, _ = _reflex_vertices(poly)
    if len(rv):
        discs = shapely.buffer(shapely.points(rv), dist * _outer(quad_segs), quad_segs=quad_segs)
        band = shapely.union_all(np.append(discs, band))
    return _polygonal(shapely.difference(poly, band))


# ---------------------------------------------------------------------------------------------
# shortest paths
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Path:
    """A collision-free polyline in the world frame.

    ``points`` is an (N, 2) float array with N >= 2, from the start to the end point (a robot
    already in the target region gets ``[start, start]``); ``length`` is its Euclidean length in
    scene units.
    """

    points: np.ndarray
    length: float

    @property
    def start(self) -> np.ndarray:
        """First point (x, y)."""
        return self.points[0]

    @property
    def end(self) -> np.ndarray:
        """Last point (x, y): the reached point of the target region."""
        return self.points[-1]

    @property
    def n_segments(self) -> int:
        """Number of straight segments (1 for a one-step motion)."""
        return len(self.points) - 1

    @property
    def one_step(self) -> bool:
        """True for a straight-line (one-step, paper 6.2) motion, including zero motion."""
        return len(self.points) == 2

    def as_linestring(self) -> shapely.LineString:
        """The path as a shapely LineString."""
        return shapely.LineString(self.points)


def _reflex_vertices(space: BaseGeometry) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Reflex vertices of a polygonal domain (convex corners of its complement).

    Returns ``(v, prev, next)`` arrays of shape (k, 2): each reflex vertex and its two ring
    neighbours.  Shortest paths bend only at these vertices.
    """
    vs, ps, ns = [], [], []
    oriented = shapely.orient_polygons(space, exterior_cw=False)  # free side on the left
    for poly in shapely.get_parts(oriented):
        if poly.geom_type != "Polygon" or poly.is_empty:
            continue
        for ring in [poly.exterior, *poly.interiors]:
            c = np.asarray(ring.coords)[:-1, :2]
            if len(c) < 3:
                continue
            prev = np.roll(c, 1, axis=0)
            nxt = np.roll(c, -1, axis=0)
            e1 = c - prev
            e2 = nxt - c
            cr = e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]
            scale = np.hypot(*e1.T) * np.hypot(*e2.T)
            mask = cr < -1e-12 * scale
            vs.append(c[mask])
            ps.append(prev[mask])
            ns.append(nxt[mask])
    if not vs:
        z = np.zeros((0, 2))
        return z, z, z
    return np.concatenate(vs), np.concatenate(ps), np.concatenate(ns)


def _tangent(v: np.ndarray, a: np.ndarray, b: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Whether the line through reflex vertex ``v`` with direction ``d`` supports its corner.

    ``a``, ``b`` are the corner's ring neighbours; True when both lie on the same side of the
    line (or on it).  Arrays of shape (m, 2); NaN neighbours (no corner: the start) give True.
    """
    ea, eb = a - v, b - v
    c1 = d[:, 0] * ea[:, 1] - d[:, 1] * ea[:, 0]
    c2 = d[:, 0] * eb[:, 1] - d[:, 1] * eb[:, 0]
    scale = (d[:, 0] ** 2 + d[:, 1] ** 2) * np.hypot(*ea.T) * np.hypot(*eb.T)
    ok = c1 * c2 >= -1e-9 * scale
    return ok | np.isnan(a[:, 0])


def _visible(cover: BaseGeometry, p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Vectorised segment test: does ``cover`` contain each segment ``p[i] -> q[i]``?"""
    if len(p) == 0:
        return np.zeros(0, dtype=bool)
    lines = shapely.linestrings(np.stack([p, q], axis=1))
    return np.asarray(shapely.covers(cover, lines), dtype=bool)


def _goal_candidates(target: BaseGeometry, nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """End-point candidates for each node: (node index, point) pairs.

    For a node u the exact end point is the point of ``target`` nearest to u among those u sees;
    it is u's nearest target point, a vertex of the target, or the foot of the perpendicular from
    u onto a target edge that faces u.  All three kinds are returned (feet only when inside the
    edge and u is on the edge's outer side).
    """
    k = len(nodes)
    idx, pts = [], []
    # 1. nearest points
    near = shapely.shortest_line(shapely.points(nodes), target)
    npts = shapely.get_coordinates(shapely.get_point(near, 1))
    idx.append(np.arange(k))
    pts.append(npts)
    # 2. vertices, 3. feet of perpendiculars
    verts = np.unique(shapely.get_coordinates(target), axis=0)
    segs_a, segs_b, facing = [], [], []
    oriented = shapely.orient_polygons(target, exterior_cw=False)
    for part in shapely.get_parts(oriented):
        if part.is_empty:
            continue
        if part.geom_type == "Polygon":
            rings, poly = [part.exterior, *part.interiors], True
        elif part.geom_type in ("LineString", "LinearRing"):
            rings, poly = [part], False
        elif part.geom_type == "MultiLineString":
            rings, poly = list(part.geoms), False
        else:
            continue
        for ring in rings:
            c = np.asarray(ring.coords)[:, :2]
            if len(c) < 2:
                continue
            segs_a.append(c[:-1])
            segs_b.append(c[1:])
            facing.append(np.full(len(c) - 1, poly))
    if len(verts):
        ii, vv = np.meshgrid(np.arange(k), np.arange(len(verts)), indexing="ij")
        idx.append(ii.ravel())
        pts.append(verts[vv.ravel()])
    if segs_a:
        a = np.concatenate(segs_a)
        b = np.concatenate(segs_b)
        fac = np.concatenate(facing)
        e = b - a
        ee = np.einsum("ij,ij->i", e, e)
        keep = ee > 0
        a, b, e, ee, fac = a[keep], b[keep], e[keep], ee[keep], fac[keep]
        # (k, s) parameters of the feet
        rel = nodes[:, None, :] - a[None, :, :]
        t = (rel[..., 0] * e[None, :, 0] + rel[..., 1] * e[None, :, 1]) / ee[None, :]
        side = e[None, :, 0] * rel[..., 1] - e[None, :, 1] * rel[..., 0]  # > 0: left (inside)
        ok = (t > 0) & (t < 1) & (~fac[None, :] | (side < 0))
        ni, si = np.nonzero(ok)
        idx.append(ni)
        pts.append(a[si] + t[ni, si, None] * e[si])
    return np.concatenate(idx), np.concatenate(pts)


def shortest_path(
    space: Scene | BaseGeometry,
    start: Any,
    goal_region: BaseGeometry,
    *,
    robot_radius: float = 0.0,
) -> Path | None:
    """Shortest collision-free path from ``start`` to the nearest point of ``goal_region``.

    Parameters
    ----------
    space : a :class:`geometry.Scene` (its configuration space for ``robot_radius`` is built with
        :func:`grow_free_space`), or a configuration space already built (shapely
        Polygon/MultiPolygon of allowed robot-centre positions, world frame).
    start : (x, y) robot centre, world frame.
    goal_region : shapely geometry (world frame) of acceptable end points; only its part inside
        the configuration space counts.
    robot_radius : used only when ``space`` is a Scene.

    Returns
    -------
    The shortest path (:class:`Path`), or ``None`` when the start is not in the configuration
    space, the goal region does not meet it, or no collision-free path connects them.

    Method
    ------
    :class:`PathField` for this space and goal, asked once; a caller with many starts and one
    goal (the oracle replanning every step) keeps the field instead.
    """
    if isinstance(space, BaseGeometry):
        cspace = _polygonal(space)
    else:
        cspace = grow_free_space(space, robot_radius)
    return PathField(cspace, goal_region).path(start)


class VisibilityGraph:
    """The reflex vertices of a configuration space ``cspace`` (shapely Polygon/MultiPolygon
    of robot-centre positions, world frame) and the visibility edges between them: an edge
    where the line supports the corners it touches and the segment lies in the space (within
    ``tol`` = 1e-9 times the space's size).  Built on the first :meth:`edges` call; the same
    for every goal, so the :class:`PathField` of several goals in one space share it."""

    def __init__(self, cspace: BaseGeometry) -> None:
        self.cspace = _polygonal(cspace)
        self.tol = _TOL_REL * max(_size(self.cspace), 1.0)
        self.cover = shapely.buffer(self.cspace, self.tol, join_style="mitre")
        shapely.prepare(self.cover)
        self._edges: tuple | None = None

    def edges(self) -> tuple:
        """``(nodes, prev, next, i, j, length)``: reflex vertices ``(n, 2)`` with their ring
        neighbours, and the edges ``i[k] -- j[k]`` of Euclidean ``length[k]``."""
        if self._edges is None:
            nodes, na, nb = _reflex_vertices(self.cspace)
            iu, ju = np.triu_indices(len(nodes), k=1)
            d = nodes[ju] - nodes[iu]
            ok = _tangent(nodes[iu], na[iu], nb[iu], d) & _tangent(nodes[ju], na[ju], nb[ju], d)
            iu, ju = iu[ok], ju[ok]
            vis = _visible(self.cover, nodes[iu], nodes[ju])
            iu, ju = iu[vis], ju[vis]
            self._edges = (nodes, na, nb, iu, ju, np.hypot(*(nodes[ju] - nodes[iu]).T))
        return self._edges


class PathField:
    """Shortest collision-free paths from any start to one goal region in one configuration
    space: the visibility graph of the space's reflex vertices and each vertex's distance to
    the goal, built once (on the first start that needs them) and asked per start.

    Exact for polygonal domains: a shortest path bends only at reflex vertices of the domain,
    so it runs start -> (visible reflex vertex -> ...) -> goal point.  The graph keeps an edge
    between two reflex vertices when the line supports the corners it touches and the segment
    lies in the domain.  The last leg from a vertex u ends at the point of the goal nearest to
    u among those u sees: u's nearest goal point, a goal vertex, or the foot of a
    perpendicular from u onto a goal edge facing u.  ``H(u)``, u's path length to the goal, is
    one multi-source Dijkstra from those last legs.  A start's path is then the shortest of its
    own last legs and ``|s - v| + H(v)`` over the vertices v it sees (candidates sorted by
    length and checked for visibility lazily, in batches: the first visible one is optimal) --
    the same optimum as a Dijkstra from the start over the graph with the start in it.  When
    the start sees its nearest goal point, the answer is that point reached in a straight
    line: the paper's one-step motion.  Segments may touch the domain boundary (tolerance
    ``1e-9`` times the domain size).

    ``cspace``: shapely Polygon/MultiPolygon of robot-centre positions (world frame);
    ``goal_region``: shapely geometry (world frame) of acceptable end points.
    """

    def __init__(
        self,
        cspace: BaseGeometry | VisibilityGraph,
        goal_region: BaseGeometry,
    ) -> None:
        #: the space's reflex-vertex visibility graph (shared by the fields of one space)
        self.graph = cspace if isinstance(cspace, VisibilityGraph) else VisibilityGraph(cspace)
        self.cspace, self.tol, self.cover = self.graph.cspace, self.graph.tol, self.graph.cover
        empty = self.cspace.is_empty
        self.target = shapely.Polygon() if empty else shapely.intersection(goal_region, self.cover)
        self._graph: tuple | None = None

    def _build(self) -> tuple:
        """``(nodes, prev, next, H, hop, end)``: reflex vertices with their ring neighbours,
        each one's path length to the goal (``inf``: none), the next vertex on that path
        (``-1``: straight to ``end``, its goal point)."""
        if self._graph is not None:
            return self._graph
        from scipy.sparse import coo_matrix  # imported lazily: scipy loads in ~0.5 s
        from scipy.sparse.csgraph import dijkstra

        nodes, na, nb, iu, ju, w = self.graph.edges()
        n = len(nodes)
        # each vertex's last leg: its shortest visible goal candidate
        last = np.full(n, np.inf)
        end = np.full((n, 2), np.nan)
        if n:
            ci, cq = _goal_candidates(self.target, nodes)
            cd = cq - nodes[ci]
            keep = _tangent(nodes[ci], na[ci], nb[ci], cd)
            ci, cq, cd = ci[keep], cq[keep], cd[keep]
            cost = np.hypot(*cd.T)
            order = np.lexsort((cost, ci))  # by vertex, then length
            ci, cq, cost = ci[order], cq[order], cost[order]
            open_ = np.ones(len(ci), dtype=bool)  # candidates of unresolved vertices
            # each candidate's position among its vertex's candidates
            first = np.r_[0, np.flatnonzero(np.diff(ci)) + 1]
            counts = np.diff(np.r_[first, len(ci)])
            rank = np.arange(len(ci)) - np.repeat(first, counts)
            depth = 0
            while open_.any():
                # each unresolved vertex's candidates of ranks depth .. depth + 7, at once
                sel = np.flatnonzero(open_ & (rank >= depth) & (rank < depth + 8))
                if not len(sel):
                    break
                hit = _visible(self.cover, nodes[ci[sel]], cq[sel])
                for k in sel[hit]:  # in order: a vertex's first visible is its shortest
                    u = ci[k]
                    if not np.isfinite(last[u]):
                        last[u], end[u] = cost[k], cq[k]
                open_ &= ~np.isfinite(last[ci])
                depth += 8
        # multi-source Dijkstra: a virtual source n joined to each vertex by its last leg
        src = np.flatnonzero(np.isfinite(last))
        i = np.concatenate([iu, np.full(len(src), n)])
        j = np.concatenate([ju, src])
        ww = np.maximum(np.concatenate([w, last[src]]), 1e-300)  # zero weights would vanish
        g = coo_matrix((ww, (i, j)), shape=(n + 1, n + 1)).tocsr()
        h, pred = dijkstra(g, directed=False, indices=n, return_predecessors=True)
        hop = np.where(pred[:n] == n, -1, pred[:n])
        self._graph = (nodes, na, nb, h[:n], hop, end)
        return self._graph

    def path(self, start: Any) -> Path | None:
        """The shortest path (:class:`Path`) from ``start`` (x, y; world frame) to the goal,
        or ``None`` when the start is not in the space (within the tolerance), the goal does
        not meet it, or no collision-free path connects them."""
        s = np.asarray(start, dtype=float).reshape(-1)[:2]
        if self.cspace.is_empty or not np.all(np.isfinite(s)):
            return None
        sp = shapely.Point(s)
        if not self.cover.covers(sp) or self.target.is_empty:
            return None
        if shapely.distance(sp, self.target) <= self.tol:  # already there
            return Path(np.array([s, s]), 0.0)
        # --- one-step motion (paper 6.2): the start sees its nearest goal point
        q0 = np.asarray(shapely.get_coordinates(shapely.shortest_line(sp, self.target))[1])
        if _visible(self.cover, s[None], q0[None])[0]:
            return Path(np.array([s, q0]), float(np.hypot(*(q0 - s))))
        nodes, na, nb, h, hop, end = self._build()
        # --- the start's own last legs, then its first hops to a vertex
        _, gq = _goal_candidates(self.target, s[None])
        ok = np.isfinite(h) & _tangent(nodes, na, nb, nodes - s)
        vi = np.flatnonzero(ok)
        pts = np.vstack([gq, nodes[vi]])
        cost = np.concatenate([np.hypot(*(gq - s).T), np.hypot(*(nodes[vi] - s).T) + h[vi]])
        order = np.argsort(cost, kind="stable")
        for b0 in range(0, len(order), _BATCH):
            sel = order[b0 : b0 + _BATCH]
            vis = _visible(self.cover, np.broadcast_to(s, (len(sel), 2)), pts[sel])
            if vis.any():
                best = int(sel[int(np.argmax(vis))])
                chain = [s, pts[best]]
                if best >= len(gq):  # through vertex u, then its hops to the goal
                    u = int(vi[best - len(gq)])
                    while hop[u] >= 0:
                        u = int(hop[u])
                        chain.append(nodes[u])
                    chain.append(end[u])
                out = np.vstack(chain)
                return Path(out, float(np.hypot(*np.diff(out, axis=0).T).sum()))
        return None


# ---------------------------------------------------------------------------------------------
# aim
# ---------------------------------------------------------------------------------------------


def _points_of(geom_or_points: Any) -> np.ndarray:
    if isinstance(geom_or_points, BaseGeometry):
        pts = shapely.get_coordinates(shapely.convex_hull(geom_or_points))
    else:
        pts = np.asarray(geom_or_points, dtype=float).reshape(-1, 2)
    if len(pts) == 0 or not np.all(np.isfinite(pts)):
        raise ValueError("best_aim: the set to aim at is empty or not finite")
    return pts


def best_aim(p: Any, target: Any, fov: float, eps_aim: float = 0.0) -> tuple[float, float]:
    """Aim that keeps the whole convex set ``target`` in the field of view with the most margin.

    Parameters
    ----------
    p : (x, y) sensor position, world frame.
    target : (n, 2) points or a shapely geometry; only its convex hull matters (typically the
        convex hull of the target's swept area A (+) G, or of the target itself).
    fov : full field-of-view angle, radians, in (0, 2 pi].
    eps_aim : worst-case aim error, radians (>= 0).

    Returns
    -------
    ``(psi, margin)``: ``psi`` is the aim direction (radians, world frame, in (-pi, pi]), the
    bisector of the angular extent of the set seen from ``p``; ``margin`` (radians) is
    ``(fov/2 - eps_aim) - extent/2``: how far the aim may additionally err with the set still
    inside the field of view.  Negative means no aim keeps the whole set in view under the aim
    uncertainty.  If ``p`` is inside the set the extent is ``2 pi``.  For a 360-degree sensor
    (``fov >= 2 pi``) every aim works: ``psi`` points at the set's centroid and ``margin`` is
    ``pi - extent/2``.
    """
    q = np.asarray(p, dtype=float).reshape(-1)[:2]
    pts = _points_of(target)
    fov = float(fov)
    eps_aim = float(eps_aim)
    hull = shapely.convex_hull(shapely.multipoints(pts))
    c = np.asarray(hull.centroid.coords[0]) if hull.geom_type == "Polygon" else pts.mean(axis=0)
    rel = pts - q
    r = np.hypot(*rel.T)
    scale = max(float(r.max()), 1e-300)
    inside = hull.geom_type == "Polygon" and hull.buffer(1e-12 * scale).contains(shapely.Point(q))
    if inside or np.all(r <= 1e-12 * scale):
        extent = 2.0 * math.pi
        psi = math.atan2(*(c - q)[::-1]) if np.hypot(*(c - q)) > 1e-12 * scale else 0.0
    else:
        far = r > 1e-12 * scale  # a hull vertex at p itself adds no direction
        phi_c = math.atan2(c[1] - q[1], c[0] - q[0])
        delta = np.angle(np.exp(1j * (np.arctan2(rel[far, 1], rel[far, 0]) - phi_c)))
        lo, hi = float(delta.min()), float(delta.max())
        extent = hi - lo
        psi = phi_c + 0.5 * (lo + hi)
        if not far.all():  # p on the hull boundary at a vertex: the set spans a half-plane
            extent = max(extent, math.pi)
        if fov >= 2 * math.pi - 1e-12:
            psi = phi_c
    psi = math.atan2(math.sin(psi), math.cos(psi))
    if fov >= 2 * math.pi - 1e-12:
        return psi, math.pi - extent / 2
    return psi, (fov / 2 - eps_aim) - extent / 2


def best_joint_aim(
    p: Any, sets: Sequence[Any], fov: float, eps_aim: float = 0.0
) -> tuple[float, float]:
    """Aim that keeps every one of several convex ``sets`` in the field of view, with the
    most margin: :func:`best_aim` for their union, not for the convex hull of the union.

    From a placement *between* K_G and K_H the hull of both contains the sensor (extent
    2 pi for :func:`best_aim`), yet a 229-degree sensor sees both if the two sets' angular
    intervals leave a gap wider than 131 degrees (the oracle failed such a Placement-v0
    episode of the ``hard`` level).  Each set's interval is :func:`best_aim`'s; the aim is
    the bisector of the shortest arc covering them all (the circle minus the largest gap
    between them).

    Returns ``(psi, margin)`` as :func:`best_aim` (radians; ``margin < 0``: no aim works).
    """
    fov, eps_aim = float(fov), float(eps_aim)
    ivs = []
    for k in sets:
        psi, margin = best_aim(p, k, fov, eps_aim)
        full = (math.pi if fov >= 2 * math.pi - 1e-12 else fov / 2 - eps_aim) - margin
        if full >= math.pi - 1e-12:  # p inside (or on the boundary at a vertex of) a set
            return best_aim(p, np.vstack([_points_of(k) for k in sets]), fov, eps_aim)
        ivs.append((psi - full, 2.0 * full))
    if not ivs:
        raise ValueError("best_joint_aim: no sets to aim at")
    tau = 2 * math.pi
    # the arcs unrolled twice round the circle, merged in order: every gap of the circle
    # is a gap between two consecutive merged arcs
    arcs = sorted((a % tau + k * tau, w) for a, w in ivs for k in (0, 1))
    merged = [[arcs[0][0], arcs[0][0] + arcs[0][1]]]
    for a, w in arcs[1:]:
        if a <= merged[-1][1]:
            merged[-1][1] = max(merged[-1][1], a + w)
        else:
            merged.append([a, a + w])
    best_gap, best_end = 0.0, 0.0
    for (_, e0), (s1, _) in zip(merged[:-1], merged[1:], strict=True):
        if s1 - e0 > best_gap:
            best_gap, best_end = s1 - e0, e0
    extent = tau - best_gap
    lo = best_end + best_gap  # the covering arc starts where the gap ends
    psi = lo + extent / 2
    psi = math.atan2(math.sin(psi), math.cos(psi))
    if fov >= 2 * math.pi - 1e-12:
        return psi, math.pi - extent / 2
    return psi, (fov / 2 - eps_aim) - extent / 2


# ---------------------------------------------------------------------------------------------
# placement
# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Placement:
    """Result of :func:`choose_placement` (world frame, scene units, radians).

    status : ``"ok"``, ``"no_placement"`` (the region is empty once shrunk and restricted to
        where the robot fits) or ``"unreachable"`` (placements exist but no collision-free path
        leads there from the start, or the start itself is not collision-free).
    point : chosen placement (x, y), or None.
    path : :class:`Path` from the start to ``point`` (None unless ``status == "ok"``).
    length : path length (``inf`` unless ok).
    one_step : True when the path is a single straight segment (the paper's one-step motion).
    reason : a sentence saying what was decided and why.
    region : the shrunk placement region actually searched (possibly empty).
    aim, aim_margin : from :func:`best_aim` at ``point`` when ``aim_at`` was given, else None.
    """

    status: str
    point: np.ndarray | None
    path: Path | None
    length: float
    one_step: bool
    reason: str
    region: BaseGeometry = field(default_factory=shapely.Polygon, repr=False)
    aim: float | None = None
    aim_margin: float | None = None

    @property
    def ok(self) -> bool:
        """``status == "ok"``."""
        return self.status == "ok"


#: Placement fields and visibility graphs kept by :func:`_placement_field` (least recently used
#: dropped first): an oracle replanning every step of 64 sub-environments of a scene pool asks
#: the same ones again and again.
_FIELDS_KEPT = 2048
_FIELDS: OrderedDict = OrderedDict()


def _placement_field(
    scene: Scene,
    region: BaseGeometry,
    robot_radius: float,
    margin: float,
    keep_out: BaseGeometry | None,
) -> tuple[BaseGeometry, BaseGeometry, BaseGeometry, PathField]:
    """``(cspace, shrunk region, target, PathField)`` of :func:`choose_placement`, kept for
    the same scene and region objects and the same radius, margin and keep-out (compared by
    value).  The entry holds the scene and the region, so their ids stay theirs while kept."""
    key = (id(scene), id(region), float(robot_radius), float(margin), keep_out)
    hit = _FIELDS.get(key)
    if hit is not None and hit[0] is scene and hit[1] is region:
        _FIELDS.move_to_end(key)
        return hit[2]
    gkey = (id(scene), None, float(robot_radius), None, keep_out)
    ghit = _FIELDS.get(gkey)
    if ghit is not None and ghit[0] is scene:
        _FIELDS.move_to_end(gkey)
        graph = ghit[2]
    else:
        graph = VisibilityGraph(grow_free_space(scene, robot_radius, keep_out=keep_out))
        _FIELDS[gkey] = (scene, None, graph)
    cspace = graph.cspace
    shrunk = shrink_region(region, margin)
    target = shapely.Polygon()
    if not shrunk.is_empty and not cspace.is_empty:
        target = shapely.intersection(shrunk, cspace)
        if shrunk.geom_type in ("Polygon", "MultiPolygon"):
            target = _polygonal(target)
    out = (cspace, shrunk, target, PathField(graph, target))
    _FIELDS[key] = (scene, region, out)
    if len(_FIELDS) > _FIELDS_KEPT:
        _FIELDS.popitem(last=False)
    return out


def choose_placement(
    scene: Scene,
    region: BaseGeometry,
    start_xy: Any,
    robot_radius: float = 0.0,
    margin: float = 0.0,
    *,
    keep_out: BaseGeometry | None = None,
    aim_at: Any = None,
    fov: float = 2 * math.pi,
    eps_aim: float = 0.0,
) -> Placement:
    """Choose the placement of ``region`` nearest to the robot by path length, and the path.

    Paper 6.2, improved: the region is shrunk by ``margin`` (model, sensor and placement
    uncertainty) and restricted to the disc robot's configuration space (obstacles and walls
    grown by ``robot_radius``; also ``keep_out`` grown by it); the point returned is the one
    reached by the shortest collision-free path (:func:`shortest_path`).  A robot that sees the
    region gets the paper's one-step motion to the nearest point.

    Parameters
    ----------
    scene : the environment.
    region : placements (world frame), e.g. from :func:`geometry.recognizable_region`.
    start_xy : robot centre (x, y), world frame.
    robot_radius : robot radius, scene units (>= 0).
    margin : shrink distance for uncertainty, scene units (>= 0).
    keep_out : optional areas the robot body must never overlap (e.g. the target's swept areas).
    aim_at : optional set to aim at from the placement (see :func:`best_aim`); with ``fov`` and
        ``eps_aim`` (radians) it fills ``Placement.aim`` and ``Placement.aim_margin``.

    Returns
    -------
    A :class:`Placement`.  Never raises because a region is empty or unreachable: those are the
    ``"no_placement"`` and ``"unreachable"`` answers, with a ``reason``.
    """
    s = np.asarray(start_xy, dtype=float).reshape(-1)[:2]

    def fail(status: str, reason: str, reg: BaseGeometry) -> Placement:
        return Placement(status, None, None, math.inf, False, reason, reg)

    if region is None or region.is_empty:
        return fail("no_placement", "the region is empty: no placement exists", shapely.Polygon())
    cspace, shrunk, target, paths = _placement_field(scene, region, robot_radius, margin, keep_out)
    if shrunk.is_empty:
        return fail(
            "no_placement",
            f"the region vanishes when shrunk by margin {margin:g} for uncertainty: "
            "no placement is robust enough",
            shrunk,
        )
    if cspace.is_empty:
        return fail(
            "no_placement",
            f"a robot of radius {robot_radius:g} fits nowhere in the free space",
            shapely.Polygon(),
        )
    if target.is_empty:
        return fail(
            "no_placement",
            f"no point of the (shrunk) region leaves room for a robot of radius "
            f"{robot_radius:g}: no placement exists",
            target,
        )
    if shapely.distance(shapely.Point(s), cspace) > paths.tol:
        return fail(
            "unreachable",
            f"the start ({s[0]:g}, {s[1]:g}) is not collision-free for a robot of radius "
            f"{robot_radius:g}",
            target,
        )
    path = paths.path(s)
    if path is None:
        return fail(
            "unreachable",
            "placements exist, but none is connected to the start by a collision-free path "
            "(they lie in a part of the free space the robot cannot reach)",
            target,
        )
    aim = aim_margin = None
    if aim_at is not None:
        aim, aim_margin = best_aim(path.end, aim_at, fov, eps_aim)
    if path.length == 0:
        reason = "the start is already a placement: no motion needed"
    elif path.one_step:
        reason = (
            f"one-step motion: straight line of length {path.length:.4g} to the nearest "
            "point of the region"
        )
    else:
        reason = (
            f"no one-step motion reaches the region; shortest path around corners with "
            f"{path.n_segments} segments, length {path.length:.4g}"
        )
    return Placement(
        "ok", path.end.copy(), path, path.length, path.one_step, reason, target, aim, aim_margin
    )
