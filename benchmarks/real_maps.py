"""The region queries on the bundled real maps (public ROS and OpenStreetMap floor plans),
with an anchor.

    python -m benchmarks.real_maps              # about a minute
    python -m benchmarks.real_maps --reps 7

For every scene of ``sensorplan_gym/scenes/real/`` (written by
:mod:`benchmarks.make_real_maps` from the Willow Garage and LSE arena occupancy maps, and by
:mod:`benchmarks.make_geojson_maps` from an OpenStreetMap indoor map in GeoJSON; G and H are
regular pentagons) it times, each call on a freshly loaded Scene (so every call
builds its per-scene structures), median over ``--reps`` calls after one warm-up call:

* ``complete_region`` and ``partial_region`` of the stationary target at G's
  representative point, orientation 0;
* ``partial_region(target_in="goal")`` (the swept partial query, paper 3.2.2-3.2.3);
* ``recognizable_region(model="partial")`` (5.2: both sweeps, G and H polygons, with the
  overlap strips);
* ``recognizable_region(model="complete")``;

and gives the ratios swept partial / stationary partial and recognizable (partial) /
stationary partial, the areas of the answers (all non-empty), and, in the same run on the
same scenes, the anchor: one CGAL visibility polygon (pyvispoly) at each of 20 free points,
median per point (see :mod:`benchmarks.scaling`).  Data (``real_maps.json``) and fragment
(``real_maps.md``) go to ``--out`` (default ``runs/benchmarks/real_maps/``) or, with
``--update-results``, to ``benchmarks/results/`` and ``docs/results/``.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable
from typing import Any

from geometry import Scene, complete_region, partial_region, recognizable_region
from sensorplan_gym.core.scenes import REAL_SCENES, load_scene, real_scene_provenance

from . import _results
from .scaling import _anchor


def _pose(s: Scene) -> tuple[float, float, float]:
    c = s.goal_geom.representative_point()
    return (c.x, c.y, 0.0)


QUERIES: list[tuple[str, Callable[[Scene], Any]]] = [
    ("complete, stationary", lambda s: complete_region(s, target_at=_pose(s))),
    ("partial, stationary", lambda s: partial_region(s, target_at=_pose(s))),
    ("partial, swept over G", lambda s: partial_region(s, target_in="goal", theta=0.0)),
    ("recognizable, partial", lambda s: recognizable_region(s, model="partial", theta=0.0)),
    ("recognizable, complete", lambda s: recognizable_region(s, model="complete", theta=0.0)),
]


def _time_fresh(fn: Callable[[Scene], Any], name: str, reps: int) -> tuple[float, float]:
    """Median seconds of ``fn`` on a freshly loaded scene (``reps`` calls after a warm-up)
    and the area of its answer."""
    area = fn(load_scene(name)).area
    times = []
    for _ in range(reps):
        s = load_scene(name)
        t0 = time.perf_counter()
        fn(s)
        times.append(time.perf_counter() - t0)
    return statistics.median(times), float(area)


def run(reps: int) -> dict[str, Any]:
    """Time every query on every real scene; seconds and square metres."""
    prov = real_scene_provenance()
    rows = []
    for real in REAL_SCENES:
        name = real.removeprefix("real/")
        s = load_scene(real)
        edges = len(s.bounds) + sum(len(o) for o in s.obstacles)
        row: dict[str, Any] = {
            "scene": name,
            "edges": edges,
            "source": f"{prov[name]['repository']} {prov[name]['path']}",
            "anchor_s": _anchor(s),
            "query_s": {},
            "area_m2": {},
        }
        for qname, fn in QUERIES:
            t, a = _time_fresh(fn, real, reps)
            row["query_s"][qname] = t
            row["area_m2"][qname] = a
            print(f"  {name:>14} edges={edges:4d} {qname:24s} {1e3 * t:9.1f} ms  {a:8.2f} m2")
        rows.append(row)
    return {"reps": reps, "rows": rows}


def _ms(t: float) -> str:
    if t >= 0.1:
        return f"{1e3 * t:,.0f} ms"
    return f"{1e3 * t:.1f} ms" if t >= 1e-3 else f"{1e3 * t:.3f} ms"


def render(data: dict[str, Any]) -> str:
    """The page fragment: one row per real scene, medians (ms), the ratios to the stationary
    partial query, and the anchor."""
    qnames = [q for q, _ in QUERIES]
    lines = [
        "| scene | edges | pyvispoly point query (anchor) | "
        + " | ".join(qnames)
        + " | swept / stationary partial | recognizable (partial) / stationary partial |",
        "| --- | ---: |" + " ---: |" * (len(qnames) + 3),
    ]
    for r in data["rows"]:
        q = r["query_s"]
        a = r["anchor_s"]
        cells = [r["scene"], str(r["edges"]), _ms(a) if a else "-"]
        cells += [_ms(q[n]) for n in qnames]
        st = q["partial, stationary"]
        cells.append(f"{q['partial, swept over G'] / st:,.0f}x")
        cells.append(f"{q['recognizable, partial'] / st:,.0f}x")
        lines.append("| " + " | ".join(cells) + " |")
    m = data["machine"]
    lines += [
        "",
        f"`{data['command']}`: median of {data['reps']} calls, each on a freshly loaded scene "
        "(after one warm-up call); G and H regular pentagons; anchor = median CGAL visibility "
        "polygon (pyvispoly) at 20 free points of the same scene, same run; "
        f"{m['cpus']} CPUs, Python {m['python']}, load average {m['load_average']}.",
    ]
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(
        prog="python -m benchmarks.real_maps", description=__doc__.split("\n\n")[0]
    )
    ap.add_argument("--reps", type=int, default=5)
    _results.add_output_args(ap, "real_maps")
    args = ap.parse_args(argv)
    data = {
        "command": _results.command("benchmarks.real_maps", argv),
        "machine": _results.machine(),
        **run(args.reps),
    }
    print(render(data))
    _results.write("real_maps", data, args.out, args.update_results)


if __name__ == "__main__":
    main()
