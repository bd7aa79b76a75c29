"""The fused step: one compiled (numba) call advances a whole batch of robot envs.

:func:`robot_step` runs, for every stepping sub-environment ``i`` and in this order, what the
modular numpy path of :class:`~.sim.BatchSim` runs as separate array operations:

1. **drive** -- translate in the robot frame, swept (a point robot) against walls, obstacles
   and the target, then turn (:meth:`BatchSim.drive`);
2. **sense** -- the executed sensor pose (displaced within ``eps_pos``, cut short at walls,
   turned within ``eps_aim``, from the pre-drawn uniforms), the beam cast with culling and
   the truncated range noise (:meth:`BatchSim.sense`), and the map-predicted ranges;
3. **query** -- the exact region test (:func:`point_in_region`, which answers as shapely's
   ``contains_xy`` on the exact region: boundary points are outside), the aim check and the
   distance to the region (:meth:`BatchSim.query`);
4. **the task's rules** -- Navigate's or Recognize's reward, termination and truncation.

Then :func:`obs_kernel` writes the robot vector observation's leading entries as float32 into
a preallocated buffer (the optional tail -- ``map_evidence``, ``sensor_fov``, ... -- is
filled afterwards by :class:`~.observations.RobotVectorObs`).

Every floating-point expression is the numpy path's, in the same order, so the two give
bitwise the same answers (the tests compare whole episodes).  Transcendentals are libm's
(numba's ``math``); the numpy path evaluates the ones whose numpy versions may differ
(``arctan2``, ``arcsin`` with SVML) through :func:`.kernels.libm`.

The single env calls the same kernel with ``idx = [0]``: there is one implementation.
Without numba (``HAVE_NUMBA`` false) nothing here is compiled and the numpy path runs.
"""

from __future__ import annotations

import math

import numpy as np

from .kernels import HAVE_NUMBA, numba

__all__ = [
    "FUSED",
    "NAVIGATE",
    "P_DECLARE_HOLD",
    "P_DISC",
    "P_OBS_MAP",
    "P_MAP",
    "P_MAX_STEPS",
    "P_MAX_TURN",
    "P_NOISE",
    "P_SHAPING",
    "P_STEP_COST",
    "P_SUCCESS_BONUS",
    "RECOGNIZE",
    "orient_sign",
    "point_in_region",
]

#: the fused kernels are available (numba installed and not disabled)
FUSED = HAVE_NUMBA

NAVIGATE, RECOGNIZE = 0, 1
# indices into the float64 parameter vector of a batch (``BatchSim.params``)
P_NOISE, P_MAX_TURN, P_STEP_COST, P_SUCCESS_BONUS, P_SHAPING = 0, 1, 2, 3, 4
P_MAX_STEPS, P_DECLARE_HOLD, P_DISC, P_MAP, P_OBS_MAP = 5, 6, 7, 8, 9
N_PARAMS = 10

# rows of the per-sub-environment constants ``BatchSim.C``
C_NAMES = (
    "diameter",
    "reach",
    "skin",
    "eps_pos",
    "eps_aim",
    "fov",
    "max_range",
    "max_speed",
)

TWO_PI = 2 * math.pi
PI = math.pi
_SPLIT = 134217729.0  # 2**27 + 1 (Dekker's split)
_ERRBOUND = 3.3306690738754716e-16  # (3 + 16 eps) eps: the double determinant's sign is exact


def _py_orient_exact(p1x, p1y, p2x, p2y, qx, qy) -> int:
    """Exact sign of ``cross(p2 - p1, q - p1)`` by rational arithmetic (a test oracle)."""
    from fractions import Fraction as F

    d = (F(p2x) - F(p1x)) * (F(qy) - F(p1y)) - (F(p2y) - F(p1y)) * (F(qx) - F(p1x))
    return (d > 0) - (d < 0)


if HAVE_NUMBA:  # pragma: no cover - exercised when numba is installed
    # error_model="numpy": a division by zero gives inf/nan (never raised: every one is
    # guarded as in the numpy code) and leaves the loops free of checks, so they vectorise
    njit = numba.njit(cache=True, nogil=True, error_model="numpy")

    # ---- exact predicates ----------------------------------------------------------------
    @njit
    def _two_sum(a, b):
        x = a + b
        bv = x - a
        av = x - bv
        return x, (a - av) + (b - bv)

    @njit
    def _split(a):
        c = _SPLIT * a
        hi = c - (c - a)
        return hi, a - hi

    @njit
    def _two_prod(a, b):
        x = a * b
        ah, al = _split(a)
        bh, bl = _split(b)
        err = x - ah * bh
        err = err - al * bh
        err = err - ah * bl
        return x, al * bl - err

    @njit
    def _exact_sign(terms, n):
        """Sign of the exact sum of ``terms[:n]`` (Shewchuk's grow-expansion with zero
        elimination: a nonoverlapping expansion whose largest component has the sum's
        sign)."""
        e = np.empty(2 * n + 1)
        m = 0
        for k in range(n):
            q = terms[k]
            j = 0
            for i in range(m):
                q, h = _two_sum(q, e[i])
                if h != 0.0:
                    e[j] = h
                    j += 1
            e[j] = q
            m = j + 1
        for i in range(m - 1, -1, -1):
            if e[i] > 0.0:
                return 1
            if e[i] < 0.0:
                return -1
        return 0

    @njit
    def _prod_terms(a1, a0, b1, b0, sg, t, k):
        """``t[k:k+8]`` := the exact product ``sg (a1 + a0)(b1 + b0)`` as eight doubles."""
        h, lo = _two_prod(a1, b1)
        t[k], t[k + 1] = sg * h, sg * lo
        h, lo = _two_prod(a1, b0)
        t[k + 2], t[k + 3] = sg * h, sg * lo
        h, lo = _two_prod(a0, b1)
        t[k + 4], t[k + 5] = sg * h, sg * lo
        h, lo = _two_prod(a0, b0)
        t[k + 6], t[k + 7] = sg * h, sg * lo

    @njit
    def orient_sign(p1x, p1y, p2x, p2y, qx, qy):
        """Exact sign of ``cross(p2 - p1, q - p1)``: 1 when ``q`` lies left of the line
        ``p1 -> p2``, -1 right, 0 on it (a floating-point filter, then exact expansion
        arithmetic on the rare nearly collinear triples)."""
        left = (p2x - p1x) * (qy - p1y)
        right = (p2y - p1y) * (qx - p1x)
        det = left - right
        if left > 0.0:
            if right <= 0.0:
                return 1 if det > 0.0 else (-1 if det < 0.0 else 0)
            detsum = left + right
        elif left < 0.0:
            if right >= 0.0:
                return 1 if det > 0.0 else (-1 if det < 0.0 else 0)
            detsum = -left - right
        else:
            return 1 if det > 0.0 else (-1 if det < 0.0 else 0)
        bound = _ERRBOUND * detsum
        if det >= bound or -det >= bound:
            return 1 if det > 0.0 else -1
        # exact: differences as two-term expansions, products as four two-products each
        a1, a0 = _two_sum(p2x, -p1x)
        b1, b0 = _two_sum(qy, -p1y)
        c1, c0 = _two_sum(p2y, -p1y)
        d1, d0 = _two_sum(qx, -p1x)
        t = np.empty(16)
        _prod_terms(a1, a0, b1, b0, 1.0, t, 0)
        _prod_terms(c1, c0, d1, d0, -1.0, t, 8)
        return _exact_sign(t, 16)

    @njit
    def point_in_region(px, py, R, r):
        """Whether ``(px, py)`` lies in the interior of the region whose boundary segments
        are row ``r`` of ``R`` ``(4, N, S)`` (start x, y, end x, y; padding at ``PAD``):
        the crossing count of a ray towards +x with exact orientations, a point on any
        boundary segment or vertex being outside -- what GEOS's prepared point locator,
        hence shapely's ``contains_xy``, answers."""
        cross = 0
        for s in range(R.shape[2]):
            x1 = R[0, r, s]
            y1 = R[1, r, s]
            x2 = R[2, r, s]
            y2 = R[3, r, s]
            if x1 < px and x2 < px:
                continue
            if px == x2 and py == y2:
                return False
            if y1 == py and y2 == py:
                lo = x1 if x1 <= x2 else x2
                hi = x2 if x1 <= x2 else x1
                if px >= lo and px <= hi:
                    return False
                continue
            if (y1 > py and y2 <= py) or (y2 > py and y1 <= py):
                o = orient_sign(x1, y1, x2, y2, px, py)
                if o == 0:
                    return False
                if y2 < y1:
                    o = -o
                if o > 0:
                    cross += 1
        return cross % 2 == 1

    @njit
    def region_test(x, y, R, idx, out):
        """``out[k]`` := :func:`point_in_region` of ``(x[k], y[k])`` in row ``idx[k]``."""
        for k in range(idx.shape[0]):
            out[k] = point_in_region(x[k], y[k], R, idx[k])

    @njit
    def clip_unit(a):
        """Clip ``a`` to [-1, 1] in place (as ``np.clip``); ``False`` (``a`` untouched) when
        it holds a NaN or an infinity."""
        f = a.ravel()
        for k in range(f.shape[0]):
            if not math.isfinite(f[k]):
                return False
        for k in range(f.shape[0]):
            f[k] = min(max(f[k], -1.0), 1.0)
        return True

    # ---- mechanics of one row --------------------------------------------------------------
    @njit
    def _sweep_point(px, py, dx, dy, S, r, skin, tt):
        """:func:`.kernels.point_sweep` for one motion against row ``r`` of ``S``; 1 when
        not moving (as :func:`.collision.sweep_batch`).  ``tt (M,)``: scratch (the first
        loop runs on SIMD lanes; the second keeps the first segment of least ``t``)."""
        if dx == 0.0 and dy == 0.0:
            return 1.0
        M = S.shape[2]
        for q in range(M):
            ax = S[0, r, q] - px
            ay = S[1, r, q] - py
            den = dx * S[3, r, q] - dy * S[2, r, q]
            inv = 1.0 / den if den != 0.0 else np.inf
            t = (ax * S[3, r, q] - ay * S[2, r, q]) * inv
            u = (ax * dy - ay * dx) * inv
            ok = (u >= 0.0) & (u <= 1.0) & (t >= 0.0)
            tt[q] = t if ok else np.inf
        best = np.inf
        bi = 0
        for q in range(M):
            if tt[q] < best:
                best = tt[q]
                bi = q
        if best <= 1.0:
            rate = max(abs(S[4, r, bi] * dx + S[5, r, bi] * dy), 1e-300)
            return max(0.0, best - skin / rate)
        return 1.0

    @njit
    def _cast_row(ox, oy, c, s, OFF, S, r, reach, ddx, ddy, best, bi, dist, nrm, hit, i):
        """:func:`.kernels.cast` (culled) of row ``i``'s fan from ``(ox, oy)`` turned by
        ``(c, s) = (cos, sin)`` of the aim against row ``r`` of ``S``; writes ``dist[i]``,
        ``nrm[i]`` and ``hit[i]`` (only ``dist`` when ``hit`` is empty).  ``ddx, ddy, best,
        bi`` ``(B,)``: scratch.  Segments outside, beams inside: the inner loop runs on SIMD
        lanes, and each beam still keeps the first segment of least distance."""
        B = OFF.shape[2]
        for j in range(B):
            ddx[j] = OFF[0, r, j] * c - OFF[1, r, j] * s
            ddy[j] = OFF[1, r, j] * c + OFF[0, r, j] * s
            best[j] = np.inf
            bi[j] = 0.0
        for q in range(S.shape[2]):
            x0 = S[0, r, q]
            y0 = S[1, r, q]
            if not (S[4, r, q] * (ox - x0) + S[5, r, q] * (oy - y0) > 0.0):
                continue  # faces away from the origin (culled)
            ex = S[2, r, q]
            ey = S[3, r, q]
            ax = x0 - ox
            ay = y0 - oy
            tn = ax * ey - ay * ex
            fq = float(q)
            for j in range(B):
                den = ddx[j] * ey - ddy[j] * ex
                inv = 1.0 / den if den != 0.0 else np.inf
                t = tn * inv
                u = (ax * ddy[j] - ay * ddx[j]) * inv
                ok = (u >= 0.0) & (u <= 1.0) & (t >= 0.0) & (t < best[j])
                best[j] = t if ok else best[j]
                bi[j] = fq if ok else bi[j]
        for j in range(B):
            h = best[j] <= reach
            dist[i, j] = best[j] if h else reach
            if hit.shape[0] == 0:
                continue
            hit[i, j] = h
            if h:
                q = int(bi[j])
                px = S[4, r, q]
                py = S[5, r, q]
                side = -(px * (S[0, r, q] - ox) + py * (S[1, r, q] - oy))
                sg = 1.0 if side > 0 else (-1.0 if side < 0 else 0.0)
                nrm[i, j, 0] = px * sg
                nrm[i, j, 1] = py * sg
            else:
                nrm[i, j, 0] = 0.0
                nrm[i, j, 1] = 0.0

    @njit
    def _wrap(a):
        return (a + PI) % TWO_PI - PI

    @njit
    def _aim_ok(x, y, psi, hulls, centers, i, fov, eps_aim, eps_pos, max_range):
        """:func:`.queries.aim_ok_batch` for one pose (same expressions, same order)."""
        K = hulls.shape[2]
        full = fov >= TWO_PI - 1e-12
        if full and max_range == np.inf:
            return True
        far = 0.0
        for g in range(2):
            for k in range(K):
                dvx = hulls[i, g, k, 0] - x
                dvy = hulls[i, g, k, 1] - y
                d = math.sqrt(dvx * dvx + dvy * dvy)
                if d > far:
                    far = d
        if far + eps_pos > max_range:
            return False
        if full:
            return True
        half = 0.5 * fov
        for g in range(2):
            inside = True
            base = math.atan2(centers[i, g, 1] - y, centers[i, g, 0] - x)
            off = _wrap(base - psi)
            lo = np.inf
            hi = -np.inf
            dmin = np.inf
            for k in range(K):
                kn = k + 1 if k + 1 < K else 0
                vx = hulls[i, g, k, 0]
                vy = hulls[i, g, k, 1]
                dvx = vx - x
                dvy = vy - y
                ex = hulls[i, g, kn, 0] - vx
                ey = hulls[i, g, kn, 1] - vy
                if not (ex * (-dvy) - ey * (-dvx) >= 0):
                    inside = False
                rel = _wrap(math.atan2(dvy, dvx) - base)
                lo = min(lo, rel)
                hi = max(hi, rel)
                if eps_pos > 0:
                    L2 = max(ex * ex + ey * ey, 1e-300)
                    t = min(max((dvx * -ex + dvy * -ey) / L2, 0.0), 1.0)
                    qx = -dvx - t * ex
                    qy = -dvy - t * ey
                    dmin = min(dmin, math.sqrt(qx * qx + qy * qy))
            if inside:
                return False
            margin = eps_aim
            if eps_pos > 0:
                margin = margin + math.asin(min(1.0, eps_pos / max(dmin, 1e-300)))
            if off + lo < -half + margin or off + hi > half - margin:
                return False
        return True

    @njit
    def _region_distance(x, y, RS, r, inside):
        """:meth:`BatchSim.query`'s distance: 0 inside, ``inf`` for an empty region."""
        if inside:
            return 0.0
        best = np.inf
        for s in range(RS.shape[2]):
            ax = x - RS[0, r, s]
            ay = y - RS[1, r, s]
            ex = RS[2, r, s]
            ey = RS[3, r, s]
            L2 = ex * ex + ey * ey
            t = (ax * ex + ay * ey) / (L2 if L2 > 0.0 else 1.0)
            t = max(min(t, 1.0), 0.0)
            qx = ax - t * ex
            qy = ay - t * ey
            d2 = qx * qx + qy * qy
            if d2 < best:
                best = d2
        d = math.sqrt(best)
        return np.inf if d >= 1e14 else d

    @njit
    def _query_row(x, y, psi, i, C, atriv, R, RS, hulls, centers):
        inside = point_in_region(x, y, R, i)
        aim = True
        if not atriv[i]:
            aim = _aim_ok(x, y, psi, hulls, centers, i, C[5, i], C[4, i], C[3, i], C[6, i])
        return inside, aim, _region_distance(x, y, RS, i, inside)

    @njit
    def query_kernel(idx, x, y, psi, C, atriv, R, RS, hulls, centers, rec, ins, aim, dist):
        """:meth:`BatchSim.query` of the poses ``(x[k], y[k], psi[k])`` in rows ``idx``."""
        for k in range(idx.shape[0]):
            i = idx[k]
            a, b, d = _query_row(x[k], y[k], psi[k], i, C, atriv, R, RS, hulls, centers)
            ins[k] = a
            aim[k] = b
            rec[k] = a and b
            dist[k] = d

    @njit
    def _sense_row(i, P, C, stoch, noise, OFF, S, U, Z, ptr, sd, sn, sh, sa, W):
        """:meth:`BatchSim.sense` of row ``i`` (the pre-drawn block already refilled)."""
        x = P[0, i]
        y = P[1, i]
        psi = P[2, i]
        if stoch[i]:
            p = ptr[i]
            ptr[i] = p + 1
            ep = C[3, i]
            ea = C[4, i]
            rr = ep * math.sqrt(U[i, p, 0])
            phi = -PI + TWO_PI * U[i, p, 1]
            ddx = rr * math.cos(phi)
            ddy = rr * math.sin(phi)
            if ep > 0:
                t = _sweep_point(x, y, ddx, ddy, S, i, C[2, i], W[4])
                x = x + t * ddx
                y = y + t * ddy
            if ea > 0:
                psi = psi + (-ea + 2 * ea * U[i, p, 2])
        c = math.cos(psi)
        s = math.sin(psi)
        reach = C[1, i]
        _cast_row(x, y, c, s, OFF, S, i, reach, W[0], W[1], W[2], W[3], sd, sn, sh, i)
        B = OFF.shape[2]
        if stoch[i] and noise > 0:
            p = ptr[i] - 1
            for j in range(B):
                d = sd[i, j]
                if sh[i, j]:
                    z = min(max(Z[i, p, j], -3.0), 3.0)
                    d = d + noise * z
                sd[i, j] = min(max(d, 0.0), reach)
        for j in range(B):
            sa[i, j] = OFF[2, i, j] + psi
        P[3, i] = x
        P[4, i] = y
        P[5, i] = psi

    @njit
    def _map_row(i, P, C, OFF, SS, md, W, nohit, nonrm):
        c = math.cos(P[2, i])
        s = math.sin(P[2, i])
        _cast_row(
            P[0, i], P[1, i], c, s, OFF, SS, i, C[1, i], W[0], W[1], W[2], W[3], md, nonrm, nohit, i
        )

    @njit
    def _obs_row(i, P, K, sd, sn, md, use_map, out, k):
        """The robot vector observation's leading ``8 + 3 B`` (+ ``B`` map ranges) entries
        of row ``i`` into ``out[k]`` (float32), as :class:`RobotVectorObs`."""
        x = P[0, i]
        y = P[1, i]
        psi = P[2, i]
        c = math.cos(psi)
        s = math.sin(psi)
        B = sd.shape[1]
        out[k, 0] = np.float32(min(max((x - K[i, 0]) * K[i, 2] - 1.0, -1.0), 1.0))
        out[k, 1] = np.float32(min(max((y - K[i, 1]) * K[i, 3] - 1.0, -1.0), 1.0))
        out[k, 2] = np.float32(c)
        out[k, 3] = np.float32(s)
        for g in range(2):
            gx = K[i, 6 + 2 * g] - x
            gy = K[i, 7 + 2 * g] - y
            out[k, 4 + 2 * g] = np.float32((c * gx + s * gy) * K[i, 4])
            out[k, 5 + 2 * g] = np.float32((c * gy - s * gx) * K[i, 4])
        for j in range(B):
            out[k, 8 + j] = np.float32(sd[i, j] * K[i, 5])
            out[k, 8 + B + j] = np.float32(c * sn[i, j, 0] + s * sn[i, j, 1])
            out[k, 8 + 2 * B + j] = np.float32(c * sn[i, j, 1] - s * sn[i, j, 0])
        if use_map:
            for j in range(B):
                out[k, 8 + 3 * B + j] = np.float32(md[i, j] * K[i, 5])

    @njit
    def sense_kernel(idx, P, C, stoch, prm, OFF, S, SS, U, Z, ptr, sd, sn, sh, sa, md, has):
        """:meth:`BatchSim.sense` of rows ``idx``; returns how many used up their pre-drawn
        block."""
        B = OFF.shape[2]
        W = (np.empty(B), np.empty(B), np.empty(B), np.empty(B), np.empty(S.shape[2]))
        nohit = np.empty((0, 0), dtype=np.bool_)
        nonrm = np.empty((0, 0, 2))
        used = 0
        for k in range(idx.shape[0]):
            i = idx[k]
            _sense_row(i, P, C, stoch, prm[P_NOISE], OFF, S, U, Z, ptr, sd, sn, sh, sa, W)
            if prm[P_MAP] != 0.0:
                _map_row(i, P, C, OFF, SS, md, W, nohit, nonrm)
            has[i] = True
            used += stoch[i] and ptr[i] >= U.shape[1]
        return used

    @njit
    def obs_kernel(idx, P, K, sd, sn, md, prm, out):
        """Observations of rows ``idx`` into ``out[:len(idx)]``."""
        for k in range(idx.shape[0]):
            _obs_row(idx[k], P, K, sd, sn, md, prm[P_OBS_MAP] != 0.0, out, k)

    @njit
    def placement_step(
        k0, idx, act, prm, P, C, stoch, atriv, lo, hi, R, RS, SP, hulls, centers, OFF, S,
        U, Z, ptr, sd, sn, sh, sa, has, placed, res,
    ):  # fmt: skip
        """Placement's step of rows ``idx[k0:]``: the commanded pose of the (clipped)
        action (x, y linear over the bounding box, aim ``pi a``) into ``P``, the query, and
        the sensor reading from it when the placement is a free point (:func:`point_in_region`
        on the free space ``SP``).  ``res (12, k)``: reward, recognizing, in region, aim ok,
        distance to the region, free, the commanded pose, the executed pose.  Returns
        ``len(idx)``, or the position of the first row whose reading needs a new block of
        pre-drawn numbers (refill it and call again from there)."""
        shaping = prm[P_SHAPING]
        B = OFF.shape[2]
        W = (np.empty(B), np.empty(B), np.empty(B), np.empty(B), np.empty(S.shape[2]))
        for k in range(k0, idx.shape[0]):
            i = idx[k]
            x = lo[i, 0] + 0.5 * (act[k, 0] + 1.0) * (hi[i, 0] - lo[i, 0])
            y = lo[i, 1] + 0.5 * (act[k, 1] + 1.0) * (hi[i, 1] - lo[i, 1])
            psi = PI * act[k, 2]
            free = point_in_region(x, y, SP, i)
            if free and stoch[i] and ptr[i] >= U.shape[1]:
                return k
            ins, aim, d = _query_row(x, y, psi, i, C, atriv, R, RS, hulls, centers)
            rec = ins and aim
            r = 1.0 if rec else 0.0
            if shaping != 0.0:
                r -= shaping * d / C[0, i] if (d != np.inf and d == d) else 0.0
            P[0, i] = x
            P[1, i] = y
            P[2, i] = psi
            placed[i] = True
            has[i] = False
            res[0, k] = r
            res[1, k] = rec
            res[2, k] = ins
            res[3, k] = aim
            res[4, k] = d
            res[5, k] = free
            res[6, k] = x
            res[7, k] = y
            res[8, k] = psi
            if free:
                _sense_row(i, P, C, stoch, prm[P_NOISE], OFF, S, U, Z, ptr, sd, sn, sh, sa, W)
                has[i] = True
                res[9, k] = P[3, i]
                res[10, k] = P[4, i]
                res[11, k] = P[5, i]
            else:
                res[9, k] = x
                res[10, k] = y
                res[11, k] = psi
        return idx.shape[0]

    # ---- the fused step ----------------------------------------------------------------
    @njit
    def robot_step(
        task,
        idx,
        act,
        prm,
        P,
        C,
        stoch,
        atriv,
        OFF,
        S,
        SS,
        R,
        RS,
        hulls,
        centers,
        U,
        Z,
        ptr,
        sd,
        sn,
        sh,
        sa,
        md,
        has,
        T,
        I8,
        col,
        reward,
        flags,
        dist,
    ):
        """One step of rows ``idx`` of a Navigate (``task = NAVIGATE``) or Recognize batch.

        ``act (k, d)``: clipped actions; ``T (N,)`` the distance to the region at the
        last step (shaping); ``I8 (5, N)`` int64 task state (elapsed
        steps, success / side, hold, pointing, declared); ``col (N,)`` collided.  Writes
        ``reward[:k]``, ``flags[:, :k]`` (terminated, truncated, recognizing, in region, aim
        ok) and ``dist[:k]`` (distance to the region).  Returns how many rows used up their
        pre-drawn block.  The observation is
        :func:`obs_kernel`'s (a separate call: resets change rows between the two)."""
        n = idx.shape[0]
        B = OFF.shape[2]
        W = (np.empty(B), np.empty(B), np.empty(B), np.empty(B), np.empty(S.shape[2]))
        nohit = np.empty((0, 0), dtype=np.bool_)
        nonrm = np.empty((0, 0, 2))
        noise = prm[P_NOISE]
        max_turn = prm[P_MAX_TURN]
        step_cost = prm[P_STEP_COST]
        shaping = prm[P_SHAPING]
        max_steps = prm[P_MAX_STEPS]
        use_map = prm[P_MAP] != 0.0
        used = 0
        for k in range(n):
            i = idx[k]
            I8[0, i] += 1
            # drive
            a0 = act[k, 0]
            a1 = act[k, 1]
            if prm[P_DISC] != 0.0:
                nrm_ = max(math.hypot(a0, a1), 1.0)
                a0 = a0 / nrm_
                a1 = a1 / nrm_
            x = P[0, i]
            y = P[1, i]
            psi = P[2, i]
            c = math.cos(psi)
            s = math.sin(psi)
            v = C[7, i]
            dx = v * (c * a0 - s * a1)
            dy = v * (s * a0 + c * a1)
            t = _sweep_point(x, y, dx, dy, S, i, C[2, i], W[4])
            P[0, i] = x + t * dx
            P[1, i] = y + t * dy
            P[2, i] = (psi + max_turn * act[k, 2] + PI) % TWO_PI - PI
            col[i] = t < 1.0
            # sense
            _sense_row(i, P, C, stoch, noise, OFF, S, U, Z, ptr, sd, sn, sh, sa, W)
            if use_map:
                _map_row(i, P, C, OFF, SS, md, W, nohit, nonrm)
            has[i] = True
            # query
            ins, aim, d = _query_row(P[0, i], P[1, i], P[2, i], i, C, atriv, R, RS, hulls, centers)
            rec = ins and aim
            dist[k] = d
            flags[2, k] = rec
            flags[3, k] = ins
            flags[4, k] = aim
            # the task
            r = -step_cost
            if task == NAVIGATE:
                before = T[i]
                T[i] = d
                if shaping != 0.0:
                    ok = d != np.inf and before != np.inf and d == d and before == before
                    r += shaping * (before - d) / C[0, i] if ok else 0.0
                r += prm[P_SUCCESS_BONUS] if rec else 0.0
                I8[1, i] = rec
                term = rec
            else:
                dd = act[k, 3]
                want = 1 if dd < -1 / 3 else (2 if dd > 1 / 3 else 0)
                if want != 0 and want == I8[3, i]:
                    hold = I8[2, i] + 1
                else:
                    hold = 1 if want != 0 else 0
                I8[2, i] = hold
                I8[3, i] = want
                dec = want if hold >= prm[P_DECLARE_HOLD] else 0
                I8[4, i] = dec
                term = dec != 0
                if shaping != 0.0:
                    before = T[i]
                    T[i] = d
                    ok = d != np.inf and before != np.inf and d == d and before == before
                    r += shaping * (before - d) / C[0, i] if ok else 0.0
                if term:
                    r += 1.0 if dec == I8[1, i] else -1.0
                else:
                    r += 0.0
            trunc = (not term) and I8[0, i] >= max_steps
            if task == RECOGNIZE:
                r -= 1.0 if trunc else 0.0
            reward[k] = r
            flags[0, k] = term
            flags[1, k] = trunc
            used += stoch[i] and ptr[i] >= U.shape[1]
        return used

else:  # pragma: no cover - without numba
    orient_sign = point_in_region = clip_unit = None
