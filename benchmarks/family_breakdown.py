"""What limits a learned policy: success by scene parameter on a benchmark level's scenes.

``python -m benchmarks.family_breakdown --env sensorplan/Navigate-v0 --policy MODEL.zip
[--level hard] [--episodes 200] [--out DIR | --update-results]``

Plays the policy and the oracle on the level's held-out test scenes (scene pool seed
:data:`agents.evaluation.benchmark.TEST_POOL_SEED`, random starts at the level's start
distance, the benchmark's evaluation seeds), measures every played scene with
:func:`geometry.families.scene_parameters`, and tabulates success by room shape, by field of
view, by range limit and by the kinds of G and H.  Rows where the policy falls behind the
oracle name what the generator's distribution asks that the policy has not learned.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

import sensorplan_gym  # noqa: F401
from agents.evaluation.benchmark import TEST_POOL_SEED
from agents.evaluation.episodes import EVAL_SEED_BASE
from agents.learning.policies import load_policy, model_config, play_env_kwargs
from agents.planning.oracle import OraclePolicy
from geometry.families import get_difficulty, scene_parameters

from . import _results

#: field-of-view bins (degrees, upper bounds)
FOV_BINS = ((45, 90), (90, 180), (180, 360), (360, 361))


def _fov_bin(fov: float) -> str:
    for lo, hi in FOV_BINS:
        if lo <= fov < hi:
            return f"{lo}-{hi}°" if hi <= 360 else "360°"
    return "360°"


def _groups(p: dict[str, Any]) -> dict[str, str]:
    return {
        "room shape": p["room_shape"],
        "field of view": _fov_bin(p["fov_deg"]),
        "range": "limited" if p["max_range"] is not None else "unlimited",
        "G/H": f"{p['goal_kind']}s",
    }


def _play(env, policy, seed: int) -> tuple[bool, dict[str, Any]]:
    obs, _info = env.reset(seed=seed)
    params = scene_parameters(env.unwrapped.world.scene)
    state, start, done, info = None, np.ones(1, dtype=bool), False, {}
    while not done:
        action, state = policy.predict(obs, state=state, episode_start=start, deterministic=True)
        start = np.zeros(1, dtype=bool)
        obs, _r, term, trunc, info = env.step(action)
        done = term or trunc
    return bool(info.get("is_success")), params


def measure(env_id: str, policy_path: str, level: str, episodes: int) -> dict[str, Any]:
    """Per-episode success of the model and the oracle, with the played scene's groups."""
    lv = get_difficulty(level)
    kw: dict[str, Any] = {"scene": "random", "difficulty": level, "scene_pool_seed": TEST_POOL_SEED}
    if env_id != "sensorplan/Placement-v0":
        kw.update(random_start=True, max_scene_tries=200)
    model_env = gym.make(env_id, **play_env_kwargs(model_config(policy_path), kw))
    oracle_env = gym.make(env_id, **kw)
    model = load_policy(policy_path, model_env)
    oracle = OraclePolicy(oracle_env)
    rows = []
    for i in range(episodes):
        seed = EVAL_SEED_BASE + i
        ok, params = _play(model_env, model, seed)
        ok_oracle, _ = _play(oracle_env, oracle, seed)
        rows.append({"model": ok, "oracle": ok_oracle, **_groups(params)})
    return {
        "env_id": env_id,
        "policy": str(policy_path),
        "level": level,
        "min_start_distance": lv.min_start_distance,
        "episodes": episodes,
        "rows": rows,
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.family_breakdown", description=__doc__)
    ap.add_argument("--env", required=True)
    ap.add_argument("--policy", required=True, help="a model zip")
    ap.add_argument("--level", default="hard", choices=["easy", "medium", "hard"])
    ap.add_argument("--episodes", type=int, default=200)
    _results.add_output_args(ap, "family_breakdown")
    a = ap.parse_args(argv)
    if not Path(a.policy).exists() and not Path(a.policy + ".zip").exists():
        ap.error(f"--policy: no model at {a.policy}")
    data = measure(a.env, a.policy, a.level, a.episodes)
    data["command"] = _results.command("benchmarks.family_breakdown", argv)
    data["machine"] = _results.machine()
    print(render(data))
    _results.write("family_breakdown", data, a.out, a.update_results)
    return 0


def render(data: dict[str, Any]) -> str:
    """The page fragment: success of the model and the oracle per group of scenes."""
    rows = data["rows"]
    name = Path(data["policy"]).stem
    lines = [
        f"| scenes | episodes | {name} | oracle |",
        "| --- | ---: | ---: | ---: |",
        f"| all | {len(rows)} | {np.mean([r['model'] for r in rows]):.2f} | "
        f"{np.mean([r['oracle'] for r in rows]):.2f} |",
    ]
    for key in ("room shape", "field of view", "range", "G/H"):
        for val in sorted({r[key] for r in rows}):
            sel = [r for r in rows if r[key] == val]
            lines.append(
                f"| {key}: {val} | {len(sel)} | {np.mean([r['model'] for r in sel]):.2f} | "
                f"{np.mean([r['oracle'] for r in sel]):.2f} |"
            )
    lines += [
        "",
        f"{data['env_id'].split('/')[-1]}, `{data['level']}` level test scenes, random starts at "
        f"{data['min_start_distance']} diameters, deterministic actions. Command: "
        f"`{data['command']}`",
    ]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    raise SystemExit(main())
