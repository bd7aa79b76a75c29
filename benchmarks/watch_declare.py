"""Watchers that declare: the shipped learned team against the oracle and random watchers.

    python -m benchmarks.watch_declare [--policy agents/pretrained/dagger_watch_lab2.pt]
        [--episodes 200] [--seed 0]

The learned team (:class:`agents.learning.watch_imitation.WatchImitationPolicy`: DAgger of the
watch oracle with the beam-evidence observation), the oracle watchers and uniform random
actions, on the env the policy was trained on (lab, 2 watchers, ``evidence=True``) and the same
episode seeds (1,000,000 + seed onwards): per-watcher declaration accuracy, the fraction of
steps each watcher (and the team) saw A, and the episodes in which every watcher was right,
each with a 95 % interval over episodes
(:func:`agents.evaluation.watch_declare.summarize`).  The data (``watch_declare.json``,
without the per-episode lists) and the page fragment go to ``--out`` (default
``runs/benchmarks/watch_declare/``), or with ``--update-results`` to
``benchmarks/results/watch_declare.json`` and ``docs/results/watch_declare.md``.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path
from typing import Any

from agents.evaluation.episodes import EVAL_SEED_BASE
from agents.evaluation.watch import run_watch_episodes
from agents.evaluation.watch_declare import METRICS, summarize
from agents.learning.watch_imitation import WatchImitationPolicy

from . import _results

DEFAULT_POLICY = Path("agents") / "pretrained" / "dagger_watch_lab2.pt"


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        prog="python -m benchmarks.watch_declare", description=__doc__.split("\n\n")[0]
    )
    ap.add_argument("--policy", type=Path, default=DEFAULT_POLICY)
    ap.add_argument("--episodes", type=int, default=200)
    ap.add_argument("--seed", type=int, default=0)
    _results.add_output_args(ap, "watch_declare")
    args = ap.parse_args(argv)
    pol = WatchImitationPolicy(args.policy)
    seeds = [EVAL_SEED_BASE + args.seed + i for i in range(args.episodes)]
    data: dict[str, Any] = {
        "command": _results.command("benchmarks.watch_declare", argv),
        "machine": _results.machine(),
        "episodes": args.episodes,
        "seed": args.seed,
        "policy": args.policy.as_posix(),
        "training_command": pol.record.get("command"),
        "training_s": pol.record.get("wall_time_s"),
        "env_kwargs": pol.env_kwargs,
        "rows": [],
    }
    t0 = time.perf_counter()
    for name, who in (("learned", pol), ("oracle", "oracle"), ("random", "random")):
        t = time.perf_counter()
        s = summarize(run_watch_episodes(pol.env_kwargs, who, seeds), seed=args.seed)
        row = {"policy": name, **s, "seconds": round(time.perf_counter() - t, 1)}
        data["rows"].append(row)
        print(row, flush=True)
    data["seconds"] = round(time.perf_counter() - t0, 1)
    _results.write("watch_declare", data, args.out, args.update_results)
    return 0


def render(data: dict[str, Any]) -> str:
    """The page fragment: one row per policy, mean [95 % bootstrap interval]."""
    lines = [
        "| watchers | per-watcher declared right | A in view, per watcher | A in view, team | "
        "every watcher right |",
        "| --- | --- | --- | --- | --- |",
    ]
    for r in data["rows"]:
        cells = [f"{r[m][0]:.3f} [{r[m][1]:.3f}, {r[m][2]:.3f}]" for m in METRICS]
        lines.append(f"| {r['policy']} | " + " | ".join(cells) + " |")
    kw = data["env_kwargs"]
    m = data["machine"]
    lines += [
        "",
        f"`{data['command']}`: `{data['policy']}` on scene `{kw['scene']}` with "
        f"{kw['n_watchers']} watchers, {data['episodes']} episodes (seeds "
        f"{EVAL_SEED_BASE + data['seed']:,} onwards), 95 % intervals over episodes (Wilson for "
        "the rates, bootstrap for the view); "
        f"{data['seconds']:,.0f} s on {m['cpus']} CPUs (load average {m['load_average']}). "
        f"Trained by `{data['training_command']}` in {data['training_s']:,.0f} s.",
    ]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    raise SystemExit(main())
