"""What the viewer shows, computed from the exact geometry (no Bokeh here).

Layers (shapely geometries, world frame, scene units):

``complete_G`` / ``complete_H``
    placements that see *all* of the target wherever it is in G (resp. H)
    (:func:`geometry.complete_region`, paper 3.1);
``partial_G`` / ``partial_H``
    placements that see *some* of it (:func:`geometry.partial_region`, paper 3.2);
``recognizable``
    R(G) n R(H) - C(G, H) for the chosen visibility model
    (:func:`geometry.recognizable_region`, paper 5).

Target motion follows :mod:`sensorplan_gym.core.world`: ``"stationary"`` puts the
target at the centre of G and of H (G and H become those points), ``"translating"``
lets it be anywhere in G/H at orientation 0, ``"rotating"`` at any orientation.
``eps_pos`` (scene units) and ``eps_aim`` (radians) are the paper's section-4
uncertainties; ``fov`` (radians) does not change where the regions are, it decides
whether one aim at a placement keeps both targets in view (:meth:`World.aim_ok`),
which :func:`probe` reports.

Nothing is sampled: each layer is one call of the exact construction, and every
point query (:func:`probe`) is a point-in-polygon test on those exact regions plus
one exact visibility polygon.
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
import shapely

from geometry import (
    Scene,
    SceneError,
    complete_region,
    partial_region,
    recognizable_region,
)

from ..core.world import MODELS, MOTIONS

__all__ = [
    "LAYERS",
    "LAYER_TITLES",
    "Layers",
    "Settings",
    "compute_layers",
    "effective_scene",
    "geom_to_multipolygon",
    "probe",
]

#: Layer keys in drawing order (bottom first).
LAYERS = ("partial_G", "partial_H", "complete_G", "complete_H", "recognizable")

LAYER_TITLES = {
    "partial_G": "partial visibility of A in G",
    "partial_H": "partial visibility of A in H",
    "complete_G": "complete visibility of A in G",
    "complete_H": "complete visibility of A in H",
    "recognizable": "recognizable region R(G)∩R(H)−C(G,H)",
}


@dataclass(frozen=True)
class Settings:
    """Viewer settings.  ``eps_pos`` in scene units; ``eps_aim`` and ``fov`` in radians."""

    model: str = "complete"
    motion: str = "translating"
    eps_pos: float = 0.0
    eps_aim: float = 0.0
    fov: float = 2 * math.pi

    def __post_init__(self) -> None:
        if self.model not in MODELS:
            raise ValueError(f"model must be one of {MODELS}, got {self.model!r}")
        if self.motion not in MOTIONS:
            raise ValueError(f"motion must be one of {MOTIONS}, got {self.motion!r}")
        for name in ("eps_pos", "eps_aim", "fov"):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise ValueError(f"{name} must be a finite number, got {v!r}")
            if v < 0:
                raise ValueError(f"{name} must be >= 0, got {v!r}")
        if not 0 < self.fov <= 2 * math.pi + 1e-12:
            raise ValueError(f"fov must be in (0, 2*pi] radians, got {self.fov!r}")

    @classmethod
    def from_scene(cls, scene: Scene, **over: Any) -> Settings:
        """The scene's own sensor spec, with keyword overrides."""
        d = {
            "eps_pos": float(scene.sensor.eps_pos),
            "eps_aim": float(scene.sensor.eps_aim),
            "fov": float(scene.sensor.fov),
        }
        d.update({k: v for k, v in over.items() if v is not None})
        return cls(**d)

    def to_dict(self) -> dict[str, Any]:
        return asdict(self)


@dataclass
class Layers:
    """Computed layers: ``geoms[key]`` (shapely), ``ms[key]`` the wall time of its exact
    construction in milliseconds, ``errors[key]`` why a layer is missing (e.g. a model and
    motion the geometry does not support)."""

    scene: Scene
    effective: Scene
    settings: Settings
    geoms: dict[str, shapely.Geometry] = field(default_factory=dict)
    ms: dict[str, float] = field(default_factory=dict)
    errors: dict[str, str] = field(default_factory=dict)

    @property
    def total_ms(self) -> float:
        return float(sum(self.ms.values()))


def _anchor(g: shapely.Geometry) -> tuple[float, float]:
    """Centroid of G/H, or a representative interior point when the centroid lies outside
    (the same convention as :mod:`sensorplan_gym.core.world`)."""
    if g.geom_type == "Point":
        return (float(g.x), float(g.y))
    c = g.centroid
    if not g.contains(c):
        c = g.representative_point()
    return (float(c.x), float(c.y))


def effective_scene(scene: Scene, settings: Settings) -> Scene:
    """The scene the geometry is asked about: for a stationary target, G and H replaced by
    their centres (may raise :class:`SceneError` when those points are not valid)."""
    if settings.motion != "stationary":
        return scene
    return scene.replace(
        goal=[list(_anchor(scene.goal_geom))], failure=[list(_anchor(scene.failure_geom))]
    )


def _theta(settings: Settings) -> float | None:
    return None if settings.motion == "rotating" else 0.0


def compute_layers(
    scene: Scene, settings: Settings, which: tuple[str, ...] | list[str] = LAYERS
) -> Layers:
    """Compute the layers named in ``which`` exactly, timing each.

    Raises :class:`geometry.SceneError` when the stationary scene is invalid; a layer the
    geometry does not support is left out with its reason in ``errors``.
    """
    for k in which:
        if k not in LAYERS:
            raise ValueError(f"unknown layer {k!r} (known: {', '.join(LAYERS)})")
    eff = effective_scene(scene, settings)
    out = Layers(scene=scene, effective=eff, settings=settings)
    th = _theta(settings)
    for key in LAYERS:
        if key not in which:
            continue
        t = time.perf_counter()
        try:
            if key.startswith("complete_"):
                g = complete_region(
                    eff,
                    target_in="goal" if key.endswith("G") else "failure",
                    theta=th,
                    eps_pos=settings.eps_pos,
                )
            elif key.startswith("partial_"):
                g = partial_region(
                    eff,
                    target_in="goal" if key.endswith("G") else "failure",
                    theta=th,
                    eps_pos=settings.eps_pos,
                    eps_aim=settings.eps_aim,
                )
            else:
                g = recognizable_region(
                    eff,
                    model=settings.model,
                    theta=th,
                    eps_pos=settings.eps_pos,
                    eps_aim=settings.eps_aim,
                )
        except NotImplementedError as e:
            out.errors[key] = str(e)
            continue
        except SceneError:
            raise
        except ValueError as e:
            out.errors[key] = str(e)
            continue
        shapely.prepare(g)
        out.ms[key] = 1e3 * (time.perf_counter() - t)
        out.geoms[key] = g
    return out


def geom_to_multipolygon(geom: shapely.Geometry) -> tuple[list, list]:
    """Bokeh ``MultiPolygons`` coordinates of a (Multi)Polygon: ``(xs, ys)`` with
    ``xs[polygon][ring] = [x, ...]``, exterior ring first, holes after (rings open)."""
    xs: list = []
    ys: list = []
    for poly in shapely.get_parts(geom):
        if poly.is_empty or poly.geom_type != "Polygon":
            continue
        px, py = [], []
        for ring in [poly.exterior, *poly.interiors]:
            c = np.asarray(ring.coords)[:-1, :2]
            px.append(c[:, 0].tolist())
            py.append(c[:, 1].tolist())
        xs.append(px)
        ys.append(py)
    return xs, ys


def probe(layers: Layers, x: float, y: float) -> dict[str, Any]:
    """Everything the viewer says about a placement ``(x, y)`` (world frame).

    Returns a dict with ``free`` (inside the free space), ``vis`` (the exact visibility
    polygon V(p) in the free space, a shapely Polygon; empty outside), ``sees_G`` /
    ``sees_H`` (p lies in the region of the chosen model for A in G / in H, or None when
    that layer was not computed), ``recognizable`` (p in the recognizable region),
    ``aim`` (the aim in radians between the directions to the two swept targets),
    ``aim_ok`` (that aim keeps both in the field of view, :meth:`World.aim_ok`) and ``ms``
    (the wall time of the query in milliseconds).
    """
    from geometry._common import scene_domain
    from geometry._vis import visibility_polygon

    t = time.perf_counter()
    eff = layers.effective
    free = bool(shapely.contains_xy(eff.free_space, x, y))
    vis = shapely.Polygon()
    if free:
        vis = visibility_polygon(scene_domain(eff), np.array([x, y], dtype=float))

    def inside(key: str) -> bool | None:
        g = layers.geoms.get(key)
        return None if g is None else bool(shapely.contains_xy(g, x, y))

    m = layers.settings.model
    res: dict[str, Any] = {
        "x": float(x),
        "y": float(y),
        "free": free,
        "vis": vis,
        "sees_G": inside(f"{m}_G"),
        "sees_H": inside(f"{m}_H"),
        "recognizable": inside("recognizable"),
    }
    aim, ok = _aim(layers, x, y) if free else (None, None)
    res["aim"], res["aim_ok"] = aim, ok
    res["ms"] = 1e3 * (time.perf_counter() - t)
    return res


def _aim(layers: Layers, x: float, y: float) -> tuple[float | None, bool | None]:
    """Best aim and the env's aim check at (x, y), from the env's own :class:`World` of the
    same settings (built once per settings; cached by :func:`get_world`).  With a full field
    of view and unlimited range every aim is fine and no World is built."""
    s = layers.settings
    full = s.fov >= 2 * math.pi - 1e-12 and layers.scene.sensor.max_range is None
    world = layers.__dict__.get("_world")
    if world is None and not full:
        from sensorplan_gym.core.cache import get_world
        from sensorplan_gym.core.world import WorldConfig

        cfg = WorldConfig(
            model=s.model, motion=s.motion, eps_pos=s.eps_pos, eps_aim=s.eps_aim, fov=s.fov
        )
        try:
            world = get_world(layers.scene, cfg)
        except (ValueError, NotImplementedError):
            return None, None
        layers.__dict__["_world"] = world
    if world is None:
        return None, True
    psi = world.best_aim(x, y)
    return float(psi), bool(world.aim_ok(x, y, psi))


def main(argv: list[str] | None = None) -> int:
    """``python -m sensorplan_gym.viewer.layers [SCENE ...]``: the viewer's layer and probe
    timings (medians of ``--repeat`` runs, milliseconds) -- what the live app re-runs on
    every edit."""
    import argparse
    import statistics

    from sensorplan_gym.core.world import load_scene

    ap = argparse.ArgumentParser(prog="python -m sensorplan_gym.viewer.layers")
    ap.add_argument("scenes", nargs="*", default=["lab"])
    ap.add_argument("--model", choices=MODELS, default="complete")
    ap.add_argument("--motion", choices=MOTIONS, default="translating")
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args(argv)
    print(f"model={args.model} motion={args.motion}; median of {args.repeat} runs, ms")
    print(f"{'scene':<10}" + "".join(f"{k:>14}" for k in LAYERS) + f"{'probe':>10}")
    for name in args.scenes:
        scene = load_scene(name)
        settings = Settings.from_scene(scene, model=args.model, motion=args.motion)
        runs = [compute_layers(scene, settings) for _ in range(args.repeat)]
        cells = []
        for k in LAYERS:
            if k in runs[0].geoms:
                cells.append(f"{statistics.median(r.ms[k] for r in runs):>14.1f}")
            else:
                cells.append(f"{'n/a':>14}")
        rng = np.random.default_rng(0)
        lo, hi = scene.bounds.min(axis=0), scene.bounds.max(axis=0)
        pts = rng.uniform(lo, hi, size=(50, 2))
        pm = statistics.median(probe(runs[0], x, y)["ms"] for x, y in pts)
        print(f"{name:<10}" + "".join(cells) + f"{pm:>10.2f}")
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
