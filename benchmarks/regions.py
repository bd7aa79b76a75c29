"""Wall time of the exact region queries versus scene size.

Run ``python -m benchmarks.regions`` (``--quick`` for fewer repetitions).  It ends
with the swept partial queries of :mod:`benchmarks.swept` (``--no-swept`` skips them).

For generated scenes with about 25, 50, 100 and 200 environment edges (walls plus
obstacle edges, :func:`geometry.generate.scene_with_edges`) it times every query
type with ``time.perf_counter`` (median and inter-quartile range over several
repetitions, each on a freshly loaded Scene so that no per-scene cache is reused),
prints a markdown table with the growth exponent (least-squares slope of
log(time) against log(edges)), and compares with what a user would otherwise do:
classify a 100 x 100 grid of placements with pyvispoly (CGAL) visibility polygons
for the stationary complete query.  The data (``regions.json``) and the page fragment
(``regions.md``) go to ``--out`` (default ``runs/benchmarks/regions/``), or with
``--update-results`` to the tracked ``benchmarks/results/regions.json`` and
``docs/results/regions.md`` (the swept queries likewise, as ``swept``).  pyvispoly is optional
(GPL, dev extra); without it the comparison is skipped.
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

from geometry import Scene, complete_region, partial_region, recognizable_region
from geometry.generate import scene_with_edges

from . import _results

EDGES = (25, 50, 100, 160, 200)
SEED = 1


def _point_variant(d: dict) -> dict:
    """The same scene with G and H shrunk to a point inside each (hulls stay clear)."""
    out = dict(d)
    for k in ("goal", "failure"):
        p = shapely.Polygon(d[k]).representative_point()
        out[k] = [[round(p.x, 6), round(p.y, 6)]]
    return out


def _queries() -> list[tuple[str, str, Callable[[Scene], object]]]:
    """(name, which scene variant, call)."""

    def pose(s: Scene) -> tuple[float, float, float]:
        c = s.goal_geom.representative_point()
        return (c.x, c.y, 0.3)

    return [
        ("complete, stationary", "poly", lambda s: complete_region(s, target_at=pose(s))),
        (
            "complete, translating (G polygon)",
            "poly",
            lambda s: complete_region(s, target_in="goal", theta=0.3),
        ),
        (
            "complete, rotating (theta=None)",
            "poly",
            lambda s: complete_region(s, target_in="goal", theta=None),
        ),
        ("partial, stationary", "poly", lambda s: partial_region(s, target_at=pose(s))),
        (
            "partial, eps_aim=5deg",
            "poly",
            lambda s: partial_region(s, target_at=pose(s), eps_aim=math.radians(5)),
        ),
        (
            "recognizable, complete (polygon G/H)",
            "poly",
            lambda s: recognizable_region(s, model="complete", theta=0.3),
        ),
        (
            "recognizable, partial (point G/H)",
            "point",
            lambda s: recognizable_region(s, model="partial", theta=0.3),
        ),
    ]


def _time(
    fn: Callable[[Scene], object], d: dict, reps: int, warm: bool = True
) -> tuple[float, float]:
    """Median and IQR (seconds) of ``fn``.

    ``warm``: repeated calls on one Scene (its cached visibility domain reused, as
    in an environment that queries the same scene many times); otherwise every
    call gets a freshly loaded Scene (first query on a scene).
    """
    times = []
    shared = Scene.from_dict(d)
    if warm:
        fn(shared)
    for _ in range(reps):
        s = shared if warm else Scene.from_dict(d)
        t0 = time.perf_counter()
        fn(s)
        times.append(time.perf_counter() - t0)
    q = statistics.quantiles(times, n=4) if len(times) >= 2 else [times[0]] * 3
    return statistics.median(times), q[2] - q[0]


def _slope(xs: list[float], ys: list[float]) -> float:
    lx, ly = np.log(xs), np.log(ys)
    return float(np.polyfit(lx, ly, 1)[0])


def _grid_oracle(d: dict, n: int) -> tuple[float, int]:
    """Seconds to classify an n x n grid for the stationary complete query with pyvispoly."""
    import pyvispoly as pv

    s = Scene.from_dict(d)
    c = s.goal_geom.representative_point()
    target = s.target_at(c.x, c.y, 0.3)
    t0 = time.perf_counter()
    fs = s.free_space
    polys = [fs] if fs.geom_type == "Polygon" else list(fs.geoms)

    def ring(coords, ccw):
        a = np.asarray(coords)[:-1]
        area2 = np.sum(a[:, 0] * np.roll(a[:, 1], -1) - np.roll(a[:, 0], -1) * a[:, 1])
        if (area2 > 0) != ccw:
            a = a[::-1]
        return pv.Polygon([pv.Point(float(x), float(y)) for x, y in a])

    calcs = [
        (
            p,
            pv.VisibilityPolygonCalculator(
                pv.PolygonWithHoles(
                    ring(p.exterior.coords, True), [ring(h.coords, False) for h in p.interiors]
                )
            ),
        )
        for p in polys
    ]
    x0, y0, x1, y1 = s.bounds_geom.bounds
    xs = np.linspace(x0, x1, n + 2)[1:-1]
    ys = np.linspace(y0, y1, n + 2)[1:-1]
    count = 0
    for x in xs:
        for y in ys:
            pt = shapely.Point(x, y)
            if target.covers(pt):
                continue
            for poly, calc in calcs:
                if poly.contains(pt):
                    q = pv.Point(float(x), float(y))
                    vp = calc.compute_visibility_polygon(q)
                    v = shapely.Polygon([(float(a.x()), float(a.y())) for a in vp.boundary()])
                    if not v.is_valid:
                        v = shapely.make_valid(v)
                    count += shapely.difference(target, v).area <= 1e-9 * target.area
                    break
    return time.perf_counter() - t0, count


def main(argv: list[str] | None = None) -> str:
    ap = argparse.ArgumentParser(
        prog="python -m benchmarks.regions", description=__doc__.splitlines()[0]
    )
    ap.add_argument("--quick", action="store_true", help="fewer repetitions, 20x20 grid")
    ap.add_argument("--reps", type=int, default=None, help="repetitions per measurement")
    ap.add_argument(
        "--no-swept", action="store_true", help="skip the swept partial queries (benchmarks.swept)"
    )
    _results.add_output_args(ap, "regions")
    args = ap.parse_args(argv)
    reps = args.reps or (5 if args.quick else 15)

    scenes = {n: scene_with_edges(n, SEED) for n in EDGES}
    actual = {n: len(d["bounds"]) + sum(len(o) for o in d["obstacles"]) for n, d in scenes.items()}
    variants = {n: {"poly": d, "point": _point_variant(d)} for n, d in scenes.items()}
    for n in EDGES:  # warm-up (imports, numpy dispatch)
        for _, var, fn in _queries():
            fn(Scene.from_dict(variants[n][var]))

    data: dict[str, Any] = {
        "command": _results.command("benchmarks.regions", argv),
        "machine": _results.machine(),
        "reps": reps,
        "seed": SEED,
        "edges": [actual[n] for n in EDGES],
        "rows": [],
        "grid": None,
    }
    medians: dict[tuple[str, bool], list[float]] = {}
    for warm in (True, False):
        for name, var, fn in _queries():
            meds, iqrs = [], []
            for n in EDGES:
                med, iqr = _time(fn, variants[n][var], reps, warm)
                meds.append(med)
                iqrs.append(iqr)
            medians[(name, warm)] = meds
            data["rows"].append({"query": name, "warm": warm, "median_s": meds, "iqr_s": iqrs})
            print(
                f"{'warm' if warm else 'cold'} {name}: "
                + ", ".join(f"{m * 1e3:.2f} ms" for m in meds),
                flush=True,
            )
    try:
        import pyvispoly  # noqa: F401

        have_pv = True
    except ImportError:
        have_pv = False
    n_bench = 100
    if have_pv:
        grid = 20 if args.quick else 100
        secs, _ = _grid_oracle(scenes[n_bench], grid)
        data["grid"] = {"edges": actual[n_bench], "grid": grid, "seconds": secs}
    text = render(data)
    print(text)
    _results.write("regions", data, args.out, args.update_results)
    if not args.no_swept:  # the swept partial queries (paper 3.2.2-3.2.3, 5.2): seconds each
        from . import swept

        out = ["--out", str(args.out.parent / "swept")]
        swept.main(
            (["--quick"] if args.quick else [])
            + (["--update-results"] if args.update_results else out)
        )
    return text


def render(data: dict[str, Any]) -> str:
    """The page fragment: warm and cold medians (ms) per query and scene size, the log-log
    growth slope, and the grid of pyvispoly visibility polygons for comparison."""
    edges = data["edges"]
    lines: list[str] = []
    for warm in (True, False):
        lines += [
            "",
            "**Warm** (repeated queries on one loaded Scene):"
            if warm
            else "**Cold** (first query on a freshly loaded Scene, building its visibility "
            "domain):",
            "",
            "| query | " + " | ".join(f"{n} edges" for n in edges) + " | growth (log-log slope) |",
            "| --- |" + " ---: |" * (len(edges) + 1),
        ]
        for r in data["rows"]:
            if r["warm"] != warm:
                continue
            cells = [f"{m * 1e3:.1f} ms" for m in r["median_s"]]
            slope = _slope(edges, r["median_s"])
            lines.append(f"| {r['query']} | " + " | ".join(cells) + f" | {slope:.2f} |")
    m = data["machine"]
    lines += [
        "",
        f"`{data['command']}`: median wall time over {data['reps']} repetitions; scenes "
        f"`scene_with_edges(n, seed={data['seed']})` (6-vertex target, polygonal G/H; the point "
        f"variant shrinks G and H to a point inside each); {m['cpus']} CPUs, Python "
        f"{m['python']}, shapely {m['shapely']}, numpy {m['numpy']}, load average "
        f"{m['load_average']}.",
    ]
    g = data.get("grid")
    if g:
        i = edges.index(g["edges"])
        warm = next(r for r in data["rows"] if r["warm"] and r["query"] == "complete, stationary")
        cold = next(
            r for r in data["rows"] if not r["warm"] and r["query"] == "complete, stationary"
        )
        scale = (100 * 100) / (g["grid"] ** 2)
        est = g["seconds"] * scale
        how = (
            "measured"
            if g["grid"] == 100
            else f"measured on a {g['grid']}x{g['grid']} grid, scaled"
        )
        lines += [
            "",
            "Without this package: classifying a 100 x 100 grid of placements with pyvispoly "
            "(CGAL) visibility polygons for the stationary complete query on the "
            f"{g['edges']}-edge "
            f"scene takes {est:.2f} s ({how}), {est / warm['median_s'][i]:,.0f} x the warm exact "
            f"query and {est / cold['median_s'][i]:,.0f} x the cold one, and gives only a raster.",
        ]
    return "\n".join(lines).strip() + "\n"


if __name__ == "__main__":
    main()
