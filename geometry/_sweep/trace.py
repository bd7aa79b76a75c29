"""The tracing of the moving shadow edges between two samples.

A shadow edge's ends are the intersections of its line with its neighbours' lines at any
time (they run on lines or conics, the paper's free shadow vertices); the trace is kept
while the exact point test on probes just inside the shadow confirms it, its death located
by bisection, and it is a polyline within ``tol`` of its curves.  Part of
:class:`geometry.sweep.Sweeper`.
"""

from __future__ import annotations

import numpy as np
import shapely

from .._shapes import cross as _cross
from .lines import _corner_pairs, _meet, _rot

#: The bisection of a traced edge's death time tests this many levels of its binary
#: tree of midpoints in one batch: see :meth:`EdgeTracing._bisect`.
BISECT_LEVELS = 3


class EdgeTracing:
    """The edge tracing of a :class:`~geometry.sweep.Sweeper` (a mixin of it: it uses the
    sweeper's anchors and its point test): :meth:`_trace_groups` over batches of
    intervals, with their time grids (:meth:`_grid_many`) and death times
    (:meth:`_bisect`)."""

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
            b, bp, bn, i, j, w = _corner_pairs(env, self._anchors())
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


def _rows(x: np.ndarray, idx: np.ndarray) -> np.ndarray:
    """Rows ``idx`` of a per-row array ``x`` (E, 1, 2), or ``x`` itself when it is one row
    for all (2,)."""
    return x if x.ndim == 1 else x[idx]


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
