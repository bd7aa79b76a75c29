"""A larger minibatch and fewer epochs: what they do to PPO's cost *and* success.

``python -m benchmarks.train_study [--configs 128x10 512x5 2048x3] [--timesteps 800000]
[--seed 1] [--out DIR | --update-results]``

Trains PPO on Navigate-v0's random-scene pool with the shipped model's settings
(``agents/pretrained/ppo_navigate_random.yaml``: 64 batched envs x 32 steps per rollout, MLP
128-128) and each ``minibatch x epochs`` configuration, one after the other, each in its own
process (``sensorplan train``), and records per configuration: the CPU seconds of the training
process (user + system, children included: what the machine's load does not change much), the
wall seconds, and the success rate of the periodic evaluations (100 episodes every 100,000
steps on the training pool's evaluation seeds; ``evaluations.npz``).  Same seed, same pool,
same rollouts: only the update differs.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from . import _results

ENV_KWARGS = {
    "scene": "random",
    "min_start_distance": 0.35,
    "max_scene_tries": 200,
    "random_start": False,
}
NET = {"net_arch": [128, 128], "activation_fn": "tanh"}


def _cmd(batch: int, epochs: int, timesteps: int, seed: int, out: Path) -> list[str]:
    return [
        sys.executable,
        "-m",
        "agents",
        "train",
        "--env",
        "sensorplan/Navigate-v0",
        "--algo",
        "ppo",
        "--timesteps",
        str(timesteps),
        "--seed",
        str(seed),
        "--n-envs",
        "64",
        "--env-kwargs",
        json.dumps(ENV_KWARGS),
        "--hp",
        "n_steps=32",
        f"batch_size={batch}",
        f"n_epochs={epochs}",
        f"policy_kwargs={json.dumps(NET)}",
        "eval_freq=100000",
        "n_eval_episodes=100",
        "--out",
        str(out),
        "--no-progress",
        "--no-tensorboard",
        "--threads",
        "1",
    ]


def run_one(batch: int, epochs: int, timesteps: int, seed: int, tmp: Path) -> dict[str, Any]:
    """Train one configuration in a child process; its costs and evaluation curve."""
    out = tmp / f"b{batch}_e{epochs}"
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run(
        _cmd(batch, epochs, timesteps, seed, out),
        check=True,
        stdout=subprocess.DEVNULL,
        env={**os.environ, "PYTHONHASHSEED": "0"},
    )
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    ev = np.load(out / "evaluations.npz")
    return {
        "batch_size": batch,
        "n_epochs": epochs,
        "timesteps": timesteps,
        "seed": seed,
        "cpu_s": round((after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime), 1),
        "wall_s": round(wall, 1),
        "eval_timesteps": [int(t) for t in ev["timesteps"]],
        "eval_success": [float(s) for s in ev["successes"].mean(axis=1)],
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.train_study", description=__doc__)
    ap.add_argument("--configs", nargs="+", default=["128x10", "512x5", "2048x3"])
    ap.add_argument("--timesteps", type=int, default=800_000)
    ap.add_argument("--seed", type=int, default=1)
    _results.add_output_args(ap, "train_study")
    a = ap.parse_args(argv)
    try:
        configs = [tuple(int(v) for v in c.split("x")) for c in a.configs]
    except ValueError:
        ap.error("--configs: give minibatch x epochs pairs such as 512x5")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for batch, epochs in configs:
            print(f"minibatch {batch} x {epochs} epochs ...", flush=True)
            rows.append(run_one(batch, epochs, a.timesteps, a.seed, Path(tmp)))
    data = {
        "command": _results.command("benchmarks.train_study", argv),
        "machine": _results.machine(),
        "rows": rows,
    }
    print(render(data))
    _results.write("train_study", data, a.out, a.update_results)
    return 0


def render(data: dict[str, Any]) -> str:
    """The page fragment: cost relative to the first configuration, and success."""
    base = data["rows"][0]["cpu_s"]
    lines = [
        "| minibatch × epochs | CPU s | CPU vs first | wall s | eval success (best) | "
        "eval success (last) | success at each evaluation |",
        "| --- | ---: | ---: | ---: | ---: | ---: | --- |",
    ]
    for r in data["rows"]:
        s = r["eval_success"]
        curve = " ".join(f"{v:.2f}" for v in s)
        lines.append(
            f"| {r['batch_size']} × {r['n_epochs']} | {r['cpu_s']:,.0f} | "
            f"{r['cpu_s'] / base:.2f} | {r['wall_s']:,.0f} | {max(s):.2f} | {s[-1]:.2f} | "
            f"{curve} |"
        )
    m = data["machine"]
    r0 = data["rows"][0]
    lines += [
        "",
        f"PPO on Navigate-v0 random scenes, {r0['timesteps']:,} steps, seed {r0['seed']}, one "
        f"run per configuration (evaluations: 100 episodes every 100,000 steps).  "
        f"{m['cpus']} CPUs, load {m['load_average']}.  Command: `{data['command']}`",
    ]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    raise SystemExit(main())
