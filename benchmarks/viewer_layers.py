"""What one edit costs in the viewer: every region layer and the hover probe, per bundled scene.

    python -m benchmarks.viewer_layers [--repeat 5]

For each bundled scene, :func:`sensorplan_gym.viewer.layers.compute_layers` (the exact regions
the live app recomputes after an edit, with the scene's own settings, complete model, target
translating) ``--repeat`` times, median milliseconds per layer; and the median of
:func:`~sensorplan_gym.viewer.layers.probe` (the hover readout) at 50 seeded points.  The same
measurement as ``python -m sensorplan_gym.viewer.layers``.  The data and the page fragment go
to ``--out`` (default ``runs/benchmarks/viewer_layers/``), or with ``--update-results`` to
``benchmarks/results/viewer_layers.json`` and ``docs/results/viewer_layers.md``.
"""

from __future__ import annotations

import argparse
import statistics
from typing import Any

import numpy as np

from sensorplan_gym.core.world import BUNDLED_SCENES, load_scene
from sensorplan_gym.viewer.layers import LAYERS, Settings, compute_layers, probe

from . import _results


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(
        prog="python -m benchmarks.viewer_layers", description=__doc__.split("\n\n")[0]
    )
    ap.add_argument("--repeat", type=int, default=5)
    _results.add_output_args(ap, "viewer_layers")
    args = ap.parse_args(argv)
    data: dict[str, Any] = {
        "command": _results.command("benchmarks.viewer_layers", argv),
        "machine": _results.machine(),
        "repeat": args.repeat,
        "layers": list(LAYERS),
        "rows": [],
    }
    for name in BUNDLED_SCENES:
        scene = load_scene(name)
        settings = Settings.from_scene(scene, model="complete", motion="translating")
        runs = [compute_layers(scene, settings) for _ in range(args.repeat)]
        ms = {
            k: (statistics.median(r.ms[k] for r in runs) if k in runs[0].geoms else None)
            for k in LAYERS
        }
        rng = np.random.default_rng(0)
        lo, hi = scene.bounds.min(axis=0), scene.bounds.max(axis=0)
        pts = rng.uniform(lo, hi, size=(50, 2))
        pm = statistics.median(probe(runs[0], x, y)["ms"] for x, y in pts)
        data["rows"].append({"scene": name, "layer_ms": ms, "probe_ms": pm})
        print(data["rows"][-1], flush=True)
    _results.write("viewer_layers", data, args.out, args.update_results)
    return 0


def render(data: dict[str, Any]) -> str:
    """The page fragment: median ms per layer and of the probe, one row per scene."""
    layers = data["layers"]
    lines = [
        "| scene | " + " | ".join(f"`{k}`" for k in layers) + " | probe |",
        "| --- |" + " ---: |" * (len(layers) + 1),
    ]
    for r in data["rows"]:
        cells = [
            "n/a" if r["layer_ms"][k] is None else f"{r['layer_ms'][k]:,.1f} ms" for k in layers
        ]
        lines.append(f"| {r['scene']} | " + " | ".join(cells) + f" | {r['probe_ms']:.2f} ms |")
    m = data["machine"]
    lines += [
        "",
        f"`{data['command']}`: median of {data['repeat']} runs per layer, probe median of 50 "
        f"points; {m['cpus']} CPUs, load average {m['load_average']}.",
    ]
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    raise SystemExit(main())
