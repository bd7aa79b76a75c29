"""Oracle success rates: ``python -m benchmarks.oracle [--episodes N] [--random-scenes M]
[--levels easy medium hard] [--level-scenes K]``.

For every environment, every bundled scene (N episodes each, evaluation seeds
1_000_000 onwards) and M procedural scenes (``geometry.generate.random_scene``, one
episode each).  A random scene whose recognizable region is empty, or not reachable
from any start, has no recognizing placement: it is excluded from the rate and counted
separately.  For every benchmark level of ``--levels`` (:data:`geometry.families.DIFFICULTIES`),
K episodes of the level's test split (a pool of 64 family scenes, as
``sensorplan benchmark --level`` plays), from random starts at the level's
``min_start_distance``.  Prints the table and writes the data (``oracle.json``) and the page
fragment (``oracle.md``) to ``--out`` (default ``runs/benchmarks/oracle/``); with
``--update-results`` the tracked ``benchmarks/results/oracle.json`` and
``docs/results/oracle.md`` instead.
"""

from __future__ import annotations

import argparse
import time
from typing import Any

import gymnasium as gym
import numpy as np

import sensorplan_gym  # noqa: F401
from agents.planning.oracle import OraclePolicy
from geometry.families import get_difficulty
from geometry.generate import random_scene

from . import _results

ENVS = ["sensorplan/Placement-v0", "sensorplan/Navigate-v0", "sensorplan/Recognize-v0"]
SCENES = ["lab", "edr", "corridor", "warehouse"]
SEED0 = 1_000_000


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
        "--levels",
        nargs="*",
        default=["hard"],
        choices=["easy", "medium", "hard"],
        help="benchmark levels whose scene families are played (default: hard)",
    )
    ap.add_argument("--level-scenes", type=int, default=100, help="episodes per level")
    _results.add_output_args(ap, "oracle")
    args = ap.parse_args(argv)
    data: dict[str, Any] = {
        "command": _results.command("benchmarks.oracle", argv),
        "machine": _results.machine(),
        "episodes": args.episodes,
        "random_scenes": args.random_scenes,
        "levels": args.levels,
        "level_scenes": args.level_scenes,
        "seed0": SEED0,
        "rows": [],
    }
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
            data["rows"].append(
                {
                    "env": env_id,
                    "scene": scene,
                    "episodes": args.episodes,
                    "successes": wins,
                    "excluded": 0,
                }
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
        data["rows"].append(
            {
                "env": env_id,
                "scene": "random",
                "episodes": runs,
                "successes": wins,
                "excluded": excluded,
            }
        )
        print(rows[-1], flush=True)
        for level in args.levels:
            data["rows"].append(_level_row(env_id, level, args.level_scenes))
            print(data["rows"][-1], flush=True)
    table = "\n".join(rows)
    data["seconds"] = round(time.perf_counter() - t0, 1)
    print(f"\n{table}\n\n({data['seconds']:.0f} s)")
    _results.write("oracle", data, args.out, args.update_results)


def _level_row(env_id: str, level: str, n: int) -> dict[str, Any]:
    """``n`` episodes of the level's held-out test split, as ``sensorplan benchmark --level``
    plays it (scene pool seed 1, the envs' default pool of 64 scenes, random starts at the
    level's ``min_start_distance``).  The pool re-draws family scenes that have no
    successful pose for the task (empty recognizable region, no reachable start, or -- for
    the tasks that reward one pose -- no sampled pose that keeps G and H in view), as the
    learned policies' splits do; how many scenes it drew is reported."""
    lv = get_difficulty(level)
    kw: dict[str, Any] = {
        "scene": "random",
        "difficulty": level,
        "scene_pool_seed": 1,  # agents.evaluation.benchmark.TEST_POOL_SEED
        "max_scene_tries": 200,
    }
    if env_id != "sensorplan/Placement-v0":
        kw.update(random_start=True, min_start_distance=lv.min_start_distance)
    env = gym.make(env_id, **kw)
    pol = OraclePolicy(env)
    wins = sum(episode(env, pol, SEED0 + i) for i in range(n))
    return {
        "env": env_id,
        "scene": f"level:{level}",
        "episodes": n,
        "successes": int(wins),
        "excluded": 0,
    }


def render(data: dict[str, Any]) -> str:
    """The page fragment: successes / episodes per env and scene."""
    scenes: list[str] = []
    by: dict[tuple[str, str], dict] = {}
    for r in data["rows"]:
        if r["scene"] not in scenes:
            scenes.append(r["scene"])
        by[(r["env"], r["scene"])] = r
    envs = list(dict.fromkeys(r["env"] for r in data["rows"]))

    def head(sc: str) -> str:
        if sc == "random":
            return f"{data['random_scenes']} random scenes"
        if sc.startswith("level:"):
            return f"`{sc[6:]}` test split ({data['level_scenes']} episodes)"
        return sc

    lines = [
        "| oracle success | " + " | ".join(head(sc) for sc in scenes) + " |",
        "| --- |" + " ---: |" * len(scenes),
    ]
    for env in envs:
        cells = []
        for sc in scenes:
            r = by.get((env, sc))
            if r is None:
                cells.append("")
                continue
            c = f"{r['successes']}/{r['episodes']}"
            if sc == "random":
                c += f" ({r['excluded']} without a placement)"
            cells.append(c)
        lines.append(f"| {env.split('/')[-1]} | " + " | ".join(cells) + " |")
    m = data["machine"]
    lines += [
        "",
        f"`{data['command']}`: {data['episodes']} episodes per bundled scene (seeds "
        f"{data['seed0']:,} onwards), one episode on each of {data['random_scenes']} procedural "
        f"scenes"
        + (
            f" and {data['level_scenes']} episodes of the "
            + ", ".join(f"`{x}`" for x in data["levels"])
            + " level's test split (`sensorplan benchmark --level`: a pool of 64 family "
            "scenes, redrawn where the task has no successful pose; random starts at the "
            "level's start distance)"
            if data.get("levels")
            else ""
        )
        + f"; {data['seconds']:,.0f} s on {m['cpus']} CPUs (load average "
        f"{m['load_average']}).",
    ]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
