"""Throughput of the watch task per agent against Navigate-v0 and CartPole-v1, in the same run.

``python -m benchmarks.watch_throughput [--scene lab] [--batch 256] [--seconds 0.3] [--repeats 5]``

Every env is stepped with uniform random actions (drawn before timing; the decide component
0, so that episodes run their full length) and restarts episodes as they end (single envs:
``reset()``; vector envs: their own NEXT_STEP autoresets, so A's motion planning at every
episode start is included).  Each row is timed in chunks of about ``--seconds`` (for the
watch rows, a whole number of episodes: their copies restart together), ``--repeats``
times, interleaved with the other rows (a shared, noisy machine slows them alike), and the
median rate is kept.  Reported: agent steps/s (env steps x watchers), and the ratios to
Navigate-v0's native vector env and to CartPole-v1's ``CartPoleVectorEnv`` with the same
number of rows (``--batch``), measured in the same run.

The batched watch rows are ``watch_v0.vector_env(E, n_watchers=A)`` with ``E A = --batch``
watcher rows; the "no resets" row sets ``max_steps`` beyond the timed steps, so it shows the
stepping alone.  Run against a tree without ``watch_v0.vector_env`` the batched watch rows
are skipped (for before/after comparisons).  Writes the data and the page fragment to
``--out`` (default ``runs/benchmarks/watch_throughput/``), or with ``--update-results`` to
``benchmarks/results/watch_throughput.json`` and ``docs/results/watch_throughput.md``.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable
from typing import Any

import numpy as np

from . import _results

ANCHOR = "Navigate-v0, vector"
CARTPOLE = "CartPole-v1, CartPoleVectorEnv"
N_ACTS = 512


def _gym_runner(env_id: str, period: int | None = None, **kw):
    import gymnasium as gym

    import sensorplan_gym  # noqa: F401

    env = gym.make(env_id, **kw)
    env.reset(seed=0)
    rng = np.random.default_rng(0)
    acts = rng.uniform(-1, 1, (N_ACTS, *env.action_space.shape)).astype(np.float32)
    if acts.shape[1] == 4:
        acts[:, 3] = 0.0
    pos = [0]

    def run(calls: int) -> float:
        t0 = time.perf_counter()
        for _ in range(calls):
            _, _, term, trunc, _ = env.step(acts[pos[0] % N_ACTS])
            pos[0] += 1
            if term or trunc:
                env.reset()
        return time.perf_counter() - t0

    return run, 1, period


def _vec_runner(make: Callable[[], Any], n_rows: int, declare_col: bool, period=None):
    venv = make()
    venv.reset(seed=0)
    rng = np.random.default_rng(0)
    shape = venv.single_action_space.shape
    if shape:
        acts = rng.uniform(-1, 1, (64, n_rows, *shape)).astype(np.float32)
        if declare_col and shape[0] == 4:
            acts[..., 3] = 0.0
    else:  # CartPole: discrete
        acts = rng.integers(0, 2, (64, n_rows))
    for k in range(3):  # compiles, caches
        venv.step(acts[k])
    pos = [0]

    def run(calls: int) -> float:
        t0 = time.perf_counter()
        for _ in range(calls):
            venv.step(acts[pos[0] % 64])
            pos[0] += 1
        return time.perf_counter() - t0

    return run, n_rows, period


def _watch_parallel_runner(scene: str, n: int):
    from sensorplan_gym import watch_v0

    env = watch_v0.parallel_env(scene=scene, n_watchers=n)
    rng = np.random.default_rng(0)
    acts = rng.uniform(-1, 1, (N_ACTS, n, 4)).astype(np.float32)
    acts[:, :, 3] = 0.0
    names = env.possible_agents
    env.reset(seed=1)
    pos = [0]

    def run(calls: int) -> float:
        t0 = time.perf_counter()
        for _ in range(calls):
            a = acts[pos[0] % N_ACTS]
            pos[0] += 1
            env.step({k: a[i] for i, k in enumerate(names)})
            if not env.agents:
                env.reset()
        return time.perf_counter() - t0

    return run, n, env.max_steps


def _runners(scene: str, batch: int) -> dict[str, tuple[Callable[[int], float], int, Any]]:
    import gymnasium as gym

    import sensorplan_gym  # noqa: F401
    from sensorplan_gym import watch_v0

    def vec(env_id, **kw):
        return lambda: gym.make_vec(
            env_id, num_envs=batch, vectorization_mode="vector_entry_point", **kw
        )

    r: dict[str, tuple[Callable[[int], float], int, Any]] = {
        ANCHOR: _vec_runner(vec("sensorplan/Navigate-v0", scene=scene), batch, False),
        CARTPOLE: _vec_runner(vec("CartPole-v1"), batch, False),
    }
    if hasattr(watch_v0, "vector_env"):
        for a in (1, 2, 4):
            e = batch // a
            r[f"watch_v0, vector, {e} x {a} watchers"] = _vec_runner(
                lambda e=e, a=a: watch_v0.vector_env(e, scene=scene, n_watchers=a),
                e * a,
                True,
                period=101,  # 100 steps, then the autoreset step: all copies in step
            )
        e = batch // 4
        r[f"watch_v0, vector, {e} x 4 watchers, no resets"] = _vec_runner(
            lambda: watch_v0.vector_env(e, scene=scene, n_watchers=4, max_steps=10**9),
            e * 4,
            True,
        )
    r["Navigate-v0, single env"] = _gym_runner("sensorplan/Navigate-v0", scene=scene)
    r["Watch-v0 (gym, 1 watcher)"] = _gym_runner("sensorplan/Watch-v0", 100, scene=scene)
    for a in (1, 2, 4):
        r[f"watch_v0, parallel_env, {a} watcher{'s' if a > 1 else ''}"] = _watch_parallel_runner(
            scene, a
        )
    return r


def _calls_for(run: Callable[[int], float], seconds: float, period: int | None) -> int:
    """Calls of ``run`` that take about ``seconds``; a whole number of ``period`` (the
    episode length, when every episode restarts at the same call: each chunk then holds the
    same share of resets)."""
    k = 1
    while True:
        dt = run(k)
        if dt >= seconds / 4:
            calls = max(1, round(k * seconds / dt))
            return calls if period is None else period * max(1, round(calls / period))
        k *= 4


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.watch_throughput")
    ap.add_argument("--scene", default="lab")
    ap.add_argument("--batch", type=int, default=256, help="rows of the vector envs")
    ap.add_argument("--seconds", type=float, default=0.3, help="length of one timed chunk")
    ap.add_argument("--repeats", type=int, default=5)
    _results.add_output_args(ap, "watch_throughput")
    a = ap.parse_args(argv)
    runners = _runners(a.scene, a.batch)
    calls = {k: _calls_for(run, a.seconds, per) for k, (run, _n, per) in runners.items()}
    rates: dict[str, list[float]] = {k: [] for k in runners}
    for _ in range(a.repeats):  # interleaved, so that load changes hit every env alike
        for k, (run, n, _per) in runners.items():
            rates[k].append(calls[k] * n / run(calls[k]))
    data: dict[str, Any] = {
        "command": _results.command("benchmarks.watch_throughput", argv),
        "machine": _results.machine(),
        "scene": a.scene,
        "batch": a.batch,
        "seconds": a.seconds,
        "repeats": a.repeats,
        "rows": [
            {"env": k, "rows": n, "agent_steps_per_s": statistics.median(rates[k])}
            for k, (_run, n, _per) in runners.items()
        ],
    }
    print(render(data))
    _results.write("watch_throughput", data, a.out, a.update_results)
    return 0


def render(data: dict[str, Any]) -> str:
    """The page fragment: agent steps/s and the ratios to Navigate-v0's and CartPole-v1's
    vector envs of the same size (same run)."""
    rows = {r["env"]: r for r in data["rows"]}
    nav = rows[ANCHOR]["agent_steps_per_s"]
    cart = rows[CARTPOLE]["agent_steps_per_s"]
    lines = [
        "| env | rows per call | agent steps/s | vs Navigate-v0 vector | vs CartPoleVectorEnv |",
        "| --- | ---: | ---: | ---: | ---: |",
    ]
    for r in data["rows"]:
        s = r["agent_steps_per_s"]
        lines.append(f"| {r['env']} | {r['rows']} | {s:,.0f} | {s / nav:.2f} | {s / cart:.3f} |")
    m = data["machine"]
    lines += [
        "",
        f"`{data['command']}`: random actions on `{data['scene']}` (never declaring), vector "
        f"envs of {data['batch']} rows (copies x watchers for watch_v0), resets included "
        f'(A\'s motion is planned at every episode start) except in the "no resets" row; '
        f"median of {data['repeats']} interleaved chunks of about {data['seconds']} s; "
        f"{m['cpus']} CPUs, load average {m['load_average']} (compare the ratios).",
    ]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
