"""Building a ``scene="random"`` pool of polygonal-G/H scenes under the partial model.

    python -m benchmarks.pool_build [--n 1024] [--jobs 1,2]

Every build goes through the env API a user calls::

    gym.make("sensorplan/Recognize-v0", scene="random", model="partial",
             random_scene_kwargs={"goal": "polygon", "failure": "polygon"},
             scene_pool_size=N, scene_pool_jobs=k, scene_pool_cache=folder)

with no world of an earlier build in memory (the process-wide pools and the world LRU are
cleared before each; worker processes are forked from this one), after one env on a bundled
scene has paid the one-time costs (imports, compiled kernels).  Rows, in the order run:

* **anchor**: the default pool of the same N (point G/H, complete model), built serially;
* **cold, jobs=k**: the polygonal pool into an empty disk-cache folder, in k processes
  (``--jobs``); with one process each scene is timed on its own (median and 90th percentile
  per scene, and the share of the time spent in ``geometry.recognizable_region``);
* **warm**: the same pool built again, serially, in a fresh env reading the folder the first
  cold build filled (the second build of a user: regions read, not computed).

The last column extrapolates each total linearly to 1,024 scenes (``total x 1024 / N``);
with ``--n 1024`` it is the measurement.  Ratios are to the anchor's total in the same run.
Data (``pool_build.json``) and fragment (``pool_build.md``) go to ``--out`` (default
``runs/benchmarks/pool_build/``), or with ``--update-results`` to the tracked
``benchmarks/results/pool_build.json`` and ``docs/results/pool_build.md``.
"""

from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

import sensorplan_gym  # noqa: F401
import sensorplan_gym.core.pool as pool_mod
import sensorplan_gym.core.world as world_mod
from sensorplan_gym.core.cache import clear_cache

from . import _results

ENV_ID = "sensorplan/Recognize-v0"
POLY = {"model": "partial", "random_scene_kwargs": {"goal": "polygon", "failure": "polygon"}}
TARGET = 1024


def _cpu() -> float:
    """CPU seconds (user + system) of this process and its finished children."""
    t = os.times()
    return t.user + t.system + t.children_user + t.children_system


def _fresh() -> None:
    """No pool or world of an earlier build in memory."""
    pool_mod._POOLS.clear()
    clear_cache()


def _serial(n: int, cache: Path | bool, **kw: Any) -> dict[str, Any]:
    """Build the pool of ``n`` scenes in this process, timing each scene: the env is made
    (scene 0 built in it), then scenes 1..n-1 are built one by one."""
    _fresh()
    region_s = [0.0]
    orig = world_mod.recognizable_region

    def timed(*a: Any, **k: Any):
        t = time.perf_counter()
        try:
            return orig(*a, **k)
        finally:
            region_s[0] += time.perf_counter() - t

    world_mod.recognizable_region = timed
    try:
        c0 = _cpu()
        t0 = time.perf_counter()
        env = gym.make(ENV_ID, scene="random", scene_pool_size=n, scene_pool_cache=cache, **kw)
        per = [time.perf_counter() - t0]
        pool = env.unwrapped.batch.source
        for k in range(1, n):
            t = time.perf_counter()
            pool.get(k)
            per.append(time.perf_counter() - t)
        total = time.perf_counter() - t0
        cpu = _cpu() - c0
    finally:
        world_mod.recognizable_region = orig
    c = pool.disk_cache
    p = np.array(per)
    return {
        "jobs": 1,
        "total_s": total,
        "cpu_s": cpu,
        "median_s": float(np.median(p)),
        "p90_s": float(np.percentile(p, 90)),
        "max_s": float(p.max()),
        "region_share": region_s[0] / total,
        "computed": None if c is None else c.misses,
        "read": None if c is None else c.hits,
    }


def _parallel(n: int, jobs: int, cache: Path, **kw: Any) -> dict[str, Any]:
    """Build the pool of ``n`` scenes at construction in ``jobs`` processes."""
    _fresh()
    c0 = _cpu()
    t0 = time.perf_counter()
    env = gym.make(
        ENV_ID,
        scene="random",
        scene_pool_size=n,
        scene_pool_jobs=jobs,
        scene_pool_cache=cache,
        **kw,
    )
    total = time.perf_counter() - t0
    cpu = _cpu() - c0  # the workers have been joined: their CPU time is counted
    pool = env.unwrapped.batch.source
    assert len(pool.entries) == n
    return {
        "jobs": jobs,
        "total_s": total,
        "cpu_s": cpu,
        "median_s": None,
        "p90_s": None,
        "max_s": None,
        "region_share": None,
        "computed": pool.disk_cache.misses,
        "read": pool.disk_cache.hits,
    }


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.pool_build", description=__doc__)
    ap.add_argument("--n", type=int, default=TARGET, help=f"scenes per pool (default {TARGET})")
    ap.add_argument("--jobs", default="1,2", help="process counts of the cold builds (1,2)")
    _results.add_output_args(ap, "pool_build")
    args = ap.parse_args(argv)
    if args.n < 2:
        ap.error("--n must be at least 2")
    jobs = sorted({int(j) for j in args.jobs.split(",")})
    if not jobs or jobs[0] < 1:
        ap.error("--jobs: positive process counts, e.g. 1,2")
    data: dict[str, Any] = {
        "command": _results.command("benchmarks.pool_build", argv),
        "machine": _results.machine(),
        "n": args.n,
        "target": TARGET,
        "rows": [],
    }

    def add(name: str, row: dict[str, Any]) -> None:
        row = {"build": name, **row}
        data["rows"].append(row)
        per = row["total_s"] / args.n
        print(
            f"{name:34s} jobs={row['jobs']} total {row['total_s']:8.1f} s  "
            f"{per:.3f} s/scene  median {row['median_s']}  computed {row['computed']}",
            flush=True,
        )

    gym.make(ENV_ID, scene="lab").reset(seed=0)  # one-time costs (imports, compiled kernels)
    add("anchor: point G/H, complete", _serial(args.n, False))
    with tempfile.TemporaryDirectory(prefix="pool_build-") as tmp:
        folders = {j: Path(tmp) / f"jobs{j}" for j in jobs}
        for j in jobs:
            if j == 1:
                add("polygonal G/H, partial: cold", _serial(args.n, folders[1], **POLY))
            else:
                add("polygonal G/H, partial: cold", _parallel(args.n, j, folders[j], **POLY))
        # the second build reads the folder of the first cold build
        add("polygonal G/H, partial: warm", _serial(args.n, folders[jobs[0]], **POLY))
    data["machine"]["load_average_end"] = _results.machine()["load_average"]
    _results.write("pool_build", data, args.out, args.update_results)


def _s(v: float | None, fmt: str = "{:.2f} s") -> str:
    return "" if v is None else fmt.format(v)


def render(data: dict[str, Any]) -> str:
    """The page fragment: one row per build."""
    n, target = data["n"], data["target"]
    anchor = data["rows"][0]["total_s"]
    ext = "measured" if n == target else f"extrapolated from {n}"
    lines = [
        f"| build of {n} scenes | processes | regions computed / read | total | CPU / wall | "
        f"per scene (total / N) | median, p90 per scene | time in the region | {target:,} scenes "
        f"({ext}) | ratio to the anchor |",
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    for r in data["rows"]:
        cr = "" if r["computed"] is None else f"{r['computed']} / {r['read']}"
        med = "" if r["median_s"] is None else f"{r['median_s']:.2f} s, {r['p90_s']:.2f} s"
        share = "" if r["region_share"] is None else f"{100 * r['region_share']:.0f} %"
        tot = r["total_s"] * target / n
        big = f"{tot / 60:.1f} min" if tot >= 120 else f"{tot:.0f} s"
        lines.append(
            f"| {r['build']} | {r['jobs']} | {cr} | {r['total_s']:.1f} s | "
            f"{r['cpu_s'] / r['total_s']:.2f} | "
            f"{r['total_s'] / n:.3f} s | {med} | {share} | {big} | "
            f"{r['total_s'] / anchor:.1f} |"
        )
    m = data["machine"]
    lines += [
        "",
        f"`{data['command']}`: {m['cpus']} CPUs shared with other jobs, Python {m['python']}, "
        f"load average {m['load_average']} at the start and {m.get('load_average_end')} at "
        "the end.",
    ]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
