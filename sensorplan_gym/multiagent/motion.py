"""Robot A's scripted motion: an EDR motion plan toward G with bounded control error.

Model (paper 1.1: an EDR plan under generalized-damper dynamics ends in G or in H, and once
there it stays).  At reset, from the episode's generator:

1. A starts at a uniform free configuration at least ``min_start_dist`` (fraction of the
   scene diameter) from G and from H.  A translates at orientation 0.
2. Its commanded motion is the shortest collision-free path to an end point drawn uniformly
   in G (:meth:`WatchWorld.shortest_path`), not crossing H when such a path exists.  With
   probability ``p_fail`` the plan fails: at a uniform fraction in ``[0.3, 0.7]`` of the way,
   A is deflected and follows the shortest path from there to an end point in H that does
   not cross G (when one exists) -- A never enters G and leaves it again.
3. The plan is executed in exactly ``move_steps`` steps: the commanded progress per step is
   ``L / move_steps`` times ``1 + xi`` with ``|xi| <= speed_noise`` (renormalised to end at
   the path's end), plus a bounded drift ``e`` off the path: a Gaussian random walk clipped to
   a disc whose radius is ``min(drift * diameter, clearance)`` -- the clearance being the
   exact distance of the commanded configuration to A's C-space boundary, so the drift never
   pushes A into a wall or obstacle -- and shrinks linearly to zero over the last
   ``settle_steps`` steps (the damper settles A exactly at the end point).
4. From step ``move_steps`` on A rests at the end point, inside G or H.

The whole trajectory is drawn at reset (``(move_steps + 1, 2)`` positions); the outcome
(``"G"`` or ``"H"``) is hidden from the watchers' observations.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .world import WatchWorld

__all__ = ["MotionConfig", "Trajectory", "plan_trajectory"]


@dataclass(frozen=True)
class MotionConfig:
    move_steps: int = 50
    p_fail: float = 0.5
    drift: float = 0.02
    speed_noise: float = 0.2
    settle_steps: int = 8
    min_start_dist: float = 0.25

    def validate(self) -> MotionConfig:
        if not isinstance(self.move_steps, (int, np.integer)) or self.move_steps < 2:
            raise ValueError(f"move_steps must be an integer >= 2, got {self.move_steps!r}")
        if not (isinstance(self.p_fail, (int, float)) and 0.0 <= self.p_fail <= 1.0):
            raise ValueError(f"p_fail must be a probability in [0, 1], got {self.p_fail!r}")
        for name in ("drift", "speed_noise", "min_start_dist"):
            v = getattr(self, name)
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0):
                raise ValueError(f"{name} must be a finite non-negative number, got {v!r}")
        if self.speed_noise >= 1:
            raise ValueError(f"speed_noise must be < 1, got {self.speed_noise!r}")
        if not isinstance(self.settle_steps, (int, np.integer)) or self.settle_steps < 1:
            raise ValueError(f"settle_steps must be a positive integer, got {self.settle_steps!r}")
        return self


@dataclass
class Trajectory:
    """A's positions ``pos[t]`` for ``t = 0 .. move_steps`` (world frame), its commanded path
    (way points), the hidden ``outcome`` ("G" or "H") and the fault point (or None)."""

    pos: np.ndarray
    path: np.ndarray
    outcome: str
    fault: np.ndarray | None

    def at(self, t: int) -> np.ndarray:
        return self.pos[min(t, len(self.pos) - 1)]


def _resample(path: np.ndarray, s: np.ndarray) -> np.ndarray:
    """Points at arc lengths ``s`` along the polyline ``path``."""
    seg = np.hypot(*np.diff(path, axis=0).T)
    cum = np.concatenate([[0.0], np.cumsum(seg)])
    s = np.clip(s, 0.0, cum[-1])
    i = np.clip(np.searchsorted(cum, s, side="right") - 1, 0, len(seg) - 1)
    t = np.where(seg[i] > 0, (s - cum[i]) / np.where(seg[i] > 0, seg[i], 1.0), 0.0)
    return path[i] + t[:, None] * (path[i + 1] - path[i])


def _length(path: np.ndarray) -> float:
    return float(np.hypot(*np.diff(path, axis=0).T).sum())


def plan_trajectory(
    world: WatchWorld, cfg: MotionConfig, rng: np.random.Generator, max_tries: int = 50
) -> Trajectory:
    """Draw one episode's motion of A (see the module docstring)."""
    diam = world.diameter
    gc = np.asarray(world.goal_geom.centroid.coords[0])
    hc = np.asarray(world.failure_geom.centroid.coords[0])
    last = "no start"
    for _ in range(max_tries):
        start = world.sample_free_config(rng)
        if min(np.hypot(*(start - gc)), np.hypot(*(start - hc))) < cfg.min_start_dist * diam:
            last = "start too close to G or H"
            continue
        qg = world.sample_end("G", rng)
        path = world.shortest_path(start, qg, avoid="H")
        if path is None:
            path = world.shortest_path(start, qg)
        if path is None:
            last = "G not reachable from the start"
            continue
        fail = bool(rng.random() < cfg.p_fail)
        fault = None
        if fail:
            qh = world.sample_end("H", rng)
            u = rng.uniform(0.3, 0.7)
            L = _length(path)
            fault = _resample(path, np.array([u * L]))[0]
            cum = np.concatenate([[0.0], np.cumsum(np.hypot(*np.diff(path, axis=0).T))])
            head = np.vstack([path[: int(np.searchsorted(cum, u * L, side="right"))], fault])
            tail = world.shortest_path(fault, qh, avoid="G")
            if tail is None:
                tail = world.shortest_path(fault, qh)
            if tail is None:
                last = "H not reachable from the fault point"
                continue
            path = np.vstack([head, tail[1:]])
        pos = _execute(world, cfg, path, rng)
        return Trajectory(pos=pos, path=path, outcome="H" if fail else "G", fault=fault)
    raise RuntimeError(f"scene {world.scene.name!r}: could not plan robot A's motion ({last})")


def _execute(world: WatchWorld, cfg: MotionConfig, path: np.ndarray, rng) -> np.ndarray:
    T = int(cfg.move_steps)
    L = _length(path)
    w = 1.0 + rng.uniform(-cfg.speed_noise, cfg.speed_noise, T)
    s = np.concatenate([[0.0], np.cumsum(w) / w.sum() * L])
    s[-1] = L
    nominal = _resample(path, s)
    out = np.empty_like(nominal)
    out[0] = nominal[0]
    emax = cfg.drift * world.diameter
    sigma = 0.25 * emax
    clear = world.clearances(nominal[1:, 0], nominal[1:, 1]).tolist()  # one query for all
    skin, settle = world.skin, cfg.settle_steps
    rs = [
        min(emax, max(0.0, clear[t - 1] - skin)) * min(1.0, (T - t) / settle)
        for t in range(1, T + 1)
    ]
    # the steps with room to drift draw two normals each, in order: drawn at once
    zl = rng.normal(0.0, sigma, (sum(r > 0 for r in rs), 2)).tolist()
    drift = []
    ex = ey = 0.0  # the drift e, in Python floats (the same IEEE operations as on arrays)
    k = 0
    for r in rs:
        if r > 0:
            ex = ex + zl[k][0]
            ey = ey + zl[k][1]
            k += 1
        else:
            ex = ey = 0.0
        n = math.hypot(ex, ey)
        if n > r and n > 0:
            f = r / n
            ex = ex * f
            ey = ey * f
        drift.append((ex, ey))
    drift = np.array(drift)
    out[1:] = nominal[1:] + drift
    out[T] = nominal[T]
    return out
