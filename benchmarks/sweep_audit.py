"""A dense-in-time audit of the sweep: does its union hold every shadow between its samples?

    python -m benchmarks.sweep_audit [--n 600] [--seed 200000] [--times 41] [--jobs 2]

On the scenes of the swept fuzz (:func:`geometry.fuzz.fuzz_scene`, every contact family), the
swept partial region over G and, where G or H is a polygon, the 5.2 recognizable region; for
every sweep the query runs, the exact stationary shadow S(t) at ``--times`` evenly spaced
configurations along each of its segments, compared with the union the sweep built
(``geometry.sweep._union_pieces``).  A part of S(t) outside the union is a shadow the sweep
missed there (or a traced curve's chord: those are within ``tol`` = 1e-4 of the scene's size).
Per query the widest such part (twice its area over its perimeter, in units of the scene's
size, the local frame's ``scale``).  This is sharper than the fuzz's sampled placements:
a missed shadow a few ``tol`` across is found wherever it lives at one of the times.

The data (``sweep_audit.json``) and fragment (``sweep_audit.md``) go to ``--out`` or, with
``--update-results``, to the tracked files (see :mod:`benchmarks._results`).
"""

from __future__ import annotations

import argparse
import time
from concurrent.futures import ProcessPoolExecutor
from typing import Any
from unittest import mock

import numpy as np
import shapely

from . import _results

#: the width classes of the table, in units of the scene's size (the last one: above 1e-4)
CLASSES = (1e-8, 1e-6, 1e-5, 1e-4)


def widest_miss(scene: Any, query: str, n_t: int) -> float:
    """The widest part (in units of the scene's size) of a shadow S(t), at ``n_t`` times along
    every segment of every sweep of ``query`` (``"swept"``: ``partial_region(target_in=
    "goal")``; ``"recognizable"``: ``recognizable_region(model="partial")``) on ``scene``,
    outside that sweep's union; 0.0 where every one lies inside."""
    from geometry import partial_region, recognizable_region
    from geometry import sweep as S

    segs: list[tuple] = []
    unions: dict[int, shapely.Geometry] = {}
    along, union = S.Sweeper.along_many, S._union_pieces

    def spy(self, pairs, *rest):
        segs.extend((self, np.asarray(a, float), np.asarray(b, float)) for a, b in pairs)
        return along(self, pairs, *rest)

    def keep(sw, pieces):
        unions[id(sw)] = got = union(sw, pieces)
        return got

    kw = {"theta": 0.0, "timeout": None}
    with (
        mock.patch.object(S.Sweeper, "along_many", spy),
        mock.patch.object(S, "_union_pieces", keep),
    ):
        if query == "swept":
            partial_region(scene, target_in="goal", **kw)
        else:
            recognizable_region(scene, model="partial", **kw)
    widest = 0.0
    for sw, a, b in segs:
        u = unions.get(id(sw))
        if u is None:
            continue
        shapely.prepare(u)
        for t in np.linspace(0.0, 1.0, n_t):
            rest = shapely.get_parts(shapely.difference(sw.shadow(a + t * (b - a))[0], u))
            if len(rest):
                w = 2.0 * shapely.area(rest) / np.maximum(shapely.length(rest), 1e-300)
                widest = max(widest, float(w.max()) / sw.env.scale)
    return widest


def _seeds(arg: tuple[int, int, int]) -> list[dict[str, Any]]:
    """Audit ``n`` seeds from ``seed`` at ``n_t`` times: one row per query."""
    from geometry import Scene, SceneError
    from geometry.fuzz import fuzz_scene

    seed, n, n_t = arg
    rows = []
    for s in range(seed, seed + n):
        d = fuzz_scene(s, contacts=True)  # None: no valid scene from this seed
        if d is None:
            continue
        try:
            scene = Scene.from_dict({k: v for k, v in d.items() if k != "features"})
        except (SceneError, ValueError):
            continue
        queries = ["swept"]
        if "Polygon" in (scene.goal_geom.geom_type, scene.failure_geom.geom_type):
            queries.append("recognizable")
        for q in queries:
            t0 = time.perf_counter()
            row: dict[str, Any] = {"seed": s, "query": q}
            try:
                row["widest"] = widest_miss(scene, q, n_t)
            except Exception as e:  # a query that fails is a finding too: kept, not fatal
                row["widest"], row["error"] = None, f"{type(e).__name__}: {e}"
            rows.append({**row, "seconds": time.perf_counter() - t0})
    return rows


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(
        prog="python -m benchmarks.sweep_audit", description=__doc__.split("\n\n")[0]
    )
    ap.add_argument("--n", type=int, default=600, help="number of seeds")
    ap.add_argument("--seed", type=int, default=200_000, help="first seed")
    ap.add_argument("--times", type=int, default=41, help="configurations per segment")
    ap.add_argument("--chunk", type=int, default=25, help="seeds per job")
    ap.add_argument("--jobs", type=int, default=1, help="processes")
    _results.add_output_args(ap, "sweep_audit")
    args = ap.parse_args(argv)
    for opt in ("n", "times", "chunk", "jobs"):
        if getattr(args, opt) < 1:
            ap.error(f"--{opt} must be a positive integer, got {getattr(args, opt)}")
    starts = range(args.seed, args.seed + args.n, args.chunk)
    todo = [(s, min(args.chunk, args.seed + args.n - s), args.times) for s in starts]
    rows: list[dict[str, Any]] = []
    with ProcessPoolExecutor(args.jobs) as ex:
        for got in ex.map(_seeds, todo):
            rows += got
            print(f"{len(rows)} queries audited", flush=True)
    data = {
        "command": _results.command("benchmarks.sweep_audit", argv),
        "machine": _results.machine(),
        "seeds": [args.seed, args.seed + args.n - 1],
        "times": args.times,
        **summarize(rows),
    }
    _results.write("sweep_audit", data, args.out, args.update_results)


def summarize(rows: list[dict[str, Any]]) -> dict[str, Any]:
    """The audit's rows (one per query: ``seed``, ``query``, ``widest`` or None and
    ``error``, ``seconds``) as tracked: per query kind the number audited and the counts per
    width class (:data:`CLASSES`, then wider), the rows wider than 1e-6 of the scene and
    those that failed (seed, query, widest to three digits), and the process-seconds."""
    ok = [r for r in rows if r["widest"] is not None]
    counts = {}
    for q in ("swept", "recognizable"):
        ws = np.array([r["widest"] for r in ok if r["query"] == q])
        counts[q] = np.bincount(np.searchsorted(CLASSES, ws), minlength=len(CLASSES) + 1)
    return {
        "queries": len(rows),
        "counts": {q: [int(c) for c in v] for q, v in counts.items()},
        "misses": [
            {"seed": r["seed"], "query": r["query"], "widest": float(f"{r['widest']:.3g}")}
            for r in sorted(ok, key=lambda r: -r["widest"])
            if r["widest"] > CLASSES[1]
        ],
        "failed": [
            {"seed": r["seed"], "query": r["query"], "error": r["error"]}
            for r in rows
            if r["widest"] is None
        ],
        "seconds": round(sum(r["seconds"] for r in rows), 1),
    }


def render(data: dict[str, Any]) -> str:
    """The page fragment: per query, how many audits found their widest missed part in each
    width class, and the queries whose miss is wider than ``tol`` (1e-4 of the scene)."""
    a, b = data["seeds"]
    heads = [f"≤ {c:g}" for c in CLASSES] + [f"> {CLASSES[-1]:g}"]
    out = [
        f"Seeds {a}-{b} of the swept fuzz's scenes, {data['queries']} queries, the exact shadow "
        f"at {data['times']} configurations along every segment of every sweep; the widest part "
        "outside the sweep's union, in units of the scene's size (`tol` is 1e-4):",
        "",
        "| query | audited | " + " | ".join(heads) + " |",
        "|---|---:|" + "---:|" * len(heads),
    ]
    for q, counts in data["counts"].items():
        out.append(f"| {q} | {sum(counts)} | " + " | ".join(map(str, counts)) + " |")
    wide = [r for r in data["misses"] if r["widest"] > CLASSES[-1]]
    out.append("")
    if wide:
        out.append(
            "Wider than `tol`: "
            + ", ".join(f"seed {r['seed']} {r['query']} ({r['widest']:.2g})" for r in wide)
            + "."
        )
    else:
        out.append("No miss wider than `tol`.")
    if data["failed"]:
        out.append(
            "Queries that failed: "
            + ", ".join(f"seed {r['seed']} {r['query']} ({r['error']})" for r in data["failed"])
            + "."
        )
    out.append(f"\n{data['seconds'] / 3600.0:.2f} process-hours.")
    return "\n".join(out) + "\n"


if __name__ == "__main__":  # pragma: no cover
    main()
