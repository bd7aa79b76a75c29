"""Policies with the stable-baselines3 ``predict`` interface, and :func:`load_policy`.

Every policy here answers ``predict(obs, state=None, episode_start=None, deterministic=True)
-> (actions, state)`` like an SB3 model, so :mod:`agents.evaluation.evaluate` (and SB3's own
``evaluate_policy``) treat the oracle, the random baseline and trained models alike.

``load_policy(spec, env)`` turns a command-line spec into such an object:

``"oracle"``
    :class:`agents.planning.oracle.OraclePolicy` bound to ``env`` (privileged: it reads the scene).
``"random"``
    :class:`RandomPolicy` sampling ``env.action_space`` from a seeded generator.
``path/to/model.zip``
    A trained SB3 (or sb3-contrib) model.  Its algorithm is read from the resolved config
    YAML that ``sensorplan train`` saves beside it (``model.yaml``, else ``config.yaml`` in
    the same folder); without one, every supported algorithm is tried in order.  When that
    config says the model was trained on stacked frames (``frame_stack: k``) or normalized
    observations (``normalize``, statistics in ``<model>_vecnormalize.pkl``), the returned
    :class:`ModelPolicy` applies the same preprocessing, so it plays a plain single env.
"""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import numpy as np
from gymnasium import spaces

__all__ = [
    "ALGOS",
    "CONTRIB_ALGOS",
    "ModelPolicy",
    "RULES",
    "RandomPolicy",
    "check_policies",
    "load_policy",
    "make_env",
    "model_config",
    "model_path",
    "policy_label",
    "vecnormalize_path",
]

#: algorithm names accepted by ``sensorplan train --algo`` (in the order tried by load_policy)
ALGOS = ("ppo", "sac", "td3", "a2c", "dqn", "qrdqn", "recurrentppo")
#: the algorithms that come from sb3-contrib (in the ``rl`` extra)
CONTRIB_ALGOS = ("qrdqn", "recurrentppo")


def algo_class(name: str):
    """The SB3 class of an algorithm name (``ppo``, ``sac``, ``td3``, ``a2c``, ``dqn``; and
    from sb3-contrib ``qrdqn`` and ``recurrentppo``, PPO with an LSTM policy)."""
    key = name.lower()
    if key not in ALGOS:
        raise ValueError(f"unknown algorithm {name!r}; choose one of {', '.join(ALGOS)}")
    if key in CONTRIB_ALGOS:
        try:
            import sb3_contrib
        except ImportError as e:
            raise ImportError(
                f"algorithm {name!r} needs sb3-contrib: pip install 'sensorplan-gym[rl]' "
                "(or pip install sb3-contrib)",
                name="sb3_contrib",
            ) from e
        return {"qrdqn": sb3_contrib.QRDQN, "recurrentppo": sb3_contrib.RecurrentPPO}[key]
    import stable_baselines3 as sb3

    classes = {"ppo": sb3.PPO, "sac": sb3.SAC, "td3": sb3.TD3, "a2c": sb3.A2C, "dqn": sb3.DQN}
    return classes[key]


def make_env(env_id: str, env_kwargs: dict | None = None, **extra: Any):
    """``gym.make(env_id, **env_kwargs, **extra)``, with a keyword the env does not take
    reported as a ``ValueError`` that names it (Gymnasium raises a ``TypeError`` from deep
    inside the env creator)."""
    import gymnasium as gym

    kw = {**(env_kwargs or {}), **extra}
    try:
        return gym.make(env_id, **kw)
    except TypeError as e:
        if "unexpected keyword" not in str(e):
            raise
        raise ValueError(
            f"env kwargs {sorted(kw)} for {env_id}: {e.args[0].split(' was raised')[0]} "
            "(see the env's docstring for the keywords it takes)"
        ) from None


def vecnormalize_path(model_path: str | Path) -> Path:
    """Where ``sensorplan train`` keeps the observation-normalization statistics
    (a pickled SB3 ``VecNormalize``) of a model trained with ``normalize``:
    ``<dir>/<stem>_vecnormalize.pkl``."""
    p = Path(model_path)
    return p.with_name(p.with_suffix("").name + "_vecnormalize.pkl")


class ModelPolicy:
    """A trained model plus the observation preprocessing it was trained with.

    ``predict(obs, state, episode_start, deterministic)`` takes the raw observation of one
    (single) env, normalizes it with the frozen training statistics (``normalize``: SB3's
    ``VecNormalize.normalize_obs``), stacks the last ``frame_stack`` of them (SB3's
    ``StackedObservations``, as ``VecFrameStack`` did in training: oldest first, zeros
    before the episode's first frame), and asks the model.  ``episode_start`` true starts a
    new stack.  Without ``episode_start`` (a plain ``predict(obs)`` loop) the policy tells a
    new episode by itself from ``env`` (the env it plays, as :func:`load_policy` binds it:
    each sensorplan env counts the episodes it started); a stacking policy bound to no such
    env raises ``ValueError`` there rather than guess.  Recurrent models get their LSTM
    state passed through.
    """

    def __init__(
        self,
        model,
        observation_space: spaces.Space,
        *,
        frame_stack: int = 1,
        vecnormalize=None,
        env=None,
    ) -> None:
        """``observation_space``: the env's own (one frame, unnormalized); ``env``: the
        single env it plays (optional; lets ``predict`` notice new episodes by itself)."""
        self.model = model
        self._batch = getattr(getattr(env, "unwrapped", None), "batch", None)
        self._episode = -1
        self.frame_stack = int(frame_stack)
        self.vecnormalize = vecnormalize
        self.observation_space = observation_space
        self.action_space = model.action_space
        self._stack = None
        if self.frame_stack > 1:
            from stable_baselines3.common.vec_env.stacked_observations import (
                StackedObservations,
            )

            self._stack = StackedObservations(1, self.frame_stack, observation_space)
        self._started = False

    def _prepare(self, obs: Any, episode_start: Any) -> np.ndarray:
        o = np.asarray(obs)[None]
        if self.vecnormalize is not None:
            o = self.vecnormalize.normalize_obs(o)
        if self._stack is None:
            return o[0]
        if episode_start is not None:
            new = bool(np.asarray(episode_start).reshape(-1)[0])
        elif self._batch is not None:
            new = int(self._batch.episodes[0]) != self._episode
        else:
            raise ValueError(
                f"this policy stacks {self.frame_stack} frames: pass episode_start to predict "
                "(True on an episode's first observation), or load it with its env "
                "(load_policy(path, env)) so that it notices new episodes itself"
            )
        if self._batch is not None:
            self._episode = int(self._batch.episodes[0])
        if new or not self._started:
            self._started = True
            return self._stack.reset(o)[0]
        stacked, _ = self._stack.update(o, np.zeros(1, dtype=bool), [{}])
        return stacked[0]

    def predict(
        self,
        observation: Any,
        state: Any = None,
        episode_start: Any = None,
        deterministic: bool = True,
    ):
        o = self._prepare(observation, episode_start)
        return self.model.predict(
            o, state=state, episode_start=episode_start, deterministic=deterministic
        )


class RandomPolicy:
    """Uniform random actions from ``action_space``, seeded.

    ``predict`` returns one action for one observation, or a batch of actions (one per row)
    for a batch of observations, as an SB3 model does.  Batching is recognised from
    ``observation_space`` when given, else a vector observation with more than one
    dimension is taken as a batch.
    """

    def __init__(
        self,
        action_space: spaces.Space,
        seed: int | None = None,
        observation_space: spaces.Space | None = None,
    ) -> None:
        # a private copy: seeding must not touch the env's own action space
        self.action_space = copy.deepcopy(action_space)
        self.observation_space = observation_space
        self.seed = seed
        self.action_space.seed(None if seed is None else int(seed))

    def _n_batch(self, obs: Any) -> int | None:
        if isinstance(obs, dict) or obs is None:
            return None
        o = np.asarray(obs)
        if self.observation_space is not None and self.observation_space.shape:
            shape = self.observation_space.shape
            return o.shape[0] if o.ndim == len(shape) + 1 else None
        return o.shape[0] if o.ndim >= 2 else None

    def predict(
        self,
        observation: Any,
        state: Any = None,
        episode_start: Any = None,
        deterministic: bool = True,
    ):
        n = self._n_batch(observation)
        if n is None:
            return np.asarray(self.action_space.sample()), state
        return np.stack([np.asarray(self.action_space.sample()) for _ in range(n)]), state


#: policy specs that name a fixed controller, with the config it is played with (its
#: observation kwargs): ``"hint-rule"`` (:mod:`agents.planning.hint_rule`; Navigate-v0 ignores
#: the evidence flags Recognize-v0's rule reads)
RULES = {
    "hint-rule": {
        "algo": "hint_rule",
        "env_kwargs": {
            "view_hint": True,
            "aim_features": True,
            "map_evidence": True,
            "self_features": True,
        },
    },
    # Recognize-v0 only: the hint to poses that see both hulls with no joint aim asked
    "hint-rule-turn": {
        "algo": "hint_rule",
        "env_kwargs": {
            "view_hint": True,
            "hint_aim": False,
            "aim_features": True,
            "map_evidence": True,
            "self_features": True,
        },
    },
}


def model_config(path: str | Path) -> dict | None:
    """The resolved training config saved beside a model zip (``None`` if there is none); for a
    rule of :data:`RULES`, its config."""
    if str(path) in RULES:
        return RULES[str(path)]
    import yaml

    p = Path(path)
    for cand in (p.with_suffix(".yaml"), p.with_suffix(".yml"), p.parent / "config.yaml"):
        if cand.is_file():
            with open(cand) as f:
                cfg = yaml.safe_load(f)
            if isinstance(cfg, dict):
                return cfg
    return None


# env kwargs that fix what a model sees or what its actions mean: a model is played with the
# values it was trained with (the user's kwargs override them; scene and starts are the user's)
OBSERVATION_KWARGS = (
    "n_beams",
    "obs_type",
    "grid_size",
    "action_type",
    "map_ranges",
    "map_evidence",
    "sensor_fov",
    "declare_hold",
    "placement_grid",
    "placement_aims",
    "self_features",
    "aim_features",
    "grid_views",
    "hull_views",
    "aim_views",
    "view_hint",
    "hint_aim",
)


def play_env_kwargs(cfg: dict | None, env_kwargs: dict | None) -> dict:
    """The env kwargs to play a model with: the observation/action kwargs of its resolved
    training config ``cfg`` (:data:`OBSERVATION_KWARGS`), with the user's ``env_kwargs``
    merged over them.  Scene, starts and reward kwargs of the training config are not
    taken.  Returns a new dict."""
    trained = (cfg or {}).get("env_kwargs") or {}
    if not isinstance(trained, dict):
        raise ValueError(f"the model config's env_kwargs must be a mapping, got {trained!r}")
    out = {k: trained[k] for k in OBSERVATION_KWARGS if k in trained}
    out.update(env_kwargs or {})
    return out


def policy_label(spec: str) -> str:
    """A short display name for a policy spec."""
    if spec in ("oracle", "random"):
        return spec
    p = Path(spec)
    return (
        p.stem
        if p.stem not in ("best_model", "final_model", "model")
        else f"{p.parent.name}/{p.stem}"
    )


def model_path(spec: str | Path) -> Path:
    """The model file a policy spec names: an SB3 zip, or a pixel policy's ``.pt``
    (:mod:`agents.learning.pixel_bc`); ``path/model`` also finds ``path/model.zip`` and then
    ``path/model.pt``.  Raises ``FileNotFoundError`` naming the spec when there is no such
    file."""
    path = Path(spec).expanduser()
    if path.suffix not in (".zip", ".pt") and not path.exists():
        for suffix in (".zip", ".pt"):
            if path.with_suffix(suffix).exists():
                path = path.with_suffix(suffix)
                break
    if not path.is_file():
        raise FileNotFoundError(
            f"policy {str(spec)!r} is neither 'oracle', 'random' nor an existing model zip "
            "or pixel policy (.pt)"
        )
    return path


def _is_pixel_policy(path: Path) -> bool:
    """A ``.pt`` file whose config beside it says ``algo: pixel_bc``."""
    return path.suffix == ".pt" and (model_config(path) or {}).get("algo") == "pixel_bc"


def check_policies(specs: list[str]) -> None:
    """Check every policy spec before any episode is played: ``"oracle"``, ``"random"`` or
    an existing zip archive (with its normalization statistics when its config says it was
    trained on normalized observations).  Raises ``FileNotFoundError`` (a missing file) or
    ``ValueError`` (anything else) listing every bad spec at once."""
    import zipfile

    missing, bad = [], []
    for spec in specs:
        if spec in ("oracle", "random", *RULES):
            continue
        try:
            path = model_path(spec)
        except FileNotFoundError as e:
            missing.append(str(e))
            continue
        if path.suffix == ".pt":
            try:
                pixel = _is_pixel_policy(path)
            except ImportError:  # no yaml (rl extra): load_policy will say so
                continue
            if not pixel:
                bad.append(
                    f"policy {spec!r}: {str(path)!r} has no config beside it with "
                    "'algo: pixel_bc' (a pixel policy, agents.learning.pixel_bc)"
                )
            continue
        if not zipfile.is_zipfile(path):
            bad.append(f"policy {spec!r}: {str(path)!r} is not a zip archive (an SB3 model)")
            continue
        try:
            cfg = model_config(path) or {}
        except ImportError:  # no yaml (rl extra): load_policy will say so
            continue
        if cfg.get("normalize") and not vecnormalize_path(path).is_file():
            missing.append(
                f"policy {spec!r} was trained with normalized observations, but their "
                f"statistics {str(vecnormalize_path(path))!r} are missing"
            )
    if missing or bad:
        msg = "; ".join(missing + bad)
        raise (FileNotFoundError if missing and not bad else ValueError)(msg)


def load_policy(spec: str, env, *, seed: int = 0, device: str = "cpu"):
    """A policy object for ``spec`` (``"oracle"``, ``"random"``, a rule of :data:`RULES`, a
    model zip or a pixel policy's ``.pt``), bound to
    ``env`` where that matters.  Raises ``FileNotFoundError`` for a missing zip and
    ``ValueError`` for a zip no algorithm can load."""
    if spec == "oracle":
        from ..planning.oracle import OraclePolicy

        return OraclePolicy(env)
    if spec == "random":
        return RandomPolicy(env.action_space, seed=seed, observation_space=env.observation_space)
    if spec in RULES:
        from ..planning.hint_rule import HintRulePolicy

        return HintRulePolicy(env)
    path = model_path(spec)
    cfg = model_config(path) or {}
    if path.suffix == ".pt":
        if cfg.get("algo") != "pixel_bc":
            raise ValueError(f"{path}: no config beside it with 'algo: pixel_bc'")
        from .pixel_bc import PixelPolicy

        return PixelPolicy.load(path)
    order = [cfg["algo"]] if cfg.get("algo") in ALGOS else list(ALGOS)
    errors = []
    model = None
    for name in order:
        try:
            model = algo_class(name).load(str(path), device=device)
            break
        except ImportError:  # the rl extra is missing: say so (agents.cli names the extra)
            if len(order) == 1:
                raise
            errors.append(f"{name}: not installed")
        except Exception as e:  # noqa: BLE001 - try the next algorithm
            errors.append(f"{name}: {type(e).__name__}: {e}")
    if model is None:
        raise ValueError(f"could not load {path} with any of {order}:\n  " + "\n  ".join(errors))
    frame_stack = int(cfg.get("frame_stack") or 1)
    vecnorm = None
    if cfg.get("normalize"):
        stats = vecnormalize_path(path)
        if not stats.is_file():
            raise FileNotFoundError(
                f"{path} was trained with normalized observations, but their statistics "
                f"{stats} are missing"
            )
        import pickle

        with open(stats, "rb") as f:
            vecnorm = pickle.load(f)
        vecnorm.training = False
    if frame_stack > 1 or vecnorm is not None:
        model = ModelPolicy(
            model, env.observation_space, frame_stack=frame_stack, vecnormalize=vecnorm, env=env
        )
    if cfg.get("residual"):  # a correction of a fixed controller (agents.learning.residual)
        from .residual import RESIDUAL_SCALE, ResidualPolicy

        return ResidualPolicy(
            model, cfg["residual"], float(cfg.get("residual_scale", RESIDUAL_SCALE))
        )
    return model
