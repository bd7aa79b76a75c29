"""The oracle watchers (and random watchers) on every bundled scene, one and two watchers.

    python -m benchmarks.watch_oracle [--episodes 200] [--seed 0]

:func:`agents.evaluation.watch.evaluate_watch` of the oracle and of uniform random actions
on ``corridor``, ``edr``, ``lab`` and ``warehouse`` with 1 and 2 watchers, the same episode
seeds (1,000,000 + seed onwards) for every row; complete model, 16 beams, watchers starting at
seeded random free poses.  The data (``watch_oracle.json``, without the per-episode lists) and
the page fragment go to ``--out`` (default ``runs/benchmarks/watch_oracle/``), or with
``--update-results`` to ``benchmarks/results/watch_oracle.json`` and
``docs/results/watch_oracle.md``.
"""

from __future__ import annotations

import argparse
import time
from typing import Any

from agents.evaluation.evaluate import EVAL_SEED_BASE
from agents.evaluation.watch import evaluate_watch
from sensorplan_gym.core.world import BUNDLED_SCENES

from . import _results

KEYS = (
    "scene",
    "n_watchers",
    "episodes",
    "successes",
    "success_ci95",
    "watcher_success",
    "visible_fraction",
    "team_visible_fraction",
    "a_in_H",
)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        prog="python -m benchmarks.watch_oracle", description=__doc__.split("\n\n")[0]
    )
    ap.add_argument("--episodes", type=int, default=200)
    ap.add_argument("--seed", type=int, default=0)
    _results.add_output_args(ap, "watch_oracle")
    args = ap.parse_args(argv)
    data: dict[str, Any] = {
        "command": _results.command("benchmarks.watch_oracle", argv),
        "machine": _results.machine(),
        "episodes": args.episodes,
        "seed": args.seed,
        "rows": [],
    }
    t0 = time.perf_counter()
    for policy in ("oracle", "random"):
        rows = evaluate_watch(
            list(BUNDLED_SCENES), [1, 2], policy=policy, episodes=args.episodes, seed=args.seed
        )
        for r in rows:
            row = {"policy": policy, **{k: r[k] for k in KEYS}}
            row["success_ci95"] = [float(v) for v in row["success_ci95"]]
            data["rows"].append(row)
            print(data["rows"][-1], flush=True)
    data["seconds"] = round(time.perf_counter() - t0, 1)
    _results.write("watch_oracle", data, args.out, args.update_results)
    return 0


def render(data: dict[str, Any]) -> str:
    """The page fragment: one row per policy, scene and number of watchers."""
    lines = [
        "| policy | scene | watchers | success (every watcher right) | 95 % Wilson CI | "
        "per-watcher right | visible fraction per watcher | team visible fraction | A ended in H |",
        "| --- | --- | ---: | ---: | --- | ---: | ---: | ---: | ---: |",
    ]
    for r in data["rows"]:
        lo, hi = r["success_ci95"]
        lines.append(
            f"| {r['policy']} | {r['scene']} | {r['n_watchers']} | "
            f"{r['successes']}/{r['episodes']} | [{lo:.3f}, {hi:.3f}] | "
            f"{r['watcher_success']:.3f} | {r['visible_fraction']:.3f} | "
            f"{r['team_visible_fraction']:.3f} | {r['a_in_H']:.2f} |"
        )
    m = data["machine"]
    lines += [
        "",
        f"`{data['command']}`: {data['episodes']} episodes per row, episode seeds "
        f"{EVAL_SEED_BASE + data['seed']:,} onwards; {data['seconds']:,.0f} s on {m['cpus']} CPUs "
        f"(load average {m['load_average']}).",
    ]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    raise SystemExit(main())
