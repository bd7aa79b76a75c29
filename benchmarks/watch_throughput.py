"""Throughput of the watch task per agent against the single-agent envs, in the same run.

``python -m benchmarks.watch_throughput [--scene lab] [--steps 2000] [--repeats 5]``

Every env is stepped with uniform random actions (drawn before timing) for ``--steps`` steps
(episodes restart on their own as they end), ``--repeats`` times, interleaved, and the median
wall time is kept.  Reported: env steps/s, agent steps/s (env steps x watchers) and the ratio
of agent steps/s to Navigate-v0's env steps/s (the anchor, measured in the same run).  Writes
the data and the page fragment to ``--out`` (default ``runs/benchmarks/watch_throughput/``), or
with ``--update-results`` to ``benchmarks/results/watch_throughput.json`` and
``docs/results/watch_throughput.md``.
"""

from __future__ import annotations

import argparse
import statistics
import time
from typing import Any

import numpy as np

from . import _results


def _gym_runner(env_id: str, scene: str, steps: int):
    import gymnasium as gym

    import sensorplan_gym  # noqa: F401

    env = gym.make(env_id, scene=scene)
    env.reset(seed=0)
    rng = np.random.default_rng(0)
    acts = rng.uniform(-1, 1, (steps, *env.action_space.shape)).astype(np.float32)
    # never declare in Recognize/Watch: episodes run their full length
    if acts.shape[1] == 4:
        acts[:, 3] = 0.0

    def run() -> float:
        env.reset(seed=1)
        t0 = time.perf_counter()
        for a in acts:
            _, _, term, trunc, _ = env.step(a)
            if term or trunc:
                env.reset()
        return time.perf_counter() - t0

    return run, 1


def _watch_runner(scene: str, n: int, steps: int):
    from sensorplan_gym import watch_v0

    env = watch_v0.parallel_env(scene=scene, n_watchers=n)
    rng = np.random.default_rng(0)
    acts = rng.uniform(-1, 1, (steps, n, 4)).astype(np.float32)
    acts[:, :, 3] = 0.0
    names = env.possible_agents

    def run() -> float:
        env.reset(seed=1)
        t0 = time.perf_counter()
        for a in acts:
            env.step({k: a[i] for i, k in enumerate(names)})
            if not env.agents:
                env.reset()
        return time.perf_counter() - t0

    return run, n


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.watch_throughput")
    ap.add_argument("--scene", default="lab")
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--repeats", type=int, default=5)
    _results.add_output_args(ap, "watch_throughput")
    a = ap.parse_args(argv)
    runners = {
        "Navigate-v0 (anchor)": _gym_runner("sensorplan/Navigate-v0", a.scene, a.steps),
        "Recognize-v0": _gym_runner("sensorplan/Recognize-v0", a.scene, a.steps),
        "Watch-v0 (gym, 1 watcher)": _gym_runner("sensorplan/Watch-v0", a.scene, a.steps),
        "watch_v0, 1 watcher": _watch_runner(a.scene, 1, a.steps),
        "watch_v0, 2 watchers": _watch_runner(a.scene, 2, a.steps),
        "watch_v0, 4 watchers": _watch_runner(a.scene, 4, a.steps),
    }
    times: dict[str, list[float]] = {k: [] for k in runners}
    for _ in range(a.repeats):  # interleaved, so that load changes hit every env alike
        for k, (run, _n) in runners.items():
            times[k].append(run())
    data: dict[str, Any] = {
        "command": _results.command("benchmarks.watch_throughput", argv),
        "machine": _results.machine(),
        "scene": a.scene,
        "steps": a.steps,
        "repeats": a.repeats,
        "rows": [
            {"env": k, "agents": n, "median_s": statistics.median(times[k])}
            for k, (_run, n) in runners.items()
        ],
    }
    print(render(data))
    _results.write("watch_throughput", data, a.out, a.update_results)
    return 0


def render(data: dict[str, Any]) -> str:
    """The page fragment: env and agent steps/s, and agent steps/s over Navigate-v0's."""
    steps = data["steps"]
    anchor = steps / data["rows"][0]["median_s"]
    lines = [
        "| env | env steps/s | agents | agent steps/s | agent steps/s vs Navigate-v0 (same run) |",
        "| --- | ---: | ---: | ---: | ---: |",
    ]
    for r in data["rows"]:
        sps = steps / r["median_s"]
        n = r["agents"]
        lines.append(f"| {r['env']} | {sps:,.0f} | {n} | {sps * n:,.0f} | {sps * n / anchor:.2f} |")
    m = data["machine"]
    lines += [
        "",
        f"`{data['command']}`: random actions on `{data['scene']}`, {steps} steps, median of "
        f"{data['repeats']} interleaved repeats; {m['cpus']} CPUs, load average "
        f"{m['load_average']} (compare the ratios).",
    ]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
