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
for the stationary complete query.  The table is also written to
``benchmarks/results/regions.md``.  pyvispoly is optional (GPL, dev extra); without
it the comparison is skipped.
"""

from __future__ import annotations

import argparse
import math
import platform
import statistics
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import shapely

from geometry import Scene, complete_region, partial_region, recognizable_region
from geometry.generate import scene_with_edges

EDGES = (25, 50, 100, 160, 200)
SEED = 1
RESULTS = Path(__file__).resolve().parent / "results" / "regions.md"


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
    args = ap.parse_args(argv)
    reps = args.reps or (5 if args.quick else 15)

    scenes = {n: scene_with_edges(n, SEED) for n in EDGES}
    actual = {n: len(d["bounds"]) + sum(len(o) for o in d["obstacles"]) for n, d in scenes.items()}
    variants = {n: {"poly": d, "point": _point_variant(d)} for n, d in scenes.items()}
    for n in EDGES:  # warm-up (imports, numpy dispatch)
        for _, var, fn in _queries():
            fn(Scene.from_dict(variants[n][var]))

    lines = []
    head = "| query | " + " | ".join(f"{actual[n]} edges" for n in EDGES) + " | growth exponent |"
    medians: dict[tuple[str, bool], list[float]] = {}
    for warm in (True, False):
        lines.append("")
        lines.append(
            "**Warm** (repeated queries on one loaded Scene):"
            if warm
            else "**Cold** (first query on a freshly loaded Scene, building its visibility domain):"
        )
        lines.append("")
        lines.append(head)
        lines.append("|" + "---|" * (len(EDGES) + 2))
        for name, var, fn in _queries():
            cells = []
            meds = []
            for n in EDGES:
                med, iqr = _time(fn, variants[n][var], reps, warm)
                meds.append(med)
                cells.append(f"{med * 1e3:.2f} ms (IQR {iqr * 1e3:.2f})")
            medians[(name, warm)] = meds
            slope = _slope([actual[n] for n in EDGES], meds)
            lines.append(f"| {name} | " + " | ".join(cells) + f" | {slope:.2f} |")

    notes = [
        "",
        f"Median wall time (IQR) over {reps} repetitions; "
        f"scenes `scene_with_edges(n, seed={SEED})` (6-vertex target, polygonal G/H; the point "
        "variant shrinks G and H to a point inside each). Growth exponent: slope of "
        "log(time) vs log(edges).",
        f"Machine: {platform.processor() or platform.machine()}, "
        f"Python {platform.python_version()}, "
        f"shapely {shapely.__version__}, numpy {np.__version__}.",
    ]
    try:
        import pyvispoly  # noqa: F401

        have_pv = True
    except ImportError:
        have_pv = False
    n_bench = 100
    if have_pv:
        grid = 20 if args.quick else 100
        secs, _ = _grid_oracle(scenes[n_bench], grid)
        scale = (100 * 100) / (grid * grid)
        est = secs * scale
        exact = medians[("complete, stationary", True)][EDGES.index(n_bench)]
        cold = medians[("complete, stationary", False)][EDGES.index(n_bench)]
        how = (
            "measured"
            if grid == 100
            else f"measured on a {grid}x{grid} subgrid and scaled x{scale:g}"
        )
        notes += [
            "",
            "Alternative without this package: classify a 100x100 grid of placements with "
            "pyvispoly (CGAL) visibility polygons for the stationary complete query on the "
            f"{actual[n_bench]}-edge "
            f"scene: {est:.3f} s ({how}); exact complete_region: {exact * 1e3:.2f} ms warm, "
            f"{cold * 1e3:.2f} ms cold; speed-up x{est / exact:,.0f} warm, x{est / cold:,.0f} cold "
            "(and the grid answer is only a raster).",
        ]
    else:
        notes += ["", "pyvispoly not installed: grid comparison skipped."]
    text = "\n".join(lines + notes).strip() + "\n"
    print(text)
    RESULTS.parent.mkdir(parents=True, exist_ok=True)
    RESULTS.write_text("# Region query benchmark (`python -m benchmarks.regions`)\n\n" + text)
    if not args.no_swept:  # the swept partial queries (paper 3.2.2-3.2.3, 5.2): seconds each
        from . import swept

        swept.main(["--quick"] if args.quick else [])
    return text


if __name__ == "__main__":
    main()
