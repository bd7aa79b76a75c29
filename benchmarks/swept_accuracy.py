"""How close the swept partial region comes to a dense reference (paper 3.2.2-3.2.3).

Run ``python -m benchmarks.swept_accuracy [first_seed] [last_seed]`` (default 0 10; about
30 s a scene).  The data (``swept_accuracy.json``) and the page fragment go to ``--out``
(default ``runs/benchmarks/swept_accuracy/``), or with ``--update-results`` to the tracked
``benchmarks/results/swept_accuracy.json`` and ``docs/results/swept_accuracy.md``.

For random scenes with a polygonal G it compares the union of the swept shadows
(:func:`geometry.sweep.swept_shadows`) with the union of 201 exact stationary shadows per edge
of G (a subset of the true union):

* *missed*: area of the reference not in the sweep (the region would be too large), and the
  depth of the deepest missed sliver (``shapely.minimum_clearance``);
* *overshoot*: points of the sweep outside the reference that no configuration among 2,001
  per edge of G blinds (exact point test): the region would be too small there; reported is
  the largest distance of such a point from the reference, in units of ``tol``.
"""

from __future__ import annotations

import argparse
from typing import Any

import numpy as np
import shapely

from geometry import Scene
from geometry._common import scene_domain, target_spec
from geometry.generate import random_scene
from geometry.sweep import Sweeper, swept_shadows

from . import _results


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(
        prog="python -m benchmarks.swept_accuracy", description=__doc__.split("\n\n")[0]
    )
    ap.add_argument("first_seed", nargs="?", type=int, default=0, help="default 0")
    ap.add_argument("last_seed", nargs="?", type=int, default=10, help="default 10")
    _results.add_output_args(ap, "swept_accuracy")
    args = ap.parse_args(argv)
    first, last = args.first_seed, args.last_seed
    data: dict[str, Any] = {
        "command": _results.command("benchmarks.swept_accuracy", argv),
        "machine": _results.machine(),
        "rows": [],
    }
    for seed in range(first, last):
        rng = np.random.default_rng(seed)
        sc = Scene.from_dict(random_scene(rng, goal="polygon", n_obstacles=8))
        ring = shapely.orient_polygons(sc.target_at(0, 0, 0), exterior_cw=False).exterior
        a0 = np.asarray(ring.coords)[:-1]
        tol = 1e-4 * sc.diameter
        sweep, _ = swept_shadows(scene_domain(sc), sc.free_space, a0, sc.goal_geom, tol=tol)
        spec = target_spec(sc, None, "goal", 0.0)
        sw = Sweeper(scene_domain(sc), sc.free_space, a0, spec.hull_pts, None, 0.0, tol)
        g = np.asarray(shapely.orient_polygons(sc.goal_geom, exterior_cw=False).exterior.coords)
        edges = list(zip(g[:-1], g[1:], strict=True))
        ref = shapely.union_all(
            [sw.shadow(a + t * (b - a))[0] for a, b in edges for t in np.linspace(0, 1, 201)]
        )
        miss = shapely.difference(ref, sweep)
        extra = shapely.difference(sweep, ref)
        qs = np.vstack([a + np.linspace(0, 1, 2001)[:, None] * (b - a) for a, b in edges])
        worst, n_probe, n_over = 0.0, 0, 0
        for part in shapely.get_parts(extra):
            if part.area < 1e-14:
                continue
            x0, y0, x1, y1 = part.bounds
            cand = np.column_stack([rng.uniform(x0, x1, 400), rng.uniform(y0, y1, 400)])
            cand = cand[shapely.contains_xy(part, cand[:, 0], cand[:, 1])][:10]
            for c in cand:
                n_probe += 1
                if not sw.blind(np.tile(c, (len(qs), 1)), qs).any():
                    n_over += 1
                    worst = max(worst, ref.distance(shapely.Point(*c)))
        depth = max([shapely.minimum_clearance(x) for x in shapely.get_parts(miss)] or [0.0])
        depth = 0.0 if not np.isfinite(depth) else depth
        print(
            f"seed {seed}: missed area {miss.area:.1e} (deepest {depth / tol:.3f} tol); "
            f"overshoot: {n_over}/{n_probe} probes unblinded, farthest {worst / tol:.2f} tol",
            flush=True,
        )
        data["rows"].append(
            {
                "seed": seed,
                "goal_edges": len(edges),
                "missed_area": float(miss.area),
                "missed_depth_tol": float(depth / tol),
                "probes": n_probe,
                "unblinded": n_over,
                "overshoot_tol": float(worst / tol),
            }
        )
    _results.write("swept_accuracy", data, args.out, args.update_results)


def render(data: dict[str, Any]) -> str:
    """The page fragment: per scene, the missed area and depth and the overshoot."""
    lines = [
        "| scene seed | edges of G | missed area | deepest missed sliver (tol) | overshoot probes "
        "not blinded | farthest overshoot (tol) |",
        "| ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    for r in data["rows"]:
        lines.append(
            f"| {r['seed']} | {r['goal_edges']} | {r['missed_area']:.1e} | "
            f"{r['missed_depth_tol']:.3f} | {r['unblinded']}/{r['probes']} | "
            f"{r['overshoot_tol']:.2f} |"
        )
    rows = data["rows"]
    if rows:
        lines += [
            "",
            f"`{data['command']}`, {len(rows)} scenes: deepest missed sliver "
            f"{max(r['missed_depth_tol'] for r in rows):.3f} tol, farthest overshoot "
            f"{max(r['overshoot_tol'] for r in rows):.2f} tol (`tol` = 1e-4 x the scene "
            "diameter).",
        ]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    main()
