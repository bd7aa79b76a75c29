"""Wall time of the swept partial-visibility queries (paper 3.2.2-3.2.3, 5.2).

Run ``python -m benchmarks.swept`` (``--quick``: one repetition, fewer sizes).

For generated scenes with about 25, 50 and 100 environment edges
(:func:`geometry.generate.scene_with_edges`) the goal G is replaced by a regular
k-gon (k = 4, 5, 6, 8) inside it, and H likewise by a k-gon inside H, so that the
growth with the edges of G can be read off.  Times
``partial_region(target_in="goal", theta=0.3)`` and
``recognizable_region(model="partial", theta=0.3)`` (both sweeps, G and H, with
the overlap strips of 5.2); median and IQR over the repetitions, each on a
freshly loaded Scene.  The table is written to ``benchmarks/results/swept.md``.
"""

from __future__ import annotations

import argparse
import math
import platform
import statistics
import time
from pathlib import Path

import numpy as np
import shapely

from geometry import Scene, partial_region, recognizable_region
from geometry.generate import scene_with_edges

RESULTS = Path(__file__).resolve().parent / "results" / "swept.md"


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
    lines = [
        f"Swept partial queries, median of {reps} (IQR), seconds; "
        f"{platform.processor() or platform.machine()}, python {platform.python_version()}",
        "",
        "| query | env edges | k = edges of G | median s | IQR s |",
        "|---|---|---|---|---|",
    ]
    for name, fn in queries:
        for n in sizes:
            for k in ks:
                d = _scene(n, k)
                med, iqr = _time(fn, d, reps)
                line = f"| {name} | {n} | {k} | {med:.2f} | {iqr:.2f} |"
                print(line, flush=True)
                lines.append(line)
    RESULTS.parent.mkdir(exist_ok=True)
    RESULTS.write_text("\n".join(lines) + "\n")
    print(f"written to {RESULTS}")


if __name__ == "__main__":
    main()
