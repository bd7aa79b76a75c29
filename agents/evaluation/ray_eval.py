"""Ray backend for the evaluations: episodes (and scenes) spread over Ray workers.

Every evaluated episode is reset with its own seed, and the episode runners here depend on
nothing else (the random baseline of ``sensorplan evaluate`` draws its actions from one
generator across episodes, so its episodes run in one task, in order), so the Ray backend
returns exactly what the local backend returns for the same seeds, in the same order.

* :func:`map_chunks` -- ``fn(job, policy, seeds_chunk)`` for every job and chunk of seeds as
  Ray tasks; the per-job results (dicts of per-episode lists) are concatenated in seed order.
* :func:`run_episodes_ray` -- the Ray counterpart of :func:`agents.evaluation.episodes.run_episodes`
  for the Gymnasium envs (``sensorplan evaluate --backend ray``).
* :func:`ensure_ray` -- connect to ``address`` (an existing cluster, e.g. ``"auto"`` or
  ``"ray://head:10001"``) or start a local instance; an already initialised Ray is reused.

Ray is in the ``multi`` extra; importing this module does not import Ray.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from ..learning.policies import load_policy
from .episodes import run_episodes

__all__ = ["ensure_ray", "map_chunks", "run_episodes_ray"]


def ensure_ray(address: str | None = None, num_cpus: int | None = None):
    """The ``ray`` module, initialised: connected to ``address`` when given, else a local
    instance with ``num_cpus`` CPUs (default: all); reused when already initialised."""
    try:
        import ray
    except ImportError as e:
        raise ImportError(
            "the Ray backend needs Ray: pip install -e '.[multi]' (ray[rllib], pettingzoo)",
            name=e.name or "ray",
        ) from None
    if not ray.is_initialized():
        # the workers import sensorplan-gym from their Python environment: on a cluster,
        # install the same version on every node
        if address:
            ray.init(address=address, log_to_driver=False)
        else:
            ray.init(num_cpus=num_cpus, include_dashboard=False, log_to_driver=False)
    return ray


def _merge(parts: list[dict[str, list]]) -> dict[str, list]:
    out: dict[str, list] = {k: [] for k in parts[0]}
    for p in parts:
        for k, v in p.items():
            out[k].extend(v)
    return out


def map_chunks(
    fn: Callable[[Any, Any, list[int]], dict[str, list]],
    jobs: list[Any],
    policy: Any,
    seeds: list[int],
    *,
    chunk: int = 25,
    address: str | None = None,
) -> list[dict[str, list]]:
    """``[fn(job, policy, seeds) for job in jobs]``, computed as Ray tasks over chunks of
    ``chunk`` seeds (``fn`` must return a dict of per-episode lists and must depend on each
    seed alone).  ``policy`` is shipped to the workers once (``ray.put``)."""
    if chunk < 1:
        raise ValueError(f"chunk must be positive, got {chunk}")
    ray = ensure_ray(address)
    task = ray.remote(num_cpus=1)(fn)
    pol = ray.put(policy)
    refs = [
        [task.remote(job, pol, seeds[i : i + chunk]) for i in range(0, len(seeds), chunk)]
        for job in jobs
    ]
    return [_merge(ray.get(r)) for r in refs]


def _gym_chunk(job: dict[str, Any], spec: str, seeds: list[int]) -> dict[str, list]:
    import gymnasium as gym

    import sensorplan_gym  # noqa: F401 - registers the ids

    env = gym.make(job["env_id"], **job["env_kwargs"])
    try:
        policy = load_policy(spec, env, seed=job["seed"])
        if spec not in ("oracle", "random"):
            import torch

            torch.manual_seed(job["seed"])
        return run_episodes(env, policy, seeds, deterministic=job.get("deterministic", True))
    finally:
        env.close()


def run_episodes_ray(
    env_id: str,
    env_kwargs: dict[str, Any],
    spec: str,
    seeds: list[int],
    *,
    seed: int = 0,
    chunk: int = 25,
    address: str | None = None,
    deterministic: bool = True,
) -> dict[str, list]:
    """The per-episode results of policy ``spec`` on ``env_id`` for ``seeds``, as
    :func:`agents.evaluation.episodes.run_episodes` gives them, computed on Ray workers.  A
    model zip path must be readable from the workers (same path on every node)."""
    job = {
        "env_id": env_id,
        "env_kwargs": dict(env_kwargs),
        "seed": int(seed),
        "deterministic": bool(deterministic),
    }
    # the random baseline's generator runs on across episodes: one task keeps its sequence
    size = len(seeds) if spec == "random" else chunk
    return map_chunks(_gym_chunk, [job], spec, seeds, chunk=max(1, size), address=address)[0]
