"""A per-domain spatial index for the exact visibility computations of :mod:`geometry._vis`.

Every region query is assembled from many angular-gap visibility computations; the
inner operation is *ray shooting*: the first boundary segment hit by a ray.  Done by
brute force that is (rays x segments) work -- at 1,600 edges about 2.5 million
ray/segment tests for one visibility polygon.  This module builds, once per domain, a
uniform grid of cells (about one per segment), each listing the segments that meet it
(grown by a float margin), and walks every ray through the cells it crosses (a DDA
walk, compiled with numba), testing only the segments listed there and stopping at
the first cell whose exit lies beyond the best hit found.  The hit test is the same
formula, with the same tolerances, as the brute-force code, so the answer (which
segment is hit first) is the same -- the index only skips segments that cannot be hit
earlier; nothing is sampled or approximated.

The same grid answers "which segments pass within ``tol`` of this point" for the
local-obstruction test of viewpoints on the boundary, and lets the compiled angular sort
of :func:`sorted_gaps` visit only the vertices in the cells a narrow sector meets.
:func:`window_ranges` is the compiled twin of the window clipping of the swept point
test (:meth:`geometry.sweep.Sweeper._windows`).  Every compiled step is tested against
the numpy code bit for bit (``tests/geometry/test_large_oracle.py``).

numba is an optional dependency (the ``fast`` extra).  Without it :func:`available`
is False and :mod:`geometry._vis` keeps its vectorised brute-force code.

A domain extended by :meth:`Domain.with_ring` (the target added as a hole) reuses its
parent's grid and tests the few added segments by brute force, so the grid of a scene
is built once (:func:`geometry._common.scene_domain` caches the scene's domain).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

try:  # pragma: no cover - exercised when numba is installed
    import numba

    _HAVE_NUMBA = True
except ImportError:  # pragma: no cover
    numba = None
    _HAVE_NUMBA = False

if TYPE_CHECKING:  # pragma: no cover
    from ._domain import Domain

__all__ = [
    "SegmentGrid",
    "available",
    "blocking",
    "first_hits",
    "grid_for",
    "near_pairs",
    "on_lines",
    "sorted_gaps",
    "window_ranges",
]

#: Registration margin of a segment in the cells, relative to the domain's scale: larger
#: than every tolerance of the hit test (s in [-1e-12, 1 + 1e-12], boundary tol 1e-12).
MARGIN_REL = 1e-9


def available() -> bool:
    """True when the compiled index can be used (numba is installed)."""
    return _HAVE_NUMBA


def _njit(f):  # pragma: no cover - trivial
    return numba.njit(cache=True, nogil=True)(f) if _HAVE_NUMBA else f


@dataclass(frozen=True)
class SegmentGrid:
    """Uniform grid over segments ``seg`` (E, 4): cell ``(ix, iy)`` lists, in
    ``items[start[c] : start[c + 1]]`` with ``c = iy * nx + ix``, the segments that meet
    the cell grown by ``margin``.  ``x0, y0`` is the grid's lower-left corner, ``h`` the
    cell size (scene units)."""

    seg: np.ndarray
    x0: float
    y0: float
    h: float
    nx: int
    ny: int
    start: np.ndarray
    items: np.ndarray
    margin: float

    @staticmethod
    def build(seg: np.ndarray, scale: float, cells_per_segment: float = 1.0) -> SegmentGrid:
        """Grid of about ``cells_per_segment * len(seg)`` square cells over the segments'
        bounding box (at most 4096 per side); ``scale`` sets the margin (scene units)."""
        seg = np.ascontiguousarray(seg, dtype=np.float64)
        margin = MARGIN_REL * max(scale, 1e-300)
        lo = np.minimum(seg[:, :2], seg[:, 2:]).min(axis=0) - 4 * margin
        hi = np.maximum(seg[:, :2], seg[:, 2:]).max(axis=0) + 4 * margin
        w, hgt = float(hi[0] - lo[0]), float(hi[1] - lo[1])
        n_cells = max(1.0, cells_per_segment * len(seg))
        h = math.sqrt(max(w * hgt, 1e-300) / n_cells)
        h = max(h, w / 4096, hgt / 4096, 1e-300)
        nx = max(1, int(math.ceil(w / h)))
        ny = max(1, int(math.ceil(hgt / h)))
        counts = _register(seg, float(lo[0]), float(lo[1]), h, nx, ny, margin, None)
        start = np.zeros(nx * ny + 1, dtype=np.int64)
        np.cumsum(counts, out=start[1:])
        items = np.empty(start[-1], dtype=np.int64)
        _register(seg, float(lo[0]), float(lo[1]), h, nx, ny, margin, (start.copy(), items))
        return SegmentGrid(seg, float(lo[0]), float(lo[1]), h, nx, ny, start, items, margin)


def _register(
    seg: np.ndarray,
    x0: float,
    y0: float,
    h: float,
    nx: int,
    ny: int,
    margin: float,
    fill: tuple[np.ndarray, np.ndarray] | None,
) -> np.ndarray | None:
    """Count (``fill`` None: returns the per-cell counts) or write (``fill = (next free
    position per cell, items)``) the segments meeting each cell grown by ``margin``."""
    if fill is None:
        counts = np.zeros(nx * ny, dtype=np.int64)
        _register_kernel(seg, x0, y0, h, nx, ny, margin, counts, counts, counts, False)
        return counts
    pos, items = fill
    dummy = np.zeros(1, dtype=np.int64)
    _register_kernel(seg, x0, y0, h, nx, ny, margin, dummy, pos, items, True)
    return None


@_njit
def _register_kernel(seg, x0, y0, h, nx, ny, margin, counts, pos, items, fill):  # pragma: no cover
    for j in range(seg.shape[0]):
        ax, ay, bx, by = seg[j, 0], seg[j, 1], seg[j, 2], seg[j, 3]
        ix0 = max(0, min(nx - 1, int(math.floor((min(ax, bx) - margin - x0) / h))))
        ix1 = max(0, min(nx - 1, int(math.floor((max(ax, bx) + margin - x0) / h))))
        iy0 = max(0, min(ny - 1, int(math.floor((min(ay, by) - margin - y0) / h))))
        iy1 = max(0, min(ny - 1, int(math.floor((max(ay, by) + margin - y0) / h))))
        ex, ey = bx - ax, by - ay
        for iy in range(iy0, iy1 + 1):
            cy0 = y0 + iy * h - margin
            cy1 = y0 + (iy + 1) * h + margin
            for ix in range(ix0, ix1 + 1):
                cx0 = x0 + ix * h - margin
                cx1 = x0 + (ix + 1) * h + margin
                # separating axis: the segment's line vs the (grown) cell's corners
                s1 = ex * (cy0 - ay) - ey * (cx0 - ax)
                s2 = ex * (cy0 - ay) - ey * (cx1 - ax)
                s3 = ex * (cy1 - ay) - ey * (cx0 - ax)
                s4 = ex * (cy1 - ay) - ey * (cx1 - ax)
                if (s1 > 0 and s2 > 0 and s3 > 0 and s4 > 0) or (
                    s1 < 0 and s2 < 0 and s3 < 0 and s4 < 0
                ):
                    continue
                c = iy * nx + ix
                if fill:
                    items[pos[c]] = j
                    pos[c] += 1
                else:
                    counts[c] += 1


@_njit
def _hit(qx, qy, dx, dy, sx0, sy0, sx1, sy1, tmin):  # pragma: no cover
    """Ray parameter t of the hit of ray q + t d with segment s, or inf (same test as
    :func:`geometry._vis._first_hits`)."""
    ex = sx1 - sx0
    ey = sy1 - sy0
    den = dx * ey - dy * ex
    if den == 0.0:
        return math.inf
    t = ((sx0 * ey - sy0 * ex) - qx * ey + qy * ex) / den
    s = (dy * sx0 - dx * sy0 + (qy * dx - qx * dy)) / den
    if t > tmin and s >= -1e-12 and s <= 1.0 + 1e-12:
        return t
    return math.inf


@_njit
def _first_hits_kernel(
    q, phi, ring_of, ring_seg, ring_len, seg, x0, y0, h, nx, ny, start, items, extra_base, tmin, out
):  # pragma: no cover
    """First segment hit by each ray ``q[i] + t (cos phi[i], sin phi[i])``, ``t > tmin``:
    the grid's segments by a walk through the cells, and the added segments of ray
    ``i``'s own ring, ``ring_seg[ring_of[i], :ring_len[ring_of[i]]]`` (numbered from
    ``extra_base``), by brute force; -1 where the ray escapes.  One domain is the batch
    of one ring (:func:`first_hits`); several rings are :func:`first_hits_rings`."""
    for i in range(phi.shape[0]):
        qx, qy = q[i, 0], q[i, 1]
        dx, dy = math.cos(phi[i]), math.sin(phi[i])
        best_t = math.inf
        best = -1
        r = ring_of[i]
        for k in range(ring_len[r]):
            t = _hit(
                qx, qy, dx, dy, ring_seg[r, k, 0], ring_seg[r, k, 1], ring_seg[r, k, 2],
                ring_seg[r, k, 3], tmin,
            )  # fmt: skip
            if t < best_t:
                best_t = t
                best = extra_base + k
        if not (x0 <= qx <= x0 + nx * h and y0 <= qy <= y0 + ny * h):
            # a viewpoint off the grid (no caller makes one): test every segment
            for j in range(seg.shape[0]):
                t = _hit(qx, qy, dx, dy, seg[j, 0], seg[j, 1], seg[j, 2], seg[j, 3], tmin)
                if t < best_t or (t == best_t and j < best):
                    best_t = t
                    best = j
            out[i] = best
            continue
        ix = int(math.floor((qx - x0) / h))
        iy = int(math.floor((qy - y0) / h))
        ix = max(0, min(nx - 1, ix))
        iy = max(0, min(ny - 1, iy))
        if dx > 0.0:
            step_x = 1
            t_max_x = (x0 + (ix + 1) * h - qx) / dx
            t_dx = h / dx
        elif dx < 0.0:
            step_x = -1
            t_max_x = (x0 + ix * h - qx) / dx
            t_dx = -h / dx
        else:
            step_x = 0
            t_max_x = math.inf
            t_dx = math.inf
        if dy > 0.0:
            step_y = 1
            t_max_y = (y0 + (iy + 1) * h - qy) / dy
            t_dy = h / dy
        elif dy < 0.0:
            step_y = -1
            t_max_y = (y0 + iy * h - qy) / dy
            t_dy = -h / dy
        else:
            step_y = 0
            t_max_y = math.inf
            t_dy = math.inf
        while True:
            c = iy * nx + ix
            for p in range(start[c], start[c + 1]):
                j = items[p]
                t = _hit(qx, qy, dx, dy, seg[j, 0], seg[j, 1], seg[j, 2], seg[j, 3], tmin)
                if t < best_t or (t == best_t and j < best):
                    best_t = t
                    best = j
            if t_max_x < t_max_y:
                if best_t <= t_max_x:
                    break
                ix += step_x
                if ix < 0 or ix >= nx:
                    break
                t_max_x += t_dx
            else:
                if best_t <= t_max_y:
                    break
                iy += step_y
                if iy < 0 or iy >= ny:
                    break
                t_max_y += t_dy
        out[i] = best


@_njit
def _near_kernel(q, seg, x0, y0, h, nx, ny, start, items, tol, rows, cols):  # pragma: no cover
    """(point, segment) pairs whose distance is at most ``tol``, from each point's cell."""
    n = 0
    for i in range(q.shape[0]):
        qx, qy = q[i, 0], q[i, 1]
        ix = max(0, min(nx - 1, int(math.floor((qx - x0) / h))))
        iy = max(0, min(ny - 1, int(math.floor((qy - y0) / h))))
        c = iy * nx + ix
        for p in range(start[c], start[c + 1]):
            j = items[p]
            ax, ay = seg[j, 0], seg[j, 1]
            ex, ey = seg[j, 2] - ax, seg[j, 3] - ay
            L2 = ex * ex + ey * ey
            t = ((qx - ax) * ex + (qy - ay) * ey) / max(L2, 1e-300)
            t = min(1.0, max(0.0, t))
            px, py = ax + t * ex - qx, ay + t * ey - qy
            if px * px + py * py <= tol * tol:
                if n < rows.shape[0]:
                    rows[n] = i
                    cols[n] = j
                n += 1
    return n


def grid_for(dom: Domain) -> tuple[SegmentGrid, int]:
    """The grid of ``dom`` (or of the domain it was extended from by ``with_ring``) and the
    number of leading segments of ``dom`` it covers (the rest are tested by brute force).
    Built on first use and kept on the domain object."""
    base = dom
    while getattr(base, "_parent", None) is not None:
        base = base._parent
    grid = getattr(base, "_visindex", None)
    if grid is None:
        grid = SegmentGrid.build(base.seg, base.scale)
        object.__setattr__(base, "_visindex", grid)
    return grid, len(base.seg)


def first_hits(dom: Domain, q: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """Index of the first segment of ``dom`` hit by rays from ``q`` ((2,) or (k, 2)) at
    angles ``phi`` (k,), or -1 where a ray escapes -- the same answer as the brute force
    :func:`geometry._vis._first_hits` (which raises on escapes).  The batch of one ring of
    :func:`first_hits_rings`: the segments ``dom`` adds to its grid's domain."""
    grid, n_base = grid_for(dom)
    ring_seg = dom.seg[None, n_base:]
    n = len(np.atleast_1d(phi))
    return _cast(
        grid, n_base, dom.scale, ring_seg, [ring_seg.shape[1]], np.zeros(n, np.int64), q, phi
    )


def first_hits_rings(
    base: Domain,
    ring_seg: np.ndarray,
    ring_len: np.ndarray,
    ring_of: np.ndarray,
    q: np.ndarray,
    phi: np.ndarray,
) -> np.ndarray:
    """:func:`first_hits` for rays in several domains at once: ray ``i`` is cast in
    ``base`` extended (:meth:`Domain.with_ring`) by ring ``ring_of[i]``, whose segments are
    ``ring_seg[r, :ring_len[r]]`` ((R, K, 4), padded).  ``base`` must be a domain with its
    own grid (not itself extended).  Segment ``k`` of a ring is numbered ``len(base.seg) +
    k``, as in the extended domain; -1 where a ray escapes.  Bit for bit the answers of
    :func:`first_hits` on each extended domain (both run :func:`_first_hits_kernel`)."""
    grid, n_base = grid_for(base)
    if n_base != len(base.seg):
        raise ValueError("first_hits_rings: base must not be an extended domain")
    return _cast(grid, n_base, base.scale, ring_seg, ring_len, ring_of, q, phi)


def _cast(
    grid: SegmentGrid,
    n_base: int,
    scale: float,
    ring_seg: np.ndarray,
    ring_len: np.ndarray | list[int],
    ring_of: np.ndarray,
    q: np.ndarray,
    phi: np.ndarray,
) -> np.ndarray:
    """Run :func:`_first_hits_kernel` (``tmin = 1e-11 scale``) on contiguous copies."""
    phi = np.ascontiguousarray(phi, dtype=np.float64)
    q = np.ascontiguousarray(np.broadcast_to(q, (len(phi), 2)), dtype=np.float64)
    out = np.empty(len(phi), dtype=np.int64)
    _first_hits_kernel(
        q,
        phi,
        np.ascontiguousarray(ring_of, dtype=np.int64),
        np.ascontiguousarray(ring_seg, dtype=np.float64),
        np.ascontiguousarray(ring_len, dtype=np.int64),
        grid.seg,
        grid.x0,
        grid.y0,
        grid.h,
        grid.nx,
        grid.ny,
        grid.start,
        grid.items,
        n_base,
        1e-11 * scale,
        out,
    )
    return out


def near_pairs(dom: Domain, q: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """Pairs ``(i, j)``: segment ``j`` of ``dom`` passes within ``tol`` of point ``q[i]``
    (a superset filter; callers apply their exact criteria to the pairs).  Sorted by
    ``i``.  ``tol`` must not exceed the grid's margin."""
    grid, n_base = grid_for(dom)
    if tol > grid.margin:
        raise ValueError("near_pairs: tol exceeds the grid margin")
    q = np.ascontiguousarray(q, dtype=np.float64).reshape(-1, 2)
    cap = 8 * len(q) + 16
    while True:
        rows = np.empty(cap, dtype=np.int64)
        cols = np.empty(cap, dtype=np.int64)
        n = _near_kernel(
            q,
            grid.seg,
            grid.x0,
            grid.y0,
            grid.h,
            grid.nx,
            grid.ny,
            grid.start,
            grid.items,
            tol,
            rows,
            cols,
        )
        if n <= cap:
            break
        cap = n
    rows, cols = rows[:n], cols[:n]
    if n_base < len(dom.seg):  # the added ring(s): brute force
        ex = dom.seg[n_base:]
        a = q[:, None, :] - ex[None, :, :2]
        e = ex[None, :, 2:] - ex[None, :, :2]
        L2 = np.maximum((e * e).sum(axis=2), 1e-300)
        t = np.clip((a * e).sum(axis=2) / L2, 0.0, 1.0)
        d = a - t[..., None] * e
        r2, c2 = np.nonzero((d * d).sum(axis=2) <= tol * tol)
        rows = np.concatenate([rows, r2])
        cols = np.concatenate([cols, c2 + n_base])
    order = np.lexsort((cols, rows))
    return rows[order], cols[order]


def blocking(dom: Domain, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`geometry._vis._blocking` from the grid: the same wedges and directions,
    computed for the (point, segment) pairs of :func:`near_pairs` only instead of for
    all points x all vertices and segments."""
    tol = 1e-12 * dom.scale
    q = np.asarray(q, dtype=float).reshape(-1, 2)
    rows, cols = near_pairs(dom, q, 2.0 * tol)
    # vertex j is the start of segment j (Domain.from_rings / with_ring)
    return blocking_from_pairs(
        q, rows, dom.vert[cols], dom.seg[cols], lambda m: dom.vert_wedge[cols[m]], tol
    )


def blocking_from_pairs(
    q: np.ndarray,
    rows: np.ndarray,
    vert: np.ndarray,
    seg: np.ndarray,
    wedge_of: Callable[[np.ndarray], np.ndarray],
    tol: float,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The ``w1, w2, along`` of :func:`blocking` for the points ``q`` (n, 2) from their
    near (point, segment) pairs: pair ``k`` is point ``rows[k]`` (sorted) and the segment
    ``seg[k]`` (x0, y0, x1, y1) whose start vertex is ``vert[k]``; ``wedge_of(mask)`` gives
    the free wedges ``(start, width)`` (radians) of the start vertices of the pairs
    selected by ``mask``.  Shared by :func:`blocking` (one domain) and
    :func:`geometry._vis._blocking_rings` (each point in its own domain)."""
    n = len(q)
    w1 = np.full((n, 2), np.nan)
    w2 = np.full((n, 2), np.nan)
    along = np.full((n, 2), np.nan)
    if len(rows) == 0:
        return w1, w2, along
    vnear = np.abs(vert - q[rows]).max(axis=1) <= tol
    r = rows[vnear]
    if len(r):
        wedge = wedge_of(vnear)
        first = np.concatenate([[True], r[1:] != r[:-1]])
        w1[r[first]] = wedge[first]
        second = ~first & np.concatenate([[False], first[:-1]])
        w2[r[second]] = wedge[second]
    e = seg[:, 2:] - seg[:, :2]
    L = np.hypot(e[:, 0], e[:, 1])
    a = q[rows] - seg[:, :2]
    dist = np.abs(e[:, 0] * a[:, 1] - e[:, 1] * a[:, 0]) / np.maximum(L, 1e-300)
    t = (a[:, 0] * e[:, 0] + a[:, 1] * e[:, 1]) / np.maximum(L * L, 1e-300)
    on = (dist <= tol) & (t * L > tol) & ((1 - t) * L > tol)
    along[rows[on]] = e[on]
    return w1, w2, along


@_njit
def _dir_rel(dx, dy, st, wd, tol, interior, narrow, c0, s0, c1, s1):  # pragma: no cover
    """Direction of (dx, dy) relative to ``st`` if it lies in ``(0, wd)``, else -1."""
    if not interior and max(abs(dx), abs(dy)) <= tol:
        return -1.0
    if narrow:
        # cheap pre-filter: clearly outside the sector (slack >> rounding)
        slack = 1e-6 * (abs(dx) + abs(dy))
        if c0 * dy - s0 * dx < -slack or dx * s1 - dy * c1 < -slack:
            return -1.0
    r = (math.atan2(dy, dx) - st) % (2.0 * math.pi)
    if r >= wd or r <= 0.0:
        return -1.0
    return r


@_njit
def _gaps_kernel(
    q,
    start,
    width,
    vert,
    crit,
    tol,
    interior,
    counts_only,
    off,
    lo_out,
    hi_out,
    gx0,
    gy0,
    h,
    nx,
    ny,
    cstart,
    items,
    vcell,
    n_base,
):  # pragma: no cover
    TWO_PI = 2.0 * math.pi
    nv = vert.shape[0]
    nk = crit.shape[1]
    buf = np.empty(nv + nk + 2)
    reach = 8.0 * math.hypot(nx * h, ny * h)
    for i in range(q.shape[0]):
        qx, qy = q[i, 0], q[i, 1]
        st, wd = start[i], width[i]
        narrow = wd < 0.9 * math.pi
        c0, s0, c1, s1 = 1.0, 0.0, 1.0, 0.0
        if narrow:
            c0, s0 = math.cos(st), math.sin(st)
            c1, s1 = math.cos(st + wd), math.sin(st + wd)
        m = 0
        buf[m] = 0.0
        m += 1
        on_grid = gx0 <= qx <= gx0 + nx * h and gy0 <= qy <= gy0 + ny * h
        if narrow and n_base > 0 and on_grid:
            # the grid cells met by the triangle (q, q + reach d0, q + reach d1), which
            # holds the part of the sector inside the grid (padded by one cell)
            ax, ay = qx + reach * c0, qy + reach * s0
            bx, by = qx + reach * c1, qy + reach * s1
            iy0 = max(0, int(math.floor((min(qy, ay, by) - gy0) / h)) - 1)
            iy1 = min(ny - 1, int(math.floor((max(qy, ay, by) - gy0) / h)) + 1)
            for iy in range(iy0, iy1 + 1):
                ya = gy0 + iy * h
                yb = ya + h
                xmin = math.inf
                xmax = -math.inf
                for e in range(3):
                    if e == 0:
                        px, py, rx, ry = qx, qy, ax, ay
                    elif e == 1:
                        px, py, rx, ry = ax, ay, bx, by
                    else:
                        px, py, rx, ry = bx, by, qx, qy
                    if py == ry:
                        if ya <= py <= yb:
                            xmin = min(xmin, px, rx)
                            xmax = max(xmax, px, rx)
                        continue
                    t0 = (ya - py) / (ry - py)
                    t1 = (yb - py) / (ry - py)
                    tlo = max(0.0, min(t0, t1))
                    thi = min(1.0, max(t0, t1))
                    if tlo <= thi:
                        xa = px + tlo * (rx - px)
                        xb = px + thi * (rx - px)
                        xmin = min(xmin, xa, xb)
                        xmax = max(xmax, xa, xb)
                if xmin > xmax:
                    continue
                ix0 = max(0, int(math.floor((xmin - gx0) / h)) - 1)
                ix1 = min(nx - 1, int(math.floor((xmax - gx0) / h)) + 1)
                for ix in range(ix0, ix1 + 1):
                    c = iy * nx + ix
                    for p in range(cstart[c], cstart[c + 1]):
                        v = items[p]
                        if vcell[v] != c:  # each vertex once: in its own cell
                            continue
                        r = _dir_rel(
                            vert[v, 0] - qx,
                            vert[v, 1] - qy,
                            st,
                            wd,
                            tol,
                            interior,
                            narrow,
                            c0,
                            s0,
                            c1,
                            s1,
                        )
                        if r >= 0.0:
                            buf[m] = r
                            m += 1
            v_from = n_base
        else:
            v_from = 0
        for v in range(v_from, nv):
            r = _dir_rel(
                vert[v, 0] - qx, vert[v, 1] - qy, st, wd, tol, interior, narrow, c0, s0, c1, s1
            )
            if r >= 0.0:
                buf[m] = r
                m += 1
        for k in range(nk):
            a = crit[i, k]
            if math.isnan(a):
                continue
            r = (a - st) % TWO_PI
            if math.isnan(r) or r >= wd or r <= 0.0:
                continue
            buf[m] = r
            m += 1
        buf[m] = wd
        m += 1
        srt = np.sort(buf[:m])
        cnt = 0
        base = off[i]
        for p in range(m - 1):
            if srt[p + 1] - srt[p] > 1e-13:
                if not counts_only:
                    lo_out[base + cnt] = st + srt[p]
                    hi_out[base + cnt] = st + srt[p + 1]
                cnt += 1
        # counting pass: the count; filling pass: the running offset (so a single filling
        # pass over a buffer of the worst-case size lays the viewpoints out one after another)
        off[i + 1] = cnt if counts_only else base + cnt


def _vertex_cells(grid: SegmentGrid) -> np.ndarray:
    """Cell of the start vertex of every segment of ``grid`` (same rule as the walk)."""
    ix = np.clip(np.floor((grid.seg[:, 0] - grid.x0) / grid.h), 0, grid.nx - 1).astype(np.int64)
    iy = np.clip(np.floor((grid.seg[:, 1] - grid.y0) / grid.h), 0, grid.ny - 1).astype(np.int64)
    return iy * grid.nx + ix


def sorted_gaps(
    q: np.ndarray,
    start: np.ndarray,
    width: np.ndarray,
    vert: np.ndarray,
    crit: np.ndarray,
    tol: float,
    interior: bool,
    dom: Domain | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The angular gaps of :func:`geometry._vis.gaps_many`, compiled: for each viewpoint
    ``q[i]`` the sorted directions to every vertex (those within ``tol`` of ``q[i]``
    dropped unless ``interior``) and the extra critical directions ``crit[i]`` (NaN
    ignored), relative to ``start[i]`` and restricted to ``(0, width[i])``; consecutive
    directions more than 1e-13 apart bound a gap.  Returns ``owner, lo, hi`` (flat, in
    viewpoint order, radians).

    A narrow sector (below 0.9 pi) first drops the vertices clearly outside it by two
    cross products; with ``dom`` (whose ``vert`` is ``vert``) it visits only the vertices
    in the grid cells met by the sector, so its cost follows the sector, not the scene.
    Either way the directions kept -- hence the gaps -- are exactly the full loop's."""
    q = np.ascontiguousarray(q, dtype=np.float64)
    n = len(q)
    if n == 0:  # no viewpoints (e.g. every candidate dropped): no gaps (issue 25 item 7)
        return np.zeros(0, dtype=np.int64), np.zeros(0), np.zeros(0)
    start = np.ascontiguousarray(start, dtype=np.float64)
    width = np.ascontiguousarray(width, dtype=np.float64)
    vert = np.ascontiguousarray(vert, dtype=np.float64)
    crit = np.ascontiguousarray(crit, dtype=np.float64).reshape(n, -1)
    if dom is not None:
        grid, n_base = grid_for(dom)
        vcell = getattr(grid, "_vcell", None)
        if vcell is None:
            vcell = _vertex_cells(grid)
            object.__setattr__(grid, "_vcell", vcell)
        g = (grid.x0, grid.y0, grid.h, grid.nx, grid.ny, grid.start, grid.items, vcell, n_base)
    else:
        z = np.zeros(1, dtype=np.int64)
        g = (0.0, 0.0, 1.0, 1, 1, z, z, z, 0)
    # one filling pass per block of viewpoints into a buffer of the worst-case size
    # (every direction a gap boundary), about 2**20 gaps per block
    cap = len(vert) + crit.shape[1] + 1
    block = max(1, (1 << 20) // cap)
    los, his, counts = [], [], []
    for b0 in range(0, n, block):
        b1 = min(n, b0 + block)
        off = np.zeros(b1 - b0 + 1, dtype=np.int64)
        lo = np.empty((b1 - b0) * cap)
        hi = np.empty((b1 - b0) * cap)
        _gaps_kernel(
            q[b0:b1],
            start[b0:b1],
            width[b0:b1],
            vert,
            crit[b0:b1],
            tol,
            interior,
            False,
            off,
            lo,
            hi,
            *g,
        )
        los.append(lo[: off[-1]])
        his.append(hi[: off[-1]])
        counts.append(np.diff(off))
    if not los:
        return np.zeros(0, dtype=np.int64), np.zeros(0), np.zeros(0)
    owner = np.repeat(np.arange(n), np.concatenate(counts))
    return owner, np.concatenate(los), np.concatenate(his)


@_njit
def _windows_kernel(
    g_lo, g_hi, own, seg_idx, seg, p, base, kv, shift, out_lo, out_hi, out_own
):  # pragma: no cover
    TWO_PI = 2.0 * math.pi
    k = kv.shape[0]
    m = 0
    for i in range(g_lo.shape[0]):
        j = seg_idx[i]
        o = own[i]
        s0x, s0y = seg[j, 0], seg[j, 1]
        sdx, sdy = seg[j, 2] - s0x, seg[j, 3] - s0y
        px, py = p[o, 0], p[o, 1]
        cp = sdx * (py - s0y) - sdy * (px - s0x)
        side_p = 1.0 if cp > 0 else (-1.0 if cp < 0 else 0.0)
        b = base[o]
        amin = math.inf
        amax = -math.inf
        for a in range(k):
            sa = (sdx * (kv[a, 1] - s0y) - sdy * (kv[a, 0] - s0x)) * side_p
            if sa > 0:
                r = (math.atan2(kv[a, 1] - py, kv[a, 0] - px) - b + math.pi) % TWO_PI - math.pi
                amin = min(amin, r)
                amax = max(amax, r)
        for a in range(k):
            c = (a + 1) % k
            sa = (sdx * (kv[a, 1] - s0y) - sdy * (kv[a, 0] - s0x)) * side_p
            sc = (sdx * (kv[c, 1] - s0y) - sdy * (kv[c, 0] - s0x)) * side_p
            if (sa > 0) != (sc > 0):
                lam = sa / (sa - sc)
                xx = kv[a, 0] + lam * (kv[c, 0] - kv[a, 0])
                xy = kv[a, 1] + lam * (kv[c, 1] - kv[a, 1])
                r = (math.atan2(xy - py, xx - px) - b + math.pi) % TWO_PI - math.pi
                amin = min(amin, r)
                amax = max(amax, r)
        r_lo = (g_lo[i] - b + math.pi) % TWO_PI - math.pi
        r_hi = r_lo + (g_hi[i] - g_lo[i])
        lo = max(r_lo + shift, amin)
        hi = min(r_hi + shift, amax)
        if hi > lo:
            out_lo[m] = lo
            out_hi[m] = hi
            out_own[m] = o
            m += 1
    return m


def window_ranges(
    g_lo: np.ndarray,
    g_hi: np.ndarray,
    own: np.ndarray,
    seg_idx: np.ndarray,
    seg: np.ndarray,
    p: np.ndarray,
    base: np.ndarray,
    hull: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Compiled twin of the gap-clipping step of :meth:`geometry.sweep.Sweeper._windows`:
    for every gap ``(g_lo, g_hi)`` of probe ``p[own]`` that ends on segment ``seg_idx``,
    the directions (relative to ``base[own]``, radians) of the part of the convex hull
    ``hull`` in front of that segment, intersected with the gap (once as is, once
    shifted by -2 pi).  Returns ``lo, hi, own`` in the order of the numpy code."""
    args = [np.ascontiguousarray(a, dtype=np.float64) for a in (g_lo, g_hi)] + [
        np.ascontiguousarray(own, dtype=np.int64),
        np.ascontiguousarray(seg_idx, dtype=np.int64),
    ]
    rest = [np.ascontiguousarray(a, dtype=np.float64) for a in (seg, p, base, hull)]
    los, his, owns = [], [], []
    for shift in (0.0, -2.0 * math.pi):
        n = len(g_lo)
        lo, hi, ow = np.empty(n), np.empty(n), np.empty(n, dtype=np.int64)
        m = _windows_kernel(*args, *rest, shift, lo, hi, ow)
        los.append(lo[:m])
        his.append(hi[:m])
        owns.append(ow[:m])
    return np.concatenate(los), np.concatenate(his), np.concatenate(owns)


@_njit
def _on_lines_kernel(v, d, ln, tab, row_table, tol, rows, cols, fill):  # pragma: no cover
    k = 0
    for i in range(v.shape[0]):
        t = row_table[i]
        den = max(ln[i], 1e-300)
        for c in range(tab.shape[1]):
            rx = tab[t, c, 0] - v[i, 0]
            ry = tab[t, c, 1] - v[i, 1]
            if abs(d[i, 0] * ry - d[i, 1] * rx) / den <= tol:
                if fill:
                    rows[k] = i
                    cols[k] = c
                k += 1
    return k


def on_lines(
    v: np.ndarray, d: np.ndarray, tab: np.ndarray, row_table: np.ndarray, tol: float
) -> tuple[np.ndarray, np.ndarray]:
    """Compiled twin of the candidate search of
    :meth:`geometry._sweep.shadow.StationaryShadows._label_rows`: the pairs ``(row,
    column)``, row-major, where point ``tab[row_table[row], column]`` (a NaN point: never)
    lies within ``tol`` of the line through ``v[row]`` along ``d[row]`` (the distance
    ``|d x (p - v)| / max(|d|, 1e-300)``, the same expressions as the numpy code)."""
    v = np.ascontiguousarray(v, dtype=np.float64)
    d = np.ascontiguousarray(d, dtype=np.float64)
    ln = np.hypot(d[:, 0], d[:, 1])
    tab = np.ascontiguousarray(tab, dtype=np.float64)
    row_table = np.ascontiguousarray(row_table, dtype=np.int64)
    none = np.zeros(0, dtype=np.int64)
    n = _on_lines_kernel(v, d, ln, tab, row_table, tol, none, none, False)
    rows, cols = np.empty(n, dtype=np.int64), np.empty(n, dtype=np.int64)
    _on_lines_kernel(v, d, ln, tab, row_table, tol, rows, cols, True)
    return rows, cols
