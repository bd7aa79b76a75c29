"""Scaling of the exact region queries to thousands of edges, with an anchor.

    python -m benchmarks.scaling                 # 100 .. 8000 edges (several minutes)
    python -m benchmarks.scaling --max-edges 1600 --reps 5

For scenes from :func:`geometry.generate.scene_with_edges` (``seed=1``) with 100, 200,
400, 800, 1,600, 3,200 and 8,000 environment edges, and for the bundled large office
floor (``sensorplan_gym/scenes/large/office_floor.json``) and the real maps of 100-300
edges (``sensorplan_gym/scenes/real/``: two public ROS maps, two OpenStreetMap floor plans
imported from GeoJSON), it times with
``time.perf_counter`` (median over ``--reps`` warm calls on one Scene, the per-scene
structures already built):

* ``complete_region`` of a stationary target (at a point of G, orientation 0.3),
* ``partial_region`` of the same stationary target,
* ``recognizable_region(model="complete", theta=0.3)`` (polygonal G and H),

and, **in the same run on the same scenes**, the anchor: one CGAL visibility polygon
(pyvispoly's triangular expansion, ``compute_visibility_polygon``) at each of 20 free
points, median per point.  The table gives each median, its ratio to the anchor, and
the log-log growth slope (least squares over 100 .. 1,600 edges).  It also times
``gym.make`` and ``reset`` of Navigate-v0 on the office floor, and with ``--swept`` the
swept partial queries at 100 edges with and without the index (same run).  Up to ``--brute-max``
edges (default 1,600) the complete and partial queries are also timed with the grid index
switched off (the numpy brute-force ray casts, the code path without numba), so the
speed-up is read off one run.  The data (``scaling.json``) and the page fragment
(``scaling.md``) go to ``--out`` (default ``runs/benchmarks/scaling/``), or with
``--update-results`` to the tracked ``benchmarks/results/scaling.json`` and
``docs/results/scaling.md``.  pyvispoly is optional (dev extra); without it the
anchor columns are empty.  The machine is shared: quote ratios and medians.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import shapely

from geometry import Scene, complete_region, partial_region, recognizable_region
from geometry.generate import scene_with_edges
from sensorplan_gym.core.scenes import load_scene

from . import _results

EDGES = (100, 200, 400, 800, 1600, 3200, 8000)
SEED = 1
OFFICE = (
    Path(__file__).resolve().parent.parent
    / "sensorplan_gym"
    / "scenes"
    / "large"
    / "office_floor.json"
)


#: the bundled real floor plans of 100-300 edges (benchmarks.make_real_maps: public ROS maps;
#: benchmarks.make_geojson_maps: OpenStreetMap indoor GeoJSON)
REAL = ("real/heidelberg_l1", "real/heidelberg_l2", "real/willow_north", "real/willow_south")


def _pose(s: Scene) -> tuple[float, float, float]:
    c = s.goal_geom.representative_point()
    return (c.x, c.y, 0.3 if s.name.startswith("bench") else 0.0)


QUERIES: list[tuple[str, Callable[[Scene], object]]] = [
    ("complete, stationary", lambda s: complete_region(s, target_at=_pose(s))),
    ("partial, stationary", lambda s: partial_region(s, target_at=_pose(s))),
    (
        "recognizable, complete",
        lambda s: recognizable_region(
            s, model="complete", theta=0.3 if s.name.startswith("bench") else 0.0
        ),
    ),
]


def _median_time(fn: Callable[[], object], reps: int, budget: float) -> float:
    """Median seconds of ``fn`` over up to ``reps`` calls after one warm call; stops
    early once ``budget`` seconds are spent (at least one timed call)."""
    t0 = time.perf_counter()
    fn()
    first = time.perf_counter() - t0
    times: list[float] = []
    spent = first
    while len(times) < reps and (not times or spent + first < budget):
        t0 = time.perf_counter()
        fn()
        dt = time.perf_counter() - t0
        times.append(dt)
        spent += dt
    return statistics.median(times)


def _anchor(s: Scene, n_points: int = 20) -> float | None:
    """Median seconds of one pyvispoly (CGAL) visibility polygon at free points of ``s``."""
    try:
        import pyvispoly as pv
    except ImportError:
        return None

    def ring(coords: np.ndarray, ccw: bool) -> pv.Polygon:
        a = np.asarray(coords)[:-1]
        area2 = np.sum(a[:, 0] * np.roll(a[:, 1], -1) - np.roll(a[:, 0], -1) * a[:, 1])
        if (area2 > 0) != ccw:
            a = a[::-1]
        return pv.Polygon([pv.Point(float(x), float(y)) for x, y in a])

    fs = s.free_space
    polys = [fs] if fs.geom_type == "Polygon" else list(fs.geoms)
    big = max(polys, key=lambda p: p.area)
    calc = pv.VisibilityPolygonCalculator(
        pv.PolygonWithHoles(
            ring(big.exterior.coords, True), [ring(h.coords, False) for h in big.interiors]
        )
    )
    rng = np.random.default_rng(0)
    x0, y0, x1, y1 = big.bounds
    shapely.prepare(big)
    pts: list[tuple[float, float]] = []
    while len(pts) < n_points:
        x, y = rng.uniform(x0, x1), rng.uniform(y0, y1)
        if big.contains(shapely.Point(x, y)):
            pts.append((x, y))
    times = []
    for x, y in pts:
        q = pv.Point(x, y)
        t0 = time.perf_counter()
        calc.compute_visibility_polygon(q)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def _slope(xs: list[float], ys: list[float]) -> float:
    return float(np.polyfit(np.log(xs), np.log(ys), 1)[0])


def _fmt_ms(t: float | None) -> str:
    if t is None:
        return "-"
    ms = 1e3 * t
    return f"{ms:,.0f}" if ms >= 100 else f"{ms:.1f}" if ms >= 1 else f"{ms:.2f}"


def _brute(fn: Callable[[], object], reps: int, budget: float) -> float:
    """:func:`_median_time` with :mod:`geometry.visindex` switched off."""
    from geometry import visindex

    saved = visindex._HAVE_NUMBA
    visindex._HAVE_NUMBA = False
    try:
        return _median_time(fn, reps, budget)
    finally:
        visindex._HAVE_NUMBA = saved


def run(
    edges: tuple[int, ...],
    reps: int,
    budget: float,
    office: bool = True,
    brute_max: int = 1600,
    real: bool = True,
) -> dict[str, Any]:
    """Time every case; returns the rows (seconds; ``None`` where not measured) and, with the
    office floor, the env timings."""
    rows = []
    cases: list[tuple[str, int, Scene]] = []
    for n in edges:
        d = scene_with_edges(n, SEED)
        cases.append((str(n), n, Scene.from_dict(d)))
    if office and OFFICE.exists():
        s = Scene.load(OFFICE)
        cases.append(("office floor", len(s.bounds) + sum(len(o) for o in s.obstacles), s))
    for name in REAL if real else ():
        s = load_scene(name)
        cases.append((s.name, len(s.bounds) + sum(len(o) for o in s.obstacles), s))
    for label, n, s in cases:
        anchor = _anchor(s)
        row: dict[str, Any] = {"scene": label, "edges": n, "anchor_s": anchor, "query_s": {}}
        for qname, fn in QUERIES:
            t = _median_time(lambda fn=fn, s=s: fn(s), reps, budget)
            row["query_s"][qname] = t
            print(f"  {label:>12} edges={n:5d} {qname:24s} {_fmt_ms(t):>8} ms", flush=True)
        row["brute_s"] = {}
        for qname, fn in QUERIES[:2]:
            if n <= brute_max:
                tb = _brute(lambda fn=fn, s=s: fn(s), reps, budget)
                print(f"  {label:>12} edges={n:5d} {qname:24s} {_fmt_ms(tb):>8} ms (brute)")
                row["brute_s"][qname] = tb
            else:
                row["brute_s"][qname] = None
        rows.append(row)
    data: dict[str, Any] = {"reps": reps, "rows": rows, "office_env": None, "swept": None}
    if office and OFFICE.exists():
        t_make, t_reset = _env_times()
        data["office_env"] = {"make_s": t_make, "reset_s": t_reset}
    return data


def render(data: dict[str, Any]) -> str:
    """The page fragment: medians (ms) with their ratio to the anchor, the growth slopes over
    100 .. 1,600 edges, the office floor's env timings and the swept queries."""
    qnames = [q for q, _ in QUERIES]
    head = (
        "| scene | edges | pyvispoly point query (anchor) | "
        + " | ".join(f"{q} (x anchor)" for q in qnames)
        + " | "
        + " | ".join(f"{q}, no index" for q in qnames[:2])
        + " |"
    )
    lines = [head, "| --- |" + " ---: |" * (4 + len(qnames))]
    for r in data["rows"]:
        a = r["anchor_s"]
        cells = [r["scene"] if not r["scene"].isdigit() else "generated", f"{r['edges']:,}"]
        cells.append(f"{_fmt_ms(a)} ms" if a else "-")
        for q in qnames:
            t = r["query_s"][q]
            cells.append(f"{_fmt_ms(t)} ms" + (f" ({t / a:,.0f}x)" if a else ""))
        for q in qnames[:2]:
            t = r["brute_s"].get(q)
            cells.append(f"{_fmt_ms(t)} ms" if t is not None else "")
        lines.append("| " + " | ".join(cells) + " |")
    slopes = []
    for q in qnames:
        pts = sorted(
            (r["edges"], r["query_s"][q])
            for r in data["rows"]
            if r["scene"].isdigit() and 100 <= r["edges"] <= 1600
        )
        slopes.append(f"{_slope(*zip(*pts, strict=True)):.2f}" if len(pts) >= 2 else "-")
    lines.append("| growth slope 100 -> 1,600 | | | " + " | ".join(slopes) + " | | |")
    m = data["machine"]
    lines += [
        "",
        f"`{data['command']}`: median of up to {data['reps']} warm calls; anchor = median CGAL "
        "visibility polygon (pyvispoly) at 20 free points of the same scene, same run; "
        f"{m['cpus']} CPUs, Python {m['python']}, load average {m['load_average']}.",
    ]
    if data.get("office_env"):
        e = data["office_env"]
        lines += [
            "",
            f"Navigate-v0 on the office floor (complete model): `gym.make` "
            f"{1e3 * e['make_s']:,.0f} ms (the world is computed once), `reset` "
            f"{1e3 * e['reset_s']:.2f} ms (median of 20 seeds).",
        ]
    if data.get("swept"):
        sw = data["swept"]
        lines += [
            "",
            f"Swept queries, {sw['edges']} edges, G and H regular {sw['k']}-gons, fresh scene "
            f"per call, median of {sw['reps']} (seconds):",
            "",
            "| query | with the index | without | ratio |",
            "| --- | ---: | ---: | ---: |",
        ]
        for r in sw["rows"]:
            a, b = r["with_s"], r["without_s"]
            lines.append(f"| `{r['query']}` | {a:.2f} | {b:.2f} | {b / a:.1f}x |")
    return "\n".join(lines) + "\n"


def swept_ab(n_edges: int = 100, k: int = 5, reps: int = 3) -> dict[str, Any]:
    """The swept partial queries (``partial_region(target_in="goal")`` and 5.2's
    ``recognizable_region(model="partial")``, theta 0.3, G and H regular k-gons as in
    :mod:`benchmarks.swept`) with and without the index, alternating, each call on a freshly
    loaded scene; returns the medians (seconds)."""
    from benchmarks.swept import _kgon
    from geometry import visindex

    d = scene_with_edges(n_edges, SEED)
    d["goal"], d["failure"] = _kgon(d["goal"], k), _kgon(d["failure"], k)
    calls = {
        'partial_region(target_in="goal")': lambda s: partial_region(
            s, target_in="goal", theta=0.3
        ),
        'recognizable_region(model="partial")': lambda s: recognizable_region(
            s, model="partial", theta=0.3
        ),
    }
    out: dict[str, Any] = {"edges": n_edges, "k": k, "reps": reps, "rows": []}
    saved = visindex._HAVE_NUMBA
    try:
        for name, fn in calls.items():
            fn(Scene.from_dict(d))  # warm-up: numba's compiled kernels loaded, caches filled
            res: dict[bool, list[float]] = {True: [], False: []}
            for _ in range(reps):
                for on in (True, False):
                    visindex._HAVE_NUMBA = on and saved
                    s = Scene.from_dict(d)
                    t0 = time.perf_counter()
                    fn(s)
                    res[on].append(time.perf_counter() - t0)
            a, b = statistics.median(res[True]), statistics.median(res[False])
            out["rows"].append({"query": name, "with_s": a, "without_s": b})
            print(f"| `{name}` | {a:.2f} | {b:.2f} | {b / a:.1f}x |", flush=True)
    finally:
        visindex._HAVE_NUMBA = saved
    return out


def _env_times() -> tuple[float, float]:
    """Seconds of ``gym.make`` and the median ``reset`` of Navigate-v0 on the office floor."""
    import gymnasium as gym

    t0 = time.perf_counter()
    env = gym.make("sensorplan_gym:sensorplan/Navigate-v0", scene=str(OFFICE))
    t_make = time.perf_counter() - t0
    env.reset(seed=0)
    resets = []
    for seed in range(1, 21):
        t0 = time.perf_counter()
        env.reset(seed=seed)
        resets.append(time.perf_counter() - t0)
    env.close()
    return t_make, statistics.median(resets)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(
        prog="python -m benchmarks.scaling", description=__doc__.split("\n\n")[0]
    )
    ap.add_argument("--max-edges", type=int, default=max(EDGES))
    ap.add_argument(
        "--edges", type=int, nargs="+", default=None, help="scene sizes (default: 100 .. 8000)"
    )
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument(
        "--budget", type=float, default=20.0, help="seconds per query and scene (fewer reps)"
    )
    ap.add_argument("--no-office", action="store_true", help="skip the bundled office floor")
    ap.add_argument("--no-real", action="store_true", help="skip the bundled real maps")
    ap.add_argument(
        "--brute-max", type=int, default=1600, help="largest scene also timed without the index"
    )
    ap.add_argument(
        "--swept",
        action="store_true",
        help="also the swept partial queries at 100 edges with and without the index",
    )
    _results.add_output_args(ap, "scaling")
    args = ap.parse_args(argv)
    edges = tuple(n for n in (args.edges or EDGES) if n <= args.max_edges)
    data = {
        "command": _results.command("benchmarks.scaling", argv),
        "machine": _results.machine(),
        **run(
            edges,
            args.reps,
            args.budget,
            office=not args.no_office,
            brute_max=args.brute_max,
            real=not args.no_real,
        ),
    }
    if args.swept:
        data["swept"] = swept_ab()
    print(render(data))
    _results.write("scaling", data, args.out, args.update_results)


if __name__ == "__main__":
    main()
