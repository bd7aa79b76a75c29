"""Do learned watchers declare right, and keep A in view?  A learned team against the oracle.

``python -m agents.evaluation.watch_declare --policy agents/pretrained/dagger_watch_lab2.pt
[--episodes 200] [--seed 0] [--json FILE]``

Plays the learned team (:class:`agents.learning.watch_imitation.WatchImitationPolicy`, on
the env it was trained on: scene, watchers and ``evidence=True`` from its resolved YAML) and
the oracle watchers (:class:`agents.planning.watch_oracle.WatchOracle`) on the same episode
seeds (``1,000,000 + seed + i``, as every evaluation here) with
:func:`agents.evaluation.watch.run_watch_episodes`, and reports for each: the per-watcher
declaration accuracy (the fraction of watchers that declared A's end region right; a
watcher that never declares is wrong), the fraction of steps each watcher saw A, the
fraction on which some watcher did, and the episodes in which every watcher was right --
each a mean over episodes with a 95 % interval that takes episodes as the independent units
(the watchers of an episode are not): for the two rates a Wilson interval of the effective
count ``mean * episodes`` out of ``episodes`` (:func:`agents.evaluation.stats.wilson_interval`;
it stays informative at 100 %), for the two view fractions a percentile bootstrap over
episodes (:func:`agents.evaluation.stats.stratified_bootstrap_ci`, the statistic the mean).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from typing import Any

import numpy as np

from ..checks import check_writable_file
from ..learning.watch_imitation import WatchImitationPolicy
from .episodes import EVAL_SEED_BASE
from .stats import stratified_bootstrap_ci, wilson_interval
from .watch import run_watch_episodes

__all__ = ["METRICS", "RATES", "compare_with_oracle", "format_table", "main", "summarize"]

# summary name -> run_watch_episodes key (RATES get a Wilson interval, the rest a bootstrap one)
RATES = ("per_watcher_right", "all_right")
METRICS = {
    "per_watcher_right": "watcher_success",
    "visible_per_watcher": "visible",
    "team_visible": "team_visible",
    "all_right": "success",
}


def summarize(ep: dict[str, list], *, seed: int = 0) -> dict[str, Any]:
    """Per metric of :data:`METRICS`: ``[mean, ci_low, ci_high]`` over the episodes of
    ``ep`` (a :func:`run_watch_episodes` result): Wilson for :data:`RATES`, 2000 bootstrap
    replicates (seeded ``seed``) for the view fractions."""
    n = len(ep["seed"])
    out: dict[str, Any] = {"episodes": n}
    for name, key in METRICS.items():
        x = np.asarray(ep[key], dtype=float)
        if name in RATES:
            est = float(x.mean())
            lo, hi = wilson_interval(est * n, n)
            out[name] = [est, float(min(lo, est)), float(max(hi, est))]
        else:
            out[name] = list(stratified_bootstrap_ci(x, statistic=np.mean, seed=seed))
    return out


def compare_with_oracle(
    policy: WatchImitationPolicy, episodes: int = 200, seed: int = 0
) -> dict[str, Any]:
    """The learned team and the oracle on the same ``episodes`` seeds of the policy's env;
    returns ``{"env_kwargs", "seeds", "learned": summary, "oracle": summary, "wall_s"}``
    with :func:`summarize`'s summaries (and the per-episode lists under ``per_episode``)."""
    seeds = [EVAL_SEED_BASE + seed + i for i in range(int(episodes))]
    kw = dict(policy.env_kwargs)
    t0 = time.perf_counter()
    learned = run_watch_episodes(kw, policy, seeds)
    t1 = time.perf_counter()
    oracle = run_watch_episodes(kw, "oracle", seeds)
    t2 = time.perf_counter()
    return {
        "env_kwargs": kw,
        "seeds": [seeds[0], seeds[-1]],
        "learned": summarize(learned),
        "oracle": summarize(oracle),
        "wall_s": {"learned": round(t1 - t0, 1), "oracle": round(t2 - t1, 1)},
        "per_episode": {"learned": learned, "oracle": oracle},
    }


def format_table(res: dict[str, Any]) -> str:
    """The comparison as a Markdown table (mean [95 % CI])."""
    lines = [
        "| watchers | per-watcher declared right | A in view, per watcher | A in view, team | "
        "every watcher right |",
        "| --- | --- | --- | --- | --- |",
    ]
    for who in ("learned", "oracle"):
        s = res[who]
        cells = [f"{s[m][0]:.3f} [{s[m][1]:.3f}, {s[m][2]:.3f}]" for m in METRICS]
        lines.append(f"| {who} | " + " | ".join(cells) + " |")
    kw = res["env_kwargs"]
    lines.append("")
    lines.append(
        f"{res['learned']['episodes']} episodes (seeds {res['seeds'][0]:,}..{res['seeds'][1]:,}),"
        f" scene {kw.get('scene')!r}, {kw.get('n_watchers', 1)} watchers; 95 % intervals over "
        "episodes (Wilson for the rates, bootstrap for the view)."
    )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        prog="python -m agents.evaluation.watch_declare", description=__doc__.split("\n\n")[0]
    )
    ap.add_argument("--policy", required=True, help="a final_model.pt of watch_imitation")
    ap.add_argument("--episodes", type=int, default=200)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--json", default=None, help="write the comparison (with per-episode data)")
    args = ap.parse_args(argv)
    try:
        if args.episodes < 1:
            raise ValueError(f"--episodes must be positive, got {args.episodes}")
        if args.json:
            check_writable_file(args.json, what="--json")
        res = compare_with_oracle(WatchImitationPolicy(args.policy), args.episodes, args.seed)
    except (ValueError, KeyError, OSError) as err:
        print(f"{ap.prog}: error: {err}", file=sys.stderr)
        return 2
    print(format_table(res))
    if args.json:
        with open(args.json, "w") as f:
            json.dump(res, f, indent=1)
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
