"""Generate the bundled real-map scenes ``sensorplan_gym/scenes/real/*.json`` from public
ROS occupancy-grid maps (issues 22 and 25: real floor plans of 100-300 edges).

The maps are not shipped; get them from ros-planning/navigation_tutorials (BSD) at the
commit recorded below, then::

    C=115e46ec9e65d49756b5d2155326ad2c1694d1e6
    git -C navigation_tutorials show $C:navigation_stage/stage_config/maps/willow-full.pgm \
        > willow-full.pgm
    git -C navigation_tutorials show $C:roomba_stage/maps/lse_arena.pgm > lse_arena.pgm
    python -m benchmarks.make_real_maps --willow willow-full.pgm --lse lse_arena.pgm

Each input's SHA-256 is checked against the recorded one, so the scenes are exactly
reproducible.  Every scene is read with :func:`geometry.occupancy.read_occupancy_grid`
(crop, simplify tolerance and the other options below), and then, deterministically:

* the target is a 0.4 m x 0.3 m box (0.2 m x 0.15 m in the small arena) centred on its
  reference point;
* G is a regular pentagon (radius 0.3 m; 0.15 m in the arena) around the centre of the
  largest circle inscribed in the free space (``shapely.maximum_inscribed_circle``);
* H is the same pentagon around the point of a grid (spacing half the pentagon's radius)
  over the free space, at least ``h_sep`` metres from G's centre and in sight of it (the
  segment between the centres is free), that lies farthest from the walls and obstacles
  (so that some sensor placements see both: the recognizable regions are not empty);
* start is the centre of the largest circle at least ``h_sep`` from both.

The provenance of every scene -- repository, path, commit, licence, resolution and where
it is stated, crop, tolerances, the input's SHA-256 -- goes to
``sensorplan_gym/scenes/real/provenance.json`` (the scene JSON format has no free-form
field).  ``--check`` compares instead of writing (exit status 1 on a difference).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import sys
from pathlib import Path
from typing import Any

import numpy as np
import shapely

from geometry import Scene
from geometry.occupancy import read_occupancy_grid

OUT = Path(__file__).resolve().parent.parent / "sensorplan_gym" / "scenes" / "real"
PROVENANCE = "provenance.json"

REPO = "https://github.com/ros-planning/navigation_tutorials"
COMMIT = "115e46ec9e65d49756b5d2155326ad2c1694d1e6"
LICENCE = "BSD (package.xml <license>BSD</license> of navigation_stage and roomba_stage)"

WILLOW = {
    "repository": REPO,
    "path": "navigation_stage/stage_config/maps/willow-full.pgm",
    "commit": COMMIT,
    "licence": LICENCE,
    "sha256": "d34c9ab9789841d96dd549d26a7164069c4c6cbfe03f18709f0812a367fa84ca",
    "what": "Willow Garage office, Menlo Park (PR2 stage map), 584 x 526 pixels",
    "resolution": 0.1,
    "resolution_source": (
        "navigation_stage/launch/move_base_amcl_10cm.launch: map_server args "
        "'willow-full.pgm 0.1'; agrees with navigation_stage/stage_config/worlds/"
        "willow-pr2.world (floorplan size [58.4 52.6] for the 584 x 526 bitmap)"
    ),
    "origin": [0.0, 0.0],
    "occupied_thresh": 0.65,
    "free_thresh": 0.196,
    "negate": False,
}
LSE = {
    "repository": REPO,
    "path": "roomba_stage/maps/lse_arena.pgm",
    "commit": COMMIT,
    "licence": LICENCE,
    "sha256": "0b2b639da59f2b301af41bcdb67330d6f41ae8fb2a9bf2faab071e9887cea986",
    "what": "LSE arena (Roomba stage map), 80 x 60 pixels",
    "resolution": 0.05,
    "resolution_source": "roomba_stage/maps/lse_arena.yaml (resolution: 0.050000)",
    "origin": [0.0, 0.0],
    "occupied_thresh": 0.65,
    "free_thresh": 0.196,
    "negate": False,
}

#: The bundled scenes: source map, crop (world metres) and vectorization options.
SCENES: dict[str, dict[str, Any]] = {
    "willow_north": {
        "source": "willow",
        "what": "north wing: corridor, offices and the lab space (pixels 90-330 x 30-210)",
        "crop": [9.0, 31.6, 33.0, 49.6],
        "simplify": 0.3,
        "min_obstacle_area": 0.5,
        "min_width": 0.3,
        "size": 0.3,
        "h_sep": 4.0,
    },
    "willow_south": {
        "source": "willow",
        "what": "south-west wing: corridor, offices and the conference area (pixels 90-340 x "
        "300-500)",
        "crop": [9.0, 2.6, 34.0, 22.6],
        "simplify": 0.2,
        "min_obstacle_area": 0.5,
        "min_width": 0.3,
        "size": 0.3,
        "h_sep": 4.0,
    },
    "lse_arena": {
        "source": "lse",
        "what": "the whole arena (4 m x 3 m); a small real map (fewer than 100 edges)",
        "crop": None,
        "simplify": 0.0,
        "min_obstacle_area": 0.0,
        "min_width": 0.0,
        "size": 0.15,
        "h_sep": 1.5,
    },
}
SOURCES = {"willow": WILLOW, "lse": LSE}


def _r(v: float) -> float:
    return round(float(v), 6)


def _ring(poly: shapely.Polygon) -> list[list[float]]:
    return [[_r(x), _r(y)] for x, y in np.asarray(poly.exterior.coords)[:-1]]


def _pentagon(c: shapely.Point, r: float) -> list[list[float]]:
    a = math.pi / 2 + 2 * math.pi * np.arange(5) / 5
    return [[_r(c.x + r * math.cos(t)), _r(c.y + r * math.sin(t))] for t in a]


def _centre(free: Any, away: list[shapely.Point], sep: float) -> shapely.Point:
    """Centre of the largest circle inscribed in ``free`` minus discs of radius ``sep``
    around the ``away`` points (over the five largest parts; tolerance 1 cm)."""
    region = free
    for p in away:
        region = region.difference(p.buffer(sep, 64))
    parts = sorted(shapely.get_parts(region), key=lambda g: -g.area)
    best = None
    for part in parts[:5]:
        line = shapely.maximum_inscribed_circle(part, 0.01)
        if best is None or line.length > best.length:
            best = line
    assert best is not None, "no free space left"
    x, y = shapely.get_coordinates(best)[0]
    return shapely.Point(_r(x), _r(y))


def _in_sight(free: Any, g: shapely.Point, sep: float, step: float) -> shapely.Point:
    """The point of a ``step`` grid over ``free`` at least ``sep`` from ``g`` whose segment
    to ``g`` lies in ``free`` and whose distance to the walls and obstacles is largest
    (ties: the first in row-major order)."""
    x0, y0, x1, y1 = free.bounds
    xs = np.arange(x0 + step / 2, x1, step)
    ys = np.arange(y0 + step / 2, y1, step)
    gx, gy = np.meshgrid(xs, ys)
    pts = shapely.points(gx.ravel(), gy.ravel())
    shapely.prepare(free)
    far = shapely.distance(pts, g) >= sep
    pts = pts[far & shapely.contains(free, pts)]
    segs = shapely.linestrings(
        np.stack(
            [
                np.column_stack([shapely.get_x(pts), shapely.get_y(pts)]),
                np.broadcast_to([g.x, g.y], (len(pts), 2)),
            ],
            axis=1,
        )
    )
    pts = pts[shapely.covers(free, segs)]
    assert len(pts), "no free point in sight of G"
    clear = shapely.distance(pts, free.boundary)
    p = pts[int(np.argmax(clear))]
    return shapely.Point(_r(p.x), _r(p.y))


def build(name: str, pgm: Path) -> tuple[dict[str, Any], dict[str, Any]]:
    """The scene dict and its provenance record for bundled scene ``name``."""
    spec = SCENES[name]
    src = SOURCES[spec["source"]]
    digest = hashlib.sha256(pgm.read_bytes()).hexdigest()
    if digest != src["sha256"]:
        raise SystemExit(
            f"{pgm}: SHA-256 {digest} is not the recorded {src['sha256']} of "
            f"{src['repository']} {src['path']} at {src['commit']}"
        )
    kw = {k: spec[k] for k in ("crop", "simplify", "min_obstacle_area", "min_width")}
    # the room: the free component with most cells
    m = read_occupancy_grid(
        pgm,
        resolution=src["resolution"],
        origin=src["origin"],
        occupied_thresh=src["occupied_thresh"],
        free_thresh=src["free_thresh"],
        negate=src["negate"],
        **kw,
    )
    free = m.boundary.difference(shapely.union_all(m.obstacles))
    s = spec["size"]
    a, b = s * 2 / 3, s / 2  # the target's half sizes
    g = _centre(free, [], 0.0)
    h = _in_sight(free, g, spec["h_sep"], spec["size"] / 2)
    st = _centre(free, [g, h], spec["h_sep"])
    d = {
        "name": name,
        "bounds": _ring(m.boundary),
        "obstacles": [_ring(o) for o in m.obstacles],
        "target": [[-a, -b], [a, -b], [a, b], [-a, b]],
        "goal": _pentagon(g, s),
        "failure": _pentagon(h, s),
        "start": [st.x, st.y, 0.0],
    }
    d["target"] = [[_r(x), _r(y)] for x, y in d["target"]]
    scene = Scene.from_dict(d)  # validates
    prov = {
        **{k: v for k, v in src.items()},
        "scene": name,
        "scene_what": spec["what"],
        **kw,
        "edges": m.n_edges,
        "obstacles": len(m.obstacles),
        "free_cells": m.cells,
        "placement": (
            "G, start: centres of the largest inscribed circles; H: the free grid point in "
            "sight of G, at least h_sep from it, farthest from the walls (see the script)"
        ),
        "h_sep": spec["h_sep"],
        "generator": "python -m benchmarks.make_real_maps",
    }
    assert len(scene.bounds) + sum(len(o) for o in scene.obstacles) == m.n_edges
    return d, prov


def main(argv: list[str] | None = None) -> None:
    """(Re)write the real scenes and their provenance (``--check``: compare only)."""
    ap = argparse.ArgumentParser(
        prog="python -m benchmarks.make_real_maps",
        description=__doc__.split("\n\n")[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog=__doc__.split("\n\n", 1)[1],
    )
    ap.add_argument("--willow", type=Path, required=True, help="willow-full.pgm")
    ap.add_argument("--lse", type=Path, required=True, help="lse_arena.pgm")
    ap.add_argument("--out", type=Path, default=OUT, help=f"folder (default {OUT})")
    ap.add_argument("--check", action="store_true", help="compare with the files, write nothing")
    args = ap.parse_args(argv)
    paths = {"willow": args.willow, "lse": args.lse}
    provenance: dict[str, Any] = {}
    texts: dict[str, str] = {}
    for name, spec in SCENES.items():
        d, prov = build(name, paths[spec["source"]])
        provenance[name] = prov
        texts[f"{name}.json"] = Scene.from_dict(d).to_json()
        print(f"{name}: {prov['edges']} edges, {prov['obstacles']} obstacles", flush=True)
    texts[PROVENANCE] = json.dumps(provenance, indent=1) + "\n"
    write_or_check(texts, args.out, args.check)


def write_or_check(texts: dict[str, str], out: Path, check: bool) -> None:
    """Write each file name -> text under ``out``; with ``check`` compare instead, print the
    files that differ and exit with status 1 if any does."""
    bad = 0
    for fname, text in texts.items():
        p = out / fname
        if check:
            if not p.exists() or p.read_text(encoding="utf-8") != text:
                print(f"differs: {p}")
                bad += 1
        else:
            p.parent.mkdir(parents=True, exist_ok=True)
            p.write_text(text, encoding="utf-8")
            print(f"wrote {p}")
    if bad:
        sys.exit(1)


if __name__ == "__main__":
    main()
