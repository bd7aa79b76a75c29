"""Wall time of the swept partial-visibility queries (paper 3.2.2-3.2.3, 5.2).

Run ``python -m benchmarks.swept`` (``--quick``: one repetition, fewer sizes).

For generated scenes with about 25, 50 and 100 environment edges
(:func:`geometry.generate.scene_with_edges`) the goal G is replaced by a regular k-gon (k =
4, 5, 6, 8) inside it, and H likewise by a k-gon inside H, so that the growth with the edges
of G can be read off. Times ``partial_region(target_in="goal", theta=0.3)`` and
``recognizable_region(model="partial", theta=0.3)`` (both sweeps, G and H, with the overlap
strips of 5.2); median and IQR over the repetitions, each on a freshly loaded Scene, and the
same with the previous sampling rules (the anchor). The data (``swept.json``) and the page
fragment (``swept.md``) go to ``--out`` (default ``runs/benchmarks/swept/``), or with
``--update-results`` to the tracked ``benchmarks/results/swept.json`` and
``docs/results/swept.md``.
"""

from __future__ import annotations

import argparse
import math
import statistics
import time
from collections.abc import Callable
from typing import Any

import numpy as np
import shapely

from geometry import Scene, partial_region, recognizable_region
from geometry import sweep as _sweep
from geometry.generate import scene_with_edges

from . import _results


def _eager(fn: Callable[[], Any]) -> Any:
    """``fn()`` with the sweep's previous sampling rules (next to every collinearity event,
    bisecting every empty eroded target: ``geometry.sweep.LAZY_SAMPLES`` False): the
    previous implementation as the anchor of the swept query, in the same run."""
    before = _sweep.LAZY_SAMPLES
    _sweep.LAZY_SAMPLES = False
    try:
        return fn()
    finally:
        _sweep.LAZY_SAMPLES = before


def _kgon(poly: list, k: int) -> list[list[float]]:
    """A regular k-gon inside the polygon ``poly`` (around its inscribed centre)."""
    g = shapely.Polygon(poly)
    c = g.representative_point()
    r = 0.8 * g.exterior.distance(c)
    ang = 0.3 + 2 * math.pi * np.arange(k) / k
    pts = np.column_stack([c.x + r * np.cos(ang), c.y + r * np.sin(ang)])
    return [[round(float(x), 6), round(float(y), 6)] for x, y in pts]


def _scene(edges: int, k: int, seed: int = 1) -> dict:
    d = dict(scene_with_edges(edges, seed))
    d["goal"] = _kgon(d["goal"], k)
    d["failure"] = _kgon(d["failure"], k)
    return d


def _time(fn, d: dict, reps: int) -> tuple[float, float]:
    times = []
    for _ in range(reps):
        s = Scene.from_dict(d)
        t0 = time.perf_counter()
        fn(s)
        times.append(time.perf_counter() - t0)
    q = statistics.quantiles(times, n=4) if len(times) >= 2 else [times[0]] * 3
    return statistics.median(times), q[2] - q[0]


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(prog="python -m benchmarks.swept", description=__doc__)
    ap.add_argument("--quick", action="store_true", help="one repetition, 25 and 100 edges")
    ap.add_argument("--reps", type=int, default=3)
    _results.add_output_args(ap, "swept")
    args = ap.parse_args(argv)
    reps = 1 if args.quick else args.reps
    sizes = (25, 100) if args.quick else (25, 50, 100)
    ks = (4, 6) if args.quick else (4, 5, 6, 8)
    queries = [
        ("partial_region(target_in=G)", lambda s: partial_region(s, target_in="goal", theta=0.3)),
        (
            "recognizable_region(partial, polygon G/H)",
            lambda s: recognizable_region(s, model="partial", theta=0.3),
        ),
    ]
    data: dict[str, Any] = {
        "command": _results.command("benchmarks.swept", argv),
        "machine": _results.machine(),
        "reps": reps,
        "rows": [],
    }
    queries[0][1](Scene.from_dict(_scene(sizes[0], ks[0])))  # one-time costs (kernels)
    for name, fn in queries:
        for n in sizes:
            for k in ks:
                d = _scene(n, k)
                med, iqr = _time(fn, d, reps)
                prev, _ = _time(lambda s, fn=fn: _eager(lambda: fn(s)), d, reps)
                data["rows"].append(
                    {
                        "query": name,
                        "edges": n,
                        "k": k,
                        "median_s": med,
                        "iqr_s": iqr,
                        "previous_s": prev,
                    }
                )
                print(f"| {name} | {n} | {k} | {med:.2f} | {iqr:.2f} | {prev:.2f} |", flush=True)
    _results.write("swept", data, args.out, args.update_results)


def render(data: dict[str, Any]) -> str:
    """The page fragment: one row per query and k, one column per scene size (median s)."""
    sizes = sorted({r["edges"] for r in data["rows"]})
    lines = [
        "| query | k = edges of G | " + " | ".join(f"{n} env edges" for n in sizes) + " |",
        "| --- | ---: |" + " ---: |" * len(sizes),
    ]
    seen: list[tuple[str, int]] = []
    for r in data["rows"]:
        if (r["query"], r["k"]) not in seen:
            seen.append((r["query"], r["k"]))
    last = None
    for q, k in seen:
        cells = []
        for n in sizes:
            m = [r for r in data["rows"] if (r["query"], r["k"], r["edges"]) == (q, k, n)]
            prev = m[0].get("previous_s") if m else None
            cell = f"{m[0]['median_s']:.2f} s" if m else ""
            cells.append(cell + (f" ({prev:.2f} s)" if prev is not None else ""))
        label = f"`{q}`" if q != last else ""
        last = q
        lines.append(f"| {label} | {k} | " + " | ".join(cells) + " |")
    m = data["machine"]
    lines += [
        "",
        f"`{data['command']}`: median of {data['reps']} calls, each on a freshly loaded scene "
        "(after one call that pays the one-time costs); in parentheses the same with the "
        "previous sampling rules (`geometry.sweep.LAZY_SAMPLES = False`), "
        f"the anchor, in the same run; {m['cpus']} CPUs, Python {m['python']}, "
        f"load average {m['load_average']}.",
    ]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
