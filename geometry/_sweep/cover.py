"""What the traces between two samples must cover, and where they leave a gap.

The edges whose sweep leaves the two samples' shadows are traced; the others are swept
inside the known shadows.  A gap (a line carrying shadow edges at both samples that the
traces do not cover, or a trace cut short) asks for a refinement sample.  Part of
:class:`geometry.sweep.Sweeper`.
"""

from __future__ import annotations

import numpy as np
import shapely

from .._shapes import areal, snapped
from .lines import _rot
from .trace import _row_sweeps

#: A traced edge that dies between samples while still this long relative to its length
#: at its sample was cut short by a neighbour's change: see :meth:`Coverage._cut_short_many`.
CUT_REL = 1e-3


class Coverage:
    """The coverage decisions of a :class:`~geometry.sweep.Sweeper` (a mixin of it: it
    uses the sweeper's samples and its tracing): which edges to trace
    (:meth:`_uncovered_seen_many`) and where the traces leave a gap
    (:meth:`_coverage_gap`, :meth:`_continuation_gap`)."""

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

    def _uncovered_seen_many(self, items: list[tuple]) -> list[list | None]:
        """Per item ``(edges, t, toward, ab, q0, q1)``: :meth:`_uncovered` for the shadows
        ``S_a``, ``S_b`` at the sample times ``ab`` of the sweep ``q0 -> q1``, from what they
        do not hold, ``X_a`` and ``X_b`` (:meth:`shadow`); None when one of them was not kept
        (the caller then unites the shadows).  The strips and the overlays of all items in one
        batch (shapely's functions act element by element, so each item gets what it would
        alone).

        ``S_a u S_b = F - (X_a n X_b)`` (``F`` the free space), so the part of a quad
        outside the known shadows is ``(quad - F) u (quad n X_a n X_b)``: one
        intersection of the two small sets (near the region, kept for :func:`_union_pieces`)
        instead of the union of two whole-map shadows, and the small quads cut by it.
        ``quad - F`` is left out where the quad lies in ``F`` grown by ``1e-12`` of the
        scene's size (a prepared test): its area there is below ``_free_band`` (that
        width times ``F``'s perimeter), which the threshold is lowered by, so no sweep
        that :meth:`_uncovered` would trace is dropped; ``quad n X_a n X_b`` is not cut by
        ``F`` (that area is only larger)."""
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

    def _cut_short_many(self, items: list[tuple]) -> list[list]:
        """Per item ``(edges, ends, t, toward, q0, dq)``: ``(edge, t_end, toward)`` for the
        traced ``edges`` whose trace from ``t`` ended at ``t_end`` (``ends``) strictly between
        ``t`` and ``toward`` while the edge still had length (at least ``CUT_REL`` of its
        length at ``t``): not a shadow edge that shrank to a point, but one whose neighbouring
        edge died, so that its line goes on bounding the shadow with another neighbour
        (:meth:`_continuation_gap`).  The ends of all items in one batch."""
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

    def _not_point_many(self, items: list[tuple]) -> list[list]:
        """Per item ``(edges, t, q0, dq)``: the ``edges`` longer than ``1e-6`` of the scene's
        size at time ``t``.  A shadow edge that is a point there (its neighbours' lines meet
        on its own) sweeps nothing in any configuration and tells nothing of the line's other
        configurations.  The ends of all items in one batch."""
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

    def _continuation_gap(
        self, cut: list, traced: dict, probed: list, q0, dq, held: dict
    ) -> float | None:
        """A time just after a trace was cut short (:meth:`_cut_short_many`) at ``t_end``
        where the cut edge's line still bounds a shadow and no edge on that line holds it
        (``held``: per line key ``(lo, hi, edge)``, the traces and the edges swept inside the
        known shadows, :meth:`_not_point_many`; an edge holds there where its configuration is
        the shadow's edge on that line, below), nor has an edge the exact point test does not
        confirm even at its own sample (``traced``: see :meth:`_coverage_gap`), or None.

        When a neighbouring edge dies, the edge's line goes on bounding the shadow with
        another neighbour from ``t_end`` on, and that configuration can be born and gone
        between two samples (the line's edge at the next sample, if any, then has other
        neighbours, or has collapsed; fuzz seed 204155: a sliver shadow 0.014 D long,
        missed at every sample).  A sample a tenth of the way from ``t_end`` to the next
        sample finds it and traces it both ways.  It is taken where the exact point test
        confirms, at that time, a twentieth of the cut edge at either end (the end whose
        neighbour lives on is still right, and the new edge runs from it): a line that
        bounds no shadow there has no continuation.  With the lazy rules the line must also
        *bound* the shadow along that twentieth: the same test on the mirrored probes (just
        outside the edge) must find a probe that sees the target.  Where the probes on both
        sides are blind, the line runs inside a shadow there and carries no edge at that
        time from that end longer than the probes' offset from it (``h``): the sample would
        hold no continuation to trace (``willow_south``'s 5.2 query: 6 such samples, none
        holding an edge on the cut edge's line).  Each death (``probed``: key and time,
        within ``1e-6`` of the sweep) is looked at once.

        An edge traced or swept inside the known shadows holds its line only while its own
        configuration (its two neighbours) lives: the continuation has a new neighbour at
        the cut end, and where that is not the holder's, the holder says nothing of it.  So
        a holder stands in only where it is, at the sample's time, the whole shadow edge on
        that line with its own neighbours (:meth:`_unheld`).  Fuzz seed 201693 (5.2): the
        edge at the later sample, swept inside, was taken to hold its line for the whole
        interval, its neighbour there a line through two corners, while the continuation ran
        with a line through a corner and another target vertex, born at one collinearity
        event and gone at the next, between the samples: a shadow 4.5 ``tol`` wide was
        missed.  Fuzz seed 202333 (with the wedge rule on): the traces from both samples
        reached each other's, while between them the two edges' lines met on a wall, a
        configuration neither traced (a shadow 16 ``tol`` wide)."""
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
                after = lo + 1e-9 if toward > t_end else hi - 1e-9
                holders = [e for x, y, e in held.get(key, []) if x <= after <= y]
                todo.append((edge, t_end + 0.1 * (toward - t_end), holders))
        if not todo:
            return None
        todo = self._unheld(todo, q0, dq)
        if not todo:
            return None
        tp = np.array([[t] for _, t in todo])
        vs, ve = self._ends_many([e for e, _ in todo], tp, q0, dq)  # (E, 1, 2) each
        d = 0.05 * (ve - vs)
        lo, hi, tt = np.concatenate([vs, ve - d]), np.concatenate([vs + d, ve]), np.vstack([tp, tp])
        near = self._valid_many(lo, hi, tt, q0, dq)[:, 0]
        if self.lazy_samples and near.any():  # the line must bound the shadow there
            k = np.flatnonzero(near)
            near[k] = self._line_bounds(lo[k], hi[k], tt[k], q0, dq)
        finite = np.isfinite(d).all(axis=(1, 2))
        go = ~finite | near[: len(todo)] | near[len(todo) :]
        return float(tp[np.argmax(go), 0]) if go.any() else None

    def _unheld(self, todo: list, q0, dq) -> list[tuple]:
        """``(edge, t)`` of the items ``(edge, t, holders)`` of :meth:`_continuation_gap` that
        no holder (an edge on the same line, traced or swept inside the known shadows) holds at time
        ``t``: a holder holds where it is, with its own neighbours, a whole shadow edge
        there: the exact point test confirms it (:meth:`_valid_many`) and its line does not
        go on bounding the shadow past either end (:meth:`_runs_on`).  The holders of all
        items in one batch."""
        rows = [(i, h) for i, (_, _, hs) in enumerate(todo) for h in hs]
        held_at = set()
        if rows:
            tp = np.array([[todo[i][1]] for i, _ in rows])
            vs, ve = self._ends_many([h for _, h in rows], tp, q0, dq)
            ok = self._valid_many(vs, ve, tp, q0, dq)[:, 0]
            if ok.any():
                k = np.flatnonzero(ok)
                ok[k] = ~self._runs_on(vs[k, 0], ve[k, 0], q0 + tp[k] * dq)
            held_at = {i for (i, _), v in zip(rows, ok, strict=True) if v}
        return [(e, t) for i, (e, t, _) in enumerate(todo) if i not in held_at]

    def _runs_on(self, vs: np.ndarray, ve: np.ndarray, q: np.ndarray) -> np.ndarray:
        """(E,) bool: does the line of the shadow edge ``vs -> ve`` ((E, 2) each, the shadow
        on its left, the target at ``q``, (E, 2)) go on bounding the shadow past an end?
        Past the end by ``h`` along the line, the probe just inside is blind and the one just
        outside is not (past a convex vertex of the shadow neither is blind, past a reflex
        one both are: there the edge ends)."""
        d = ve - vs
        ln = np.hypot(d[:, 0], d[:, 1])
        with np.errstate(divide="ignore", invalid="ignore"):
            u = d / ln[:, None]
        nrm = _rot(u) * (1e-3 * self.h)
        past = np.stack([vs - self.h * u, ve + self.h * u], axis=1)  # (E, 2, 2)
        probes = np.stack([past + nrm[:, None, :], past - nrm[:, None, :]], axis=1)  # in, out
        blind = self._probes_blind(probes[..., None, :], q[:, None, None, :])
        return ~np.isfinite(ln) | (blind[:, 0] & ~blind[:, 1]).any(axis=1)

    def _line_bounds(self, lo: np.ndarray, hi: np.ndarray, ts: np.ndarray, q0, dq) -> np.ndarray:
        """(E,) bool: does some probe just outside the segments ``lo -> hi`` ((E, 1, 2) each,
        the shadow on their left) see the target at times ``ts`` ((E, 1))?  The exact point
        test of :meth:`_valid_many` on the mirrored segments (``hi -> lo``: the same probes on
        the other side); where it finds every probe blind there too, the segment's line runs
        inside a shadow and bounds none along it (:meth:`_continuation_gap`)."""
        return ~self._valid_many(hi, lo, ts, q0, dq)[:, 0]

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
