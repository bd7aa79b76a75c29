"""Fuzzing a range of seeds (:func:`run_many`, in processes with ``jobs``) and the command line
(``python -m geometry.fuzz``)."""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections import Counter
from typing import Any

from .checks import check_scene
from .scenes import fuzz_scene

#: The command line's description (the first line of :mod:`geometry.fuzz`).
DESCRIPTION = "Fuzzing the region functions on degenerate scenes (issue 10)."


def run_many(
    n: int,
    *,
    seed: int = 0,
    swept: bool = False,
    max_edges: int = 60,
    verbose: bool = False,
    contacts: bool = False,
    frames: bool = False,
    nonstar: bool = False,
    jobs: int = 1,
    certify: bool = False,
) -> dict[str, Any]:
    """Fuzz ``n`` scenes (seeds ``seed .. seed + n - 1``); returns a summary dictionary.

    ``jobs`` > 1 splits the seeds into that many contiguous chunks run in separate
    processes (the summary is the same as one process's, ``seconds`` is wall time)."""
    if not isinstance(jobs, int) or jobs < 1:
        raise ValueError(f"jobs must be a positive integer, got {jobs!r}")
    if jobs > 1 and n > 1:
        return _run_parallel(
            n, seed, jobs, dict(swept=swept, max_edges=max_edges, verbose=verbose,
                                contacts=contacts, frames=frames, nonstar=nonstar,
                                certify=certify),
        )  # fmt: skip
    kinds: Counter[str] = Counter()
    failing: list[dict[str, Any]] = []
    slowest: dict[str, float] = {}
    n_valid = 0
    t0 = time.perf_counter()
    for i in range(seed, seed + n):
        d = fuzz_scene(i, max_edges=max_edges, contacts=contacts, nonstar=nonstar)
        if d is None:
            continue
        n_valid += 1
        found, times = check_scene(d, swept=swept, seed=i, frames=frames, certify=certify)
        for k, v in times.items():
            slowest[k] = max(slowest.get(k, 0.0), v)
        for f in found:
            kinds[f.kind] += 1
        if found:
            failing.append(
                {"seed": i, "features": d.get("features"), "findings": [vars(f) for f in found]}
            )
            if verbose:
                print(i, d.get("features"), [vars(f) for f in found], file=sys.stderr)
    return {
        "scenes": n,
        "valid": n_valid,
        "violations": dict(kinds),
        "failing_scenes": failing,
        "slowest_query_s": {k: round(v, 3) for k, v in sorted(slowest.items())},
        "seconds": round(time.perf_counter() - t0, 1),
    }


def _run_parallel(n: int, seed: int, jobs: int, kw: dict[str, Any]) -> dict[str, Any]:
    from concurrent.futures import ProcessPoolExecutor

    t0 = time.perf_counter()
    per = -(-n // jobs)
    chunks = [(s0, min(per, seed + n - s0)) for s0 in range(seed, seed + n, per)]
    with ProcessPoolExecutor(len(chunks)) as ex:
        parts = list(ex.map(_run_chunk, [(c, kw) for c in chunks]))
    kinds: Counter[str] = Counter()
    slowest: dict[str, float] = {}
    for r in parts:
        kinds.update(r["violations"])
        for k, v in r["slowest_query_s"].items():
            slowest[k] = max(slowest.get(k, 0.0), v)
    return {
        "scenes": n,
        "valid": sum(r["valid"] for r in parts),
        "violations": dict(kinds),
        "failing_scenes": [f for r in parts for f in r["failing_scenes"]],
        "slowest_query_s": dict(sorted(slowest.items())),
        "seconds": round(time.perf_counter() - t0, 1),
    }


def _run_chunk(arg: tuple[tuple[int, int], dict[str, Any]]) -> dict[str, Any]:
    (s0, k), kw = arg
    return run_many(k, seed=s0, **kw)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python -m geometry.fuzz", description=DESCRIPTION)
    ap.add_argument("--n", type=int, default=200, help="number of seeds (default 200)")
    ap.add_argument("--seed", type=int, default=0, help="first seed")
    ap.add_argument(
        "--swept", action="store_true", help="also the swept (target_in) partial queries"
    )
    ap.add_argument("--max-edges", type=int, default=60)
    ap.add_argument(
        "--contacts", action="store_true", help="the contact families of issue 26 in the scenes"
    )
    ap.add_argument(
        "--frames", action="store_true", help="also scaled (1e-3, 1e3) and UTM frames (issue 26)"
    )
    ap.add_argument(
        "--nonstar", action="store_true", help="non-star-shaped targets (U, comb, hook; issue 25)"
    )
    ap.add_argument(
        "--certify",
        action="store_true",
        help="with --swept: also the certified bounds (swept_bounds; issue 25)",
    )
    ap.add_argument("--jobs", type=int, default=1, help="processes (default 1)")
    ap.add_argument("--json", help="write the summary (with failing seeds) to this file")
    ap.add_argument("-v", "--verbose", action="store_true")
    a = ap.parse_args(argv)
    res = run_many(
        a.n,
        seed=a.seed,
        swept=a.swept,
        max_edges=a.max_edges,
        verbose=a.verbose,
        contacts=a.contacts,
        frames=a.frames,
        nonstar=a.nonstar,
        jobs=a.jobs,
        certify=a.certify,
    )
    if a.json:
        with open(a.json, "w", encoding="utf-8") as f:
            json.dump(res, f, indent=1)
    print(f"seeds {a.seed}..{a.seed + a.n - 1}: {res['valid']} valid scenes, {res['seconds']} s")
    for k in ("crash", "invalid", "outside", "inclusion", "unsafe", "translation", "frame", "hang"):
        print(f"  {k:12s} {res['violations'].get(k, 0)}")
    print("  slowest query (s):", res["slowest_query_s"])
    return 1 if res["violations"] else 0
