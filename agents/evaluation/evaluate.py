"""Evaluate policies (oracle, random, trained SB3 models) on the same episodes.

``sensorplan evaluate --env ID --policies oracle random path/to/model.zip ... --episodes N
--seed S [--env-kwargs JSON] [--out DIR]``

Every policy plays the same ``N`` episodes, reset with seeds ``1_000_000 + S + i``
(``i = 0 .. N-1``): disjoint from the training seeds (``S .. S + n_envs - 1``) and from the
periodic-evaluation seed (``S + 10_000``) of :mod:`agents.learning.train`.  Trained models act
deterministically, or with ``deterministic=False`` (``--stochastic``) sample their actions
(torch seeded with ``S`` before each policy, so a stochastic evaluation repeats exactly).

When the episodes replay one fixed scene from one fixed start (a bundled scene without
``random_start``), a deterministic policy plays nearly the same episode each time: only the
target's side and place and the pose noise vary.  The episodes are then not independent
samples of the policy's skill: the results carry ``independent_episodes: false`` and a
printed note, and each policy's ``distinct_episodes`` (distinct scene and start pairs, see
:func:`agents.evaluation.episodes.episode_key`) sizes its Wilson interval (``k/n`` successes
of ``distinct_episodes`` trials), so one start gives a wide interval; the interval across
training seeds (IQM) is the honest one.

Per policy: success rate (``info["is_success"]`` at the episode's last step) with its 95%
Wilson interval, mean return, mean steps, mean path length (the sum of the position changes
of ``info["pose"]``, reset included), and the normalized score
``(agent - random) / (oracle - random)`` on success rate (``None`` unless both ``oracle``
and ``random`` are evaluated in the same call, or when they tie).  When several models of
the same algorithm come from different training seeds, the interquartile mean of their
success rates with a stratified bootstrap 95% interval (:mod:`agents.evaluation.stats`, the rliable
method) is reported per algorithm.

Writes ``results.json``, ``results.csv`` and ``results.png`` to ``--out`` (default
``runs/eval_<env>_s<seed>``) and prints a table.  :func:`evaluate` returns the results
dict (the JSON's content).
"""

from __future__ import annotations

import csv
import json
import math
import time
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

from ..checks import check_writable_dir
from ..learning.policies import (
    RULES,
    check_policies,
    load_policy,
    make_env,
    model_config,
    play_env_kwargs,
    policy_label,
)
from .episodes import EVAL_SEED_BASE, run_episodes
from .ray_eval import run_episodes_ray
from .stats import iqm, normalized_score, stratified_bootstrap_ci, wilson_interval

__all__ = ["EVAL_SEED_BASE", "evaluate", "format_table", "run_episodes"]

# env kwargs that change only the reward, not what the agent sees or how the world behaves
_REWARD_ONLY = {"shaping", "step_cost", "success_bonus"}


def _summary(name: str, spec: str, ep: dict[str, list], meta: dict) -> dict[str, Any]:
    n = len(ep["success"])
    k = int(sum(ep["success"]))
    # repeated (scene, start) pairs are not independent trials: the interval is sized by
    # the number of distinct episodes m, at the measured rate (k/n successes of m)
    keys = ep.get("episode_key")
    m = len(set(keys)) if keys else n
    lo, hi = wilson_interval(k * m / n, m) if n else wilson_interval(0, 0)
    if n:  # guard against round-off at 0 or n successes (e.g. a 5e-17 lower bound at 0/n)
        lo, hi = min(lo, k / n), max(hi, k / n)
    return {
        "name": name,
        "spec": spec,
        **meta,
        "episodes": n,
        "successes": k,
        "distinct_episodes": m,
        "success_rate": k / n if n else float("nan"),
        "success_ci95": [lo, hi],
        "mean_return": float(np.mean(ep["return"])),
        "std_return": float(np.std(ep["return"])),
        "mean_steps": float(np.mean(ep["steps"])),
        "mean_path_length": float(np.mean(ep["path_length"])),
        "normalized_score": None,
        "per_episode": ep,
    }


def _fmt(v, nd=3) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "-"
    return f"{v:.{nd}f}"


def format_table(results: dict) -> str:
    """The results as a fixed-width text table (also used by the demo)."""
    head = ["policy", "success", "95% CI", "return", "steps", "path", "norm."]
    rows = []
    for p in results["policies"]:
        lo, hi = p["success_ci95"]
        rows.append(
            [
                p["name"],
                _fmt(p["success_rate"]),
                f"[{lo:.3f}, {hi:.3f}]",
                _fmt(p["mean_return"]),
                _fmt(p["mean_steps"], 1),
                _fmt(p["mean_path_length"], 2),
                _fmt(p["normalized_score"]),
            ]
        )
    widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(head)]
    line = "  ".join(
        h.ljust(w) if i == 0 else h.rjust(w)
        for i, (h, w) in enumerate(zip(head, widths, strict=True))
    )
    out = [line, "-" * len(line)]
    for r in rows:
        out.append(
            "  ".join(
                c.ljust(w) if i == 0 else c.rjust(w)
                for i, (c, w) in enumerate(zip(r, widths, strict=True))
            )
        )
    for algo, a in (results.get("iqm") or {}).items():
        out.append(
            f"{algo}: IQM success over {a['n_runs']} training seeds = {a['iqm']:.3f} "
            f"[{a['ci95'][0]:.3f}, {a['ci95'][1]:.3f}] (stratified bootstrap)"
        )
    return "\n".join(out)


def _plot(results: dict, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    pols = results["policies"]
    names = [p["name"] for p in pols]
    x = np.arange(len(pols))
    fig, axes = plt.subplots(1, 3, figsize=(4 + 2.2 * len(pols), 3.6))
    sr = np.array([p["success_rate"] for p in pols])
    lo = np.array([p["success_ci95"][0] for p in pols])
    hi = np.array([p["success_ci95"][1] for p in pols])
    axes[0].bar(x, sr, color="tab:blue", alpha=0.8)
    yerr = [np.clip(sr - lo, 0, None), np.clip(hi - sr, 0, None)]
    axes[0].errorbar(x, sr, yerr=yerr, fmt="none", ecolor="k", capsize=4)
    axes[0].set_ylim(0, 1.05)
    axes[0].set_title("success rate (95% Wilson CI)")
    axes[1].bar(
        x,
        [p["mean_return"] for p in pols],
        yerr=[p["std_return"] for p in pols],
        color="tab:green",
        alpha=0.8,
        capsize=4,
    )
    axes[1].set_title("return (mean +- std)")
    axes[2].bar(x, [p["mean_steps"] for p in pols], color="tab:orange", alpha=0.8)
    axes[2].set_title("steps per episode (mean)")
    for ax in axes:
        ax.set_xticks(x)
        ax.set_xticklabels(names, rotation=20, ha="right", fontsize=8)
    fig.suptitle(
        f"{results['env_id']} {results['env_kwargs'] or ''}: "
        f"{results['episodes']} episodes, seeds {results['episode_seeds'][0]}.."
        f"{results['episode_seeds'][1]}",
        fontsize=9,
    )
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _unique(names: list[str]) -> list[str]:
    seen: dict[str, int] = defaultdict(int)
    out = []
    for n in names:
        seen[n] += 1
        out.append(n if seen[n] == 1 else f"{n}#{seen[n]}")
    return out


def fresh_dir(base: Path) -> Path:
    """``base`` if it does not exist yet, else the first of ``base.2``, ``base.3``, ... that
    does not: the default output folder of a run, so that consecutive runs never overwrite
    each other's results."""
    base = Path(base)
    d, k = base, 1
    while d.exists():
        k += 1
        d = base.with_name(f"{base.name}.{k}")
    return d


def evaluate(
    env_id: str,
    policies: list[str],
    *,
    episodes: int = 100,
    seed: int = 0,
    env_kwargs: dict | None = None,
    out: str | Path | None = None,
    plot: bool = True,
    verbose: bool = True,
    threads: int | None = 1,
    backend: str = "local",
    address: str | None = None,
    deterministic: bool = True,
) -> dict[str, Any]:
    """Evaluate each policy spec (``"oracle"``, ``"random"``, a model zip) for ``episodes``
    episodes of ``env_id`` made with ``env_kwargs``; returns the results dict and, unless
    ``out`` is ``False``, writes results.json / results.csv / results.png there.
    ``backend="ray"`` plays the episodes on Ray workers (:mod:`agents.evaluation.ray_eval`; a local
    instance, or the cluster at ``address``) with results identical to ``"local"``.
    ``deterministic=False``: trained models sample their actions (torch seeded with ``seed``
    before each policy)."""
    if backend not in ("local", "ray"):
        raise ValueError(f"backend must be 'local' or 'ray', got {backend!r}")
    import gymnasium as gym

    import sensorplan_gym  # noqa: F401 - registers the ids

    if episodes < 1:
        raise ValueError(f"episodes must be positive, got {episodes}")
    if not policies:
        raise ValueError("no policies to evaluate")
    check_policies(policies)  # every path, before any episode is played
    if out is not False:
        outdir = check_writable_dir(
            out
            if out is not None
            else fresh_dir(
                Path("runs") / f"eval_{env_id.split('/')[-1].split('-v')[0].lower()}_s{seed}"
            )
        )
    if env_id not in gym.registry:
        raise ValueError(
            f"unknown env id {env_id!r}; sensorplan ids: {', '.join(sensorplan_gym.ENV_IDS)}"
        )
    if threads:
        try:
            import torch

            torch.set_num_threads(int(threads))
        except ImportError:
            pass
    env_kwargs = dict(env_kwargs or {})
    seeds = [EVAL_SEED_BASE + seed + i for i in range(episodes)]
    names = _unique([policy_label(p) for p in policies])
    fixed = env_kwargs.get("scene", "lab") != "random" and not env_kwargs.get("random_start")
    results: dict[str, Any] = {
        "env_id": env_id,
        "env_kwargs": env_kwargs,
        "episodes": episodes,
        "seed": seed,
        "deterministic": bool(deterministic),
        "independent_episodes": not fixed,
        "episode_seeds": [seeds[0], seeds[-1]],
        "policies": [],
        "iqm": {},
        "files": {},
    }
    for name, spec in zip(names, policies, strict=True):
        play_kwargs = env_kwargs
        if spec not in ("oracle", "random"):
            play_kwargs = play_env_kwargs(model_config(spec), env_kwargs)
        env = make_env(env_id, play_kwargs)
        try:
            policy = load_policy(spec, env, seed=seed)
            kind = spec if spec in ("oracle", "random") else "rule" if spec in RULES else "model"
            meta: dict[str, Any] = {"kind": kind}
            if kind == "rule":
                meta["play_env_kwargs"] = play_kwargs
            if meta["kind"] == "model":
                cfg = model_config(spec) or {}
                meta.update(
                    {
                        "algo": cfg.get("algo") or type(policy).__name__.lower(),
                        # sensorplan imitate's method (bc, dagger, dagger+ppo): seeds of
                        # different methods are different configs
                        "method": cfg.get("method"),
                        "expert": (cfg.get("config") or {}).get("expert"),
                        "train_seed": cfg.get("seed"),
                        "train_env_kwargs": cfg.get("env_kwargs"),
                        "play_env_kwargs": play_kwargs,
                    }
                )
                if cfg.get("env_id") not in (None, env_id):
                    print(f"warning: {spec} was trained on {cfg['env_id']}, evaluated on {env_id}")
                tk = {
                    k: v for k, v in (cfg.get("env_kwargs") or {}).items() if k not in _REWARD_ONLY
                }
                diff = {
                    k: (v, env_kwargs.get(k))
                    for k, v in tk.items()
                    if env_kwargs.get(k, "lab" if k == "scene" else None) != v
                }
                if diff and verbose:
                    print(f"note: {name} was trained with env kwargs {diff} (trained, evaluated)")
            t0 = time.perf_counter()
            if meta["kind"] == "model":
                import torch

                torch.manual_seed(seed)  # stochastic actions repeat exactly
            if backend == "ray":
                ep = run_episodes_ray(
                    env_id,
                    play_kwargs,
                    spec,
                    seeds,
                    seed=seed,
                    address=address,
                    deterministic=deterministic,
                )
            else:
                ep = run_episodes(env, policy, seeds, deterministic=deterministic)
            meta["backend"] = backend
            meta["eval_time_s"] = round(time.perf_counter() - t0, 2)
        finally:
            env.close()
        results["policies"].append(_summary(name, spec, ep, meta))
        if verbose:
            s = results["policies"][-1]
            print(
                f"  {name}: success {s['success_rate']:.3f} in {meta['eval_time_s']:.1f} s",
                flush=True,
            )

    by = {p["kind"]: p for p in results["policies"] if p["kind"] in ("oracle", "random")}
    if "oracle" in by and "random" in by:
        for p in results["policies"]:
            v = normalized_score(
                p["success_rate"], by["random"]["success_rate"], by["oracle"]["success_rate"]
            )
            p["normalized_score"] = None if math.isnan(v) else v

    # runs of one algorithm trained with the same env kwargs, differing only in the seed
    by_config: dict[tuple[str, str], list[dict]] = defaultdict(list)
    for p in results["policies"]:
        if p["kind"] == "model":
            kw = json.dumps(p.get("train_env_kwargs") or {}, sort_keys=True)
            name = "+".join(
                str(x) for x in (p["algo"], p.get("method"), p.get("expert")) if x is not None
            )
            by_config[(name, kw)].append(p)
    n_configs = defaultdict(int)
    for algo, _ in by_config:
        n_configs[algo] += 1
    groups = {
        (algo if n_configs[algo] == 1 else f"{algo} {kw}"): runs
        for (algo, kw), runs in by_config.items()
    }
    for algo, runs in groups.items():
        train_seeds = {r.get("train_seed") for r in runs}
        if len(runs) >= 2 and len(train_seeds) == len(runs):
            scores = np.array([[r["success_rate"]] for r in runs])  # (runs, tasks=1)
            est, lo, hi = stratified_bootstrap_ci(scores, iqm, seed=seed)
            results["iqm"][algo] = {
                "n_runs": len(runs),
                "train_seeds": sorted(train_seeds, key=lambda s: (s is None, s)),
                "iqm": est,
                "ci95": [lo, hi],
                "policies": [r["name"] for r in runs],
            }

    if out is not False:
        outdir.mkdir(parents=True, exist_ok=True)
        files = {"json": str(outdir / "results.json"), "csv": str(outdir / "results.csv")}
        if plot:
            files["png"] = str(outdir / "results.png")
        results["files"] = files
        with open(files["json"], "w") as f:
            json.dump(results, f, indent=1)
        cols = [
            "name",
            "spec",
            "kind",
            "episodes",
            "successes",
            "success_rate",
            "ci95_low",
            "ci95_high",
            "mean_return",
            "std_return",
            "mean_steps",
            "mean_path_length",
            "normalized_score",
        ]
        with open(files["csv"], "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(cols)
            for p in results["policies"]:
                row = dict(p, ci95_low=p["success_ci95"][0], ci95_high=p["success_ci95"][1])
                w.writerow(["" if row.get(c) is None else row.get(c) for c in cols])
        if plot:
            _plot(results, Path(files["png"]))
    if verbose:
        print(
            f"\n{env_id}{' ' + json.dumps(env_kwargs) if env_kwargs else ''}: {episodes} "
            f"episodes, seeds "
            f"{seeds[0]}..{seeds[-1]}"
        )
        print(format_table(results))
        if not deterministic:
            print("trained models sampled their actions (stochastic evaluation)")
        if fixed:
            print(
                "note: every episode starts from the scene's fixed start, so a deterministic "
                "policy replays nearly one episode; the Wilson intervals are sized by the "
                "distinct (scene, start) episodes -- compare training seeds (IQM) too"
            )
        if results["files"]:
            print("wrote " + ", ".join(results["files"].values()))
    return results
