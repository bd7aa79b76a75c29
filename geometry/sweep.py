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
carry a shadow edge at some sample (:meth:`Sweeper._live_mids`; not in the first or last
interval where the sample at the segment's end stands in, :meth:`Sweeper._ends_clear`) --,
and just after a traced edge was cut short by the death of a neighbour while its line still
bounds a shadow (the edge goes on with another neighbour, a configuration that may live
between two samples only: :meth:`Sweeper._continuation_gap`).  What this does not prove is listed in
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

from ._common import polygonal
from ._shapes import areal, snapped, union_all
from ._shapes import cross as _cross
from ._sweep.births import BirthChecks
from ._sweep.blind import PointTest
from ._sweep.cover import Coverage
from ._sweep.events import CollinearityEvents
from ._sweep.lines import _meet, _rot
from ._sweep.shadow import StationaryShadows, _rings
from ._sweep.trace import EdgeTracing
from ._sweep.wedges import WedgeCover
from ._vis import Domain

#: The union of the pieces is snap-rounded onto a grid of ``2**-GRID_BITS`` of the scene's
#: size (about 1e-12): see :func:`swept_shadows`.
GRID_BITS = 40

#: The stationary shadows (free space minus target minus weak visibility region) are
#: computed by snap-rounding onto a grid ``2**-SHADOW_BITS`` finer than the union's:
#: see :meth:`Sweeper.shadow`.
SHADOW_BITS = 8

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


@dataclass
class _Cover:
    """What the traces of one edge of the region covered (:meth:`Sweeper._sweep_intervals`):
    per line key the intervals covered (``cover``), the intervals ``(lo, hi, edge)`` reached
    by an edge's trace or held by an edge swept inside the known shadows (``held``: an edge
    holds its line only while its own configuration lives, :meth:`Sweeper._continuation_gap`),
    the intervals of edges the tracing cannot confirm (``traced``), the confirmed ``(t, key)``
    pairs and the cut traces already sampled after (``probed``)."""

    cover: dict[tuple, list] = field(default_factory=dict)
    confirmed: set[tuple] = field(default_factory=set)
    traced: dict[tuple, list] = field(default_factory=dict)
    held: dict[tuple, list] = field(default_factory=dict)
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
    already found live, its closed intervals and its counters."""

    sw: Sweeper
    q0: np.ndarray
    q1: np.ndarray
    frames: dict[float, tuple] = field(default_factory=dict)
    looked: set[tuple[int, int]] = field(default_factory=set)
    stats: dict[str, int] = field(default_factory=lambda: {"samples": 0, "edges": 0, "refined": 0})
    #: its events (:meth:`Sweeper._events`: times, anchors, sides); None until one may be
    #: live (:meth:`live_mids`)
    ev_t: np.ndarray | None = None
    ev_ids: list = field(default_factory=list)
    ev_side: list = field(default_factory=list)
    #: whether the samples at 0 and 1 stand in for the first and last interval's event
    #: samples (:meth:`Sweeper._ends_clear`; computed when first asked, :meth:`ends_clear`)
    ends: tuple[bool, bool] | None = None
    #: the birth check's upper bounds of intervals (a, b) where it found no birth
    bounds: dict[tuple[float, float], shapely.Geometry] = field(default_factory=dict)
    #: the birth check's upper bounds of all intervals (a, b) it bounded, births found or
    #: not (:meth:`Sweeper._wedge_covered`)
    uppers: dict[tuple[float, float], shapely.Geometry] = field(default_factory=dict)
    #: per interval (a, b) tested: is it closed (:meth:`closes`; closed: its samples'
    #: shadows hold every shadow in between, nothing to trace or sample there)
    closed: dict[tuple[float, float], bool] = field(default_factory=dict)

    def __post_init__(self) -> None:
        self.dq = self.q1 - self.q0

    def closes(self, a: float, b: float) -> bool:
        """Whether the interval ``(a, b)`` between two consecutive samples is closed
        (:meth:`Sweeper._closes` on the birth check's bound of it, where it has one; tested
        once, kept in :attr:`closed`)."""
        got = self.closed.get((a, b))
        if got is None:
            upper = self.bounds.get((a, b))
            got = self.closed[(a, b)] = upper is not None and self.sw._closes(self, a, b, upper)
        return got

    def live_mids(self) -> list[float]:
        """The event samples :meth:`Sweeper._live_mids` asks for now.  The events are
        computed the first time one of them may be live (:meth:`Sweeper._may_be_live`):
        until then no event is, and nothing is asked for."""
        if self.ev_t is None:
            if not self.sw._may_be_live(self.q0, self.dq, self.frames):
                return []
            self.ev_t, self.ev_ids, self.ev_side = self.sw._events(self.q0, self.dq)
        return self.sw._live_mids(*self.event_args())

    def event_args(self) -> tuple:
        """The arguments of :meth:`Sweeper._live_mids` for this segment."""
        return (
            self.ev_t,
            self.ev_ids,
            self.frames,
            self.looked,
            self.ev_side,
            self.closes,
            self.ends_clear,
            self.wedge_covered,
        )

    def wedge_covered(self, k: int, side: int, lo: float, hi: float) -> bool:
        """Whether event ``k`` needs no sample in the interval ``(lo, hi)`` on its ``side``
        (:meth:`Sweeper._wedge_covered`)."""
        return self.sw._wedge_covered(self, k, side, lo, hi)

    def ends_clear(self, end: int) -> bool:
        """Whether the sample at time ``end`` (0 or 1) stands in for the event samples of
        the first (last) interval between events (:meth:`Sweeper._ends_clear`, once)."""
        if self.ends is None:
            self.ends = self.sw._ends_clear(self.q0, self.dq, self.ev_t)
        return self.ends[end]

    def frame(self, t: float) -> tuple:
        """(shadow, edges) at time ``t`` (:meth:`Sweeper.shadow`, :meth:`Sweeper._edges`),
        computed once per configuration."""
        got = self.frames.get(t)
        if got is None:
            sw = self.sw
            q = self.at(t)
            key = (float(q[0]), float(q[1]))
            if key not in sw._frames:
                shadow, table, tid = sw.shadow(q)
                sw._frames[key] = (shadow, sw._edges(shadow, table, tid))
                self.stats["samples"] += 1
            got = self.frames[t] = sw._frames[key]
        return got

    def at(self, t: float) -> np.ndarray:
        """The reference point at time ``t`` (``q1`` itself at 1)."""
        return self.q1 if t == 1.0 else self.q0 + t * self.dq


@dataclass
class Sweeper(
    StationaryShadows,
    PointTest,
    CollinearityEvents,
    WedgeCover,
    Coverage,
    BirthChecks,
    EdgeTracing,
):
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

    Its parts live in :mod:`geometry._sweep`, one mixin each: the samples' stationary
    shadows (:class:`~geometry._sweep.shadow.StationaryShadows`), the exact point test
    (:class:`~geometry._sweep.blind.PointTest`), the collinearity events
    (:class:`~geometry._sweep.events.CollinearityEvents`) and the wedges they need not sample
    (:class:`~geometry._sweep.wedges.WedgeCover`), the coverage decisions
    (:class:`~geometry._sweep.cover.Coverage`), the birth checks
    (:class:`~geometry._sweep.births.BirthChecks`) and the edge tracing
    (:class:`~geometry._sweep.trace.EdgeTracing`); this class holds the state and runs
    the phases in order (:meth:`along_many`).
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

    def _frames_many(self, items: list[tuple[_Run, float]]) -> None:
        """``run.frame(t)`` for each ``(run, t)`` of ``items``, in that order, with the edges
        of the new shadows labelled in one batch (:meth:`_edges_many`: each gets what
        :meth:`_edges` gives it alone; a configuration is computed once, counted as a
        sample of the first run that asks for it, as one by one)."""
        todo: dict[tuple[float, float], tuple[_Run, np.ndarray]] = {}
        for r, t in items:
            if t in r.frames:
                continue
            q = r.at(t)
            key = (float(q[0]), float(q[1]))
            if key not in self._frames and key not in todo:
                todo[key] = (r, q)
        if len(todo) > 1:
            shadows = [self.shadow(q) for _, q in todo.values()]
            for (key, (r, _)), sh, edges in zip(
                todo.items(), shadows, self._edges_many(shadows), strict=True
            ):
                self._frames[key] = (sh[0], edges)
                r.stats["samples"] += 1
        for r, t in items:
            r.frame(t)

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
            self._frames_many([(run, t) for run, ts in zip(runs, ts_all, strict=True) for t in ts])
        if moving:
            with clock("birth checks"):
                # the first level is the one whose bounds the vertex batch computed
                self._refine_births_many(
                    moving, [ts_all[runs.index(r)] for r in moving], (pairs, split)
                )
        # the collinearity events (shadows born on a line) are sampled lazily: once
        # between consecutive events next to a *live* event, one whose wedge's lines carry
        # a shadow edge at a sample so far (see _live_mids), until no new one is live;
        # first from the samples alone, then again after the refinements of the tracing (a
        # segment computes its events once one may be live: _Run.live_mids)
        with clock("event samples"):
            while True:
                asked = [(r, r.live_mids()) for r in moving]
                asked = [(r, mids) for r, mids in asked if mids]
                if not asked:
                    break
                self._prefetch([r.q0 + t * r.dq for r, mids in asked for t in mids])
                self._frames_many([(r, t) for r, mids in asked for t in mids])
        with clock("tracing"):
            # the first round of every segment's traces in one batch
            jobs = [(r.q0, r.q1, r.frame, _open_pairs(r)) for r in moving]
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
        todo = [(a, b, 0) for a, b in _open_pairs(run)]
        while True:
            self._sweep_intervals(todo, q0, q1, frame, pieces, state, stats, pre)
            pre = None
            mids = run.live_mids()
            if not mids:
                return pieces
            self._prefetch([q0 + t * dq for t in mids])
            self._frames_many([(run, t) for t in mids])
            for t in mids:
                pieces.append(frame(t)[0])
            grid = sorted(set(run.frames) | set(mids))
            todo = [
                (a, b, 0)
                for a, b in zip(grid[:-1], grid[1:], strict=True)
                if a in mids or b in mids
            ]

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
                    state.held.setdefault(e[1], []).append((a, b, e))
                stats["edges"] += len(edges)
                pieces.extend(quads)
                for e, end in zip(edges, ends, strict=True):
                    cover.setdefault(e[1], []).append((min(t, end), max(t, end)))
                    if end != t:
                        confirmed.add((t, e[1]))
                        state.held.setdefault(e[1], []).append((min(t, end), max(t, end), e))
                    else:  # not confirmed even at its own sample: tracing cannot cover it
                        traced.setdefault(e[1], []).append((a, b))
                cut += cut_short
                confirmed.update((t, e[1]) for e in inside)
            gap = self._coverage_gap(frame(a)[1], frame(b)[1], cover, a, b, confirmed)
            if gap is None:
                gap = self._continuation_gap(cut, traced, probed, q0, dq, state.held)
            if gap is not None and depth < self.max_depth:
                stats["refined"] += 1
                pieces.append(frame(gap)[0])
                todo += [(a, gap, depth + 1), (gap, b, depth + 1)]

    def _interval_traces(self, jobs: list[tuple]) -> list[dict[tuple[float, float], list]]:
        """Per job ``(q0, q1, frame, intervals)`` (a sweep ``q0 -> q1``, its frames, intervals
        ``(a, b)`` of its sample times), per interval: for the shadow edges at ``a`` traced
        towards ``b``, then those at ``b`` towards ``a``, ``(edges, quads, ends, inside,
        not_point, cut)``: the edges whose sweep leaves the two samples' shadows
        (:meth:`_uncovered_seen_many`, else :meth:`_uncovered`), what :meth:`_trace_many`
        makes of them, the other edges (swept inside the known shadows), those of them that
        are no point (:meth:`_not_point_many`) and the traces cut short
        (:meth:`_cut_short_many`); each of these in one batch over all the intervals (none
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
                known = None  # the shadows' union, if their X (_uncovered_seen_many) is not kept
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

    def _check_time(self) -> None:
        if self.deadline is not None and time.monotonic() > self.deadline:
            raise _Expired


def _open_pairs(run: _Run) -> list[tuple[float, float]]:
    """The intervals between the run's consecutive sample times that are not closed."""
    return [ab for ab in _pairs(sorted(run.frames)) if not run.closed.get(ab, False)]


def _pairs(ts: list[float]) -> list[tuple[float, float]]:
    """Consecutive pairs ``(ts[i], ts[i + 1])`` of a sorted list of times."""
    return list(zip(ts[:-1], ts[1:], strict=True))


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
