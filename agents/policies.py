"""Policies with the stable-baselines3 ``predict`` interface, and :func:`load_policy`.

Every policy here answers ``predict(obs, state=None, episode_start=None, deterministic=True)
-> (actions, state)`` like an SB3 model, so :mod:`agents.evaluate` (and SB3's own
``evaluate_policy``) treat the oracle, the random baseline and trained models alike.

``load_policy(spec, env)`` turns a command-line spec into such an object:

``"oracle"``
    :class:`agents.oracle.OraclePolicy` bound to ``env`` (privileged: it reads the scene).
``"random"``
    :class:`RandomPolicy` sampling ``env.action_space`` from a seeded generator.
``path/to/model.zip``
    A trained SB3 model.  Its algorithm is read from the resolved config YAML that
    ``sensorplan train`` saves beside it (``model.yaml``, else ``config.yaml`` in the same
    folder); without one, every supported algorithm is tried in order.
"""

from __future__ import annotations

import copy
from pathlib import Path
from typing import Any

import numpy as np
from gymnasium import spaces

__all__ = ["ALGOS", "RandomPolicy", "load_policy", "model_config", "policy_label"]

#: algorithm names accepted by ``sensorplan train --algo`` (in the order tried by load_policy)
ALGOS = ("ppo", "sac", "td3", "a2c", "dqn")


def algo_class(name: str):
    """The SB3 class of an algorithm name (``ppo``, ``sac``, ``td3``, ``a2c``, ``dqn``)."""
    import stable_baselines3 as sb3

    classes = {"ppo": sb3.PPO, "sac": sb3.SAC, "td3": sb3.TD3, "a2c": sb3.A2C, "dqn": sb3.DQN}
    try:
        return classes[name.lower()]
    except KeyError:
        raise ValueError(f"unknown algorithm {name!r}; choose one of {', '.join(ALGOS)}") from None


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


def model_config(path: str | Path) -> dict | None:
    """The resolved training config saved beside a model zip (``None`` if there is none)."""
    import yaml

    p = Path(path)
    for cand in (p.with_suffix(".yaml"), p.with_suffix(".yml"), p.parent / "config.yaml"):
        if cand.is_file():
            with open(cand) as f:
                cfg = yaml.safe_load(f)
            if isinstance(cfg, dict):
                return cfg
    return None


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


def load_policy(spec: str, env, *, seed: int = 0, device: str = "cpu"):
    """A policy object for ``spec`` (``"oracle"``, ``"random"`` or a model zip), bound to
    ``env`` where that matters.  Raises ``FileNotFoundError`` for a missing zip and
    ``ValueError`` for a zip no algorithm can load."""
    if spec == "oracle":
        from .oracle import OraclePolicy

        return OraclePolicy(env)
    if spec == "random":
        return RandomPolicy(env.action_space, seed=seed, observation_space=env.observation_space)
    path = Path(spec)
    if path.suffix != ".zip" and not path.exists() and path.with_suffix(".zip").exists():
        path = path.with_suffix(".zip")
    if not path.is_file():
        raise FileNotFoundError(
            f"policy {spec!r} is neither 'oracle', 'random' nor an existing model zip"
        )
    cfg = model_config(path) or {}
    order = [cfg["algo"]] if cfg.get("algo") in ALGOS else list(ALGOS)
    errors = []
    for name in order:
        try:
            return algo_class(name).load(str(path), device=device)
        except ImportError:  # the rl extra is missing: say so (agents.cli names the extra)
            raise
        except Exception as e:  # noqa: BLE001 - try the next algorithm
            errors.append(f"{name}: {type(e).__name__}: {e}")
    raise ValueError(f"could not load {path} with any of {order}:\n  " + "\n  ".join(errors))
