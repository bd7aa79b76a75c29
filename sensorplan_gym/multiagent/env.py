"""``watch_v0``: watcher robots keep robot A in view and tell whether it ended in G or H.

The paper's first motivation (Briggs & Donald, section 1): robot A performs a task, robot B
carries a sensor and must "watch" A; in EDR terms (1.1, 5) B must also tell whether A's
motion plan ended in the goal G or in the failure region H.  Here A is scripted
(:mod:`sensorplan_gym.multiagent.motion`: a plan toward G with bounded drift that sometimes
ends in H) and ``n_watchers`` watcher robots are the agents.

Agents ``watcher_0 .. watcher_{n-1}`` (all act every step; PettingZoo ``ParallelEnv``).

Action (per watcher)
    ``Box(-1, 1, (4,), float32)`` = ``(forward, lateral, turn, decide)`` as in
    ``Recognize-v0``: the watcher translates by ``max_speed * (forward, lateral)`` in its own
    frame (swept against walls, obstacles and A's current outline: it stops at contact),
    then turns by ``max_turn * turn``.  ``decide < -1/3`` declares **G**, ``> 1/3`` declares
    **H**; only a watcher's first declaration counts (later ``decide`` values are ignored);
    a watcher keeps moving and watching after it has declared.  Out-of-range values are
    clipped; NaN/inf, a wrong shape or a missing live agent raise ``ValueError``.
Observation (per watcher, ``Box`` float32, length ``8 + 4 n_beams + 3 + 2 (n_watchers - 1)``)
    As Navigate/Recognize-v0 (position scaled to [-1, 1], ``cos/sin`` heading, vectors to the
    centres of G and H in the watcher's frame / diameter, ``n_beams`` ranges / reach and
    normals in the watcher's frame), then what the **map predicts** for the same beams (the
    ranges to walls and obstacles alone, / reach: a beam reading shorter than its prediction
    hit A), the elapsed fraction ``t / max_steps``, whether A's plan is over (``t >=
    move_steps``: a constant of the task, not of the outcome), the watcher's own declaration
    (0 none, -1 G, +1 H), and the other watchers' positions in its frame / diameter.  A's
    pose and outcome are never part of it: A shows only through the beams it reflects.
    ``evidence=True`` appends 4 entries in [0, 1): what the watcher's own beams have shown
    of A since A's plan is over, ``(seen_G, seen_H, looked_G, looked_H)``
    (:mod:`sensorplan_gym.multiagent.evidence`: saturating counts of the steps on which a
    short beam ended in ``A (+) G`` / ``A (+) H``, and on which a beam crossed them).
Reward (``reward="individual"``, default)
    ``see_reward`` (default 0.01) on every step at whose end the watcher *sees* A under the
    configured model (:meth:`WatchWorld.sees`: exact, from the geometry, with the field of
    view and range), plus +1 / -1 for a right / wrong declaration on the step it is made,
    and -1 at the horizon for a watcher that never declared.
    ``reward="team"``: every watcher gets ``see_reward`` if *some* watcher sees A, plus the
    mean of that step's declaration rewards over the watchers.
Episode
    A fixed horizon of ``max_steps`` steps (default 100) -- the verdict is due then, so every
    watcher is ``terminated`` at step ``max_steps`` (``truncated`` stays False).  A moves for
    ``move_steps`` (default 50) steps and then rests in G or H.
Info (per watcher)
    ``sees``, ``declared`` (None, "G" or "H"), ``collided``, ``pose``; at the end also
    ``is_success`` (declared right), ``a_ends_in`` ("G"/"H") and ``visible_fraction`` (the
    fraction of steps 1..max_steps on which this watcher saw A) and ``team_visible_fraction``.

Keyword arguments: ``scene`` (bundled name, JSON path, dict or Scene), ``n_watchers`` (1),
``model`` ("complete"/"partial"), ``fov_deg``, ``max_range``, ``n_beams`` (16), ``noise``
(range std), ``robot_radius`` (0), ``max_speed`` (None: 3% of the diameter per step),
``max_turn`` (pi/8), ``max_steps`` (100), ``move_steps`` (50), ``p_fail`` (0.5),
``drift`` (0.02 of the diameter), ``speed_noise`` (0.2), ``reward``, ``see_reward``,
``random_start`` (True: watchers start at seeded uniform free positions; False: watcher 0 at
the scene's ``start``, the others at fixed positions), ``render_mode`` (None/"rgb_array"),
``evidence`` (False; computed here, on top of the batch: :class:`~.vector.WatchVectorEnv`
has no such option).
The sensor has no placement/aim uncertainty here (``eps_pos``/``eps_aim`` are not modelled).

Implementation: the env is the batch of one of :class:`~.batch.WatchBatch` (its watchers are
the rows of one batch, A's outline an extra moving obstacle); the vector env
:class:`~.vector.WatchVectorEnv` is the batch of many copies.  With numba the drive, the
beam casts and the "sees A" test are compiled kernels (:mod:`.kernels`); the numpy fallback
gives bitwise the same answers.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
from gymnasium import spaces

from .batch import REWARD_MODES, WatchBatch
from .evidence import N_EVIDENCE, BeamEvidence
from .motion import Trajectory
from .rendering import WatchRenderer

try:  # PettingZoo is optional (extra "multi"); the env works without it
    from pettingzoo import ParallelEnv as _Base
except ImportError:  # pragma: no cover - exercised only without the extra

    class _Base:  # minimal stand-in with PettingZoo's derived properties
        @property
        def num_agents(self) -> int:
            return len(self.agents)

        @property
        def max_num_agents(self) -> int:
            return len(self.possible_agents)

        @property
        def unwrapped(self):
            return self


__all__ = ["WatchParallelEnv", "REWARD_MODES"]

#: configuration attributes read through from the batch
_CONFIG = (
    "world",
    "scene",
    "sensor",
    "motion_cfg",
    "n_watchers",
    "n_beams",
    "noise",
    "robot_radius",
    "max_speed",
    "max_turn",
    "max_steps",
    "move_steps",
    "reward_mode",
    "see_reward",
    "random_start",
)
_ALL = np.zeros(1, dtype=np.int64)


class WatchParallelEnv(_Base):
    """The watch task as a PettingZoo ``ParallelEnv`` (see the module docstring)."""

    metadata = {
        "render_modes": ["rgb_array"],
        "name": "watch_v0",
        "is_parallelizable": True,
        "render_fps": 10,
    }

    def __init__(
        self,
        scene: Any = "lab",
        *,
        n_watchers: int = 1,
        model: str = "complete",
        fov_deg: float | None = None,
        max_range: float | None = None,
        n_beams: int = 16,
        noise: float = 0.0,
        robot_radius: float = 0.0,
        max_speed: float | None = None,
        max_turn: float = math.pi / 8,
        max_steps: int = 100,
        move_steps: int = 50,
        p_fail: float = 0.5,
        drift: float = 0.02,
        speed_noise: float = 0.2,
        reward: str = "individual",
        see_reward: float = 0.01,
        random_start: bool = True,
        render_mode: str | None = None,
        evidence: bool = False,
    ) -> None:
        if not isinstance(evidence, bool):
            raise ValueError(f"evidence must be True or False, got {evidence!r}")
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(f"render_mode must be None or 'rgb_array', got {render_mode!r}")
        self.batch = WatchBatch(
            1,
            scene,
            n_watchers=n_watchers,
            model=model,
            fov_deg=fov_deg,
            max_range=max_range,
            n_beams=n_beams,
            noise=noise,
            robot_radius=robot_radius,
            max_speed=max_speed,
            max_turn=max_turn,
            max_steps=max_steps,
            move_steps=move_steps,
            p_fail=p_fail,
            drift=drift,
            speed_noise=speed_noise,
            reward=reward,
            see_reward=see_reward,
            random_start=random_start,
        )
        self.render_mode = render_mode
        self.possible_agents = [f"watcher_{i}" for i in range(self.batch.n_watchers)]
        self.agents: list[str] = []
        self._obs_space = self.batch.single_observation_space
        self.evidence: BeamEvidence | None = None
        if evidence:
            w, box = self.batch.world, self._obs_space
            self.evidence = BeamEvidence(
                w.swept, self.batch.n_watchers, 3 * self.batch.noise + 1e-3 * w.reach
            )
            self._obs_space = spaces.Box(
                np.concatenate([box.low, np.zeros(N_EVIDENCE, np.float32)]),
                np.ones(box.shape[0] + N_EVIDENCE, np.float32),
                dtype=np.float32,
            )
        self._obs_spaces = {a: self._obs_space for a in self.possible_agents}
        self._act_spaces = {
            a: spaces.Box(-1.0, 1.0, (4,), dtype=np.float32) for a in self.possible_agents
        }
        self.observation_spaces = self._obs_spaces
        self.action_spaces = self._act_spaces
        self._renderer = None
        self._obs: np.ndarray | None = None

    def __getattr__(self, name: str):
        if name in _CONFIG:
            return getattr(self.__dict__["batch"], name)
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    # ---- PettingZoo API --------------------------------------------------------------------
    def observation_space(self, agent: str) -> spaces.Box:
        """The (same, shared) observation space object of every watcher."""
        return self._obs_spaces[agent]

    def action_space(self, agent: str) -> spaces.Box:
        """The action space object of ``agent`` (one object per agent, so seeding one does not
        seed the others)."""
        return self._act_spaces[agent]

    @property
    def np_random(self) -> np.random.Generator:
        """The env's generator (A's motion, the random starts, the range noise)."""
        return self.batch.rngs[0]

    @np_random.setter
    def np_random(self, rng: np.random.Generator) -> None:
        self.batch.rngs[0] = rng

    def reset(self, seed: int | None = None, options: dict | None = None):
        if seed is not None:
            self.batch.seed_env(0, int(seed))
        self.batch.reset_envs(_ALL)
        self.agents = list(self.possible_agents)
        if self.evidence is not None:
            self.evidence.reset()
        self._obs = self._observe_all()
        obs = {a: self._obs[i].copy() for i, a in enumerate(self.agents)}
        infos = {a: self.batch.info(0, i) for i, a in enumerate(self.agents)}
        return obs, infos

    def step(self, actions: dict[str, Any]):
        if not self.agents:
            raise RuntimeError("step() called on a finished episode; call reset() first")
        acts = []
        for a in self.agents:
            if a not in actions:
                raise ValueError(f"no action for live agent {a!r}")
            acts.append(_check_action(actions[a]))
        unknown = set(actions) - set(self.agents)
        if unknown:
            raise ValueError(f"actions for agents that are not live: {sorted(unknown)}")
        b = self.batch
        rew, done, _ = b.step_envs(np.array(acts), _ALL)
        done = bool(done[0])
        agents = self.agents
        self._obs = self._observe_all()
        obs = {a: self._obs[i].copy() for i, a in enumerate(agents)}
        rewards = {a: float(rew[0, i]) for i, a in enumerate(agents)}
        terms = {a: done for a in agents}
        truncs = {a: False for a in agents}
        infos = {a: b.info(0, i, final=done) for i, a in enumerate(agents)}
        if done:
            self.agents = []
        return obs, rewards, terms, truncs, infos

    def render(self):
        if self.render_mode is None:
            import gymnasium

            gymnasium.logger.warn("render() called without a render_mode; pass render_mode=")
            return None
        if self._renderer is None:
            self._renderer = WatchRenderer()
        return self._renderer.render(self)

    def close(self) -> None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None

    def __getstate__(self) -> dict:
        st = self.__dict__.copy()
        st["_renderer"] = None
        return st

    def __setstate__(self, st: dict) -> None:
        self.__dict__.update(st)

    # ---- the state, as the renderer, the oracle watchers and the tests read it --------------
    @property
    def t(self) -> int:
        """Elapsed steps of the episode."""
        return int(self.batch.t[0])

    @property
    def traj(self) -> Trajectory | None:
        """A's trajectory this episode (hidden from the observations)."""
        return self.batch.trajs[0]

    @property
    def poses(self) -> list[tuple[float, float, float]]:
        """The watchers' poses ``(x, y, heading)`` (world frame, radians)."""
        return [self.batch.pose(i) for i in range(self.batch.n_watchers)]

    @property
    def declared(self) -> list[str | None]:
        return [self.batch.info(0, i)["declared"] for i in range(self.batch.n_watchers)]

    @property
    def collided(self) -> list[bool]:
        return [bool(v) for v in self.batch.collided[: self.batch.n_watchers]]

    @property
    def sees(self) -> list[bool]:
        return [bool(v) for v in self.batch.sees[: self.batch.n_watchers]] if self.traj else []

    @property
    def scans(self) -> list[tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]]:
        """Per watcher ``(dist, normal, hit, angles)`` of the latest reading (copies)."""
        if self.traj is None:
            return []
        b = self.batch
        return [
            (
                b.scan_dist[i].copy(),
                b.scan_normal[i].copy(),
                b.scan_hit[i].copy(),
                b.sensor.beam_angles(b.P[2, i]),
            )
            for i in range(b.n_watchers)
        ]

    @property
    def predicted(self) -> list[np.ndarray]:
        """Per watcher the ranges the map predicts (walls and obstacles alone)."""
        return [self.batch.map_dist[i].copy() for i in range(self.batch.n_watchers)]

    @property
    def trail(self) -> list[np.ndarray]:
        """A's positions at steps ``0 .. t``."""
        pos = self.traj.pos
        return [pos[min(k, len(pos) - 1)].copy() for k in range(self.t + 1)]

    @property
    def seen_steps(self) -> list[int]:
        return [int(v) for v in self.batch.seen_steps[0]]

    @property
    def team_seen_steps(self) -> int:
        return int(self.batch.team_seen_steps[0])

    @property
    def a_position(self) -> np.ndarray:
        """A's reference point now (world frame) -- for rendering and tests, not observed."""
        return self.traj.at(self.t)

    @property
    def _a_poly(self) -> np.ndarray:
        return self.world.target_at(self.batch.Q[0])

    def _draw_pose(self, rng, others, *, avoid_a: bool) -> tuple[float, float, float]:
        return self.batch.draw_pose(rng, others, self._a_poly if avoid_a else None)

    def _observe(self, i: int) -> np.ndarray:
        return self._observe_all()[i]

    def _observe_all(self) -> np.ndarray:
        """The batch's observations of every watcher, with the evidence entries appended
        (counted first, once A's plan is over) when ``evidence=True``."""
        o = self.batch.observe(_ALL)
        ev = self.evidence
        if ev is None:
            return o
        b = self.batch
        if self.t >= b.move_steps and self.t > ev.t_counted:
            for i, (dist, _, _, ang) in enumerate(self.scans):
                ev.update(i, b.pose(i), ang, dist, b.map_dist[i])
            ev.t_counted = self.t
        feats = np.stack([ev.features(i) for i in range(b.n_watchers)]).astype(np.float32)
        return np.concatenate([o, feats], axis=1)


def _check_action(action) -> np.ndarray:
    try:
        a = np.asarray(action, dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise ValueError(f"action must be a numeric array of shape (4,), got {action!r}") from e
    if a.shape != (4,):
        raise ValueError(f"action must have shape (4,), got shape {a.shape}")
    if not np.all(np.isfinite(a)):
        raise ValueError(f"action contains NaN or infinite values: {a.tolist()}")
    return np.clip(a, -1.0, 1.0)
