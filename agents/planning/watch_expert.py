"""The watch oracle as a teacher: an action for every watcher from *any* state.

:class:`WatchExpert` labels the states a learner visits (DAgger) on a
``watch_v0.parallel_env(evidence=True)``.  It keeps :class:`~.watch_oracle.WatchOracle`'s
placement (the exact regions that see A wherever it is in G / in H, the shortest-path
candidate, the bisector aim) but holds no episode state of its own, so that its answer is a
function of what the learner can observe:

* **Placement, replanned every step** from the watchers' current poses (a path from where a
  learner drove, not from where the oracle would be).  ``placement="oracle"``: the oracle's
  rule -- one watcher: the region that sees A in G *and* H; two or more: watchers 0 and 1
  take G and H, the assignment with the shorter total path from the current poses, further
  watchers take both.  ``placement="both"``: every watcher goes to the region that sees A
  in G and in H (the oracle's one-watcher placement) -- no roles to infer.
* **Scanning.**  From ``move_steps`` on the watcher turns at the oracle's scan step (less
  than half A's angular width as seen from the placement) so that the beam fan sweeps its
  gaps; with a field of view below 360 degrees it sweeps the oracle's offsets around the aim
  (by the time since ``move_steps``).
* **Declaration from the evidence features** (:mod:`sensorplan_gym.multiagent.evidence`, the
  watcher's own beams): A seen in ``A (+) G`` only -> G, in ``A (+) H`` only -> H (both: the
  likelier by count); with no sighting by ``max_steps - decide_window``, a watcher in the G
  (H) region but not in the H (G) one declares H (G), any other declares G.

``act(observations)`` returns the actions dict, like :class:`WatchOracle`.  Privileged on the
map and the watchers' own poses only: never A's trajectory or outcome.
"""

from __future__ import annotations

import math

import numpy as np
import shapely

from .watch_oracle import WatchOracle, _len, _Plan, _wrap

__all__ = ["PLACEMENTS", "WatchExpert"]

PLACEMENTS = ("oracle", "both")


class WatchExpert:
    """Stateless teacher for every watcher of a ``watch_v0`` env built with
    ``evidence=True`` (see the module docstring)."""

    def __init__(self, env, placement: str = "oracle", decide_window: int = 10) -> None:
        if placement not in PLACEMENTS:
            raise ValueError(f"placement must be one of {PLACEMENTS}, got {placement!r}")
        if getattr(env, "evidence", None) is None:
            raise ValueError("WatchExpert needs watch_v0.parallel_env(..., evidence=True)")
        if not isinstance(decide_window, int) or decide_window < 1:
            raise ValueError(f"decide_window must be a positive integer, got {decide_window!r}")
        self.env = env
        self.placement = placement
        self.decide_window = decide_window
        self.oracle = WatchOracle(env)
        if placement == "both" and self.oracle.regions["both"].is_empty:
            raise ValueError(
                f"scene {env.scene.name!r}: no region sees A both in G and in H; "
                "use placement='oracle'"
            )
        for g in self.oracle.regions.values():
            shapely.prepare(g)

    # ---- placement ----------------------------------------------------------------------
    def plans(self) -> list[_Plan | None]:
        """This step's plan of every watcher (from the current poses)."""
        env, o = self.env, self.oracle
        poses = env.poses
        n = env.n_watchers
        if self.placement == "both" or n == 1:
            which = "both" if not o.regions["both"].is_empty else "G"
            return [o._plan_for(p, which) or o._plan_for(p, "G") for p in poses]
        a = [o._plan_for(poses[0], "G"), o._plan_for(poses[1], "H")]
        b = [o._plan_for(poses[0], "H"), o._plan_for(poses[1], "G")]
        cost = [sum(_len(p) for p in pair) for pair in (a, b)]
        plans: list[_Plan | None] = list(a if cost[0] <= cost[1] else b)
        for i in range(2, n):
            plans.append(o._plan_for(poses[i], "both") or o._plan_for(poses[i], "G"))
        return plans

    # ---- acting -------------------------------------------------------------------------
    def act(self, observations: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """The teacher's action (``float32 (4,)``) for every watcher in ``observations``."""
        env = self.env
        plans = self.plans()
        out = {}
        for i, agent in enumerate(env.possible_agents):
            if agent in observations:
                out[agent] = self._act_one(i, plans[i])
        return out

    def _act_one(self, i: int, plan: _Plan | None) -> np.ndarray:
        env, o = self.env, self.oracle
        x, y, psi = env.poses[i]
        fwd = lat = 0.0
        turn = 0.0
        if plan is not None:
            path = plan.path
            k = 1
            while k < len(path) and np.hypot(*(path[k] - (x, y))) < 1e-9:
                k += 1
            if k < len(path):
                dx, dy = path[k] - (x, y)
                v = env.max_speed
                c, s = math.cos(psi), math.sin(psi)
                f, lt = (c * dx + s * dy) / v, (-s * dx + c * dy) / v
                scale = max(1.0, abs(f), abs(lt))
                fwd, lat = f / scale, lt / scale
            if env.t >= env.move_steps:
                if env.world.full_fov:
                    turn = plan.scan_step / env.max_turn
                else:
                    offs = np.arange(-0.5 * o.spacing, 0.5 * o.spacing + 1e-12, plan.scan_step)
                    aim = plan.aim + float(offs[(env.t - env.move_steps) % len(offs)])
                    turn = _wrap(aim - psi) / env.max_turn
            else:
                turn = _wrap(plan.aim - psi) / env.max_turn
        return np.array([fwd, lat, float(np.clip(turn, -1, 1)), self.decide(i)], dtype=np.float32)

    def decide(self, i: int) -> float:
        """The decide component for watcher ``i`` now: -1 (G), +1 (H) or 0 (not yet / done)."""
        env = self.env
        if env.declared[i] is not None or env.t < env.move_steps:
            return 0.0
        hits = env.evidence.hits[i]
        if hits[0] > 0 or hits[1] > 0:
            if hits[0] != hits[1]:
                return -1.0 if hits[0] > hits[1] else 1.0
        if env.t < env.max_steps - self.decide_window:
            return 0.0
        x, y = env.poses[i][:2]
        reg = self.oracle.regions
        in_g = bool(shapely.contains_xy(reg["G"], x, y))
        in_h = bool(shapely.contains_xy(reg["H"], x, y))
        if in_g and not in_h:
            return 1.0  # it looks at G and saw no A there
        return -1.0
