"""Certified swept answers on the bundled and real maps: how far apart the bounds are.

    python -m benchmarks.certified [--densify 0]

For every bundled scene with a polygonal G (``lab``, ``warehouse``, ...) and every real map
(``sensorplan_gym/scenes/real/``), :func:`geometry.swept_bounds` of the swept partial query
(``target_in="goal"``, paper 3.2.2) and, where G or H is a polygon, of the 5.2 recognizable
query (``recognizable=True``), orientation 0, no uncertainty.  Per query: the area of the
outer bound (``E ⊆ outer``, proven), of the traced inner bound (the ``conservative=True``
answer, checked, not proven) and of the proven inner bound (``proven_inner``, proven for
every query without aim error; docs/DESIGN.md, "Certified swept answers"), the upper
Hausdorff bounds of both inner bounds to outer as fractions of the scene's diameter D, and
the wall time of the call.  Data (``certified.json``) and fragment (``certified.md``) go to
``--out`` (default ``runs/benchmarks/certified/``) or, with ``--update-results``, to
``benchmarks/results/`` and ``docs/results/``.
"""

from __future__ import annotations

import argparse
import time
from typing import Any

from geometry import Scene, swept_bounds
from sensorplan_gym.core.scenes import BUNDLED_SCENES, REAL_SCENES, load_scene

from . import _results


def _scenes() -> list[tuple[str, Scene]]:
    """The bundled scenes with a polygonal goal or failure region, then the real maps, by
    name (``lab``, ``real/willow_north``, ...)."""
    out = []
    for name in (*BUNDLED_SCENES, *REAL_SCENES):
        s = load_scene(name)
        if s.goal_geom.geom_type == "Polygon" or s.failure_geom.geom_type == "Polygon":
            out.append((name, s))
    return out


def _row(name: str, query: str, s: Scene, kw: dict[str, Any]) -> dict[str, Any]:
    t0 = time.perf_counter()
    b = swept_bounds(s, **kw)
    dt = time.perf_counter() - t0
    D = s.diameter
    return {
        "scene": name,
        "query": query,
        "edges": int(sum(len(o) for o in s.obstacles) + len(s.bounds)),
        "outer": b.outer.area / D**2,
        "inner": b.inner.area / D**2,
        "proven": None if b.proven_inner is None else b.proven_inner.area / D**2,
        "hausdorff_inner": b.hausdorff / D,
        "hausdorff_proven": None if b.proven_hausdorff is None else b.proven_hausdorff / D,
        "samples": b.samples,
        "seconds": round(dt, 2),
    }


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        prog="python -m benchmarks.certified", description=__doc__.split("\n\n")[0]
    )
    ap.add_argument("--densify", type=int, default=0, help="swept_bounds(densify=...)")
    _results.add_output_args(ap, "certified")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    rows = []
    for rel, s in _scenes():
        if s.goal_geom.geom_type == "Polygon":
            rows.append(_row(rel, "swept", s, {"target_in": "goal", "densify": args.densify}))
        rows.append(_row(rel, "5.2", s, {"recognizable": True, "densify": args.densify}))
        print(rows[-1], flush=True)
    data = {
        "command": _results.command("benchmarks.certified", argv),
        "machine": _results.machine(),
        "densify": args.densify,
        "rows": rows,
        "seconds": round(time.perf_counter() - t0, 1),
    }
    _results.write("certified", data, args.out, args.update_results)
    print(render(data))
    return 0


def _e(x: float | None) -> str:
    return "–" if x is None else f"{x:.2e}"


def render(data: dict[str, Any]) -> str:
    """The page fragment: one row per scene and query."""
    lines = [
        "| scene | query | edges | outer (D²) | inner (D²) | proven inner (D²) "
        "| Hausdorff inner–outer (D) | proven–outer (D) | seconds |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in data["rows"]:
        lines.append(
            f"| {r['scene']} | {r['query']} | {r['edges']} | {r['outer']:.5f} | {r['inner']:.5f} "
            f"| {'–' if r['proven'] is None else format(r['proven'], '.5f')} "
            f"| {_e(r['hausdorff_inner'])} | {_e(r['hausdorff_proven'])} | {r['seconds']} |"
        )
    m = data["machine"]
    lines += [
        "",
        "Areas as fractions of D², distances of D (D the scene's diameter); upper Hausdorff "
        "bounds (`hausdorff_bounds`). *outer* ⊇ the exact answer and *proven inner* ⊆ it are "
        "proven; *inner* is the `conservative=True` answer with the sweep's previous, denser "
        "sampling rules, which `swept_bounds` takes (checked, not proven; within 2 `tol` of "
        "the default lazy answer). `swept`: "
        '`partial_region(target_in="goal")`; `5.2`: `recognizable_region(model="partial")`. '
        f"`densify={data['densify']}`.",
        "",
        f"Measured with `{data['command']}` ({data['seconds']} s; {m['cpus']} CPUs, "
        f"load average {m['load_average']}).",
    ]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    raise SystemExit(main())
