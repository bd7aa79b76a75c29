"""Learning from the exact planner: behaviour cloning, DAgger, and PPO fine-tuning from them.

``sensorplan imitate --env sensorplan/Navigate-v0 --method dagger+ppo [--config FILE]
[--seed S] [--out DIR] [--wall-s SECONDS]``

The expert is :class:`agents.planning.oracle.OraclePolicy` bound to a native vector env
(``gym.make_vec``, :class:`sensorplan_gym.envs.vector.SensorPlanVectorEnv`): it reads each
sub-environment's map, pose and readings and answers with the action of the exact planner
from the state the sub-environment is in (it replans when another policy drove).  The learner
is the policy of a stable-baselines3 model (PPO's ``ActorCriticPolicy`` by default; SAC and
TD3 policies work as well), trained on torch:

* :func:`fit` -- supervised steps on ``(observation, oracle action)`` pairs: the mean squared
  error between the policy's deterministic action (``policy._predict(obs, deterministic=True)``:
  the Gaussian mean of PPO/A2C, the squashed mean of SAC, TD3's actor) and the oracle's action
  (``loss="mse"``), or the negative log-likelihood of the oracle's action under the policy's
  own distribution (``loss="nll"``, ``policy.evaluate_actions``; PPO/A2C only);
* :func:`collect` -- ``steps`` steps of all sub-environments in which each sub-environment
  follows the oracle with probability ``beta`` and the learner otherwise (drawn per step),
  recording the visited observations with the oracle's labels;
* :func:`dagger` -- Ross et al. (2011): iteration ``i`` collects with ``beta_i = beta0 *
  decay ** i`` (iteration 0 with ``beta0 = 1`` is behaviour cloning on oracle rollouts),
  aggregates everything collected so far, and refits the policy;
* :func:`train_imitation` -- the methods ``bc``, ``dagger``, ``dagger+ppo`` (DAgger, then
  ``PPO.learn`` continues from the imitated weights) and ``ppo`` (from scratch, the same code
  path, for comparisons at equal wall time), with hyperparameters from
  ``agents/configs/imitation.yaml``.  Writes ``final_model.zip`` (an SB3 PPO zip: ``sensorplan
  evaluate`` / ``benchmark`` load it) and ``final_model.yaml`` (the resolved config).

Frames and units are the env's: observations and actions as the env's spaces define them.
"""

from __future__ import annotations

import copy
import json
import math
import shutil
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import torch
import yaml
from stable_baselines3.common.callbacks import BaseCallback
from stable_baselines3.common.policies import ActorCriticPolicy, BasePolicy

import sensorplan_gym  # noqa: F401  (registers the env ids)

from ..planning.oracle import OraclePolicy
from .policies import RULES, algo_class
from .train import _activation
from .vecenv import BatchedVecEnv

__all__ = [
    "CONFIG",
    "METHODS",
    "DaggerResult",
    "collect",
    "dagger",
    "fit",
    "load_config",
    "make_expert",
    "success_rate",
    "train_imitation",
]

CONFIG = Path(__file__).resolve().parent.parent / "configs" / "imitation.yaml"
METHODS = ("bc", "dagger", "dagger+ppo", "ppo")
#: the log standard deviation a policy of ``bc`` / ``dagger`` is saved with (the fit sets the
#: Gaussian's mean only; SB3's ``predict`` samples unless ``deterministic=True``, and the
#: initial spread, 1, would drown the imitated actions): a config's ``dagger.log_std``
#: overrides it
IMITATED_LOG_STD = -3.0
LOSSES = ("mse", "nll")


# ---------------------------------------------------------------------------------------------
# supervised steps
# ---------------------------------------------------------------------------------------------


def _check_policy(policy: BasePolicy, loss: str) -> None:
    if loss not in LOSSES:
        raise ValueError(f"loss must be one of {LOSSES}, got {loss!r}")
    if not isinstance(policy.action_space, gym.spaces.Box):
        raise TypeError(
            "imitation of the oracle needs a continuous (Box) action space; the oracle does "
            f"not act in {policy.action_space}"
        )
    if loss == "nll" and not isinstance(policy, ActorCriticPolicy):
        raise TypeError(
            f"loss='nll' needs an ActorCriticPolicy (PPO, A2C), got {type(policy).__name__}; "
            "use loss='mse'"
        )


def imitation_loss(
    policy: BasePolicy, obs: torch.Tensor, act: torch.Tensor, loss: str = "mse"
) -> torch.Tensor:
    """The loss of ``policy`` on a batch of oracle pairs (``obs`` ``(b, *obs_shape)``,
    ``act`` ``(b, action_dim)``, in the env's action units): the mean over the batch of the
    squared error of the deterministic action summed over action components (``"mse"``), or
    of the negative log-likelihood of the oracle's action (``"nll"``)."""
    if loss == "nll":
        _, logp, _ = policy.evaluate_actions(obs, act)
        return -logp.mean()
    pred = policy._predict(obs, deterministic=True)
    return ((pred - act) ** 2).sum(dim=1).mean()


def fit(
    policy: BasePolicy,
    obs: np.ndarray,
    acts: np.ndarray,
    *,
    epochs: int = 10,
    batch_size: int = 256,
    learning_rate: float = 1e-3,
    loss: str = "mse",
    seed: int = 0,
) -> list[float]:
    """Supervised epochs of ``policy`` on ``(obs, acts)`` (numpy, ``(n, *obs_shape)`` and
    ``(n, action_dim)``; actions are clipped to the action space first) with Adam over all
    of the policy's parameters.  Returns the mean loss of each epoch."""
    _check_policy(policy, loss)
    if len(obs) != len(acts) or len(obs) == 0:
        raise ValueError(f"fit: {len(obs)} observations for {len(acts)} actions")
    if epochs < 1 or batch_size < 1 or not learning_rate > 0:
        raise ValueError("fit: epochs, batch_size and learning_rate must be positive")
    space = policy.action_space
    a = np.clip(np.asarray(acts, dtype=np.float32), space.low, space.high)
    o_t = torch.as_tensor(np.asarray(obs, dtype=np.float32), device=policy.device)
    a_t = torch.as_tensor(a, device=policy.device)
    opt = torch.optim.Adam(policy.parameters(), lr=learning_rate)
    gen = torch.Generator().manual_seed(int(seed))
    policy.set_training_mode(True)
    history = []
    for _ in range(int(epochs)):
        perm = torch.randperm(len(o_t), generator=gen)
        total, n = 0.0, 0
        for i in range(0, len(perm), batch_size):
            j = perm[i : i + batch_size].to(policy.device)
            value = imitation_loss(policy, o_t[j], a_t[j], loss)
            opt.zero_grad()
            value.backward()
            opt.step()
            total += float(value.detach()) * len(j)
            n += len(j)
        history.append(total / n)
    policy.set_training_mode(False)
    return history


# ---------------------------------------------------------------------------------------------
# data from the oracle on the batched env
# ---------------------------------------------------------------------------------------------


def collect(
    venv: gym.vector.VectorEnv,
    oracle: OraclePolicy,
    policy: BasePolicy | None,
    steps: int,
    *,
    beta: float = 1.0,
    rng: np.random.Generator | None = None,
    obs: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, dict]:
    """Step all sub-environments of the native vector env ``venv`` ``steps`` times.  Each
    step every sub-environment follows the oracle with probability ``beta`` and ``policy``
    (deterministic) otherwise; the observations it visits are recorded with the oracle's
    action there.  ``obs`` is the current observation batch (``None``: ``venv`` is reset
    first, unseeded).  Returns ``(observations (k, ...), oracle actions (k, d), the last
    observation batch, stats)`` with ``stats`` = ``episodes`` ended, ``successes`` among them,
    ``expert_fraction`` of the steps taken by the oracle.  The observation after an episode's
    last step (before the vector env's next-step reset) is not recorded."""
    if not 0.0 <= beta <= 1.0:
        raise ValueError(f"beta must be in [0, 1], got {beta!r}")
    if policy is None and beta < 1.0:
        raise ValueError("collect: beta < 1 needs a learner policy")
    rng = rng if rng is not None else np.random.default_rng()
    if obs is None:
        obs, _ = venv.reset()
    n = venv.num_envs
    ended = np.zeros(n, dtype=bool)  # the last step ended these: this obs is terminal
    xs, ys = [], []
    episodes = successes = expert_steps = 0
    for _ in range(int(steps)):
        label, _ = oracle.predict(obs)
        keep = ~ended
        xs.append(obs[keep])
        ys.append(label[keep])
        use = rng.random(n) < beta
        act = label
        if not use.all():
            mine, _ = policy.predict(obs, deterministic=True)
            act = np.where(use[:, None], label, mine)
        expert_steps += int(use[keep].sum())
        obs, _, term, trunc, info = venv.step(act.astype(np.float32))
        ended = term | trunc
        episodes += int(ended.sum())
        if "is_success" in info:
            successes += int(np.sum(np.asarray(info["is_success"], dtype=bool) & ended))
    x, y = np.concatenate(xs), np.concatenate(ys)
    stats = {
        "episodes": episodes,
        "successes": successes,
        "expert_fraction": expert_steps / max(len(x), 1),
    }
    return x, y, obs, stats


@dataclass
class DaggerResult:
    """What :func:`dagger` did: the aggregated data set (``obs``, ``acts``) and per iteration
    ``beta``, the pairs added, episodes/successes while collecting, the final fit loss and
    the wall time (s)."""

    obs: np.ndarray
    acts: np.ndarray
    history: list[dict[str, Any]] = field(default_factory=list)


def make_expert(expert: str, venv: gym.vector.VectorEnv) -> Any:
    """The labeller :func:`dagger` names: ``"oracle"`` (:class:`OraclePolicy` bound to
    ``venv``) or a rule of :data:`~agents.learning.policies.RULES`; anything else raises
    ``ValueError`` listing the choices."""
    if expert == "oracle":
        return OraclePolicy(venv)
    if expert in RULES:
        from ..planning.hint_rule import HintRulePolicy

        return HintRulePolicy(venv)
    raise ValueError(f"expert must be 'oracle' or one of {', '.join(RULES)}, got {expert!r}")


def dagger(
    venv: gym.vector.VectorEnv,
    policy: BasePolicy,
    *,
    iterations: int = 6,
    steps: int = 64,
    beta0: float = 1.0,
    decay: float = 0.5,
    epochs: int = 10,
    batch_size: int = 256,
    learning_rate: float = 1e-3,
    loss: str = "mse",
    seed: int = 0,
    max_pairs: int | None = None,
    deadline: float | None = None,
    log: Callable[[str], None] | None = None,
    expert: str = "oracle",
) -> DaggerResult:
    """DAgger on the native vector env ``venv`` (reset with ``seed``): ``iterations`` rounds
    of :func:`collect` (``steps`` steps of every sub-environment with ``beta_i = beta0 *
    decay ** i``), aggregation, and :func:`fit` of ``policy`` on all pairs so far (the newest
    ``max_pairs`` when given).  ``deadline`` (``time.perf_counter()`` value): stop after the
    iteration that passes it.  ``expert``: who labels, ``"oracle"`` (the exact planner) or
    a fixed rule of :data:`agents.learning.policies.RULES` (``"hint-rule"``: a function of
    the observation, so a learner can fit its labels exactly).  Returns a
    :class:`DaggerResult`."""
    if iterations < 1 or steps < 1:
        raise ValueError("dagger: iterations and steps must be positive")
    if not (0.0 <= beta0 <= 1.0 and 0.0 <= decay <= 1.0):
        raise ValueError(f"dagger: beta0 and decay must be in [0, 1], got {beta0}, {decay}")
    _check_policy(policy, loss)
    oracle = make_expert(expert, venv)
    rng = np.random.default_rng(seed)
    obs, _ = venv.reset(seed=seed)
    xs: list[np.ndarray] = []
    ys: list[np.ndarray] = []
    result = DaggerResult(np.empty(0), np.empty(0))
    t0 = time.perf_counter()
    for it in range(int(iterations)):
        beta = beta0 * decay**it
        x, y, obs, stats = collect(venv, oracle, policy, steps, beta=beta, rng=rng, obs=obs)
        xs.append(x)
        ys.append(y)
        X, Y = np.concatenate(xs), np.concatenate(ys)
        if max_pairs is not None and len(X) > max_pairs:
            X, Y = X[-max_pairs:], Y[-max_pairs:]
        losses = fit(
            policy,
            X,
            Y,
            epochs=epochs,
            batch_size=batch_size,
            learning_rate=learning_rate,
            loss=loss,
            seed=seed + it,
        )
        rec = {
            "iteration": it,
            "beta": beta,
            "pairs": len(x),
            "total_pairs": len(X),
            **stats,
            "loss": losses[-1],
            "wall_s": round(time.perf_counter() - t0, 1),
        }
        result.history.append(rec)
        if log:
            log(
                f"dagger {it}: beta {beta:.3f}, {len(X)} pairs, collected episodes "
                f"{stats['episodes']} ({stats['successes']} won), loss {losses[-1]:.4f}, "
                f"{rec['wall_s']} s"
            )
        if deadline is not None and time.perf_counter() > deadline:
            break
    result.obs, result.acts = np.concatenate(xs), np.concatenate(ys)
    return result


# ---------------------------------------------------------------------------------------------
# evaluation
# ---------------------------------------------------------------------------------------------


def success_rate(
    policy: BasePolicy | None,
    env_id: str,
    env_kwargs: dict[str, Any],
    episodes: int = 64,
    *,
    n_envs: int = 16,
    seed: int = 1_000_000,
) -> float:
    """The fraction of episodes won by ``policy`` (an SB3 policy or model, played
    deterministically; ``None`` plays the oracle) on a native vector env of ``env_id`` with
    ``env_kwargs``: ``n_envs`` sub-environments seeded ``seed + i``, each playing
    ``ceil(episodes / n_envs)`` whole episodes (so the count is not biased toward short
    episodes)."""
    n = max(1, min(int(n_envs), int(episodes)))
    per = math.ceil(episodes / n)
    venv = gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point", **env_kwargs)
    actor = OraclePolicy(venv) if policy is None else policy
    obs, _ = venv.reset(seed=seed)
    done = np.zeros(n, dtype=int)
    wins = np.zeros(n, dtype=int)
    ended = np.zeros(n, dtype=bool)
    while (done < per).any():
        if isinstance(actor, OraclePolicy):
            act, _ = actor.predict(obs)
        else:
            act, _ = actor.predict(obs, deterministic=True)
        obs, _, term, trunc, info = venv.step(np.asarray(act, dtype=np.float32))
        fin = (term | trunc) & ~ended & (done < per)
        ended = term | trunc
        if fin.any():
            wins += fin & np.asarray(info.get("is_success", np.zeros(n, bool)), dtype=bool)
            done += fin
    venv.close()
    return float(wins.sum() / done.sum())


# ---------------------------------------------------------------------------------------------
# the training entry
# ---------------------------------------------------------------------------------------------


def load_config(env_id: str, config: str | Path | None = None) -> dict[str, Any]:
    """The section for ``env_id`` of the imitation config (default ``CONFIG``), with the
    keys ``algo`` (``ppo``), ``n_envs``, ``env_kwargs`` (training env), ``eval_env_kwargs``,
    ``policy_kwargs``, ``ppo`` (PPO constructor arguments), ``bc``, ``dagger`` and
    ``finetune`` (see the YAML file)."""
    path = Path(config) if config is not None else CONFIG
    if not path.is_file():
        raise FileNotFoundError(f"no imitation config {path}")
    data = yaml.safe_load(path.read_text()) or {}
    if env_id in data:
        return copy.deepcopy(data[env_id])
    if "env_id" in data and "config" in data:  # a resolved run config
        return copy.deepcopy(data["config"])
    raise KeyError(f"{path} has no section for {env_id!r} (sections: {', '.join(data)})")


class _WallClock(BaseCallback):
    """Stops ``learn`` once ``time.perf_counter()`` passes ``deadline``."""

    def __init__(self, deadline: float | None) -> None:
        super().__init__()
        self.deadline = deadline

    def _on_step(self) -> bool:
        return self.deadline is None or time.perf_counter() < self.deadline


def _model(cfg: dict, venv_sb3, seed: int):
    kw = dict(cfg.get("ppo") or {})
    pk = dict(cfg.get("policy_kwargs") or {})
    if "activation_fn" in pk:
        pk["activation_fn"] = _activation(pk["activation_fn"])
    algo = str(cfg.get("algo", "ppo")).lower()
    if algo != "ppo":
        raise ValueError(f"train_imitation fine-tunes PPO models; got algo {algo!r}")
    return algo_class(algo)(
        "MlpPolicy", venv_sb3, seed=seed, verbose=0, device="cpu", policy_kwargs=pk, **kw
    )


def train_imitation(
    env_id: str,
    method: str = "dagger",
    *,
    config: str | Path | None = None,
    seed: int = 0,
    out: str | Path | None = None,
    wall_s: float | None = None,
    overrides: dict[str, Any] | None = None,
    verbose: int = 1,
) -> dict[str, Any]:
    """Train a PPO policy on ``env_id`` by ``method`` (one of :data:`METHODS`) and save it as
    ``<out>/final_model.zip`` (+ ``best_model.zip``, the same model, and the resolved
    ``.yaml`` beside each).  ``wall_s``: a wall-clock budget (seconds) for the whole run --
    DAgger stops after the iteration that passes its share, PPO ``learn`` stops when the
    budget is spent -- so methods compare at equal wall time.  ``overrides``: a dict merged
    into the config section (one level deep).  Returns the resolved record (also written as
    YAML)."""
    if method not in METHODS:
        raise ValueError(f"method must be one of {', '.join(METHODS)}, got {method!r}")
    cfg = load_config(env_id, config)
    for k, v in (overrides or {}).items():
        if isinstance(v, dict) and isinstance(cfg.get(k), dict):
            cfg[k].update(v)
        else:
            cfg[k] = v
    torch.set_num_threads(int(cfg.get("torch_threads", 1)))
    out = (
        Path(out)
        if out is not None
        else Path("runs")
        / (f"{method.replace('+', '_')}_{env_id.split('/')[-1].split('-v')[0].lower()}_s{seed}")
    )
    out.mkdir(parents=True, exist_ok=True)
    n_envs = int(cfg.get("n_envs", 64))
    env_kwargs = dict(cfg.get("env_kwargs") or {})
    log = print if verbose else None
    t0 = time.perf_counter()
    deadline = None if wall_s is None else t0 + float(wall_s)
    venv = gym.make_vec(
        env_id, num_envs=n_envs, vectorization_mode="vector_entry_point", **env_kwargs
    )
    sb3_env = BatchedVecEnv(venv)
    sb3_env.seed(seed)
    model = _model(cfg, sb3_env, seed)
    record: dict[str, Any] = {
        "algo": "ppo",
        "method": method,
        "env_id": env_id,
        "env_kwargs": env_kwargs,
        "seed": int(seed),
        "n_envs": n_envs,
        "wall_budget_s": wall_s,
        "config": cfg,
        "command": " ".join(
            ["sensorplan", "imitate", "--env", env_id, "--method", method, "--seed", str(seed)]
            + (["--config", str(config)] if config else [])
            + (["--wall-s", str(wall_s)] if wall_s else [])
            + (["--overrides", json.dumps(overrides)] if overrides else [])
        ),
    }
    loss = str(cfg.get("loss", "mse"))
    if method in ("bc", "dagger", "dagger+ppo"):
        d = dict(cfg.get("dagger") or {})
        if method == "bc":  # one iteration of pure oracle rollouts: behaviour cloning
            d = {**d, **(cfg.get("bc") or {}), "iterations": 1, "beta0": 1.0}
        share = float(cfg.get("imitation_share", 0.5)) if method == "dagger+ppo" else 1.0
        dl = None if wall_s is None else t0 + share * float(wall_s)
        res = dagger(
            venv,
            model.policy,
            iterations=int(d.get("iterations", 6)),
            steps=int(d.get("steps", 64)),
            beta0=float(d.get("beta0", 1.0)),
            decay=float(d.get("decay", 0.5)),
            epochs=int(d.get("epochs", 10)),
            batch_size=int(d.get("batch_size", 256)),
            learning_rate=float(d.get("learning_rate", 1e-3)),
            loss=loss,
            seed=seed,
            max_pairs=d.get("max_pairs"),
            deadline=dl,
            log=log,
            expert=str(cfg.get("expert", "oracle")),
        )
        record["imitation"] = res.history
        record["imitation_s"] = round(time.perf_counter() - t0, 1)
        if method != "dagger+ppo":  # the fit sets the mean only: a narrow spread to keep
            with torch.no_grad():
                model.policy.log_std.fill_(float(d.get("log_std", IMITATED_LOG_STD)))
    if method in ("dagger+ppo", "ppo"):
        ft = dict(cfg.get("finetune") or {})
        if method == "dagger+ppo" and ft.get("log_std") is not None:
            with torch.no_grad():  # the imitated mean, with a chosen exploration noise
                model.policy.log_std.fill_(float(ft["log_std"]))
        steps = int(ft.get("timesteps", 1_000_000))
        sb3_env.seed(seed + 1)
        model.set_env(sb3_env)
        t1 = time.perf_counter()
        model.learn(total_timesteps=steps, callback=_WallClock(deadline), reset_num_timesteps=True)
        record["ppo_timesteps"] = int(model.num_timesteps)
        record["ppo_s"] = round(time.perf_counter() - t1, 1)
        if log:
            log(f"ppo: {model.num_timesteps} steps in {record['ppo_s']} s")
    record["wall_time_s"] = round(time.perf_counter() - t0, 1)
    venv.close()
    ev = dict(cfg.get("eval") or {})
    if ev.get("episodes"):
        eval_kw = {**env_kwargs, **(cfg.get("eval_env_kwargs") or {})}
        record["success_rate"] = success_rate(
            model.policy, env_id, eval_kw, int(ev["episodes"]), seed=1_000_000 + seed
        )
        if log:
            log(f"success {record['success_rate']:.3f} over {ev['episodes']} episodes {eval_kw}")
    model.save(out / "final_model.zip")
    shutil.copyfile(out / "final_model.zip", out / "best_model.zip")
    for name in ("final_model.yaml", "best_model.yaml"):
        with open(out / name, "w") as f:
            f.write(f"# resolved config written by sensorplan imitate ({time.strftime('%F')})\n")
            yaml.safe_dump(_plain(record), f, sort_keys=False)
    record["out"] = str(out)
    return record


def _plain(x: Any) -> Any:
    """``x`` with numpy scalars made Python numbers (for YAML)."""
    if isinstance(x, dict):
        return {k: _plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_plain(v) for v in x]
    if isinstance(x, np.generic):
        return x.item()
    return x
