"""Evaluating watcher policies on ``watch_v0``: the oracle watchers
(:class:`agents.planning.watch_oracle.WatchOracle`), random actions or an RLlib policy.

:func:`run_watch_episodes` plays episodes and reports per-episode success (every watcher
declared right), per-watcher success and the fraction of steps on which each watcher (and the
team) saw A; :func:`evaluate_watch` does so for every scene and watcher count, locally or on
Ray workers, with the same episode seeds as :mod:`agents.evaluation.evaluate`.

``python -m agents.evaluation.watch --scenes lab edr corridor warehouse --watchers 1 2
--episodes 200 [--backend ray] [--policy oracle|random|RLLIB_CHECKPOINT|TEAM.pt]`` prints the
table in the README (``TEAM.pt``: a team of :mod:`agents.learning.watch_imitation`, played on
``evidence=True`` envs).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from typing import Any

import numpy as np

from ..checks import check_writable_file, missing_extra_message
from ..learning.rllib_train import RLlibWatchPolicy
from ..learning.watch_imitation import WatchImitationPolicy
from ..planning.watch_oracle import WatchOracle
from .episodes import EVAL_SEED_BASE
from .ray_eval import map_chunks
from .stats import wilson_interval

__all__ = ["evaluate_watch", "format_rows", "main", "run_watch_episodes"]


def run_watch_episodes(
    env_kwargs: dict[str, Any], policy: str | Any, seeds: list[int]
) -> dict[str, list]:
    """Play one episode per seed of ``watch_v0.parallel_env(**env_kwargs)``.

    ``policy``: ``"oracle"``, ``"random"`` (uniform actions, seeded per episode from the
    episode seed so that any split of the seeds gives the same episodes), or an object with
    ``act(observations) -> actions`` (e.g. :class:`agents.learning.rllib_train.RLlibWatchPolicy`).
    Returns per-episode lists: ``success`` (every watcher declared right), ``watcher_success``
    (fraction of watchers right), ``visible`` (mean over watchers of the fraction of steps
    each saw A), ``team_visible`` (fraction of steps some watcher saw A), ``a_ends_in``,
    ``return`` (summed over watchers), ``seed``."""
    from sensorplan_gym import watch_v0

    env = watch_v0.parallel_env(**env_kwargs)
    out: dict[str, list] = {
        k: []
        for k in (
            "seed",
            "success",
            "watcher_success",
            "visible",
            "team_visible",
            "a_ends_in",
            "return",
        )
    }
    oracle = WatchOracle(env) if policy == "oracle" else None
    for s in seeds:
        obs, _ = env.reset(seed=int(s))
        rng = np.random.default_rng([int(s), 7])
        if oracle is not None:
            oracle.reset()
        elif policy != "random" and hasattr(policy, "reset"):
            policy.reset()
        ret = 0.0
        info: dict = {}
        while env.agents:
            if oracle is not None:
                acts = oracle.act(obs)
            elif policy == "random":
                acts = {a: rng.uniform(-1, 1, 4).astype(np.float32) for a in env.agents}
            else:
                acts = policy.act(obs)
            obs, rew, term, trunc, info = env.step(acts)
            ret += float(sum(rew.values()))
        ok = [bool(i["is_success"]) for i in info.values()]
        out["seed"].append(int(s))
        out["success"].append(all(ok))
        out["watcher_success"].append(float(np.mean(ok)))
        out["visible"].append(float(np.mean([i["visible_fraction"] for i in info.values()])))
        out["team_visible"].append(float(next(iter(info.values()))["team_visible_fraction"]))
        out["a_ends_in"].append(next(iter(info.values()))["a_ends_in"])
        out["return"].append(ret)
    env.close()
    return out


def _summary(ep: dict[str, list]) -> dict[str, Any]:
    n = len(ep["success"])
    k = int(sum(ep["success"]))
    lo, hi = wilson_interval(k, n)
    return {
        "episodes": n,
        "successes": k,
        "success_rate": k / n,
        "success_ci95": [min(lo, k / n), max(hi, k / n)],
        "watcher_success": float(np.mean(ep["watcher_success"])),
        "visible_fraction": float(np.mean(ep["visible"])),
        "team_visible_fraction": float(np.mean(ep["team_visible"])),
        "mean_return": float(np.mean(ep["return"])),
        "a_in_H": float(np.mean([a == "H" for a in ep["a_ends_in"]])),
    }


def evaluate_watch(
    scenes: list[str],
    watchers: list[int],
    *,
    policy: str | Any = "oracle",
    episodes: int = 100,
    seed: int = 0,
    env_kwargs: dict | None = None,
    backend: str = "local",
    address: str | None = None,
    chunk: int = 25,
) -> list[dict[str, Any]]:
    """Evaluate ``policy`` on every ``scene x n_watchers`` with the same episode seeds
    (``1_000_000 + seed + i``); ``backend="ray"`` spreads (scene, watchers, chunk of seeds)
    tasks over Ray workers (:mod:`.ray_eval`) -- each episode depends only on
    its seed, so the results are identical to the local backend."""
    seeds = [EVAL_SEED_BASE + seed + i for i in range(episodes)]
    jobs = []
    for scene in scenes:
        for n in watchers:
            kw = {**(env_kwargs or {}), "scene": scene, "n_watchers": int(n)}
            jobs.append(kw)
    t0 = time.perf_counter()
    if backend == "local":
        eps = [run_watch_episodes(kw, policy, seeds) for kw in jobs]
    elif backend == "ray":
        eps = map_chunks(run_watch_episodes, jobs, policy, seeds, chunk=chunk, address=address)
    else:
        raise ValueError(f"backend must be 'local' or 'ray', got {backend!r}")
    dt = time.perf_counter() - t0
    rows = []
    for kw, ep in zip(jobs, eps, strict=True):
        rows.append(
            {
                "scene": kw["scene"],
                "n_watchers": kw["n_watchers"],
                **_summary(ep),
                "per_episode": ep,
            }
        )
    for r in rows:
        r["wall_s_total"] = round(dt, 2)
    return rows


def format_rows(rows: list[dict[str, Any]]) -> str:
    head = (
        f"{'scene':<10} {'watchers':>8} {'success':>9} {'95% CI':>16} {'per-watcher':>11} "
        f"{'visible':>8} {'team vis.':>9} {'A in H':>7}"
    )
    lines = [head, "-" * len(head)]
    for r in rows:
        lo, hi = r["success_ci95"]
        lines.append(
            f"{r['scene']:<10} {r['n_watchers']:>8} {r['successes']:>4}/{r['episodes']:<4} "
            f"[{lo:.3f}, {hi:.3f}] {r['watcher_success']:>11.3f} {r['visible_fraction']:>8.3f} "
            f"{r['team_visible_fraction']:>9.3f} {r['a_in_H']:>7.2f}"
        )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    from sensorplan_gym.core.world import BUNDLED_SCENES

    ap = argparse.ArgumentParser(prog="python -m agents.evaluation.watch", description=__doc__)
    ap.add_argument("--scenes", nargs="+", default=list(BUNDLED_SCENES))
    ap.add_argument("--watchers", nargs="+", type=int, default=[1, 2])
    ap.add_argument(
        "--policy",
        default="oracle",
        help="oracle, random, an RLlib checkpoint or a watch_imitation .pt (adds evidence=True)",
    )
    ap.add_argument("--episodes", type=int, default=100)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--env-kwargs", type=json.loads, default=None)
    ap.add_argument("--backend", choices=("local", "ray"), default="local")
    ap.add_argument("--address", default=None, help="Ray cluster address (backend ray)")
    ap.add_argument("--json", default=None, help="write the rows (with per-episode data) here")
    args = ap.parse_args(argv)
    try:
        if args.json:
            check_writable_file(args.json, what="--json")
        policy: Any = args.policy
        env_kwargs = args.env_kwargs
        if policy.endswith(".pt"):  # a watcher team of agents.learning.watch_imitation
            policy = WatchImitationPolicy(policy)
            env_kwargs = {**(env_kwargs or {}), "evidence": True}
        elif policy not in ("oracle", "random"):
            policy = RLlibWatchPolicy(policy)  # a relative checkpoint path is made absolute
        rows = evaluate_watch(
            args.scenes,
            args.watchers,
            policy=policy,
            episodes=args.episodes,
            seed=args.seed,
            env_kwargs=env_kwargs,
            backend=args.backend,
            address=args.address,
        )
    except ImportError as err:
        msg = missing_extra_message(ap.prog, err)
        if msg is None:
            raise
        print(msg, file=sys.stderr)
        return 2
    except (ValueError, KeyError, OSError) as err:
        print(f"{ap.prog}: error: {err}", file=sys.stderr)
        return 2
    print(format_rows(rows))
    print(f"({args.backend} backend, {rows[0]['wall_s_total']:.1f} s)")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
