"""Swept shadows in the partial-visibility model (paper 3.2.2-3.2.3 and 5.2).

A placement p is *blinded* by configuration q when no wanted point of the
target A_q is visible from p.  For a target translating (fixed orientation)
through a region G the placements to avoid are the union of the shadows S(q)
over q in G.  For a target that is star-shaped with respect to its reference
point it suffices to let q run along the boundary of G (docs/DESIGN.md); the
overlap-reduced targets of paper 5.2 are handled the same way (checked on
interior configurations in the tests).

Along one edge q(t) = q0 + t D of G (0 <= t <= 1) the shadow S(t) changes
continuously.  Every edge of S(t) lies on a line through two *anchor points*:
environment vertices (fixed), target vertices (moving with q), or the ends of
the target's wanted pieces (moving along a fixed line, 5.2).  A point of the
union of the S(t) that is in no sampled shadow lies on the boundary of some
S(t), on an edge whose line moves, so the union is

    the exact stationary shadows at sample times t_k  (paper 3.2.1)
    plus the area swept by the moving shadow edges between the samples.

Each moving edge found at a sample is traced toward the neighbouring samples
in closed form: its ends are the intersections of its line with its
neighbours' lines at any t, and they run on lines or conics (the paper's free
shadow vertices).  A trace is kept while an exact point test (below) on probes
just inside the shadow along the edge confirms it; the end of its life (a
critical event) is located by bisection.  Edges whose sweep lies inside the two
neighbouring shadows (they rotate into their own shadow) are not traced.  The
traces are polylines fine enough that every chord lies within ``tol`` of its
curve (the sagitta at the parameter midpoint, checked on a doubling grid).

Exact point test: the obstacles do not meet K = CH(A (+) G) (the paper's
assumption, checked by :class:`Scene`), so a ray that enters K reaches
everything in K behind its entry point.  The directions in which p sees into
K (its *windows*) do not depend on q; p sees a wanted piece of A_q iff some
window overlaps a direction in which, ignoring the obstacles, that piece is
the first thing hit on A_q.

Samples are added where a moving line carries shadow edges at both ends of an
interval but the traces leave part of it uncovered (an edge configuration born
and gone in between), and where the shadow of the eroded target (the part of A
common to the whole interval, whose shadow contains every S(t) there) has a
component that neither neighbouring shadow meets (a shadow born and gone in
between), and once between consecutive *collinearity events* (:meth:`Sweeper._events`:
a moving anchor crossing a line through two obstacle corners or an obstacle edge, a line
through two target vertices crossing a corner), where a shadow can be born as a segment
that continues a known shadow edge (issue 26.3, 26.4) -- next to the events whose lines
carry a shadow edge at some sample (:meth:`Sweeper._live_mids`) --, and just after a traced edge was
cut short by the death of a neighbour while its line still bounds a shadow (the edge goes
on with another neighbour, a configuration that may live between two samples only:
:meth:`Sweeper._continuation_gap`).  What this does not prove is listed in
docs/DESIGN.md.
"""

from __future__ import annotations

import contextlib
import math
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

import numpy as np
import shapely
from shapely import affinity

from . import _libm
from . import visindex as _visindex
from ._common import polygonal
from ._shapes import areal, snapped, union_all
from ._shapes import cross as _cross
from ._vis import TAU, Domain, RayEscapeError, gaps_many
from .weak import ENV as _ENV
from .weak import WANTED as _WANTED
from .weak import corners_seeing, weak_visibility, weak_visibility_many

#: The union of the pieces is snap-rounded onto a grid of ``2**-GRID_BITS`` of the scene's
#: size (about 1e-12): see :func:`swept_shadows`.
GRID_BITS = 40

#: The stationary shadows (free space minus target minus weak visibility region) are
#: computed by snap-rounding onto a grid ``2**-SHADOW_BITS`` finer than the union's:
#: see :meth:`Sweeper.shadow`.
SHADOW_BITS = 8

#: A traced edge that dies between samples while still this long relative to its length
#: at its sample was cut short by a neighbour's change: see :meth:`Sweeper._cut_short`.
CUT_REL = 1e-3

#: The bisection of a traced edge's death time tests this many levels of its binary
#: tree of midpoints in one batch: see :meth:`Sweeper._bisect`.
BISECT_LEVELS = 3

#: The sampling rules of the sweeps (:attr:`Sweeper.lazy_samples`) when the caller does not
#: choose: True, the lazy ones; False, the previous, denser ones (the reference the tests and
#: benchmarks compare with; :mod:`geometry.certify` always takes those).
LAZY_SAMPLES = True

__all__ = ["QueryTimeout", "Sweeper", "star_center", "swept_shadows"]


class QueryTimeout(TimeoutError):
    """A swept query ran past its ``timeout``.  The message names the query, the
    limit and what was left (edges of the region's boundary not yet swept)."""


class _Expired(Exception):
    """Internal: the sweeper's deadline passed (turned into :class:`QueryTimeout`)."""


def _meet(a0: np.ndarray, a1: np.ndarray, b0: np.ndarray, b1: np.ndarray) -> np.ndarray:
    """Intersection of the lines (a0, a1) and (b0, b1), row by row (NaN if parallel)."""
    da, db = a1 - a0, b1 - b0
    den = _cross(da, db)
    with np.errstate(divide="ignore", invalid="ignore"):
        s = _cross(b0 - a0, db) / den
    return a0 + da * s[..., None]


@dataclass
class _Cover:
    """What the traces of one edge of the region covered (:meth:`Sweeper._sweep_intervals`):
    per line key the intervals covered (``cover``) and reached by traces (``traced``),
    the confirmed ``(t, key)`` pairs and the cut traces already sampled after (``probed``)."""

    cover: dict[tuple, list] = field(default_factory=dict)
    confirmed: set[tuple] = field(default_factory=set)
    traced: dict[tuple, list] = field(default_factory=dict)
    probed: list[tuple] = field(default_factory=list)


class PhaseClock:
    """Wall seconds and new samples per phase of a sweep (``with clock("tracing"): ...``):
    ``seconds`` and ``samples`` map a phase name to its totals (a sample: an exact stationary
    shadow, counted by the sweeper's ``_frames``; the birth checks' eroded targets are not
    samples).  ``swept_shadows`` returns them in its stats (``stats["seconds"]``,
    ``stats["phase_samples"]``); ``benchmarks.swept_phases`` tabulates them."""

    def __init__(self, count: Callable[[], int]) -> None:
        self.seconds: dict[str, float] = {}
        self.samples: dict[str, int] = {}
        self._count = count

    @contextlib.contextmanager
    def __call__(self, phase: str) -> Iterator[None]:
        n0, t0 = self._count(), time.perf_counter()
        try:
            yield
        finally:
            self.seconds[phase] = self.seconds.get(phase, 0.0) + time.perf_counter() - t0
            self.samples[phase] = self.samples.get(phase, 0) + self._count() - n0


@dataclass(eq=False)
class _Run:
    """One segment ``q0 -> q1`` of a sweep (:meth:`Sweeper.along_many`): its sample times
    and their frames (time -> (shadow, edges), shared through the sweeper's cache by the
    segments meeting at a vertex of G), its events (:meth:`Sweeper._events`), the events
    already found live and its counters."""

    sw: Sweeper
    q0: np.ndarray
    q1: np.ndarray
    frames: dict[float, tuple] = field(default_factory=dict)
    looked: set[int] = field(default_factory=set)
    stats: dict[str, int] = field(default_factory=lambda: {"samples": 0, "edges": 0, "refined": 0})
    ev_t: np.ndarray = field(default_factory=lambda: np.zeros(0))
    ev_ids: list = field(default_factory=list)

    def __post_init__(self) -> None:
        self.dq = self.q1 - self.q0

    def frame(self, t: float) -> tuple:
        """(shadow, edges) at time ``t`` (:meth:`Sweeper.shadow`, :meth:`Sweeper._edges`),
        computed once per configuration."""
        got = self.frames.get(t)
        if got is None:
            sw = self.sw
            q = self.q1 if t == 1.0 else self.q0 + t * self.dq
            key = (float(q[0]), float(q[1]))
            if key not in sw._frames:
                shadow, table, tid = sw.shadow(q)
                sw._frames[key] = (shadow, sw._edges(shadow, table, tid))
                self.stats["samples"] += 1
            got = self.frames[t] = sw._frames[key]
        return got


@dataclass
class Sweeper:
    """Swept shadows of one target (fixed orientation) moving along segments.

    Parameters
    ----------
    env : the free space as a visibility domain (no target).
    free : the free space as a shapely geometry.
    ring0 : (m, 2) target outline at reference point (0, 0), counter-clockwise.
    hull : (k, 2) vertices of K = CH(A (+) G), counter-clockwise; obstacle-free.
    strips : optional, per target edge i, a shapely geometry U_i such that the
        part of edge i of A_q inside U_i is *not* wanted (paper 5.2:
        U_i = union of e_j (+) H over the edges j parallel to i with the same
        outward direction).  ``None``: the whole outline is wanted.
    eps_aim : aim uncertainty (radians) of the stationary shadows.
    tol : polyline tolerance for the traced conic arcs (scene units).
    """

    env: Domain
    free: shapely.Geometry
    ring0: np.ndarray
    hull: np.ndarray
    strips: list[shapely.Geometry] | None
    eps_aim: float
    tol: float
    n_samples: int = 1
    max_depth: int = 6
    bisect_steps: int = 14
    probes: int = 4
    #: the birth check bounds an interval without an eroded target by the eroded targets of
    #: its pieces after at most this many halvings (``2**max_split`` weak visibility regions
    #: instead of a sample and two checks per level; lazy rule only)
    max_split: int = 2
    #: sample only next to the collinearity events whose wedge lines carry a shadow edge
    #: (:meth:`_live_mids`), and bisect for births only where an eroded target exists within
    #: the depth limit (:meth:`_core_within_depth`); False: next to every event and on every
    #: empty eroded target (the previous rules, the reference the tests compare with)
    lazy_samples: bool = True
    #: ``time.monotonic()`` value after which the sweep stops (None: no limit).
    deadline: float | None = None
    _cut_segs: np.ndarray = field(init=False, repr=False)
    _cut_edge: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        self.ring0 = np.asarray(self.ring0, dtype=float)
        self.hull = np.asarray(self.hull, dtype=float)
        self.n_fixed = len(self.env.vert)
        self.m = len(self.ring0)
        self.edge0 = np.roll(self.ring0, -1, axis=0) - self.ring0
        #: a convex target: A_qa n A_qb is then common to every A_q in between (no edge
        #: sweeps over it, :meth:`_eroded_core_of`)
        turn = _cross(self.edge0, np.roll(self.edge0, -1, axis=0))
        self._convex = bool((turn >= 0).all() or (turn <= 0).all())
        segs, owner = [np.zeros((0, 4))], [np.zeros(0, dtype=int)]
        if self.strips is not None:
            for i, u in enumerate(self.strips):
                if u is None or u.is_empty:
                    continue
                for ring in _rings(u):
                    c = np.asarray(ring.coords)[:, :2]
                    segs.append(np.hstack([c[:-1], c[1:]]))
                    owner.append(np.full(len(c) - 1, i))
                shapely.prepare(u)
        self._frames: dict[tuple[float, float], tuple] = {}
        self._cut_segs = np.vstack(segs)
        self._cut_edge = np.concatenate(owner)
        shapely.prepare(self.free)
        self._hull_poly = shapely.Polygon(self.hull)
        shapely.prepare(self._hull_poly)
        self.h = 1e-7 * self.env.scale
        self.tol_lab = 1e-8 * self.env.scale
        #: snap-rounding grid of the final union (scene units, a power of two)
        self.grid = snap_grid(self.env.scale)
        #: snap-rounding grid of the stationary shadows (scene units, a power of two)
        self.shadow_grid = math.ldexp(self.grid, -SHADOW_BITS)
        #: the ``grazing`` anchors of the stationary shadows (None: all; same answer)
        self._grazing: np.ndarray | None = None
        #: per configuration (x, y) of a stationary shadow: the placements it does not hold
        #: (target and weak visibility region, snap-rounded): see :func:`_union_pieces`
        self._seen: dict[tuple[float, float], shapely.Geometry] = {}
        #: weak visibility regions computed ahead in a batch (:meth:`_prefetch`), with the
        #: ``grazing`` mask they were computed with
        self._weak_pre: dict[tuple[float, float], tuple] = {}
        self._eroded_pre: dict[tuple, shapely.Geometry] = {}
        #: :meth:`outline` per configuration (x, y), with strips
        self._outlines: dict[tuple[float, float], tuple] = {}
        #: where the sweep's time went (:class:`PhaseClock`)
        self.clock = PhaseClock(lambda: len(self._frames))

    # ------------------------------------------------------------------ anchors
    def pos(self, ids: np.ndarray, q: np.ndarray) -> np.ndarray:
        """Positions of anchor points ``ids`` (n,) at reference points ``q`` (n, 2)."""
        ids = np.asarray(ids)
        out = np.empty((len(ids), 2))
        n, m = self.n_fixed, self.m
        f = ids < n
        out[f] = self.env.vert[ids[f]]
        v = (ids >= n) & (ids < n + m)
        out[v] = self.ring0[ids[v] - n] + q[v]
        c = ids >= n + m
        if c.any():
            k = ids[c] - n - m
            i = self._cut_edge[k]
            s = self._cut_segs[k]
            c0, c1 = s[:, :2], s[:, 2:]
            out[c] = _meet(c0, c1, self.ring0[i] + q[c], self.ring0[i] + q[c] + self.edge0[i])
        return out

    def outline(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Target at ``q``: counter-clockwise ring with the ends of the wanted
        pieces inserted, wanted flag per edge, anchor id per ring vertex."""
        n, m = self.n_fixed, self.m
        ring = self.ring0 + q
        if self.strips is None:
            return ring, np.ones(m, dtype=bool), n + np.arange(m)
        key = (float(q[0]), float(q[1]))
        got = self._outlines.get(key)
        if got is None:  # once per configuration (the batch and the shadow both ask)
            got = self._outlines[key] = self._cut_outline(ring)
        return got

    def _cut_outline(self, ring: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:meth:`outline` of the target ``ring`` (counter-clockwise, placed) cut by the
        strips."""
        n, m = self.n_fixed, self.m
        pts, wanted, ids = [], [], []
        for i in range(m):
            a, e = ring[i], self.edge0[i]
            ks = np.flatnonzero(self._cut_edge == i)
            params = [(0.0, n + i)]
            if len(ks):
                s = self._cut_segs[ks]
                c0, d = s[:, :2], s[:, 2:] - s[:, :2]
                den = _cross(e[None, :], d)
                with np.errstate(divide="ignore", invalid="ignore"):
                    u = _cross(c0 - a, d) / den  # along the edge
                    w = _cross(c0 - a, e[None, :]) / den  # along the strip segment
                ok = (
                    np.isfinite(u)
                    & (u > 1e-12)
                    & (u < 1 - 1e-12)
                    & (w >= -1e-12)
                    & (w <= 1 + 1e-12)
                )
                params += [(float(uu), n + m + int(k)) for uu, k in zip(u[ok], ks[ok], strict=True)]
            params.sort()
            us = np.array([p for p, _ in params] + [1.0])
            mids = a + e * (0.5 * (us[:-1] + us[1:]))[:, None]
            inside = shapely.contains_xy(self.strips[i], mids[:, 0], mids[:, 1])
            for (u0, aid), ins in zip(params, inside, strict=True):
                pts.append(a + u0 * e)
                wanted.append(not ins)
                ids.append(aid)
        return np.asarray(pts), np.asarray(wanted), np.asarray(ids)

    # --------------------------------------------------------- stationary shadow
    def shadow(self, q: np.ndarray) -> tuple[shapely.Geometry, np.ndarray, np.ndarray]:
        """Shadow S(q) (free space minus target minus the partial region), with the
        anchor table used to label its edges.

        The overlay is snap-rounded onto ``shadow_grid`` (``2**-SHADOW_BITS`` of the
        union's grid).  The weak visibility region's fans end on the target at ray hits
        computed in floating point, so the region's hole around the target is the target
        with its vertices moved by an ulp or two; GEOS's floating overlay of the target
        with that nearly coincident hole can assign rings wrongly (an invalid "nested
        shells" union, then TopologyException "unable to assign free hole to a shell",
        fuzz seed 506058).  Snap-rounding is robust, and the two snap-roundings together
        (this one and the union's) move no point by more than ``grid / sqrt(2) * (1 +
        2**-SHADOW_BITS) < grid``, which ``conservative=True`` covers."""

        ring, wanted, ids = self.outline(q)
        area = shapely.Polygon(self.ring0 + q)
        g = self.shadow_grid
        if not wanted.any():
            shadow = snapped(shapely.difference, self.free, area, g)
            self._seen[(float(q[0]), float(q[1]))] = area
        else:
            pre, grazing = self._weak_pre.pop((float(q[0]), float(q[1])), (None, None))
            reg = pre if pre is not None and grazing is self._grazing else None
            if reg is None:
                reg = weak_visibility(
                    self.env, ring[::-1], np.roll(wanted[::-1], -1), self.eps_aim, self._grazing
                )
            # areal(): snap-rounding collapses slivers of the union narrower than the grid
            # into lines, and a snap-rounded overlay refuses mixed-dimension input
            seen = areal(snapped(shapely.union, reg, area, g))
            shadow = snapped(shapely.difference, self.free, seen, g)
            self._seen[(float(q[0]), float(q[1]))] = seen
        table = np.vstack([self.env.vert, ring])
        tid = np.concatenate([np.arange(self.n_fixed), ids])
        return polygonal(shadow), table, tid

    def _prefetch(
        self, qs: list[np.ndarray], eroded: list[tuple[np.ndarray, np.ndarray]] = ()
    ) -> None:
        """The weak visibility regions that :meth:`shadow` needs at the reference points
        ``qs`` (those not sampled yet) and that :meth:`_eroded_shadow` needs for the
        intervals ``eroded`` ((qa, qb) each), computed in one batch by
        :func:`~geometry.weak.weak_visibility_many` (bit for bit the regions
        :func:`~geometry.weak.weak_visibility` gives one by one; the ray casting of all
        targets together) and kept until taken."""
        todo, keys = [], set()
        for q in qs:
            key = (float(q[0]), float(q[1]))
            if key in self._frames or key in self._weak_pre or key in keys:
                continue
            keys.add(key)
            ring, wanted, _ = self.outline(q)
            if wanted.any():
                todo.append((key, ring[::-1], np.roll(wanted[::-1], -1)))
        todo_e = []
        for qa, qb in eroded:
            key = (tuple(qa.tolist()), tuple(qb.tolist()))
            if key in self._eroded_pre or key in keys:
                continue
            keys.add(key)
            got = self._eroded_core(qa, qb)
            if got is not None:
                todo_e.append((key, got[1]))
        if todo and todo_e and self._anchors() is not self._grazing:
            self._prefetch([], eroded)  # different grazing masks: two batches
            todo_e = []
        if len(todo) + len(todo_e) < 2:
            return
        rings = [r for _, r, _ in todo] + [r for _, r in todo_e]
        wanted = [w for _, _, w in todo] + [np.ones(len(r), dtype=bool) for _, r in todo_e]
        grazing = self._grazing if todo else self._anchors()
        regs = weak_visibility_many(self.env, rings, wanted, self.eps_aim, grazing)
        for (key, _, _), reg in zip(todo, regs[: len(todo)], strict=True):
            self._weak_pre[key] = (reg, self._grazing)
        for (key, _), reg in zip(todo_e, regs[len(todo) :], strict=True):
            self._eroded_pre[key] = reg

    def _edges(self, shadow: shapely.Geometry, table: np.ndarray, tid: np.ndarray) -> list:
        """Edges of ``shadow`` on moving lines: ``(key_prev, key, key_next)``, each
        key a pair of anchor ids spanning the line (shadow on the edge's left)."""
        out = []
        n = self.n_fixed
        merged = _drop_short_many(
            _ring_coords(_rings(shapely.orient_polygons(shadow, exterior_cw=False))),
            self.tol_lab,
            self._vertex_at,
        )
        vs = [v for v in merged if len(v) >= 3]
        if not vs:
            return out
        # all rings labelled in one batch (row by row, so as if ring by ring)
        d = np.concatenate([np.roll(v, -1, axis=0) - v for v in vs])
        flat = np.concatenate(vs)
        off = np.cumsum([0] + [len(v) for v in vs])
        # an edge between two environment vertices far apart is on a fixed line (its key
        # is two fixed anchors, see below): only the other edges and their neighbours are
        # labelled (most of a shadow's boundary is the free space's)
        fixed = self._fixed_edges(flat, off)
        ring_of = np.repeat(np.arange(len(vs)), np.diff(off))
        idx = np.arange(len(flat))
        nxt = np.where(idx + 1 == off[ring_of + 1], off[ring_of], idx + 1)
        prv = np.where(idx == off[ring_of], off[ring_of + 1] - 1, idx - 1)
        need = ~fixed | ~fixed[nxt] | ~fixed[prv]
        all_keys = np.full((len(flat), 2), -1, dtype=np.int64)
        if need.any():
            all_keys[need] = self._label(flat[need], table, tid, d=d[need])
        # consecutive edges on one line (the same key) are one shadow edge: the overlay can
        # leave a vertex inside an edge (a node of another ring, a hot pixel), and its pieces
        # would each see their own line as a neighbour and be dropped below (a shadow traced
        # in one frame and missed in another, fuzz seed 8103); a ring all of one line holds
        # none.  All rings at once; the keys are sorted pairs, so equal lines are equal rows.
        same = (all_keys == all_keys[prv]).all(axis=1) & (all_keys >= 0).all(axis=1)
        kept = np.flatnonzero(~same & ~np.logical_and.reduceat(same, off[:-1])[ring_of])
        if not len(kept):
            return out
        kr = ring_of[kept]
        pos = np.arange(len(kept))
        first = np.searchsorted(kr, kr, side="left")  # the ring's first and last kept edge
        last = np.searchsorted(kr, kr, side="right") - 1
        keys = all_keys[kept]
        kp = keys[np.where(pos == first, last, pos - 1)]  # neighbours along the ring
        kn = keys[np.where(pos == last, first, pos + 1)]
        moving = (keys >= n).any(axis=1) & (keys >= 0).all(axis=1)
        ok = moving & (kp >= 0).all(axis=1) & (kn >= 0).all(axis=1)
        ok &= ~(kp == keys).all(axis=1) & ~(kn == keys).all(axis=1)
        for j in np.flatnonzero(ok):
            out.append((tuple(kp[j]), tuple(keys[j]), tuple(kn[j])))
        return out

    def _fixed_edges(self, v: np.ndarray, off: np.ndarray) -> np.ndarray:
        """(n,) bool per edge ``v[i] -> v[i + 1]`` of the closed rings ``v[off[r] :
        off[r + 1]]``: both ends are environment vertices (within ``1e-12`` of the scene's
        size: the shadow's overlay snap-rounds them onto ``shadow_grid``) more than
        ``3 tol_lab`` apart.  Such an edge's line passes within ``tol_lab`` of two fixed
        anchors that are not both within ``tol_lab`` of any one anchor, so :meth:`_label`
        keys it by two fixed anchors (it prefers fixed ones): it does not move."""
        env = self.env.vert
        at = self._vertex_cell(v)
        ok = at >= 0
        ok[ok] = np.abs(env[at[ok]] - v[ok]).max(axis=1) <= 1e-12 * self.env.scale
        ring_of = np.repeat(np.arange(len(off) - 1), np.diff(off))
        idx = np.arange(len(v))
        nxt = np.where(idx + 1 == off[ring_of + 1], off[ring_of], idx + 1)
        both = ok & ok[nxt]
        out = np.zeros(len(v), dtype=bool)
        out[both] = np.abs(env[at[both]] - env[at[nxt[both]]]).max(axis=1) > 3.0 * self.tol_lab
        return out

    def _vertex_cell(self, v: np.ndarray) -> np.ndarray:
        """Per point of ``v`` (k, 2): the environment vertex in the same cell of the
        ``shadow_grid`` (its coordinates rounded to the grid), the last one if several, or
        -1.  The cells are sorted once (complex numbers order by x, then y)."""
        got = getattr(self, "_vert_cells", None)
        if got is None:
            cell = np.round(self.env.vert / self.shadow_grid)
            key = np.empty(len(cell), dtype=complex)
            key.real, key.imag = cell[:, 0], cell[:, 1]
            rev, first = np.unique(key[::-1], return_index=True)  # the last of equal cells
            got = self._vert_cells = (rev, len(key) - 1 - first)
        cells, idx = got
        if not len(cells):
            return np.full(len(v), -1, dtype=np.int64)
        c = np.round(v / self.shadow_grid)
        q = np.empty(len(c), dtype=complex)
        q.real, q.imag = c[:, 0], c[:, 1]
        pos = np.minimum(np.searchsorted(cells, q), len(cells) - 1)
        return np.where(cells[pos] == q, idx[pos], -1).astype(np.int64)

    def _label(
        self, v: np.ndarray, table: np.ndarray, tid: np.ndarray, d: np.ndarray | None = None
    ) -> np.ndarray:
        """Per edge of the closed ring ``v``: two anchor ids spanning its line, or -1.
        ``d``: the edge vectors (default: of the closed ring ``v``; given, the rows are
        edges ``v[i] -> v[i] + d[i]`` of any rings)."""
        if d is None:
            d = np.roll(v, -1, axis=0) - v
        ln = np.hypot(d[:, 0], d[:, 1])
        dist = np.abs(_cross(d[:, None, :], table[None, :, :] - v[:, None, :])) / np.maximum(
            ln[:, None], 1e-300
        )
        keys = np.full((len(v), 2), -1, dtype=np.int64)
        # two distinct positions on the line; prefer fixed anchors, then moving ones (in
        # table order): the first pair (i, j), i before j in that order, of candidates
        # more than tol_lab apart whose line is the edge's.  Two anchors barely "far"
        # apart (the two vertices at a sliver's end, 1e-8 across) both lie on the edge's
        # line, but the line they span points anywhere: the edge's ends must lie on it
        # (fuzz seed 205296: a sliver's shadow edges were keyed to the sliver's ends,
        # read as fixed, and never traced)
        perm = np.argsort(tid >= self.n_fixed, kind="stable")
        on = (dist <= self.tol_lab)[:, perm]
        r_on, c_on = np.nonzero(on)  # row-major: by row, then in perm order
        if len(r_on) == 0:
            return keys
        tab = table[perm]
        # the candidates are few per row: their pairs (i, j), i < j, in one row
        cnt = np.bincount(r_on, minlength=len(v))
        pi, pj = [], []
        for s in range(1, int(cnt.max())):
            k = np.flatnonzero(r_on[:-s] == r_on[s:])
            pi.append(k)
            pj.append(k + s)
        if not pi:
            return keys
        pi, pj = np.concatenate(pi), np.concatenate(pj)
        ci, cj = c_on[pi], c_on[pj]
        good = np.abs(tab[cj] - tab[ci]).max(axis=1) > self.tol_lab
        rr = r_on[pi]
        good[good] = self._fits(tab[ci[good]], tab[cj[good]], v[rr[good]], d[rr[good]])
        pi, pj, rr = pi[good], pj[good], rr[good]
        order = np.lexsort((pj, pi))  # the first pair of each row
        rr_s = rr[order]
        r_first, first = np.unique(rr_s, return_index=True)
        ids = tid[perm]
        sel = order[first]
        keys[r_first] = np.sort(np.stack([ids[c_on[pi[sel]]], ids[c_on[pj[sel]]]], axis=1), axis=1)
        # an edge too short for two anchors "far" apart whose ends are two vertices of
        # the environment lies on their line (a short edge that _drop_short kept)
        short = np.flatnonzero((keys[:, 0] < 0) & (np.abs(d).max(axis=1) <= self.tol_lab))
        if len(short):
            ends = np.stack([v[short], v[short] + d[short]], axis=1).reshape(-1, 2)
            at = self._vertex_at(ends).reshape(-1, 2)
            both = (at >= 0).all(axis=1) & (at[:, 0] != at[:, 1])
            keys[short[both]] = np.sort(at[both], axis=1)
        return keys

    def _fits(self, a: np.ndarray, b: np.ndarray, v: np.ndarray, d: np.ndarray) -> np.ndarray:
        """Row by row: do both ends of the edge ``v -> v + d`` lie within ``tol_lab`` of
        the line through the anchors ``a`` and ``b`` (all (k, 2))?  (k,) bool."""
        w = b - a
        ln = np.maximum(np.hypot(w[:, 0], w[:, 1]), 1e-300)
        d0 = np.abs(_cross(w, v - a)) / ln
        d1 = np.abs(_cross(w, v + d - a)) / ln
        return np.maximum(d0, d1) <= self.tol_lab

    def _vertex_at(self, pts: np.ndarray) -> np.ndarray:
        """Per point of ``pts`` (k, 2): the index of an environment vertex within the
        union's snap grid of it (max-norm), or -1."""
        vert = self.env.vert
        near = np.abs(vert[None, :, :] - pts[:, None, :]).max(axis=2) <= self.grid
        return np.where(near.any(axis=1), np.argmax(near, axis=1), -1)

    # -------------------------------------------------------------- point test
    def blind(self, p: np.ndarray, q: np.ndarray) -> np.ndarray:
        """Exact test, row by row: is placement ``p[j]`` blind to every wanted
        point of the target at reference point ``q[j]``?  (Q,) bool."""
        p = np.asarray(p, dtype=float).reshape(-1, 2)
        q = np.asarray(q, dtype=float).reshape(-1, 2)
        # the test is row by row, so equal rows (byte for byte) are tested once: the
        # probes of _valid_many repeat (NaN-padded fractions become 0.5, the ends of
        # neighbouring traces meet), about two thirds of them on slow fuzz scenes
        rows = np.ascontiguousarray(np.hstack([p, q])).view(np.dtype((np.void, 32)))[:, 0]
        _, first, back = np.unique(rows, return_index=True, return_inverse=True)
        if len(first) < len(p):
            return self._blind_rows(p[first], q[first])[back.reshape(-1)]
        return self._blind_rows(p, q)

    def _blind_rows(self, p: np.ndarray, q: np.ndarray) -> np.ndarray:
        """:meth:`blind` on (n, 2) float arrays ``p``, ``q``."""
        out = np.zeros(len(p), dtype=bool)
        # from inside K everything in K is in sight: never blind
        far = ~shapely.contains_xy(self._hull_poly, p[:, 0], p[:, 1])
        far &= shapely.contains_xy(self.free, p[:, 0], p[:, 1])  # probes off the map: not blind
        p, q = p[far], q[far]
        if len(p) == 0:
            return out
        try:
            out[far] = self._blind(p, q)
        except RayEscapeError:  # defensive: isolate the offending probe, one by one
            idx = np.flatnonzero(far)
            for j in range(len(p)):
                try:
                    out[idx[j]] = self._blind(p[j : j + 1], q[j : j + 1])[0]
                except RayEscapeError:
                    out[idx[j]] = False
        return out

    def _blind(self, p: np.ndarray, q: np.ndarray) -> np.ndarray:
        base = _libm.atan2(*(self.hull.mean(axis=0) - p).T[::-1])
        rel = self.ring0[None, :, :] + (q - p)[:, None, :]
        ang = (_libm.atan2(rel[..., 1], rel[..., 0]) - base[:, None] + np.pi) % TAU - np.pi
        lo, hi = ang.min(axis=1), ang.max(axis=1)
        w_lo, w_hi, w_own = self._windows(p, base, np.stack([base + lo, hi - lo], axis=1))
        # a row without a window into K is blind whatever it would see of the target:
        # the wanted directions are needed (and computed) for the other rows only
        look = np.unique(w_own)
        if len(look) == 0:
            return np.ones(len(p), dtype=bool)
        t_lo, t_hi, t_own = self._wanted_dirs(p[look], q[look], base[look])
        return ~_overlaps(w_lo, w_hi, w_own, t_lo, t_hi, look[t_own], len(p))

    def _windows(self, p: np.ndarray, base: np.ndarray, sectors: np.ndarray) -> tuple:
        """Directions (relative to ``base``) inside ``sectors`` (start, width) in
        which each p sees into K."""
        g, off = gaps_many(self.env, p, sectors=sectors, flat=True, interior=True)
        own = np.repeat(np.arange(len(p)), np.diff(off))
        ok = g.seg >= 0
        g_lo, g_hi, own, seg = g.lo[ok], g.hi[ok], own[ok], g.seg[ok]
        if _visindex.available():  # the compiled twin of the clipping below
            return _visindex.window_ranges(g_lo, g_hi, own, seg, self.env.seg, p, base, self.hull)
        sg = self.env.seg[seg]
        s0, sd = sg[:, :2], sg[:, 2:] - sg[:, :2]
        pp = p[own]
        side_p = np.sign(_cross(sd, pp - s0))
        kv = self.hull
        side = _cross(sd[:, None, :], kv[None, :, :] - s0[:, None, :]) * side_p[:, None]
        keep = side > 0
        nxt = np.roll(np.arange(len(kv)), -1)
        cross_e = (side > 0) != (side[:, nxt] > 0)
        with np.errstate(divide="ignore", invalid="ignore"):
            lam = side / (side - side[:, nxt])
            xpt = kv[None, :, :] + lam[..., None] * (kv[nxt] - kv)[None, :, :]
        pts = np.concatenate([np.broadcast_to(kv, xpt.shape), xpt], axis=1)
        use = np.concatenate([keep, cross_e], axis=1)
        rel = _libm.atan2(pts[..., 1] - pp[:, None, 1], pts[..., 0] - pp[:, None, 0])
        rel = (rel - base[own][:, None] + np.pi) % TAU - np.pi
        amin = np.where(use, rel, np.inf).min(axis=1)
        amax = np.where(use, rel, -np.inf).max(axis=1)
        r_lo = (g_lo - base[own] + np.pi) % TAU - np.pi
        r_hi = r_lo + (g_hi - g_lo)
        los, his, owns = [], [], []
        for shift in (0.0, -TAU):
            lo = np.maximum(r_lo + shift, amin)
            hi = np.minimum(r_hi + shift, amax)
            k = hi > lo
            los.append(lo[k])
            his.append(hi[k])
            owns.append(own[k])
        return np.concatenate(los), np.concatenate(his), np.concatenate(owns)

    def _wanted_dirs(self, p: np.ndarray, q: np.ndarray, base: np.ndarray) -> tuple:
        """Directions (relative to ``base``) in which, ignoring obstacles, the first
        point of A_q hit from p is wanted."""
        rel_pts = self.ring0[None, :, :] + (q - p)[:, None, :]
        ang = _libm.atan2(rel_pts[..., 1], rel_pts[..., 0])
        ang = (ang - base[:, None] + np.pi) % TAU - np.pi
        if self.strips is None:
            return ang.min(axis=1), ang.max(axis=1), np.arange(len(p))
        dom = self._target_domain()
        g, off = gaps_many(dom, p - q, flat=True)
        own = np.repeat(np.arange(len(p)), np.diff(off))
        hit = (g.seg >= 0) & (dom.seg_tag[np.maximum(g.seg, 0)] == _WANTED)
        los, his, owns = [], [], []
        m = self.m
        on_ring = hit & (dom.seg_ring[np.maximum(g.seg, 0)] == 1)
        # cw ring segment k runs from ring0[m-1-k] to ring0[m-2-k]: ccw edge i = m-2-k
        edge_of = (m - 2 - (g.seg - self._box_segs)) % m
        # the probes of one trace share their q: cut the edges once per distinct q
        q_u, q_inv = np.unique(q, axis=0, return_inverse=True)
        q_inv = q_inv.reshape(-1)
        for i in range(m):
            sel = on_ring & (edge_of == i)
            if not sel.any():
                continue
            j = own[sel]
            a, e = self.ring0[i], self.edge0[i]
            ee = e @ e
            u0 = ((g.p0[sel] - a) @ e) / ee
            u1 = ((g.p1[sel] - a) @ e) / ee
            ulo, uhi = np.minimum(u0, u1), np.maximum(u0, u1)
            rows = q_inv[j]
            used, back = np.unique(rows, return_inverse=True)
            back = back.reshape(-1)
            cells = [(c0[back], c1[back], ins[back]) for c0, c1, ins in self._cells(i, q_u[used])]
            for c0, c1, ins in cells:
                lo = np.maximum(ulo, c0)
                hi = np.minimum(uhi, c1)
                k = (hi > lo) & ~ins
                if not k.any():
                    continue
                pl = a + lo[k, None] * e - (p - q)[j[k]]
                ph = a + hi[k, None] * e - (p - q)[j[k]]
                al = (_libm.atan2(pl[:, 1], pl[:, 0]) - base[j[k]] + np.pi) % TAU - np.pi
                ah = (_libm.atan2(ph[:, 1], ph[:, 0]) - base[j[k]] + np.pi) % TAU - np.pi
                los.append(np.minimum(al, ah))
                his.append(np.maximum(al, ah))
                owns.append(j[k])
        if not los:
            return np.zeros(0), np.zeros(0), np.zeros(0, dtype=int)
        return np.concatenate(los), np.concatenate(his), np.concatenate(owns)

    def _cells(self, i: int, q: np.ndarray) -> list:
        """Edge i of A_q cut by its strip: list of ``(u0, u1, inside)`` arrays over q."""
        nq = len(q)
        ks = np.flatnonzero(self._cut_edge == i)
        a, e = self.ring0[i] + q, self.edge0[i]
        if len(ks) == 0:
            return [(np.zeros(nq), np.ones(nq), np.zeros(nq, dtype=bool))]
        s = self._cut_segs[ks]
        c0, d = s[:, :2], s[:, 2:] - s[:, :2]
        den = _cross(e[None, :], d)[None, :]
        with np.errstate(divide="ignore", invalid="ignore"):
            u = _cross(c0[None] - a[:, None], d[None]) / den
            w = _cross(c0[None] - a[:, None], e[None, None, :]) / den
        ok = np.isfinite(u) & (u > 0) & (u < 1) & (w >= 0) & (w <= 1)
        us = np.sort(np.where(ok, u, 1.0), axis=1)
        us = np.hstack([np.zeros((nq, 1)), us, np.ones((nq, 1))])
        out = []
        for c in range(us.shape[1] - 1):
            mid = a + (0.5 * (us[:, c] + us[:, c + 1]))[:, None] * e
            ins = shapely.contains_xy(self.strips[i], mid[:, 0], mid[:, 1])
            out.append((us[:, c], us[:, c + 1], ins))
        return out

    def _target_domain(self) -> Domain:
        dom = getattr(self, "_dom_a", None)
        if dom is None:
            big = 1e3 * self.env.scale
            box = np.array([[-big, -big], [big, -big], [big, big], [-big, big]])
            dom = Domain.from_rings([box, self.ring0[::-1]], [_ENV, _WANTED])
            self._box_segs = 4
            self._dom_a = dom
        return dom

    # ------------------------------------------------------------------ sweep
    def along(self, q0: np.ndarray, q1: np.ndarray) -> tuple[list[shapely.Geometry], dict]:
        """Pieces whose union is the union of the shadows S(q) for q on the
        segment ``q0 -> q1``, and counters (samples, traced edges, refinements)."""
        pieces, stats = self.along_many([(q0, q1)])
        return pieces[0], stats

    def along_many(
        self, segs: list[tuple], traced: Callable[[int], None] | None = None
    ) -> tuple[list[list[shapely.Geometry]], dict]:
        """:meth:`along` for each segment ``(q0, q1)`` of ``segs``: per segment its pieces,
        and the counters summed; ``traced(i)`` is called once segment ``i`` is done (they are
        traced in order, after the samples of all).

        The same pieces as :meth:`along` segment by segment (every decision of a segment
        depends on its own samples, and a shadow is a function of its configuration), with
        the exact weak visibility regions that the birth checks and the event samples need
        computed in one batch per round over all segments instead of one per segment (a lone
        weak visibility region costs about twice its share of a batch)."""
        # the shadows of a sweep skip the corners that see no point of K (one weak
        # visibility of K, paid back over the samples; a lone shadow does without)
        clock = self.clock
        with clock("anchors"):
            self._grazing = self._anchors()
        runs = [_Run(self, np.asarray(a, dtype=float), np.asarray(b, dtype=float)) for a, b in segs]
        ts_all = [[float(t) for t in np.linspace(0.0, 1.0, self.n_samples + 1)] for _ in runs]
        moving = [r for r in runs if float(np.hypot(*r.dq)) > 0]
        with clock("vertex samples"):
            # the samples and the first level of the birth checks' eroded targets (which do
            # not depend on the samples) in one batch
            level = [
                (r, a, b, 0)
                for r, ts in zip(runs, ts_all, strict=True)
                if r in moving
                for a, b in zip(ts[:-1], ts[1:], strict=True)
            ]
            pairs, split = self._birth_bounds(level) if moving else ([], {})
            self._prefetch(
                [
                    r.q1 if t == 1.0 else r.q0 + t * r.dq
                    for r, ts in zip(runs, ts_all, strict=True)
                    for t in ts
                ],
                pairs + [p for ps in split.values() for p in ps],
            )
            for run, ts in zip(runs, ts_all, strict=True):
                for t in ts:
                    run.frame(t)
        if moving:
            with clock("birth checks"):
                # the first level is the one whose bounds the vertex batch computed
                self._refine_births_many(
                    moving, [ts_all[runs.index(r)] for r in moving], (pairs, split)
                )
        # the collinearity events (shadows born on a line) are sampled lazily: once
        # between consecutive events next to a *live* event, one whose wedge's lines carry
        # a shadow edge at a sample so far (see _live_mids), until no new one is live;
        # first from the samples alone, then again after the refinements of the tracing
        with clock("event samples"):
            for r in moving:
                r.ev_t, r.ev_ids = self._events(r.q0, r.dq)
            while True:
                asked = [(r, self._live_mids(r.ev_t, r.ev_ids, r.frames, r.looked)) for r in moving]
                asked = [(r, mids) for r, mids in asked if mids]
                if not asked:
                    break
                self._prefetch([r.q0 + t * r.dq for r, mids in asked for t in mids])
                for r, mids in asked:
                    for t in mids:
                        r.frame(t)
        with clock("tracing"):
            # the first round of every segment's traces in one batch
            jobs = [(r.q0, r.q1, r.frame, _pairs(sorted(r.frames))) for r in moving]
            first = dict(zip(map(id, moving), self._interval_traces(jobs), strict=True))
        out = []
        for i, r in enumerate(runs):
            with clock("tracing"):
                out.append(self._trace_run(r, first[id(r)]) if r in moving else [r.frame(0.0)[0]])
            if traced is not None:
                traced(i)
        stats = {k: sum(r.stats[k] for r in runs) for k in ("samples", "edges", "refined")}
        return out, stats

    def _trace_run(self, run: _Run, pre: dict | None = None) -> list[shapely.Geometry]:
        """The pieces of one segment once its samples are taken: its sampled shadows, then
        the traces between them (:meth:`_sweep_intervals`; ``pre``: the traces of the
        intervals between its samples, :meth:`_interval_traces`, if done ahead), asking
        :meth:`_live_mids` again after the tracing's refinements."""
        q0, q1, dq, frame, stats = run.q0, run.q1, run.dq, run.frame, run.stats
        ts = sorted(run.frames)
        pieces = [frame(t)[0] for t in ts]
        state = _Cover()
        todo = [(a, b, 0) for a, b in _pairs(ts)]
        while True:
            self._sweep_intervals(todo, q0, q1, frame, pieces, state, stats, pre)
            pre = None
            mids = self._live_mids(run.ev_t, run.ev_ids, run.frames, run.looked)
            if not mids:
                return pieces
            self._prefetch([q0 + t * dq for t in mids])
            for t in mids:
                pieces.append(frame(t)[0])
            grid = sorted(set(run.frames) | set(mids))
            todo = [
                (a, b, 0)
                for a, b in zip(grid[:-1], grid[1:], strict=True)
                if a in mids or b in mids
            ]

    def _live_mids(
        self, ev_t: np.ndarray, ev_ids: list, frames: dict, looked: set[int]
    ) -> list[float]:
        """The sample times (sorted, not sampled yet) that the collinearity events
        :meth:`_events` asks for now: the midpoint of each interval between consecutive
        events (0 and 1 included) next to a live event that holds no sample yet.

        An event (index into ``ev_t``) is *live* when a shadow edge at a sample so far
        (``frames``: time -> (shadow, edges); the edge or one of its neighbours) lies on a
        line spanned by two of its anchors, one of them moving (:meth:`_events`' ids; an
        unknown id, -1, makes it live; ``lazy_samples=False``: the previous rule, the
        midpoint of every interval between events, 0.5 on an edge without events).  The wedge
        that opens at an event grows from a line that continues an edge of an existing
        shadow, and that edge lies on such a line, so an event none of whose lines
        carries a shadow edge at any sample opens no wedge *unless* that edge itself is
        born and gone between samples: the rule assumes it is not (measured, not proven:
        docs/DESIGN.md, "Collinearity events").  The caller samples, then asks again (the
        new samples can make more events live); each event is looked at until it is live
        once (``looked``)."""
        bounds = np.concatenate([[0.0], ev_t, [1.0]])
        if not self.lazy_samples:  # the previous rule: once between every two events, at once
            if -1 in looked:
                return []
            looked.update([-1, *range(len(ev_t))])
            return sorted({float(t) for t in 0.5 * (bounds[1:] + bounds[:-1])} - set(frames))
        keys = {frozenset(k) for _, es in frames.values() for e in es for k in e}
        times = np.array(sorted(frames))
        out: set[float] = set()
        for k in range(len(ev_t)):
            if k in looked:
                continue
            live = False
            for mov, other in ev_ids[k]:
                if -1 in mov or -1 in other:
                    live = True
                    break
                if any(frozenset((u, v)) in keys for u in mov for v in (*mov, *other) if v != u):
                    live = True
                    break
            if not live:
                continue
            looked.add(k)
            for lo, hi in ((bounds[k], bounds[k + 1]), (bounds[k + 1], bounds[k + 2])):
                if not ((times > lo) & (times < hi)).any():
                    out.add(float(0.5 * (lo + hi)))
        return sorted(out)

    def _sweep_intervals(
        self,
        todo: list,
        q0: np.ndarray,
        q1: np.ndarray,
        frame,
        pieces: list,
        state,
        stats,
        pre: dict | None = None,
    ) -> None:
        """Trace the moving shadow edges over the intervals ``todo`` ((a, b, depth) each,
        sample times of the sweep ``q0 -> q1``), refining where a configuration may be
        born and gone in between; the traced quads and the refinement samples' shadows
        go to ``pieces``.  ``state`` (:class:`_Cover`) carries what the traces covered
        from one call to the next; ``pre``: traces of intervals done ahead (taken from it)."""
        dq = q1 - q0
        cover, confirmed, traced, probed = state.cover, state.confirmed, state.traced, state.probed
        pre = {} if pre is None else pre  # interval -> its traces, both ways
        while todo:
            self._check_time()
            if (todo[-1][0], todo[-1][1]) not in pre:
                # the traces of every interval waiting, in one batch (a trace depends only
                # on its interval's two samples, not on what the others covered)
                wait = [(a_, b_) for a_, b_, _ in todo if (a_, b_) not in pre]
                pre.update(self._interval_traces([(q0, q1, frame, wait)])[0])
            a, b, depth = todo.pop()
            cut: list[tuple] = []  # (edge, t_end, toward): traces ended by a neighbour's change
            done = pre.pop((a, b))
            for (t, _), (edges, quads, ends, inside, not_point, cut_short) in zip(
                ((a, b), (b, a)), done, strict=True
            ):
                for e in inside:  # swept inside the known shadows: nothing to trace
                    cover.setdefault(e[1], []).append((a, b))
                for e in not_point:
                    traced.setdefault(e[1], []).append((a, b))
                stats["edges"] += len(edges)
                pieces.extend(quads)
                for e, end in zip(edges, ends, strict=True):
                    cover.setdefault(e[1], []).append((min(t, end), max(t, end)))
                    if end != t:
                        confirmed.add((t, e[1]))
                        traced.setdefault(e[1], []).append((min(t, end), max(t, end)))
                    else:  # not confirmed even at its own sample: tracing cannot cover it
                        traced.setdefault(e[1], []).append((a, b))
                cut += cut_short
                confirmed.update((t, e[1]) for e in inside)
            gap = self._coverage_gap(frame(a)[1], frame(b)[1], cover, a, b, confirmed)
            if gap is None:
                gap = self._continuation_gap(cut, traced, probed, q0, dq)
            if gap is not None and depth < self.max_depth:
                stats["refined"] += 1
                pieces.append(frame(gap)[0])
                todo += [(a, gap, depth + 1), (gap, b, depth + 1)]

    def _interval_traces(self, jobs: list[tuple]) -> list[dict[tuple[float, float], list]]:
        """Per job ``(q0, q1, frame, intervals)`` (a sweep ``q0 -> q1``, its frames, intervals
        ``(a, b)`` of its sample times), per interval: for the shadow edges at ``a`` traced
        towards ``b``, then those at ``b`` towards ``a``, ``(edges, quads, ends, inside,
        not_point, cut)``: the edges whose sweep leaves the two samples' shadows
        (:meth:`_uncovered_seen`, else :meth:`_uncovered`), what :meth:`_trace_many` makes
        of them, the other edges (swept inside the known shadows), those of them that are
        no point (:meth:`_not_point`) and the traces cut
        short (:meth:`_cut_short`); each of these in one batch over all the intervals (none
        depends on what the others covered)."""
        self._check_time()
        items = [
            (frame(t)[1], t, toward, (a, b), q0, q1)
            for q0, q1, frame, intervals in jobs
            for a, b in intervals
            for t, toward in ((a, b), (b, a))
        ]
        seen = iter(self._uncovered_seen_many(items))
        groups = []
        for q0, q1, frame, intervals in jobs:
            dq = q1 - q0
            for a, b in intervals:
                # the areal part: GEOS's union of two nearly coincident shadows can carry
                # collapsed edges (LineStrings), and an overlay with such a collection fails
                # ("Result area inconsistent with overlay operation", fuzz seed 501057)
                known = None  # the shadows' union, if their X (see _uncovered_seen) is not kept
                for t, toward in ((a, b), (b, a)):
                    edges = next(seen)
                    if edges is None:
                        if known is None:
                            known = areal(shapely.union(frame(a)[0], frame(b)[0]))
                        edges = self._uncovered(frame(t)[1], t, toward, known, q0, dq)
                    groups.append((edges, t, toward, q0, dq))
        traces = self._trace_groups(groups)
        frames = [frame for _, _, frame, intervals in jobs for _ in intervals for _ in (0, 1)]
        inside = [
            ([e for e in frame(t)[1] if e not in edges], t, q0, dq)
            for frame, (edges, t, _, q0, dq) in zip(frames, groups, strict=True)
        ]
        points = self._not_point_many(inside)  # of the edges swept inside the known shadows
        cuts = self._cut_short_many(
            [(g[0], tr[1], *g[1:]) for g, tr in zip(groups, traces, strict=True)]
        )
        got = iter(zip(groups, traces, inside, points, cuts, strict=True))
        out = []
        for _, _, _, intervals in jobs:
            done = {}
            for ab in intervals:
                done[ab] = [
                    (g[0], *tr, ins[0], pt, ct) for g, tr, ins, pt, ct in (next(got), next(got))
                ]
            out.append(done)
        return out

    def _events(self, q0: np.ndarray, dq: np.ndarray) -> tuple[np.ndarray, list]:
        """Times in (0, 1), sorted, at which the target moving along ``q0 + t dq`` meets
        a *collinearity event*: a moving anchor (target vertex or end of a wanted piece)
        crosses the line through two convex obstacle corners whose joining line is
        tangent at both, or through an obstacle edge; or the line through two target
        vertices crosses a convex obstacle corner.  Only events whose line is
        unobstructed between its anchors count.  Also, per time, the anchor ids of its
        events: ``(moving ids, other ids)`` each (ids as :meth:`pos` takes them; -1: the
        neighbour of an obstacle corner not known), for :meth:`_live_mids`.

        At such an event two shadow-edge lines coincide, and a shadow can be born as a
        segment on that line (it then grows from a line that continues an edge of an
        existing shadow, so the eroded-target test of :meth:`_refine_births`, which
        looks for shadow components apart from the known ones, does not see it: fuzz
        issue 26.3/26.4).  Sampling once between consecutive events catches such a
        shadow at a time it has area, and its edges are then traced both ways (next to
        the events :meth:`_live_mids` finds live)."""
        b, i, j = self._event_lines()
        env = self.env
        # obstacle edges with a convex end (a beam can graze along them past that end)
        cvx = self._event_corners()
        p0 = np.vstack([b[i], env.vert[cvx], env.vert[cvx]])
        p1 = np.vstack([b[j], env.vert_next[cvx], env.vert_prev[cvx]])
        w = p1 - p0
        # moving anchors at t = 0 and their velocities (target vertices: dq; ends of the
        # wanted pieces slide along their strip segment)
        q0v = q0[None, :]
        mov0 = [self.ring0 + q0v]
        vel = [np.broadcast_to(dq, self.ring0.shape)]
        if len(self._cut_segs):
            ids = self.n_fixed + self.m + np.arange(len(self._cut_segs))
            with np.errstate(invalid="ignore"):  # an edge parallel to its strip segment
                c0 = self.pos(ids, np.repeat(q0v, len(ids), 0))
                c1 = self.pos(ids, np.repeat((q0 + dq)[None, :], len(ids), 0))
            ok = np.isfinite(c0).all(axis=1) & np.isfinite(c1).all(axis=1)
            mov0.append(c0[ok])
            vel.append(c1[ok] - c0[ok])
        x0, vx = np.vstack(mov0), np.vstack(vel)
        with np.errstate(divide="ignore", invalid="ignore"):
            # x0 + t vx on the line (p0, w)
            ta = _cross(w[:, None, :], p0[:, None, :] - x0[None]) / _cross(w[:, None, :], vx[None])
            ii, kk = np.triu_indices(self.m, 1)
            wt = self.ring0[kk] - self.ring0[ii]
            a0 = self.ring0 + q0v
            tb = _cross(wt[None], b[:, None, :] - a0[ii][None]) / _cross(wt, dq)[None]
        lo, hi = 1e-9, 1 - 1e-9
        la, xa = np.nonzero(np.isfinite(ta) & (ta > lo) & (ta < hi))
        ta = ta[la, xa]
        lb, pb = np.nonzero(np.isfinite(tb) & (tb > lo) & (tb < hi))
        tb = tb[lb, pb]
        # unobstructed: the line's piece spanning its three points lies in the free space
        xs = x0[xa] + ta[:, None] * vx[xa]
        pts = np.stack([p0[la], p1[la], xs], axis=1)  # (A, 3, 2)
        u = w[la] / np.maximum(np.hypot(w[la, 0], w[la, 1]), 1e-300)[:, None]
        s_ = np.einsum("akj,aj->ak", pts - pts[:, :1], u)
        seg_a = np.stack(
            [
                pts[np.arange(len(pts)), np.argmin(s_, axis=1)],
                pts[np.arange(len(pts)), np.argmax(s_, axis=1)],
            ],
            axis=1,
        )
        ai = a0[ii[pb]] + tb[:, None] * dq
        ak = a0[kk[pb]] + tb[:, None] * dq
        bb = b[lb]
        near = np.where((np.hypot(*(ai - bb).T) <= np.hypot(*(ak - bb).T))[:, None], ai, ak)
        seg_b = np.stack([bb, near], axis=1)
        segs = np.concatenate([seg_a, seg_b])
        t = np.concatenate([ta, tb])
        if len(t) == 0:
            return t, []
        keep = self._tangent_events(xa, ta, la, w, lb, pb, b, ii, kk)
        idx = np.flatnonzero(keep)  # the covering test only where the tangency holds
        keep[idx] = shapely.covers(self._free_near(), shapely.linestrings(segs[idx]))
        cut = np.flatnonzero(xa >= self.m)  # ends of wanted pieces: on their edge then?
        if len(cut):
            k = xa[cut] - self.m
            kk_ = np.flatnonzero(np.isfinite(c0).all(axis=1) & np.isfinite(c1).all(axis=1))[k]
            i_e = self._cut_edge[kk_]
            a_e = self.ring0[i_e] + q0 + ta[cut, None] * dq
            e_e = self.edge0[i_e]
            s_e = self._cut_segs[kk_]
            x_e = xs[cut]
            u_e = np.einsum("ij,ij->i", x_e - a_e, e_e) / np.einsum("ij,ij->i", e_e, e_e)
            d_s = s_e[:, 2:] - s_e[:, :2]
            w_e = np.einsum("ij,ij->i", x_e - s_e[:, :2], d_s) / np.maximum(
                np.einsum("ij,ij->i", d_s, d_s), 1e-300
            )
            keep[cut] &= (u_e >= -1e-9) & (u_e <= 1 + 1e-9) & (w_e >= -1e-9) & (w_e <= 1 + 1e-9)
        # the anchor ids of each event: the moving ones and the others (lines through two
        # of them carry the edges of the wedge that opens there, see _live_mids)
        n = self.n_fixed
        mov_id = n + np.arange(self.m)
        if len(self._cut_segs):
            mov_id = np.concatenate([mov_id, n + self.m + np.flatnonzero(ok)])
        nxt, prv = self._ring_neighbours()
        fix = np.vstack(
            [
                np.stack([cvx[i], cvx[j]], axis=1),
                np.stack([cvx, nxt[cvx]], axis=1),
                np.stack([cvx, prv[cvx]], axis=1),
            ]
        )
        ids = [((int(mov_id[x]),), tuple(fix[k].tolist())) for x, k in zip(xa, la, strict=True)]
        ids += [
            ((n + int(ii[p]), n + int(kk[p])), (int(cvx[k]),)) for p, k in zip(pb, lb, strict=True)
        ]
        kept = np.flatnonzero(keep)
        kept = kept[np.argsort(t[kept], kind="stable")]
        ts = t[kept]
        # merge events closer than the tracing can tell apart (the first time stands)
        first = np.concatenate([[True], np.diff(ts) > 1e-9]) if len(ts) else np.zeros(0, bool)
        group = np.cumsum(first) - 1
        out: list[list] = [[] for _ in range(int(first.sum()))]
        for g, c in zip(group, kept, strict=True):
            out[g].append(ids[c])
        return ts[first], out

    def _ring_neighbours(self) -> tuple[np.ndarray, np.ndarray]:
        """(len(env.vert),) indices of each environment vertex's next and previous vertex
        along its ring, -1 where the domain's rings are not stored one after the other
        (cached)."""
        got = getattr(self, "_neighbours", None)
        if got is None:
            env = self.env
            r = np.asarray(env.vert_ring)
            idx = np.arange(len(r))
            nxt = np.full(len(r), -1)
            prv = np.full(len(r), -1)
            if len(r) and (np.diff(r) >= 0).all():
                first = np.searchsorted(r, r, side="left")
                last = np.searchsorted(r, r, side="right") - 1
                n_ = np.where(idx == last, first, idx + 1)
                p_ = np.where(idx == first, last, idx - 1)
                ok_n = (env.vert[n_] == env.vert_next).all(axis=1)
                ok_p = (env.vert[p_] == env.vert_prev).all(axis=1)
                nxt[ok_n] = n_[ok_n]
                prv[ok_p] = p_[ok_p]
            got = self._neighbours = (nxt, prv)
        return got

    def _tangent_events(self, xa, ta, la, w, lb, pb, b, ii, kk) -> np.ndarray:
        """Which events can bound a shadow: the moving vertex's line is tangent to the
        target there (both ring neighbours on one side), the line through two target
        vertices has the whole target on one side and grazes the obstacle at ``b``."""
        m = self.m
        keep_a = np.ones(len(ta), dtype=bool)
        tv = xa < m
        if tv.any():
            k = xa[tv]
            r0 = self.ring0
            keep_a[tv] = _tangent(w[la[tv]], r0[(k - 1) % m] - r0[k], r0[(k + 1) % m] - r0[k])
        wt = self.ring0[kk[pb]] - self.ring0[ii[pb]]
        rel = self.ring0[None, :, :] - self.ring0[ii[pb]][:, None, :]
        side = _cross(wt[:, None, :], rel)
        zero = np.abs(side) <= 1e-9 * np.hypot(wt[:, 0], wt[:, 1])[:, None] * np.hypot(
            rel[..., 0], rel[..., 1]
        )
        one_side = ~(((side > 0) & ~zero).any(axis=1) & ((side < 0) & ~zero).any(axis=1))
        env = self.env
        cvx = self._event_corners()
        bp = env.vert_prev[cvx][lb] - b[lb]
        bn = env.vert_next[cvx][lb] - b[lb]
        graze = _tangent(wt, bp, bn)
        return np.concatenate([keep_a, one_side & graze])

    def _event_lines(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Convex obstacle corners and the pairs (i, j) of them whose joining line is
        tangent at both, with collinear neighbours counting as tangent (cached).  Unlike
        :meth:`_corners_and_tangents` the test has a tolerance: rows of collinear corners
        and flush edges are where the events are, and a bare sign test there flips with
        the rounding of the frame (fuzz seed 8103, scaled by 1e3)."""
        got = getattr(self, "_ev_lines", None)
        if got is None:
            env = self.env
            cvx = self._event_corners()
            b = env.vert[cvx]
            bp = env.vert_prev[cvx] - b
            bn = env.vert_next[cvx] - b
            i, j = np.triu_indices(len(b), 1)
            w = b[j] - b[i]
            ok = _tangent(w, bp[i], bn[i]) & _tangent(w, bp[j], bn[j])
            got = self._ev_lines = (b, i[ok], j[ok])
        return got

    def _event_corners(self) -> np.ndarray:
        """Indices of the environment vertices that anchor collinearity events: the convex
        obstacle corners that see K (:meth:`_anchors`; cached).  An event counts only when
        the line's piece spanning its anchors lies in the free space, and one of them is on
        the target, inside K, so both corners of an event line see K (up to the free
        space's ``tol_lab`` growth: a line that merely grazes an obstacle between a corner
        and K is dropped with it; measured, see docs/DESIGN.md).  On office maps most
        corners see no point of K, and the pairs of corners were most of the events' cost.
        With ``lazy_samples=False`` (the previous rules): every convex corner."""
        got = getattr(self, "_ev_corners", None)
        if got is None:
            keep = self.env.reflex & (self._anchors() if self.lazy_samples else True)
            got = self._ev_corners = np.flatnonzero(keep)
        return got

    def _free_near(self) -> shapely.Geometry:
        """The free space grown by ``tol_lab`` (cached, prepared): lines that graze
        obstacles are unobstructed."""
        got = getattr(self, "_free_grown", None)
        if got is None:
            got = self._free_grown = shapely.buffer(self.free, self.tol_lab)
            shapely.prepare(got)
        return got

    def _check_time(self) -> None:
        if self.deadline is not None and time.monotonic() > self.deadline:
            raise _Expired

    def _strips(
        self, edges: list, t: float, toward: float, q0, dq
    ) -> tuple[np.ndarray, np.ndarray]:
        """The areas the shadow edges ``edges`` (found at sample ``t``) would sweep from
        ``t`` to ``toward`` if they lived that long, as valid polygons, and per edge
        whether its ends are finite there (an edge that is not must be traced).

        Each is the strip between the paths of the edge's two ends, on the time grid of
        :meth:`_grid` (chords within ``tol`` of the paths): not the quadrilateral of
        its first and last positions.  An edge that pivots on a fixed corner while its
        far end runs out and back sweeps a fan whose first and last positions nearly
        coincide; that quadrilateral has no area, the edge was taken as swept inside the
        known shadows and not traced, and the fan was missed (fuzz seed 203869: 3.5e-8 D²
        of shadow at a configuration between samples, kept in the ``conservative=True``
        region)."""
        return self._strips_many([(edges, t, toward, q0, dq)])[0]

    def _strips_many(self, groups: list[tuple]) -> list[tuple[np.ndarray, np.ndarray]]:
        """:meth:`_strips` for each group ``(edges, t, toward, q0, dq)`` (edges not empty),
        the grids in one batch (:meth:`_grid_many`)."""
        grids = self._grid_many(
            [(e, min(t, toward), max(t, toward), q0, dq) for e, t, toward, q0, dq in groups]
        )
        rings, oks = [], []
        for _, vs, ve in grids:  # (E, T, 2) each
            ring = np.concatenate([vs, ve[:, ::-1]], axis=1)
            ok = np.isfinite(ring).all(axis=(1, 2))
            rings.append(shapely.polygons(np.where(ok[:, None, None], ring, 0.0)))
            oks.append(ok)
        polys = shapely.make_valid(np.concatenate(rings))
        at = np.cumsum([0] + [len(r) for r in rings])
        return [(polys[at[k] : at[k + 1]], ok) for k, ok in enumerate(oks)]

    def _uncovered(self, edges: list, t: float, toward: float, known, q0, dq) -> list:
        """The edges whose sweep from t to ``toward`` (assuming it lives that long)
        is not already inside ``known`` (rotating into their own shadow)."""
        if not edges:
            return []
        polys, ok = self._strips(edges, t, toward, q0, dq)
        shapely.prepare(known)
        rest = shapely.area(shapely.difference(polys, known))
        need = ~ok | (rest > 1e-9 * self.env.scale**2)
        return [e for e, n_ in zip(edges, need, strict=True) if n_]

    def _uncovered_seen(
        self, edges: list, t: float, toward: float, ab: tuple[float, float], q0, q1
    ) -> list | None:
        """:meth:`_uncovered` for the shadows ``S_a``, ``S_b`` at the sample times ``ab``
        from what they do not hold, ``X_a`` and ``X_b`` (:meth:`shadow`); None when one
        of them was not kept (the caller then unites the shadows).

        ``S_a u S_b = F - (X_a n X_b)`` (``F`` the free space), so the part of a quad
        outside the known shadows is ``(quad - F) u (quad n X_a n X_b)``: one
        intersection of the two small sets (near the region, kept for :func:`_union_pieces`)
        instead of the union of two whole-map shadows, and the small quads cut by it.
        ``quad - F`` is left out where the quad lies in ``F`` grown by ``1e-12`` of the
        scene's size (a prepared test): its area there is below ``_free_band`` (that
        width times ``F``'s perimeter), which the threshold is lowered by, so no sweep
        that :meth:`_uncovered` would trace is dropped; ``quad n X_a n X_b`` is not cut by
        ``F`` (that area is only larger)."""
        return self._uncovered_seen_many([(edges, t, toward, ab, q0, q1)])[0]

    def _uncovered_seen_many(self, items: list[tuple]) -> list[list | None]:
        """:meth:`_uncovered_seen` for each item ``(edges, t, toward, ab, q0, q1)``, the strips
        and the overlays of all items in one batch (shapely's functions act element by
        element, so each item gets what it would alone)."""
        out: list[list | None] = [None] * len(items)
        todo, inters = [], []
        for k, (edges, _, _, ab, q0, q1) in enumerate(items):
            if not edges:
                out[k] = []
                continue
            inter = self._seen_pair(*(self._frame_key(q0, q1, u) for u in ab))
            if inter is not None:
                todo.append(k)
                inters.append(inter)
        if not todo:
            return out
        got = self._strips_many(
            [
                (items[k][0], items[k][1], items[k][2], items[k][4], items[k][5] - items[k][4])
                for k in todo
            ]
        )
        polys = np.concatenate([p for p, _ in got])
        ok = np.concatenate([o for _, o in got])
        counts = [len(o) for _, o in got]
        inter = np.repeat(np.asarray(inters, dtype=object), counts)
        grown, band = self._free_grown_eps()
        rest = np.zeros(len(polys))
        idx = np.flatnonzero(ok)
        meets = shapely.intersects(inter[idx], polys[idx])
        sel = idx[meets]
        rest[sel] = shapely.area(shapely.intersection(polys[sel], inter[sel]))
        off = idx[~shapely.covers(grown, polys[idx])]
        if len(off):
            rest[off] += shapely.area(shapely.difference(polys[off], self.free))
        need = ~ok | (rest > 1e-9 * self.env.scale**2 - band)
        at = np.cumsum([0] + counts)
        for j, k in enumerate(todo):
            flags = need[at[j] : at[j + 1]]
            out[k] = [e for e, n_ in zip(items[k][0], flags, strict=True) if n_]
        return out

    @staticmethod
    def _frame_key(q0: np.ndarray, q1: np.ndarray, t: float) -> tuple[float, float]:
        """The key of the sample at time ``t`` of the sweep ``q0 -> q1`` in ``_frames``
        and ``_seen`` (as :meth:`along` computes it)."""
        q = q1 if t == 1.0 else q0 + t * (q1 - q0)
        return (float(q[0]), float(q[1]))

    def _seen_pair(self, ka: tuple, kb: tuple) -> shapely.Geometry | None:
        """``X_a n X_b`` for the samples at ``ka``, ``kb`` (snap-rounded on ``grid``,
        prepared, cached: :func:`_union_pieces` starts from these); None when one of them
        was not kept."""
        pairs = self.__dict__.setdefault("_pairs", {})
        got = pairs.get((ka, kb))
        if got is None:
            xa, xb = self._seen.get(ka), self._seen.get(kb)
            if xa is None or xb is None:
                return None
            got = pairs[(ka, kb)] = areal(snapped(shapely.intersection, xa, xb, self.grid))
            shapely.prepare(got)
        return got

    def _free_grown_eps(self) -> tuple[shapely.Geometry, float]:
        """The free space grown by ``1e-12`` of the scene's size (prepared) and a bound on
        the area of that band (the width times the free space's perimeter, doubled),
        cached."""
        got = getattr(self, "_free_eps", None)
        if got is None:
            eps = 1e-12 * self.env.scale
            grown = shapely.buffer(self.free, eps)
            shapely.prepare(grown)
            got = self._free_eps = (grown, 2.0 * eps * float(shapely.length(self.free)))
        return got

    def _cut_short(self, edges: list, ends: list, t: float, toward: float, q0, dq) -> list:
        """``(edge, t_end, toward)`` for the traced ``edges`` whose trace from ``t`` ended
        at ``t_end`` strictly between ``t`` and ``toward`` while the edge still had length
        (at least ``CUT_REL`` of its length at ``t``): not a shadow edge that shrank to a
        point, but one whose neighbouring edge died, so that its line goes on bounding the
        shadow with another neighbour (:meth:`_continuation_gap`)."""
        return self._cut_short_many([(edges, ends, t, toward, q0, dq)])[0]

    def _cut_short_many(self, items: list[tuple]) -> list[list]:
        """:meth:`_cut_short` for each item ``(edges, ends, t, toward, q0, dq)``, the ends in
        one batch."""
        out: list[list] = [[] for _ in items]
        picks = []  # (item, its indices)
        for k, (_, ends, t, toward, _, _) in enumerate(items):
            span = abs(toward - t)
            idx = [
                i for i, end in enumerate(ends)
                if end != t and abs(end - toward) > 1e-9 * span
            ]  # fmt: skip
            if idx:
                picks.append((k, idx))
        if not picks:
            return out
        rows = [len(idx) for _, idx in picks]
        sub = [items[k][0][i] for k, idx in picks for i in idx]
        te = np.array([[items[k][2], items[k][1][i]] for k, idx in picks for i in idx])
        q0, dq = _row_sweeps([items[k][4:6] for k, _ in picks], rows)
        vs, ve = self._ends_many(sub, te, q0, dq)
        ln = np.hypot(*np.moveaxis(ve - vs, -1, 0))  # (E, 2): at t and at the end
        long_ = np.isfinite(ln).all(axis=1) & (ln[:, 1] > CUT_REL * ln[:, 0])
        r = 0
        for k, idx in picks:
            edges, ends, _, toward = items[k][:4]
            for i in idx:
                if long_[r]:
                    out[k].append((edges[i], ends[i], toward))
                r += 1
        return out

    def _not_point(self, edges: list, t: float, q0, dq) -> list:
        """The ``edges`` longer than ``1e-6`` of the scene's size at time ``t``: a shadow
        edge that is a point there (its neighbours' lines meet on its own) sweeps nothing
        in any configuration and tells nothing of the line's other configurations."""
        return self._not_point_many([(edges, t, q0, dq)])[0]

    def _not_point_many(self, items: list[tuple]) -> list[list]:
        """:meth:`_not_point` for each item ``(edges, t, q0, dq)``, the ends in one batch."""
        out: list[list] = [[] for _ in items]
        live = [k for k, it in enumerate(items) if it[0]]
        if not live:
            return out
        rows = [len(items[k][0]) for k in live]
        ts = np.concatenate([np.full((r, 1), items[k][1]) for k, r in zip(live, rows, strict=True)])
        q0, dq = _row_sweeps([items[k][2:4] for k in live], rows)
        vs, ve = self._ends_many([e for k in live for e in items[k][0]], ts, q0, dq)
        ln = np.hypot(*np.moveaxis(ve[:, 0] - vs[:, 0], -1, 0))
        long_ = ln > 1e-6 * self.env.scale
        at = np.cumsum([0] + rows)
        for j, k in enumerate(live):
            flags = long_[at[j] : at[j + 1]]
            out[k] = [e for e, n_ in zip(items[k][0], flags, strict=True) if n_]
        return out

    def _continuation_gap(self, cut: list, traced: dict, probed: list, q0, dq) -> float | None:
        """A time just after a trace was cut short (:meth:`_cut_short`) at ``t_end``
        where the cut edge's line still bounds a shadow and no trace of that line has
        reached (nor an edge on it found swept inside the known shadows,
        :meth:`_not_point`, or one that the exact point test does not confirm even at
        its own sample: see :meth:`_coverage_gap`), or None.

        When a neighbouring edge dies, the edge's line goes on bounding the shadow with
        another neighbour from ``t_end`` on, and that configuration can be born and gone
        between two samples (the line's edge at the next sample, if any, then has other
        neighbours, or has collapsed; fuzz seed 204155: a sliver shadow 0.014 D long,
        missed at every sample).  A sample a tenth of the way from ``t_end`` to the next
        sample finds it and traces it both ways.  It is taken where the exact point test
        confirms, at that time, a twentieth of the cut edge at either end (the end whose
        neighbour lives on is still right, and the new edge runs from it): a line that
        bounds no shadow there has no continuation.  Each death (``probed``: key and
        time, within ``1e-6`` of the sweep) is looked at once."""
        todo = []
        for edge, t_end, toward in cut:
            key = edge[1]
            lo, hi = min(t_end, toward), max(t_end, toward)
            if hi - lo <= 1e-6 or any(k == key and abs(t - t_end) <= 1e-6 for k, t in probed):
                continue
            probed.append((key, t_end))
            iv = sorted(
                (max(x, lo), min(y, hi)) for x, y in traced.get(key, []) if y > lo and x < hi
            )
            # is the time just after t_end (towards ``toward``) held by no trace?
            if toward > t_end:
                free = not iv or iv[0][0] > lo + 1e-9
            else:
                free = not iv or iv[-1][1] < hi - 1e-9
            if free:
                todo.append((edge, t_end + 0.1 * (toward - t_end)))
        if not todo:
            return None
        tp = np.array([[t] for _, t in todo])
        vs, ve = self._ends_many([e for e, _ in todo], tp, q0, dq)  # (E, 1, 2) each
        d = 0.05 * (ve - vs)
        near = self._valid_many(
            np.concatenate([vs, ve - d]), np.concatenate([vs + d, ve]), np.vstack([tp, tp]), q0, dq
        )[:, 0]
        finite = np.isfinite(d).all(axis=(1, 2))
        go = ~finite | near[: len(todo)] | near[len(todo) :]
        return float(tp[np.argmax(go), 0]) if go.any() else None

    def _coverage_gap(
        self, ea: list, eb: list, cover: dict, a: float, b: float, confirmed: set
    ) -> float | None:
        """A time in (a, b) where a moving line that carries confirmed shadow edges at
        both a and b has not been traced (an edge configuration born and gone between
        the samples), or None.  A line whose edge at a or b the exact point test does
        not confirm even at its own sample (e.g. an edge inside K, where the test sees
        no shadow) cannot be covered by tracing, and bisecting for it only multiplied
        the samples (fuzz seed 507801: 157 refinements, 15 s)."""
        span = b - a
        for key in {e[1] for e in ea} & {e[1] for e in eb}:
            if (a, key) not in confirmed or (b, key) not in confirmed:
                continue
            iv = sorted(
                (max(lo, a), min(hi, b)) for lo, hi in cover.get(key, []) if hi > a and lo < b
            )
            reach = a
            for lo, hi in iv:
                if lo > reach + 1e-9 * span:
                    return 0.5 * (reach + lo)
                reach = max(reach, hi)
            if reach < b - 1e-9 * span:
                return 0.5 * (reach + b)
        return None

    def _refine_births_many(
        self, runs: list[_Run], ts_all: list[list], first: tuple | None = None
    ) -> None:
        """Add sample times (to each run's frames) where the eroded target's shadow has a
        component that neither neighbouring sample's shadow meets (a shadow born and dying in
        between, :meth:`_born`); bisect up to ``max_depth`` times.  An interval without an
        eroded target is bounded by the union of its pieces' eroded targets' shadows where
        halving it at most ``max_split`` times gives each piece one (lazy rule,
        :meth:`_split_shadow`; a component of that union apart from both ends' shadows is
        bisected as before), else bisected where an eroded target exists within the depth
        limit (:meth:`_core_within_depth`).  With
        overlap strips (5.2) the eroded
        target's whole outline counts as wanted: its shadow bounds the full target's
        shadows, which the 5.2 shadows contain, so a shadow of the full target born in
        between is caught here too (and the 5.2 region stays inside R(G); fuzz seed 411063,
        mixed G/H).  Births of shadows that exist only because pieces are unwanted are not
        detected by it.  ``runs``: the segments, ``ts_all``: their sample times so far;
        ``first``: :meth:`_birth_bounds` of the first level when the caller has it."""
        todo = [
            (r, a, b, 0)
            for r, ts in zip(runs, ts_all, strict=True)
            for a, b in zip(ts[:-1], ts[1:], strict=True)
        ]
        # level by level, over all segments (each decision depends on its interval alone, so
        # the order does not matter): the eroded targets' regions of a level, then its new
        # samples, are computed in one batch each
        while todo:
            self._check_time()
            level = [(r, a, b, depth) for r, a, b, depth in todo if depth < self.max_depth]
            pairs, split = first if first is not None else self._birth_bounds(level)
            first = None
            self._prefetch([], pairs + [p for ps in split.values() for p in ps])
            todo, mids = [], []
            for i, (r, a, b, depth) in enumerate(level):
                self._check_time()
                if i in split:
                    upper = self._split_shadow(split[i])
                else:
                    upper = self._eroded_shadow(*pairs[i])
                if upper is None:
                    # no eroded target: bisect where one exists within the depth limit
                    new = self._core_within_depth(b - a, depth, r.dq)
                else:
                    new = len(self._born(upper, r.frame(a)[0], r.frame(b)[0])) > 0
                if new:
                    mids.append((r, a, 0.5 * (a + b), b, depth))
            self._prefetch([r.q0 + m * r.dq for r, _, m, _, _ in mids])
            for r, a, m, b, depth in mids:
                r.frame(m)
                r.stats["refined"] += 1
                todo += [(r, a, m, depth + 1), (r, m, b, depth + 1)]

    def _birth_bounds(self, level: list[tuple]) -> tuple[list, dict[int, list]]:
        """For the intervals ``level`` ((run, a, b, depth) each) of the birth check: their
        ends ``(qa, qb)``, and for those (by index) without an eroded target whose pieces
        after ``k <= max_split`` halvings have one (lazy rule), the pieces' ends.  An interval
        without an eroded target (the target moves further than its own thickness) is
        bounded by the eroded targets of its pieces; the previous rule bisects it with
        samples."""
        pairs = [(r.q0 + a * r.dq, r.q0 + b * r.dq) for r, a, b, _ in level]
        split: dict[int, list] = {}
        if self.lazy_samples:
            for i, ((r, a, b, depth), (qa, qb)) in enumerate(zip(level, pairs, strict=True)):
                if self._eroded_core(qa, qb) is None:
                    k = self._split_depth(b - a, depth, r.dq)
                    if k is None or k > self.max_split:
                        continue  # bisect with samples (or not at all, as before)
                    ts = np.linspace(a, b, 2**k + 1)
                    qs = [r.q0 + t * r.dq for t in ts]
                    split[i] = list(zip(qs[:-1], qs[1:], strict=False))
        return pairs, split

    def _born(
        self, upper: shapely.Geometry, sa: shapely.Geometry, sb: shapely.Geometry
    ) -> np.ndarray:
        """The parts of the upper bound ``upper`` of the shadows over an interval that meet
        neither end's shadow (``sa``, ``sb``): where a shadow may be born and gone in between.
        With the lazy rules, parts narrower than the union's snap grid (twice their area over
        their perimeter) do not count: they are rounding (heidelberg_l2: a sliver 6e-16 D wide,
        a few ulps of its coordinates), and the union's snap-rounding would collapse such a
        shadow into a line anyway."""
        parts = shapely.get_parts(upper)
        parts = parts[~shapely.is_empty(parts)]  # an empty shadow: no new component
        if self.lazy_samples:
            parts = parts[2.0 * shapely.area(parts) > self.grid * shapely.length(parts)]
        # meets the union of the two shadows = meets one of them (no overlay)
        meets = shapely.intersects(parts, sa) | shapely.intersects(parts, sb)
        return parts[~meets]

    def _core_within_depth(self, span: float, depth: int, dq: np.ndarray) -> bool:
        """Whether the target has a non-empty eroded part (:meth:`_eroded_core`) over the
        shortest interval the birth check still examines below an interval ``span`` long (in
        t) at ``depth``: ``span / 2**(max_depth - 1 - depth)`` (the check looks at depths
        below ``max_depth``).  Where it has none even there (a sliver moving across its own
        thickness), bisecting cannot give the check an upper bound to test with, only
        samples.  Always True with ``lazy_samples=False`` (the previous rule)."""
        if not self.lazy_samples:
            return True
        if depth >= self.max_depth - 1:
            return False
        step = math.ldexp(span, depth + 1 - self.max_depth)
        return self._eroded_core(np.zeros(2), step * dq) is not None

    def _eroded_shadow(self, qa: np.ndarray, qb: np.ndarray) -> shapely.Geometry | None:
        """Shadow of the part of A common to all A_q, q in [qa, qb] (it contains
        every S(q) there); None when that part is empty."""
        seen = self._eroded_seen(qa, qb)
        if seen is None:
            return None
        return polygonal(snapped(shapely.difference, self.free, seen, self.shadow_grid))

    def _eroded_seen(self, qa: np.ndarray, qb: np.ndarray) -> shapely.Geometry | None:
        """The placements that see the part of A common to all A_q, q in [qa, qb], or lie in
        it (that part and its weak visibility region, snap-rounded); None when it is empty."""
        got = self._eroded_core(qa, qb)
        if got is None:
            return None
        core, ring = got
        reg = self._eroded_pre.pop((tuple(qa.tolist()), tuple(qb.tolist())), None)
        if reg is None:
            reg = weak_visibility(
                self.env, ring, np.ones(len(ring), dtype=bool), self.eps_aim, self._anchors()
            )
        g = self.shadow_grid  # as in shadow(): the region's hole nearly coincides with core
        # snap-rounding can raise "Ring edge missing" at scale 1e-3 (fuzz seed 201039, --swept)
        return areal(snapped(shapely.union, reg, core, g))

    def _split_shadow(self, pieces: list[tuple[np.ndarray, np.ndarray]]) -> shapely.Geometry:
        """The union of the eroded targets' shadows (:meth:`_eroded_shadow`) of the
        sub-intervals ``pieces`` ((qa, qb) each, every one with an eroded target): it contains
        every S(q) of their union.  As in :func:`_union_pieces`, the free space minus the
        intersection of what they do not hold."""
        g = self.shadow_grid
        xs = [self._eroded_seen(qa, qb) for qa, qb in pieces]
        while len(xs) > 1:
            pairs = zip(xs[0::2], xs[1::2], strict=False)  # an odd one out waits a round
            nxt = [areal(snapped(shapely.intersection, a, b, g)) for a, b in pairs]
            xs = nxt + xs[len(nxt) * 2 :]
        return polygonal(snapped(shapely.difference, self.free, xs[0], g))

    def _split_depth(self, span: float, depth: int, dq: np.ndarray) -> int | None:
        """The fewest halvings ``k >= 1`` of an interval ``span`` long (in t) at ``depth``
        after which the target has an eroded part over each piece, with ``depth + k`` below
        ``max_depth`` (the deepest the birth check looks); None when there is none."""
        for k in range(1, self.max_depth - depth):
            if self._eroded_core(np.zeros(2), math.ldexp(span, -k) * dq) is not None:
                return k
        return None

    def _eroded_core(self, qa: np.ndarray, qb: np.ndarray) -> tuple | None:
        """The part of A common to all A_q, q in [qa, qb] (its largest piece) and its
        outline (clockwise), or None when it is empty (:meth:`_eroded_shadow`); kept per
        interval (the batch of :meth:`_prefetch` and the check ask for the same)."""
        key = (tuple(qa.tolist()), tuple(qb.tolist()))
        cache = self.__dict__.setdefault("_cores", {})
        if key not in cache:
            cache[key] = self._eroded_core_of(qa, qb)
        return cache[key]

    def _eroded_core_of(self, qa: np.ndarray, qb: np.ndarray) -> tuple | None:
        aa = shapely.Polygon(self.ring0 + qa)
        ab = shapely.Polygon(self.ring0 + qb)
        core = shapely.intersection(aa, ab)
        if not (self._convex and self.lazy_samples):  # the previous rules: as they were
            # a point of A_qa n A_qb that an edge sweeps over in between leaves A_q there
            r = self.ring0 + qa
            e = np.roll(r, -1, axis=0)
            d = qb - qa
            par = shapely.polygons(np.stack([r, e, e + d, r + d], axis=1))
            core = shapely.difference(core, union_all(par))
        core = polygonal(core)
        if core.is_empty:
            return None
        parts = shapely.get_parts(core)
        core = parts[np.argmax(shapely.area(parts))]
        ring = np.asarray(shapely.orient_polygons(core, exterior_cw=True).exterior.coords)[:-1]
        return core, ring

    def _trace_many(self, edges: list, ta: float, tb: float, q0, dq) -> tuple[list, list]:
        """Areas swept by moving shadow edges found at sample ``ta`` while they live
        between ``ta`` and ``tb``; returns ``(quads, end time reached per edge)``."""
        return self._trace_groups([(edges, ta, tb, q0, dq)])[0]

    def _trace_groups(self, groups: list[tuple]) -> list[tuple[list, list]]:
        """:meth:`_trace_many` for each group ``(edges, ta, tb, q0, dq)`` (edges of the sweep
        ``q0 + t dq``), in one batch: the time grids are each group's own (:meth:`_grid`),
        padded with their last column to a common length, and every row carries its sweep
        (the exact point test tests equal rows once, and every step decides row by row), so
        each group gets what it would alone."""
        out: list[tuple[list, list]] = [([], []) for _ in groups]
        live = [g for g, grp in enumerate(groups) if grp[0]]
        if not live:
            return out
        grids = self._grid_many([groups[g] for g in live])
        width = max(len(ts) for ts, _, _ in grids)

        def pad(x: np.ndarray) -> np.ndarray:
            return np.concatenate([x, np.repeat(x[:, -1:], width - x.shape[1], axis=1)], axis=1)

        rows = [len(groups[g][0]) for g in live]
        ts = np.concatenate(
            [np.repeat(pad(g[0][None, :]), n, axis=0) for g, n in zip(grids, rows, strict=True)]
        )
        vs = np.concatenate([pad(v) for _, v, _ in grids])
        ve = np.concatenate([pad(v) for _, _, v in grids])
        n_t = np.repeat([len(t) for t, _, _ in grids], rows)  # each row's own grid length
        q0, dq = _row_sweeps([groups[g][3:5] for g in live], rows)
        ok = self._valid_many(vs, ve, ts, q0, dq) | (np.arange(width)[None, :] >= n_t[:, None])
        n_ok = np.where(ok.all(axis=1), n_t, np.argmin(ok, axis=1))
        edges = [e for g in live for e in groups[g][0]]
        # bisect the death time of the edges that die inside their interval
        dying = np.flatnonzero((n_ok > 0) & (n_ok < n_t))
        t_end = ts[np.arange(len(edges)), n_t - 1].astype(float)
        if len(dying):
            t_ok = ts[dying, n_ok[dying] - 1].astype(float)
            t_bad = ts[dying, n_ok[dying]].astype(float)
            sub = [edges[i] for i in dying]
            q0d, dqd = q0[dying], dq[dying]
            t_ok, t_bad = self._bisect(sub, t_ok, t_bad, q0d, dqd)
            t_end[dying] = t_ok
            # the ends at the death times in one batch (those on the grid are vs, ve)
            da, db = self._ends_many(sub, t_end[dying][:, None], q0d, dqd)
            if self.lazy_samples:  # the death's band: see _past_death
                ba, bb = self._ends_many(sub, t_bad[:, None], q0d, dqd)
                late = self._past_death(da, db, ba, bb)
                t_end[dying[late]] = t_bad[late]
                da[late], db[late] = ba[late], bb[late]
        quads: list[list] = [[] for _ in live]
        first = np.cumsum([0] + rows)
        for k, g in enumerate(live):
            ta, ends = groups[g][1], out[g][1]
            for i in range(first[k], first[k + 1]):
                n = int(n_ok[i])
                if n == 0:
                    ends.append(ta)
                    continue
                a, b = vs[i, :n], ve[i, :n]
                if n < n_t[i]:
                    j = int(np.searchsorted(dying, i))
                    a, b = np.vstack([a, da[j]]), np.vstack([b, db[j]])
                ends.append(float(ts[i, n - 1]) if n == n_t[i] else float(t_end[i]))
                if len(a) < 2:
                    continue
                quads[k].append(np.stack([a[:-1], a[1:], b[1:], b[:-1]], axis=1))
        counts = [sum(len(x) for x in qs) for qs in quads]
        if not sum(counts):
            return out
        polys = shapely.polygons(np.concatenate([x for qs in quads for x in qs]))
        bad = ~shapely.is_valid(polys)
        if bad.any():
            polys[bad] = shapely.make_valid(polys[bad])
        at = np.cumsum([0] + counts)
        for k, g in enumerate(live):
            out[g] = (list(polys[at[k] : at[k + 1]]), out[g][1])
        return out

    def _past_death(
        self, da: np.ndarray, db: np.ndarray, ba: np.ndarray, bb: np.ndarray
    ) -> np.ndarray:
        """(E,) bool: which traces of dying edges are carried on from the last time found
        valid (ends ``da``, ``db``, (E, 1, 2) each) to the first time found not valid (ends
        ``ba``, ``bb``): those whose two ends move by at most ``tol / 4`` in between (lazy
        rules).

        The quad added is a band that narrow along the edge, so the traced shadow grows by
        no more than that (on the safe side); in exchange, where a line's edge changes
        neighbours at an instant (three lines concurrent), the traces from both sides meet
        or overlap instead of leaving a gap of one bisection step, which
        :meth:`_coverage_gap` and :meth:`_continuation_gap` took for a configuration born
        and gone there and resolved with a full sample (``lse_arena``'s 5.2 query: 2 of its
        7 samples)."""
        move = np.maximum(
            np.hypot(*np.moveaxis(ba - da, -1, 0)), np.hypot(*np.moveaxis(bb - db, -1, 0))
        )[:, 0]
        return np.isfinite(move) & (move <= 0.25 * self.tol)

    def _bisect(
        self, edges: list, t_ok: np.ndarray, t_bad: np.ndarray, q0, dq
    ) -> tuple[np.ndarray, np.ndarray]:
        """``bisect_steps`` bisection steps on the death time of each edge (valid at
        ``t_ok``, not at ``t_bad``): the last time found valid and the first found not.

        The steps run in rounds of up to ``BISECT_LEVELS``: a round tests, in one batch,
        the midpoints of every interval that the next levels of the bisection can reach
        (2**levels - 1 per edge), then follows each edge's path through them.  The times
        tested on the path and their outcomes are those of the steps one at a time
        (validity is decided row by row), so the answer is the same; the exact point
        test runs once per round instead of once per step.

        With the lazy rules an edge leaves the bisection once its two ends move by at most
        ``tol / 4`` from ``t_ok`` to ``t_bad`` (:meth:`_past_death`: its trace is then carried
        on to ``t_bad``, and a finer death time would move the trace's end by less than
        that); the previous rules take all the steps."""
        t_ok, t_bad = np.array(t_ok, dtype=float), np.array(t_bad, dtype=float)
        active = np.arange(len(edges))
        steps = self.bisect_steps
        while steps > 0:
            if self.lazy_samples:
                sub = [edges[i] for i in active]
                ta, tb = self._ends_many(
                    sub,
                    np.stack([t_ok[active], t_bad[active]], axis=1),
                    _rows(q0, active),
                    _rows(dq, active),
                )
                active = active[~self._past_death(ta[:, :1], tb[:, :1], ta[:, 1:], tb[:, 1:])]
            if not len(active):
                break
            sub = [edges[i] for i in active]
            ok, bad = t_ok[active], t_bad[active]
            rows = np.arange(len(active))
            levels = min(BISECT_LEVELS, steps)
            lo, hi = ok[:, None], bad[:, None]
            mids = []
            for _ in range(levels):  # node j's children: 2j (not valid), 2j + 1 (valid)
                mid = 0.5 * (lo + hi)
                mids.append(mid)
                lo = np.stack([lo, mid], axis=-1).reshape(len(active), -1)
                hi = np.stack([mid, hi], axis=-1).reshape(len(active), -1)
            tm = np.concatenate(mids, axis=1)  # (E, 2**levels - 1), level by level
            q0a, dqa = _rows(q0, active), _rows(dq, active)
            a, b = self._ends_many(sub, tm, q0a, dqa)
            good = self._valid_many(a, b, tm, q0a, dqa)
            node = np.zeros(len(active), dtype=np.int64)
            first = 0
            for level in range(levels):
                col = first + node
                g, t = good[rows, col], tm[rows, col]
                ok = np.where(g, t, ok)
                bad = np.where(g, bad, t)
                first += 2**level
                node = 2 * node + g
            t_ok[active], t_bad[active] = ok, bad
            steps -= levels
        return t_ok, t_bad

    def _ends(self, edge, ts: np.ndarray, q0, dq) -> tuple[np.ndarray, np.ndarray]:
        """Start and end points of one shadow edge at times ``ts``."""
        a, b = self._ends_many([edge], np.asarray(ts)[None, :], q0, dq)
        return a[0], b[0]

    def _ends_many(self, edges: list, ts: np.ndarray, q0, dq) -> tuple[np.ndarray, np.ndarray]:
        """Start and end points of shadow edges (E) at times ``ts`` (E, T) or (1, T)."""
        k = np.asarray(edges, dtype=np.int64)  # (E, 3, 2)
        ts = np.broadcast_to(ts, (len(edges), ts.shape[-1]))
        q = q0 + ts[..., None] * dq  # (E, T, 2)
        ids = np.broadcast_to(k[:, None, :, :], (len(edges), ts.shape[1], 3, 2))
        qq = np.broadcast_to(q[:, :, None, None, :], ids.shape + (2,))
        p = self.pos(ids.reshape(-1), qq.reshape(-1, 2)).reshape(ids.shape + (2,))
        lp, le, ln_ = p[:, :, 0], p[:, :, 1], p[:, :, 2]
        return _meet(lp[..., 0, :], lp[..., 1, :], le[..., 0, :], le[..., 1, :]), _meet(
            le[..., 0, :], le[..., 1, :], ln_[..., 0, :], ln_[..., 1, :]
        )

    def _grid(self, edges: list, a: float, b: float, q0, dq) -> tuple[np.ndarray, ...]:
        """Times from a to b so fine that the traced polylines stay within tol, and the
        ends of every edge at those times (:meth:`_ends_many`, (E, T, 2) each)."""
        return self._grid_many([(edges, a, b, q0, dq)])[0]

    def _grid_many(self, groups: list[tuple]) -> list[tuple[np.ndarray, ...]]:
        """:meth:`_grid` for each group ``(edges, a, b, q0, dq)`` (edges of the sweep ``q0 + t
        dq``, not empty): the groups still refining take each step together (one
        :meth:`_ends_many` call, each row with its own times and sweep), so each gets what
        it would alone."""
        out: list[tuple[np.ndarray, ...]] = [() for _ in groups]
        todo = list(range(len(groups)))
        n = 9
        while todo:
            rows = [len(groups[g][0]) for g in todo]
            tss = [np.linspace(groups[g][1], groups[g][2], n) for g in todo]
            # the ends at the grid times and at the midpoints in one call (row by row)
            times = np.concatenate(
                [
                    np.repeat(np.concatenate([ts, 0.5 * (ts[:-1] + ts[1:])])[None, :], r, axis=0)
                    for ts, r in zip(tss, rows, strict=True)
                ]
            )
            q0, dq = _row_sweeps([groups[g][3:5] for g in todo], rows)
            both = self._ends_many([e for g in todo for e in groups[g][0]], times, q0, dq)
            ends = [c[:, :n] for c in both]
            err = np.zeros(len(times))  # per row: the largest finite deviation of a chord
            for c, m in zip(ends, (c[:, n:] for c in both), strict=True):
                chord = c[:, 1:] - c[:, :-1]
                ln = np.hypot(chord[..., 0], chord[..., 1])
                with np.errstate(divide="ignore", invalid="ignore"):
                    dev = np.where(ln > 0, np.abs(_cross(chord, m - c[:, :-1])) / ln, 0.0)
                err = np.maximum(err, np.where(np.isfinite(dev), dev, 0.0).max(axis=1))
            at = np.cumsum([0] + rows)
            left = []
            for k, g in enumerate(todo):
                if float(err[at[k] : at[k + 1]].max()) <= self.tol or n >= 257:
                    out[g] = (tss[k], ends[0][at[k] : at[k + 1]], ends[1][at[k] : at[k + 1]])
                else:
                    left.append(g)
            todo = left
            n = 2 * n - 1
        return out

    def _between_lines(self, vs: np.ndarray, d: np.ndarray, ts: np.ndarray, q0, dq) -> np.ndarray:
        """Fractions along each edge (E, T, K) between consecutive crossings of the
        lines that can bound a visible beam: through a convex obstacle corner and a
        target vertex, or through two convex obstacle corners.  Between two such
        crossings blindness along the edge does not change.

        Only the corners that see K count, and of the lines through two corners only
        those that meet K (:meth:`_corners_and_tangents`): a beam from p into K that a
        corner bounds runs on from the corner into K unobstructed.  The other lines
        cannot change what p sees of the target, so dropping them only merges intervals
        on which blindness is constant anyway."""
        if not self.env.reflex.any():
            return np.full(vs.shape[:-1] + (0,), np.nan)
        b, bp, bn, i, j = self._corners_and_tangents()
        a = self.ring0[None, None, :, :] + (q0 + ts[..., None] * dq)[..., None, :]  # (E, T, m, 2)
        w = a[..., None, :, :] - b[None, None, :, None, :]  # (E, T, R, m, 2)
        rel = b[None, None, :, None, :] - vs[..., None, None, :]
        dd = d[..., None, None, :]
        # only lines tangent to the obstacle at b can bound a beam
        tangent = _cross(w, bp[None, None, :, None, :]) * _cross(w, bn[None, None, :, None, :]) >= 0
        with np.errstate(divide="ignore", invalid="ignore"):
            s1 = np.where(tangent, _cross(rel, w) / _cross(dd, w), np.nan)
            s1 = s1.reshape(vs.shape[:-1] + (-1,))
            wf = (b[j] - b[i])[None, None]
            relf = b[i][None, None] - vs[..., None, :]
            s2 = _cross(relf, wf) / _cross(d[..., None, :], wf)
            # lines through two target vertices (a non-convex target hiding itself)
            ii, jj = np.triu_indices(self.m, 1)
            wt = (self.ring0[jj] - self.ring0[ii])[None, None]
            relt = a[..., ii, :] - vs[..., None, :]
            s3 = _cross(relt, wt) / _cross(d[..., None, :], wt)
            # the free space's boundary: a probe lands in every piece of the edge that runs
            # through an obstacle (off the map: not blind), as the lines dropped above
            # happened to make it land there
            sg = self.env.seg
            s0, sd = sg[:, :2], sg[:, 2:] - sg[:, :2]
            rel4 = s0 - vs[..., None, :]
            den = _cross(d[..., None, :], sd)
            s4 = _cross(rel4, sd) / den
            u4 = _cross(rel4, d[..., None, :]) / den
            s4 = np.where((u4 >= 0.0) & (u4 <= 1.0), s4, np.nan)
        return _between(np.concatenate([s1, s2, s3, s4], axis=-1))

    def _corners_and_tangents(self) -> tuple[np.ndarray, ...]:
        """Convex obstacle corners that see K, their edge vectors to the previous and
        next boundary vertex, and the pairs (i, j) of them whose joining line is tangent
        to the obstacles at both and meets K (cached; "see" and "meet" within 1e-6 of the
        scene's size, generous: a corner too many only adds probes).  K is obstacle-free
        and holds every A_q, so a corner that sees no point of K never grazes a beam from
        a placement into the target."""
        got = getattr(self, "_tangents", None)
        if got is None:
            env = self.env
            sees = self._anchors()
            b = env.vert[sees]
            bp = env.vert_prev[sees] - b
            bn = env.vert_next[sees] - b
            i, j = np.triu_indices(len(b), 1)
            w = b[j] - b[i]
            ok = (_cross(w, bp[i]) * _cross(w, bn[i]) >= 0) & (
                _cross(w, bp[j]) * _cross(w, bn[j]) >= 0
            )
            # coincident corners (a pinch) span no line: their crossings are NaN anyway
            ok &= np.hypot(w[:, 0], w[:, 1]) > 0
            i, j = i[ok], j[ok]
            if len(i):  # the line through the two corners meets K
                u = w[ok] / np.hypot(w[ok, 0], w[ok, 1])[:, None]
                r = 4.0 * env.scale  # both corners and K lie within the scene's size
                lines = shapely.linestrings(np.stack([b[i] - r * u, b[i] + r * u], axis=1))
                near = shapely.dwithin(lines, self._hull_poly, 1e-6 * env.scale)
                i, j = i[near], j[near]
            got = self._tangents = (b, bp, bn, i, j)
        return got

    def _anchors(self) -> np.ndarray:
        """(len(env.vert),) bool: the convex obstacle corners (reflex vertices of the free
        space) that see some point of K: within 1e-6 of the scene's size of K or of the
        weak visibility region of K's outline (cached).  K holds every A_q, so the other
        corners see no target: they are no grazing anchors of any stationary shadow
        (:func:`~geometry.weak.weak_visibility`'s ``grazing``) and bound no beam into it."""
        got = getattr(self, "_anchor_mask", None)
        if got is None:
            env = self.env
            got = np.zeros(len(env.vert), dtype=bool)
            idx = np.flatnonzero(env.reflex)
            if len(idx):
                if self.lazy_samples:
                    # the corners whose rays towards K reach it (no fans, no union)
                    got = corners_seeing(env, self.hull[::-1])
                    near = shapely.dwithin(
                        self._hull_poly, shapely.points(env.vert[idx]), 1e-6 * env.scale
                    )
                    got[idx[near]] = True
                else:
                    ring = self.hull[::-1]  # clockwise: a hole of the domain
                    seen = weak_visibility(env, ring, np.ones(len(ring), dtype=bool))
                    seen = shapely.union(seen, self._hull_poly)
                    pts = shapely.points(env.vert[idx])
                    got[idx] = shapely.dwithin(seen, pts, 1e-6 * env.scale)
            self._anchor_mask = got
        return got

    def _valid_many(self, vs: np.ndarray, ve: np.ndarray, ts: np.ndarray, q0, dq) -> np.ndarray:
        """(E, T) bool: the traced edge is a shadow edge at that time (exact point
        test on probes just inside the shadow along the edge).

        The probes are tested in two rounds: the ends and the fixed fractions first,
        then the probes between the crossings of :meth:`_between_lines` (hundreds per
        edge on maps of a few hundred edges) only where the first round found every
        probe blind.  An edge is valid iff all its probes are blind, so the answer is
        the same as testing them all at once."""
        d = ve - vs
        ln = np.hypot(d[..., 0], d[..., 1])
        with np.errstate(divide="ignore", invalid="ignore"):
            u = d / ln[..., None]
        h = np.minimum(self.h, 0.05 * ln)[..., None]
        nrm = _rot(u) * (1e-3 * h)
        edge_h = (h[..., 0] / np.where(ln > 0, ln, 1.0))[..., None]
        q = q0 + ts[..., None] * dq  # (E, T, 2)
        fr = np.broadcast_to(np.arange(1, self.probes) / self.probes, ln.shape + (self.probes - 1,))
        fr = np.clip(fr, edge_h, 1 - edge_h)  # ends: probed below
        ends = np.stack([vs + h * u + nrm, ve - h * u + nrm], axis=-2)
        inner = vs[..., None, :] + fr[..., None] * d[..., None, :] + nrm[..., None, :]
        ok = self._probes_blind(np.concatenate([ends, inner], axis=-2), q) & (ln > 0)
        if ok.any():
            vs2, d2, q2 = vs[ok][:, None], d[ok][:, None], q[ok][:, None]
            q0k = np.broadcast_to(q0, q.shape)[ok][:, None]  # each row's sweep
            dqk = np.broadcast_to(dq, q.shape)[ok][:, None]
            fb = self._between_lines(vs2, d2, np.asarray(ts)[ok][:, None], q0k, dqk)
            eh = edge_h[ok][:, None]
            fb = np.clip(np.where(np.isfinite(fb), fb, 0.5), eh, 1 - eh)
            more = vs2[..., None, :] + fb[..., None] * d2[..., None, :] + nrm[ok][:, None, None, :]
            ok[ok] = self._probes_blind(more, q2)[:, 0]
        return ok

    def _probes_blind(self, probes: np.ndarray, q: np.ndarray) -> np.ndarray:
        """(...) bool: every probe ``probes`` (..., P, 2) is blind to the target at
        ``q`` (..., 2) (a probe that is not finite is not blind)."""
        qq = np.broadcast_to(q[..., None, :], probes.shape)
        flat_p, flat_q = probes.reshape(-1, 2), qq.reshape(-1, 2)
        finite = np.isfinite(flat_p).all(axis=1)
        res = np.zeros(len(flat_p), dtype=bool)
        res[finite] = self.blind(flat_p[finite], flat_q[finite])
        return res.reshape(probes.shape[:-1]).all(axis=-1)


def _row_sweeps(sweeps: list, rows: list[int]) -> tuple[np.ndarray, np.ndarray]:
    """Per-row sweeps for a batch: ``(q0, dq)`` of each group of ``sweeps`` repeated over
    its ``rows``, as (E, 1, 2) arrays (:meth:`Sweeper._ends_many` and the point tests take
    them where they take one sweep's (2,) vectors)."""
    return tuple(
        np.concatenate(
            [np.repeat(sw[c][None, None, :], r, axis=0) for sw, r in zip(sweeps, rows, strict=True)]
        )
        for c in (0, 1)
    )  # type: ignore[return-value]


def _pairs(ts: list[float]) -> list[tuple[float, float]]:
    """Consecutive pairs ``(ts[i], ts[i + 1])`` of a sorted list of times."""
    return list(zip(ts[:-1], ts[1:], strict=True))


def _rows(x: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """Rows ``idx`` of a per-row array ``x`` (E, 1, 2), or ``x`` itself when it is one row
    for all (2,)."""
    return x if x.ndim == 1 else x[idx]


def _tangent(w: np.ndarray, bp: np.ndarray, bn: np.ndarray, rel: float = 1e-9) -> np.ndarray:
    """Row by row: does the line of direction ``w`` through a corner keep the corner's
    two edges (``bp``, ``bn``: from the corner to its neighbours) on one side?  An edge
    within ``rel`` (relative sine) of the line counts as on it, i.e. on either side."""
    cp, cn = _cross(w, bp), _cross(w, bn)
    lw = np.hypot(w[..., 0], w[..., 1])
    zp = np.abs(cp) <= rel * lw * np.hypot(bp[..., 0], bp[..., 1])
    zn = np.abs(cn) <= rel * lw * np.hypot(bn[..., 0], bn[..., 1])
    return zp | zn | (cp * cn > 0)


def _between(s: np.ndarray) -> np.ndarray:
    """Midpoints between consecutive sorted values of ``s`` (..., L) inside (0, 1);
    NaN-padded to the largest count."""
    s = np.where((s > 0) & (s < 1), s, np.nan)
    s = np.sort(s, axis=-1)  # NaN last
    k = int(np.max(np.sum(np.isfinite(s), axis=-1), initial=0))
    if k == 0:
        return np.full(s.shape[:-1] + (0,), np.nan)
    s = s[..., :k]
    return 0.5 * (s[..., 1:] + s[..., :-1]) if k > 1 else np.full(s.shape[:-1] + (0,), np.nan)


def _overlaps(a_lo, a_hi, a_own, b_lo, b_hi, b_own, n: int, eps: float = 1e-12) -> np.ndarray:
    """(n,) bool: does some interval of family a overlap (by more than ``eps``)
    some interval of family b with the same owner?"""
    out = np.zeros(n, dtype=bool)
    if len(a_lo) == 0 or len(b_lo) == 0:
        return out
    ia = np.argsort(a_own, kind="stable")
    ib = np.argsort(b_own, kind="stable")
    a_lo, a_hi, a_own = a_lo[ia], a_hi[ia], a_own[ia]
    b_lo, b_hi, b_own = b_lo[ib], b_hi[ib], b_own[ib]
    ca = np.bincount(a_own, minlength=n)
    cb = np.bincount(b_own, minlength=n)
    oa = np.concatenate([[0], np.cumsum(ca)])
    ob = np.concatenate([[0], np.cumsum(cb)])
    wa, wb = int(ca.max()), int(cb.max())
    A_lo = np.full((n, wa), np.nan)
    A_hi = np.full((n, wa), np.nan)
    B_lo = np.full((n, wb), np.nan)
    B_hi = np.full((n, wb), np.nan)
    ra = np.arange(len(a_lo)) - oa[a_own]
    rb = np.arange(len(b_lo)) - ob[b_own]
    A_lo[a_own, ra], A_hi[a_own, ra] = a_lo, a_hi
    B_lo[b_own, rb], B_hi[b_own, rb] = b_lo, b_hi
    with np.errstate(invalid="ignore"):
        ov = np.minimum(A_hi[:, :, None], B_hi[:, None, :]) - np.maximum(
            A_lo[:, :, None], B_lo[:, None, :]
        )
        return (ov > eps).any(axis=(1, 2))


def _rings(g: shapely.Geometry) -> list:
    out = []
    for poly in shapely.get_parts(g):
        if poly.geom_type != "Polygon" or poly.is_empty:
            continue
        out.append(poly.exterior)
        out.extend(poly.interiors)
    return out


def _ring_coords(rings: list) -> list[np.ndarray]:
    """The vertices (n, 2) of each closed ring of ``rings`` (shapely LinearRings), without
    the closing repeat, read in one call."""
    if not rings:
        return []
    arr = np.asarray(rings, dtype=object)
    xy = shapely.get_coordinates(arr)
    at = np.cumsum(np.concatenate([[0], shapely.get_num_coordinates(arr)]))
    return [xy[a : b - 1] for a, b in zip(at[:-1], at[1:], strict=True)]


def _drop_short_many(
    rings: list[np.ndarray],
    length: float,
    vertex_at: Callable[[np.ndarray], np.ndarray] | None = None,
) -> list[np.ndarray]:
    """:func:`_drop_short` of each closed ring of ``rings``: the rings without a step
    shorter than ``length`` (the closing step included), most of them, are found in one
    pass and come back as they are (as :func:`_drop_short` returns them)."""
    flat = np.concatenate(rings) if rings else np.zeros((0, 2))
    if len(flat) == 0:
        return list(rings)
    nxt = np.roll(flat, -1, axis=0)
    off = np.cumsum([0] + [len(v) for v in rings])
    last = off[1:] - 1  # each ring's closing step: from its last vertex to its first
    nxt[last[off[1:] > off[:-1]]] = flat[off[:-1][off[1:] > off[:-1]]]
    short = np.abs(nxt - flat).max(axis=1) < length
    any_short = np.logical_or.reduceat(short, np.minimum(off[:-1], len(flat) - 1)) & (
        off[1:] > off[:-1]
    )
    return [_drop_short(v, length, vertex_at) if any_short[k] else v for k, v in enumerate(rings)]


def _drop_short(
    v: np.ndarray, length: float, vertex_at: Callable[[np.ndarray], np.ndarray] | None = None
) -> np.ndarray:
    """The closed ring ``v`` (n, 2) without the vertices that end an edge shorter than
    ``length`` (scene units): such an edge is a corner split by the overlay's rounding
    (snap-rounding nodes a corner at a hot pixel, floating overlay leaves ulp-sized
    edges), and its line is not determined to within ``length``, so it cannot be
    labelled and would hide its neighbours from the tracing.  ``vertex_at``: per point
    of some (k, 2), the environment vertex it is at, or -1 (see :func:`_corners`)."""
    if len(v) == 0:
        return v
    # vertex i is kept iff it lies at least ``length`` (max-norm) from the last kept one;
    # after a kept vertex that is its step's length, so the runs of long steps are kept
    # whole and only the vertices after a short step are compared one by one
    n = len(v)
    short = np.flatnonzero(np.abs(np.diff(v, axis=0)).max(axis=1) < length)
    keep = [0]
    i = 1  # the next vertex to decide; vertex i - 1 is kept
    for s in short:
        if s < i - 1:
            continue  # a short step inside a cluster already dropped
        keep.extend(range(i, s + 1))  # long steps from i - 1 to s
        j = s + 2  # v[s + 1] lies within length of v[s]: dropped, and so are the next
        while j < n and np.abs(v[j] - v[s]).max() < length:
            j += 1
        if j < n:
            keep.append(j)
        i = j + 1
        if i >= n:
            break
    keep.extend(range(i, n))
    tail = len(v)  # the vertices from ``tail`` on join vertex 0's cluster (the ring closes)
    while len(keep) > 1 and np.abs(v[keep[-1]] - v[0]).max() < length:
        tail = keep.pop()
    if len(keep) == len(v):
        return v
    return _corners(v, keep, tail, length, vertex_at)


def _corners(
    v: np.ndarray,
    keep: list,
    tail: int,
    length: float,
    vertex_at: Callable[[np.ndarray], np.ndarray] | None = None,
) -> np.ndarray:
    """The kept vertices of :func:`_drop_short`, each moved to the corner of its cluster
    (itself and the vertices dropped after it, ``tail ..`` joining vertex 0): where the
    line of the edge entering the cluster meets that of the edge leaving it, when those
    lines cross within ``4 length`` of the kept vertex.  Keeping the cluster's first
    vertex instead left a ring whose edge from it is off its own line by the split (fuzz
    seed 203978: 6e-9 of 8.6e-9 allowed), so the edge got no label, its neighbour was
    dropped as unlabelled, and that shadow edge was traced in one frame and not in
    another.

    Where the two lines do not cross that close, the cluster is no split corner but a
    short edge of its own; when the cluster holds two distinct vertices of the
    environment (``vertex_at``; a sliver obstacle's end 1.2e-8 across, fuzz seed 208530)
    the first and the last of them are kept: the edge between lies on their line
    (:meth:`Sweeper._label` labels it by them), and either one alone would leave the edge
    on its other side off its line by the short edge's length, unlabelled, and its
    moving neighbour dropped from the tracing."""
    n = len(v)
    kept = np.asarray(keep)
    first = kept.copy()  # each cluster's first vertex (vertex 0's: from ``tail`` on)
    if tail < n:
        first[0] = tail % n
    last = np.append(kept[1:], tail) - 1  # and its last
    pts = v[kept].copy()
    extra: dict[int, np.ndarray] = {}  # a second vertex after pts[j]
    for j in np.flatnonzero(first != last).tolist():
        f, lt, k = int(first[j]), int(last[j]), int(kept[j])
        # the two lines' crossing in Python floats (the same IEEE operations as numpy's
        # element by element, without its per-scalar overhead)
        (a0x, a0y), (a1x, a1y) = v[f - 1].tolist(), v[f].tolist()
        (b0x, b0y), (b1x, b1y) = v[lt].tolist(), v[(lt + 1) % n].tolist()
        dax, day, dbx, dby = a1x - a0x, a1y - a0y, b1x - b0x, b1y - b0y
        den = dax * dby - day * dbx
        cx = cy = math.inf
        if den != 0.0:
            u = ((b0x - a0x) * dby - (b0y - a0y) * dbx) / den
            cx, cy = a0x + u * dax, a0y + u * day
        vx, vy = v[k].tolist()
        if (
            math.isfinite(cx)
            and math.isfinite(cy)
            and max(abs(cx - vx), abs(cy - vy)) <= 4.0 * length
        ):
            pts[j] = (cx, cy)
        elif vertex_at is not None:
            idx = np.arange(f, f + (lt - f) % n + 1) % n
            at = vertex_at(v[idx])
            env = np.flatnonzero(at >= 0)
            if len(env) and (at[env] != at[env[0]]).any():
                pts[j] = v[idx[env[0]]]
                extra[j] = v[idx[env[at[env] != at[env[0]]][-1]]]
    if not extra:
        return pts
    out: list[np.ndarray] = []
    for j in range(len(pts)):
        out.append(pts[j])
        if j in extra:
            out.append(extra[j])
    return np.asarray(out)


def _rot(v: np.ndarray) -> np.ndarray:
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def star_center(ring: np.ndarray) -> np.ndarray | None:
    """A point of the kernel of the polygon ``ring`` (counter-clockwise), preferring
    the origin; None when the polygon is not star-shaped (its kernel has no area above
    ``1e-12`` of the squared size of the ring).

    Frame-free: the half-planes are built around the ring's own centre with unit edge
    directions and extents relative to its size, so scaling or moving the ring scales or
    moves the answer (an absolute ``+ 1`` in the extents and edge vectors used as
    directions once cut the kernel of a small target: a star-shaped target of a scene
    scaled by 1e-3 swept as its convex hull, fuzz seed 200033)."""
    ring = np.asarray(ring, dtype=float)
    if (_cross(ring, np.roll(ring, -1, axis=0)) >= 0).all():
        return np.zeros(2)
    mid = 0.5 * (ring.min(axis=0) + ring.max(axis=0))
    r = ring - mid
    size = float(np.hypot(r[:, 0], r[:, 1]).max())
    if not size > 0:
        return None
    big = 4.0 * size  # every point within ``size`` of mid projects within 2 size of a
    ker = shapely.box(-big, -big, big, big)
    e = np.roll(r, -1, axis=0) - r
    for a, d in zip(r, e, strict=True):
        ln = float(np.hypot(*d))
        if not ln > 0:
            continue
        u = d / ln
        n = _rot(u)  # inward normal (ccw ring)
        half = shapely.Polygon(
            [a - u * big, a + u * big, a + u * big + n * big, a - u * big + n * big]
        )
        ker = shapely.intersection(ker, half)
    if ker.is_empty or ker.area <= 1e-12 * size * size:
        return None
    return np.asarray(ker.centroid.coords[0]) + mid


def swept_shadows(
    env: Domain,
    free: shapely.Geometry,
    target: np.ndarray,
    region: shapely.Geometry,
    *,
    strips: list[shapely.Geometry] | None = None,
    eps_aim: float = 0.0,
    tol: float,
    deadline: float | None = None,
    progress: Callable[[int, int], None] | None = None,
    what: str = "the swept query",
    samples: list | None = None,
    extra_samples: int = 0,
    lazy: bool | None = None,
) -> tuple[shapely.Geometry, dict]:
    """Union of the partial-visibility shadows S(q) over the reference points q
    of ``region`` (a Point or Polygon), for the target outline ``target``
    (counter-clockwise, reference point at the origin, fixed orientation).

    ``deadline`` (a ``time.monotonic()`` value) stops the sweep with
    :class:`QueryTimeout` (naming ``what`` and the edges left); ``progress(done,
    total)`` is called after every swept edge of the region's boundary.

    The target must be star-shaped; the sweep runs over the boundary of the
    region with the reference point moved into the target's kernel (the swept
    set of placements does not depend on that choice).  Returns the union (a
    shapely geometry, world frame) and counters (``stats["grid"]``: the snap-rounding
    grid, below; ``stats["seconds"]`` and ``stats["phase_samples"]``: wall seconds and new
    samples per phase, see :class:`PhaseClock`).

    The pieces (sampled shadows and traced quads, a few hundred for a long edge of G)
    are united by GEOS *snap-rounding* on a grid of ``2**-GRID_BITS`` of the scene's size
    (``stats["grid"]``), not by its floating-point overlay.  The floating overlay
    (OverlayNG with its heuristic fallbacks) is not robust on such inputs: nearly
    coincident shadows whose boolean construction left collapsed parts (rings of two
    distinct points a few ulps apart, which GEOS's validity check accepts) and zero-width
    spikes made it return, without an error, a union that lacked up to half of one of
    its inputs (fuzz seeds 410993, 411063, 421105: the swept region then held placements
    that the stationary shadow at a vertex of G blinds).  Snap-rounding is GEOS's fully
    robust overlay: its output is valid and every point of it lies within
    ``grid / sqrt(2)`` of the exact union and vice versa; ``conservative=True`` grows the
    union by ``tol + grid`` to cover that too.

    ``samples``: a list to which ``(q, shadow)`` is appended for every exact stationary
    shadow the sweep sampled (``q`` the configuration, a reference point of ``region``
    in the caller's frame; used by :mod:`geometry.certify` for the outer bound), and
    for ``extra_samples`` more configurations evenly spaced inside every edge of the
    region's boundary (those shadows are not part of the union returned).

    ``lazy``: the sampling rules of :attr:`Sweeper.lazy_samples` (False: the previous,
    denser ones; :mod:`geometry.certify` takes those, its outer bound is made of the samples;
    None: :data:`LAZY_SAMPLES`).
    """
    c = star_center(target)
    if c is None:
        raise NotImplementedError(
            "the swept partial region needs a star-shaped target (traversing the boundary "
            "of the region only suffices then); this target has an empty kernel"
        )
    ring0 = target - c
    region = affinity.translate(region, c[0], c[1])
    hull = shapely.convex_hull(
        shapely.multipoints((ring0[:, None, :] + _region_pts(region)[None, :, :]).reshape(-1, 2))
    )
    hull_pts = np.asarray(shapely.orient_polygons(hull, exterior_cw=False).exterior.coords)[:-1]
    lazy = LAZY_SAMPLES if lazy is None else lazy
    sw = Sweeper(
        env, free, ring0, hull_pts, strips, eps_aim, tol, deadline=deadline, lazy_samples=lazy
    )
    pieces: list[shapely.Geometry] = []
    stats = {"samples": 0, "edges": 0, "refined": 0}
    if region.geom_type == "Point":
        q = np.array([region.x, region.y])
        pieces.append(sw.shadow(q)[0])
        stats["samples"] = 1
    else:
        segs = [
            (a, b)
            for ring in _rings(shapely.orient_polygons(region, exterior_cw=False))
            for a, b in zip(
                np.asarray(ring.coords)[:-1, :2], np.asarray(ring.coords)[1:, :2], strict=True
            )
        ]
        done = [0]

        def traced(_: int) -> None:
            done[0] += 1
            if progress is not None:
                progress(done[0], len(segs))

        try:
            got, stats = sw.along_many(segs, traced)
        except _Expired:
            raise QueryTimeout(
                f"{what} ran past its timeout after sweeping {done[0]} of the {len(segs)} "
                f"edges of the region's boundary ({len(segs) - done[0]} left, the current "
                "one included); raise timeout= or give timeout=None"
            ) from None
        for g in got:
            pieces += g
    stats["grid"] = sw.grid
    if samples is not None:
        if region.geom_type == "Point":
            samples.append((np.array([region.x, region.y]) - c, pieces[0]))
        else:
            samples.extend((np.array(k) - c, v[0]) for k, v in sw._frames.items())
            ts = np.arange(1, extra_samples + 1) / (extra_samples + 1)
            sw._prefetch([a + t * (b - a) for a, b in segs for t in ts])  # one batch
            for a, b in segs:
                for t in ts:
                    q = a + t * (b - a)
                    samples.append((q - c, sw.shadow(q)[0]))
    with sw.clock("union"):
        union = _union_pieces(sw, pieces)
    stats["seconds"] = dict(sw.clock.seconds)
    stats["phase_samples"] = dict(sw.clock.samples)
    return union, stats


def _union_pieces(sw: Sweeper, pieces: list[shapely.Geometry]) -> shapely.Geometry:
    """The union of the pieces of a sweep (its sampled stationary shadows and traced
    quads), snap-rounded on ``sw.grid``.

    The sampled shadows are ``S_k = F - X_k`` (``F`` the free space, ``X_k`` the target
    and its weak visibility region at sample k, kept by :meth:`Sweeper.shadow`), so their
    union is ``F - (X_1 n ... n X_n)`` (De Morgan): the intersection of the small sets
    ``X_k`` (near the region, balanced pairwise) and one difference with the free space
    replace the union of n shadows that each span the whole map (nearly coincident
    copies of the free space's boundary: GEOS's overlay spent most of its time there).
    The traced quads are united with that.  Every overlay snap-rounds on ``sw.grid``, as
    the one union it replaces did (:func:`swept_shadows`).  Parts of ``F - X_k`` that
    :meth:`Sweeper.shadow` dropped as float slivers (area below
    ``geometry._shapes.SLIVER`` times their squared perimeter) are part of this union.
    Shadows without their ``X_k`` (none expected) fall back to the plain union."""
    by_id = {id(v[0]): k for k, v in sw._frames.items()}
    keys = list(dict.fromkeys(by_id[id(p)] for p in pieces if id(p) in by_id))
    rest = [p for p in pieces if id(p) not in by_id]
    if not keys or any(k not in sw._seen for k in keys):
        return polygonal(union_all(pieces, grid_size=sw.grid))
    g = sw.grid
    pairs = sw.__dict__.get("_pairs", {})
    xs = []
    i = 0
    while i < len(keys):  # consecutive samples: their intersection is often kept already
        if i + 1 < len(keys) and (keys[i], keys[i + 1]) in pairs:
            xs.append(pairs[(keys[i], keys[i + 1])])
            i += 2
        else:
            xs.append(sw._seen[keys[i]])
            i += 1
    while len(xs) > 1:
        pairs = zip(xs[0::2], xs[1::2], strict=False)  # an odd one out waits a round
        nxt = [areal(snapped(shapely.intersection, a, b, g)) for a, b in pairs]
        xs = nxt + xs[len(nxt) * 2 :]
    shadows = areal(snapped(shapely.difference, sw.free, xs[0], g))
    if not rest:
        return polygonal(shadows)
    return polygonal(union_all([shadows, *rest], grid_size=g))


def snap_grid(scale: float) -> float:
    """The snap-rounding grid of the swept union for a scene of size ``scale`` (scene
    units): the power of two nearest below ``2**-GRID_BITS * scale``."""
    return math.ldexp(1.0, math.floor(math.log2(scale)) - GRID_BITS)


def _region_pts(region: shapely.Geometry) -> np.ndarray:
    if region.geom_type == "Point":
        return np.array([[region.x, region.y]])
    return np.asarray(region.exterior.coords)[:-1, :2]
