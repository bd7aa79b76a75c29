"""Registration of the Gymnasium ids (entry points are strings: nothing heavy is imported
until ``gym.make``)."""

from __future__ import annotations

import gymnasium as gym

__all__ = ["ENV_IDS", "WATCH_ID", "register_sensorplan_envs"]

WATCH_ID = "sensorplan/Watch-v0"

# id -> (single-env entry point, vector entry point, max_episode_steps).  Placement-v0 ends
# after its one step by termination, so it has no time limit.
ENV_IDS = {
    "sensorplan/Placement-v0": (
        "sensorplan_gym.envs.placement:PlacementEnv",
        "sensorplan_gym.envs.vector:PlacementVectorEnv",
        None,
    ),
    "sensorplan/Navigate-v0": (
        "sensorplan_gym.envs.navigate:NavigateEnv",
        "sensorplan_gym.envs.vector:NavigateVectorEnv",
        200,
    ),
    "sensorplan/Recognize-v0": (
        "sensorplan_gym.envs.recognize:RecognizeEnv",
        "sensorplan_gym.envs.vector:RecognizeVectorEnv",
        200,
    ),
}


def register_sensorplan_envs() -> None:
    """Register every sensorplan id once (idempotent)."""
    for env_id, (entry_point, vector_entry_point, steps) in ENV_IDS.items():
        if env_id in gym.registry:
            continue
        gym.register(
            id=env_id,
            entry_point=entry_point,
            vector_entry_point=vector_entry_point,
            max_episode_steps=steps,
        )
    # the watch task (issue 11): one watcher; its fixed horizon is part of the task (no TimeLimit)
    if WATCH_ID not in gym.registry:
        gym.register(id=WATCH_ID, entry_point="sensorplan_gym.multiagent.gym_env:WatchEnv")
