"""Beam evidence of where A rests, accumulated per watcher (``watch_v0(evidence=True)``).

A watcher that carries the map knows what its beams should read without A (the *predicted*
ranges, walls and obstacles alone).  A beam that reads shorter than its prediction hit A;
where its end point lies tells where A is.  Once A's plan is over (``t >= move_steps``, a
constant of the task, not of the outcome) A rests with its reference point in G or in H, so
its outline lies in the swept area ``A (+) G`` or ``A (+) H`` (:attr:`WatchWorld.swept`).
:class:`BeamEvidence` counts, per watcher and from that step on:

* ``hits[k]`` -- the steps on which at least one beam fell short and ended in ``A (+) k``
  (``k`` = G, H): *positive* evidence that A rests in ``k`` (as in Recognize-v0's
  ``map_evidence`` flags, but kept over the episode);
* ``looks[k]`` -- the steps on which at least one beam's map-predicted segment (from the
  watcher to where the map says the beam ends) crossed ``A (+) k``: the watcher looked there.
  Looks without hits are *negative* evidence (A is not where the beams passed).

:meth:`BeamEvidence.features` returns ``(seen_G, seen_H, looked_G, looked_H)`` =
``1 - 0.5 ** hits`` and ``1 - 0.5 ** (looks / 4)``, each in [0, 1) -- saturating counts
appended to the watcher's observation.  "Short" means shorter than the prediction by more
than ``3 noise + 1e-3 reach`` (the Recognize-v0 threshold).  Frames: world coordinates,
scene units; beam angles in radians counter-clockwise from +x.
"""

from __future__ import annotations

import numpy as np
import shapely

__all__ = ["N_EVIDENCE", "BeamEvidence", "beam_evidence"]

N_EVIDENCE = 4  # seen_G, seen_H, looked_G, looked_H


def beam_evidence(
    swept: dict[str, shapely.Geometry],
    pose: tuple[float, float, float],
    angles: np.ndarray,
    measured: np.ndarray,
    predicted: np.ndarray,
    tol: float,
) -> tuple[np.ndarray, np.ndarray]:
    """One watcher's evidence on one step: ``(hit, look)``, two bool arrays of shape ``(2,)``
    for (G, H).  ``hit[k]``: some beam read shorter than ``predicted - tol`` and its end point
    (``pose + measured * (cos, sin)(angle)``) lies in ``swept[k]`` (boundary included);
    ``look[k]``: some beam's predicted segment (``pose`` to ``pose + predicted * (cos,
    sin)(angle)``) meets ``swept[k]``.  ``angles``, ``measured`` and ``predicted`` are per
    beam (world radians, scene units)."""
    angles = np.asarray(angles, dtype=np.float64)
    measured = np.asarray(measured, dtype=np.float64)
    predicted = np.asarray(predicted, dtype=np.float64)
    if not (angles.shape == measured.shape == predicted.shape and angles.ndim == 1):
        raise ValueError(
            f"beam_evidence: angles {angles.shape}, measured {measured.shape} and predicted "
            f"{predicted.shape} must be one-dimensional of the same length"
        )
    x, y = float(pose[0]), float(pose[1])
    c, s = np.cos(angles), np.sin(angles)
    short = measured < predicted - tol
    hit = np.zeros(2, dtype=bool)
    look = np.zeros(2, dtype=bool)
    px, py = x + measured[short] * c[short], y + measured[short] * s[short]
    n = len(angles)
    seg = np.empty((n, 2, 2))
    seg[:, 0, 0], seg[:, 0, 1] = x, y
    seg[:, 1, 0], seg[:, 1, 1] = x + predicted * c, y + predicted * s
    lines = shapely.linestrings(seg)
    for j, k in enumerate("GH"):
        g = swept[k]
        if short.any():
            hit[j] = bool(shapely.intersects_xy(g, px, py).any())
        look[j] = bool(shapely.intersects(g, lines).any())
    return hit, look


class BeamEvidence:
    """Per-watcher counters of :func:`beam_evidence` from ``move_steps`` on (see the module
    docstring).  ``swept``: ``{"G": ..., "H": ...}`` polygons (world frame); ``tol``: the
    shortfall (scene units) that counts as a hit."""

    def __init__(self, swept: dict[str, shapely.Geometry], n_watchers: int, tol: float) -> None:
        self.swept = {k: swept[k] for k in "GH"}
        for g in self.swept.values():
            shapely.prepare(g)
        self.tol = float(tol)
        self.hits = np.zeros((int(n_watchers), 2), dtype=np.int64)
        self.looks = np.zeros((int(n_watchers), 2), dtype=np.int64)
        #: the last step counted (the env counts each step once)
        self.t_counted = -1

    def reset(self) -> None:
        """Forget everything (a new episode)."""
        self.hits[:] = 0
        self.looks[:] = 0
        self.t_counted = -1

    def update(
        self,
        i: int,
        pose: tuple[float, float, float],
        angles: np.ndarray,
        measured: np.ndarray,
        predicted: np.ndarray,
    ) -> None:
        """Count watcher ``i``'s readings of this step (call only once A's plan is over);
        arguments as :func:`beam_evidence`."""
        hit, look = beam_evidence(self.swept, pose, angles, measured, predicted, self.tol)
        self.hits[i] += hit
        self.looks[i] += look

    def features(self, i: int) -> np.ndarray:
        """``(seen_G, seen_H, looked_G, looked_H)`` of watcher ``i``, float64 in [0, 1)."""
        return np.concatenate([1.0 - 0.5 ** self.hits[i], 1.0 - 0.5 ** (self.looks[i] / 4.0)])
