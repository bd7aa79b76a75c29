"""The exact stationary shadows that a sweep samples (paper 3.2.1) and the lines of their edges.

A sample at configuration q is the shadow S(q) = F - A_q - W(A_q) (``F`` the free space,
``W`` the weak visibility region of the target's wanted pieces, :mod:`geometry.weak`),
snap-rounded; its edges are labelled by the two anchor points spanning their lines
(environment vertices, target vertices, ends of the wanted pieces), which is what the
tracing carries between samples.  Part of :class:`geometry.sweep.Sweeper`.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NamedTuple

import numpy as np
import shapely

from .. import visindex as _visindex
from .._common import polygonal
from .._shapes import areal, snapped
from .._shapes import cross as _cross
from ..weak import corners_seeing, weak_visibility, weak_visibility_many


class StationaryShadows:
    """The samples of a :class:`~geometry.sweep.Sweeper` (a mixin of it: it uses the
    sweeper's scene, target and caches): stationary shadows computed in batches
    (:meth:`shadow`, :meth:`_prefetch`) and their edges on moving lines (:meth:`_edges`)."""

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
            if key in self._eroded_pre or key in keys or key in self.__dict__.get("_eroded_xs", {}):
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
        return self._edges_many([(shadow, table, tid)])[0]

    def _edges_many(self, shadows: list[tuple]) -> list[list]:
        """:meth:`_edges` of each ``(shadow, table, tid)`` of ``shadows`` (:meth:`shadow`'s
        answers), the rings of all of them in one batch: every step below is ring by ring
        (:meth:`_label_rows` row by row, each row with its own shadow's anchor table), so
        each shadow gets what it would alone."""
        out: list[list] = [[] for _ in shadows]
        n = self.n_fixed
        per = [
            _ring_coords(_rings(shapely.orient_polygons(sh, exterior_cw=False)))
            for sh, _, _ in shadows
        ]
        merged = _drop_short_many([r for rs in per for r in rs], self.tol_lab, self._vertex_at)
        of = np.repeat(np.arange(len(shadows)), [len(rs) for rs in per])
        big = [k for k, v in enumerate(merged) if len(v) >= 3]
        if not big:
            return out
        vs = [merged[k] for k in big]
        shadow_of = of[big]  # per ring kept: its shadow
        # all rings labelled in one batch (row by row, so as if ring by ring)
        flat = np.concatenate(vs)
        off = np.cumsum([0] + [len(v) for v in vs])
        ring_of = np.repeat(np.arange(len(vs)), np.diff(off))
        idx = np.arange(len(flat))
        nxt = np.where(idx + 1 == off[ring_of + 1], off[ring_of], idx + 1)
        prv = np.where(idx == off[ring_of], off[ring_of + 1] - 1, idx - 1)
        d = flat[nxt] - flat  # each ring's edge vectors, closing edge included
        # an edge between two environment vertices far apart is on a fixed line (its key
        # is two fixed anchors, see below): only the other edges and their neighbours are
        # labelled (most of a shadow's boundary is the free space's)
        fixed = self._fixed_edges(flat, off)
        need = ~fixed | ~fixed[nxt] | ~fixed[prv]
        all_keys = np.full((len(flat), 2), -1, dtype=np.int64)
        if need.any():
            tables = [(table, tid) for _, table, tid in shadows]
            all_keys[need] = self._label_rows(flat[need], d[need], tables, shadow_of[ring_of[need]])
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
        for j in np.flatnonzero(ok).tolist():
            out[shadow_of[kr[j]]].append((tuple(kp[j]), tuple(keys[j]), tuple(kn[j])))
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
        return self._label_rows(v, d, [(table, tid)], np.zeros(len(v), dtype=np.int64))

    def _label_rows(
        self, v: np.ndarray, d: np.ndarray, tables: list[tuple], row_table: np.ndarray
    ) -> np.ndarray:
        """Per edge ``v[i] -> v[i] + d[i]``: two anchor ids spanning its line, or -1, from
        the anchor table ``tables[row_table[i]]`` (``(table, tid)``: positions and ids,
        :meth:`shadow`), row by row (the tables padded to one length with points that lie
        on no line)."""
        size = max(len(t) for t, _ in tables)
        tab_all = np.full((len(tables), size, 2), np.nan)
        ids_all = np.full((len(tables), size), -1, dtype=np.int64)
        for k, (table, tid) in enumerate(tables):
            # prefer fixed anchors, then moving ones (in table order); the padding after
            # them (NaN points) is never a candidate
            perm = np.argsort(tid >= self.n_fixed, kind="stable")
            tab_all[k, : len(table)] = table[perm]
            ids_all[k, : len(tid)] = tid[perm]
        if _visindex.available():  # the compiled twin of _on_lines
            r_on, c_on = _visindex.on_lines(v, d, tab_all, row_table, self.tol_lab)
        else:
            r_on, c_on = _on_lines(v, d, tab_all, row_table, self.tol_lab)
        keys = np.full((len(v), 2), -1, dtype=np.int64)
        # two distinct positions on the line; prefer fixed anchors, then moving ones (in
        # table order): the first pair (i, j), i before j in that order, of candidates
        # more than tol_lab apart whose line is the edge's.  Two anchors barely "far"
        # apart (the two vertices at a sliver's end, 1e-8 across) both lie on the edge's
        # line, but the line they span points anywhere: the edge's ends must lie on it
        # (fuzz seed 205296: a sliver's shadow edges were keyed to the sliver's ends,
        # read as fixed, and never traced).  The candidates come row-major: by row, then
        # in preference order
        if len(r_on) == 0:
            return keys
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
        rr = r_on[pi]
        tr = row_table[rr]
        ti, tj = tab_all[tr, ci], tab_all[tr, cj]
        good = np.abs(tj - ti).max(axis=1) > self.tol_lab
        good[good] = self._fits(ti[good], tj[good], v[rr[good]], d[rr[good]])
        pi, pj, rr = pi[good], pj[good], rr[good]
        order = np.lexsort((pj, pi))  # the first pair of each row
        rr_s = rr[order]
        r_first, first = np.unique(rr_s, return_index=True)
        sel = order[first]
        ts = row_table[r_on[pi[sel]]]
        keys[r_first] = np.sort(
            np.stack([ids_all[ts, c_on[pi[sel]]], ids_all[ts, c_on[pj[sel]]]], axis=1), axis=1
        )
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


def _on_lines(
    v: np.ndarray, d: np.ndarray, tab: np.ndarray, row_table: np.ndarray, tol: float
) -> tuple[np.ndarray, np.ndarray]:
    """The pairs ``(row, column)``, row-major, where the point ``tab[row_table[row],
    column]`` (a NaN point: never) lies within ``tol`` of the line through ``v[row]`` along
    ``d[row]``: ``|d x (p - v)| / max(|d|, 1e-300) <= tol``, the cross product's terms as
    :func:`~geometry._shapes.cross` computes them (numpy; :func:`geometry.visindex.on_lines`
    is its compiled twin)."""
    ln = np.hypot(d[:, 0], d[:, 1])
    rx = tab[row_table, :, 0] - v[:, None, 0]
    ry = tab[row_table, :, 1] - v[:, None, 1]
    with np.errstate(invalid="ignore"):
        dist = np.abs(d[:, None, 0] * ry - d[:, None, 1] * rx) / np.maximum(ln[:, None], 1e-300)
        return np.nonzero(dist <= tol)


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


class _FlatRings(NamedTuple):
    """Closed rings stored flat: ring ``r`` is ``flat[off[r] : off[r + 1]]``; per vertex its
    ring (``ring_of``), its successor and predecessor on it (``nxt``, ``prv``), and whether
    its step to the successor is short (``short``)."""

    flat: np.ndarray
    off: np.ndarray
    ring_of: np.ndarray
    nxt: np.ndarray
    prv: np.ndarray
    short: np.ndarray


def _drop_short_many(
    rings: list[np.ndarray],
    length: float,
    vertex_at: Callable[[np.ndarray], np.ndarray] | None = None,
) -> list[np.ndarray]:
    """:func:`_drop_short` of each closed ring of ``rings``: the rings without a step
    shorter than ``length`` (the closing step included), most of them, are found in one
    pass and come back as they are (as :func:`_drop_short` returns them); the rings whose
    runs of short steps are all tight (:func:`_tight_runs`: split corners, most of the
    others) are done in one batch too (:func:`_drop_tight_runs`); the rest one by one."""
    flat = np.concatenate(rings) if rings else np.zeros((0, 2))
    if len(flat) == 0:
        return list(rings)
    n_of = np.array([len(v) for v in rings])
    off = np.concatenate([[0], np.cumsum(n_of)])
    ring_of = np.repeat(np.arange(len(rings)), n_of)
    idx = np.arange(len(flat))
    nxt = np.where(idx + 1 == off[ring_of + 1], off[ring_of], idx + 1)  # closing step included
    short = np.abs(flat[nxt] - flat).max(axis=1) < length
    any_short = np.zeros(len(rings), dtype=bool)
    any_short[ring_of[short]] = True
    if not any_short.any():
        return list(rings)
    prv = np.empty_like(nxt)
    prv[nxt] = idx
    fr = _FlatRings(flat, off, ring_of, nxt, prv, short)
    s, e, tight = _tight_runs(fr, length)
    out = list(rings)
    batch = np.flatnonzero(any_short & tight)
    if len(batch):
        got = _drop_tight_runs(fr, (s, e), batch, length, vertex_at)
        for k, v in zip(batch.tolist(), got, strict=True):
            out[k] = v
    for k in np.flatnonzero(any_short & ~tight).tolist():
        out[k] = _drop_short(rings[k], length, vertex_at)
    return out


def _tight_runs(fr: _FlatRings, length: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The runs of short steps (shorter than ``length``) of the closed rings ``fr``: per
    run, its first vertex ``s`` and its last ``e`` (the steps ``s .. e - 1`` are short, the
    step from ``e`` is long), and per ring whether all its runs are *tight*: the closing
    step is long, every vertex of a run lies within ``length`` of the run's first and the
    vertex after it does not, in a ring of at least 4 vertices.  In such a ring
    :func:`_drop_short` keeps each run's first vertex and the vertices outside the runs
    (each vertex kept lies at least ``length`` from the one kept before it, and no kept
    vertex joins vertex 0's cluster), and its clusters are the runs: :func:`_drop_tight_runs`
    gives what it gives."""
    flat, off, ring_of, nxt, prv, short = fr
    tight = np.diff(off) >= 4
    if short.all():  # no step is long: no run ends (and no ring is tight)
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64), tight & False
    last = off[1:][tight] - 1
    tight[tight] = ~short[last]  # the closing step is long
    first = short & ~short[prv]  # a run's first vertex (runs do not wrap in tight rings)
    s = np.flatnonzero(first)
    longs = np.flatnonzero(~short)
    e = longs[np.minimum(np.searchsorted(longs, s), len(longs) - 1)]
    inside = np.flatnonzero(short[prv])  # the vertices a short step enters: s + 1 .. e
    run = np.cumsum(first)[inside] - 1  # the run each lies in
    ok = (run >= 0) & (run < len(s))
    near = np.zeros(len(inside), dtype=bool)
    near[ok] = np.abs(flat[inside[ok]] - flat[s[run[ok]]]).max(axis=1) < length
    tight[ring_of[inside[~near]]] = False
    apart = np.abs(flat[nxt[e]] - flat[s]).max(axis=1) >= length
    tight[ring_of[s[~apart]]] = False
    return s, e, tight


def _drop_tight_runs(
    fr: _FlatRings,
    runs: tuple[np.ndarray, np.ndarray],
    rings: np.ndarray,
    length: float,
    vertex_at: Callable[[np.ndarray], np.ndarray] | None,
) -> list[np.ndarray]:
    """:func:`_drop_short` of the rings ``rings`` (indices into ``fr``; all their runs of
    short steps tight, :func:`_tight_runs`, whose runs ``(s, e)`` are given) in one batch:
    per run, its vertices after the first are dropped and the first moved to where the
    lines of the steps entering and leaving the run cross, when that lies within ``4
    length`` of it (the same floating-point operations as :func:`_corners`); otherwise,
    where the run holds two distinct vertices of the environment (``vertex_at``), the
    first and the last of them are kept, as :func:`_corners` keeps them."""
    flat, off, ring_of, nxt, prv, short = fr
    want = np.zeros(len(off) - 1, dtype=bool)
    want[rings] = True
    sel = want[ring_of]
    s, e = runs
    pick = sel[s]
    s, e = s[pick], e[pick]
    a0, a1, b0, b1 = flat[prv[s]], flat[s], flat[e], flat[nxt[e]]
    da, db = a1 - a0, b1 - b0
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        den = da[:, 0] * db[:, 1] - da[:, 1] * db[:, 0]
        u = ((b0[:, 0] - a0[:, 0]) * db[:, 1] - (b0[:, 1] - a0[:, 1]) * db[:, 0]) / den
        cx = np.where(den != 0.0, a0[:, 0] + u * da[:, 0], np.inf)
        cy = np.where(den != 0.0, a0[:, 1] + u * da[:, 1], np.inf)
        close = (
            np.isfinite(cx)
            & np.isfinite(cy)
            & (np.maximum(np.abs(cx - a1[:, 0]), np.abs(cy - a1[:, 1])) <= 4.0 * length)
        )
    pts = flat.copy()
    pts[s[close], 0], pts[s[close], 1] = cx[close], cy[close]
    keep = sel & ~short[prv]
    if vertex_at is not None:
        for k in np.flatnonzero(~close).tolist():  # rare: a short edge, not a split corner
            idx = np.arange(s[k], e[k] + 1)
            at = vertex_at(flat[idx])
            env = np.flatnonzero(at >= 0)
            if len(env) and (at[env] != at[env[0]]).any():
                pts[s[k]] = flat[idx[env[0]]]
                keep[idx[env[at[env] != at[env[0]]][-1]]] = True
    kept = np.flatnonzero(keep)
    starts, ends = np.searchsorted(kept, off[rings]), np.searchsorted(kept, off[rings + 1])
    return [pts[kept[a:b]] for a, b in zip(starts.tolist(), ends.tolist(), strict=True)]


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
