"""``sensorplan view [SCENE]``: the live viewer, a Bokeh server app on localhost.

What it does
------------
* draws the scene and the layers of :mod:`.layers` (complete / partial visibility of
  the target in G and in H, the recognizable region), each toggled by a checkbox;
* controls for the visibility model, the target motion, ``eps_pos`` (scene units),
  ``eps_aim`` and the field of view (degrees);
* drag-to-edit: the vertices of the walls, obstacles, G, H and the target
  (``PolyEditTool``: press and hold a shape, then drag its vertices; ``PolyDrawTool``
  adds obstacles; ``PointDrawTool`` moves the start and point-shaped G/H); every edit
  rebuilds the :class:`geometry.Scene` and recomputes the checked layers exactly,
  and the page says how long that took;
* an invalid edit shows the :class:`geometry.SceneError` message (the last valid
  regions stay on screen, greyed), it never crashes the app;
* moving the mouse over the plot shows, for the placement under the cursor, its
  exact visibility polygon, whether it sees A in G and in H (the chosen model),
  whether it is in the recognizable region and whether the best aim passes the
  field-of-view check; a click pins the placement;
* save the edited scene on this machine (scene JSON, ``.geojson`` or ``.wkt``, by the
  name's extension), or load a scene file (scene JSON, GeoJSON or WKT) from the browser;
* a second tab replays a rollout saved by :mod:`.replay` when one is given.

Access and files
----------------
* The server listens on 127.0.0.1 only and serves only requests carrying its token:
  ``sensorplan view`` prints ``http://localhost:PORT/?token=...`` (a random token per
  launch; ``--token`` or ``$SENSORPLAN_VIEW_TOKEN`` give one).  A page opened without it
  gets a 403 page and no session (see :mod:`.auth`).
* Saves are confined to the viewer's *root* folder: the folder it was started in, or
  ``--root DIR``.  A path outside it (after resolving symlinks and ``..``), or one not
  ending in ``.json``/``.geojson``/``.wkt``, is refused with a message in the page and
  nothing is written (see :mod:`.files`).  Loading uploads the content of a file the
  browser's user picks; the server opens no path for it.
"""

from __future__ import annotations

import base64
import html
import math
import time
from os import PathLike
from pathlib import Path
from typing import Any

from geometry import Scene, SceneError
from geometry.formats import scene_from_text

from .figure import build_figure, layer_data, scene_data
from .files import save_scene_confined
from .layers import (
    LAYER_TITLES,
    LAYERS,
    MODELS,
    MOTIONS,
    Layers,
    Settings,
    _anchor,
    compute_layers,
    geom_to_multipolygon,
    probe,
)

__all__ = ["ViewerApp", "make_document", "scene_from_sources", "serve"]

#: Layers computed and shown when the app opens (the partial ones take ~0.5 s each on the
#: bundled scenes with polygonal G/H, the others a few milliseconds).
DEFAULT_VISIBLE = ("complete_G", "complete_H", "recognizable")


def _pts(xs: list, ys: list) -> list[list[float]]:
    return [[float(x), float(y)] for x, y in zip(xs, ys, strict=True)]


def scene_from_sources(base: Scene, data: dict[str, dict[str, list]], target_at: Any) -> Scene:
    """Rebuild a validated scene from the plot's column data (see :func:`figure.scene_data`).

    ``target_at`` is the world point at which the target was drawn (its reference point):
    the drawn target minus that point is the target in its own frame.  Raises
    :class:`geometry.SceneError` for an invalid scene.
    """
    d = base.to_dict()
    b = data["bounds"]
    if len(b["xs"]) != 1:
        raise SceneError(f"bounds: expected one polygon, got {len(b['xs'])}")
    d["bounds"] = _pts(b["xs"][0], b["ys"][0])
    o = data["obstacles"]
    d["obstacles"] = [_pts(x, y) for x, y in zip(o["xs"], o["ys"], strict=True)]
    for key in ("goal", "failure"):
        g = data[key]
        if "xs" in g:
            if len(g["xs"]) != 1:
                raise SceneError(f"{key}: expected one polygon, got {len(g['xs'])}")
            d[key] = _pts(g["xs"][0], g["ys"][0])
        else:
            if len(g["x"]) != 1:
                raise SceneError(f"{key}: expected one point, got {len(g['x'])}")
            d[key] = [[float(g["x"][0]), float(g["y"][0])]]
    t = data["target"]
    if len(t["xs"]) != 1:
        raise SceneError(f"target: expected one polygon, got {len(t['xs'])}")
    ax, ay = target_at
    d["target"] = [[x - ax, y - ay] for x, y in _pts(t["xs"][0], t["ys"][0])]
    s = data["start"]
    if len(s["x"]) == 1:
        theta = float(base.start[2]) if base.start is not None else 0.0
        d["start"] = [float(s["x"][0]), float(s["y"][0]), theta]
    elif len(s["x"]) > 1:
        raise SceneError(f"start: expected one point, got {len(s['x'])}")
    else:
        d.pop("start", None)
    return Scene.from_dict(d)


class ViewerApp:
    """State and callbacks of one browser session (one Bokeh document)."""

    def __init__(
        self,
        scene: Scene,
        settings: Settings | None = None,
        *,
        visible: tuple[str, ...] = DEFAULT_VISIBLE,
        save_path: str | None = None,
        rollout: str | None = None,
        unit: str = "m",
        root: str | PathLike[str] | None = None,
    ) -> None:
        """``root``: the folder saves are confined to (default: the current directory);
        ``save_path``: the save box's initial value, relative to ``root``."""
        self.unit = unit
        self.root_dir = Path.cwd().resolve() if root is None else Path(root).resolve()
        if not self.root_dir.is_dir():
            raise NotADirectoryError(f"the viewer's root folder {self.root_dir} is not a directory")
        self.scene = scene
        self.settings = Settings.from_scene(scene) if settings is None else settings
        self.visible = tuple(visible)
        self.save_path = save_path or f"{scene.name}_edited.json"
        self.rollout = rollout
        self.layers: Layers | None = None
        self.error: str | None = None
        self.last_ms = 0.0
        self.recomputes = 0
        self._syncing = False
        self._pending = False
        self.doc = None
        self.root = None
        self._build()

    # ---- layout ----------------------------------------------------------------------
    def _build(self) -> None:
        from bokeh.layouts import column, row
        from bokeh.models import (
            Button,
            CheckboxGroup,
            Div,
            FileInput,
            PointDrawTool,
            PolyDrawTool,
            PolyEditTool,
            Select,
            Spinner,
            TabPanel,
            Tabs,
            TextInput,
        )

        s = self.settings
        self.target_at = _anchor(self.scene.goal_geom)
        self.layers = self._compute(self.scene) or self.layers
        sf = build_figure(
            self.scene, self.layers, visible=self.visible, unit=self.unit, width=920, hover=False
        )
        self.sf = sf
        fig = sf.fig
        # the visibility polygon of the placement under the cursor, and the placement
        from bokeh.models import ColumnDataSource

        self.vis_src = ColumnDataSource({"xs": [], "ys": []}, name="src:vis")
        fig.multi_polygons(
            "xs",
            "ys",
            source=self.vis_src,
            fill_color="#ffd92f",
            fill_alpha=0.35,
            line_color="#b8860b",
            line_width=1,
            name="probe:vis",
        )
        self.probe_src = ColumnDataSource(
            {"x": [], "y": [], "ax": [], "ay": [], "r": [], "a0": [], "a1": []}, name="src:probe"
        )
        # the field of view at the best aim (drawn only when it is narrower than 360 degrees)
        fig.wedge(
            "x", "y", radius="r", start_angle="a0", end_angle="a1", source=self.probe_src,
            fill_color="#7b3294", fill_alpha=0.12, line_color="#7b3294", line_alpha=0.5,
            name="probe:fov",
        )  # fmt: skip
        fig.segment(
            "x",
            "y",
            "ax",
            "ay",
            source=self.probe_src,
            line_color="#7b3294",
            line_width=2.5,
            name="probe:aim",
        )
        fig.scatter("x", "y", source=self.probe_src, size=9, color="#7b3294", name="probe:point")
        # editing tools
        vtx = fig.scatter([], [], size=9, color="#ff7f0e", name="edit:vertices")
        editable = [
            sf.renderers[k]
            for k in ("obstacles", "goal", "failure", "target", "bounds")
            if sf.renderers[k].glyph.__class__.__name__ == "Patches"
        ]
        fig.add_tools(
            PolyEditTool(
                renderers=editable,
                vertex_renderer=vtx,
                description="Edit vertices (press and hold a shape, drag its vertices)",
            )
        )
        fig.add_tools(
            PolyDrawTool(
                renderers=[sf.renderers["obstacles"]],
                description="Draw a new obstacle (click vertices, "
                "double-click to close; Backspace deletes)",
            )
        )
        points = [sf.renderers["start"]] + [
            sf.renderers[k]
            for k in ("goal", "failure")
            if sf.renderers[k].glyph.__class__.__name__ == "Scatter"
        ]
        fig.add_tools(
            PointDrawTool(renderers=points, add=False, description="Move the start (and point G/H)")
        )
        for name in ("bounds", "obstacles", "goal", "failure", "target", "start"):
            sf.sources[name].on_change("data", self._on_scene_edit)

        # controls
        self.w_model = Select(
            title="visibility model", value=s.model, options=list(MODELS), name="model"
        )
        self.w_motion = Select(
            title="target motion", value=s.motion, options=list(MOTIONS), name="motion"
        )
        self.w_eps_pos = Spinner(
            title=f"eps_pos ({self.unit}, placement error)",
            low=0,
            step=0.01,
            value=s.eps_pos,
            name="eps_pos",
            width=200,
        )
        self.w_eps_aim = Spinner(
            title="eps_aim (deg, aim error)",
            low=0,
            high=179.9,
            step=0.5,
            value=math.degrees(s.eps_aim),
            name="eps_aim",
            width=200,
        )
        self.w_fov = Spinner(
            title="fov (deg, field of view)",
            low=1,
            high=360,
            step=5,
            value=math.degrees(s.fov),
            name="fov",
            width=200,
        )
        for w in (self.w_model, self.w_motion, self.w_eps_pos, self.w_eps_aim, self.w_fov):
            w.on_change("value", self._on_settings)
        self.w_layers = CheckboxGroup(
            labels=[LAYER_TITLES[k] for k in LAYERS],
            active=[i for i, k in enumerate(LAYERS) if k in self.visible],
            name="layer_toggles",
        )
        self.w_layers.on_change("active", self._on_layers)
        self.status = Div(text="", width=330, name="status")
        self.info = Div(
            text="<i>move the mouse over the plot: the placement under the "
            "cursor is probed; click to pin it</i>",
            width=330,
            name="probe",
        )
        self.w_save_path = TextInput(
            title=f"save scene to (.json, .geojson or .wkt, inside {self.root_dir})",
            value=self.save_path,
            name="save_path",
            width=330,
        )
        self.w_save = Button(label="Save scene", name="save", width=120)
        self.w_save.on_click(self._on_save)
        self.w_load = FileInput(
            accept=".json,.geojson,.wkt",
            name="load",
            title="load a scene (scene JSON, GeoJSON or WKT)",
        )
        self.w_load.on_change("value", self._on_load)
        self.file_status = Div(text="", width=330, name="file_status")
        self.w_reset = Button(label="Revert to the last loaded scene", name="revert", width=220)
        self.w_reset.on_click(self._on_revert)
        self.loaded = self.scene

        from bokeh import events

        fig.on_event(events.MouseMove, self._on_move)
        fig.on_event(events.Tap, self._on_tap)
        self.pinned = False

        help_div = Div(
            text=(
                "<b>Edit</b>: pick the <i>edit vertices</i> tool, press and hold a shape "
                "(obstacle, G, H, target, walls) until its vertices show (orange), then drag "
                "them; Backspace deletes a selected vertex. New obstacle: the <i>draw</i> tool "
                "(click the corners, double-click to close). Invalid scenes are reported, "
                "not applied."
            ),
            width=330,
        )
        controls = column(
            Div(
                text=f"<h3 style='margin:0'>sensorplan view: {html.escape(self.scene.name)}</h3>",
                name="title",
            ),
            self.w_model,
            self.w_motion,
            self.w_eps_pos,
            self.w_eps_aim,
            self.w_fov,
            Div(text="<b>Layers</b> (unchecked layers are not computed)"),
            self.w_layers,
            self.status,
            self.info,
            help_div,
            self.w_save_path,
            row(self.w_save, self.w_reset),
            self.file_status,
            self.w_load,
            width=350,
        )
        tabs = [TabPanel(child=row(fig, controls), title="Scene and regions")]
        if self.rollout is not None:
            from .replay import replay_layout

            tabs.append(TabPanel(child=replay_layout(self.rollout, unit=self.unit), title="Replay"))
        self.root = Tabs(tabs=tabs, name="tabs")
        self._show_status()

    # ---- computation -----------------------------------------------------------------
    def _compute(self, scene: Scene) -> Layers | None:
        t = time.perf_counter()
        try:
            layers = compute_layers(scene, self.settings, self.visible)
        except SceneError as e:
            self.error = str(e)
            return None
        self.last_ms = 1e3 * (time.perf_counter() - t)
        self.recomputes += 1
        self.error = None
        return layers

    def _push_layers(self) -> None:
        for key in LAYERS:
            self.sf.sources[key].data = layer_data(self.layers, key)
            self.sf.renderers[key].visible = key in self.visible
            self.sf.renderers[key].glyph.fill_alpha = (
                0.15 if self.error else (0.65 if key == "recognizable" else 0.45)
            )

    def _show_status(self) -> None:
        if self.error:
            self.status.text = (
                "<div style='color:#b00020;border:1px solid #b00020;padding:4px' "
                f"id='scene-error'><b>Invalid scene</b>: {html.escape(self.error)}<br>"
                "<i>showing the last valid regions (greyed); fix or revert the edit</i></div>"
            )
            return
        lay = self.layers
        parts = []
        for key in LAYERS:
            if lay is not None and key in lay.geoms:
                parts.append(
                    f"{html.escape(LAYER_TITLES[key])}: {lay.geoms[key].area:.2f} "
                    f"{self.unit}² in {lay.ms[key]:.1f} ms"
                )
            elif lay is not None and key in lay.errors:
                parts.append(
                    f"{html.escape(LAYER_TITLES[key])}: <i>n/a</i> ({html.escape(lay.errors[key])})"
                )
        self.status.text = (
            f"<div id='timing'><b>Exact recomputation: {self.last_ms:.1f} ms</b> "
            f"(update #{self.recomputes})<br>" + "<br>".join(parts) + "</div>"
        )

    def recompute(self) -> None:
        """Rebuild the scene from the plot and recompute the visible layers now."""
        self._pending = False
        try:
            scene = scene_from_sources(self.scene, self._data(), self.target_at)
        except SceneError as e:
            self.error = str(e)
        else:
            layers = self._compute(scene)
            if layers is not None:
                self.scene, self.layers = scene, layers
                new_at = _anchor(scene.goal_geom)
                if new_at != self.target_at:  # G moved: the target is drawn at its centre
                    self.target_at = new_at
                    self._syncing = True
                    try:
                        self.sf.sources["target"].data = scene_data(scene)["target"]
                    finally:
                        self._syncing = False
        self._push_layers()
        self._show_status()
        if self.probe_src.data["x"]:  # the probed placement, against the new scene
            self.probe_at(self.probe_src.data["x"][0], self.probe_src.data["y"][0])

    def _data(self) -> dict[str, dict[str, list]]:
        return {
            k: dict(self.sf.sources[k].data)
            for k in ("bounds", "obstacles", "goal", "failure", "target", "start")
        }

    def _schedule(self) -> None:
        if self.doc is None:
            self.recompute()
            return
        if not self._pending:
            self._pending = True
            self.doc.add_next_tick_callback(self.recompute)

    # ---- callbacks -------------------------------------------------------------------
    def _on_scene_edit(self, attr, old, new) -> None:
        if not self._syncing:
            self._schedule()

    def _on_settings(self, attr, old, new) -> None:
        try:
            self.settings = Settings(
                model=self.w_model.value,
                motion=self.w_motion.value,
                eps_pos=float(self.w_eps_pos.value or 0.0),
                eps_aim=math.radians(float(self.w_eps_aim.value or 0.0)),
                fov=math.radians(float(self.w_fov.value or 360.0)),
            )
        except ValueError as e:
            self.error = str(e)
            self._show_status()
            return
        self._schedule()

    def _on_layers(self, attr, old, new) -> None:
        self.visible = tuple(LAYERS[i] for i in new)
        self._schedule()

    def probe_at(self, x: float, y: float) -> dict[str, Any] | None:
        """Probe the placement (x, y): update the visibility polygon and the text."""
        if self.layers is None:
            return None
        res = probe(self.layers, x, y)
        xs, ys = geom_to_multipolygon(res["vis"])
        self.vis_src.data = {"xs": [xs] if xs else [], "ys": [ys] if ys else []}
        fov = self.settings.fov
        if res["free"] and res["aim"] is not None:
            psi = res["aim"]
            L = 0.05 * self.scene.diameter
            ax, ay = x + L * math.cos(psi), y + L * math.sin(psi)
            r = 0.25 * self.scene.diameter if fov < 2 * math.pi - 1e-9 else 0.0
            self.probe_src.data = {
                "x": [x], "y": [y], "ax": [ax], "ay": [ay], "r": [r],
                "a0": [psi - fov / 2], "a1": [psi + fov / 2],
            }  # fmt: skip
        else:
            self.probe_src.data = {
                "x": [x],
                "y": [y],
                "ax": [x],
                "ay": [y],
                "r": [0.0],
                "a0": [0.0],
                "a1": [0.0],
            }

        def yn(v):
            return (
                "—"
                if v is None
                else (
                    "<b style='color:#137333'>yes</b>" if v else "<b style='color:#b00020'>no</b>"
                )
            )

        m = self.settings.model
        if not res["free"]:
            body = "not in the free space (inside an obstacle or outside the walls)"
        else:
            aim = "" if res["aim"] is None else f" (aim {math.degrees(res['aim']):.1f}°)"
            body = (
                f"sees A in G ({m}): {yn(res['sees_G'])}<br>"
                f"sees A in H ({m}): {yn(res['sees_H'])}<br>"
                f"in the recognizable region: {yn(res['recognizable'])}<br>"
                f"one aim keeps both in the fov{aim}: {yn(res['aim_ok'])}<br>"
                f"visibility polygon: {res['vis'].area:.2f} {self.unit}²"
            )
        self.info.text = (
            f"<div id='probe-info'><b>placement ({x:.2f}, {y:.2f}) {self.unit}</b>"
            f"{' (pinned)' if self.pinned else ''}<br>{body}<br>"
            f"<i>query {res['ms']:.1f} ms</i></div>"
        )
        return res

    def _on_move(self, event) -> None:
        if not self.pinned:
            self.probe_at(event.x, event.y)

    def _on_tap(self, event) -> None:
        self.pinned = not self.pinned
        self.probe_at(event.x, event.y)

    def _file_message(self, kind: str, text: str, ok: bool) -> None:
        colour = "#137333" if ok else "#b00020"
        self.file_status.text = (
            f"<div id='{kind}' style='color:{colour};border:1px solid {colour};padding:4px'>"
            f"{text}</div>"
        )

    def save(self, path: str) -> Path | None:
        """Save the scene as drawn to ``path`` (relative to the root, confined to it; see
        :func:`.files.save_scene_confined`); returns the path written, or ``None`` with the
        reason shown in the page."""
        try:
            scene = scene_from_sources(self.scene, self._data(), self.target_at)
            out = save_scene_confined(scene, path, self.root_dir)
        except OSError as e:
            where = f" ({e.filename})" if getattr(e, "filename", None) else ""
            msg = f"{e.strerror or e}{where}"
            self._file_message("save-refused", f"<b>Not saved</b>: {html.escape(msg)}", False)
            return None
        except ValueError as e:  # SceneError, OutsideRootError, a bad name
            self._file_message("save-refused", f"<b>Not saved</b>: {html.escape(str(e))}", False)
            return None
        self._file_message("saved", f"saved {html.escape(str(out))}", True)
        return out

    def _on_save(self) -> None:
        self.save(self.w_save_path.value)

    def _on_load(self, attr, old, new) -> None:
        try:
            text = base64.b64decode(new).decode("utf-8")
            scene = scene_from_text(text, None, default_name="uploaded")
        except (ValueError, UnicodeDecodeError) as e:  # SceneError, FormatError, base64
            self._file_message("load-error", f"<b>Not loaded</b>: {html.escape(str(e))}", False)
            return
        self.replace_scene(scene)
        self._file_message("loaded", f"loaded scene {html.escape(scene.name)}", True)

    def _on_revert(self) -> None:
        self.replace_scene(self.loaded)

    def replace_scene(self, scene: Scene) -> None:
        """Show another scene (rebuilds the page's layout)."""
        self.scene = self.loaded = scene
        self.settings = Settings.from_scene(
            scene, model=self.settings.model, motion=self.settings.motion
        )
        self.error = None
        old = self.root
        self._build()
        if self.doc is not None and old is not None:
            self.doc.remove_root(old)
            self.doc.add_root(self.root)

    def attach(self, doc) -> None:
        """Put the app into a Bokeh document."""
        self.doc = doc
        doc.title = f"sensorplan view: {self.scene.name}"
        doc.add_root(self.root)


def make_document(doc, scene: Scene, settings: Settings | None = None, **kw: Any) -> ViewerApp:
    """Bokeh ``FunctionHandler`` body: a fresh :class:`ViewerApp` per browser session."""
    app = ViewerApp(scene, settings, **kw)
    app.attach(doc)
    return app


def serve(
    scene: Scene,
    settings: Settings | None = None,
    *,
    port: int = 5006,
    show: bool = True,
    rollout: str | None = None,
    unit: str = "m",
    ready: Any = None,
    root: str | PathLike[str] | None = None,
    token: str | None = None,
) -> None:
    """Serve the viewer on ``http://localhost:<port>/?token=<token>`` until interrupted.

    ``port=0`` picks a free port.  ``token``: the access token every page request must
    carry (default: a random one, see :mod:`.auth`); ``root``: the folder the page's
    saves are confined to (default: the current directory, see :mod:`.files`).
    ``ready(url)`` is called with the full URL (token included) once the server listens.
    """
    from bokeh.application import Application
    from bokeh.application.handlers.function import FunctionHandler
    from bokeh.server.server import Server
    from bokeh.util.token import generate_secret_key

    from .auth import TokenAuth, new_token

    port = port or free_port()
    token = new_token() if token is None else token
    root_dir = Path.cwd().resolve() if root is None else Path(root).resolve()
    if not root_dir.is_dir():
        raise NotADirectoryError(f"--root {root_dir}: not a directory")
    secret_key = generate_secret_key()  # per launch: signs the session ids and JWTs

    def handler(doc):
        make_document(doc, scene, settings, rollout=rollout, unit=unit, root=root_dir)

    server = Server(
        {"/": Application(FunctionHandler(handler))},
        port=port,
        address="127.0.0.1",
        allow_websocket_origin=[f"localhost:{port}", f"127.0.0.1:{port}"],
        auth_provider=TokenAuth(token, secret_key),
        sign_sessions=True,
        secret_key=secret_key,
        generate_session_ids=True,
    )
    server.start()
    url = f"http://localhost:{port}/?token={token}"
    print(
        f"sensorplan view: serving {scene.name!r} at {url} (Ctrl-C to stop); "
        f"the page saves inside {root_dir}",
        flush=True,
    )
    if ready is not None:
        ready(url)
    if show:
        server.io_loop.add_callback(server.show, f"/?token={token}")
    try:
        server.io_loop.start()
    except KeyboardInterrupt:  # pragma: no cover - interactive
        pass
    finally:
        server.stop()


def free_port() -> int:
    """A TCP port on 127.0.0.1 that is free right now."""
    import socket

    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])
