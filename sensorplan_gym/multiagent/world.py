"""The static part of the watch task: one scene under one sensor configuration.

:class:`WatchWorld` holds everything that does not change during an episode:

* the free space, its edges as a :class:`~sensorplan_gym.core.sensor.Segments` set (walls and
  merged obstacles, for the range sensor and the collision sweep);
* the configuration space of robot A: A translates at orientation 0 (the paper's translating
  target, 3.1.2), and its convex hull ``K = CH(A)`` must stay in the free space, so the free
  configurations are ``C = {q : K + q in free}``, built exactly as the free space minus the
  Minkowski sums ``(walls, obstacles) (+) (-K)``; a margin ``m`` keeps A's planned path strictly
  inside it.  Keeping the *hull* free is the paper's standing assumption (3.1.1): no obstacle
  meets CH(A), so "A is completely visible from p" is "conv({p} u A) meets no obstacle";
* a shortest-path planner for A in ``C`` (visibility graph over ``C``'s vertices, Dijkstra);
* the exact visibility predicate :meth:`WatchWorld.sees` (complete or partial model, field
  of view and range).

Frames and units: world frame, scene units, angles in radians (counter-clockwise).
"""

from __future__ import annotations

import math
from collections import OrderedDict
from dataclasses import dataclass

import numpy as np
import shapely
from shapely.geometry import Point

from geometry import Scene

from ..core.sensor import Segments
from ..core.world import boundary_segments, segment_normals
from . import kernels as _wk

__all__ = ["VisGraph", "WatchConfig", "WatchWorld", "get_watch_world"]

MODELS = ("complete", "partial")


@dataclass(frozen=True)
class WatchConfig:
    """Sensor configuration of the watchers.  ``fov`` in radians (``None``: the scene's),
    ``max_range`` in scene units (``None``: the scene's, ``math.inf``: unlimited)."""

    model: str = "complete"
    fov: float | None = None
    max_range: float | None = None

    def validate(self) -> WatchConfig:
        if self.model not in MODELS:
            raise ValueError(f"model must be one of {MODELS}, got {self.model!r}")
        if self.fov is not None and not (
            isinstance(self.fov, (int, float)) and 0 < self.fov <= 2 * math.pi + 1e-12
        ):
            raise ValueError(f"fov_deg must be in (0, 360], got {math.degrees(self.fov)!r}")
        mr = self.max_range
        if mr is not None and not (isinstance(mr, (int, float)) and mr > 0 and not math.isnan(mr)):
            raise ValueError(f"max_range must be a positive number or None, got {mr!r}")
        return self


def _triangles(g: shapely.Geometry) -> np.ndarray:
    tris = shapely.constrained_delaunay_triangles(g)
    return np.array([np.asarray(t.exterior.coords)[:3] for t in shapely.get_parts(tris)])


def _sum_convex(g: shapely.Geometry, K: np.ndarray) -> shapely.Geometry:
    """Exact Minkowski sum of a polygon (triangulated) and a convex polygon ``K`` (vertices):
    the union of the convex hulls of every triangle's vertices plus every vertex of ``K``."""
    tri = _triangles(g)
    if not len(tri):
        return shapely.Polygon()
    pts = (tri[:, :, None, :] + K[None, None, :, :]).reshape(len(tri), -1, 2)
    return shapely.union_all(shapely.convex_hull(shapely.multipoints(pts)))


class WatchWorld:
    """One scene under one :class:`WatchConfig` (see the module docstring).  Immutable."""

    def __init__(self, scene: Scene, cfg: WatchConfig) -> None:
        cfg.validate()
        self.scene = scene
        self.cfg = cfg
        self.model = cfg.model
        sensor = scene.sensor
        self.fov = float(sensor.fov if cfg.fov is None else cfg.fov)
        mr = sensor.max_range if cfg.max_range is None else cfg.max_range
        self.max_range = math.inf if mr is None else float(mr)
        self.full_fov = self.fov >= 2 * math.pi - 1e-12
        self.lo = scene.bounds.min(axis=0).astype(np.float64)
        self.hi = scene.bounds.max(axis=0).astype(np.float64)
        self.diameter = float(scene.diameter)
        self.reach = min(self.max_range, self.diameter)
        self.skin = 1e-7 * self.diameter

        self.free_space = scene.free_space
        shapely.prepare(self.free_space)
        self.segs = boundary_segments(self.free_space)
        self.seg_set = Segments(self.segs, segment_normals(self.segs))
        self.goal_geom = scene.goal_geom
        self.failure_geom = scene.failure_geom
        self.target = np.asarray(scene.target, dtype=np.float64)  # A at q = 0, orientation 0
        hull = shapely.MultiPoint(self.target).convex_hull
        self.hull = np.asarray(hull.exterior.coords)[:-1]  # K = CH(A), vertices
        self.target_radius = float(scene.target_radius)
        #: A's swept areas A (+) G and A (+) H (where A's body can be once it has settled)
        self.swept = {
            "G": _sum_convex_or_point(self.goal_geom, self.target),
            "H": _sum_convex_or_point(self.failure_geom, self.target),
        }
        self._build_cspace()
        self._pdom = None

    # ---- pickling: shapely's "prepared" flag does not survive -----------------------------
    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        for g in (self.free_space, self.cspace, self.cspace_m):
            shapely.prepare(g)

    # ---- robot A's configuration space ------------------------------------------------------
    def _build_cspace(self) -> None:
        scene = self.scene
        negK = -self.hull[::-1]
        span = self.hi - self.lo
        box = shapely.box(*(self.lo - span), *(self.hi + span))
        outside = shapely.difference(box, scene.bounds_geom)
        forbidden = shapely.union(_sum_convex(outside, negK), _sum_convex_all(scene, negK))
        cs = shapely.difference(scene.bounds_geom, forbidden)
        #: exact free configurations of A's reference point (orientation 0)
        self.cspace = cs
        self.cspace_segs = Segments(boundary_segments(cs))
        #: margin kept between A's planned path and the C-space boundary
        self.margin = 0.01 * self.diameter
        self.cspace_m = cs.buffer(-self.margin, quad_segs=8, join_style="mitre")
        for geom in (self.cspace, self.cspace_m):
            shapely.prepare(geom)
        self._graphs: dict[str, VisGraph] = {}

    def clearance(self, x: float, y: float) -> float:
        """Distance from configuration ``(x, y)`` to the boundary of A's exact C-space (how far
        A may drift from there without touching a wall or obstacle); 0 outside it."""
        if not shapely.contains_xy(self.cspace, x, y):
            return 0.0
        return self.cspace_segs.clearance(x, y)

    def clearances(self, x: np.ndarray, y: np.ndarray) -> np.ndarray:
        """:meth:`clearance` of the points ``(x[k], y[k])`` at once (the same numbers)."""
        from ..core.segments import point_segment_distance

        x = np.ascontiguousarray(x, dtype=np.float64)
        y = np.ascontiguousarray(y, dtype=np.float64)
        inside = shapely.contains_xy(self.cspace, x, y)
        out = np.zeros(len(x))
        if inside.any():
            out[inside] = point_segment_distance(x[inside], y[inside], self.cspace_segs)
        return out

    def shortest_path(self, a, b, *, avoid: str | None = None) -> np.ndarray | None:
        """Shortest path of A's reference point from ``a`` to ``b`` inside the margin-shrunk
        C-space -- with ``avoid="G"`` (``"H"``) also outside G (H) grown by the margin, so that
        A does not pass through the region it must not end in -- as ``(N, 2)`` way points, or
        ``None`` when there is none."""
        key = avoid or "main"
        g = self._graphs.get(key)
        if g is None:
            dom = self.cspace_m
            if avoid is not None:
                region = self.goal_geom if avoid == "G" else self.failure_geom
                dom = shapely.difference(dom, region.buffer(self.margin))
            g = self._graphs[key] = VisGraph(dom)
        return g.shortest_path(a, b)

    def sample_free_config(self, rng: np.random.Generator, tries: int = 10_000) -> np.ndarray:
        """A uniform point of the margin-shrunk C-space (rejection from the bounding box)."""
        for _ in range(tries):
            x = rng.uniform(self.lo[0], self.hi[0])
            y = rng.uniform(self.lo[1], self.hi[1])
            if shapely.contains_xy(self.cspace_m, x, y):
                return np.array([x, y])
        raise RuntimeError(f"scene {self.scene.name!r}: no free configuration for robot A found")

    def sample_end(self, which: str, rng: np.random.Generator) -> np.ndarray:
        """A uniform end point of A's reference point in G (``which="G"``) or H, inside the
        margin-shrunk C-space when that leaves any of it (else anywhere in the region)."""
        g = self.goal_geom if which == "G" else self.failure_geom
        if g.geom_type == "Point":
            return np.array([g.x, g.y])
        cache = self.__dict__.setdefault("_end_src", {})
        src = cache.get(which)
        if src is None:  # the part of the region inside the margin-shrunk C-space (once)
            inner = shapely.intersection(g, self.cspace_m)
            src = cache[which] = inner if inner.area > 1e-9 * g.area else g
            shapely.prepare(src)
        x0, y0, x1, y1 = src.bounds
        for _ in range(10_000):
            x, y = rng.uniform(x0, x1), rng.uniform(y0, y1)
            if shapely.contains_xy(src, x, y):
                return np.array([x, y])
        c = src.representative_point()
        return np.array([c.x, c.y])

    # ---- exact visibility of A --------------------------------------------------------------
    def target_at(self, q) -> np.ndarray:
        """A's vertices with its reference point at ``q`` (orientation 0)."""
        return self.target + np.asarray(q, dtype=np.float64)

    def sees(self, pose, q) -> bool:
        """Whether a watcher at ``pose = (x, y, psi)`` sees robot A with reference point ``q``
        under the configured model, exactly:

        * ``complete``: every point of A is visible -- ``conv({p} u A)`` lies in the free
          space (no obstacle meets CH(A), so this is exact, paper 3.1.1) -- and all of A is
          inside the field of view (A's angular interval from ``p`` within ``psi +- fov/2``)
          and within ``max_range`` (its farthest vertex);
        * ``partial``: some point of A is visible and inside the field of view and range --
          ``V(p) n A n wedge`` is non-empty and its nearest point is within ``max_range``,
          with ``V(p)`` the exact visibility polygon of ``p`` (:mod:`geometry._vis`).

        A watcher inside A sees nothing."""
        x, y, psi = float(pose[0]), float(pose[1]), float(pose[2])
        P = self.target_at(q)
        poly = shapely.Polygon(P)
        if shapely.intersects_xy(poly, x, y):
            return False
        if self.model == "complete":
            d = P - (x, y)
            if math.isfinite(self.max_range) and float(np.hypot(d[:, 0], d[:, 1]).max()) > (
                self.max_range
            ):
                return False
            if not self.full_fov and not self._in_fov(x, y, psi, P):
                return False
            fan = shapely.convex_hull(shapely.MultiPoint(np.vstack([P, [[x, y]]])))
            return bool(shapely.covers(self.free_space, fan))
        vis = self.visibility_polygon(x, y)
        part = shapely.intersection(vis, poly)
        if not self.full_fov:
            part = shapely.intersection(part, self._wedge(x, y, psi))
        if part.is_empty or not part.area > 0.0:  # a touch at a point or along an edge is no view
            return False
        if math.isfinite(self.max_range):
            return bool(shapely.distance(Point(x, y), part) <= self.max_range)
        return True

    def _in_fov(self, x: float, y: float, psi: float, P: np.ndarray) -> bool:
        c = P.mean(axis=0)
        base = math.atan2(c[1] - y, c[0] - x)
        rel = np.arctan2(P[:, 1] - y, P[:, 0] - x) - base
        rel = (rel + math.pi) % (2 * math.pi) - math.pi
        off = (base - psi + math.pi) % (2 * math.pi) - math.pi
        half = 0.5 * self.fov
        return bool(off + rel.min() >= -half and off + rel.max() <= half)

    def _wedge(self, x: float, y: float, psi: float) -> shapely.Polygon:
        """The field of view from ``(x, y)`` as a polygon, exact within the room: its far
        boundary (a polyline with vertices at radius ``4 x diameter``, at most 45 degrees
        apart) stays farther than the room's diameter."""
        R = 4.0 * self.diameter
        k = max(2, int(math.ceil(self.fov / (math.pi / 4))) + 1)
        ang = psi + np.linspace(-0.5 * self.fov, 0.5 * self.fov, k)
        arc = np.stack([x + R * np.cos(ang), y + R * np.sin(ang)], axis=1)
        return shapely.Polygon(np.vstack([[[x, y]], arc]))

    def visibility_polygon(self, x: float, y: float) -> shapely.Geometry:
        """The exact visibility polygon ``V(p)`` of a point of the free space."""
        from geometry._vis import domain_from_geometry, visibility_polygon

        if self._pdom is None:
            self._pdom = domain_from_geometry(self.free_space)
        return visibility_polygon(self._pdom, np.array([x, y], dtype=np.float64))

    # ---- oracle support ---------------------------------------------------------------------
    def in_fov_of_hulls(self, x: float, y: float, psi: float, hulls: list[np.ndarray]) -> bool:
        """All the given point sets inside the field of view from ``(x, y)`` aimed at ``psi``
        (each set's angular interval as seen from the point)."""
        return all(self._in_fov(x, y, psi, h) for h in hulls)


class VisGraph:
    """Shortest paths inside a polygonal domain: the visibility graph of its boundary vertices
    (built once, ``shapely.covers`` on every vertex pair, vectorised), joined per query to the
    two end points, and Dijkstra (scipy).  Paths are polylines through domain vertices; they
    touch the domain's boundary there (callers shrink the domain by a margin first)."""

    def __init__(self, domain: shapely.Geometry) -> None:
        self.domain = domain
        shapely.prepare(domain)
        nodes = np.unique(shapely.get_coordinates(shapely.boundary(domain)), axis=0)
        i, j = np.triu_indices(len(nodes), 1)
        ok = shapely.covers(domain, shapely.linestrings(np.stack([nodes[i], nodes[j]], axis=1)))
        self.nodes = nodes
        self.ii, self.jj = i[ok], j[ok]
        self.w = np.hypot(*(nodes[self.ii] - nodes[self.jj]).T)
        self._edges = _vertex_edges(domain, nodes)

    def _visible(self, ends: np.ndarray) -> np.ndarray:
        """``(2, n)`` bool: the segment from ``ends[k]`` to every node lies in the domain
        (``shapely.covers``; with numba decided exactly by :func:`.kernels.visible_from`,
        shapely answering only the cases it leaves open)."""
        nodes, n = self.nodes, len(self.nodes)
        if _wk.visible_from is None or self._edges is None:
            segs = shapely.linestrings(
                np.stack([np.repeat(ends, n, axis=0), np.tile(nodes, (2, 1))], axis=1)
            )
            return shapely.covers(self.domain, segs).reshape(2, n)
        E, pin, pout, amb = self._edges
        out = np.empty((2, n), dtype=np.int64)
        for k in range(2):
            _wk.visible_from(float(ends[k, 0]), float(ends[k, 1]), nodes, E, pin, pout, amb,
                             out[k])  # fmt: skip
        vis = out == 1
        ku, nu = np.nonzero(out == _wk.UNSURE)
        if len(ku):
            segs = shapely.linestrings(np.stack([ends[ku], nodes[nu]], axis=1))
            vis[ku, nu] = shapely.covers(self.domain, segs)
        return vis

    def __setstate__(self, st: dict) -> None:
        self.__dict__.update(st)
        shapely.prepare(self.domain)

    def contains(self, x: float, y: float) -> bool:
        return bool(shapely.contains_xy(self.domain, x, y))

    def shortest_path(self, a, b) -> np.ndarray | None:
        """Way points ``(N, 2)`` of a shortest path from ``a`` to ``b`` within the domain
        (``None`` if there is none, e.g. an end point outside it)."""
        from scipy.sparse.csgraph import dijkstra

        dom, nodes = self.domain, self.nodes
        a = np.asarray(a, dtype=np.float64)
        b = np.asarray(b, dtype=np.float64)
        if shapely.covers(dom, shapely.linestrings([a, b])):
            return np.stack([a, b])
        n = len(nodes)
        ends = np.stack([a, b])
        vis = self._visible(ends)
        rows, cols, ws = [self.ii, self.jj], [self.jj, self.ii], [self.w, self.w]
        for k in range(2):
            idx = np.nonzero(vis[k])[0]
            d = np.hypot(*(nodes[idx] - ends[k]).T)
            rows += [np.full(len(idx), n + k), idx]
            cols += [idx, np.full(len(idx), n + k)]
            ws += [d, d]
        M = _canonical_csr(np.concatenate(rows), np.concatenate(cols), np.concatenate(ws), n + 2)
        dist, pred = dijkstra(M, indices=n, return_predecessors=True)
        if not np.isfinite(dist[n + 1]):
            return None
        path = [n + 1]
        while path[-1] != n:
            path.append(int(pred[path[-1]]))
        return np.concatenate([nodes, ends])[path[::-1]]


def _canonical_csr(rows: np.ndarray, cols: np.ndarray, data: np.ndarray, n: int):
    """The ``n x n`` CSR matrix of the (distinct) entries ``(rows, cols, data)`` in canonical
    form -- column indices sorted within each row --, the matrix
    ``coo_matrix(...).tocsr()`` gives, built without its checks."""
    from scipy.sparse import csr_matrix

    order = np.lexsort((cols, rows))
    indptr = np.zeros(n + 1, dtype=np.int32)
    np.cumsum(np.bincount(rows, minlength=n), out=indptr[1:])
    M = csr_matrix((data[order], cols[order].astype(np.int32), indptr), shape=(n, n))
    M.has_sorted_indices = True
    return M


def _vertex_edges(domain: shapely.Geometry, nodes: np.ndarray):
    """The domain's boundary edges ``(4, M)`` (start x, y, end x, y; exteriors
    counter-clockwise, holes clockwise: the interior on every edge's left) and, per node, its
    incoming and outgoing edge and whether it is not a simple vertex (it occurs more than
    once on the boundary); ``None`` when a node is not found on the oriented boundary."""
    rings = []
    for poly in shapely.get_parts(shapely.orient_polygons(domain)):
        if poly.is_empty:
            continue
        rings.append(np.asarray(poly.exterior.coords)[:-1])
        rings.extend(np.asarray(r.coords)[:-1] for r in poly.interiors)
    index = {(float(x), float(y)): k for k, (x, y) in enumerate(nodes)}
    n = len(nodes)
    pin = np.full(n, -1, dtype=np.int64)
    pout = np.full(n, -1, dtype=np.int64)
    amb = np.zeros(n, dtype=np.bool_)
    E = []
    for ring in rings:
        m0 = len(E)
        L = len(ring)
        for j in range(L):
            p, q = ring[j], ring[(j + 1) % L]
            E.append((p[0], p[1], q[0], q[1]))
            kp = index.get((float(p[0]), float(p[1])))
            kq = index.get((float(q[0]), float(q[1])))
            if kp is None or kq is None:
                return None
            if pout[kp] >= 0:
                amb[kp] = True
            pout[kp] = m0 + j
            pin[kq] = m0 + j
    if (pin < 0).any() or (pout < 0).any():
        return None
    return np.ascontiguousarray(np.array(E, dtype=np.float64).T), pin, pout, amb


def _sum_convex_all(scene: Scene, negK: np.ndarray) -> shapely.Geometry:
    parts = [_sum_convex(o, negK) for o in scene.obstacle_geoms]
    return shapely.union_all(parts) if parts else shapely.Polygon()


def _sum_convex_or_point(g: shapely.Geometry, A: np.ndarray) -> shapely.Geometry:
    """A (+) g for a polygon or a point ``g`` (A need not be convex: A is triangulated)."""
    if g.geom_type == "Point":
        return shapely.Polygon(A + (g.x, g.y))
    tri_a = _triangles(shapely.Polygon(A))
    tri_g = _triangles(g)
    pts = (tri_a[:, None, :, None, :] + tri_g[None, :, None, :, :]).reshape(-1, 9, 2)
    return shapely.union_all(shapely.convex_hull(shapely.multipoints(pts)))


_CACHE: OrderedDict[tuple, WatchWorld] = OrderedDict()


def get_watch_world(scene: Scene, cfg: WatchConfig) -> WatchWorld:
    """The cached :class:`WatchWorld` of ``(scene, cfg)`` (LRU of 16)."""
    import json

    key = (json.dumps(scene.to_dict(), sort_keys=True), cfg)
    w = _CACHE.get(key)
    if w is None:
        w = _CACHE[key] = WatchWorld(scene, cfg)
        if len(_CACHE) > 16:
            _CACHE.popitem(last=False)
    else:
        _CACHE.move_to_end(key)
    return w
