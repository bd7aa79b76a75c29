"""Lines and directions, row by row."""

from __future__ import annotations

import numpy as np

from .._shapes import cross as _cross


def _meet(a0: np.ndarray, a1: np.ndarray, b0: np.ndarray, b1: np.ndarray) -> np.ndarray:
    """Intersection of the lines (a0, a1) and (b0, b1), row by row (NaN if parallel)."""
    da, db = a1 - a0, b1 - b0
    den = _cross(da, db)
    with np.errstate(divide="ignore", invalid="ignore"):  # parallel: inf * 0 = NaN
        s = _cross(b0 - a0, db) / den
        return a0 + da * s[..., None]


def _rot(v: np.ndarray) -> np.ndarray:
    """``v`` (..., 2) turned by +90 degrees."""
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def _corner_pairs(env, sel: np.ndarray) -> tuple[np.ndarray, ...]:
    """The obstacle corners ``env.vert[sel]`` (``b``), their edge vectors to the previous
    and next boundary vertex (``bp``, ``bn``), every pair ``(i, j)``, ``i < j``, of them
    and the vector ``w`` from corner i to corner j of each pair."""
    b = env.vert[sel]
    bp = env.vert_prev[sel] - b
    bn = env.vert_next[sel] - b
    i, j = np.triu_indices(len(b), 1)
    return b, bp, bn, i, j, b[j] - b[i]
