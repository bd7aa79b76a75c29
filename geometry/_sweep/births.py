"""The birth checks: shadows born and gone between two samples.

The shadow of the eroded target (the part of A common to every configuration of an
interval) contains every S(t) there; a component of it that neither neighbouring sample's
shadow meets may hold a shadow born and gone in between, and the interval is bisected.
Part of :class:`geometry.sweep.Sweeper`.
"""

from __future__ import annotations

import math

import numpy as np
import shapely

from .._common import polygonal
from .._shapes import areal, snapped, union_all
from ..weak import weak_visibility


class BirthChecks:
    """The birth checks of a :class:`~geometry.sweep.Sweeper` (a mixin of it: it uses the
    sweeper's samples and caches): eroded targets' shadows per interval
    (:meth:`_eroded_shadow`) and the bisections they ask for (:meth:`_refine_births_many`)."""

    def _refine_births_many(
        self, runs: list, ts_all: list[list], first: tuple | None = None
    ) -> None:
        """Per run (``geometry.sweep._Run``: a segment of the sweep) with its sample times so far
        (``ts_all``): add sample times (to each run's frames) where the eroded target's shadow has a
        component that neither neighbouring sample's shadow meets (a shadow born and dying in
        between, :meth:`_born`); bisect up to ``max_depth`` times. An interval without an eroded
        target is bounded by the union of its pieces' eroded targets' shadows where halving it at
        most ``max_split`` times gives each piece one (lazy rule, :meth:`_split_shadow`; a component
        of that union apart from both ends' shadows is bisected as before), else bisected where an
        eroded target exists within the depth limit (:meth:`_core_within_depth`). With overlap
        strips (5.2) the eroded target's whole outline counts as wanted: its shadow bounds the full
        target's shadows, which the 5.2 shadows contain, so a shadow of the full target born in
        between is caught here too (and the 5.2 region stays inside R(G); fuzz seed 411063, mixed
        G/H). Births of shadows that exist only because pieces are unwanted are not detected by it.
        An alarm whose bisection would find nothing (the halves' eroded targets settle it,
        :meth:`_settled`; lazy rules) takes no sample.
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
            todo, mids, alarms, new_at = [], [], [], []
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
                    r.uppers[(a, b)] = upper  # for _wedge_covered, alarmed or not
                    born = self._born(upper, r.frame(a)[0], r.frame(b)[0])
                    new = len(born) > 0
                    if new and i not in split and self._halves_checked(r, a, b, depth):
                        alarms.append((i, born))  # decided below, in one batch
                    elif not new:
                        r.bounds[(a, b)] = upper  # for _Run.closes
                if new:
                    mids.append((r, a, 0.5 * (a + b), b, depth))
                    new_at.append(i)
            if alarms:
                # an alarm whose bisection would find nothing takes no sample (_settled); the
                # halves' eroded targets of all alarms of the level in one batch
                halves = {i: self._halves(*level[i][:3]) for i, _ in alarms}
                self._prefetch([], [p for h in halves.values() for p in h])
                left = {i for i, born in alarms if self._settled(*level[i][:3], born, halves[i])}
                mids = [m for i, m in zip(new_at, mids, strict=True) if i not in left]
            self._prefetch([r.q0 + m * r.dq for r, _, m, _, _ in mids])
            self._frames_many([(r, m) for r, _, m, _, _ in mids])
            for r, a, m, b, depth in mids:
                r.stats["refined"] += 1
                todo += [(r, a, m, depth + 1), (r, m, b, depth + 1)]

    def _closes(self, r, a: float, b: float, upper: shapely.Geometry) -> bool:
        """Whether the interval ``[a, b]`` between two samples of the run ``r`` is *closed*:
        its upper bound ``upper`` (every S(q) of the interval lies in it: the eroded target's
        shadow, or the union of its pieces') lies in S_a u S_b but for parts narrower than the
        union's grid (as :meth:`_born` counts).  Then every shadow of the interval lies in
        the two samples' shadows, which the union holds: the interval needs no tracing, no
        refinement and no event sample, whatever is born or dies in it.  Lazy rules only.
        With overlap strips (5.2) ``upper`` bounds the full target's shadows, not the larger
        ones of the wanted pieces: there only where no strip comes within ``1e-6`` of the
        scene's size of the area its edge sweeps over the interval (:meth:`_strips_miss`), so
        that the whole outline is wanted all along and the shadows are the full ones.
        ``S_a u S_b = F - (X_a n X_b)`` and ``upper`` lies in ``F``, so its part outside is
        ``upper n X_a n X_b`` (:meth:`_seen_pair`, which the tracing of an open interval uses
        too)."""
        if not self.lazy_samples or (self.strips is not None and not self._strips_miss(r, a, b)):
            return False
        seen = self._seen_pair(*(self._frame_key(r.q0, r.q1, t) for t in (a, b)))
        if seen is None:
            return False
        parts = shapely.get_parts(areal(snapped(shapely.intersection, upper, seen, self.grid)))
        return not (2.0 * shapely.area(parts) > self.grid * shapely.length(parts)).any()

    def _strips_miss(self, r, a: float, b: float) -> bool:
        """Whether no overlap strip comes within ``1e-6`` of the scene's size of the area its
        target edge sweeps while the target moves over ``[a, b]`` of the run ``r`` (the
        parallelogram between the edge's two positions): the whole outline is wanted at every
        configuration of the interval."""
        qa, qb = (r.q1 if t == 1.0 else r.q0 + t * r.dq for t in (a, b))
        ring, nxt = self.ring0, np.roll(self.ring0, -1, axis=0)
        swept = shapely.polygons(np.stack([ring + qa, nxt + qa, nxt + qb, ring + qb], axis=1))
        swept = shapely.convex_hull(swept)  # an edge along the motion: a degenerate one
        near = shapely.dwithin(self._strip_array(), swept, 1e-6 * self.env.scale)
        return not near.any()

    def _halves(self, r, a: float, b: float) -> list[tuple[np.ndarray, np.ndarray]]:
        """The two halves ``(qa, qm), (qm, qb)`` of the interval ``[a, b]`` of the run ``r``."""
        qa, qm, qb = (r.q0 + t * r.dq for t in (a, 0.5 * (a + b), b))
        return [(qa, qm), (qm, qb)]

    def _halves_checked(self, r, a: float, b: float, depth: int) -> bool:
        """Whether the bisection of an alarmed interval ``[a, b]`` at ``depth`` would check
        its halves against their eroded targets' shadows (the next level exists and each
        half has an eroded target): then :meth:`_settled` can tell ahead what it would find
        (lazy rules only)."""
        if not self.lazy_samples or depth + 1 >= self.max_depth:
            return False
        return all(self._eroded_core(qa, qb) is not None for qa, qb in self._halves(r, a, b))

    def _settled(self, r, a: float, b: float, born: np.ndarray, halves: list) -> bool:
        """Whether the sample that an alarm on ``[a, b]`` (``born``: the parts of the eroded
        target's shadow apart from both ends' shadows, :meth:`_born`) asks for at the
        midpoint m can be left out: the bisection would find nothing with it.

        With the sample, the next level checks each half against the eroded target of that
        half, U1 on [a, m] and U2 on [m, b] (both exist: :meth:`_halves_checked`), and asks for
        no more where every part of U1 meets S_a and every part of U2 meets S_b (meeting S_m
        too is not needed then).  The sample itself, S_m, lies inside U1 n U2; where that
        has no part in ``born`` (none wider than the union's grid, as :meth:`_born` counts),
        S_m holds nothing of the alarm, so the bisection that the alarm starts would take
        the one sample and find nothing in it or below it.  Then it is not taken; otherwise
        it is, as before, and the next level reuses the halves' eroded targets computed
        here.  ``born`` lies in the free space, so its part outside U1 n U2 is ``born - X1 -
        X2`` (X: what an eroded target's shadow does not hold, :meth:`_eroded_seen`)."""
        sa, sb = r.frame(a)[0], r.frame(b)[0]
        (qa, qm), (_, qb) = halves
        u1, u2 = self._eroded_shadow(qa, qm), self._eroded_shadow(qm, qb)
        none = shapely.Polygon()
        if len(self._born(u1, sa, none)) or len(self._born(u2, sb, none)):
            return False
        g = self.shadow_grid
        left = union_all(list(born), grid_size=g)
        for qx, qy in halves:
            left = areal(snapped(shapely.difference, left, self._eroded_seen(qx, qy), g))
        parts = shapely.get_parts(left)
        return not (2.0 * shapely.area(parts) > self.grid * shapely.length(parts)).any()

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
        key = (tuple(qa.tolist()), tuple(qb.tolist()))
        cache = self.__dict__.setdefault("_eroded_shadows", {})
        if key not in cache:
            seen = self._eroded_seen(qa, qb)
            cache[key] = (
                None
                if seen is None
                else polygonal(snapped(shapely.difference, self.free, seen, self.shadow_grid))
            )
        return cache[key]

    def _eroded_seen(self, qa: np.ndarray, qb: np.ndarray) -> shapely.Geometry | None:
        """The placements that see the part of A common to all A_q, q in [qa, qb], or lie in
        it (that part and its weak visibility region, snap-rounded); None when it is empty."""
        key = (tuple(qa.tolist()), tuple(qb.tolist()))
        cache = self.__dict__.setdefault("_eroded_xs", {})
        if key in cache:
            return cache[key]
        got = self._eroded_core(qa, qb)
        if got is None:
            cache[key] = None
            return None
        core, ring = got
        reg = self._eroded_pre.pop(key, None)
        if reg is None:
            reg = weak_visibility(
                self.env, ring, np.ones(len(ring), dtype=bool), self.eps_aim, self._anchors()
            )
        g = self.shadow_grid  # as in shadow(): the region's hole nearly coincides with core
        # snap-rounding can raise "Ring edge missing" at scale 1e-3 (fuzz seed 201039, --swept)
        cache[key] = areal(snapped(shapely.union, reg, core, g))
        return cache[key]

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
