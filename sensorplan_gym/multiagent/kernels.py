"""Compiled (numba) kernels of the batched watch task, built on the single-agent kernels of
:mod:`sensorplan_gym.core.fused`.

The watchers of ``E`` copies of the task are the rows ``i = e * A + a`` of one batch (``A``
watchers per copy).  Robot A's outline is copy ``e``'s moving obstacle: its edges are row
``e`` of per-copy segment arrays (appended to the map's edges for the collision sweep; a
separate set for the beam cast).  One call of :func:`watch_step` runs, for every watcher of
the stepping copies, what the numpy path of :class:`~.batch.WatchBatch` runs as array
operations:

1. **drive** -- :func:`~sensorplan_gym.core.fused._sweep_point` against the map and A (a
   point watcher; disc watchers are swept by the numpy capsule sweep before the call);
2. **sense** -- :func:`~sensorplan_gym.core.fused._cast_row` against the map (culled: the
   map's normals point into the free space; this is also the map's *prediction*), then
   against A's edges with their normals pointing out of A -- or into A for a watcher inside
   A, so that culling stays exact -- and the nearer hit of the two per beam (the map's on a
   tie, as one cast over "map, then A" keeps the first segment of least distance);
3. **sees** -- :func:`sees_filter`: the complete-model visibility test of
   :meth:`~.world.WatchWorld.sees` decided with floating-point margins where the answer is
   certain, and marked :data:`UNSURE` (to be answered by the exact shapely predicate)
   where a margin is not met -- a watcher within ``eps`` of A, A's farthest vertex within
   ``eps`` of the range, a bound of the field of view within ``1e-9`` rad, or a map edge
   within ``eps`` of the fan ``conv({p} u A)``.  The partial model is always UNSURE.

:func:`obs_kernel` writes the observations (the leading ``8 + 4 B`` entries by
:func:`~sensorplan_gym.core.fused._obs_row`, then the task's tail).  The numpy path computes
the same expressions in the same order, so the two answer bitwise alike.

:func:`visible_from` serves A's planner (:class:`~.world.VisGraph`): whether a segment from a
point to a vertex of the planner's domain lies in the domain, with exact orientations.

The kernels are cached on disk (``cache=True``) like the core's; numba's cache does not notice
a change of a *called* kernel in another file (:mod:`sensorplan_gym.core.fused`), so after
editing one there, clear ``sensorplan_gym/multiagent/__pycache__/kernels.*.nb*``.
"""

from __future__ import annotations

import math

import numpy as np

from ..core.kernels import HAVE_NUMBA, numba

__all__ = ["SEES_NO", "SEES_YES", "UNSURE", "W_NAMES"]

SEES_NO, SEES_YES, UNSURE = 0, 1, 2
#: the float64 parameters of the watch kernels, in this order
W_NAMES = (
    "max_speed",
    "max_turn",
    "skin",
    "reach",
    "eps",
    "fov",
    "max_range",
    "complete",
    "full_fov",
    "drive",
)
W_MAX_SPEED, W_MAX_TURN, W_SKIN, W_REACH, W_EPS, W_FOV, W_MAX_RANGE = range(7)
W_COMPLETE, W_FULL_FOV, W_DRIVE = 7, 8, 9

PI = math.pi
TWO_PI = 2 * math.pi
#: angular margin (radians) of the field-of-view decision
FOV_TOL = 1e-9
#: the wrap of an angle is ambiguous this close to +-pi
WRAP_TOL = 1e-6


if HAVE_NUMBA:  # pragma: no cover - exercised when numba is installed
    from ..core.fused import _cast_row, _obs_row, _sweep_point, _wrap, orient_sign, point_in_region

    njit = numba.njit(cache=True, nogil=True, error_model="numpy")

    @njit
    def set_a(idx, Q, tgt, tnrm, m0, S, SA_out, SA_in, AR):
        """A's outline with its reference point at ``Q[e]`` for the copies ``e`` in ``idx``:
        the columns ``m0 ..`` of ``S (6, E, m0 + K)`` (the sweep's set), ``SA_out`` /
        ``SA_in (6, E, K)`` (the cast's, normals out of / into A) and ``AR (4, E, K)``
        (start and end points, for :func:`point_in_region`).  ``tgt (K, 2)``: A's vertices
        at the origin; ``tnrm (K, 2)``: its edges' outward unit normals."""
        K = tgt.shape[0]
        for k in range(idx.shape[0]):
            e = idx[k]
            qx = Q[e, 0]
            qy = Q[e, 1]
            for j in range(K):
                jn = j + 1 if j + 1 < K else 0
                x0 = tgt[j, 0] + qx
                y0 = tgt[j, 1] + qy
                x1 = tgt[jn, 0] + qx
                y1 = tgt[jn, 1] + qy
                ex = x1 - x0
                ey = y1 - y0
                nx = tnrm[j, 0]
                ny = tnrm[j, 1]
                S[0, e, m0 + j] = x0
                S[1, e, m0 + j] = y0
                S[2, e, m0 + j] = ex
                S[3, e, m0 + j] = ey
                S[4, e, m0 + j] = nx
                S[5, e, m0 + j] = ny
                SA_out[0, e, j] = x0
                SA_out[1, e, j] = y0
                SA_out[2, e, j] = ex
                SA_out[3, e, j] = ey
                SA_out[4, e, j] = nx
                SA_out[5, e, j] = ny
                SA_in[0, e, j] = x0
                SA_in[1, e, j] = y0
                SA_in[2, e, j] = ex
                SA_in[3, e, j] = ey
                SA_in[4, e, j] = -nx
                SA_in[5, e, j] = -ny
                AR[0, e, j] = x0
                AR[1, e, j] = y0
                AR[2, e, j] = x1
                AR[3, e, j] = y1

    @njit
    def _seg_dist2(px, py, x0, y0, ex, ey):
        ax = px - x0
        ay = py - y0
        L2 = ex * ex + ey * ey
        t = (ax * ex + ay * ey) / (L2 if L2 > 0.0 else 1.0)
        t = max(min(t, 1.0), 0.0)
        qx = ax - t * ex
        qy = ay - t * ey
        return qx * qx + qy * qy

    @njit
    def sees_filter(x, y, psi, inside, qx, qy, tgt, hull, SS, prm, HP):
        """The complete-model "sees A" of a watcher at ``(x, y, psi)`` with A's reference
        point at ``(qx, qy)``: :data:`SEES_YES`, :data:`SEES_NO`, or :data:`UNSURE` (see the
        module docstring).  ``inside``: the watcher lies inside A; ``tgt (K, 2)`` A's
        vertices and ``hull (H, 2)`` its convex hull's (counter-clockwise) at the origin;
        ``SS (6, 1, M)`` the map's edges; ``HP (5, H + 2)`` scratch (the fan's sides: a point,
        the direction and 1 / its length)."""
        eps = prm[W_EPS]
        K = tgt.shape[0]
        d2 = np.inf
        for j in range(K):
            jn = j + 1 if j + 1 < K else 0
            x0 = tgt[j, 0] + qx
            y0 = tgt[j, 1] + qy
            d2 = min(d2, _seg_dist2(x, y, x0, y0, tgt[jn, 0] + qx - x0, tgt[jn, 1] + qy - y0))
        if not (math.sqrt(d2) > eps):
            return UNSURE
        if inside:
            return SEES_NO
        if prm[W_COMPLETE] == 0.0:
            return UNSURE
        mr = prm[W_MAX_RANGE]
        if mr < np.inf:
            far = 0.0
            for j in range(K):
                far = max(far, math.hypot(tgt[j, 0] + qx - x, tgt[j, 1] + qy - y))
            if far > mr + eps:
                return SEES_NO
            if far >= mr - eps:
                return UNSURE
        if prm[W_FULL_FOV] == 0.0:
            cx = 0.0
            cy = 0.0
            for j in range(K):
                cx += tgt[j, 0] + qx
                cy += tgt[j, 1] + qy
            base = math.atan2(cy / K - y, cx / K - x)
            off = _wrap(base - psi)
            if abs(off) > PI - WRAP_TOL:
                return UNSURE
            lo = np.inf
            hi = -np.inf
            for j in range(K):
                rel = _wrap(math.atan2(tgt[j, 1] + qy - y, tgt[j, 0] + qx - x) - base)
                if abs(rel) > PI - WRAP_TOL:
                    return UNSURE
                lo = min(lo, rel)
                hi = max(hi, rel)
            half = 0.5 * prm[W_FOV]
            if off + lo < -half - FOV_TOL or off + hi > half + FOV_TOL:
                return SEES_NO
            if off + lo < -half + FOV_TOL or off + hi > half - FOV_TOL:
                return UNSURE
        # the fan F = conv({p} u hull) as half-planes (a, dir, length): the hull's edges
        # that p does not see, then hull[a] -> p -> hull[b] around the ones it sees
        H = hull.shape[0]
        n = 0
        first = -1
        last = -1
        bx0 = x
        bx1 = x
        by0 = y
        by1 = y
        for j in range(H):
            jn = j + 1 if j + 1 < H else 0
            ax = hull[j, 0] + qx
            ay = hull[j, 1] + qy
            dx = hull[jn, 0] - hull[j, 0]
            dy = hull[jn, 1] - hull[j, 1]
            L = math.hypot(dx, dy)
            sd = (dx * (y - ay) - dy * (x - ax)) / L
            if abs(sd) <= eps:
                return UNSURE  # p (nearly) on the line of a hull edge
            bx0 = min(bx0, ax)
            bx1 = max(bx1, ax)
            by0 = min(by0, ay)
            by1 = max(by1, ay)
            jp = j - 1 if j > 0 else H - 1
            if sd > 0.0:
                HP[0, n] = ax
                HP[1, n] = ay
                HP[2, n] = dx
                HP[3, n] = dy
                HP[4, n] = 1.0 / L
                n += 1
            else:
                # edge j is seen from p; is the previous / next one not?
                jpx = hull[j, 0] - hull[jp, 0]
                jpy = hull[j, 1] - hull[jp, 1]
                apx = hull[jp, 0] + qx
                apy = hull[jp, 1] + qy
                if jpx * (y - apy) - jpy * (x - apx) > 0.0:
                    first = j
                jnn = jn + 1 if jn + 1 < H else 0
                nx_ = hull[jnn, 0] - hull[jn, 0]
                ny_ = hull[jnn, 1] - hull[jn, 1]
                anx = hull[jn, 0] + qx
                any_ = hull[jn, 1] + qy
                if nx_ * (y - any_) - ny_ * (x - anx) > 0.0:
                    last = jn
        if first >= 0 and last >= 0:
            ax = hull[first, 0] + qx
            ay = hull[first, 1] + qy
            dx = x - ax
            dy = y - ay
            HP[0, n] = ax
            HP[1, n] = ay
            HP[2, n] = dx
            HP[3, n] = dy
            HP[4, n] = 1.0 / math.hypot(dx, dy)
            n += 1
            bx = hull[last, 0] + qx
            by = hull[last, 1] + qy
            HP[0, n] = x
            HP[1, n] = y
            HP[2, n] = bx - x
            HP[3, n] = by - y
            HP[4, n] = 1.0 / math.hypot(bx - x, by - y)
            n += 1
        elif first >= 0 or last >= 0:
            return UNSURE  # cannot happen for a convex hull; be safe
        bx0 -= 2 * eps
        bx1 += 2 * eps
        by0 -= 2 * eps
        by1 += 2 * eps
        for s in range(SS.shape[2]):
            x0 = SS[0, 0, s]
            y0 = SS[1, 0, s]
            ex = SS[2, 0, s]
            ey = SS[3, 0, s]
            if max(x0, x0 + ex) < bx0 or min(x0, x0 + ex) > bx1:
                continue
            if max(y0, y0 + ey) < by0 or min(y0, y0 + ey) > by1:
                continue
            # the parts of the edge deeper than eps inside F, and not farther than eps outside
            lo_in, hi_in, lo_near, hi_near = 0.0, 1.0, 0.0, 1.0
            for h in range(n):
                inv = HP[4, h]
                a0 = (HP[2, h] * (y0 - HP[1, h]) - HP[3, h] * (x0 - HP[0, h])) * inv
                b0 = (HP[2, h] * ey - HP[3, h] * ex) * inv
                if a0 < -eps and a0 + b0 < -eps:
                    hi_near = -1.0  # the whole edge farther than eps outside this side
                    hi_in = -1.0
                    break
                # a0 + b0 t > eps (inside) / >= -eps (near)
                if b0 == 0.0:
                    if not (a0 > eps):
                        hi_in = -1.0
                    if not (a0 >= -eps):
                        hi_near = -1.0
                elif b0 > 0.0:
                    lo_in = max(lo_in, (eps - a0) / b0)
                    lo_near = max(lo_near, (-eps - a0) / b0)
                else:
                    hi_in = min(hi_in, (eps - a0) / b0)
                    hi_near = min(hi_near, (-eps - a0) / b0)
            if lo_in < hi_in:
                return SEES_NO  # a point of the map's boundary deep inside the fan
            if lo_near <= hi_near:
                return UNSURE
        return SEES_YES

    @njit
    def watch_step(
        idx, nw, act, prm, P, Q, tgt, hull, S, SA_out, SA_in, AR, SS, OFF, sd, sn, sh, md,
        col, ins, code, HP,
    ):  # fmt: skip
        """Drive (when ``prm[W_DRIVE]``), sense and the sees filter of the watchers of the
        copies ``idx`` (``act (len(idx) * nw, >= 3)`` their clipped actions, copy by copy);
        A's outline must be in place (:func:`set_a`).  Writes the poses ``P (3, N)``,
        ``sd, sn, sh`` (sensed ranges, normals, hits), ``md`` (the map's ranges), ``col``
        (collided), ``ins`` (inside A) and ``code`` (:func:`sees_filter`)."""
        B = OFF.shape[2]
        W = (np.empty(B), np.empty(B), np.empty(B), np.empty(B), np.empty(S.shape[2]))
        ad = np.empty((1, B))
        an = np.empty((1, B, 2))
        ah = np.empty((1, B), dtype=np.bool_)
        reach = prm[W_REACH]
        drive = prm[W_DRIVE] != 0.0
        v = prm[W_MAX_SPEED]
        max_turn = prm[W_MAX_TURN]
        skin = prm[W_SKIN]
        for k in range(idx.shape[0]):
            e = idx[k]
            for w in range(nw):
                i = e * nw + w
                if drive:
                    r = k * nw + w
                    x = P[0, i]
                    y = P[1, i]
                    psi = P[2, i]
                    c = math.cos(psi)
                    s = math.sin(psi)
                    a0 = act[r, 0]
                    a1 = act[r, 1]
                    dx = v * (c * a0 - s * a1)
                    dy = v * (s * a0 + c * a1)
                    t = _sweep_point(x, y, dx, dy, S, e, skin, W[4])
                    P[0, i] = x + t * dx
                    P[1, i] = y + t * dy
                    P[2, i] = (psi + max_turn * act[r, 2] + PI) % TWO_PI - PI
                    col[i] = t < 1.0
                x = P[0, i]
                y = P[1, i]
                psi = P[2, i]
                c = math.cos(psi)
                s = math.sin(psi)
                _cast_row(x, y, c, s, OFF, SS, 0, reach, W[0], W[1], W[2], W[3], sd, sn, sh, i)
                for j in range(B):
                    md[i, j] = sd[i, j]
                inside = point_in_region(x, y, AR, e)
                ins[i] = inside
                SA = SA_in if inside else SA_out
                _cast_row(x, y, c, s, OFF, SA, e, reach, W[0], W[1], W[2], W[3], ad, an, ah, 0)
                for j in range(B):
                    if ah[0, j] and (not sh[i, j] or ad[0, j] < sd[i, j]):
                        sd[i, j] = ad[0, j]
                        sn[i, j, 0] = an[0, j, 0]
                        sn[i, j, 1] = an[0, j, 1]
                        sh[i, j] = True
                code[i] = sees_filter(x, y, psi, inside, Q[e, 0], Q[e, 1], tgt, hull, SS, prm, HP)

    @njit
    def obs_kernel(idx, nw, P, K, sd, sn, md, t, dec, max_steps, move_steps, low, out):
        """Observations of the watchers of copies ``idx`` into ``out[:len(idx) * nw]``
        (float32): :func:`_obs_row`'s ``8 + 4 B`` entries, the elapsed fraction ``t[e] /
        max_steps``, whether A's plan is over, the watcher's declaration ``dec[e, w]`` and the
        other watchers' positions in its frame / diameter; every entry clipped to
        ``[low, 1]``."""
        B = sd.shape[1]
        D = out.shape[1]
        base = 8 + 4 * B
        for k in range(idx.shape[0]):
            e = idx[k]
            for w in range(nw):
                i = e * nw + w
                r = k * nw + w
                _obs_row(i, P, K, sd, sn, md, True, out, r)
                out[r, base] = np.float32(t[e] / max_steps)
                out[r, base + 1] = np.float32(1.0 if t[e] >= move_steps else 0.0)
                out[r, base + 2] = np.float32(dec[e, w])
                x = P[0, i]
                y = P[1, i]
                c = math.cos(P[2, i])
                s = math.sin(P[2, i])
                inv = K[i, 4]
                m = base + 3
                for o in range(nw):
                    if o == w:
                        continue
                    j = e * nw + o
                    gx = P[0, j] - x
                    gy = P[1, j] - y
                    out[r, m] = np.float32((c * gx + s * gy) * inv)
                    out[r, m + 1] = np.float32((c * gy - s * gx) * inv)
                    m += 2
                for m in range(D):
                    out[r, m] = min(max(out[r, m], low[m]), np.float32(1.0))

    @njit
    def advance(idx, t, Q, TRJ):
        """One step of time for the copies ``idx``: ``t[e] += 1`` and A's reference point
        ``Q[e]`` := ``TRJ[e, min(t[e], T)]`` (it rests after its last planned step)."""
        last = TRJ.shape[1] - 1
        for k in range(idx.shape[0]):
            e = idx[k]
            t[e] += 1
            j = min(t[e], last)
            Q[e, 0] = TRJ[e, j, 0]
            Q[e, 1] = TRJ[e, j, 1]

    @njit
    def watch_rules(idx, nw, act, t, max_steps, truth, dec, sees, seen, team, see_reward,
                    rew, decl_r, done):  # fmt: skip
        """Declarations and rewards of the copies ``idx`` after their step (see
        :meth:`.batch.WatchBatch.step_envs`): ``act[r, 3]`` declares G (< -1/3) or H (> 1/3)
        when watcher ``r`` has not yet; +1 / -1 for a right / wrong declaration (``truth``:
        -1 G, +1 H), -1 at the horizon for a watcher that never declared; the individual
        reward ``see_reward * sees + that``; the counters of steps seen."""
        for k in range(idx.shape[0]):
            e = idx[k]
            dn = t[e] >= max_steps
            done[k] = dn
            anyone = False
            for w in range(nw):
                r = k * nw + w
                i = e * nw + w
                d = act[r, 3]
                want = -1 if d < -1 / 3 else (1 if d > 1 / 3 else 0)
                dr = 0.0
                if dec[e, w] == 0 and want != 0:
                    dec[e, w] = want
                    dr = 1.0 if want == truth[e] else -1.0
                if dn and dec[e, w] == 0:
                    dr = -1.0
                decl_r[k, w] = dr
                sv = sees[i]
                seen[e, w] += 1 if sv else 0
                anyone = anyone or sv
                rew[k, w] = see_reward * (1.0 if sv else 0.0) + dr
            team[e] += 1 if anyone else 0

    @njit
    def _cone_side(ux, uy, vx, vy, wx, wy, ax, ay):
        """Whether ``a`` lies strictly inside the domain's angle at vertex ``v`` between its
        incoming edge ``u -> v`` and outgoing edge ``v -> w`` (interior on the left): 1 yes,
        0 no, -1 on a bounding ray or a degenerate vertex."""
        o_in = orient_sign(ux, uy, vx, vy, ax, ay)
        o_out = orient_sign(vx, vy, wx, wy, ax, ay)
        if o_in == 0 or o_out == 0:
            return -1
        turn = orient_sign(ux, uy, vx, vy, wx, wy)
        if turn == 0:
            if (vx - ux) * (wx - vx) + (vy - uy) * (wy - vy) <= 0.0:
                return -1  # a spike
            turn = 1
        if turn > 0:
            return 1 if (o_in > 0 and o_out > 0) else 0
        return 1 if (o_in > 0 or o_out > 0) else 0

    @njit
    def visible_from(ax, ay, nodes, E, pin, pout, amb, out):
        """For every boundary vertex ``nodes[k]`` of a polygonal domain, whether the segment
        from ``(ax, ay)`` to it lies in the (closed) domain -- ``shapely.covers(domain,
        segment)`` -- decided with exact orientations: 1 yes, 0 no, :data:`UNSURE` when the
        segment meets a boundary vertex or runs along an edge, ``a`` lies on the boundary, or
        the vertex is not simple (``amb``).  ``E (4, M)``: the boundary's edges (start x, y,
        end x, y), interior on their left; ``pin``/``pout``: each vertex's incoming and
        outgoing edge."""
        M = E.shape[1]
        for k in range(nodes.shape[0]):
            vx = nodes[k, 0]
            vy = nodes[k, 1]
            if amb[k] or (vx == ax and vy == ay):
                out[k] = UNSURE
                continue
            ei = pin[k]
            eo = pout[k]
            side = _cone_side(E[0, ei], E[1, ei], vx, vy, E[2, eo], E[3, eo], ax, ay)
            if side < 0:
                out[k] = UNSURE
                continue
            if side == 0:
                out[k] = 0
                continue
            x0 = min(ax, vx)
            x1 = max(ax, vx)
            y0 = min(ay, vy)
            y1 = max(ay, vy)
            res = 1
            for j in range(M):
                if j == ei or j == eo:
                    continue
                px = E[0, j]
                py = E[1, j]
                qx = E[2, j]
                qy = E[3, j]
                if max(px, qx) < x0 or min(px, qx) > x1 or max(py, qy) < y0 or min(py, qy) > y1:
                    continue
                o1 = orient_sign(ax, ay, vx, vy, px, py)
                o2 = orient_sign(ax, ay, vx, vy, qx, qy)
                if o1 == 0 and x0 <= px <= x1 and y0 <= py <= y1:
                    res = UNSURE
                    break
                if o2 == 0 and x0 <= qx <= x1 and y0 <= qy <= y1:
                    res = UNSURE
                    break
                if o1 * o2 < 0:
                    o3 = orient_sign(px, py, qx, qy, ax, ay)
                    o4 = orient_sign(px, py, qx, qy, vx, vy)
                    if o3 == 0 or o4 == 0:
                        res = UNSURE
                        break
                    if o3 * o4 < 0:
                        res = 0
                        break
            out[k] = res

else:  # pragma: no cover - without numba
    set_a = sees_filter = watch_step = obs_kernel = visible_from = None
    advance = watch_rules = None
