"""The collinearity events of a sweep, and the samples taken next to the live ones.

A moving anchor crossing the line through two obstacle corners (or an obstacle edge), or
the line through two target vertices crossing a corner: there a shadow can be born as a
segment continuing a known shadow edge.  Part of :class:`geometry.sweep.Sweeper`.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np
import shapely

from .._shapes import cross as _cross
from .lines import _corner_pairs

#: The window of a segment's line (times, the segment being (0, 1)) whose events
#: :meth:`CollinearityEvents._event_window` computes once per segment and filters for every
#: window inside it: the segment's, and the half intervals past its ends (at most half the
#: segment) that :meth:`CollinearityEvents._ends_clear` looks at.
ROWS_WINDOW = (-0.5, 1.5)


class _Times(NamedTuple):
    """The geometric candidates of a segment's events (:meth:`CollinearityEvents._event_times`):
    the event lines ``p0 + s w`` (``p1 = p0 + w``), the moving anchors at t = 0 (``x0``) and
    their velocities (``vx``), their ids (``mov_id``; ``ok``: which ends of wanted pieces
    move with a finite position), the pairs (``ii``, ``kk``) of target vertices and the
    target's vertices at t = 0 (``a0``); the crossings of a moving anchor ``xa`` with line
    ``la`` at ``ta`` and of the line of the vertex pair ``pb`` with corner ``lb`` at ``tb``."""

    p0: np.ndarray
    p1: np.ndarray
    w: np.ndarray
    x0: np.ndarray
    vx: np.ndarray
    ii: np.ndarray
    kk: np.ndarray
    a0: np.ndarray
    ok: np.ndarray
    mov_id: np.ndarray
    la: np.ndarray
    xa: np.ndarray
    ta: np.ndarray
    lb: np.ndarray
    pb: np.ndarray
    tb: np.ndarray


#: An unordered pair of anchor ids ``a < b`` as one integer, ``a * _PAIR + b``
#: (:meth:`CollinearityEvents._may_be_live`; ids are below it).
_PAIR = 1 << 31


class CollinearityEvents:
    """The collinearity events of a :class:`~geometry.sweep.Sweeper` (a mixin of it: it
    uses the sweeper's scene, target and anchors): :meth:`_events` along a segment,
    whether one of them may be live before they are computed (:meth:`_may_be_live`) and the
    samples :meth:`_live_mids` asks for next to them."""

    def _live_mids(
        self,
        ev_t: np.ndarray,
        ev_ids: list,
        frames: dict,
        looked: set,
        ev_side: list | None = None,
        closes: Callable[[float, float], bool] | None = None,
        ends: Callable[[int], bool] | None = None,
        covered: Callable[[int, int, float, float], bool] | None = None,
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
        docs/DESIGN.md, "Collinearity events").  ``ev_side`` (:meth:`_events`), per anchor
        tuple of ``ev_ids``: the sides of the event (-1 before, 1 after) where its wedge can
        be a shadow, whose intervals a live event has sampled (None: both).  The caller
        samples, then asks again (the new samples can make more events live); each side of
        an event is looked at until it is live once (``looked``: ``(event, side)``).  No
        sample is asked for inside an interval ``(a, b)`` between two samples where
        ``closes(a, b)`` (:meth:`~geometry._sweep.births.BirthChecks._closes`: its two samples'
        shadows hold every shadow in between, the wedge's too).  Nor inside the first (last)
        interval between events where ``ends(0)`` (``ends(1)``) holds: the sample at 0 (1)
        stands in for it (:meth:`_ends_clear`).  Nor for a side of an event where
        ``covered(event, side, lo, hi)`` holds (:meth:`_wedge_covered`: the two samples'
        shadows already hold every wedge it can open there)."""
        bounds = np.concatenate([[0.0], ev_t, [1.0]])
        if not self.lazy_samples:  # the previous rule: once between every two events, at once
            if looked:
                return []
            looked.add((-1, 0))
            return sorted({float(t) for t in 0.5 * (bounds[1:] + bounds[:-1])} - set(frames))
        keys = self._frame_keys(frames)
        times = np.array(sorted(frames))
        out: set[float] = set()
        for k in range(len(ev_t)):
            if (k, -1) in looked and (k, 1) in looked:
                continue
            sides: set[int] = set()
            for a, (mov, other) in enumerate(ev_ids[k]):
                if (
                    -1 in mov
                    or -1 in other
                    or any(frozenset((u, v)) in keys for u in mov for v in (*mov, *other) if v != u)
                ):
                    sides.update((-1, 1) if ev_side is None else ev_side[k][a])
            for side in sorted(sides - {s for e, s in looked if e == k}):
                looked.add((k, side))
                lo, hi = (bounds[k], bounds[k + 1]) if side < 0 else (bounds[k + 1], bounds[k + 2])
                if ((times > lo) & (times < hi)).any() or _inside(times, lo, hi, closes):
                    continue
                if ends is not None and any(
                    b == end and end in frames and ends(int(end))
                    for b, end in ((lo, 0.0), (hi, 1.0))
                ):
                    continue
                if covered is not None and covered(k, side, float(lo), float(hi)):
                    continue
                out.add(float(0.5 * (lo + hi)))
        return sorted(out)

    def _frame_keys(self, frames: dict) -> set:
        """The lines (frozensets of two anchor ids) of the shadow edges and their neighbours
        at the samples ``frames`` (time -> (shadow, edges)), kept per dict and extended with
        the samples added since the last call (a sample's edges do not change)."""
        return self._frame_lines(frames)[0]

    def _frame_lines(self, frames: dict) -> tuple[set, set]:
        """:meth:`_frame_keys`, and the same lines of two distinct anchors as integers
        (``a * _PAIR + b``, ``a < b``)."""
        cache = self.__dict__.setdefault("_keys_of", {})
        got = cache.get(id(frames))
        if got is None or got[0] is not frames:
            got = cache[id(frames)] = (frames, set(), set(), set())
        _, done, keys, codes = got
        for t, (_, es) in frames.items():
            if t not in done:
                done.add(t)
                new = {frozenset(k) for e in es for k in e}
                keys.update(new)
                codes.update(min(k) * _PAIR + max(k) for k in new if len(k) == 2)
        return keys, codes

    def _ends_clear(self, q0: np.ndarray, dq: np.ndarray, ev_t: np.ndarray) -> tuple[bool, bool]:
        """Whether the samples at the ends of the segment ``q0 + t dq`` (t = 0, 1) stand in
        for the event samples of the first and last interval between its events ``ev_t``
        (:meth:`_events`; lazy rules only): no event of the motion's line (extended past the
        segment) that can open a wedge facing the segment lies within half that interval's
        length before 0 (after 1), or at the end.

        Between consecutive events no wedge is born or dies (they are born and die at
        events), so a wedge alive in the first interval ``(0, t_1)`` is alive at 0 too, born
        at least ``t_1 / 2`` before it: at least as old as it would be at the interval's
        midpoint, the sample the interval takes otherwise (whose worst case is a wedge born
        at 0), and alive at least ``t_1`` after it.  The sample at 0 then holds it, and its
        edges are traced from there to its death as any edge of a sample.  The last interval
        likewise, with the sample at 1 and the events after 1.

        Only events that can open a wedge on the side facing the segment count: before 0,
        those whose wedge can be a shadow after them, and after 1 those whose wedge can be
        one before them (:meth:`_wedge_sides`).  A wedge dies at an event where one would be
        born with the sweep run backwards, and the sides are read from the geometry at the
        event, whichever way the target runs: an event with no such side neither gives
        birth to nor kills the wedge the end sample stands in for."""
        if not self.lazy_samples or len(ev_t) == 0:
            return (False, False)
        t1, tn = float(ev_t[0]), float(ev_t[-1])
        before = self._event_window(q0, dq, -0.5 * t1, 2e-9)[2]
        after = self._event_window(q0, dq, 1 - 2e-9, 1 + 0.5 * (1 - tn))[2]
        return (
            not any(1 in side for sides in before for side in sides),
            not any(-1 in side for sides in after for side in sides),
        )

    def _events(self, q0: np.ndarray, dq: np.ndarray) -> tuple[np.ndarray, list, list]:
        """:meth:`_event_window` over the segment, times in (0, 1) (1e-9 off its ends)."""
        return self._event_window(q0, dq, 1e-9, 1 - 1e-9)

    def _event_window(
        self, q0: np.ndarray, dq: np.ndarray, lo: float, hi: float
    ) -> tuple[np.ndarray, list, list]:
        """Times in ``(lo, hi)`` (the line of the motion extended past the segment where
        outside [0, 1]), sorted, at which the target moving along ``q0 + t dq`` meets
        a *collinearity event*: a moving anchor (target vertex or end of a wanted piece)
        crosses the line through two convex obstacle corners whose joining line is
        tangent at both, or through an obstacle edge; or the line through two target
        vertices crosses a convex obstacle corner.  Only events whose line is
        unobstructed between its anchors count, and with the lazy rules not those whose
        moving anchor lies between the two corners (:func:`_between`: no wedge opens
        there).  Also, per time, the anchor ids of its
        events: ``(moving ids, other ids)`` each (ids as :meth:`pos` takes them; -1: the
        neighbour of an obstacle corner not known), and per event the sides of it (-1 before,
        1 after) where its wedge can be a shadow (:meth:`_wedge_sides`; with the previous
        rules both), for :meth:`_live_mids`.

        At such an event two shadow-edge lines coincide, and a shadow can be born as a
        segment on that line (it then grows from a line that continues an edge of an
        existing shadow, so the eroded-target test of :meth:`_refine_births`, which
        looks for shadow components apart from the known ones, does not see it: fuzz
        issue 26.3/26.4).  Sampling once between consecutive events catches such a
        shadow at a time it has area, and its edges are then traced both ways (next to
        the events :meth:`_live_mids` finds live).

        The events of a segment are computed once, over the window :data:`ROWS_WINDOW` of
        its line (:meth:`_event_rows`), and each window inside it (the segment's, and the
        half intervals past its ends that :meth:`_ends_clear` looks at) takes its rows from
        them: every test of an event is row by row, so the rows of a window are the same,
        bit for bit, as if it were computed alone (a window outside it is)."""
        if ROWS_WINDOW[0] <= lo and hi <= ROWS_WINDOW[1]:
            rows = self._per_segment(
                "_ev_rows", q0, dq, lambda: self._event_rows(q0, dq, *ROWS_WINDOW)
            )
        else:
            rows = self._event_rows(q0, dq, lo, hi)
        t, ids, side, keep = rows
        kept = np.flatnonzero(keep & (t > lo) & (t < hi))
        kept = kept[np.argsort(t[kept], kind="stable")]
        ts = t[kept]
        # merge events closer than the tracing can tell apart (the first time stands)
        first = np.concatenate([[True], np.diff(ts) > 1e-9]) if len(ts) else np.zeros(0, bool)
        group = np.cumsum(first) - 1
        out: list[list] = [[] for _ in range(int(first.sum()))]
        sides: list[list] = [[] for _ in out]
        for g, c in zip(group, kept, strict=True):
            out[g].append(ids[c])
            sides[g].append(_SIDES[int(side[c])])
        return ts[first], out, sides

    def _event_rows(
        self, q0: np.ndarray, dq: np.ndarray, lo: float, hi: float
    ) -> tuple[np.ndarray, list, np.ndarray, np.ndarray]:
        """Every candidate event of :meth:`_event_window` in the window ``(lo, hi)``, one row
        each, unsorted: its time, its anchor ids, the sides of it where its wedge can be a
        shadow (a code of ``_SIDES``) and whether it counts (tangent, unobstructed, ...)."""
        b, i, _ = self._event_lines()
        cvx = self._event_corners()
        ev = self._times_kept(q0, dq) if (lo, hi) == ROWS_WINDOW else None
        if ev is None:
            ev = self._event_times(q0, dq, lo, hi)
        p0, p1, w, x0, vx, ii, kk, a0 = ev.p0, ev.p1, ev.w, ev.x0, ev.vx, ev.ii, ev.kk, ev.a0
        la, xa, ta, lb, pb, tb = ev.la, ev.xa, ev.ta, ev.lb, ev.pb, ev.tb
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
        first = (np.hypot(*(ai - bb).T) <= np.hypot(*(ak - bb).T))[:, None]
        seg_b = np.stack([bb, np.where(first, ai, ak)], axis=1)  # to the nearer vertex
        segs = np.concatenate([seg_a, seg_b])
        spans = np.concatenate([seg_a, np.stack([bb, np.where(first, ak, ai)], axis=1)])
        t = np.concatenate([ta, tb])
        if len(t) == 0:
            return t, [], np.zeros(0, dtype=int), np.zeros(0, dtype=bool)
        keep = self._tangent_events(xa, ta, la, w, lb, pb, b, ii, kk)
        if self.lazy_samples:  # (the previous rules keep them)
            keep[: len(ta)] &= ~_between(s_, la < len(i), self.tol_lab)
        idx = np.flatnonzero(keep)  # the covering test only where the tangency holds
        keep[idx] = shapely.covers(self._free_near(), shapely.linestrings(segs[idx]))
        cut = np.flatnonzero(xa >= self.m)  # ends of wanted pieces: on their edge then?
        if len(cut):
            kk_ = np.flatnonzero(ev.ok)[xa[cut] - self.m]
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
        mov_id, fix = ev.mov_id, self._event_fixed()
        ids = [((int(mov_id[x]),), tuple(fix[k].tolist())) for x, k in zip(xa, la, strict=True)]
        ids += [
            ((n + int(ii[p]), n + int(kk[p])), (int(cvx[k]),)) for p, k in zip(pb, lb, strict=True)
        ]
        # the sides of each event where its wedge can be a shadow (the previous rules: either)
        side = np.zeros(len(t), dtype=int)
        if self.lazy_samples:
            k = np.flatnonzero(keep)
            side[k] = self._wedge_sides(
                k, len(ta), xa, la, w, s_, vx, spans, fix, pb, lb, cvx, ii, kk, q0 + t[:, None] * dq
            )
        return t, ids, side, keep

    def _event_times(self, q0: np.ndarray, dq: np.ndarray, lo: float, hi: float) -> _Times:
        """The times in ``(lo, hi)`` at which a moving anchor crosses an event line, or the
        line of two target vertices crosses a convex corner: the geometric candidates of
        :meth:`_event_rows`, before any test of them (:class:`_Times`)."""
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
        mov_id = self.n_fixed + np.arange(self.m)
        ok = np.zeros(0, dtype=bool)
        if len(self._cut_segs):
            ids = self.n_fixed + self.m + np.arange(len(self._cut_segs))
            with np.errstate(invalid="ignore"):  # an edge parallel to its strip segment
                c0 = self.pos(ids, np.repeat(q0v, len(ids), 0))
                c1 = self.pos(ids, np.repeat((q0 + dq)[None, :], len(ids), 0))
            ok = np.isfinite(c0).all(axis=1) & np.isfinite(c1).all(axis=1)
            mov0.append(c0[ok])
            vel.append(c1[ok] - c0[ok])
            mov_id = np.concatenate([mov_id, ids[ok]])
        x0, vx = np.vstack(mov0), np.vstack(vel)
        with np.errstate(divide="ignore", invalid="ignore"):
            # x0 + t vx on the line (p0, w)
            ta = _cross(w[:, None, :], p0[:, None, :] - x0[None]) / _cross(w[:, None, :], vx[None])
            ii, kk = np.triu_indices(self.m, 1)
            wt = self.ring0[kk] - self.ring0[ii]
            a0 = self.ring0 + q0v
            tb = _cross(wt[None], b[:, None, :] - a0[ii][None]) / _cross(wt, dq)[None]
        la, xa = np.nonzero(np.isfinite(ta) & (ta > lo) & (ta < hi))
        lb, pb = np.nonzero(np.isfinite(tb) & (tb > lo) & (tb < hi))
        return _Times(
            p0, p1, w, x0, vx, ii, kk, a0, ok, mov_id, la, xa, ta[la, xa], lb, pb, tb[lb, pb]
        )

    def _times_kept(self, q0: np.ndarray, dq: np.ndarray) -> _Times | None:
        """:meth:`_event_times` over :data:`ROWS_WINDOW` of the segment, computed once for it
        (:meth:`_may_be_live` and :meth:`_event_rows` both start from them); None where that
        window does not hold the segment's own (0, 1)."""
        lo, hi = ROWS_WINDOW
        if not (lo <= 1e-9 and 1 - 1e-9 <= hi):
            return None
        return self._per_segment(
            "_ev_times", q0, dq, lambda: self._event_times(q0, dq, lo, hi), (lo, hi)
        )

    def _per_segment(
        self,
        name: str,
        q0: np.ndarray,
        dq: np.ndarray,
        make: Callable[[], object],
        extra: tuple = (),
    ) -> object:
        """``make()``, computed once per segment ``q0 + t dq`` (and ``extra``) and kept in the
        sweeper's dict ``name``: what it keeps depends only on the segment and the sweeper's
        fixed state (lines, corners, strips, rules)."""
        cache = self.__dict__.setdefault(name, {})
        key = (q0.tobytes(), dq.tobytes(), *extra)
        got = cache.get(key)
        if got is None:
            got = cache[key] = make()
        return got

    def _event_fixed(self) -> np.ndarray:
        """(lines, 2) the two environment vertices of each event line of
        :meth:`_event_times` (``p0``'s rows): two corners, or a convex corner and its next
        or previous vertex along its ring (-1 where not known), cached."""
        got = getattr(self, "_ev_fixed", None)
        if got is None:
            _, i, j = self._event_lines()
            cvx = self._event_corners()
            nxt, prv = self._ring_neighbours()
            got = self._ev_fixed = np.vstack(
                [
                    np.stack([cvx[i], cvx[j]], axis=1),
                    np.stack([cvx, nxt[cvx]], axis=1),
                    np.stack([cvx, prv[cvx]], axis=1),
                ]
            )
        return got

    def _may_be_live(self, q0: np.ndarray, dq: np.ndarray, frames: dict) -> bool:
        """Whether :meth:`_live_mids` can find an event of the segment ``q0 + t dq`` live
        with the samples ``frames``: some candidate event of :meth:`_events`' window (before
        the tests that decide whether it counts, and its sides) has an unknown anchor (-1) or
        two anchors, one of them moving, whose line carries a shadow edge or a neighbour of
        one at a sample (:meth:`_frame_keys`), which is what makes an event live.  When
        none has, no event is live and :meth:`_live_mids` asks for nothing, whatever the
        tests would decide: the events need not be computed (yet).  The candidates' anchor
        pairs (:meth:`_candidate_pairs`) are kept per segment."""
        unknown, codes = self._per_segment(
            "_ev_pairs", q0, dq, lambda: self._candidate_pairs(q0, dq)
        )
        if unknown:
            return True
        return not codes.isdisjoint(self._frame_lines(frames)[1])

    def _candidate_pairs(self, q0: np.ndarray, dq: np.ndarray) -> tuple[bool, set]:
        """For :meth:`_may_be_live`: whether some candidate event of the segment's window
        (1e-9, 1 - 1e-9) has an unknown anchor (-1), and the pairs of the candidates' anchors
        that make an event live when a sample's shadow edge lies on their line (one of them
        moving), as integers (``a * _PAIR + b``, ``a < b``)."""
        ev = self._times_kept(q0, dq)
        if ev is None:
            ev = self._event_times(q0, dq, 1e-9, 1 - 1e-9)
        a = (ev.ta > 1e-9) & (ev.ta < 1 - 1e-9)
        b = (ev.tb > 1e-9) & (ev.tb < 1 - 1e-9)
        fix = self._event_fixed()[ev.la[a]]
        m = ev.mov_id[ev.xa[a]]
        n = self.n_fixed
        pb, lb = ev.pb[b], ev.lb[b]
        x1, x2, c = n + ev.ii[pb], n + ev.kk[pb], self._event_corners()[lb]
        pairs = np.concatenate(
            [
                np.stack([m, fix[:, 0]], axis=1),
                np.stack([m, fix[:, 1]], axis=1),
                np.stack([x1, x2], axis=1),
                np.stack([x1, c], axis=1),
                np.stack([x2, c], axis=1),
            ]
        ).astype(np.int64)
        lo, hi = np.sort(pairs, axis=1).T
        return bool((fix < 0).any()), set((lo * _PAIR + hi).tolist())

    def _wedge_sides(
        self, k, n_a, xa, la, w, s_, vx, spans, fix, pb, lb, cvx, ii, kk, qe
    ) -> np.ndarray:
        """The side codes (see ``_SIDES``) of the events ``k`` (indices into :meth:`_events`'
        arrays: the first ``n_a`` of the first kind, a target vertex x on the line of two
        corners or of an obstacle edge, ``fix[la]`` its two environment vertices; the rest of
        the second kind, the line of two target vertices through a corner; ``spans``: the
        segment spanning each event's three anchors; the other arguments as there; ``qe``:
        the target's reference point at each event).  With part of the outline wanted (5.2)
        only where the target's anchors are wanted with all of the outline near them, and
        for the second kind the target edge between them (:meth:`_wanted_near`): what p sees
        there is wanted.

        Where the event is *lone* (no obstacle edge but the corners' own comes within
        ``1e-6`` of the scene's size of its span, and the corners' edges off the line lie
        strictly on one side of it: both edges of a corner of two, the other edge at each
        end of an obstacle edge), a sight line close to the line is blocked near the event
        only where it passes a corner (or crosses the obstacle edge) on the obstacle's side,
        and reaches the target otherwise.  A point p in the wedge the event opens (beyond the
        corner farthest from the target, between the two lines through it) has two sight
        lines along them, to the two anchors on the target's side, passing that corner on
        opposite sides; and sight lines to the points of the target just beside x, on the
        target's side of the line (x's edges lie strictly on one side), pass the corners on
        that side:

        * second kind (target vertices a_n, a_f through corner b): one of the two passes b
          on its free side and reaches the target, so p is not blind and no shadow opens:
          neither side;
        * first kind, obstacles on the side opposite the target (both corners, or the
          obstacle edge): the sight lines beside x pass on the free side: neither side;
        * first kind, corners (not the two ends of one obstacle edge) of obstacles on
          opposite sides of the line: the sight line to
          x passes b_n (the corner nearer x) and b_f on opposite sides, so it is blocked
          only while it passes b_n on its obstacle's side, i.e. while x is on that side of
          the line: the side of the event where x is;
        * first kind, an obstacle edge from a convex corner b_n (nearer x) to a concave one
          b_f whose other edges lie on opposite sides of the line (a room's corner: the
          obstacle lies along the edge on b_n's side, and beyond b_f the line runs into
          it): a shadow can be born only along the edge, on its free side, between b_n and
          b_f.  A point p there, with x on the free side of the line too, sees x along a
          sight line that stays in that half-plane next to the line (b_n's other edge
          lies on the obstacle's side, b_f's rises from b_f more steeply than the sight line
          near the event), so it is blocked only while x is on the obstacle's side: the
          side of the event where x is, as in the previous case;
        * otherwise (obstacles and the target on one side, not lone): either side."""
        out = np.zeros(len(k), dtype=int)
        ka, kb = k[k < n_a], k[k >= n_a]
        ka = ka[(xa[ka] < self.m) & (fix[la[ka]] >= 0).all(axis=1)]
        if len(ka) + len(kb) == 0:
            return out
        corners = np.concatenate([fix[la[ka]], np.repeat(cvx[lb[kb - n_a], None], 2, axis=1)])
        p, q = pb[kb - n_a], self.ring0
        lines = np.concatenate([w[la[ka]], q[kk[p]] - q[ii[p]]])
        rows = np.concatenate([ka, kb])
        s0 = self._obstacle_side(corners[:, 0], corners[:, 1], lines)
        s1 = self._obstacle_side(corners[:, 1], corners[:, 0], lines)
        lone = (s0 != 0) & (s1 != 0) & self._clear(spans[rows], corners)
        na = len(ka)
        if self.strips is not None:  # 5.2: the target's anchors and what lies between wanted
            v0 = np.concatenate([xa[ka], ii[p]])
            v1 = np.concatenate([xa[ka], kk[p]])
            lone &= self._wanted_near(v0, qe[rows]) & self._wanted_near(v1, qe[rows])
            m = self.m
            e = np.where(kk[p] == ii[p] + 1, ii[p], m - 1)
            joined = (kk[p] == ii[p] + 1) | ((ii[p] == 0) & (kk[p] == m - 1))
            lone[na:] &= joined & self._wanted_near(e, qe[kb], edge=True)
        out[np.isin(k, kb[lone[na:]])] = _NEITHER  # second kind
        lone, s0, s1, lines = lone[:na], s0[:na], s1[:na], lines[:na]
        # the target's side at x: its two edges strictly on one side of the line
        x = xa[ka]
        m = self.m
        tp = _side(lines, q[(x - 1) % m] - q[x])
        tn = _side(lines, q[(x + 1) % m] - q[x])
        s_t = np.where(tp == tn, tp, 0)
        code = np.zeros(na, dtype=int)
        code[lone & (s0 == s1) & (s_t == -s0)] = _NEITHER
        # (corners of two obstacles, or not neighbours: a sight line crossing the line
        # between the two ends of an obstacle edge crosses the edge; or an obstacle edge
        # from a convex corner next to x to a concave one, a room's corner: see above)
        env = self.env
        c0, c1 = corners[:na, 0], corners[:na, 1]
        edge = (env.vert_next[c0] == env.vert[c1]).all(axis=1) | (
            env.vert_prev[c0] == env.vert[c1]
        ).all(axis=1)
        near_i = np.abs(s_[ka, 0] - s_[ka, 2]) <= np.abs(s_[ka, 1] - s_[ka, 2])
        room = self._room_edges(edge, np.where(near_i, c0, c1))
        sel = lone & (s0 == -s1) & (~edge | room)
        if sel.any():
            ks = ka[sel]
            s_near = np.where(near_i[sel], s0[sel], s1[sel])
            after = _side(lines[sel], vx[xa[ks]])
            code[sel] = np.where(after == 0, 0, np.where(after == s_near, 1, -1))
        out[np.searchsorted(k, ka)] = code
        return out

    def _room_edges(self, edge: np.ndarray, near: np.ndarray) -> np.ndarray:
        """Per row of :meth:`_wedge_sides`' first kind: is the line an obstacle edge
        (``edge``) whose end nearer x (``near``) is a convex corner (a reflex vertex of the
        free space)?  With the two ends' other edges on opposite sides of the line, its other
        end is then a concave one: a room's corner.  (n,) bool."""
        return edge & self.env.reflex[near]

    def _wanted_near(self, v: np.ndarray, q: np.ndarray, edge: bool = False) -> np.ndarray:
        """Per row, with the target at reference point ``q[r]``: is every point of its
        outline within ``1e-6`` of the scene's size of vertex ``v[r]`` wanted (no strip of
        its two edges comes that near), or with ``edge``, every point of edge ``v[r]``?"""
        arr = self._strip_array()
        m, r0 = self.m, self.ring0
        if edge:
            geom = shapely.linestrings(np.stack([r0[v] + q, r0[(v + 1) % m] + q], axis=1))
            near = [v]
        else:
            geom = shapely.points(r0[v] + q)
            near = [(v - 1) % m, v]
        ok = np.ones(len(v), dtype=bool)
        for i in near:
            d = shapely.distance(arr[i], geom)
            ok &= ~(d <= 1e-6 * self.env.scale)  # NaN: no strip, the whole edge wanted
        return ok

    def _strip_array(self) -> np.ndarray:
        """The overlap strips (``strips``), one object per target edge, None where it has
        none (cached)."""
        arr = getattr(self, "_strip_arr", None)
        if arr is None:  # the trailing None keeps numpy from nesting
            arr = self._strip_arr = np.array(
                [None if u is None or u.is_empty else u for u in self.strips] + [None],
                dtype=object,
            )[:-1]
        return arr

    def _obstacle_side(self, v: np.ndarray, other: np.ndarray, w: np.ndarray) -> np.ndarray:
        """Per row: the side (1 left, -1 right, :func:`_side`) of the line of direction ``w``
        through the environment vertex ``v`` where its edges lie, but an edge to ``other``
        (the line's other vertex: the line of an obstacle edge); 0 where one lies on the
        line or they lie on both sides."""
        env = self.env
        sp = _side(w, env.vert_prev[v] - env.vert[v])
        sn = _side(w, env.vert_next[v] - env.vert[v])
        to = env.vert[other]
        sp = np.where((env.vert_prev[v] == to).all(axis=1), sn, sp)
        sn = np.where((env.vert_next[v] == to).all(axis=1), sp, sn)
        return np.where(sp == sn, sp, 0)

    def _clear(self, segs: np.ndarray, corners: np.ndarray) -> np.ndarray:
        """Per row: does no obstacle edge but those at the environment vertices
        ``corners[r]`` come within ``1e-6`` of the scene's size of the segment
        ``segs[r]`` ((N, 2, 2))?"""
        got = getattr(self, "_edge_tree", None)
        env = self.env
        if got is None:
            lines = shapely.linestrings(env.seg.reshape(-1, 2, 2))
            got = self._edge_tree = shapely.STRtree(lines)
        r, e = got.query(shapely.linestrings(segs), predicate="dwithin", distance=1e-6 * env.scale)
        ends = env.seg[e].reshape(-1, 2, 2)
        at = env.vert[corners[r]]  # (H, 2, 2): the row's two corners
        own = (ends[:, :, None, :] == at[:, None, :, :]).all(axis=3).any(axis=(1, 2))
        out = np.ones(len(segs), dtype=bool)
        out[r[~own]] = False
        # each corner's own two edges, no more (another ring touching at the corner)
        distinct = 1 + (corners[:, 0] != corners[:, 1])
        out &= np.bincount(r[own], minlength=len(segs)) <= 2 * distinct
        return out

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
            b, bp, bn, i, j, w = _corner_pairs(self.env, self._event_corners())
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


def _tangent(w: np.ndarray, bp: np.ndarray, bn: np.ndarray, rel: float = 1e-9) -> np.ndarray:
    """Row by row: does the line of direction ``w`` through a corner keep the corner's
    two edges (``bp``, ``bn``: from the corner to its neighbours) on one side?  An edge
    within ``rel`` (relative sine) of the line counts as on it, i.e. on either side."""
    cp, cn = _cross(w, bp), _cross(w, bn)
    lw = np.hypot(w[..., 0], w[..., 1])
    zp = np.abs(cp) <= rel * lw * np.hypot(bp[..., 0], bp[..., 1])
    zn = np.abs(cn) <= rel * lw * np.hypot(bn[..., 0], bn[..., 1])
    return zp | zn | (cp * cn > 0)


#: the codes of :meth:`CollinearityEvents._events`' sides: either side, only after, only
#: before, neither
_NEITHER = 2
_SIDES = {0: (-1, 1), 1: (1,), -1: (-1,), _NEITHER: ()}


def _side(w: np.ndarray, v: np.ndarray, rel: float = 1e-9) -> np.ndarray:
    """Row by row: the side (1 left, -1 right) of the line of direction ``w`` that the
    vector ``v`` points to, 0 within ``rel`` (relative sine) of the line (as :func:`_tangent`)."""
    c = _cross(w, v)
    lw = np.hypot(w[..., 0], w[..., 1])
    zero = np.abs(c) <= rel * lw * np.hypot(v[..., 0], v[..., 1])
    return np.where(zero, 0, np.sign(c)).astype(int)


def _inside(
    times: np.ndarray, lo: float, hi: float, closes: Callable[[float, float], bool] | None
) -> bool:
    """Does the interval ``[lo, hi]`` (holding no sample time strictly inside) lie in an
    interval between two consecutive sample times of ``times`` (sorted) that ``closes``?"""
    if closes is None:
        return False
    k = int(np.searchsorted(times, lo, side="right"))
    return 0 < k < len(times) and closes(float(times[k - 1]), float(times[k]))


def _between(s_: np.ndarray, pair: np.ndarray, tol: float) -> np.ndarray:
    """Per event of a moving anchor x on the line of two corners: is x strictly between the
    corners (``s_``: (A, 3) positions of the two corners and x along the line; ``pair``: the
    line is through two corners, not along an obstacle edge)?  Then the edges on the lines
    (x, corner) are rays from each corner away from x, on opposite sides of x: neither
    continues the other, and no wedge opens there."""
    lo = np.minimum(s_[:, 0], s_[:, 1]) + tol
    hi = np.maximum(s_[:, 0], s_[:, 1]) - tol
    return pair & (s_[:, 2] > lo) & (s_[:, 2] < hi)
