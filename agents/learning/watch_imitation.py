"""Watchers that declare: DAgger of the watch oracle on ``watch_v0`` with beam evidence.

``python -m agents.learning.watch_imitation [--config agents/configs/watch_imitation.yaml]
[--seed S] [--out DIR] [--wall-s SECONDS] [--overrides JSON]``

The recipe (issue 22 item 4):

* **Evidence features.**  The env is ``watch_v0.parallel_env(..., evidence=True)``: each
  watcher's observation ends with what its own beams have shown of A since A's plan is over
  (:mod:`sensorplan_gym.multiagent.evidence`: a beam shorter than the map's prediction ending
  in ``A (+) G`` / ``A (+) H``, and beams that crossed them) -- Recognize-v0's
  ``map_evidence``, accumulated over the episode.  Without it a memoryless policy cannot
  remember a sighting and declares at chance.
* **Imitation of the watch oracle.**  The teacher is :class:`agents.planning.watch_expert.
  WatchExpert` (the oracle's placement replanned from the current poses, a scan, and the
  declaration from the evidence); DAgger (Ross et al. 2011) lets it label the states the
  learners visit.  One policy is shared by all watchers (parameter sharing): every watcher's
  ``(observation, teacher action)`` pair is a sample of the same data set.
* The learner is a stable-baselines3 ``ActorCriticPolicy`` (an MLP; the Gaussian's mean is
  the action) fitted with :func:`agents.learning.imitation.fit` (the project's BC/DAgger
  regression, mean squared error of the deterministic action).

Collection runs ``n_envs`` envs in lock step (every episode lasts ``max_steps`` steps) so
the learner's forward pass is batched.  Writes ``<out>/final_model.pt`` (the policy,
``ActorCriticPolicy.save``) and ``<out>/final_model.yaml`` (the resolved config, the
command, the DAgger history); :class:`WatchImitationPolicy` loads them for
``python -m agents.evaluation.watch_declare --policy <out>/final_model.pt``.
Frames and units are the env's.
"""

from __future__ import annotations

import argparse
import copy
import json
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import torch
import yaml
from stable_baselines3.common.policies import ActorCriticPolicy

from sensorplan_gym.multiagent.evidence import N_EVIDENCE

from ..planning.watch_expert import WatchExpert
from .imitation import _plain, fit
from .train import _activation

__all__ = [
    "CONFIG",
    "WatchImitationPolicy",
    "collect_watch",
    "dagger_watch",
    "load_config",
    "make_env",
    "new_policy",
    "train_watch_imitation",
]

CONFIG = Path(__file__).resolve().parent.parent / "configs" / "watch_imitation.yaml"
TRAIN_SEED_BASE = 10_000_000  # training episodes' seeds (evaluation uses 1,000,000 onwards)


def load_config(config: str | Path | dict | None = None) -> dict[str, Any]:
    """The training config: a YAML file (default :data:`CONFIG`), a resolved
    ``final_model.yaml`` (its ``config`` section) or a dict (copied).  Keys: ``env_kwargs``,
    ``placement``, ``decide_window``, ``n_envs``, ``policy_kwargs``, ``dagger``,
    ``mask_evidence`` (the ablation: the learner never sees the evidence entries)."""
    if isinstance(config, dict):
        cfg = copy.deepcopy(config)
    else:
        p = Path(config) if config is not None else CONFIG
        if not p.is_file():
            raise FileNotFoundError(f"no watch imitation config {p}")
        cfg = yaml.safe_load(p.read_text()) or {}
        if "config" in cfg and "command" in cfg:
            cfg = cfg["config"]
    for key in ("env_kwargs", "dagger"):
        if not isinstance(cfg.get(key), dict):
            raise ValueError(f"watch imitation config: section {key!r} missing or not a mapping")
    return cfg


def make_env(env_kwargs: dict[str, Any]):
    """``watch_v0.parallel_env(**env_kwargs, evidence=True)``."""
    from sensorplan_gym import watch_v0

    return watch_v0.parallel_env(**{**env_kwargs, "evidence": True})


def new_policy(env, policy_kwargs: dict | None = None, seed: int = 0) -> ActorCriticPolicy:
    """A fresh SB3 ``ActorCriticPolicy`` for the (shared) spaces of ``env``'s watchers."""
    pk = dict(policy_kwargs or {})
    if "activation_fn" in pk:
        pk["activation_fn"] = _activation(pk["activation_fn"])
    torch.manual_seed(int(seed))
    agent = env.possible_agents[0]
    return ActorCriticPolicy(
        env.observation_space(agent), env.action_space(agent), lambda _: 3e-4, **pk
    )


def _act(policy: ActorCriticPolicy, obs: np.ndarray) -> np.ndarray:
    with torch.no_grad():
        a = policy._predict(torch.as_tensor(obs, dtype=torch.float32), deterministic=True)
    return np.clip(a.numpy(), -1.0, 1.0).astype(np.float32)


def collect_watch(
    envs: list,
    experts: list[WatchExpert],
    policy: ActorCriticPolicy | None,
    seeds: list[int],
    *,
    beta: float = 1.0,
    rng: np.random.Generator | None = None,
    mask_evidence: bool = False,
) -> tuple[np.ndarray, np.ndarray, dict[str, float]]:
    """Play one episode per env (``envs[j]`` reset with ``seeds[j]``), all in lock step.  On
    every step each watcher follows its teacher with probability ``beta`` and ``policy``
    (deterministic) otherwise; every visited observation is recorded with the teacher's
    action there.  Returns ``(observations (k, d), teacher actions (k, 4), stats)``, stats =
    ``episodes``, ``watcher_success`` (fraction of watchers right), ``visible`` (mean
    per-watcher fraction of steps A was seen), ``expert_fraction``.  ``mask_evidence``: the
    learner sees (and the data set records) zeros in place of the evidence entries (an
    ablation; the teacher still declares from the evidence)."""
    if not 0.0 <= beta <= 1.0:
        raise ValueError(f"beta must be in [0, 1], got {beta!r}")
    if policy is None and beta < 1.0:
        raise ValueError("collect_watch: beta < 1 needs a learner policy")
    if len(envs) != len(experts) or len(envs) != len(seeds):
        raise ValueError("collect_watch: one expert and one seed per env")
    rng = rng if rng is not None else np.random.default_rng()
    obs = [env.reset(seed=int(s))[0] for env, s in zip(envs, seeds, strict=True)]
    xs, ys = [], []
    ok, vis = [], []
    expert_steps = total = 0
    while envs[0].agents:
        agents = [list(o) for o in obs]
        labels = [ex.act(o) for ex, o in zip(experts, obs, strict=True)]
        X = np.stack([o[a] for o, ag in zip(obs, agents, strict=True) for a in ag])
        if mask_evidence:
            X[:, -N_EVIDENCE:] = 0.0
        Y = np.stack([lab[a] for lab, ag in zip(labels, agents, strict=True) for a in ag])
        use = rng.random(len(X)) < beta
        A = Y if use.all() else np.where(use[:, None], Y, _act(policy, X))
        xs.append(X)
        ys.append(Y)
        expert_steps += int(use.sum())
        total += len(X)
        k = 0
        for j, env in enumerate(envs):
            acts = {a: A[k + m] for m, a in enumerate(agents[j])}
            k += len(agents[j])
            obs[j], _, _, _, info = env.step(acts)
            if not env.agents:
                ok += [bool(i["is_success"]) for i in info.values()]
                vis += [float(i["visible_fraction"]) for i in info.values()]
    stats = {
        "episodes": len(envs),
        "watcher_success": float(np.mean(ok)),
        "visible": float(np.mean(vis)),
        "expert_fraction": expert_steps / max(total, 1),
    }
    return np.concatenate(xs), np.concatenate(ys), stats


def dagger_watch(
    env_kwargs: dict[str, Any],
    policy: ActorCriticPolicy,
    *,
    placement: str = "oracle",
    decide_window: int = 10,
    n_envs: int = 8,
    iterations: int = 8,
    episodes: int = 16,
    beta0: float = 1.0,
    decay: float = 0.5,
    epochs: int = 10,
    batch_size: int = 256,
    learning_rate: float = 1e-3,
    seed: int = 0,
    deadline: float | None = None,
    mask_evidence: bool = False,
    log=None,
) -> list[dict[str, Any]]:
    """DAgger: ``iterations`` rounds of :func:`collect_watch` (``episodes`` per round, in
    batches of ``n_envs`` envs, ``beta_i = beta0 * decay ** i``), aggregation of all pairs
    so far and :func:`agents.learning.imitation.fit` of ``policy``.  Training episodes are
    seeded ``10,000,000 + 100,000 seed + k`` (never the evaluation seeds).  ``deadline``
    (``time.perf_counter()``): stop after the round that passes it; ``mask_evidence``: as in
    :func:`collect_watch`.  Returns the per-round
    history (beta, pairs, the round's per-watcher success and visible fraction, loss, s)."""
    if iterations < 1 or episodes < 1 or n_envs < 1:
        raise ValueError("dagger_watch: iterations, episodes and n_envs must be positive")
    envs = [make_env(env_kwargs) for _ in range(min(n_envs, episodes))]
    experts = [WatchExpert(e, placement=placement, decide_window=decide_window) for e in envs]
    rng = np.random.default_rng(seed)
    xs: list[np.ndarray] = []
    ys: list[np.ndarray] = []
    history = []
    t0 = time.perf_counter()
    ep = 0
    for it in range(int(iterations)):
        beta = beta0 * decay**it
        st: list[dict] = []
        done = 0
        while done < episodes:
            m = min(len(envs), episodes - done)
            seeds = [TRAIN_SEED_BASE + 100_000 * seed + ep + j for j in range(m)]
            x, y, s = collect_watch(
                envs[:m],
                experts[:m],
                policy,
                seeds,
                beta=beta,
                rng=rng,
                mask_evidence=mask_evidence,
            )
            xs.append(x)
            ys.append(y)
            st.append(s)
            done += m
            ep += m
        X, Y = np.concatenate(xs), np.concatenate(ys)
        losses = fit(
            policy,
            X,
            Y,
            epochs=epochs,
            batch_size=batch_size,
            learning_rate=learning_rate,
            seed=seed + it,
        )
        w = [s["episodes"] for s in st]
        rec = {
            "iteration": it,
            "beta": beta,
            "total_pairs": len(X),
            "watcher_success": float(np.average([s["watcher_success"] for s in st], weights=w)),
            "visible": float(np.average([s["visible"] for s in st], weights=w)),
            "loss": float(losses[-1]),
            "wall_s": round(time.perf_counter() - t0, 1),
        }
        history.append(rec)
        if log:
            log(
                f"dagger {it}: beta {beta:.3f}, {len(X)} pairs, collected per-watcher right "
                f"{rec['watcher_success']:.3f}, visible {rec['visible']:.3f}, loss "
                f"{rec['loss']:.4f}, {rec['wall_s']} s"
            )
        if deadline is not None and time.perf_counter() > deadline:
            break
    return history


def train_watch_imitation(
    config: str | Path | dict | None = None,
    *,
    seed: int = 0,
    out: str | Path | None = None,
    wall_s: float | None = None,
    overrides: dict[str, Any] | None = None,
    verbose: bool = True,
) -> dict[str, Any]:
    """Train a shared watcher policy by DAgger of the watch oracle (see the module
    docstring) and save ``<out>/final_model.pt`` + ``<out>/final_model.yaml``.
    ``overrides``: merged into the config (one level deep).  ``wall_s``: stop DAgger after
    the round that passes this many seconds.  Returns the resolved record."""
    cfg = load_config(config)
    for k, v in (overrides or {}).items():
        if isinstance(v, dict) and isinstance(cfg.get(k), dict):
            cfg[k] = {**cfg[k], **v}
        else:
            cfg[k] = v
    torch.set_num_threads(int(cfg.get("torch_threads", 1)))
    env_kwargs = dict(cfg["env_kwargs"])
    outdir = Path(out) if out is not None else Path("runs") / f"watch_imitation_s{seed}"
    outdir.mkdir(parents=True, exist_ok=True)
    probe = make_env(env_kwargs)
    policy = new_policy(probe, cfg.get("policy_kwargs"), seed)
    probe.close()
    t0 = time.perf_counter()
    d = dict(cfg["dagger"])
    history = dagger_watch(
        env_kwargs,
        policy,
        placement=str(cfg.get("placement", "oracle")),
        decide_window=int(cfg.get("decide_window", 10)),
        n_envs=int(cfg.get("n_envs", 8)),
        iterations=int(d.get("iterations", 8)),
        episodes=int(d.get("episodes", 16)),
        beta0=float(d.get("beta0", 1.0)),
        decay=float(d.get("decay", 0.5)),
        epochs=int(d.get("epochs", 10)),
        batch_size=int(d.get("batch_size", 256)),
        learning_rate=float(d.get("learning_rate", 1e-3)),
        seed=seed,
        deadline=None if wall_s is None else t0 + float(wall_s),
        mask_evidence=bool(cfg.get("mask_evidence", False)),
        log=print if verbose else None,
    )
    record = {
        "method": "dagger",
        "env": "sensorplan_gym.watch_v0",
        "seed": int(seed),
        "config": cfg,
        "imitation": history,
        "wall_time_s": round(time.perf_counter() - t0, 1),
        "torch_version": str(torch.__version__),
        "command": " ".join(
            ["python -m agents.learning.watch_imitation", "--seed", str(seed)]
            + (["--config", str(config)] if isinstance(config, (str, Path)) else [])
            + (["--wall-s", str(wall_s)] if wall_s else [])
            + (["--overrides", f"'{json.dumps(overrides)}'"] if overrides else [])
        ),
    }
    policy.save(str(outdir / "final_model.pt"))
    with open(outdir / "final_model.yaml", "w") as f:
        f.write(f"# resolved config written by watch_imitation ({time.strftime('%F')})\n")
        yaml.safe_dump(_plain(record), f, sort_keys=False)
    record["out"] = str(outdir)
    return record


class WatchImitationPolicy:
    """Deterministic actions of a policy saved by :func:`train_watch_imitation` for every
    watcher at once (``act(observations) -> actions``, as
    :class:`agents.planning.watch_oracle.WatchOracle`).  :attr:`env_kwargs` are the env's
    keyword arguments it was trained with (``evidence=True`` included): evaluate it on an env
    built with them.  Picklable (the module is loaded on first use)."""

    def __init__(self, path: str | Path) -> None:
        p = Path(path)
        if not p.is_file():
            raise FileNotFoundError(f"no watcher policy {p}")
        y = p.with_suffix(".yaml")
        if not y.is_file():
            raise FileNotFoundError(f"no resolved config {y} beside the policy {p}")
        self.path = str(p.resolve())
        self.record = yaml.safe_load(y.read_text())
        self.env_kwargs = {**self.record["config"]["env_kwargs"], "evidence": True}
        self.mask_evidence = bool(self.record["config"].get("mask_evidence", False))
        self._policy = None

    def __getstate__(self) -> dict:
        return {**self.__dict__, "_policy": None}

    def reset(self) -> None:  # stateless: the evidence is in the observation
        return None

    def act(self, observations: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        if self._policy is None:
            torch.set_num_threads(1)
            self._policy = ActorCriticPolicy.load(self.path, device="cpu")
            self._policy.set_training_mode(False)
        agents = list(observations)
        if not agents:
            return {}
        x = np.stack([observations[k] for k in agents])
        if self.mask_evidence:  # trained blind to the evidence (the ablation)
            x[:, -N_EVIDENCE:] = 0.0
        a = _act(self._policy, x)
        return {k: a[i] for i, k in enumerate(agents)}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        prog="python -m agents.learning.watch_imitation", description=__doc__.split("\n\n")[0]
    )
    ap.add_argument("--config", default=None)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--out", default=None)
    ap.add_argument("--wall-s", type=float, default=None)
    ap.add_argument("--overrides", type=json.loads, default=None)
    a = ap.parse_args(argv)
    try:
        rec = train_watch_imitation(
            a.config, seed=a.seed, out=a.out, wall_s=a.wall_s, overrides=a.overrides
        )
    except (ValueError, KeyError, OSError) as err:
        print(f"{ap.prog}: error: {err}", file=sys.stderr)
        return 2
    print(f"policy: {rec['out']}/final_model.pt  ({rec['wall_time_s']:.0f} s)")
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
