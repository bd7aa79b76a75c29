"""The region queries on the bundled real maps (public ROS and OpenStreetMap floor plans),
with an anchor.

    python -m benchmarks.real_maps              # about six minutes
    python -m benchmarks.real_maps --reps 7
    python -m benchmarks.real_maps --no-slow    # the real maps only, about a minute

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
:mod:`benchmarks.scaling`). Data (``real_maps.json``) and fragment (``real_maps.md``) go to
``--out`` (default ``runs/benchmarks/real_maps/``) or, with ``--update-results``, to
``benchmarks/results/`` and ``docs/results/``.
"""

from __future__ import annotations

import argparse
import json
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


def run(reps: int, slow: bool = True) -> dict[str, Any]:
    """Time every query on every real scene (and, with ``slow``, the fuzzer's slow
    reproductions); seconds and square metres."""
    rows = []
    for name, src, load, theta in _cases():
        if not slow and name in SLOW_REPROS:
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
        "(after one warm-up call; the queries of a scene interleaved, one call of each per "
        "rep); G and H regular pentagons on the real maps; "
        "anchor = median CGAL visibility polygon (pyvispoly) at 20 free points of the same "
        "scene, same run; "
        '"swept, previous rules": the swept query sampled as before issue 25\'s lazy rules '
        "(next to every collinearity event, bisecting every empty eroded target: "
        "`geometry.sweep.LAZY_SAMPLES = False`), the previous implementation as an anchor; "
        "`slow_1`, `slow_2`: the independent fuzzer's slow "
        "reproductions (issue 25 item 7; their own G, H, target and orientation: "
        + "; ".join(
            f"{r['scene']} theta = {r['theta']:.3f}" for r in data["rows"] if "fuzz" in r["source"]
        )
        + "); "
        f"{m['cpus']} CPUs, Python {m['python']}, load average {m['load_average']}.",
    ]
    return "\n".join(lines) + "\n"


def cli(
    name: str,
    doc: str,
    run_fn: Callable[..., dict[str, Any]],
    render_fn: Callable[[dict[str, Any]], str],
    argv: list[str] | None,
) -> None:
    """The command line of a benchmark over the real maps (``--reps``, ``--no-slow`` and the
    output options): runs ``run_fn(reps, slow=...)``, prints ``render_fn`` of the data and
    writes it as benchmark ``name``."""
    ap = argparse.ArgumentParser(prog=f"python -m benchmarks.{name}", description=doc)
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument(
        "--no-slow", action="store_true", help="leave out the fuzzer's slow reproductions"
    )
    _results.add_output_args(ap, name)
    args = ap.parse_args(argv)
    data = {
        "command": _results.command(f"benchmarks.{name}", argv),
        "machine": _results.machine(),
        **run_fn(args.reps, slow=not args.no_slow),
    }
    print(render_fn(data))
    _results.write(name, data, args.out, args.update_results)


def main(argv: list[str] | None = None) -> None:
    cli("real_maps", __doc__.split("\n\n")[0], run, render, argv)


if __name__ == "__main__":
    main()
