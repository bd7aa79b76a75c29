"""The analytic oracle: a privileged planner that acts through a policy interface.

``OraclePolicy(env)`` reads the scene and the exact recognizable region of the
environment it is bound to and returns actions through
``predict(obs, state=None, episode_start=None, deterministic=True)``, so SB3's
``evaluate_policy`` and :mod:`agents.evaluation.evaluate` treat it like a trained model.

What it does (paper section 6, done better):

* **Placement** (6.2): the recognizable region (already computed with the
  sensor's ``eps_pos``/``eps_aim``) is shrunk by a safety margin and restricted
  to placements where one aim keeps both swept targets in the field of view;
  the reachable point nearest the robot is chosen.  When no straight one-step
  motion exists the robot follows the exact shortest collision-free path (a
  visibility graph over the grown obstacles, :func:`agents.planning.planner.shortest_path`).
  When no placement exists, :func:`plan_viewpoint` says so in its result.
* **Aim** (6.3): the bisector of the angular extent of both swept hulls, which
  keeps them inside the field of view with the largest margin.
* **Recognition** (6.4, on range data): readings whose end points do not lie on
  the static map are target points; :func:`agents.planning.recognition.classify` matches
  them to the target outline over G and over H by a fractional Hausdorff
  distance.  "Not seen" makes the oracle re-aim (sweeping the beam fan) and
  then move closer instead of guessing; only on the very last step of an
  episode does it fall back to the better-fitting hypothesis.

The oracle never reads the hidden target: only the map, its own commanded pose
and the sensor readings the agent also gets.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import shapely

from .planner import Placement, best_aim, best_joint_aim, choose_placement
from .recognition import classify

__all__ = ["OraclePolicy", "ViewpointPlan", "plan_viewpoint"]


@dataclass
class ViewpointPlan:
    """Where to look from: ``status`` ``"ok"``, ``"no_placement"`` or ``"unreachable"``;
    ``point`` (world frame), ``aim`` (radians), ``path`` ((N, 2) way points from the start,
    world frame, or None), ``length`` (scene units), ``one_step`` and a ``reason``."""

    status: str
    point: np.ndarray | None = None
    aim: float = 0.0
    path: np.ndarray | None = None
    length: float = math.inf
    one_step: bool = False
    reason: str = ""
    placement: Placement | None = field(default=None, repr=False)


def _aim_for(world, p: np.ndarray) -> tuple[float, float]:
    # one aim for K_G and K_H: their union, not its hull (which may hold p)
    psi, margin = best_joint_aim(p, world.must_see, world.fov, world.eps_aim)
    return float(psi), float(margin)


#: per world, the aim-feasible part of a region (:func:`_aim_feasible_region`), by region
_FEASIBLE: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _aim_feasible_region(world, region: shapely.Geometry, n: int = 24) -> shapely.Geometry:
    """The part of ``region`` where one aim satisfies the field of view, approximated from
    inside by the cells of an ``n x n`` grid over its bounding box whose four corners all
    pass the exact check; the grid is refined (2n, 4n, 8n) while that finds no cell, since a
    thin region in a large box can fall between the corners of a coarse one."""
    if world.fov >= 2 * math.pi - 1e-12 and math.isinf(world.max_range):
        return region
    kept = _FEASIBLE.setdefault(world, {})
    hit = kept.get((id(region), n))
    if hit is not None and hit[0] is region:  # the world's own region: computed once
        return hit[1]
    for k in (n, 2 * n, 4 * n, 8 * n):
        cells = _aim_feasible_cells(world, region, k)
        if not cells.is_empty:
            break
    kept[(id(region), n)] = (region, cells)
    return cells


def _aim_feasible_cells(world, region: shapely.Geometry, n: int) -> shapely.Geometry:
    """:func:`_aim_feasible_region` on one ``n x n`` grid (empty when no cell passes)."""
    x0, y0, x1, y1 = region.bounds
    xs = np.linspace(x0, x1, n + 1)
    ys = np.linspace(y0, y1, n + 1)
    gx, gy = np.meshgrid(xs, ys, indexing="ij")
    ok = np.zeros_like(gx, dtype=bool)
    inside = shapely.contains_xy(region, gx, gy)
    for i, j in zip(*np.nonzero(inside), strict=False):
        x, y = gx[i, j], gy[i, j]
        ok[i, j] = world.aim_ok(x, y, _aim_for(world, np.array([x, y]))[0])
    good = ok[:-1, :-1] & ok[1:, :-1] & ok[:-1, 1:] & ok[1:, 1:]
    gi, gj = np.nonzero(good)
    if len(gi) == 0:
        return shapely.Polygon()
    cells = shapely.box(xs[gi], ys[gj], xs[gi + 1], ys[gj + 1])
    return shapely.intersection(region, shapely.union_all(cells))


def plan_viewpoint(
    world,
    start_xy: Any,
    *,
    keep_out: shapely.Geometry | None = None,
    margin: float | None = None,
    joint_aim: bool = True,
) -> ViewpointPlan:
    """Choose a recognizing pose reachable from ``start_xy`` (paper 6.2-6.3).

    ``world`` is an environment's :class:`sensorplan_gym.core.world.World`;
    ``keep_out`` an area the robot must not enter (e.g. where the target may stand);
    ``margin`` the safety margin the region is shrunk by (default 0.2% of the scene
    diameter).  With ``joint_aim`` the placement must also admit one aim that keeps both
    swept targets in the field of view and range (what Placement and Navigate reward);
    without it any placement of the region will do (a sensor that looks at G and at H in
    turn).  Never raises for an empty or unreachable region: the result's ``status`` and
    ``reason`` say what happened.
    """
    start = np.asarray(start_xy, dtype=float)
    margin = 2e-3 * world.diameter if margin is None else float(margin)
    region = world.region
    if region.is_empty:
        return ViewpointPlan("no_placement", reason="the recognizable region is empty")
    here = shapely.Point(start)
    if keep_out is not None and keep_out.intersects(here):
        keep_out = None  # already inside it: cannot keep out
    room = float(world.free_space.boundary.distance(here))
    if keep_out is not None:
        room = min(room, float(keep_out.distance(here)))
    rr = world.robot_radius
    # keep path corners a hair off the obstacles (1e-4 D), but never more than a quarter of
    # the start's room; rounded down to a power of two, so that few distinct configuration
    # spaces arise and their path fields are reused (choose_placement keeps them)
    clearance = max(rr, min(rr + 1e-4 * world.diameter, rr + 0.25 * (room - rr)))
    if clearance > rr:
        clearance = rr + 2.0 ** math.floor(math.log2(clearance - rr))

    def attempt(reg: shapely.Geometry) -> ViewpointPlan:
        # a region thinner than twice the margin vanishes when shrunk: then smaller margins
        for m in (margin, margin / 10, margin / 100):
            pl = choose_placement(
                world.scene, reg, start, robot_radius=clearance, margin=m, keep_out=keep_out
            )
            if pl.status == "ok":
                break
        if pl.status != "ok":
            return ViewpointPlan(pl.status, reason=pl.reason, placement=pl)
        psi, _ = _aim_for(world, pl.point)
        return ViewpointPlan(
            "ok", np.asarray(pl.point), psi, pl.path.points, pl.length, pl.one_step, pl.reason, pl
        )

    plan = attempt(region)
    if plan.status == "ok" and (not joint_aim or world.aim_ok(*plan.point, plan.aim)):
        return plan
    feasible = _aim_feasible_region(world, region)
    if feasible.is_empty:
        return ViewpointPlan(
            "no_placement",
            reason="no placement of the recognizable region "
            "keeps both swept targets in the field of view and range",
        )
    plan = attempt(feasible)
    if plan.status == "ok" and not world.aim_ok(*plan.point, plan.aim):
        plan.status, plan.reason = "no_placement", "the chosen point fails the aim check"
    return plan


def _swept_hulls(world) -> list[shapely.Geometry]:
    """CH(A (+) G) and CH(A (+) H): the hulls of the target swept over G and over H."""
    k = world._cache.get("oracle_hulls")
    if k is None:
        k = world._cache["oracle_hulls"] = [
            shapely.convex_hull(shapely.multipoints(h)) for h in world.must_see
        ]
    return k


def _convex_parts(g: shapely.Geometry) -> list[np.ndarray]:
    """Vertex arrays of convex pieces whose union is ``g`` (a point, or the triangles of a
    constrained Delaunay triangulation of a polygon)."""
    if g.geom_type == "Point":
        return [np.array([[g.x, g.y]])]
    tris = shapely.get_parts(shapely.constrained_delaunay_triangles(g))
    return [np.asarray(t.exterior.coords)[:-1] for t in tris]


def _footprints(world) -> list[shapely.Geometry]:
    """The exact A (+) G and A (+) H: every point the target covers at some placement in G,
    resp. H (for a rotating target, G and H grown by the target's radius).  A Minkowski sum of
    convex pieces is the hull of their vertex sums."""
    k = world._cache.get("oracle_footprints")
    if k is not None:
        return k
    out = []
    for g in (world.goal_geom, world.failure_geom):
        if world.theta is None:
            out.append(g.buffer(world.target_radius))
            continue
        pieces = [
            shapely.convex_hull(shapely.multipoints((a[:, None, :] + b[None, :, :]).reshape(-1, 2)))
            for a in _convex_parts(shapely.Polygon(world.target))
            for b in _convex_parts(g)
        ]
        out.append(shapely.union_all(pieces))
    world._cache["oracle_footprints"] = out
    return out


def _wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


class _Driver:
    """Per-episode controller of one robot env (Navigate-v0 / Recognize-v0)."""

    def __init__(self, env) -> None:
        self.env = env
        self.plan: ViewpointPlan | None = None
        self.waypoints: list[np.ndarray] = []
        self.steps = 0
        self.stuck = 0
        self.last_xy: np.ndarray | None = None
        self.points: list[np.ndarray] = []
        self.dither = 0
        self.looking = False  # arrived at the viewpoint once: now observing
        self.n_classified = -1
        self.decision = None
        self.latched = 0.0  # a declaration, repeated until the env takes it (declare_hold)
        self.looks: list[float] | None = None
        self.episode = -1  # the env's episode counter when this driver was made
        self.expect: np.ndarray | None = None  # where the last action should take the robot
        self.last_move: np.ndarray | None = None
        self.bumps: list[shapely.Geometry] = []  # discs where the robot ran into the target

    # -- planning -----------------------------------------------------------------------
    def _keep_outs(self) -> list[shapely.Geometry | None]:
        """Areas to keep out of, most cautious first (Recognize; ``[None]`` otherwise): where
        the hidden target may stand, CH(A (+) G) and CH(A (+) H), less a hull the robot is in
        already (it cannot keep out of that one), then the exact A (+) G and A (+) H less one
        the robot is in, each with what the robot bumped into off the map; then the bumps
        alone; then nothing."""
        if self.env.spec_kind != "recognize":
            return [None]
        w = self.env.world
        x, y, _ = self.env.pose
        here = shapely.Point(x, y)
        bumped = shapely.union_all(self.bumps) if self.bumps else None
        out: list[shapely.Geometry | None] = []
        families = [_swept_hulls(w)] + ([_footprints(w)] if self.bumps else [])
        for family in families:
            parts = [g for g in family if not g.intersects(here)]
            if bumped is not None:
                parts.append(bumped)
            if parts:
                out.append(shapely.union_all(parts))
        if bumped is not None:
            out.append(bumped)
        out.append(None)
        return out

    def _replan(self) -> None:
        w = self.env.world
        x, y, _ = self.env.pose
        for keep_out in self._keep_outs():
            self.plan = plan_viewpoint(w, (x, y), keep_out=keep_out)
            self.looks = None
            if self.plan.status != "ok" and self.env.spec_kind == "recognize":
                # no single aim sees both: stand anywhere in the region, look at G, then at H
                self.plan = plan_viewpoint(w, (x, y), keep_out=keep_out, joint_aim=False)
                if self.plan.status == "ok":
                    p = self.plan.point
                    self.looks = [best_aim(p, k, w.fov, w.eps_aim)[0] for k in w.must_see]
                    self.plan.aim = self.looks[0]
            if self.plan.status == "ok":
                break
        self.waypoints = [] if self.plan.status != "ok" else [p for p in self.plan.path[1:]]

    def _bumped(self, pos: np.ndarray) -> None:
        """After a collision away from the map's walls and obstacles (Recognize: the hidden
        target), remember a small disc just ahead of the contact as an obstacle."""
        env = self.env
        if env.spec_kind != "recognize" or not env.collided or self.last_move is None:
            return
        w = env.world
        n = float(np.hypot(*self.last_move))
        gap = float(w.free_space.boundary.distance(shapely.Point(pos)))
        if n == 0 or gap <= 1e-3 * w.diameter + w.robot_radius:
            return  # a wall or an obstacle of the map: the plan already knows it
        r = 0.1 * w.target_radius
        c = pos + self.last_move * ((r + w.robot_radius + 1e-4 * w.diameter) / n)
        self.bumps.append(shapely.Point(c).buffer(r, quad_segs=4))

    # -- motion -------------------------------------------------------------------------
    def drive(self) -> np.ndarray:
        """Action ``(forward, lateral, turn)`` following the plan and turning to its aim."""
        env = self.env
        x, y, psi = env.pose
        pos = np.array([x, y])
        if self.plan is None:
            self._replan()
        elif self.expect is not None and (
            abs(pos[0] - self.expect[0]) + abs(pos[1] - self.expect[1]) > 1e-6 * env.world.diameter
        ):
            # not where the last action of the plan led: a collision, or another policy
            # drove (DAgger labels the states a learner visits): plan from here
            self._bumped(pos)
            self._replan()
            self.looking = False
            self.stuck = 0
        if (
            self.last_xy is not None
            and self.waypoints
            and np.allclose(pos, self.last_xy, atol=1e-12)
        ):
            self.stuck += 1
            if self.stuck >= 3:
                self._replan()
                self.stuck = 0
        self.last_xy = pos
        v = env.max_speed
        box = getattr(env, "speed_limit", "box") == "box"
        move = np.zeros(2)
        if self.waypoints:
            # the action square ("box" speed limit) allows sqrt(2) * v along the robot's
            # diagonals: go as far along the current leg as the limit permits (never past
            # its corner); a "disc" limit allows v in every direction
            d = self.waypoints[0] - pos
            dist = float(np.hypot(*d))
            rel = math.atan2(d[1], d[0]) - psi
            reach = v / max(abs(math.cos(rel)), abs(math.sin(rel)), 1e-12) if box else v
            if dist <= reach:
                move = d
                self.waypoints.pop(0)
            else:
                move = d * (reach / dist)
        aim = self.plan.aim if self.plan is not None and self.plan.status == "ok" else psi
        left = sum(
            float(np.hypot(*(b - a)))
            for a, b in zip([pos + move, *self.waypoints[:-1]], self.waypoints, strict=False)
        )
        if box and self.waypoints and left > math.sqrt(2) * v:
            # still travelling: turn so that the next leg runs along a diagonal
            nxt = self.waypoints[0] - (pos + move)
            travel = math.atan2(nxt[1], nxt[0])
            aim = min(
                (travel - math.pi / 4, travel + math.pi / 4), key=lambda a: abs(_wrap(a - psi))
            )
        self.expect = pos + move
        self.last_move = move
        c, s = math.cos(psi), math.sin(psi)
        fwd = (c * move[0] + s * move[1]) / v
        lat = (-s * move[0] + c * move[1]) / v
        turn = float(np.clip(_wrap(aim - psi) / env.max_turn, -1.0, 1.0))
        return np.array([fwd, lat, turn], dtype=np.float32)

    @property
    def arrived(self) -> bool:
        if self.plan is None or self.plan.status != "ok" or self.waypoints:
            return False
        x, y, psi = self.env.pose
        return abs(_wrap(self.plan.aim - psi)) < 1e-9

    # -- recognition --------------------------------------------------------------------
    def observe_target(self) -> None:
        env, w = self.env, self.env.world
        scan = env.scan
        if scan is None:
            return
        dist, _, hit, ang = scan
        x, y, _ = env.pose
        pts = np.stack([x + dist * np.cos(ang), y + dist * np.sin(ang)], axis=1)[hit]
        if len(pts) == 0:
            return
        tol = max(3.0 * env.sensor.noise, w.eps_pos, w.range_acc) + 1e-3 * w.diameter
        static = shapely.distance(shapely.points(pts), w.scene.free_space.boundary)
        self.points.extend(pts[static > tol])

    def decide(self, final: bool) -> float:
        """``decide`` component: -1 declares G, +1 declares H, 0 continues."""
        n = len(self.points)
        if (n < 3 or n == self.n_classified) and not final:
            return 0.0
        self.n_classified = n
        w = self.env.world
        pts = np.asarray(self.points) if self.points else np.empty((0, 2))
        tol = max(3.0 * self.env.sensor.noise, w.eps_pos, w.range_acc)
        if w.theta is None:  # orientation unknown: a coarser search over the circle
            tau = max(0.15 * w.target_radius, 2.5 * tol)
            res = tau / 2
        else:
            tau = max(0.05 * w.target_radius, 2.5 * tol)
            res = None
        dec = classify(
            pts,
            np.ones(len(pts), dtype=bool),
            w.scene,
            goal=w.goal_geom,
            failure=w.failure_geom,
            theta=w.theta,
            tau=tau,
            resolution=res,
        )
        self.decision = dec
        if dec.label == "G":
            return -1.0
        if dec.label == "H":
            return 1.0
        if final:  # last chance: the better-fitting hypothesis beats a certain timeout
            return -1.0 if dec.d_G <= dec.d_H else 1.0
        return 0.0


class _SubEnv:
    """Sub-environment ``i`` of a batched env (``SensorPlanVectorEnv``) seen through the
    attributes the oracle reads from a single env (``world``, ``pose``, ``scan``, ...)."""

    def __init__(self, batch, i: int) -> None:
        self.batch = batch
        self.i = int(i)
        self.spec = None
        self.max_turn = getattr(batch, "max_turn", None)  # Placement has no robot
        self.speed_limit = getattr(batch, "speed_limit", "box")
        self.max_steps = batch.max_steps

    @property
    def unwrapped(self) -> _SubEnv:
        return self

    @property
    def world(self):
        return self.batch.worlds[self.i]

    @property
    def pose(self) -> tuple[float, float, float] | None:
        return self.batch.pose(self.i) if self.batch.episodes[self.i] > 0 else None

    @property
    def scan(self):
        return self.batch.scan(self.i) if self.batch.episodes[self.i] > 0 else None

    @property
    def start(self) -> tuple[float, float, float]:
        return tuple(float(v) for v in self.batch.starts[self.i])

    @property
    def sensor(self):
        return self.batch.sensor(self.i)

    @property
    def max_speed(self) -> float:
        return float(self.batch.max_speed[self.i])

    @property
    def elapsed(self) -> int:
        return int(self.batch.elapsed[self.i])

    @property
    def collided(self) -> bool:
        return bool(self.batch.collided[self.i])


_KINDS = {"Placement": "placement", "Navigate": "navigate", "Recognize": "recognize"}


def _kind(batch) -> str:
    name = type(batch).__name__.replace("Batch", "")
    if name not in _KINDS:
        raise TypeError(f"OraclePolicy supports the sensorplan envs, got a {type(batch).__name__}")
    return _KINDS[name]


class OraclePolicy:
    """Privileged planner with an SB3-style ``predict``.

    Parameters
    ----------
    env : a Gymnasium env of this package (wrappers are looked through), an SB3
        ``DummyVecEnv`` of them, a native vector env (``gym.make_vec``,
        :class:`sensorplan_gym.envs.vector.SensorPlanVectorEnv`) or the SB3
        :class:`agents.learning.vecenv.BatchedVecEnv` over one.  ``SubprocVecEnv`` cannot be
        read from and is rejected.

    The policy tells a new episode from the next step of the current one by itself: each
    sub-environment counts the episodes it started (``batch.episodes``), so ``predict`` in a
    plain loop (no ``episode_start``) never carries a plan into the next episode.
    """

    def __init__(self, env) -> None:
        envs = getattr(env, "envs", None)
        if envs is None and hasattr(env, "remotes"):
            raise TypeError(
                "OraclePolicy needs in-process envs: use DummyVecEnv, not SubprocVecEnv"
            )
        vec = env
        while envs is None and not hasattr(vec, "batch") and hasattr(vec, "venv"):
            vec = vec.venv  # SB3 wrappers (VecMonitor, ...), agents.learning.vecenv.BatchedVecEnv
        vec = getattr(vec, "unwrapped", vec)
        if envs is None and hasattr(vec, "batch") and hasattr(vec, "num_envs"):
            batch = vec.batch  # a native vector env: one view per sub-environment
            self.vectorized = True
            self.envs = [_SubEnv(batch, i) for i in range(batch.n)]
        else:
            self.vectorized = envs is not None
            self.envs = [e.unwrapped for e in (envs if envs is not None else [env])]
        for e in self.envs:
            batch = getattr(e, "batch", None)
            if batch is None:
                raise TypeError(
                    f"OraclePolicy supports the sensorplan envs, got {type(e).__name__}"
                )
            e.spec_kind = _kind(batch)
            if getattr(batch, "action_type", "continuous") != "continuous":
                raise TypeError(
                    "OraclePolicy acts in the continuous action space; make the env with "
                    "action_type='continuous' (the default)"
                )
        self.drivers = [_Driver(e) for e in self.envs]

    @staticmethod
    def _episode(env) -> int:
        """The number of episodes ``env`` (a single env or a :class:`_SubEnv`) has started."""
        i = env.i if isinstance(env, _SubEnv) else 0
        return int(env.batch.episodes[i])

    def reset(self) -> None:
        """Forget all episode state (not needed between episodes: ``predict`` notices them)."""
        self.drivers = [_Driver(e) for e in self.envs]

    def predict(
        self,
        observation: Any,
        state: Any = None,
        episode_start: Any = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, Any]:
        """Actions for the current state of the bound env(s); ``(actions, state)`` as in SB3.

        ``observation`` is not read (the oracle reads the env); ``episode_start`` may be
        given, as SB3 does, but is not needed.  Raises ``RuntimeError`` when an env has not
        been reset yet."""
        starts = (
            np.zeros(len(self.envs), dtype=bool)
            if episode_start is None
            else np.atleast_1d(np.asarray(episode_start, dtype=bool))
        )
        actions = []
        for i, env in enumerate(self.envs):
            ep = self._episode(env)
            if ep == 0:
                raise RuntimeError(
                    f"OraclePolicy.predict: sub-environment {i} has not been reset; "
                    "call env.reset() first"
                )
            drv = self.drivers[i]
            new = bool(starts[i]) if i < len(starts) else False
            if new or drv.episode != ep:
                drv = self.drivers[i] = _Driver(env)
                drv.episode = ep
            actions.append(self._act(env, drv))
            drv.steps += 1
        out = np.stack(actions)
        return (out if self.vectorized else out[0]), state

    # -- per env --------------------------------------------------------------------------
    def _act(self, env, drv: _Driver) -> np.ndarray:
        if env.spec_kind == "placement":
            return self._place(env)
        if drv.plan is None:
            drv._replan()
        a = drv.drive()
        if env.spec_kind == "navigate":
            return a
        # Recognize: look once there, sweep the fan of beams, then decide
        decide = 0.0
        horizon = env.max_steps or (env.spec.max_episode_steps if env.spec else None) or 200
        final = env.elapsed >= horizon - 1
        drv.looking = drv.looking or drv.arrived
        if drv.latched:
            decide = drv.latched
        elif drv.looking or final or drv.plan.status != "ok":
            drv.observe_target()
            decide = drv.decide(final)
            drv.latched = decide
            if decide == 0.0 and drv.looking:
                # re-aim: sweep the gaps between beams around the planned aim (or around
                # the aims at G and at H in turn when no single aim sees both): a triangle
                # wave over one beam spacing, with a step incommensurate with it so that
                # later passes fall between earlier ones, and never faster than a turn
                spacing = (
                    2 * math.pi if env.sensor.fov >= 2 * math.pi - 1e-12 else env.sensor.fov
                ) / max(env.sensor.n_beams, 1)
                drv.dither += 1
                looks = drv.looks or [drv.plan.aim]
                base = looks[(drv.dither // 16) % len(looks)]
                step = min(0.1459 * spacing, 0.9 * env.max_turn)
                phase = (drv.dither * step / spacing) % 2.0
                offset = spacing * ((phase if phase <= 1.0 else 2.0 - phase) - 0.5)
                a[2] = np.clip(_wrap(base + offset - env.pose[2]) / env.max_turn, -1, 1)
        return np.array([a[0], a[1], a[2], decide], dtype=np.float32)

    def _place(self, env) -> np.ndarray:
        w = env.world
        region = w.region
        if region.is_empty:
            return np.zeros(3, dtype=np.float32)
        feasible = _aim_feasible_region(w, region)
        if feasible.is_empty:
            feasible = region
        # the most robust placement: the pole of inaccessibility of the largest part
        parts = shapely.get_parts(feasible)
        big = parts[np.argmax(shapely.area(parts))]
        p = np.asarray(
            shapely.maximum_inscribed_circle(big, 1e-4 * w.diameter).boundary.geoms[0].coords[0]
        )
        psi, _ = _aim_for(w, p)
        lo, hi = w.lo, w.hi
        xy = 2 * (p - lo) / (hi - lo) - 1
        return np.array([xy[0], xy[1], _wrap(psi) / math.pi], dtype=np.float32)
