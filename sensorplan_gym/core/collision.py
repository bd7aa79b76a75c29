"""The collision sweep: how far a robot (a point or a disc) can move before it meets a
segment, for N robots at once."""

from __future__ import annotations

import numpy as np

from .kernels import point_sweep
from .segments import Segments

__all__ = ["sweep", "sweep_batch"]

_ERR = {"divide": "ignore", "invalid": "ignore", "over": "ignore"}


def sweep_batch(px, py, dx, dy, S, radius: float, skin) -> np.ndarray:
    """Largest fractions ``t (N,)`` in [0, 1] of the motions ``p -> p + d`` that keep a disc
    of ``radius`` at ``p`` from crossing into any segment (a capsule sweep), backed off by
    ``skin`` (scalar or ``(N,)``) measured along the contact normal.  ``radius=0`` is a point
    robot.  ``S``: one :class:`Segments` for all N, or ``(N, M)`` rows.  A disc already
    touching a segment cannot move further into it."""
    px, py, dx, dy = (np.asarray(v, dtype=np.float64) for v in (px, py, dx, dy))
    n = px.shape[0]
    skin = np.asarray(skin, dtype=np.float64)
    if skin.ndim == 0:
        skin = np.full(n, float(skin))
    out = np.ones(n)
    if S.x0.shape[-1] == 0 or n == 0:
        return out
    moving = (dx != 0.0) | (dy != 0.0)
    d_x, d_y = dx[:, None], dy[:, None]
    if radius == 0.0:  # a point: one ray p + t d, t in [0, 1], against every segment
        seg = [a if a.ndim == 2 else a[None, :] for a in (S.x0, S.y0, S.ex, S.ey, S.nx, S.ny)]
        t = point_sweep(px, py, dx, dy, *seg, np.ascontiguousarray(skin))
        return np.where(moving, t, 1.0)
    ax = px[:, None] - S.x0
    ay = py[:, None] - S.y0
    L2 = S.ex * S.ex + S.ey * S.ey
    with np.errstate(**_ERR):
        L = np.sqrt(L2)
        nx, ny = -S.ey / L, S.ex / L
        s0 = nx * ax + ny * ay  # signed distance to the line
        sd = nx * d_x + ny * d_y  # its rate of change
        toward = s0 * sd < 0
        on = np.abs(s0) <= radius
        toward |= on & (sd != 0) & ((s0 == 0) | toward)
        t_line = np.where(on, 0.0, (np.sign(s0) * radius - s0) / sd)
        u = ((ax + t_line * d_x) * S.ex + (ay + t_line * d_y) * S.ey) / L2
    ok = toward & (t_line >= 0) & (t_line <= 1) & (u >= 0) & (u <= 1) & (L2 > 0)
    tl = np.where(ok, t_line, np.inf)
    i = tl.argmin(axis=1)
    rows = np.arange(n)
    t_best = np.minimum(tl[rows, i], 1.0)
    with np.errstate(**_ERR):
        back = np.where(
            tl[rows, i] <= 1.0, skin / np.abs(np.broadcast_to(sd, tl.shape)[rows, i]), np.inf
        )
    dd = dx * dx + dy * dy
    x1 = S.x0 + S.ex
    y1 = S.y0 + S.ey
    for qx0, qy0 in ((ax, ay), (px[:, None] - x1, py[:, None] - y1)):
        b = qx0 * d_x + qy0 * d_y
        c = qx0 * qx0 + qy0 * qy0 - radius * radius
        disc = b * b - dd[:, None] * c
        with np.errstate(**_ERR):
            t = (-b - np.sqrt(np.maximum(disc, 0.0))) / dd[:, None]
        t = np.where(c <= 0, 0.0, t)
        hit = (disc >= 0) & (b < 0) & (t >= 0) & (t <= 1)
        th = np.where(hit, t, np.inf)
        j = th.argmin(axis=1)
        tj = th[rows, j]
        better = tj < t_best
        if better.any():
            with np.errstate(**_ERR):  # rows without a hit (tj = inf) are masked below
                qx = qx0[rows, j] + tj * dx
                qy = qy0[rows, j] + tj * dy
                rate = np.maximum(np.abs(qx * dx + qy * dy) / max(radius, 1e-300), 1e-300)
            t_best = np.where(better, tj, t_best)
            back = np.where(better, skin / rate, back)
    res = np.where(t_best >= 1.0, 1.0, np.maximum(0.0, t_best - back))
    return np.where(moving, res, 1.0)


def sweep(p, d, S: Segments, radius: float, skin: float) -> float:
    """One robot: :func:`sweep_batch` for N = 1 (``p``, ``d``: 2-sequences)."""
    return float(
        sweep_batch(
            np.array([p[0]]), np.array([p[1]]), np.array([d[0]]), np.array([d[1]]), S, radius, skin
        )[0]
    )
