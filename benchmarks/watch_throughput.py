"""Throughput of the watch task per agent against the single-agent envs, in the same run.

``python -m benchmarks.watch_throughput [--scene lab] [--steps 2000] [--repeats 5]``

Every env is stepped with uniform random actions (drawn before timing) for ``--steps`` steps
(episodes restart on their own as they end), ``--repeats`` times, interleaved, and the median
wall time is kept.  Reported: env steps/s, agent steps/s (env steps x watchers) and the ratio
of agent steps/s to Navigate-v0's env steps/s (the anchor, measured in the same run).  Writes
``benchmarks/results/watch_throughput.md``.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np


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
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "watch_throughput.md"))
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
    anchor = a.steps / statistics.median(times["Navigate-v0 (anchor)"])
    lines = [
        f"Random actions, scene `{a.scene}`, {a.steps} steps x {a.repeats} repeats (median), "
        "complete model, 16 beams.",
        "",
        "| env | env steps/s | agents | agent steps/s | agent steps/s vs Navigate-v0 |",
        "| --- | ---: | ---: | ---: | ---: |",
    ]
    for k, (_run, n) in runners.items():
        sps = a.steps / statistics.median(times[k])
        lines.append(f"| {k} | {sps:,.0f} | {n} | {sps * n:,.0f} | {sps * n / anchor:.2f} |")
    text = "\n".join(lines)
    print(text)
    Path(a.out).parent.mkdir(parents=True, exist_ok=True)
    Path(a.out).write_text(
        "# watch_v0 throughput\n\n`python -m benchmarks.watch_throughput`\n\n" + text + "\n"
    )
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
