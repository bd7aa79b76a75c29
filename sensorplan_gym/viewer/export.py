"""``sensorplan view --export view.html``: one self-contained HTML file, no server.

The scene and all five precomputed layers (:data:`layers.LAYERS`), each toggled by a
checkbox or by clicking its legend entry; pan, wheel zoom, box zoom; hovering a
region lists every layer under the cursor with its area.  BokehJS is inlined
(``bokeh.resources.INLINE``), so the file opens offline.  With a saved rollout
(:mod:`.replay`) a second tab replays it.
"""

from __future__ import annotations

import html
import json
import math
from pathlib import Path

from geometry import Scene

from .figure import build_figure
from .layers import LAYER_TITLES, LAYERS, Settings, compute_layers

__all__ = ["export_html", "export_layout"]


def _settings_text(s: Settings, unit: str) -> str:
    return (
        f"model={s.model}, motion={s.motion}, eps_pos={s.eps_pos:g} {unit}, "
        f"eps_aim={math.degrees(s.eps_aim):g}°, fov={math.degrees(s.fov):g}°"
    )


def export_layout(scene: Scene, settings: Settings | None = None, *, unit: str = "m"):
    """The Bokeh layout of the export (for embedding elsewhere) and the computed layers."""
    from bokeh.layouts import column, row
    from bokeh.models import CheckboxGroup, CustomJS, Div

    settings = Settings.from_scene(scene) if settings is None else settings
    layers = compute_layers(scene, settings)
    sf = build_figure(scene, layers, unit=unit)
    labels, renderers = [], []
    for key in LAYERS:
        if key in layers.geoms:
            labels.append(f"{LAYER_TITLES[key]} ({layers.ms[key]:.1f} ms)")
        else:
            labels.append(f"{LAYER_TITLES[key]} (not available)")
        renderers.append(sf.renderers[key])
    toggles = CheckboxGroup(labels=labels, active=list(range(len(LAYERS))), name="layer_toggles")
    toggles.js_on_change(
        "active",
        CustomJS(
            args={"rs": renderers},
            code="for (let i = 0; i < rs.length; i++) { rs[i].visible = this.active.includes(i) }",
        ),
    )
    errors = "".join(
        f"<li><b>{html.escape(LAYER_TITLES[k])}</b>: {html.escape(v)}</li>"
        for k, v in layers.errors.items()
    )
    head = Div(
        text=(
            f"<h2 style='margin:0'>sensorplan: scene “{html.escape(scene.name)}”</h2>"
            f"<p>{html.escape(_settings_text(settings, unit))}<br>"
            f"Exact regions (nothing sampled), computed in {layers.total_ms:.0f} ms in all. "
            "Toggle layers with the checkboxes or the legend; wheel to zoom; hover a "
            "region to list the layers under the cursor.</p>"
            + (f"<ul>{errors}</ul>" if errors else "")
        ),
        width=1100,
        name="header",
    )
    info = Div(
        text="<pre style='font-size:11px'>"
        + html.escape(
            json.dumps({k: round(float(g.area), 4) for k, g in layers.geoms.items()}, indent=1)
        )
        + "</pre>",
        name="areas",
    )
    layout = column(head, row(sf.fig, column(Div(text="<b>Layers</b>"), toggles, info)))
    return layout, layers


def export_html(
    scene: Scene,
    path: str | Path,
    settings: Settings | None = None,
    *,
    unit: str = "m",
    rollout: str | Path | dict | None = None,
) -> Path:
    """Write the self-contained HTML view of ``scene`` to ``path``; returns the path.
    With ``rollout`` (a file of :mod:`.replay` or its dict) a second tab replays it."""
    from bokeh.embed import file_html
    from bokeh.resources import INLINE

    layout, _ = export_layout(scene, settings, unit=unit)
    if rollout is not None:
        from bokeh.models import TabPanel, Tabs

        from .replay import replay_layout

        layout = Tabs(
            tabs=[
                TabPanel(child=layout, title="Scene and regions"),
                TabPanel(child=replay_layout(rollout, unit=unit), title="Replay"),
            ],
            name="tabs",
        )
    text = file_html(layout, resources=INLINE, title=f"sensorplan view: {scene.name}")
    p = Path(path)
    p.write_text(text, encoding="utf-8")
    return p
