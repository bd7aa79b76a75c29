"""Where ``sensorplan train``'s time goes: a profile per shipped configuration.

``python -m benchmarks.train_profile [--cases NAME ...] [--timesteps-scale S]
[--out DIR | --update-results]``

Each case trains with the hyperparameters of a shipped model (``agents/pretrained/*.yaml``)
or of a config section (``agents/configs/*.yaml``) under :mod:`cProfile`, with the periodic
evaluation, the progress bar and tensorboard off (they are not the learner's work), and splits
the wall time into

* **env step** -- the vector env's ``step`` (the batched core, its observation arrays and
  SB3's VecMonitor/VecEnv glue),
* **policy (rollout)** -- the policy's forward passes while collecting (``predict`` /
  ``forward``),
* **buffer + callbacks** -- the rest of ``collect_rollouts`` (rollout/replay buffer adds,
  ``obs_as_tensor``, callbacks, info dicts),
* **learner update** -- the algorithm's ``train()`` (the gradient work: minibatches,
  backward passes, optimizer steps),
* **setup + other** -- env and model construction, pools, saving.

The *config study* cases train PPO on Navigate-v0 random scenes with the shipped model's
settings but a larger minibatch and fewer epochs, to show what the update's share does to the
wall time (success needs full-length runs: ``sensorplan train`` with the same ``--hp`` and the
shipped timesteps; their results are quoted on the performance page with their commands).

The fractions are measured under cProfile (which slows Python calls, the env's more than
torch's kernels), so the wall times are upper bounds; steps/s is also measured without the
profiler in the same run.
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import statistics
import tempfile
import time
from pathlib import Path
from typing import Any

import yaml

from . import _results

ROOT = Path(__file__).resolve().parent.parent
PRETRAINED = ROOT / "agents" / "pretrained"

#: name -> (algo, env id, source of the hyperparameters, timesteps, hp overrides)
CASES: dict[str, tuple[str, str, str, int, dict[str, Any]]] = {
    "ppo-navigate-random": (
        "ppo",
        "sensorplan/Navigate-v0",
        "pretrained:ppo_navigate_random",
        65_536,
        {},
    ),
    "ppo-recognize-random": (
        "ppo",
        "sensorplan/Recognize-v0",
        "pretrained:ppo_recognize_random",
        65_536,
        {},
    ),
    "sac-navigate-lab": ("sac", "sensorplan/Navigate-v0", "config", 4_000, {}),
    "ppo-navigate-random batch 512 x 5 epochs": (
        "ppo",
        "sensorplan/Navigate-v0",
        "pretrained:ppo_navigate_random",
        65_536,
        {"batch_size": 512, "n_epochs": 5},
    ),
    "ppo-navigate-random batch 2048 x 3 epochs": (
        "ppo",
        "sensorplan/Navigate-v0",
        "pretrained:ppo_navigate_random",
        65_536,
        {"batch_size": 2048, "n_epochs": 3},
    ),
}

#: (bucket, file suffix, function name) of the profiled functions (cumulative times)
_FUNCS = {
    "collect": [
        ("on_policy_algorithm.py", "collect_rollouts"),
        ("off_policy_algorithm.py", "collect_rollouts"),
    ],
    "env": [("base_vec_env.py", "step")],
    "policy": [
        ("policies.py", "forward"),  # PPO: ActorCriticPolicy.forward in collect_rollouts
        ("off_policy_algorithm.py", "_sample_action"),
    ],
    "train": [("ppo.py", "train"), ("sac.py", "train")],
}


def _settings(source: str, algo: str, env_id: str) -> tuple[dict, dict, int]:
    """(hp overrides incl. env_kwargs, n_envs ...), vec env name, n_envs of a case."""
    if source.startswith("pretrained:"):
        cfg = yaml.safe_load((PRETRAINED / f"{source.split(':', 1)[1]}.yaml").read_text())
        hp = dict(cfg["hyperparams"])
        hp["env_kwargs"] = cfg["env_kwargs"]
        hp["n_envs"] = cfg["n_envs"]
        hp["vec_env"] = cfg.get("vec_env", "batched")
        return hp, cfg["env_kwargs"], int(cfg["n_envs"])
    from agents.learning.train import load_hyperparams

    hp = load_hyperparams(algo, env_id, None)
    return {}, hp.get("env_kwargs") or {}, int(hp.get("n_envs", 1))


def _cum(stats: pstats.Stats, bucket: str) -> float:
    """Summed cumulative seconds of the bucket's functions (outermost calls only: cProfile's
    cumulative time already excludes recursive re-entries)."""
    total = 0.0
    for (file, _line, func), (_cc, _nc, _tt, ct, _callers) in stats.stats.items():  # type: ignore[attr-defined]
        for suffix, name in _FUNCS[bucket]:
            if func == name and file.endswith(suffix) and "stable_baselines3" in file:
                total += ct
    return total


def _train(algo: str, env_id: str, source: str, timesteps: int, extra: dict, out: Path) -> None:
    from agents.learning.train import train

    hp, _kw, n_envs = _settings(source, algo, env_id)
    hp.update(extra)
    train(
        env_id,
        algo,
        timesteps=timesteps,
        seed=0,
        n_envs=n_envs,
        out=out,
        eval_freq=10**12,
        eval_episodes=1,
        progress_bar=False,
        tensorboard=False,
        verbose=0,
        hp_overrides=hp,
    )


def measure(name: str, scale: float, repeats: int) -> dict[str, Any]:
    """One case: profiled buckets (seconds) and unprofiled wall times (median of
    ``repeats``)."""
    algo, env_id, source, timesteps, extra = CASES[name]
    steps = max(256, int(timesteps * scale))
    with tempfile.TemporaryDirectory() as tmp:
        walls = []
        for r in range(repeats):
            t0 = time.perf_counter()
            _train(algo, env_id, source, steps, extra, Path(tmp) / f"plain{r}")
            walls.append(time.perf_counter() - t0)
        prof = cProfile.Profile()
        t0 = time.perf_counter()
        prof.enable()
        _train(algo, env_id, source, steps, extra, Path(tmp) / "profiled")
        prof.disable()
        wall_prof = time.perf_counter() - t0
    st = pstats.Stats(prof)
    collect, env, policy, upd = (_cum(st, b) for b in ("collect", "env", "policy", "train"))
    return {
        "case": name,
        "algo": algo,
        "env_id": env_id,
        "hyperparams_from": source,
        "overrides": extra,
        "timesteps": steps,
        "wall_s": statistics.median(walls),
        "profiled_wall_s": wall_prof,
        "seconds": {
            "env step": env,
            "policy (rollout)": policy,
            "buffer + callbacks": max(0.0, collect - env - policy),
            "learner update": upd,
            "setup + other": max(0.0, wall_prof - collect - upd),
        },
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.train_profile", description=__doc__)
    ap.add_argument("--cases", nargs="+", choices=sorted(CASES), default=list(CASES))
    ap.add_argument(
        "--timesteps-scale",
        type=float,
        default=1.0,
        help="multiply every case's timesteps (default 1: 65,536 PPO / 4,000 SAC steps)",
    )
    ap.add_argument("--repeats", type=int, default=1, help="unprofiled runs per case")
    _results.add_output_args(ap, "train_profile")
    a = ap.parse_args(argv)
    import torch

    torch.set_num_threads(1)
    rows = []
    for name in a.cases:
        print(f"{name} ...", flush=True)
        rows.append(measure(name, a.timesteps_scale, a.repeats))
    data = {
        "command": _results.command("benchmarks.train_profile", argv),
        "machine": _results.machine(),
        "rows": rows,
    }
    print(render(data))
    _results.write("train_profile", data, a.out, a.update_results)
    return 0


def render(data: dict[str, Any]) -> str:
    """The page fragment: steps/s and the share of each part of the profiled wall time."""
    buckets = list(data["rows"][0]["seconds"])
    lines = [
        "| case | steps | env steps/s | " + " | ".join(buckets) + " |",
        "| --- | ---: | ---: | " + " | ".join("---:" for _ in buckets) + " |",
    ]
    for r in data["rows"]:
        tot = r["profiled_wall_s"]
        shares = " | ".join(f"{100 * r['seconds'][b] / tot:.0f} %" for b in buckets)
        lines.append(
            f"| {r['case']} | {r['timesteps']:,} | {r['timesteps'] / r['wall_s']:,.0f} | {shares} |"
        )
    m = data["machine"]
    lines += [
        "",
        f"Shares of the wall time under cProfile; steps/s without it (median).  "
        f"{m['cpus']} CPUs, load {m['load_average']}, torch 1 thread.  "
        f"Command: `{data['command']}`",
    ]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    raise SystemExit(main())
