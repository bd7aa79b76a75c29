"""Playing evaluation episodes: the seeds they are reset with and the per-episode record.

Every evaluated episode ``i`` is reset with seed ``EVAL_SEED_BASE + seed + i``, and
:func:`run_episodes` depends on nothing else, so the local evaluation
(:mod:`agents.evaluation.evaluate`) and the Ray one (:mod:`agents.evaluation.ray_eval`) both
call it and agree episode for episode.
"""

from __future__ import annotations

import numpy as np

__all__ = ["EVAL_SEED_BASE", "run_episodes"]

#: evaluation episode ``i`` is reset with seed ``EVAL_SEED_BASE + seed + i``
EVAL_SEED_BASE = 1_000_000


def _xy(info: dict) -> np.ndarray | None:
    pose = info.get("pose")
    if pose is None:
        return None
    return np.asarray(pose[:2], dtype=float)


def episode_key(env, info: dict) -> str:
    """What makes an episode distinct: its scene (name, bounds and region area, to 12
    significant digits) and its start pose (``info["pose"]`` after reset, scene units and
    radians; none for Placement).  Two episodes with the same key replay the same problem."""
    w = env.unwrapped.world
    parts = [w.scene.name, *(f"{float(v):.12g}" for v in (*w.lo, *w.hi, w.region.area))]
    pose = info.get("pose")
    if pose is not None:
        parts += [f"{float(v):.12g}" for v in pose[:3]]
    return "|".join(parts)


def run_episodes(env, policy, seeds: list[int], *, deterministic: bool = True) -> dict[str, list]:
    """Play one episode per seed; per-episode success, return, steps, path length and
    :func:`episode_key` (``"episode_key"``: which scene and start it played)."""
    out: dict[str, list] = {
        "success": [],
        "return": [],
        "steps": [],
        "path_length": [],
        "episode_key": [],
    }
    for s in seeds:
        obs, info = env.reset(seed=int(s))
        out["episode_key"].append(episode_key(env, info))
        state = None
        start = np.ones(1, dtype=bool)
        prev = _xy(info)
        ret, steps, path = 0.0, 0, 0.0
        done = False
        while not done:
            action, state = policy.predict(
                obs, state=state, episode_start=start, deterministic=deterministic
            )
            start = np.zeros(1, dtype=bool)
            obs, reward, terminated, truncated, info = env.step(action)
            ret += float(reward)
            steps += 1
            xy = _xy(info)
            if xy is not None and prev is not None:
                path += float(np.hypot(*(xy - prev)))
            if xy is not None:
                prev = xy
            done = terminated or truncated
        out["success"].append(bool(info.get("is_success", False)))
        out["return"].append(ret)
        out["steps"].append(steps)
        out["path_length"].append(path)
    return out
