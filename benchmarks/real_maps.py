"""The region queries on the bundled real maps (public ROS and OpenStreetMap floor plans),
with an anchor.

    python -m benchmarks.real_maps                      # about six minutes a process
    python -m benchmarks.real_maps --reps 7 --processes 3
    python -m benchmarks.real_maps --no-slow            # the real maps only
    python -m benchmarks.real_maps --scenes willow_north,willow_south --processes 5

For every scene of ``sensorplan_gym/scenes/real/`` (written by
:mod:`benchmarks.make_real_maps` from the Willow Garage and LSE arena occupancy maps, and by
:mod:`benchmarks.make_geojson_maps` from an OpenStreetMap indoor map in GeoJSON; G and H are
regular pentagons) it times, each call on a freshly loaded Scene (so every call
builds its per-scene structures), median over ``--reps`` calls after one warm-up call, the
queries of a scene interleaved rep by rep (a slow spell of the machine falls on all alike):

* ``complete_region`` and ``partial_region`` of the stationary target at G's
  representative point, orientation 0;
* ``partial_region(target_in="goal")`` (the swept partial query, paper 3.2.2-3.2.3), and the
  same with the sampling rules before issue 25's lazy ones (next to every collinearity
  event, bisecting every empty eroded target: the previous implementation, as an anchor);
* ``recognizable_region(model="partial")`` (5.2: both sweeps, G and H polygons, with the
  overlap strips);
* ``recognizable_region(model="complete")``;

then the same on the independent fuzzer's slow reproductions (``slow_1``, ``slow_2``: issue
25 item 7, their own regions and orientation), and gives the ratios swept partial /
stationary partial and recognizable (partial) / stationary partial, the areas of the answers
(all non-empty), and, in the same run on the same scenes, the anchor: one CGAL visibility
polygon (pyvispoly) at each of 20 free points, median per point (see
:mod:`benchmarks.scaling`).

With ``--processes k`` (default 3) all of this runs ``k`` times, one after the other, each
time in a fresh Python process: on a 2-core machine one process's stationary query can run at
14 ms and the next one's at 20 ms (same code, same input, steady within a process), so one
process's ratios can be off by a fifth either way.  The table then gives, per query, the
median over the processes of their medians, and, per ratio, the median over the processes of
each one's ratio with the lowest and the highest.  Data (``real_maps.json``) and fragment
(``real_maps.md``) go to ``--out`` (default ``runs/benchmarks/real_maps/``) or, with
``--update-results``, to ``benchmarks/results/`` and ``docs/results/``.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import statistics
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from geometry import Scene, complete_region, partial_region, recognizable_region
from sensorplan_gym.core.scenes import REAL_SCENES, load_scene, real_scene_provenance

from . import _results
from .scaling import _anchor
from .swept import _eager

#: The independent fuzzer's slow swept queries (issue 25 item 7; ``tests/geometry/fuzz_repro/``,
#: copies of ``shared/fuzz-repro/``): scene JSON plus the call that took 6.6-10.7 s.
SLOW_REPROS = ("slow_1", "slow_2")

REPRO_DIR = Path(__file__).resolve().parents[1] / "tests" / "geometry" / "fuzz_repro"


def _pose(s: Scene, theta: float) -> tuple[float, float, float]:
    c = s.goal_geom.representative_point()
    return (c.x, c.y, theta)


def queries(theta: float) -> list[tuple[str, Callable[[Scene], Any]]]:
    """The timed queries, the target at orientation ``theta`` (radians)."""
    return [
        ("complete, stationary", lambda s: complete_region(s, target_at=_pose(s, theta))),
        ("partial, stationary", lambda s: partial_region(s, target_at=_pose(s, theta))),
        ("partial, swept over G", lambda s: partial_region(s, target_in="goal", theta=theta)),
        (
            "swept, previous rules",
            lambda s: _eager(lambda: partial_region(s, target_in="goal", theta=theta)),
        ),
        (
            "recognizable, partial",
            lambda s: recognizable_region(s, model="partial", theta=theta),
        ),
        (
            "recognizable, complete",
            lambda s: recognizable_region(s, model="complete", theta=theta),
        ),
    ]


QUERIES = queries(0.0)


def _repro(name: str) -> tuple[dict, float]:
    """The scene dictionary of a slow reproduction and the orientation of its call."""
    d = json.loads((REPRO_DIR / f"{name}.json").read_text(encoding="utf-8"))
    call = d["call"]
    theta = float(call.split("'theta': ")[1].split("}")[0].split(",")[0])
    return d["scene"], theta


def _time_fresh(
    fns: list[Callable[[Scene], Any]], load: Callable[[], Scene], reps: int
) -> list[tuple[float, float]]:
    """Per function of ``fns``: its median seconds on a freshly loaded scene (``reps`` calls
    after a warm-up) and the area of its answer.  The calls are interleaved, rep by rep (each
    function once per rep, in order), so that a slow spell of a noisy machine falls on every
    query of the scene alike instead of on one (a row's ratios come from these medians)."""
    areas = [float(fn(load()).area) for fn in fns]
    times: list[list[float]] = [[] for _ in fns]
    for _ in range(reps):
        for fn, got in zip(fns, times, strict=True):
            s = load()
            t0 = time.perf_counter()
            fn(s)
            got.append(time.perf_counter() - t0)
    return [(statistics.median(t), a) for t, a in zip(times, areas, strict=True)]


def _cases() -> list[tuple[str, str, Callable[[], Scene], float]]:
    """(name, source, loader, theta) of every timed scene: the bundled real maps, then the
    fuzzer's slow reproductions."""
    prov = real_scene_provenance()
    out = []
    for real in REAL_SCENES:
        name = real.removeprefix("real/")
        src = f"{prov[name]['repository']} {prov[name]['path']}"
        out.append((name, src, lambda real=real: load_scene(real), 0.0))
    for name in SLOW_REPROS:
        d, theta = _repro(name)
        src = f"tests/geometry/fuzz_repro/{name}.json (independent fuzzer, issue 25)"
        out.append((name, src, lambda d=d: Scene.from_dict(d), theta))
    return out


def _run_here(reps: int, slow: bool, scenes: tuple[str, ...] | None) -> dict[str, Any]:
    """:func:`run` in this process: seconds and square metres per scene and query."""
    rows = []
    for name, src, load, theta in _cases():
        if (not slow and name in SLOW_REPROS) or (scenes is not None and name not in scenes):
            continue
        s = load()
        edges = len(s.bounds) + sum(len(o) for o in s.obstacles)
        row: dict[str, Any] = {
            "scene": name,
            "edges": edges,
            "source": src,
            "theta": theta,
            "anchor_s": _anchor(s),
            "query_s": {},
            "area_m2": {},
        }
        qs = queries(theta)
        for (qname, _), (t, a) in zip(qs, _time_fresh([f for _, f in qs], load, reps), strict=True):
            row["query_s"][qname] = t
            row["area_m2"][qname] = a
            print(f"  {name:>14} edges={edges:4d} {qname:24s} {1e3 * t:9.1f} ms  {a:8.2f} m2")
        rows.append(row)
    return {"reps": reps, "rows": rows}


#: The ratios the table reports: column title -> query divided by the stationary partial one.
RATIOS = {
    "swept / stationary partial": "partial, swept over G",
    "recognizable (partial) / stationary partial": "recognizable, partial",
}


def combine(runs: list[dict[str, Any]]) -> dict[str, Any]:
    """One table from the data of several processes' :func:`_run_here`: per scene and query
    the median over the processes of their medians (seconds; the anchor likewise), and per
    ratio of :data:`RATIOS` every process's own ratio (``row["ratios"][title]``, in process
    order).  The areas must agree between the processes (the queries are deterministic):
    a difference raises ``ValueError`` naming the scene and the query."""
    if not runs:
        raise ValueError("combine: no runs")
    rows = []
    for i, first in enumerate(runs[0]["rows"]):
        same = [r["rows"][i] for r in runs]
        if any(r["scene"] != first["scene"] for r in same):
            raise ValueError(f"combine: the runs time different scenes at row {i}")
        row = {k: first[k] for k in ("scene", "edges", "source", "theta")}
        anchors = [r["anchor_s"] for r in same if r["anchor_s"]]
        row["anchor_s"] = statistics.median(anchors) if anchors else None
        row["query_s"] = {
            q: statistics.median(r["query_s"][q] for r in same) for q in first["query_s"]
        }
        for q, a in first["area_m2"].items():
            for r in same[1:]:
                if abs(r["area_m2"][q] - a) > 1e-9 * max(1.0, abs(a)):
                    raise ValueError(
                        f"combine: {first['scene']} {q!r}: area {r['area_m2'][q]!r} in one "
                        f"process, {a!r} in another"
                    )
        row["area_m2"] = dict(first["area_m2"])
        row["ratios"] = {
            title: [r["query_s"][q] / r["query_s"]["partial, stationary"] for r in same]
            for title, q in RATIOS.items()
        }
        rows.append(row)
    return {"reps": runs[0]["reps"], "processes": len(runs), "rows": rows}


def run(
    reps: int, slow: bool = True, processes: int = 3, scenes: tuple[str, ...] | None = None
) -> dict[str, Any]:
    """Time every query on every real scene (and, with ``slow``, the fuzzer's slow
    reproductions; ``scenes``: only those names) in ``processes`` fresh Python processes one
    after the other (``processes=1``: in this one), combined by :func:`combine`; seconds and
    square metres."""
    if processes < 1:
        raise ValueError(f"processes must be at least 1, got {processes}")
    known = [name for name, *_ in _cases()]
    if scenes is not None and (unknown := sorted(set(scenes) - set(known))):
        raise ValueError(f"unknown scene(s) {', '.join(unknown)}; known: {', '.join(known)}")
    if processes == 1:
        return combine([_run_here(reps, slow, scenes)])
    runs = []
    ctx = multiprocessing.get_context("spawn")
    for k in range(processes):
        print(f"process {k + 1} of {processes}", flush=True)
        with ctx.Pool(1) as pool:
            runs.append(pool.apply(_run_here, (reps, slow, scenes)))
    return combine(runs)


def _ms(t: float) -> str:
    if t >= 0.1:
        return f"{1e3 * t:,.0f} ms"
    return f"{1e3 * t:.1f} ms" if t >= 1e-3 else f"{1e3 * t:.3f} ms"


def _ratio_cell(ratios: list[float]) -> str:
    """``"10.3x"`` for one process's ratio, ``"10.3x (9.8-12.1)"`` (median, lowest, highest)
    for several."""
    med = f"{statistics.median(ratios):,.1f}x"
    if len(ratios) == 1:
        return med
    return f"{med} ({min(ratios):,.1f}-{max(ratios):,.1f})"


def render(data: dict[str, Any]) -> str:
    """The page fragment: one row per real scene, medians (ms), the ratios to the stationary
    partial query (over the processes: median, lowest and highest), and the anchor."""
    qnames = [q for q, _ in QUERIES]
    lines = [
        "| scene | edges | pyvispoly point query (anchor) | "
        + " | ".join(qnames)
        + " | "
        + " | ".join(RATIOS)
        + " |",
        "| --- | ---: |" + " ---: |" * (len(qnames) + 1 + len(RATIOS)),
    ]
    for r in data["rows"]:
        q = r["query_s"]
        a = r["anchor_s"]
        cells = [r["scene"], str(r["edges"]), _ms(a) if a else "-"]
        cells += [_ms(q[n]) for n in qnames]
        cells += [_ratio_cell(r["ratios"][title]) for title in RATIOS]
        lines.append("| " + " | ".join(cells) + " |")
    m = data["machine"]
    k = data["processes"]
    slow = [r for r in data["rows"] if "fuzz" in r["source"]]
    over = (
        f"in each of {k} fresh Python processes run one after the other: times are the median "
        "over the processes of their medians, ratios the median over the processes of each "
        "one's ratio (in brackets the lowest and the highest)"
        if k > 1
        else "in one Python process"
    )
    lines += [
        "",
        f"`{data['command']}`: median of {data['reps']} calls, each on a freshly loaded scene "
        "(after one warm-up call; the queries of a scene interleaved, one call of each per "
        f"rep), {over}; G and H regular pentagons on the real maps; "
        "anchor = median CGAL visibility polygon (pyvispoly) at 20 free points of the same "
        "scene, same run; "
        '"swept, previous rules": the swept query sampled as before issue 25\'s lazy rules '
        "(next to every collinearity event, bisecting every empty eroded target: "
        "`geometry.sweep.LAZY_SAMPLES = False`), the previous implementation as an anchor; "
        + (
            "`slow_1`, `slow_2`: the independent fuzzer's slow reproductions (issue 25 item 7; "
            "their own G, H, target and orientation: "
            + "; ".join(f"{r['scene']} theta = {r['theta']:.3f}" for r in slow)
            + "); "
            if slow
            else ""
        )
        + f"{m['cpus']} CPUs, Python {m['python']}, load average {m['load_average']}.",
    ]
    return "\n".join(lines) + "\n"


def cli(
    name: str,
    doc: str,
    run_fn: Callable[..., dict[str, Any]],
    render_fn: Callable[[dict[str, Any]], str],
    argv: list[str] | None,
    processes: bool = False,
) -> None:
    """The command line of a benchmark over the real maps (``--reps``, ``--no-slow`` and the
    output options; with ``processes`` also ``--processes`` and ``--scenes``): runs
    ``run_fn(reps, slow=...)`` (and ``processes=``, ``scenes=``), prints ``render_fn`` of the
    data and writes it as benchmark ``name``."""
    ap = argparse.ArgumentParser(prog=f"python -m benchmarks.{name}", description=doc)
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument(
        "--no-slow", action="store_true", help="leave out the fuzzer's slow reproductions"
    )
    if processes:
        ap.add_argument(
            "--processes",
            type=int,
            default=3,
            help="fresh Python processes to measure in, one after the other (default 3)",
        )
        ap.add_argument(
            "--scenes", help="comma-separated scene names (default: all of them)", default=None
        )
    _results.add_output_args(ap, name)
    args = ap.parse_args(argv)
    kw: dict[str, Any] = {"slow": not args.no_slow}
    if processes:
        kw["processes"] = args.processes
        kw["scenes"] = tuple(args.scenes.split(",")) if args.scenes else None
    data = {
        "command": _results.command(f"benchmarks.{name}", argv),
        "machine": _results.machine(),
        **run_fn(args.reps, **kw),
    }
    print(render_fn(data))
    _results.write(name, data, args.out, args.update_results)


def main(argv: list[str] | None = None) -> None:
    cli("real_maps", __doc__.split("\n\n")[0], run, render, argv, processes=True)


if __name__ == "__main__":
    main()
