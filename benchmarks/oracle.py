"""Oracle success rates: ``python -m benchmarks.oracle [--episodes N] [--random-scenes M]``.

For every environment, every bundled scene (N episodes each, evaluation seeds
1_000_000 onwards) and M procedural scenes (``geometry.generate.random_scene``, one
episode each).  A random scene whose recognizable region is empty, or not reachable
from any start, has no recognizing placement: it is excluded from the rate and counted
separately.  Prints a markdown table and writes it to ``--out`` (default
``runs/benchmarks/oracle.md``); the tracked ``benchmarks/results/oracle.md`` is
rewritten only with ``--update-results``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import gymnasium as gym
import numpy as np

import sensorplan_gym  # noqa: F401
from agents.planning.oracle import OraclePolicy
from geometry.generate import random_scene

ENVS = ["sensorplan/Placement-v0", "sensorplan/Navigate-v0", "sensorplan/Recognize-v0"]
SCENES = ["lab", "edr", "corridor", "warehouse"]
SEED0 = 1_000_000
#: the tracked results file (rewritten only with --update-results)
TRACKED = Path(__file__).parent / "results" / "oracle.md"
#: where a run writes by default (runs/ is git-ignored)
DEFAULT_OUT = Path("runs") / "benchmarks" / "oracle.md"


def episode(env, policy, seed: int) -> bool:
    obs, _ = env.reset(seed=seed)
    start, done, info = True, False, {}
    while not done:
        action, _ = policy.predict(obs, episode_start=start)
        start = False
        obs, _, term, trunc, info = env.step(action)
        done = term or trunc
    return bool(info.get("is_success"))


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(
        prog="python -m benchmarks.oracle", description=__doc__.split("\n\n")[0]
    )
    ap.add_argument("--episodes", type=int, default=100)
    ap.add_argument("--random-scenes", type=int, default=200)
    ap.add_argument(
        "--out",
        type=Path,
        default=DEFAULT_OUT,
        help=f"markdown file for the table (default {DEFAULT_OUT})",
    )
    ap.add_argument(
        "--update-results",
        action="store_true",
        help=f"write the tracked {TRACKED} instead of --out",
    )
    args = ap.parse_args(argv)
    rows = [
        "| env | scene | episodes | successes | success rate | excluded (no placement) |",
        "| --- | --- | ---: | ---: | ---: | ---: |",
    ]
    t0 = time.perf_counter()
    for env_id in ENVS:
        for scene in SCENES:
            env = gym.make(env_id, scene=scene)
            pol = OraclePolicy(env)
            wins = sum(episode(env, pol, SEED0 + i) for i in range(args.episodes))
            rows.append(
                f"| {env_id} | {scene} | {args.episodes} | {wins} | "
                f"{wins / args.episodes:.3f} | 0 |"
            )
            print(rows[-1], flush=True)
        rng = np.random.default_rng(SEED0)
        wins = runs = excluded = 0
        for _ in range(args.random_scenes):
            d = random_scene(rng)
            try:
                env = gym.make(env_id, scene=d)
            except ValueError as e:  # no recognizing placement reachable from a start
                if "unusable" not in str(e):
                    raise
                excluded += 1
                continue
            runs += 1
            wins += episode(env, OraclePolicy(env), SEED0 + runs)
        rows.append(
            f"| {env_id} | random ({args.random_scenes} scenes) | {runs} | {wins} | "
            f"{wins / max(runs, 1):.3f} | {excluded} |"
        )
        print(rows[-1], flush=True)
    table = "\n".join(rows)
    out = TRACKED if args.update_results else args.out
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text("# Oracle success (`python -m benchmarks.oracle`)\n\n" + table + "\n")
    print(f"\n{table}\n\n({time.perf_counter() - t0:.0f} s; written to {out})")


if __name__ == "__main__":
    main()
