"""The ray-cast inner loop, compiled with numba when the ``fast`` extra is installed.

:func:`cast` returns, for N fans of B rays and segment sets of M segments, the distance to
the first hit and the hit segment's normal; :func:`point_sweep` how far N points can move
before they cross a segment.  Two implementations compute the
same floating-point expressions in the same order, so their answers are bitwise identical
(a test checks it):

* the compiled loop (numba, no fast-math): N x B x M scalar iterations, no temporaries;
* the numpy broadcast over ``(N, B, M)`` arrays, used without numba.

Setting the environment variable ``SENSORPLAN_NO_NUMBA=1`` forces the numpy versions.
Everything around them (angles, noise, disc robots) is shared numpy code in :mod:`.sensor`
and :mod:`.collision`.
"""

from __future__ import annotations

import os

import numpy as np

try:  # pragma: no cover - exercised when numba is installed
    if os.environ.get("SENSORPLAN_NO_NUMBA"):
        raise ImportError("SENSORPLAN_NO_NUMBA is set")
    import numba

    HAVE_NUMBA = True
except ImportError:  # pragma: no cover
    numba = None
    HAVE_NUMBA = False

__all__ = [
    "HAVE_NUMBA",
    "libm",
    "cast",
    "cast_numpy",
    "point_sweep",
    "point_sweep_numpy",
    "seg_distance",
    "seg_distance_numpy",
]

_ERR = {"divide": "ignore", "invalid": "ignore", "over": "ignore"}
_UFUNCS: dict = {}


def libm(f, *args: np.ndarray) -> np.ndarray:
    """``f`` (a :mod:`math` function: the C library's, as numba calls it) elementwise over
    the broadcast float64 ``args``.  The numpy paths use it where numpy's own version may
    differ in the last bit (``arctan2``, ``arcsin`` and, on some builds, ``cos``/``sin`` use
    SIMD implementations), so that they answer bitwise as the compiled kernels do."""
    u = _UFUNCS.get(f)
    if u is None:
        u = _UFUNCS[f] = np.frompyfunc(f, len(args), 1)
    out = u(*args)
    return np.asarray(out, dtype=np.float64)


def cast_numpy(ox, oy, dx, dy, x0, y0, ex, ey, nx, ny, max_range, cull=False):
    """First hits of rays ``o + t d`` on segments ``a + u e``.

    ``ox, oy``: ``(N,)``; ``dx, dy``: ``(N, B)`` unit directions; ``x0, y0, ex, ey, nx, ny``:
    ``(N, M)`` segment starts, edge vectors and unit normals (or ``(1, M)``, shared);
    ``max_range``: ``(N,)``.  Returns ``dist (N, B)`` (clipped at ``max_range``), ``hit``
    (bool) and the hit segment's normal turned to face the origin, ``(N, B)`` x and y
    (zero where nothing was hit).  ``cull=True``: skip the segments whose normal points away
    from the origin (:func:`_front`) -- exact when every normal points into the free space
    and the origins are free points."""
    ax = x0 - ox[:, None]  # (N, M): a - o
    ay = y0 - oy[:, None]
    tnum = (ax * ey - ay * ex)[:, None, :]  # cross(a - o, e)
    d_x, d_y = dx[:, :, None], dy[:, :, None]
    with np.errstate(**_ERR):
        inv = 1.0 / (d_x * ey[:, None, :] - d_y * ex[:, None, :])  # 1 / cross(d, e)
        t = tnum * inv
        u = (ax[:, None, :] * d_y - ay[:, None, :] * d_x) * inv  # cross(a - o, d) / cross(d, e)
    ok = u >= 0.0
    ok &= u <= 1.0
    ok &= t >= 0.0  # NaN (parallel, collinear, padding) fails every test
    if cull:
        ok &= _front(ox, oy, x0, y0, nx, ny)[:, None, :]
    np.copyto(t, np.inf, where=~ok)
    idx = t.argmin(axis=2)
    dist = np.take_along_axis(t, idx[:, :, None], 2)[:, :, 0]
    mr = max_range[:, None]
    hit = dist <= mr
    np.minimum(dist, mr, out=dist)
    rows = np.arange(len(ox))[:, None]
    r = rows if x0.shape[0] > 1 else 0
    gx, gy = nx[r, idx], ny[r, idx]
    sgn = np.sign(-(gx * ax[rows, idx] + gy * ay[rows, idx]))
    # +0.0 where nothing was hit (as the compiled loop writes it: bitwise, not just equal)
    return dist, hit, np.where(hit, gx * sgn, 0.0), np.where(hit, gy * sgn, 0.0)


def _front(ox, oy, x0, y0, nx, ny) -> np.ndarray:
    """``(N, M)``: the origin lies strictly on the side of segment ``s`` its normal points to.
    With normals pointing into the free space, a ray from a free point first meets the
    boundary at such a segment, so the others can be skipped without changing any answer."""
    return nx * (ox[:, None] - x0) + ny * (oy[:, None] - y0) > 0.0


def point_sweep_numpy(px, py, dx, dy, x0, y0, ex, ey, nx, ny, skin):
    """Largest fractions ``(N,)`` in [0, 1] of the point motions ``p -> p + d`` that cross no
    segment, backed off by ``skin`` ``(N,)`` along the contact normal (shapes as in
    :func:`cast_numpy`, one motion per row)."""
    ax = x0 - px[:, None]
    ay = y0 - py[:, None]
    d_x, d_y = dx[:, None], dy[:, None]
    with np.errstate(**_ERR):
        inv = 1.0 / (d_x * ey - d_y * ex)
        t = (ax * ey - ay * ex) * inv
        u = (ax * d_y - ay * d_x) * inv
    ok = u >= 0.0
    ok &= u <= 1.0
    ok &= t >= 0.0
    np.copyto(t, np.inf, where=~ok)
    i = t.argmin(axis=1)
    rows = np.arange(len(px))
    r = rows if x0.shape[0] > 1 else 0
    ti = t[rows, i]
    rate = np.maximum(np.abs(nx[r, i] * dx + ny[r, i] * dy), 1e-300)  # approach speed
    out = np.ones(len(px))
    stop = ti <= 1.0
    out[stop] = np.maximum(0.0, ti[stop] - skin[stop] / rate[stop])
    return out


def seg_distance_numpy(px, py, x0, y0, ex, ey):
    """Distance ``(N,)`` from point ``(px[i], py[i])`` to the nearest segment of row ``i``
    (``(N, M)`` arrays, or ``(1, M)`` shared); ``inf`` with no segments."""
    ax = px[:, None] - x0
    ay = py[:, None] - y0
    L2 = ex * ex + ey * ey
    t = (ax * ex + ay * ey) / np.where(L2 > 0.0, L2, 1.0)
    np.minimum(t, 1.0, out=t)
    np.maximum(t, 0.0, out=t)
    qx = ax - t * ex
    qy = ay - t * ey
    if x0.shape[1] == 0:
        return np.full(len(px), np.inf)
    return np.sqrt(np.min(qx * qx + qy * qy, axis=1))


if HAVE_NUMBA:  # pragma: no cover - exercised when numba is installed

    @numba.njit(cache=True, nogil=True)
    def _seg_distance_nb(px, py, x0, y0, ex, ey, out):
        n = px.shape[0]
        m = x0.shape[1]
        shared = x0.shape[0] == 1
        for k in range(n):
            r = 0 if shared else k
            best = np.inf
            for s in range(m):
                ax = px[k] - x0[r, s]
                ay = py[k] - y0[r, s]
                L2 = ex[r, s] * ex[r, s] + ey[r, s] * ey[r, s]
                t = (ax * ex[r, s] + ay * ey[r, s]) / (L2 if L2 > 0.0 else 1.0)
                t = min(t, 1.0)
                t = max(t, 0.0)
                qx = ax - t * ex[r, s]
                qy = ay - t * ey[r, s]
                d2 = qx * qx + qy * qy
                if d2 < best:
                    best = d2
            out[k] = np.sqrt(best)

    @numba.njit(cache=True, nogil=True)
    def _cast_nb(ox, oy, dx, dy, x0, y0, ex, ey, nx, ny, max_range, cull, dist, hit, gx, gy):
        n, b = dx.shape
        m = x0.shape[1]
        shared = x0.shape[0] == 1
        front = np.empty(m, dtype=np.intp)
        for k in range(n):
            r = 0 if shared else k
            nf = 0
            for s in range(m):  # the segments whose free side faces the origin
                if not cull or nx[r, s] * (ox[k] - x0[r, s]) + ny[r, s] * (oy[k] - y0[r, s]) > 0.0:
                    front[nf] = s
                    nf += 1
            for j in range(b):
                best = np.inf
                bi = 0
                ddx = dx[k, j]
                ddy = dy[k, j]
                for f in range(nf):
                    s = front[f]
                    ax = x0[r, s] - ox[k]
                    ay = y0[r, s] - oy[k]
                    den = ddx * ey[r, s] - ddy * ex[r, s]
                    inv = 1.0 / den if den != 0.0 else np.inf
                    t = (ax * ey[r, s] - ay * ex[r, s]) * inv
                    u = (ax * ddy - ay * ddx) * inv
                    if u >= 0.0 and u <= 1.0 and t >= 0.0 and t < best:
                        best = t
                        bi = s
                h = best <= max_range[k]
                dist[k, j] = best if h else max_range[k]
                hit[k, j] = h
                if h:
                    px = nx[r, bi]
                    py = ny[r, bi]
                    side = -(px * (x0[r, bi] - ox[k]) + py * (y0[r, bi] - oy[k]))
                    sg = 1.0 if side > 0 else (-1.0 if side < 0 else 0.0)
                    gx[k, j] = px * sg
                    gy[k, j] = py * sg
                else:
                    gx[k, j] = 0.0
                    gy[k, j] = 0.0

    @numba.njit(cache=True, nogil=True)
    def _point_sweep_nb(px, py, dx, dy, x0, y0, ex, ey, nx, ny, skin, out):
        n = px.shape[0]
        m = x0.shape[1]
        shared = x0.shape[0] == 1
        for k in range(n):
            r = 0 if shared else k
            best = np.inf
            bi = 0
            for s in range(m):
                ax = x0[r, s] - px[k]
                ay = y0[r, s] - py[k]
                den = dx[k] * ey[r, s] - dy[k] * ex[r, s]
                inv = 1.0 / den if den != 0.0 else np.inf
                t = (ax * ey[r, s] - ay * ex[r, s]) * inv
                u = (ax * dy[k] - ay * dx[k]) * inv
                if u >= 0.0 and u <= 1.0 and t >= 0.0 and t < best:
                    best = t
                    bi = s
            if best <= 1.0:
                rate = max(abs(nx[r, bi] * dx[k] + ny[r, bi] * dy[k]), 1e-300)
                out[k] = max(0.0, best - skin[k] / rate)
            else:
                out[k] = 1.0


def cast(ox, oy, dx, dy, x0, y0, ex, ey, nx, ny, max_range, cull=False):
    """:func:`cast_numpy`, compiled when numba is available (same answers)."""
    if not HAVE_NUMBA:
        return cast_numpy(ox, oy, dx, dy, x0, y0, ex, ey, nx, ny, max_range, cull)
    n, b = dx.shape
    dist = np.empty((n, b))
    hit = np.empty((n, b), dtype=np.bool_)
    gx = np.empty((n, b))
    gy = np.empty((n, b))
    _cast_nb(ox, oy, dx, dy, x0, y0, ex, ey, nx, ny, max_range, cull, dist, hit, gx, gy)
    return dist, hit, gx, gy


def point_sweep(px, py, dx, dy, x0, y0, ex, ey, nx, ny, skin):
    """:func:`point_sweep_numpy`, compiled when numba is available (same answers)."""
    if not HAVE_NUMBA:
        return point_sweep_numpy(px, py, dx, dy, x0, y0, ex, ey, nx, ny, skin)
    out = np.empty(len(px))
    _point_sweep_nb(px, py, dx, dy, x0, y0, ex, ey, nx, ny, skin, out)
    return out


def seg_distance(px, py, x0, y0, ex, ey) -> np.ndarray:
    """:func:`seg_distance_numpy`, compiled when numba is available (same answers)."""
    if not HAVE_NUMBA:
        return seg_distance_numpy(px, py, x0, y0, ex, ey)
    out = np.empty(len(px))
    _seg_distance_nb(px, py, x0, y0, ex, ey, out)
    return out
