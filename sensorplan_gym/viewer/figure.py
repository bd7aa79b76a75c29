"""The Bokeh plot of a scene and its layers, shared by the static export and the live app.

World frame, scene units (the bundled scenes are in metres); equal aspect.  Every
renderer and data source carries a ``name`` so that a page can be inspected: layer
renderers are named ``layer:<key>`` (keys in :data:`layers.LAYERS`), scene parts
``scene:<part>``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from geometry import Scene

from .layers import LAYER_TITLES, LAYERS, Layers, _anchor, geom_to_multipolygon

__all__ = ["COLORS", "SceneFigure", "build_figure", "layer_data", "scene_data"]

#: Fill colours of the layers (G blue, H red, recognizable green, as in the figures).
COLORS = {
    "partial_G": "#c6dbef",
    "partial_H": "#fcbba1",
    "complete_G": "#6baed6",
    "complete_H": "#fb6a4a",
    "recognizable": "#31a354",
}
ALPHAS = {
    "partial_G": 0.45,
    "partial_H": 0.45,
    "complete_G": 0.45,
    "complete_H": 0.45,
    "recognizable": 0.65,
}
G_COLOR, H_COLOR, TARGET_COLOR = "#1f5fd1", "#d12f2f", "#7a2fbf"


def _ring(pts: np.ndarray) -> tuple[list[float], list[float]]:
    p = np.asarray(pts, dtype=float)
    return p[:, 0].tolist(), p[:, 1].tolist()


def scene_data(scene: Scene) -> dict[str, dict[str, list]]:
    """Column data for the scene parts: ``bounds``, ``obstacles``, ``goal``, ``failure``
    (patches; a point G/H is a one-row ``x``/``y`` column instead), ``target`` (drawn at the
    centre of G, world frame) and ``start`` (empty columns when the scene has none)."""
    d: dict[str, dict[str, list]] = {}
    bx, by = _ring(scene.bounds)
    d["bounds"] = {"xs": [bx], "ys": [by]}
    obs = [_ring(o) for o in scene.obstacles]
    d["obstacles"] = {"xs": [o[0] for o in obs], "ys": [o[1] for o in obs]}
    for key, pts in (("goal", scene.goal), ("failure", scene.failure)):
        if len(pts) == 1:
            d[key] = {"x": [float(pts[0, 0])], "y": [float(pts[0, 1])]}
        else:
            x, y = _ring(pts)
            d[key] = {"xs": [x], "ys": [y]}
    ax, ay = _anchor(scene.goal_geom)
    tx, ty = _ring(np.asarray(scene.target) + (ax, ay))
    d["target"] = {"xs": [tx], "ys": [ty]}
    if scene.start is not None:
        d["start"] = {"x": [float(scene.start[0])], "y": [float(scene.start[1])]}
    else:
        d["start"] = {"x": [], "y": []}
    return d


def layer_data(layers: Layers | None, key: str) -> dict[str, list]:
    """One-row ``MultiPolygons`` column data of a layer (empty columns if not computed)."""
    g = None if layers is None else layers.geoms.get(key)
    if g is None:
        return {"xs": [], "ys": [], "name": [], "area": [], "ms": []}
    xs, ys = geom_to_multipolygon(g)
    return {
        "xs": [xs],
        "ys": [ys],
        "name": [LAYER_TITLES[key]],
        "area": [float(g.area)],
        "ms": [float(layers.ms.get(key, math.nan))],
    }


@dataclass
class SceneFigure:
    """The figure with its data sources (``sources[name]``) and renderers
    (``renderers[name]``), names as in the module docstring."""

    fig: Any
    sources: dict[str, Any] = field(default_factory=dict)
    renderers: dict[str, Any] = field(default_factory=dict)


def build_figure(
    scene: Scene,
    layers: Layers | None,
    *,
    visible: tuple[str, ...] | list[str] = LAYERS,
    width: int = 820,
    height: int = 640,
    unit: str = "m",
    hover: bool = True,
) -> SceneFigure:
    """A Bokeh figure of ``scene`` with one toggleable renderer per layer and pan/zoom; with
    ``hover`` a tooltip lists the layers under the cursor (the live app shows its own probe
    panel instead)."""
    from bokeh.models import ColumnDataSource, HoverTool
    from bokeh.plotting import figure

    lo = scene.bounds.min(axis=0)
    hi = scene.bounds.max(axis=0)
    pad = 0.04 * float((hi - lo).max())
    fig = figure(
        width=width,
        height=height,
        match_aspect=True,
        x_range=(float(lo[0] - pad), float(hi[0] + pad)),
        y_range=(float(lo[1] - pad), float(hi[1] + pad)),
        tools="pan,wheel_zoom,box_zoom,reset,save",
        active_scroll="wheel_zoom",
        x_axis_label=f"x ({unit})",
        y_axis_label=f"y ({unit})",
        name="scene_figure",
        output_backend="canvas",
    )
    fig.background_fill_color = "#9a9a9a"
    fig.grid.visible = False
    out = SceneFigure(fig)
    sd = scene_data(scene)

    def src(name: str, data: dict) -> ColumnDataSource:
        s = ColumnDataSource(data=data, name=f"src:{name}")
        out.sources[name] = s
        return s

    r = fig.patches(
        "xs",
        "ys",
        source=src("bounds", sd["bounds"]),
        fill_color="white",
        line_color="black",
        line_width=2,
        name="scene:bounds",
        legend_label="room (walls)",
    )
    out.renderers["bounds"] = r
    hover_layers = []
    for key in LAYERS:
        r = fig.multi_polygons(
            "xs",
            "ys",
            source=src(key, layer_data(layers, key)),
            fill_color=COLORS[key],
            fill_alpha=ALPHAS[key],
            line_color=COLORS[key] if key != "recognizable" else "#006d2c",
            line_width=1 if key != "recognizable" else 1.5,
            name=f"layer:{key}",
            legend_label=LAYER_TITLES[key],
            visible=key in visible,
        )
        out.renderers[key] = r
        hover_layers.append(r)
    r = fig.patches(
        "xs",
        "ys",
        source=src("obstacles", sd["obstacles"]),
        fill_color="#454545",
        line_color="black",
        name="scene:obstacles",
        legend_label="obstacles",
    )
    out.renderers["obstacles"] = r
    for key, color, label in (
        ("goal", G_COLOR, "G: goal region"),
        ("failure", H_COLOR, "H: failure region"),
    ):
        if "xs" in sd[key]:
            r = fig.patches(
                "xs",
                "ys",
                source=src(key, sd[key]),
                fill_color=color,
                fill_alpha=0.45,
                line_color=color,
                line_width=1.5,
                name=f"scene:{key}",
                legend_label=label,
            )
        else:
            r = fig.scatter(
                "x",
                "y",
                source=src(key, sd[key]),
                size=11,
                color=color,
                name=f"scene:{key}",
                legend_label=label,
            )
        out.renderers[key] = r
    r = fig.patches(
        "xs",
        "ys",
        source=src("target", sd["target"]),
        fill_alpha=0.0,
        line_color=TARGET_COLOR,
        line_dash="dashed",
        line_width=2,
        name="scene:target",
        legend_label="target A (drawn at the centre of G)",
    )
    out.renderers["target"] = r
    r = fig.scatter(
        "x",
        "y",
        source=src("start", sd["start"]),
        marker="square",
        size=10,
        color="black",
        name="scene:start",
        legend_label="robot start",
    )
    out.renderers["start"] = r
    if hover:
        fig.add_tools(
            HoverTool(
                renderers=hover_layers,
                tooltips=[
                    ("layer", "@name"),
                    ("area", f"@area{{0.00}} {unit}²"),
                    ("computed in", "@ms{0.0} ms"),
                    ("cursor", f"($x{{0.00}}, $y{{0.00}}) {unit}"),
                ],
                name="hover:layers",
            )
        )
    fig.legend.click_policy = "hide"
    fig.legend.location = "top_left"
    fig.legend.label_text_font_size = "8pt"
    fig.legend.background_fill_alpha = 0.8
    fig.add_layout(fig.legend[0], "right")
    return out
