"""Environment speed: steps/s with random actions and reset times.

    python -m benchmarks.envs [--steps 4000] [--quick]

Prints a markdown table and writes it to ``benchmarks/results/envs.md``.

* steps/s, single env: ``gym.make(id)`` (with its standard wrappers), random actions from
  ``action_space.sample()`` drawn up front, resets included when an episode ends; the best
  of three equal chunks (the 2-core machine is often shared, which only ever slows a run).  For
  Recognize-v0 the decide component is set to 0 ("continue") so episodes are not cut to
  a step or two by random declarations (the declaring variant is also shown).
* steps/s, ``make_vec`` with 4 envs: env-steps per second (4 per vector step), sync and
  async (one worker process per env).
* reset: median wall time of ``env.reset()`` on a bundled scene (``lab``; the world is
  cached, so this is the per-episode cost) and on ``scene="random"`` (a new procedural
  scene, its exact recognizable region and derived data on every reset), for the
  complete and the partial model.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from pathlib import Path

import gymnasium as gym
import numpy as np

import sensorplan_gym  # noqa: F401

IDS = ["sensorplan/Placement-v0", "sensorplan/Navigate-v0", "sensorplan/Recognize-v0"]


def _actions(space, n, seed, declare=True):
    space.seed(seed)
    acts = [space.sample() for _ in range(n)]
    if not declare and space.shape == (4,):
        for a in acts:
            a[3] = 0.0
    return acts


def steps_per_second(env_id, n, declare=False, **kw):
    env = gym.make(env_id, **kw)
    if not isinstance(env.action_space, gym.spaces.Box):
        declare = True
    env.reset(seed=0)
    acts = _actions(env.action_space, n, 0, declare)
    for a in acts[:50]:  # warm-up
        if any(env.step(a)[2:4]):
            env.reset()
    best = 0.0
    for chunk in np.array_split(np.arange(n), 3):  # best of 3 (the machine may be shared)
        t = time.perf_counter()
        for k in chunk:
            _, _, te, tr, _ = env.step(acts[k])
            if te or tr:
                env.reset()
        best = max(best, len(chunk) / (time.perf_counter() - t))
    env.close()
    return best


def vec_steps_per_second(env_id, n, mode, num_envs=4, **kw):
    envs = gym.make_vec(env_id, num_envs=num_envs, vectorization_mode=mode, vector_kwargs={}, **kw)
    try:
        envs.reset(seed=0)
        acts = _actions(envs.action_space, n, 0)
        if envs.single_action_space.shape == (4,):
            for a in acts:
                a[:, 3] = 0.0
        for a in acts[:20]:
            envs.step(a)
        t = time.perf_counter()
        for a in acts:
            envs.step(a)
        dt = time.perf_counter() - t
    finally:
        envs.close()
    return n * num_envs / dt


def reset_ms(env_id, scene, n, **kw):
    env = gym.make(env_id, scene=scene, **kw)
    env.reset(seed=987_654)  # seeds not used elsewhere: no cache hits for random scenes
    ts = []
    for _ in range(n):
        t = time.perf_counter()
        env.reset()
        ts.append(time.perf_counter() - t)
    return 1e3 * float(np.median(ts))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=4000)
    ap.add_argument("--quick", action="store_true", help="fewer steps (smoke run)")
    ap.add_argument("--out", default=str(Path(__file__).parent / "results" / "envs.md"))
    args = ap.parse_args(argv)
    n = 300 if args.quick else args.steps
    nv = max(50, n // 8)
    nr = 8 if args.quick else 40

    rows = []
    for env_id in IDS:
        for obs in ("vector", "grid"):
            single = steps_per_second(env_id, n, obs_type=obs)
            sync = vec_steps_per_second(env_id, nv, "sync", obs_type=obs)
            asyn = vec_steps_per_second(env_id, nv, "async", obs_type=obs)
            rows.append((env_id, obs, single, sync, asyn))
    rec_decl = steps_per_second("sensorplan/Recognize-v0", n, declare=True)
    cartpole = steps_per_second("CartPole-v1", n)

    resets = []
    for model, motion in (("complete", "translating"), ("partial", "stationary")):
        for scene in ("lab", "random"):
            ms = reset_ms("sensorplan/Navigate-v0", scene, nr, model=model, motion=motion)
            resets.append((scene, model, motion, ms))
    ms = reset_ms("sensorplan/Navigate-v0", "random", nr, model="partial", motion="translating")
    resets.append(("random", "partial", "translating", ms))

    lines = [
        "# Environment speed",
        "",
        f"Machine: {os.cpu_count()} cores, {platform.python_implementation()} "
        f"{platform.python_version()}, numpy {np.__version__}.  "
        "Command: `python -m benchmarks.envs`.",
        f"Load average at the end of the run: {os.getloadavg()[0]:.1f} (other jobs slow every "
        "row alike; compare with the CartPole-v1 anchor, ~120k steps/s on an idle machine).",
        "",
        "| env | obs | steps/s (1 env) | env-steps/s (make_vec 4, sync) | "
        "env-steps/s (make_vec 4, async) |",
        "| --- | --- | ---: | ---: | ---: |",
    ]
    for env_id, obs, single, sync, asyn in rows:
        lines.append(f"| {env_id} | {obs} | {single:,.0f} | {sync:,.0f} | {asyn:,.0f} |")
    lines.append(f"| CartPole-v1 (anchor, same run) | - | {cartpole:,.0f} | | |")
    lines += [
        "",
        f"Recognize-v0 with fully random actions (2/3 of them declare, so most steps are resets): "
        f"{rec_decl:,.0f} steps/s.",
        "",
        "| reset of Navigate-v0 | model | motion | median ms |",
        "| --- | --- | --- | ---: |",
    ]
    for scene, model, motion, ms in resets:
        what = "bundled `lab` (cached world)" if scene == "lab" else '`scene="random"` (new scene)'
        lines.append(f"| {what} | {model} | {motion} | {ms:.2f} |")
    text = "\n".join(lines) + "\n"
    print(text)
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(text)


if __name__ == "__main__":
    main()
