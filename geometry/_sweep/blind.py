"""The sweep's exact point test: is a placement blind to every wanted point of the target?

The obstacles do not meet K = CH(A (+) G), so a ray that enters K reaches everything in
K behind its entry point: a placement sees a wanted piece of A_q iff one of its windows
into K (independent of q) overlaps a direction in which, ignoring the obstacles, that
piece is the first thing hit on A_q.  Part of :class:`geometry.sweep.Sweeper`.
"""

from __future__ import annotations

import numpy as np
import shapely

from .. import _libm
from .. import visindex as _visindex
from .._shapes import cross as _cross
from .._vis import TAU, Domain, RayEscapeError, gaps_many
from ..weak import ENV as _ENV
from ..weak import WANTED as _WANTED


class PointTest:
    """The exact point test of a :class:`~geometry.sweep.Sweeper` (a mixin of it: it uses
    the sweeper's scene and target): :meth:`blind`, row by row over placements and
    configurations."""

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
        g, off = gaps_many(self.env, p, sectors=sectors, flat=True, interior=True, ends=False)
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

    def _probes_blind(self, probes: np.ndarray, q: np.ndarray) -> np.ndarray:
        """(...) bool: every probe ``probes`` (..., P, 2) is blind to the target at
        ``q`` (..., 2) (a probe that is not finite is not blind)."""
        qq = np.broadcast_to(q[..., None, :], probes.shape)
        flat_p, flat_q = probes.reshape(-1, 2), qq.reshape(-1, 2)
        finite = np.isfinite(flat_p).all(axis=1)
        res = np.zeros(len(flat_p), dtype=bool)
        res[finite] = self.blind(flat_p[finite], flat_q[finite])
        return res.reshape(probes.shape[:-1]).all(axis=-1)


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
