"""Generate the bundled large scene ``sensorplan_gym/scenes/large/office_floor.json``.

An office floor, 48 m x 30 m (L-shaped: a stair core cut from the north-east corner),
in metres: a corridor with eight private offices to the north (partition walls with
doorways, desk, chair, cabinet and plant in each), an open-plan area with desk clusters,
two meeting rooms with round tables, a lounge and structural columns to the south and
east.  Deterministic (seed 0); about 1,500 environment edges.  The target is a 0.5 m x
0.4 m parcel; G is a drop-off spot in the corridor, H a spot in the open-plan area.

    python -m benchmarks.make_office_floor            # (re)writes the JSON
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import shapely

OUT = Path(__file__).resolve().parent.parent / "sensorplan_gym" / "scenes" / "large"
T = 0.15  # wall thickness (m)


def rect(x0: float, y0: float, x1: float, y1: float) -> np.ndarray:
    return np.array([[x0, y0], [x1, y0], [x1, y1], [x0, y1]], dtype=float)


def rot_rect(cx: float, cy: float, w: float, h: float, ang: float) -> np.ndarray:
    c, s = math.cos(ang), math.sin(ang)
    p = np.array([[-w, -h], [w, -h], [w, h], [-w, h]]) / 2
    return p @ np.array([[c, s], [-s, c]]) + [cx, cy]


def ngon(cx: float, cy: float, r: float, n: int, phase: float = 0.0) -> np.ndarray:
    a = phase + 2 * math.pi * np.arange(n) / n
    return np.column_stack([cx + r * np.cos(a), cy + r * np.sin(a)])


def ellipse(cx: float, cy: float, a: float, b: float, n: int) -> np.ndarray:
    t = 2 * math.pi * np.arange(n) / n
    return np.column_stack([cx + a * np.cos(t), cy + b * np.sin(t)])


def wall_with_doors(
    x0: float, x1: float, y: float, doors: list[tuple[float, float]]
) -> list[np.ndarray]:
    """A horizontal wall from x0 to x1 centred on y, with doorway intervals cut out."""
    out, x = [], x0
    for d0, d1 in sorted(doors):
        if d0 > x:
            out.append(rect(x, y - T / 2, d0, y + T / 2))
        x = d1
    if x < x1:
        out.append(rect(x, y - T / 2, x1, y + T / 2))
    return out


def office_floor(seed: int = 0) -> dict:
    rng = np.random.default_rng(seed)
    W, H, core_x, core_y = 48.0, 30.0, 40.0, 24.0
    bounds = np.array([[0, 0], [W, 0], [W, core_y], [core_x, core_y], [core_x, H], [0, H]], float)
    obs: list[np.ndarray] = []
    cy0, cy1 = 13.0, 16.0  # corridor y-range
    # --- north offices: 8 rooms of 5 m, doors of 1 m
    doors_n = [(5 * k + 3.6, 5 * k + 4.6) for k in range(8)]
    obs += wall_with_doors(0.0, core_x, cy1, doors_n)
    for k in range(1, 8):
        obs.append(rect(5 * k - T / 2, cy1, 5 * k + T / 2, H))
    for k in range(8):
        x = 5 * k
        j = rng.uniform(-0.15, 0.15, 6)
        obs.append(rot_rect(x + 2.5 + j[0], 27.6, 1.8, 0.8, j[1] * 0.2))  # desk
        obs.append(ngon(x + 2.5 + j[2], 26.5, 0.3, 12, j[3]))  # chair
        obs.append(rect(x + 0.3, 18.0 + j[4], x + 0.8, 19.4 + j[4]))  # cabinet
        obs.append(ngon(x + 4.4, 29.4, 0.25, 10))  # plant
        obs.append(rot_rect(x + 1.2, 24.0 + j[5], 0.6, 1.6, 0.0))  # bookshelf
    # --- south side: wall along the corridor with openings to the open plan
    obs += wall_with_doors(
        0.0, core_x, cy0, [(3.0, 6.0), (13.0, 16.0), (22.0, 25.0), (31.0, 32.0), (36.0, 37.0)]
    )
    # meeting rooms (x 28..40, y 0..13), split at x = 34
    for x in (28.0, 34.0):
        obs.append(rect(x - T / 2, 0.0, x + T / 2, cy0))
    for x0 in (28.0, 34.0):
        cx, cyy = x0 + 3.0, 6.0
        obs.append(ellipse(cx, cyy, 1.6, 1.0, 16))  # table
        for t in np.linspace(0, 2 * math.pi, 9)[:-1] + 0.2:
            obs.append(ngon(cx + 2.15 * math.cos(t), cyy + 1.55 * math.sin(t), 0.28, 12, t))
        obs.append(rect(x0 + 0.4, 11.5, x0 + 2.4, 12.1))  # credenza
    # open plan (x 0..28, y 0..13): 2 x 3 desk clusters of 4 desks
    for cx in (5.5, 13.5, 21.5):
        for cyy in (3.8, 9.0):
            for sx in (-1, 1):
                for sy in (-1, 1):
                    d0 = cx + sx * 0.8
                    d1 = cyy + sy * 0.4
                    obs.append(rect(d0 - 0.8, d1 - 0.4, d0 + 0.8, d1 + 0.4))
                    ang = rng.uniform(0, math.pi)
                    obs.append(ngon(d0 + rng.uniform(-0.2, 0.2), cyy + sy * 1.35, 0.28, 12, ang))
    # columns on an 8 m grid (open plan and lounge), 12-gons
    for x in (8.0, 16.0, 24.0, 44.0):
        for y in (1.5, 11.5, 20.0):
            if x < core_x and y > cy0:
                continue
            obs.append(ngon(x + 0.8, y, 0.3, 12))
    # lounge (x 40..48, y 0..24): sofas, coffee tables, shelves, plants
    for y in (4.0, 10.0, 16.0):
        obs.append(rect(41.0, y - 0.5, 42.0, y + 1.5))
        obs.append(ellipse(43.5, y + 0.5, 0.7, 0.5, 14))
        obs.append(rect(45.0, y - 0.5, 46.0, y + 1.5))
    obs.append(rect(47.4, 2.0, 47.9, 22.0))  # long shelf on the east wall
    for x, y in [(1.0, 0.6), (27.3, 0.6), (1.0, 12.3), (27.3, 12.3), (40.6, 23.3), (47.3, 0.7)]:
        obs.append(ngon(x, y, 0.3, 10))
    # printers / bins along the corridor
    for x in (9.0, 19.0, 29.0, 38.5):
        obs.append(rect(x, cy0 + 0.1, x + 0.6, cy0 + 0.6))
    target = rect(-0.25, -0.2, 0.25, 0.2)
    goal = rect(11.6, 14.1, 12.6, 14.9)  # drop-off spot in the corridor
    failure = [[20.0, 6.4]]  # a spot in the open plan (between clusters)
    d = {
        "name": "office_floor",
        "bounds": bounds,
        "obstacles": obs,
        "target": target,
        "goal": goal,
        "failure": failure,
        "start": [2.5, 20.5, 0.0],
    }

    def r(a):
        return [[round(float(x), 4), round(float(y), 4)] for x, y in np.asarray(a)]

    out = {k: (r(v) if k in ("bounds", "target", "goal", "failure") else v) for k, v in d.items()}
    out["obstacles"] = [r(o) for o in obs]
    return out


def n_edges(d: dict) -> int:
    return len(d["bounds"]) + sum(len(o) for o in d["obstacles"])


def main(argv: list[str] | None = None) -> None:
    """(Re)write ``office_floor.json`` (no options; ``--help`` describes the scene)."""
    import argparse

    from geometry import Scene

    argparse.ArgumentParser(
        prog="python -m benchmarks.make_office_floor",
        description=__doc__.split("\n\n")[0] + f"  Writes {OUT / 'office_floor.json'}.",
    ).parse_args(argv)

    d = office_floor()
    s = Scene.from_dict(d)
    fs = s.free_space
    rings = sum(1 + len(p.interiors) for p in getattr(fs, "geoms", [fs]))
    OUT.mkdir(parents=True, exist_ok=True)
    path = OUT / "office_floor.json"
    path.write_text(json.dumps(d, separators=(",", ":")) + "\n", encoding="utf-8")
    n_fs = len(shapely.get_coordinates(fs)) - rings
    print(
        f"{path}: {len(d['obstacles'])} obstacles, {n_edges(d)} scene edges, "
        f"{n_fs} free-space edges"
    )


if __name__ == "__main__":
    main()
