"""Base class of the sensor-planning environments: configuration, scene handling, seeding,
action checking, sensing and rendering shared by Placement, Navigate and Recognize.

Common keyword arguments (``gym.make(id, **kwargs)``)
-----------------------------------------------------
scene : str | path | dict | geometry.Scene, default ``"lab"``
    A bundled scene name (``lab``, ``edr``, ``corridor``, ``warehouse``), a path to a scene
    JSON file in the pinned format, or ``"random"``: a new procedural scene
    (:func:`geometry.generate.random_scene`) on every reset, drawn from ``self.np_random``.
    Random scenes whose region is empty, unreachable from the start, or that contain the
    start are re-drawn (deterministically, up to ``max_scene_tries`` times).
model : ``"complete"`` | ``"partial"`` -- the visibility model of the recognizable region.
motion : ``"stationary"`` | ``"translating"`` | ``"rotating"`` (see
    :mod:`sensorplan_gym.core.world`).  Unsupported combinations raise
    ``NotImplementedError`` at construction.
eps_pos : float | None -- placement uncertainty (scene units); ``None``: the scene's.
eps_aim : float | None -- aim uncertainty in **radians**; ``None``: the scene's.
fov_deg : float | None -- field of view in degrees; ``None``: the scene's.
max_range : float | None -- sensor range; ``None``: the scene's; ``math.inf``: unlimited.
n_beams : int, default 16 -- beams in the sensor's fan (and in Placement's scans).
noise : float, default 0 -- std of Gaussian range noise (scene units).
obs_type : ``"vector"`` (default) | ``"grid"`` (see :mod:`sensorplan_gym.core.observations`).
grid_size : int, default 64 -- side of the grid observation.
robot_radius : float, default 0 -- the robot is a disc of this radius (0: a point).
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

import math
from typing import Any

import gymnasium as gym
import numpy as np
import shapely

from geometry import Scene

from ..core.observations import make_observation
from ..core.rendering import HumanViewer, Renderer
from ..core.sensor import RangeSensor
from ..core.world import World, WorldConfig, get_world, load_scene, sweep

__all__ = ["SensorPlanEnv"]


class SensorPlanEnv(gym.Env):
    """Shared machinery; subclasses define ``obs_kind``, ``action_space`` and the hooks
    ``_reset_episode``, ``_step`` and ``_scene_ok``."""

    metadata = {"render_modes": ["rgb_array", "human"], "render_fps": 10}
    obs_kind = "robot"
    needs_start = True

    def __init__(
        self,
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
        render_mode: str | None = None,
    ) -> None:
        super().__init__()
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"render_mode must be None or one of {self.metadata['render_modes']}, "
                f"got {render_mode!r}"
            )
        self.render_mode = render_mode
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
        self.cfg = WorldConfig(
            model=model,
            motion=motion,
            eps_pos=None if eps_pos is None else float(eps_pos),
            eps_aim=None if eps_aim is None else float(eps_aim),
            fov=None if fov_deg is None else math.radians(float(fov_deg)),
            max_range=None if max_range is None else float(max_range),
            robot_radius=float(robot_radius),
        ).validate()
        self.n_beams = int(n_beams)
        self.noise = float(noise)
        self.obs_type = obs_type
        self.max_scene_tries = int(max_scene_tries)
        self.random_scene_kwargs = dict(random_scene_kwargs or {})
        self._obs = make_observation(self.obs_kind, obs_type, self.n_beams, grid_size)
        self.observation_space = self._obs.space

        self.random = isinstance(scene, str) and scene == "random"
        if self.random:
            try:
                from geometry.generate import random_scene  # noqa: F401
            except ImportError as e:  # pragma: no cover - generate.py ships with geometry
                raise ImportError("scene='random' needs geometry.generate.random_scene") from e
            # probe once (fixed seed) so unsupported configurations fail here, not at reset
            self.world, self.start = self._draw_world(np.random.default_rng(0))
        else:
            self._scene = load_scene(scene)
            self.world = get_world(self._scene, self.cfg)
            self.start = self._start_pose(self.world, np.random.default_rng(0))
            problem = self._scene_problem(self.world, self.start)
            if problem:
                raise ValueError(
                    f"scene {self._scene.name!r} unusable for {type(self).__name__}: {problem}"
                )
        self._renderer = Renderer() if render_mode is not None else None
        self._viewer = HumanViewer() if render_mode == "human" else None
        self.pose: tuple[float, float, float] | None = None
        self.sensor_pose: tuple[float, float, float] | None = None
        self.scan = None
        self._target_poly: np.ndarray | None = None
        self._segs = self.world.seg_set
        self._make_sensor()

    # ---- scenes ---------------------------------------------------------------------------
    def _make_sensor(self) -> None:
        w = self.world
        self.sensor = RangeSensor(self.n_beams, w.fov, w.reach, self.noise)

    def _start_pose(self, world: World, rng: np.random.Generator) -> tuple[float, float, float]:
        s = world.scene.start
        if s is not None and world.in_free_space(s[0], s[1]):
            return (float(s[0]), float(s[1]), float(s[2]))
        if not self.needs_start:
            return (float(world.goal_center[0]), float(world.goal_center[1]), 0.0)
        # sample a free start that does not recognize
        for _ in range(2000):
            x = rng.uniform(world.lo[0], world.hi[0])
            y = rng.uniform(world.lo[1], world.hi[1])
            if world.in_free_space(x, y) and not world.in_region(x, y):
                return (float(x), float(y), float(rng.uniform(-math.pi, math.pi)))
        raise ValueError(f"scene {world.scene.name!r}: found no free start outside the region")

    def _scene_problem(self, world: World, start) -> str | None:
        """Why this world cannot host an episode (``None`` if it can)."""
        if world.region.is_empty:
            return "the recognizable region is empty under this configuration"
        if not self.needs_start:
            return None
        if world.reachable_region(start[:2]).is_empty:
            return "the recognizable region is not reachable from the start"
        if world.recognizing(*start):
            return "the start pose already recognizes G vs H"
        return None

    def _draw_world(self, rng: np.random.Generator) -> tuple[World, tuple[float, float, float]]:
        from geometry.generate import random_scene

        last = None
        for _ in range(self.max_scene_tries):
            d = random_scene(rng, **self.random_scene_kwargs)
            scene = Scene.from_dict(d)
            world = get_world(scene, self.cfg, d)
            start = self._start_pose(world, rng)
            last = self._scene_problem(world, start)
            if last is None:
                return world, start
        raise RuntimeError(
            f"scene='random': no usable scene in {self.max_scene_tries} draws ({last}); "
            "relax the configuration or raise max_scene_tries"
        )

    # ---- gym API --------------------------------------------------------------------------
    def reset(self, *, seed: int | None = None, options: dict | None = None):
        super().reset(seed=seed)
        if self.random:
            self.world, self.start = self._draw_world(self.np_random)
            self._make_sensor()
        self._segs = self.world.seg_set
        self._target_poly = None
        self._reset_episode(options or {})
        obs = self._observe()
        info = self._info()
        if self.render_mode == "human":
            self.render()
        return obs, info

    def step(self, action):
        a = self._check_action(action)
        obs, reward, terminated, truncated, info = self._step(a)
        if self.render_mode == "human":
            self.render()
        return obs, float(reward), bool(terminated), bool(truncated), info

    def render(self):
        if self.render_mode is None:
            gym.logger.warn("render() called without a render_mode; pass render_mode= to make()")
            return None
        frame = self._renderer.render(self.world, self._render_state())
        if self.render_mode == "rgb_array":
            return frame
        self._viewer.show(frame, self.metadata["render_fps"])
        return None

    def close(self) -> None:
        if self._viewer is not None:
            self._viewer.close()
        if self._renderer is not None:
            self._renderer.close()

    # ---- helpers --------------------------------------------------------------------------
    def _check_action(self, action) -> list[float]:
        """Validate and clip: wrong shape or non-finite values raise ``ValueError``; values
        outside [-1, 1] are clipped to it.  Returns the components as Python floats."""
        shape = self.action_space.shape
        try:
            a = np.asarray(action, dtype=np.float64)
        except (TypeError, ValueError) as e:
            raise ValueError(
                f"action must be a numeric array of shape {shape}, got {action!r}"
            ) from e
        if a.shape != shape:
            raise ValueError(f"action must have shape {shape}, got shape {a.shape}")
        vals = a.tolist()
        out = []
        for v in vals:
            if not math.isfinite(v):
                raise ValueError(f"action contains NaN or infinite values: {vals}")
            out.append(-1.0 if v < -1.0 else (1.0 if v > 1.0 else v))
        return out

    def _execute_sensor_pose(self, pose) -> tuple[float, float, float]:
        """The commanded sensor pose perturbed within eps_pos / eps_aim (section 4)."""
        w = self.world
        x, y, psi = pose
        if w.eps_pos > 0:
            r = w.eps_pos * math.sqrt(self.np_random.random())
            phi = self.np_random.uniform(-math.pi, math.pi)
            d = (r * math.cos(phi), r * math.sin(phi))
            t = sweep((x, y), d, self._segs, 0.0, w.skin)
            x, y = x + t * d[0], y + t * d[1]
        if w.eps_aim > 0:
            psi = psi + self.np_random.uniform(-w.eps_aim, w.eps_aim)
        return (x, y, psi)

    def _read_sensor(self, pose) -> None:
        sp = self._execute_sensor_pose(pose)
        self.sensor_pose = sp
        self.scan = self.sensor.read(sp, self._segs, self.np_random)

    def _observe(self):
        return self._obs(self.world, self.pose, self.scan)

    def _base_info(self) -> dict[str, Any]:
        w = self.world
        if self.pose is None:
            return {"is_success": False, "recognizing": False, "distance_to_region": math.inf}
        x, y, psi = self.pose
        return {
            "recognizing": w.recognizing(x, y, psi),
            "distance_to_region": w.distance_to_region(x, y),
        }

    def _render_state(self) -> dict[str, Any]:
        return {
            "pose": self.pose,
            "sensor_pose": self.sensor_pose,
            "scan": self.scan,
            "recognizing": bool(self.pose is not None and self.world.recognizing(*self.pose)),
            "title": f"{type(self).__name__}: {self.world.scene.name}",
        }

    # ---- hooks ----------------------------------------------------------------------------
    def _reset_episode(self, options: dict) -> None:  # pragma: no cover - abstract
        raise NotImplementedError

    def _step(self, a: np.ndarray):  # pragma: no cover - abstract
        raise NotImplementedError

    def _info(self) -> dict[str, Any]:  # pragma: no cover - abstract
        raise NotImplementedError


class RobotEnv(SensorPlanEnv):
    """A mobile sensor: a disc (or point) robot that drives and turns, with collisions.

    Action ``Box(-1, 1, (k,), float32)`` whose first three components are ``forward``,
    ``lateral`` (to the left) and ``turn`` (counter-clockwise).  The robot first translates by
    ``max_speed * (forward, lateral)`` in its current heading's frame, then turns by
    ``max_turn * turn``.  The translation is swept against walls, obstacles (and the hidden
    target in Recognize): on contact the robot stops there (it never passes through), and
    ``info["collided"]`` is True.  Out-of-range components are clipped to [-1, 1].

    ``random_start=True`` draws every episode's start pose from ``self.np_random``: a
    uniform free position that does not recognize yet, in a part of the free space from
    which the recognizable region is reachable, with a uniform heading (default: the
    scene's ``start``, like TOMMY's fixed start in the paper).
    """

    def __init__(
        self,
        scene="lab",
        *,
        max_speed: float | None = None,
        max_turn: float = math.pi / 8,
        random_start: bool = False,
        **kwargs,
    ) -> None:
        if not isinstance(random_start, bool):
            raise ValueError(f"random_start must be True or False, got {random_start!r}")
        self.random_start = random_start
        for name, v in (("max_speed", max_speed), ("max_turn", max_turn)):
            if v is not None and (
                not isinstance(v, (int, float)) or not math.isfinite(v) or v <= 0
            ):
                raise ValueError(f"{name} must be a positive number, got {v!r}")
        self._max_speed_cfg = max_speed
        self.max_turn = float(max_turn)
        self._extra_clearance = None  # distance to dynamic segments (Recognize's target)
        super().__init__(scene, **kwargs)

    def _episode_start(self) -> tuple[float, float, float]:
        """The start pose of a new episode (see ``random_start``)."""
        if not self.random_start:
            return self.start
        w = self.world
        space = w._cache.get("start_space")
        if space is None:
            comps = shapely.get_parts(w.robot_space)
            space = shapely.union_all(comps[shapely.intersects(comps, w.region)])
            shapely.prepare(space)
            w._cache["start_space"] = space
        rng = self.np_random
        for _ in range(10_000):
            x = rng.uniform(w.lo[0], w.hi[0])
            y = rng.uniform(w.lo[1], w.hi[1])
            if shapely.contains_xy(space, x, y) and not w.in_region(x, y):
                return (float(x), float(y), float(rng.uniform(-math.pi, math.pi)))
        return self.start  # a region covering nearly all of the free space

    @property
    def max_speed(self) -> float:
        """Per-step translation at full action; default 3% of the scene diameter."""
        if self._max_speed_cfg is not None:
            return float(self._max_speed_cfg)
        return 0.03 * self.world.diameter

    def _move(self, a: np.ndarray) -> bool:
        x, y, psi = self.pose
        c, s = math.cos(psi), math.sin(psi)
        v = self.max_speed
        a0, a1 = float(a[0]), float(a[1])
        d = (v * (c * a0 - s * a1), v * (s * a0 + c * a1))
        step = math.hypot(d[0], d[1])
        w = self.world
        # sweep only when a wall, an obstacle or the target may be within reach
        need = step + w.robot_radius + 2 * w.skin
        clear = w.clearance_at(x, y)
        if self._extra_clearance is not None and clear > need:
            clear = min(clear, self._extra_clearance(x, y))
        if clear <= need:
            t = sweep((x, y), d, self._segs, w.robot_radius, w.skin)
            collided = t < 1.0
        else:
            t = 1.0
            collided = False
        psi = psi + self.max_turn * float(a[2])
        psi = (psi + math.pi) % (2 * math.pi) - math.pi
        self.pose = (x + t * float(d[0]), y + t * float(d[1]), psi)
        return collided
