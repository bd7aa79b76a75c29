"""Action types, chosen by the env kwarg ``action_type`` (highway-env style).

Every task is simulated on continuous action vectors in [-1, 1]^d (see each env's docstring
for what the components mean); an action type declares the agent-facing space and turns a
batch of agent actions into those vectors.

``"continuous"`` (default)
    ``Box(-1, 1, (d,), float32)``: the vector itself.  Values outside [-1, 1] are clipped;
    NaN/inf or a wrong shape raise ``ValueError``.
``"discrete"``
    ``Discrete(K)``: row ``a`` of a fixed table of continuous actions, for DQN-style agents.
    Robot envs (Navigate, Recognize): ``0`` stay, ``1`` forward, ``2`` backward, ``3`` left,
    ``4`` right (full speed, robot frame), ``5`` turn left, ``6`` turn right (a full turn step);
    Recognize adds ``7`` declare G and ``8`` declare H.  Placement: a ``G x G`` grid of
    placements over the scene's bounding box (cell centres) times ``A`` aims
    ``-pi + 2 pi k / A``: ``a = (i * G + j) * A + k`` for column ``i`` (x), row ``j`` (y),
    aim ``k`` (``G = 16``, ``A = 8`` by default).  A non-integer, or an integer outside
    ``[0, K)``, raises ``ValueError``.
``"pixel"`` (Placement)
    ``Discrete(S * S * A)``: one placement per pixel of the grid observation (its centre;
    ``S = grid_size``, the scene's bounding box fit into the square, row 0 at the top) times
    ``A = placement_aims`` aims ``-pi + 2 pi k / A``: ``a = (row * S + col) * A + k``, i.e.
    ``np.unravel_index(a, (S, S, A))``, so that a fully convolutional policy's output map
    lines up with its input.  A pixel outside the bounding box (the square's padding) is
    placed on the box's edge.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from gymnasium import spaces

from . import fused

__all__ = ["ACTION_TYPES", "ContinuousActions", "DiscreteActions", "make_actions"]

ACTION_TYPES = ("continuous", "discrete", "pixel")


class ContinuousActions:
    """The task's own ``Box(-1, 1, (d,))``."""

    square = False  # x and y span the bounding box (see DiscreteActions)

    def __init__(self, dim: int) -> None:
        self.dim = dim
        self.space = spaces.Box(-1.0, 1.0, (dim,), np.float32)

    def to_array(self, actions: Any, k: int) -> np.ndarray:
        """``(k, d)`` float64 actions, validated and clipped to [-1, 1]."""
        shape = (k, self.dim)
        try:
            a = np.array(actions, dtype=np.float64)  # a copy: clipped in place below
        except (TypeError, ValueError) as e:
            raise ValueError(
                f"action must be a numeric array of shape {shape[1:]}, got {actions!r}"
            ) from e
        if a.shape != shape:
            raise ValueError(f"action must have shape {shape[1:]}, got shape {a.shape[1:]}")
        if fused.FUSED and fused.clip_unit(a):
            return a
        if not np.isfinite(a).all():
            raise ValueError(f"action contains NaN or infinite values: {a.tolist()}")
        return np.clip(a, -1.0, 1.0)


class DiscreteActions:
    """``Discrete(K)``: rows of ``table`` ``(K, d)``.  ``square``: a Placement table whose x and
    y span the grid observation's square (``"pixel"``), not the bounding box."""

    def __init__(
        self, table: np.ndarray, names: list[str] | None = None, *, square: bool = False
    ) -> None:
        self.square = bool(square)
        self.table = np.asarray(table, dtype=np.float64)
        self.dim = self.table.shape[1]
        self.names = names
        self.space = spaces.Discrete(len(self.table))

    def to_array(self, actions: Any, k: int) -> np.ndarray:
        a = np.asarray(actions)
        if a.shape not in ((k,), (k, 1)) or a.dtype.kind not in "iub":
            raise ValueError(
                f"action must be {k} integer(s) in [0, {len(self.table)}), got {actions!r}"
            )
        a = a.reshape(k).astype(np.int64)
        if ((a < 0) | (a >= len(self.table))).any():
            raise ValueError(f"action out of range [0, {len(self.table)}): {a.tolist()}")
        return self.table[a]


ROBOT_MOTIONS = [
    ("stay", (0, 0, 0)),
    ("forward", (1, 0, 0)),
    ("backward", (-1, 0, 0)),
    ("left", (0, 1, 0)),
    ("right", (0, -1, 0)),
    ("turn left", (0, 0, 1)),
    ("turn right", (0, 0, -1)),
]


def make_actions(kind: str, task: str, dim: int, **kw: Any):
    """The action type ``kind`` for ``task`` ("robot", "recognize" or "placement")."""
    if kind not in ACTION_TYPES:
        raise ValueError(f"action_type must be one of {ACTION_TYPES}, got {kind!r}")
    if kind == "continuous":
        return ContinuousActions(dim)
    if kind == "pixel":
        if task != "placement":
            raise ValueError("action_type='pixel' is Placement's (one action per grid pixel)")
        if "placement_grid" in kw:
            raise ValueError(
                "action_type='pixel' takes its grid from grid_size, not placement_grid"
            )
        s, na = int(kw.get("grid_size", 64)), int(kw.get("placement_aims", 8))
        if na < 1:
            raise ValueError(f"placement_aims must be >= 1, got {na}")
        u = -1.0 + (2 * np.arange(s) + 1) / s  # pixel centres, left to right
        R, C, A = np.meshgrid(-u, u, -1.0 + 2 * np.arange(na) / na, indexing="ij")
        return DiscreteActions(np.stack([C.ravel(), R.ravel(), A.ravel()], axis=1), square=True)
    if task == "placement":
        g, na = int(kw.get("placement_grid", 16)), int(kw.get("placement_aims", 8))
        if g < 1 or na < 1:
            raise ValueError(f"placement_grid and placement_aims must be >= 1, got {g}, {na}")
        c = -1.0 + (2 * np.arange(g) + 1) / g
        aims = -1.0 + 2 * np.arange(na) / na
        X, Y, A = np.meshgrid(c, c, aims, indexing="ij")
        return DiscreteActions(np.stack([X.ravel(), Y.ravel(), A.ravel()], axis=1))
    rows = [m for _, m in ROBOT_MOTIONS]
    names = [n for n, _ in ROBOT_MOTIONS]
    if task == "recognize":
        rows = [(*m, 0) for m in rows] + [(0, 0, 0, -1), (0, 0, 0, 1)]
        names += ["declare G", "declare H"]
    return DiscreteActions(np.array(rows), names)
