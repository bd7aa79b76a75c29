"""Hiding Recognize's target at reset, for many sub-environments in one call.

:func:`place_targets` is plain scalar Python: compiled by numba when the ``fast`` extra is
installed, run as is otherwise.  One source, and floating-point operations that Python and
numba evaluate identically (IEEE doubles, libm's ``cos``/``sin``, no fused multiply-adds),
so both give bitwise the same targets.

Randomness comes from a block of pre-drawn uniforms per sub-environment
(:class:`TargetTables` ``.U``), refilled from the sub-environment's own generator when fewer
than :data:`NEED` remain, so a sub-environment of a batch hides its targets exactly where a
single env seeded the same way hides them.

Per reset of row ``i`` (world frame, scene units):

1. the side: G when ``u < 1/2``, else H;
2. up to :data:`TRIES` attempts, each taking four uniforms: a point of the side's region
   uniform by area (a triangle of its triangulation chosen by area, a uniform point in it;
   the point itself when the region is a point) and, for a rotating target, an orientation
   uniform in ``[0, 2 pi)``; an attempt is kept when the robot (a disc of ``radius``) keeps
   clear of the placed target by more than ``1e-9`` -- always when it keeps clear of the
   side's must-see hull, which holds every placement;
3. the target's edges (unit normals pointing out of it) are written after row ``i``'s
   static edges in the sensed/collided segments, and alone in the target's segments.
"""

from __future__ import annotations

import math

import numpy as np

from .kernels import HAVE_NUMBA, numba
from .segments import PAD

__all__ = ["NEED", "TRIES", "TargetTables", "place_targets", "targets_clear"]

#: attempts at a placement clear of the robot
TRIES = 20
#: uniforms one reset may use (the side, then four per attempt)
NEED = 1 + 4 * TRIES
#: uniforms drawn per refill of a row's block
BLOCK = 4 * NEED


def place_targets(idx, U, uptr, P, radius, tri, cum, ntri, pts, tgt, nv, rot, H, nh, trows,
                  nstat, S, TS, side, poly):  # fmt: skip
    """Hide the target of rows ``idx`` (see the module docstring).

    ``U (N, RB)`` uniforms, ``uptr (N,)`` next unused; ``P`` poses (row 0, 1: x, y);
    ``tri (N, 2, T, 3, 2)`` triangles of G and H, ``cum (N, 2, T)`` their cumulative area
    weights, ``ntri (N, 2)`` their counts (0: the region is the point ``pts[i, g]``);
    ``tgt (N, V, 2)`` the target's vertices (``nv[i]`` of them) at the origin, ``rot (N,)``
    rotating; ``H (N, 2, K, 2)`` the must-see hulls (``nh[i, g]`` vertices); ``trows (N, 6,
    V)`` the target's edge rows at the origin; ``nstat (N,)`` static edges per row.
    Writes ``S (6, N, M)`` (after the static edges), ``TS (6, N, V)``, ``side (N,)`` (1: G,
    2: H) and ``poly (N, V, 2)`` (the placed target's vertices)."""
    lim = radius + 1e-9
    for k in range(idx.shape[0]):
        i = idx[k]
        p = uptr[i]
        g = 0 if U[i, p] < 0.5 else 1
        p += 1
        side[i] = g + 1
        px = P[0, i]
        py = P[1, i]
        far = _dist_placed(px, py, H[i], g, nh[i, g]) > lim
        m = nv[i]
        qx = 0.0
        qy = 0.0
        for _ in range(TRIES):
            u0 = U[i, p]
            u = U[i, p + 1]
            v = U[i, p + 2]
            th = U[i, p + 3] * (2 * math.pi) if rot[i] else 0.0
            p += 4
            nt = ntri[i, g]
            if nt == 0:
                qx = pts[i, g, 0]
                qy = pts[i, g, 1]
            else:
                j = 0
                while j < nt and cum[i, g, j] <= u0:
                    j += 1
                j = min(j, nt - 1)
                if u + v > 1:
                    u = 1 - u
                    v = 1 - v
                t0x = tri[i, g, j, 0, 0]
                t0y = tri[i, g, j, 0, 1]
                qx = t0x + u * (tri[i, g, j, 1, 0] - t0x) + v * (tri[i, g, j, 2, 0] - t0x)
                qy = t0y + u * (tri[i, g, j, 1, 1] - t0y) + v * (tri[i, g, j, 2, 1] - t0y)
            c = math.cos(th)
            s = math.sin(th)
            for q in range(m):
                poly[i, q, 0] = (tgt[i, q, 0] * c - tgt[i, q, 1] * s) + qx
                poly[i, q, 1] = (tgt[i, q, 0] * s + tgt[i, q, 1] * c) + qy
            if far or _dist_placed(px, py, poly, i, m) > lim:
                break
        uptr[i] = p
        ns = nstat[i]
        if rot[i]:
            area2 = 0.0
            for q in range(m):
                qn = q + 1 if q + 1 < m else 0
                area2 += poly[i, q, 0] * poly[i, qn, 1] - poly[i, qn, 0] * poly[i, q, 1]
            flip = -1.0 if area2 > 0 else 1.0
            for q in range(m):
                qn = q + 1 if q + 1 < m else 0
                ex = poly[i, qn, 0] - poly[i, q, 0]
                ey = poly[i, qn, 1] - poly[i, q, 1]
                L = math.sqrt(ey * ey + ex * ex)
                L = L if L != 0.0 else 1.0
                row = (poly[i, q, 0], poly[i, q, 1], ex, ey, flip * (-ey / L), flip * (ex / L))
                for f in range(6):
                    TS[f, i, q] = row[f]
        else:
            for q in range(m):
                TS[0, i, q] = trows[i, 0, q] + qx
                TS[1, i, q] = trows[i, 1, q] + qy
                for f in range(2, 6):
                    TS[f, i, q] = trows[i, f, q]
        for q in range(m, TS.shape[2]):
            TS[0, i, q] = PAD
            TS[1, i, q] = PAD
            for f in range(2, 6):
                TS[f, i, q] = 0.0
        for q in range(m):
            for f in range(6):
                S[f, i, ns + q] = TS[f, i, q]
        for q in range(ns + m, S.shape[2]):
            S[0, i, q] = PAD
            S[1, i, q] = PAD
            for f in range(2, 6):
                S[f, i, q] = 0.0


def _dist_placed(px, py, poly, i, m):
    """Distance from ``(px, py)`` to the polygon ``poly[i, :m]`` (0 inside): a placed target,
    or a must-see hull ``H[r][g, :nh]``."""
    best = math.inf
    cross = 0
    for k in range(m):
        kn = k + 1 if k + 1 < m else 0
        x1 = poly[i, k, 0]
        y1 = poly[i, k, 1]
        x2 = poly[i, kn, 0]
        y2 = poly[i, kn, 1]
        ex = x2 - x1
        ey = y2 - y1
        ax = px - x1
        ay = py - y1
        L2 = ex * ex + ey * ey
        t = (ax * ex + ay * ey) / (L2 if L2 > 0.0 else 1.0)
        t = max(min(t, 1.0), 0.0)
        qx = ax - t * ex
        qy = ay - t * ey
        best = min(best, qx * qx + qy * qy)
        if (y1 > py) != (y2 > py) and px < x1 + (py - y1) / (y2 - y1) * ex:
            cross += 1
    if cross % 2 == 1:
        return 0.0
    return math.sqrt(best)


def targets_clear(idx, P, radius, poly, nv, out):
    """``out[k]`` = whether the robot of row ``idx[k]`` (a disc of ``radius`` at ``P[0:2,
    i]``) keeps clear of its placed target ``poly[i, :nv[i]]`` by more than ``1e-9``.  False
    where every attempt of :func:`place_targets` met the robot (G or H a point whose target
    covers the start)."""
    lim = radius + 1e-9
    for k in range(idx.shape[0]):
        i = idx[k]
        out[k] = _dist_placed(P[0, i], P[1, i], poly, i, nv[i]) > lim


if HAVE_NUMBA:  # pragma: no cover - exercised when numba is installed
    _jit = numba.njit(cache=True, nogil=True, error_model="numpy")
    _dist_placed = _jit(_dist_placed)
    place_targets = _jit(place_targets)
    targets_clear = _jit(targets_clear)


class TargetTables:
    """Per-row arrays :func:`place_targets` reads (padded; filled by :meth:`load` when a
    row gets a world) and the rows' blocks of uniforms."""

    def __init__(self, n: int) -> None:
        self.n = n
        self.U = np.zeros((n, BLOCK))
        self.uptr = np.full(n, BLOCK, dtype=np.int64)
        self.tri = np.zeros((n, 2, 1, 3, 2))
        self.cum = np.ones((n, 2, 1))
        self.ntri = np.zeros((n, 2), dtype=np.int64)
        self.pts = np.zeros((n, 2, 2))
        self.tgt = np.zeros((n, 1, 2))
        self.nv = np.zeros(n, dtype=np.int64)
        self.rot = np.zeros(n, dtype=np.bool_)
        self.H = np.zeros((n, 2, 1, 2))
        self.nh = np.zeros((n, 2), dtype=np.int64)
        self.trows = np.zeros((n, 6, 1))
        self.nstat = np.zeros(n, dtype=np.int64)
        self.poly = np.zeros((n, 1, 2))

    def _fit(self, name: str, shape: tuple[int, ...]) -> np.ndarray:
        a = getattr(self, name)
        want = tuple(max(w, h) for w, h in zip(shape, a.shape[1:], strict=True))
        if want != a.shape[1:]:
            pad = [(0, 0)] + [(0, w - h) for w, h in zip(want, a.shape[1:], strict=True)]
            a = np.pad(a, pad, constant_values=1.0 if name == "cum" else 0.0)
            setattr(self, name, a)
        return a

    def load(self, i: int, world, target_rows: np.ndarray, nstat: int) -> None:
        """Row ``i`` := ``world``'s G and H, target and must-see hulls; ``target_rows``
        ``(6, V)``: the target's edges at the origin; ``nstat``: the row's static edges."""
        for g, (which, geom) in enumerate(
            (("goal", world.goal_geom), ("failure", world.failure_geom))
        ):
            if geom.geom_type == "Point":
                self.ntri[i, g] = 0
                self.pts[i, g] = (geom.x, geom.y)
            else:
                arr, cum = world.triangles(which)
                t = len(arr)
                self._fit("tri", (2, t, 3, 2))[i, g, :t] = arr
                c = self._fit("cum", (2, t))
                c[i, g] = 1.0
                c[i, g, :t] = cum
                self.ntri[i, g] = t
            h = world.must_see[g]
            self._fit("H", (2, len(h), 2))[i, g, : len(h)] = h
            self.nh[i, g] = len(h)
        v = len(world.target)
        self._fit("tgt", (v, 2))[i, :v] = world.target
        self._fit("trows", (6, v))[i, :, :v] = target_rows
        self._fit("poly", (v, 2))
        self.nv[i] = v
        self.rot[i] = world.theta is None
        self.nstat[i] = nstat

    def refill(self, idx: np.ndarray, rngs) -> None:
        """Give the rows of ``idx`` with fewer than :data:`NEED` uniforms left a new block
        from their generators."""
        low = idx[self.uptr[idx] > BLOCK - NEED]
        for i in low.tolist():
            self.U[i] = rngs[i].random(BLOCK)
            self.uptr[i] = 0
