"""Base classes of the sensor-planning environments.

Each task (Placement, Navigate, Recognize) is written once, as a *batch* class
(:class:`SensorPlanBatch`, a :class:`~sensorplan_gym.core.sim.BatchSim`) whose ``reset_envs``
and ``step_envs`` advance any subset of N sub-environments with array operations.  The
Gymnasium single env :class:`SensorPlanEnv` is the batch of one; the native vector env
(:mod:`sensorplan_gym.envs.vector`) is the batch of N.  There is no second implementation:
with numba (the ``fast`` extra) a step of Navigate or Recognize is one compiled call over
the stepping rows (:mod:`sensorplan_gym.core.fused`) and the single env makes that call with
one row; without numba the numpy path of the same batch classes runs, with bitwise the same
answers (``tests/test_fused.py`` compares whole episodes).

Common keyword arguments (``gym.make(id, **kwargs)`` and ``gym.make_vec(id, **kwargs)``)
----------------------------------------------------------------------------------------
scene : str | path | dict | geometry.Scene, default ``"lab"``
    A bundled scene name (``lab``, ``edr``, ``corridor``, ``warehouse``), a path to a scene
    file (scene JSON in the pinned format, GeoJSON or WKT: see
    :func:`sensorplan_gym.core.scenes.load_scene`), a dict, a ``geometry.Scene``, or
    ``"random"``: at every reset a scene drawn (with the env's ``np_random``) from a
    seeded pool of procedural scenes
    (:class:`~sensorplan_gym.core.pool.ScenePool`; scenes whose region is empty, unreachable
    from the start, or that contain the start are re-drawn when the pool is built).
scene_pool_size : int, default 64 -- scenes in the ``"random"`` pool.
scene_pool_seed : int, default 0 -- the pool's seed (disjoint seeds: disjoint splits).
scene_pool_jobs : int | None, default None -- ``None``: pool scenes are built on first use;
    an integer ``k``: the whole pool is built at construction in ``k`` processes
    (:meth:`~sensorplan_gym.core.pool.ScenePool.build`; the same scenes either way).
scene_pool_cache : bool | path | None, default None -- where pool regions are cached on disk
    (:mod:`sensorplan_gym.core.diskcache`): ``None`` the default folder
    (``$XDG_CACHE_HOME/sensorplan-gym``; ``SENSORPLAN_GYM_CACHE=off`` switches it off),
    ``False`` no disk cache, a path that folder.
min_start_distance : float | None, default None (0, or the ``difficulty``'s) -- a difficulty
    knob for ``scene="random"``: pool scenes whose start lies closer than this fraction of the
    scene diameter to the recognizable region are re-drawn (Navigate, Recognize); with
    ``random_start=True`` every drawn start keeps this distance too (any scene; the scene's
    start when none is found).
family : str | geometry.families.SceneFamily | None -- with ``scene="random"``, draw the pool
    from this scene family (``"easy"``, ``"medium"``, ``"hard"`` or a ``SceneFamily``) instead
    of :func:`geometry.generate.random_scene` (the default, unchanged).
difficulty : ``"easy"`` | ``"medium"`` | ``"hard"`` | None -- with ``scene="random"``, a
    benchmark level (:data:`geometry.families.DIFFICULTIES`): its family and its
    ``min_start_distance`` (an explicit ``min_start_distance`` wins).
model : ``"complete"`` | ``"partial"`` -- the visibility model of the recognizable region.
motion : ``"stationary"`` | ``"translating"`` | ``"rotating"`` (see
    :mod:`sensorplan_gym.core.world`).  Unsupported combinations raise
    ``NotImplementedError`` at construction.
eps_pos : float | None -- placement uncertainty (scene units); ``None``: the scene's.
eps_aim : float | None -- aim uncertainty in **radians**; ``None``: the scene's.
fov_deg : float | None -- field of view in degrees; ``None``: the scene's.
max_range : float | None -- sensor range; ``None``: the scene's; ``math.inf``: unlimited.
n_beams : int, default 16 -- beams in the sensor's fan (and in Placement's scans).
noise : float, default 0 -- std of Gaussian range noise (scene units), truncated at 3 std:
    the recognizable region is computed for a sensor accurate to ``max(3 noise, the scene's
    sensor.range_acc)`` (paper section 2), so confusability allows for the noise.
obs_type : ``"vector"`` (default) | ``"grid"`` (see :mod:`sensorplan_gym.core.observations`).
grid_size : int, default 64 -- side of the grid observation.
robot_radius : float, default 0 -- the robot is a disc of this radius (0: a point).
action_type : ``"continuous"`` (default) | ``"discrete"`` | ``"pixel"`` (Placement: one
    action per pixel of the grid observation and aim; see :mod:`sensorplan_gym.core.actions`).
map_ranges : bool, default False -- Navigate/Recognize vector observations also carry, per
    beam, the range the static map predicts from the commanded pose (see
    :mod:`sensorplan_gym.core.observations`): a reading that differs reveals the target.
map_evidence : bool, default False -- per beam, whether it read shorter than the map predicts
    and ended in the hull of the target swept over G, resp. H (the readings interpreted with
    the map; vector observations of Navigate/Recognize).
sensor_fov : bool, default False -- Navigate/Recognize vector observations end with the
    sensor's field of view / 360 degrees (for scenes whose field of view varies).
self_features : bool, default False -- vector observations (Navigate, Recognize, Placement)
    end with what the robot knows of its own sensor: field of view / 360 degrees and reach
    (maximum range, at most the diameter) / scene diameter (for scene families whose sensors
    differ); Placement's grid observation gets them as two constant channels.
grid_views : bool, default False -- Placement's grid observation gets two more channels, the
    free space seen from G's and from H's anchor point (the raster twin of the vector
    observation's two scans).
hull_views : bool, default False -- Placement's grid observation gets two more channels, the
    free space seen from every corner of K_G and of K_H (the hulls of the target swept over G
    and H that the sensor must see): where all of a hull's corners are in view.
aim_views : bool, default False -- Placement's grid observation gets ``placement_aims`` more
    channels, one per aim of the Placement actions: where that aim from the pixel's centre keeps
    K_G and K_H in the field of view (with the aim and position margins) and within range, the
    angular half of the reward's test (occlusion is the other).
view_hint : bool, default False -- Navigate/Recognize vector observations end with the way
    to the nearest pose that sees every corner of K_G and K_H with a passing aim (map geometry,
    not the recognizable region): the first step of the shortest grid path there in the robot's
    frame and its length / diameter (:func:`sensorplan_gym.core.observations.view_hint`).
hint_aim : bool, default True -- with ``view_hint``: its target poses admit one aim that passes
    the aim test (both hulls in view at once); ``False`` (Recognize-v0 only, which may look at
    G, then at H): every corner of both hulls seen, and within range, with no joint aim asked.
aim_features : bool, default False -- Navigate/Recognize vector observations end with the
    arcs of directions that K_G and K_H (the swept hulls) cover from the robot's pose, relative
    to its heading, and their farthest vertex's distance over the reach (see
    :mod:`sensorplan_gym.core.observations`): map geometry an aim must satisfy.
max_steps : int | None -- the time limit (default 200; Placement: 1).
random_scene_kwargs : dict | None -- passed to ``random_scene`` when ``scene="random"``.
render_mode : ``None`` | ``"rgb_array"`` | ``"human"``.

Uncertainty in the simulation
-----------------------------
The robot's own pose evolves exactly.  Every sensor reading is taken from the *executed*
sensor pose: the commanded pose displaced uniformly within the ``eps_pos`` disc (the
displacement is cut short at walls and obstacles) and turned uniformly within
``+- eps_aim``.  Recognizability is judged at the commanded pose against the region
computed *with* those uncertainties (paper section 4), so a recognizing pose is
recognizing for every executed pose.
"""

from __future__ import annotations

import functools
import math
import os
from typing import Any

import gymnasium as gym
import numpy as np
import shapely

from geometry.families import SceneFamily, get_difficulty, get_family

from ..core import fused
from ..core.actions import make_actions
from ..core.cache import get_world
from ..core.observations import make_observation
from ..core.pool import FixedScene, check_jobs, shared_pool
from ..core.queries import aim_ok_batch
from ..core.rendering import HumanViewer, Renderer
from ..core.sensor import NOISE_BOUND, RangeSensor
from ..core.sim import BatchSim
from ..core.world import World, WorldConfig, load_scene

__all__ = ["SPEED_LIMITS", "RobotBatch", "SensorPlanBatch", "SensorPlanEnv"]

Start = tuple[float, float, float]
SPEED_LIMITS = ("box", "disc")  # RobotBatch's ``speed_limit``


def _start_pose(world: World, rng: np.random.Generator, needs_start: bool) -> Start:
    s = world.scene.start
    if s is not None and world.in_free_space(s[0], s[1]):
        return (float(s[0]), float(s[1]), float(s[2]))
    if not needs_start:
        return (float(world.goal_center[0]), float(world.goal_center[1]), 0.0)
    # sample a free start that does not recognize
    for _ in range(2000):
        x = rng.uniform(world.lo[0], world.hi[0])
        y = rng.uniform(world.lo[1], world.hi[1])
        if world.in_free_space(x, y) and not world.in_region(x, y):
            return (float(x), float(y), float(rng.uniform(-math.pi, math.pi)))
    raise ValueError(f"scene {world.scene.name!r}: found no free start outside the region")


def _scene_problem(world: World, start: Start, needs_start: bool) -> str | None:
    """Why this world cannot host an episode (``None`` if it can)."""
    if world.region.is_empty:
        return "the recognizable region is empty under this configuration"
    if not needs_start:
        return None
    if world.reachable_region(start[:2]).is_empty:
        return "the recognizable region is not reachable from the start"
    if world.recognizing(*start):
        return "the start pose already recognizes G vs H"
    return None


def _sampled_start(world: World, rng: np.random.Generator, tries: int = 10_000) -> Start | None:
    """A start drawn from ``rng``: a uniform free position outside the recognizable region in
    a free-space component that meets the region (so the region is reachable), with a uniform
    heading; ``None`` when ``tries`` draws find none."""
    comps = shapely.get_parts(world.robot_space)
    space = shapely.union_all(comps[shapely.intersects(comps, world.region)])
    if space.is_empty:
        return None
    shapely.prepare(space)
    for _ in range(tries):
        x = float(rng.uniform(world.lo[0], world.hi[0]))
        y = float(rng.uniform(world.lo[1], world.hi[1]))
        if shapely.contains_xy(space, x, y) and not world.in_region(x, y):
            return (x, y, float(rng.uniform(-math.pi, math.pi)))
    return None


def _has_view(
    world: World, space: shapely.Geometry, rng: np.random.Generator, n: int = 256
) -> bool:
    """Whether a pose with its position in ``space`` (a part of the recognizable region) keeps
    K_G and K_H in the field of view and within range (:meth:`World.aim_ok`), found among
    ``n`` positions drawn from ``rng`` in ``space`` and seven aims each (the one between the
    directions to K_G and K_H, and that one turned by +-0.1, 0.2, 0.3 field of view).
    ``True`` without drawing for a 360-degree sensor of unlimited range.  A sampled test:
    ``False`` may miss a thin set of such poses (the scene is then re-drawn)."""
    if world.fov >= 2 * math.pi - 1e-12 and math.isinf(world.max_range):
        return True
    if space.is_empty:
        return False
    x0, y0, x1, y1 = space.bounds
    pts = rng.uniform((x0, y0), (x1, y1), (8 * n, 2))
    pts = pts[shapely.contains_xy(space, pts[:, 0], pts[:, 1])][:n]
    if len(pts) == 0:
        return False
    r = world.batch_rows()
    c = r["centers"]
    a = np.arctan2(c[0, 1] - pts[:, 1], c[0, 0] - pts[:, 0])
    b = np.arctan2(c[1, 1] - pts[:, 1], c[1, 0] - pts[:, 0])
    mid = a + 0.5 * ((b - a + math.pi) % (2 * math.pi) - math.pi)
    turns = world.fov * np.array([0.0, -0.1, 0.1, -0.2, 0.2, -0.3, 0.3])
    psi = (mid[:, None] + turns[None, :]).ravel()
    xs, ys = np.repeat(pts[:, 0], len(turns)), np.repeat(pts[:, 1], len(turns))
    m = len(psi)
    ok = aim_ok_batch(
        xs,
        ys,
        psi,
        np.broadcast_to(r["hulls"][None], (m, *r["hulls"].shape)),
        np.broadcast_to(c[None], (m, *c.shape)),
        fov=world.fov,
        eps_aim=world.eps_aim,
        eps_pos=world.eps_pos,
        max_range=world.max_range,
    )
    return bool(ok.any())


def _check_pose(
    world: World,
    rng: np.random.Generator,
    needs_start: bool,
    min_start_distance: float = 0.0,
    fallback_start: bool = False,
):
    """``(start, problem)`` of a world: its start pose and why it cannot host an episode
    (``None`` if it can).  With ``min_start_distance`` > 0 the start is drawn uniformly among
    the free positions at least that fraction of the diameter away from the region.  With
    ``fallback_start`` (a fixed scene), a scene start that already recognizes or cannot reach
    the region is replaced by a start drawn from ``rng`` (:func:`_sampled_start`); only when
    none exists is the problem returned.  A scene whose own start is fine keeps it."""
    if needs_start and min_start_distance > 0:
        thr = min_start_distance * world.diameter
        for _ in range(500):
            x = float(rng.uniform(world.lo[0], world.hi[0]))
            y = float(rng.uniform(world.lo[1], world.hi[1]))
            if world.in_free_space(x, y) and world.distance_to_region(x, y) >= thr:
                start = (x, y, float(rng.uniform(-math.pi, math.pi)))
                return start, _scene_problem(world, start, needs_start)
        return None, f"no free start {min_start_distance} diameters from the region"
    try:
        start = _start_pose(world, rng, needs_start)
    except ValueError as e:
        return None, str(e)
    problem = _scene_problem(world, start, needs_start)
    if problem and fallback_start and needs_start and not world.region.is_empty:
        alt = _sampled_start(world, rng)
        if alt is not None and _scene_problem(world, alt, needs_start) is None:
            return alt, None
        problem += " (and no free start outside the region can reach it)"
    return start, problem


def _check(
    world: World,
    rng: np.random.Generator,
    needs_start: bool,
    min_start_distance: float = 0.0,
    fallback_start: bool = False,
    needs_view: bool = False,
):
    """``(start, problem)`` of a world (see :func:`_check_pose`).  With ``needs_view``
    (scene-family pools of tasks whose success is one recognizing pose), a world where no
    sampled pose of the (reachable) region keeps G and H in view is a problem too
    (:func:`_has_view`)."""
    start, problem = _check_pose(world, rng, needs_start, min_start_distance, fallback_start)
    if problem is None and needs_view:
        space = world.reachable_region(start[:2]) if needs_start else world.region
        if not _has_view(world, space, rng):
            problem = "no sampled pose of the region keeps G and H in the field of view and range"
    return start, problem


def _resolve_family(
    random: bool,
    family: str | SceneFamily | None,
    difficulty: str | None,
    min_start_distance: float | None,
    random_scene_kwargs: dict | None,
) -> tuple[SceneFamily | None, float | None]:
    """``(scene family or None, min_start_distance)`` from the envs' ``family`` /
    ``difficulty`` / ``min_start_distance`` kwargs (an explicit ``min_start_distance`` wins
    over the difficulty's; ``None`` stays ``None`` without a difficulty)."""
    if family is None and difficulty is None:
        return None, min_start_distance
    if not random:
        raise ValueError("family= and difficulty= need scene='random'")
    if random_scene_kwargs:
        raise ValueError("give random_scene_kwargs or family=/difficulty=, not both")
    if difficulty is not None:
        level = get_difficulty(difficulty)
        if family is not None and get_family(family) != level.family:
            raise ValueError(
                f"difficulty={difficulty!r} has its own family ({level.family.name!r}); "
                f"drop family={family!r} or the difficulty"
            )
        if min_start_distance is None:
            min_start_distance = level.min_start_distance
        return level.family, min_start_distance
    return get_family(family), min_start_distance


class SensorPlanBatch(BatchSim):
    """A task over N sub-environments; subclasses define ``obs_kind``, ``action_dim`` and the
    hooks ``_reset_one`` (Python, per resetting sub-environment: draws from its generator),
    ``_after_reset`` and ``step_envs`` (arrays over the stepping sub-environments)."""

    obs_kind = "robot"
    needs_start = True
    action_dim = 3
    action_task = "robot"
    horizon = 200
    #: success is one pose that keeps G and H in view (family pools re-draw scenes without one)
    joint_view = True

    def __init__(
        self,
        n: int,
        scene: str | Any = "lab",
        *,
        model: str = "complete",
        motion: str = "translating",
        eps_pos: float | None = None,
        eps_aim: float | None = None,
        fov_deg: float | None = None,
        max_range: float | None = None,
        n_beams: int = 16,
        noise: float = 0.0,
        obs_type: str = "vector",
        grid_size: int = 64,
        robot_radius: float = 0.0,
        random_scene_kwargs: dict | None = None,
        max_scene_tries: int = 25,
        min_start_distance: float | None = None,
        family: str | SceneFamily | None = None,
        difficulty: str | None = None,
        scene_pool_size: int = 64,
        scene_pool_seed: int = 0,
        scene_pool_jobs: int | None = None,
        scene_pool_cache: bool | str | os.PathLike[str] | None = None,
        max_steps: int | None = None,
        action_type: str = "continuous",
        map_ranges: bool = False,
        map_evidence: bool = False,
        sensor_fov: bool = False,
        self_features: bool = False,
        aim_features: bool = False,
        grid_views: bool = False,
        hull_views: bool = False,
        aim_views: bool = False,
        view_hint: bool = False,
        hint_aim: bool = True,
        **action_kw: Any,
    ) -> None:
        for name, v in (
            ("eps_pos", eps_pos),
            ("eps_aim", eps_aim),
            ("fov_deg", fov_deg),
            ("max_range", max_range),
        ):
            if v is not None and not isinstance(v, (int, float)):
                raise ValueError(f"{name} must be a number or None, got {v!r}")
        if not isinstance(noise, (int, float)) or not math.isfinite(noise) or noise < 0:
            raise ValueError(f"noise must be a finite non-negative number, got {noise!r}")
        if not isinstance(n_beams, (int, np.integer)) or n_beams < 1:
            raise ValueError(f"n_beams must be a positive integer, got {n_beams!r}")
        if max_steps is not None and (not isinstance(max_steps, int) or max_steps < 1):
            raise ValueError(f"max_steps must be a positive integer or None, got {max_steps!r}")
        self.max_steps = int(max_steps) if max_steps is not None else self.horizon
        self.cfg = WorldConfig(
            model=model,
            motion=motion,
            eps_pos=None if eps_pos is None else float(eps_pos),
            eps_aim=None if eps_aim is None else float(eps_aim),
            fov=None if fov_deg is None else math.radians(float(fov_deg)),
            max_range=None if max_range is None else float(max_range),
            robot_radius=float(robot_radius),
            range_acc=NOISE_BOUND * float(noise) if noise > 0 else None,
        ).validate()
        super().__init__(n, n_beams, noise, robot_radius)
        unknown = set(action_kw) - {"placement_grid", "placement_aims"}
        if unknown or (action_kw and self.action_task != "placement"):
            bad = sorted(action_kw if not unknown else unknown)
            raise TypeError(f"{self.task_name}: unexpected keyword argument(s) {bad}")
        for name, v in (
            ("map_ranges", map_ranges),
            ("map_evidence", map_evidence),
            ("sensor_fov", sensor_fov),
            ("self_features", self_features),
            ("aim_features", aim_features),
            ("grid_views", grid_views),
            ("hull_views", hull_views),
            ("aim_views", aim_views),
            ("view_hint", view_hint),
        ):
            if not isinstance(v, bool):
                raise ValueError(f"{name} must be True or False, got {v!r}")
            placement = self.obs_kind == "placement"
            raster = name in ("grid_views", "hull_views", "aim_views")  # Placement's grid
            if (
                not v
                or raster
                and placement
                and obs_type == "grid"
                or not raster
                and obs_type == "vector"
                and (not placement or name == "self_features")
                or name == "self_features"
                and placement
            ):
                continue
            raise ValueError(
                f"{name}=True needs obs_type='grid' in Placement"
                if raster
                else f"{name}=True needs obs_type='vector' in Navigate or Recognize"
                + (" (or Placement)" if name == "self_features" else "")
            )
        if not isinstance(hint_aim, bool):
            raise ValueError(f"hint_aim must be True or False, got {hint_aim!r}")
        if not hint_aim and (not view_hint or self.joint_view):
            raise ValueError(
                "hint_aim=False needs view_hint=True"
                if not view_hint
                else f"hint_aim=False: {self.task_name} needs one aim at both hulls (its "
                "success is a joint view); Recognize-v0 may look at G, then at H"
            )
        self.map_ranges = map_ranges or map_evidence  # the sim computes the map's ranges
        self.params[fused.P_MAP] = self.map_ranges
        self.params[fused.P_OBS_MAP] = map_ranges
        self.params[fused.P_MAX_STEPS] = self.max_steps
        self.obs_type = obs_type
        self.obs = make_observation(
            self.obs_kind,
            obs_type,
            self.n_beams,
            grid_size,
            map_ranges=map_ranges,
            map_evidence=map_evidence,
            sensor_fov=sensor_fov,
            self_features=self_features,
            aim_features=aim_features,
            grid_views=grid_views,
            hull_views=hull_views,
            aim_views=int(action_kw.get("placement_aims", 8)) if aim_views else 0,
            view_hint=view_hint,
            hint_aim=hint_aim,
        )
        self.single_observation_space = self.obs.space
        self.actions = make_actions(
            action_type, self.action_task, self.action_dim, grid_size=grid_size, **action_kw
        )
        self.action_type = action_type
        self.single_action_space = self.actions.space
        # episodes started per sub-environment: a planner bound to the env tells a new
        # episode from the next step of the current one by it (agents.planning.oracle)
        self.episodes = np.zeros(self.n, dtype=np.int64)
        self.random = isinstance(scene, str) and scene == "random"
        family, min_start_distance = _resolve_family(
            self.random, family, difficulty, min_start_distance, random_scene_kwargs
        )
        if min_start_distance is None:
            min_start_distance = 0.0
        if not isinstance(min_start_distance, (int, float)) or not 0 <= min_start_distance < 1:
            raise ValueError(f"min_start_distance must be in [0, 1), got {min_start_distance!r}")
        self.min_start_distance = float(min_start_distance)
        if not self.random and (scene_pool_jobs is not None or scene_pool_cache is not None):
            raise ValueError("scene_pool_jobs= and scene_pool_cache= need scene='random'")
        check = functools.partial(_check, needs_start=self.needs_start)
        if self.random:
            view = family is not None and self.joint_view
            check = functools.partial(
                check, min_start_distance=self.min_start_distance, needs_view=view
            )
            self.source = shared_pool(
                self.cfg,
                check,
                (f"start>={self.min_start_distance}" if self.needs_start else "nostart")
                + ("+view" if view else ""),
                size=scene_pool_size,
                seed=scene_pool_seed,
                scene_kwargs=dict(random_scene_kwargs or {}),
                max_tries=max_scene_tries,
                family=family,
                disk_cache=scene_pool_cache,
            )
            if scene_pool_jobs is not None:
                check_jobs(scene_pool_jobs)
            world, start = self.source.get(0)  # unsupported configurations fail here
            if scene_pool_jobs is not None:
                self.source.build(jobs=scene_pool_jobs)
        else:
            sc = load_scene(scene)
            world = get_world(sc, self.cfg)
            start, problem = check(world, np.random.default_rng(0), fallback_start=True)
            if problem:
                raise ValueError(f"scene {sc.name!r} unusable for {self.task_name}: {problem}")
            self.source = FixedScene(world, start)
        self.starts = np.tile(np.asarray(start, dtype=np.float64), (self.n, 1))
        for i in range(self.n):
            self.load_world(i, world)

    @property
    def task_name(self) -> str:
        return type(self).__name__.replace("Batch", "Env")

    def sensor(self, i: int = 0) -> RangeSensor:
        """The range sensor of sub-environment ``i`` (beams, field of view, reach, noise)."""
        return RangeSensor(self.n_beams, float(self.fov[i]), float(self.reach[i]), self.noise)

    # ---- episodes ---------------------------------------------------------------------
    def reset_envs(self, idx: np.ndarray, options: dict | None = None) -> None:
        """Start new episodes in sub-environments ``idx``."""
        options = options or {}
        src = self.source
        if not (
            isinstance(src, FixedScene) and self._one_world and self.worlds[0] is src.world
        ):  # a fixed scene is loaded in every row already, and its start never changes
            drawn = [src.draw(self.rngs[i]) for i in idx.tolist()]
            self.load_worlds(idx, [w for w, _ in drawn])
            self.starts[idx] = [s for _, s in drawn]
        self.elapsed[idx] = 0
        self.episodes[idx] += 1
        self._reset_rows(idx, options)
        self._after_reset(idx)

    def _reset_rows(self, idx: np.ndarray, options: dict) -> None:
        """The task's own reset of rows ``idx`` (their worlds loaded); by default
        :meth:`_reset_one` row by row."""
        for i in idx.tolist():
            self._reset_one(i, options)

    def _reset_one(self, i: int, options: dict) -> None:  # pragma: no cover - abstract
        raise NotImplementedError

    def _after_reset(self, idx: np.ndarray) -> None:
        pass

    def step_envs(self, act: np.ndarray, idx: np.ndarray) -> tuple[np.ndarray, ...]:
        """Advance sub-environments ``idx`` by the (checked) actions ``act`` ``(k, d)``.
        Returns ``(reward, terminated, truncated, info)``: ``(k,)`` arrays and a dict of
        info columns ``name -> (values (k, ...), mask (k,) or None)``."""
        raise NotImplementedError  # pragma: no cover - abstract

    def observe(self, idx: np.ndarray) -> np.ndarray:
        """Observations ``(k, *single_observation_space.shape)`` of sub-environments ``idx``."""
        return self.obs(self, idx)

    def reset_info(self, idx: np.ndarray) -> dict[str, tuple[np.ndarray, np.ndarray | None]]:
        """Info columns at reset."""
        raise NotImplementedError  # pragma: no cover - abstract

    def render_state(self, i: int) -> dict[str, Any]:
        """What the renderer draws for sub-environment ``i``."""
        has = bool(self.has_scan[i])
        pose = self.pose(i) if self._has_pose(i) else None
        rec = False
        if pose is not None:
            rec = bool(self.query(np.array([i]))[0][0])
        return {
            "pose": pose,
            "sensor_pose": self.sensor_pose(i) if has else pose,
            "scan": self.scan(i),
            "recognizing": rec,
            "title": f"{self.task_name}: {self.worlds[i].scene.name}",
        }

    def _has_pose(self, i: int) -> bool:
        return True


class RobotBatch(SensorPlanBatch):
    """A mobile sensor: a disc (or point) robot that drives and turns, with collisions.

    Action ``Box(-1, 1, (k,), float32)`` whose first three components are ``forward``,
    ``lateral`` (to the left) and ``turn`` (counter-clockwise).  The robot first translates by
    ``max_speed * (forward, lateral)`` in its current heading's frame, then turns by
    ``max_turn * turn``.  The translation is swept against walls, obstacles (and the hidden
    target in Recognize): on contact the robot stops there (it never passes through), and
    ``info["collided"]`` is True.  Out-of-range components are clipped to [-1, 1].

    ``speed_limit`` says how fast the robot may translate: ``"box"`` (the v0 default) limits
    ``forward`` and ``lateral`` separately, so a diagonal action moves ``sqrt(2) * max_speed``;
    ``"disc"`` limits the translation's length to ``max_speed`` in every direction (an action
    whose ``(forward, lateral)`` has norm above 1 is scaled to norm 1), so that the fewest
    steps are also the shortest path.

    ``random_start=True`` draws every episode's start pose from the env's ``np_random``: a
    uniform free position that does not recognize yet, in a part of the free space from
    which the recognizable region is reachable, with a uniform heading (default: the
    scene's ``start``, like TOMMY's fixed start in the paper).
    """

    def __init__(
        self,
        n: int,
        scene="lab",
        *,
        max_speed: float | None = None,
        max_turn: float = math.pi / 8,
        random_start: bool = False,
        speed_limit: str = "box",
        **kwargs,
    ) -> None:
        if not isinstance(random_start, bool):
            raise ValueError(f"random_start must be True or False, got {random_start!r}")
        if speed_limit not in SPEED_LIMITS:
            raise ValueError(f"speed_limit must be one of {SPEED_LIMITS}, got {speed_limit!r}")
        self.speed_limit = speed_limit
        for name, v in (("max_speed", max_speed), ("max_turn", max_turn)):
            if v is not None and (
                not isinstance(v, (int, float)) or not math.isfinite(v) or v <= 0
            ):
                raise ValueError(f"{name} must be a positive number, got {v!r}")
        self.random_start = random_start
        self._max_speed_cfg = None if max_speed is None else float(max_speed)
        self.max_turn = float(max_turn)
        self.collided = np.zeros(n, dtype=bool)
        self.dist = np.zeros(n)  # distance to the region at the last step (shaping)
        self.shaping = getattr(self, "shaping", 0.0)
        super().__init__(n, scene, **kwargs)
        self.params[fused.P_MAX_TURN] = self.max_turn
        self.params[fused.P_DISC] = speed_limit == "disc"
        self.params[fused.P_SHAPING] = self.shaping
        self.params[fused.P_STEP_COST] = getattr(self, "step_cost", 0.0)

    @property
    def compiled_step(self) -> bool:
        """Whether :meth:`step_envs` runs the fused compiled kernel (numba installed, a
        point robot); else the numpy path (bitwise the same answers)."""
        return self.fused and self.robot_radius == 0.0

    def _step_compiled(self, act: np.ndarray, idx: np.ndarray, task: int):
        """:func:`.fused.robot_step` of rows ``idx``: ``(reward (k,), flags (5, k), dist
        (k,))`` with flags terminated, truncated, recognizing, in region, aim ok."""
        if self._empty:
            self._refill(idx)
        args = self._kargs
        if args is None:
            args = self._kargs = self._step_args()
        if act.dtype != np.float64 or not act.flags.c_contiguous:
            act = np.ascontiguousarray(act, dtype=np.float64)
        if fused.robot_step(task, idx, act, *args):
            self._note_used(idx)
        b = self._kbuf
        k = len(idx)
        return b.reward[:k].copy(), b.flags[:, :k].copy(), b.dist[:k].copy()

    def _step_args(self) -> tuple:
        """The arrays :func:`.fused.robot_step` reads and writes (after ``task, idx, act``);
        rebuilt when a world or the segments change (arrays may be reallocated)."""
        b = self._kbuf
        return (
            self.params,
            self.P,
            self.C,
            self.stochastic,
            self.aim_trivial,
            self.OFF,
            self.segs.data,
            self.static_segs.data,
            self.region_xy,
            self.region_segs.data,
            self.hulls,
            self.centers,
            self._U,
            self._Z,
            self._ptr,
            self.scan_dist,
            self.scan_normal,
            self.scan_hit,
            self.scan_ang,
            self.map_dist,
            self.has_scan,
            self.dist,
            self.I8,
            self.collided,
            b.reward,
            b.flags,
            b.dist,
        )

    def load_world(self, i: int, world: World, max_speed: float | None = None) -> None:
        super().load_world(i, world, self._max_speed_cfg)

    def episode_start(self, i: int) -> Start:
        """The start pose of a new episode of sub-environment ``i`` (see ``random_start``)."""
        if not self.random_start:
            return tuple(float(v) for v in self.starts[i])
        w = self.worlds[i]
        space = w._cache.get("start_space")
        if space is None:
            comps = shapely.get_parts(w.robot_space)
            space = shapely.union_all(comps[shapely.intersects(comps, w.region)])
            shapely.prepare(space)
            w._cache["start_space"] = space
        rng = self.rngs[i]
        for _ in range(10_000):
            x = rng.uniform(w.lo[0], w.hi[0])
            y = rng.uniform(w.lo[1], w.hi[1])
            if (
                shapely.contains_xy(space, x, y)
                and not w.in_region(x, y)
                and self.far_enough(i, x, y)
            ):
                return (float(x), float(y), float(rng.uniform(-math.pi, math.pi)))
        # a region covering nearly all free space: the scene's (checked) start
        return tuple(float(v) for v in self.starts[i])

    def far_enough(self, i: int, x: float, y: float) -> bool:
        """Whether ``(x, y)`` is at least ``min_start_distance`` scene diameters from the
        recognizable region of sub-environment ``i`` (always, when that is 0)."""
        if self.min_start_distance <= 0:
            return True
        w = self.worlds[i]
        return w.distance_to_region(float(x), float(y)) >= self.min_start_distance * w.diameter

    def set_pose(self, i: int, pose) -> None:
        self.x[i], self.y[i], self.psi[i] = (float(v) for v in pose)

    def _start_from_options(self, i: int, options: dict) -> None:
        start = options.get("start")
        if start is not None:
            x, y, psi = (float(v) for v in start)
            if not all(math.isfinite(v) for v in (x, y, psi)):
                raise ValueError(f"options['start'] = {start!r}: non-finite value")
            psi = math.remainder(psi, 2 * math.pi)  # the heading in [-pi, pi], radians
            if not self.worlds[i].in_free_space(x, y):
                raise ValueError(f"options['start'] = {start!r} is not in the robot's free space")
            self.set_pose(i, (x, y, psi))
        else:
            self.set_pose(i, self.episode_start(i))
        self.collided[i] = False

    def _reset_starts(self, idx: np.ndarray, options: dict) -> None:
        """Put the robots of rows ``idx`` at their episode starts (see ``random_start`` and
        ``options["start"]``), not collided."""
        if options.get("start") is None and not self.random_start:
            self.P[:3, idx] = self.starts[idx].T
            self.collided[idx] = False
        else:
            for i in idx.tolist():
                self._start_from_options(i, options)

    def _after_reset(self, idx: np.ndarray) -> None:
        self.sense(idx)

    def shaping_reward(self, idx: np.ndarray, dist: np.ndarray) -> np.ndarray:
        """Potential-based shaping ``shaping * (d_before - d_after) / diameter`` of
        sub-environments ``idx`` (0 where a distance is infinite); ``dist`` becomes the
        new ``d``."""
        before = self.dist[idx]
        self.dist[idx] = dist
        ok = np.isfinite(dist) & np.isfinite(before)
        return np.where(ok, self.shaping * (before - dist) / self.diameter[idx], 0.0)

    def move(self, act: np.ndarray, idx: np.ndarray) -> np.ndarray:
        """Drive sub-environments ``idx`` and read their sensors; returns ``collided``."""
        if self.speed_limit == "disc":
            norm = np.hypot(act[:, 0], act[:, 1])
            act = act.copy()
            act[:, :2] /= np.maximum(norm, 1.0)[:, None]
        col = self.drive(act, idx, self.max_turn)
        self.collided[idx] = col
        self.sense(idx)
        return col


def _one_row(v: Any) -> Any:
    """Row 0 of an info column as a plain Python value."""
    if isinstance(v, np.ndarray):
        if v.ndim == 0:
            return v.item()
        return tuple(float(c) for c in v) if v.dtype.kind == "f" else v.tolist()
    if isinstance(v, np.generic):
        return v.item()
    return v


class SensorPlanEnv(gym.Env):
    """The Gymnasium env of a task: its batch class (``batch_cls``) with N = 1.

    The attributes a planner or a test reads (``world``, ``pose``, ``scan``, ``sensor_pose``,
    ``start``, ``sensor``, ``max_speed``, ...) are views of sub-environment 0."""

    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": 10}
    batch_cls: type[SensorPlanBatch] = SensorPlanBatch
    _ONE = np.zeros(1, dtype=np.intp)

    def __init__(self, scene: str | Any = "lab", *, render_mode: str | None = None, **kwargs):
        super().__init__()
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"render_mode must be None or one of {self.metadata['render_modes']}, "
                f"got {render_mode!r}"
            )
        self.render_mode = render_mode
        self.batch = self.batch_cls(1, scene, **kwargs)
        self.observation_space = self.batch.single_observation_space
        self.action_space = self.batch.single_action_space
        self._renderer = Renderer() if render_mode is not None else None
        self._viewer = HumanViewer() if render_mode == "human" else None
        self._started = False

    # ---- views of sub-environment 0 ---------------------------------------------------
    @property
    def np_random(self) -> np.random.Generator:
        return self.batch.rngs[0]

    @np_random.setter
    def np_random(self, value: np.random.Generator) -> None:
        self.batch.rngs[0] = value
        self.batch.drop_block(0)

    @property
    def world(self) -> World:
        return self.batch.worlds[0]

    @property
    def pose(self) -> tuple[float, float, float] | None:
        return self.batch.pose(0) if self._started and self.batch._has_pose(0) else None

    @pose.setter
    def pose(self, value) -> None:
        self.batch.set_pose(0, value)

    @property
    def sensor_pose(self):
        return self.batch.sensor_pose(0) if self._started and self.batch.has_scan[0] else None

    @property
    def scan(self):
        return self.batch.scan(0) if self._started else None

    @property
    def start(self) -> tuple[float, float, float]:
        return tuple(float(v) for v in self.batch.starts[0])

    @property
    def sensor(self) -> RangeSensor:
        return self.batch.sensor(0)

    @property
    def max_steps(self) -> int:
        return self.batch.max_steps

    def __getattr__(self, name: str) -> Any:
        # task parameters (max_speed, max_turn, random_start, step_cost, ...) live on the batch
        if name.startswith("__") or name == "batch":
            raise AttributeError(name)
        b = self.__dict__.get("batch")
        if b is None:
            raise AttributeError(name)
        v = getattr(b, name)
        if isinstance(v, np.ndarray) and v.shape[:1] == (1,):
            return _one_row(v[0])
        return v

    # ---- gym API ----------------------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        if seed is not None:
            self.batch.seed_env(0, seed)
            self._np_random_seed = seed
        self._np_random = self.batch.rngs[0]
        self.batch.reset_envs(self._ONE, options)
        self._started = True
        obs = self.batch.observe(self._ONE)[0]
        info = self._info(self.batch.reset_info(self._ONE))
        if self.render_mode == "human":
            self.render()
        return obs, info

    def step(self, action):
        a = self.batch.actions.to_array(_as_batch(action), 1)
        reward, term, trunc, cols = self.batch.step_envs(a, self._ONE)
        obs = self.batch.observe(self._ONE)[0]
        if self.render_mode == "human":
            self.render()
        return obs, float(reward[0]), bool(term[0]), bool(trunc[0]), self._info(cols)

    @staticmethod
    def _info(cols: dict) -> dict[str, Any]:
        out = {}
        for k, (v, m) in cols.items():
            if m is None or m[0]:
                x = v[0]
                if isinstance(x, np.generic):
                    out[k] = x.item()
                elif isinstance(x, np.ndarray):
                    out[k] = tuple(x.tolist()) if x.dtype.kind == "f" else x.tolist()
                else:
                    out[k] = x
        return out

    def render(self):
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode; pass render_mode= to make()")
            return None
        frame = self._renderer.render(self.world, self.batch.render_state(0))
        if self.render_mode == "rgb_array":
            return frame
        self._viewer.show(frame, self.metadata["render_fps"])
        return None

    def close(self) -> None:
        if self._viewer is not None:
            self._viewer.close()
        if self._renderer is not None:
            self._renderer.close()


def _as_batch(action: Any) -> Any:
    """One action as a batch of one (left as is when it is not an array: the check says so)."""
    try:
        return np.asarray(action)[None]
    except (TypeError, ValueError):
        return action
