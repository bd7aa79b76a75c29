"""The oracle watchers of ``watch_v0``.

:class:`WatchOracle` (privileged on the *map* only: it never reads A's trajectory or outcome)

* **Placement.**  The exact regions that see A wherever it is in G, and wherever it is in H
  (swept complete/partial visibility, paper 3.1.2/3.2.2: ``complete_region(scene,
  target_in="goal")`` ...).  One watcher goes to their intersection -- it sees A anywhere in
  G u H -- or, when that is empty, to G's region alone; with two or more, watcher 0 covers G
  and watcher 1 covers H (the assignment with the shorter total path), further watchers cover
  both.  Within its region a watcher takes, among candidate points at least a safety margin
  inside it, the one with the shortest collision-free path that also keeps the swept hulls
  ``CH(A (+) G)`` / ``CH(A (+) H)`` inside its field of view with a margin of half a beam
  spacing and within range; it drives there (visibility-graph shortest path) and aims at
  the bisector of their angular interval.
* **Declaration, from its readings.**  From step ``move_steps`` on (A's plan is over: a task
  constant) it sweeps its beam fan through one beam spacing in steps smaller than A's
  angular width, collects the beam end points that fall short of the map's prediction (they
  hit A) and declares G if one lies in A's swept area over G, H if one lies in that over H; a
  watcher that covers only G (H) and saw no A there after the sweep declares H (G).

Episodes with it (and with random or RLlib watchers) are played and summarized by
:mod:`agents.evaluation.watch` (``python -m agents.evaluation.watch``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import shapely

__all__ = ["WatchOracle"]


def _wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


@dataclass
class _Plan:
    covers: str  # "both", "G" or "H"
    point: np.ndarray
    aim: float
    path: np.ndarray
    scan_step: float
    hits: dict = field(default_factory=lambda: {"G": 0, "H": 0})
    wp: int = 1
    scan_k: int = 0


class WatchOracle:
    """Oracle controller for every watcher of a :class:`WatchParallelEnv` (see the module
    docstring).  ``act(observations)`` returns the actions dict; call ``reset()`` (done
    automatically when the env's step counter is back at 0) after every ``env.reset``."""

    def __init__(self, env, n_candidates: int = 400) -> None:
        from sensorplan_gym.multiagent.rendering import watch_region
        from sensorplan_gym.multiagent.world import VisGraph

        self.env = env
        w = env.world
        self.world = w
        self.n_candidates = int(n_candidates)
        margin = 0.01 * w.diameter
        space = w.free_space.buffer(-(env.robot_radius + margin), join_style="mitre")
        self.graph = VisGraph(space)
        self.regions = {k: shapely.intersection(watch_region(w, k), space) for k in ("G", "H")}
        self.regions["both"] = shapely.intersection(self.regions["G"], self.regions["H"])
        self.hulls = {
            k: np.asarray(shapely.convex_hull(w.swept[k]).exterior.coords)[:-1] for k in "GH"
        }
        self.swept = {k: w.swept[k].buffer(1e-6 * w.diameter) for k in "GH"}
        for g in self.swept.values():
            shapely.prepare(g)
        n = env.sensor.n_beams
        self.spacing = w.fov / max(n - 1, 1) if not w.full_fov else 2 * math.pi / n
        hull = shapely.MultiPoint(w.target).convex_hull
        self.min_width = _min_width(np.asarray(hull.exterior.coords)[:-1])
        self._cands: dict[str, np.ndarray] = {}
        self.plans: list[_Plan | None] = []
        self._t_last = None

    # ---- planning ---------------------------------------------------------------------------
    def _candidates(self, which: str) -> np.ndarray:
        c = self._cands.get(which)
        if c is None:
            R = self.regions[which]
            deep = R.buffer(-0.02 * self.world.diameter)
            src = deep if not deep.is_empty and deep.area > 0.05 * R.area else R
            c = _grid_points(src, self.n_candidates)
            self._cands[which] = c
        return c

    def _plan_for(self, pose, which: str) -> _Plan | None:
        w = self.world
        hulls = [self.hulls["G"], self.hulls["H"]] if which == "both" else [self.hulls[which]]
        best = None
        cands = self._candidates(which)
        chord = np.hypot(*(cands - np.asarray(pose[:2])).T)
        for p in cands[np.argsort(chord, kind="stable")]:
            aim, _ = _aim_interval(p, hulls)
            if not w.full_fov:
                # the whole angular interval plus half a beam spacing either side must fit
                if _span(p, hulls) + self.spacing > w.fov:
                    continue
            dmax = max(float(np.hypot(*(h - p).T).max()) for h in hulls)
            if dmax > w.max_range:
                continue
            if best is not None and np.hypot(*(p - pose[:2])) >= best[0]:
                break  # no later candidate can win: a path is never shorter than its chord
            path = self._path(pose[:2], p)
            if path is None:
                continue
            L = float(np.hypot(*np.diff(path, axis=0).T).sum())
            if best is None or L < best[0]:
                best = (L, p, aim, path, dmax)
        if best is None:
            return None
        L, p, aim, path, dmax = best
        step = min(0.5 * self.min_width / dmax, self.env.max_turn)
        return _Plan(covers=which, point=p, aim=aim, path=path, scan_step=step)

    def _path(self, a, b) -> np.ndarray | None:
        """Shortest path from ``a`` to ``b``; a start closer to a wall than the planning margin
        first steps straight to the nearest point of the planning domain."""
        a = np.asarray(a, dtype=np.float64)
        if self.graph.contains(a[0], a[1]):
            return self.graph.shortest_path(a, b)
        from shapely.ops import nearest_points

        inner = self.__dict__.get("_inner")
        if inner is None:
            inner = self._inner = self.graph.domain.buffer(-1e-6 * self.world.diameter)
        q = nearest_points(inner, shapely.Point(a))[0]
        qq = np.array([q.x, q.y])
        rest = self.graph.shortest_path(qq, b)
        return None if rest is None else np.vstack([a, rest])

    def reset(self) -> None:
        env = self.env
        n = env.n_watchers
        poses = env.poses
        plans: list[_Plan | None] = [None] * n
        if n == 1:
            order = ["both"] if not self.regions["both"].is_empty else ["G"]
            plans[0] = self._plan_for(poses[0], order[0])
            if plans[0] is None and order[0] == "both":
                plans[0] = self._plan_for(poses[0], "G")
        else:
            a = [self._plan_for(poses[0], "G"), self._plan_for(poses[1], "H")]
            b = [self._plan_for(poses[0], "H"), self._plan_for(poses[1], "G")]
            cost = [
                sum(_len(p) for p in pair) if all(p is not None for p in pair) else math.inf
                for pair in (a, b)
            ]
            plans[0], plans[1] = a if cost[0] <= cost[1] else b
            for i in range(2, n):
                plans[i] = self._plan_for(poses[i], "both") or self._plan_for(poses[i], "G")
        self.plans = plans

    # ---- acting -----------------------------------------------------------------------------
    def act(self, observations: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        env = self.env
        if env.t == 0 and self._t_last != 0:
            self.reset()
        self._t_last = env.t
        out = {}
        for i, agent in enumerate(env.possible_agents):
            if agent not in observations:
                continue
            out[agent] = self._act_one(i, observations[agent])
        return out

    def _act_one(self, i: int, obs: np.ndarray) -> np.ndarray:
        env = self.env
        plan = self.plans[i]
        x, y, psi = env.poses[i]  # the watcher's own (commanded) pose: odometry
        if plan is None:  # no placement: stay and declare the likelier G at the end
            d = -1.0 if env.t >= env.max_steps - 1 and env.declared[i] is None else 0.0
            return np.array([0, 0, 0, d], dtype=np.float32)
        fwd = lat = 0.0
        target_aim = plan.aim
        # drive along the path
        while plan.wp < len(plan.path) and np.hypot(*(plan.path[plan.wp] - (x, y))) < 1e-9:
            plan.wp += 1
        arrived = plan.wp >= len(plan.path)
        if not arrived:
            dx, dy = plan.path[plan.wp] - (x, y)
            dist = math.hypot(dx, dy)
            v = env.max_speed
            # the action square allows sqrt(2) x speed along the diagonal; stay within 1 per axis
            c, s = math.cos(psi), math.sin(psi)
            f, lt = (c * dx + s * dy) / v, (-s * dx + c * dy) / v
            scale = max(1.0, abs(f), abs(lt))
            fwd, lat = f / scale, lt / scale
            if scale == 1.0 and dist <= v * math.sqrt(2):
                plan.wp += 1
        decide = 0.0
        if arrived and env.t >= env.move_steps and env.declared[i] is None:
            # scanning: collect the beams that hit A on this step, then turn to the next offset
            self._collect(i, obs, (x, y, psi), plan)
            verdict = self._verdict(plan)
            if verdict is not None:
                decide = -1.0 if verdict == "G" else 1.0
            k = plan.scan_k
            offsets = np.arange(-0.5 * self.spacing, 0.5 * self.spacing + 1e-12, plan.scan_step)
            target_aim = plan.aim + float(offsets[k % len(offsets)])
            plan.scan_k += 1
            if plan.scan_k > len(offsets) and verdict is None:
                verdict = {"G": "H", "H": "G", "both": None}[plan.covers]
                if verdict is None:  # A not seen from a placement that sees all of G u H
                    verdict = "G" if plan.hits["G"] >= plan.hits["H"] else "H"
                decide = -1.0 if verdict == "G" else 1.0
        turn = float(np.clip(_wrap(target_aim - psi) / env.max_turn, -1, 1))
        return np.array([fwd, lat, turn, decide], dtype=np.float32)

    def _collect(self, i: int, obs: np.ndarray, pose, plan: _Plan) -> None:
        env, w = self.env, self.world
        n = env.sensor.n_beams
        meas = obs[8 : 8 + n].astype(np.float64) * w.reach
        pred = obs[8 + 3 * n : 8 + 4 * n].astype(np.float64) * w.reach
        short = meas < pred - 1e-4 * w.diameter  # float32 observation resolution
        if not short.any():
            return
        ang = env.sensor.beam_angles(pose[2])[short]
        px = pose[0] + meas[short] * np.cos(ang)
        py = pose[1] + meas[short] * np.sin(ang)
        for k in "GH":
            plan.hits[k] += int(shapely.contains_xy(self.swept[k], px, py).sum())

    @staticmethod
    def _verdict(plan: _Plan) -> str | None:
        g, h = plan.hits["G"] > 0, plan.hits["H"] > 0
        if g and not h:
            return "G"
        if h and not g:
            return "H"
        return None


def _len(plan: _Plan | None) -> float:
    return math.inf if plan is None else float(np.hypot(*np.diff(plan.path, axis=0).T).sum())


def _min_width(hull: np.ndarray) -> float:
    """Minimum width of a convex polygon (over its edge normals)."""
    e = np.roll(hull, -1, axis=0) - hull
    nrm = np.stack([-e[:, 1], e[:, 0]], axis=1) / np.hypot(e[:, 0], e[:, 1])[:, None]
    proj = hull @ nrm.T
    return float((proj.max(axis=0) - proj.min(axis=0)).min())


def _angles(p: np.ndarray, hulls: list[np.ndarray]) -> tuple[float, np.ndarray]:
    pts = np.vstack(hulls)
    c = pts.mean(axis=0)
    base = math.atan2(c[1] - p[1], c[0] - p[0])
    rel = np.arctan2(pts[:, 1] - p[1], pts[:, 0] - p[0]) - base
    return base, (rel + math.pi) % (2 * math.pi) - math.pi


def _span(p: np.ndarray, hulls: list[np.ndarray]) -> float:
    _, rel = _angles(p, hulls)
    return float(rel.max() - rel.min())


def _aim_interval(p: np.ndarray, hulls: list[np.ndarray]) -> tuple[float, float]:
    """The bisector aim of the angular interval of the hulls seen from ``p`` and its half
    width."""
    base, rel = _angles(p, hulls)
    lo, hi = float(rel.min()), float(rel.max())
    return _wrap(base + 0.5 * (lo + hi)), 0.5 * (hi - lo)


def _grid_points(region: shapely.Geometry, n: int) -> np.ndarray:
    """About ``n`` points of a square grid inside ``region`` (its cell centres), plus a
    representative point -- candidates for a placement in the exact region."""
    if region.is_empty:
        return np.zeros((0, 2))
    x0, y0, x1, y1 = region.bounds
    h = math.sqrt(max(region.area, 1e-12) / n)
    xs = np.arange(x0 + h / 2, x1, h)
    ys = np.arange(y0 + h / 2, y1, h)
    X, Y = np.meshgrid(xs, ys)
    P = np.stack([X.ravel(), Y.ravel()], axis=1)
    P = P[shapely.contains_xy(region, P[:, 0], P[:, 1])]
    rp = region.representative_point()
    return np.vstack([P, [[rp.x, rp.y]]])
