"""Multi-agent PPO for the watch task with RLlib: one policy shared by every watcher.

``sensorplan train --backend rllib [--config agents/configs/rllib_watch.yaml] [--seed S]
[--iterations N] [--address ADDR] [--out DIR]`` (or ``python -m agents.learning.rllib_train ...``)
trains on ``sensorplan_gym.watch_v0.parallel_env(**config["env"])`` through RLlib's
``ParallelPettingZooEnv`` wrapper; every watcher maps to the module ``"shared"`` (parameter
sharing).  Without ``--address`` a local Ray instance is started (``num_cpus`` = the env
runners + 1); with it, the run attaches to an existing Ray cluster (``"auto"`` on a node of
the cluster, or ``ray://<head>:10001``) and the env runners are scheduled on its nodes --
sensorplan-gym must be installed on every node.

Writes to ``--out`` (default ``runs/rllib_watch_s<seed>``): ``config.yaml`` (the resolved
config, with the seed and the Ray/RLlib version), ``progress.jsonl`` (one line per iteration:
env steps, mean episode return, wall time) and ``checkpoint/`` (``algo.save``).
:class:`RLlibWatchPolicy` loads the shared module from such a checkpoint for evaluation
(``python -m agents.evaluation.watch --policy runs/.../checkpoint``).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from ..checks import absolute_path, check_writable_dir, missing_extra_message

__all__ = ["ENV_NAME", "RLlibWatchPolicy", "build_config", "load_config", "train_rllib"]

ENV_NAME = "sensorplan_watch_v0"
DEFAULT_CONFIG = Path(__file__).resolve().parent.parent / "configs" / "rllib_watch.yaml"
MODULE_ID = "shared"


def load_config(path: str | Path | dict | None = None) -> dict[str, Any]:
    """The training config: a YAML file (default ``agents/configs/rllib_watch.yaml``) or an
    already loaded dict (copied)."""
    import copy

    import yaml

    if isinstance(path, dict):
        cfg, p = copy.deepcopy(path), "config dict"
    else:
        p = Path(path) if path is not None else DEFAULT_CONFIG
        if not p.is_file():
            raise FileNotFoundError(f"RLlib config not found: {p}")
        with open(p) as f:
            cfg = yaml.safe_load(f)
    if not isinstance(cfg, dict):
        raise ValueError(f"{p}: not a mapping")
    for key in ("env", "ppo", "model", "runners"):
        if not isinstance(cfg.get(key), dict):
            raise ValueError(f"{p}: section {key!r} missing or not a mapping")
    return cfg


def _env_creator(env_config: dict):
    from ray.rllib.env.wrappers.pettingzoo_env import ParallelPettingZooEnv

    from sensorplan_gym import watch_v0

    return ParallelPettingZooEnv(watch_v0.parallel_env(**dict(env_config)))


def build_config(cfg: dict[str, Any], seed: int):
    """The RLlib ``PPOConfig`` of a training config dict (multi-agent, one shared module)."""
    from ray.rllib.algorithms.ppo import PPOConfig
    from ray.rllib.core.rl_module.multi_rl_module import MultiRLModuleSpec
    from ray.rllib.core.rl_module.rl_module import RLModuleSpec
    from ray.tune.registry import register_env

    register_env(ENV_NAME, _env_creator)
    return (
        PPOConfig()
        .environment(ENV_NAME, env_config=dict(cfg["env"]))
        .env_runners(**cfg["runners"])
        .multi_agent(
            policies={MODULE_ID},
            policy_mapping_fn=lambda agent_id, *args, **kwargs: MODULE_ID,
        )
        .rl_module(
            rl_module_spec=MultiRLModuleSpec(
                rl_module_specs={MODULE_ID: RLModuleSpec(model_config=dict(cfg["model"]))}
            )
        )
        .training(**cfg["ppo"])
        .debugging(seed=int(seed))
    )


def _num(v: Any) -> float | None:
    """A metric as a float, ``None`` when RLlib reports none (missing or NaN: e.g. no
    episode finished in that iteration); JSON has no NaN."""
    try:
        f = float(v)
    except (TypeError, ValueError):
        return None
    return f if math.isfinite(f) else None


def train_rllib(
    config: str | Path | dict | None = None,
    *,
    seed: int = 0,
    iterations: int | None = None,
    address: str | None = None,
    out: str | Path | None = None,
    env_kwargs: dict | None = None,
    verbose: bool = True,
) -> dict[str, Any]:
    """Train (see the module docstring); returns ``{"out", "checkpoint", "progress",
    "wall_s"}``.  A Ray instance already initialised by the caller (e.g. a test's
    ``ray.init(num_cpus=2)``) is used as it is."""
    try:
        import ray
    except ImportError as e:
        raise ImportError(
            "--backend rllib needs Ray RLlib and PettingZoo: pip install -e '.[multi]'",
            name=e.name or "ray",
        ) from None
    import yaml

    cfg = load_config(config)
    if env_kwargs:
        cfg["env"] = {**cfg["env"], **env_kwargs}
    n_iter = int(iterations if iterations is not None else cfg.get("iterations", 10))
    if n_iter < 1:
        raise ValueError(f"iterations must be positive, got {n_iter}")
    outdir = Path(out) if out is not None else Path("runs") / f"rllib_watch_s{seed}"
    check_writable_dir(outdir)
    outdir.mkdir(parents=True, exist_ok=True)
    started_here = False
    if not ray.is_initialized():
        if address:
            ray.init(address=address, log_to_driver=False)
        else:
            n_cpus = int(cfg["runners"].get("num_env_runners", 1)) + 1
            ray.init(num_cpus=n_cpus, include_dashboard=False, log_to_driver=False)
        started_here = True
    resolved = {
        **cfg,
        "seed": int(seed),
        "iterations": n_iter,
        "ray_version": ray.__version__,
        "address": address,
    }
    with open(outdir / "config.yaml", "w") as f:
        yaml.safe_dump(resolved, f, sort_keys=False)
    t0 = time.perf_counter()
    algo = build_config(cfg, seed).build_algo()
    progress = []
    try:
        with open(outdir / "progress.jsonl", "w") as f:
            for it in range(1, n_iter + 1):
                r = algo.train()
                er = r.get("env_runners", {})
                row = {
                    "iteration": it,
                    "env_steps": _num(r.get("num_env_steps_sampled_lifetime")),
                    "episode_return_mean": _num(er.get("episode_return_mean")),
                    "episodes": _num(er.get("num_episodes")),
                    "wall_s": round(time.perf_counter() - t0, 2),
                }
                progress.append(row)
                f.write(json.dumps(row) + "\n")
                f.flush()
                if verbose:
                    ret = row["episode_return_mean"]
                    print(
                        f"iter {it:3d}  env steps {row['env_steps'] or 0:8.0f}  "
                        f"return (all watchers) {'-' if ret is None else f'{ret:7.3f}'}  "
                        f"{row['wall_s']:7.1f} s",
                        flush=True,
                    )
        ckpt = Path(algo.save(str((outdir / "checkpoint").resolve())).checkpoint.path)
    finally:
        algo.stop()
        if started_here:
            ray.shutdown()
    return {
        "out": str(outdir),
        "checkpoint": str(ckpt),
        "progress": progress,
        "wall_s": round(time.perf_counter() - t0, 2),
    }


class RLlibWatchPolicy:
    """Deterministic actions (the Gaussian's mean, clipped to [-1, 1]) of the shared module of
    an RLlib checkpoint written by :func:`train_rllib`, for every watcher at once.  Picklable
    (holds the path; the module is loaded on first use), so Ray evaluation workers load it
    themselves."""

    def __init__(self, checkpoint: str | Path) -> None:
        p = absolute_path(checkpoint)  # RLlib reads a bare relative path as a URI
        mod = p / "learner_group" / "learner" / "rl_module" / MODULE_ID
        if not mod.is_dir():
            raise FileNotFoundError(f"no RLlib module {MODULE_ID!r} under {p} (expected {mod})")
        self.path = str(mod)
        self._module = None

    def __getstate__(self) -> dict:
        return {"path": self.path, "_module": None}

    def reset(self) -> None:  # stateless (no recurrent state)
        return None

    def act(self, observations: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        import torch

        if self._module is None:
            from ray.rllib.core.rl_module.rl_module import RLModule

            torch.set_num_threads(1)  # one small MLP forward per step: threads only contend

            self._module = RLModule.from_checkpoint(self.path)
        agents = list(observations)
        if not agents:
            return {}
        obs = torch.from_numpy(np.stack([observations[a] for a in agents]).astype(np.float32))
        with torch.no_grad():
            out = self._module.forward_inference({"obs": obs})
        logits = out["action_dist_inputs"].numpy()
        mean = logits[:, : logits.shape[1] // 2]  # [mean | log_std] of the diagonal Gaussian
        acts = np.clip(mean, -1.0, 1.0).astype(np.float32)
        return {a: acts[i] for i, a in enumerate(agents)}


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m agents.learning.rllib_train", description=__doc__)
    ap.add_argument("--config", default=None)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--iterations", type=int, default=None)
    ap.add_argument("--address", default=None)
    ap.add_argument("--out", default=None)
    ap.add_argument("--env-kwargs", type=json.loads, default=None)
    a = ap.parse_args(argv)
    try:
        res = train_rllib(
            a.config,
            seed=a.seed,
            iterations=a.iterations,
            address=a.address,
            out=a.out,
            env_kwargs=a.env_kwargs,
        )
    except ImportError as err:
        msg = missing_extra_message(ap.prog, err)
        if msg is None:
            raise
        print(msg, file=sys.stderr)
        return 2
    except (ValueError, OSError) as err:
        print(f"{ap.prog}: error: {err}", file=sys.stderr)
        return 2
    print(f"checkpoint: {res['checkpoint']}  ({res['wall_s']:.0f} s)")
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
