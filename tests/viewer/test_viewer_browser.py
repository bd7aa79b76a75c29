"""The viewer in a real browser: Debian's chromium, headless, no driver.

* the static export is loaded from a file: a screenshot that is not blank and shows the
  region colours, the five region layers in the page's document;
* the live app is served by ``sensorplan view`` in a subprocess on a free port and
  driven over the DevTools protocol (tornado's websocket client, which Bokeh brings):
  the page renders, an obstacle edited in the browser changes the region computed on
  the server, an invalid edit shows the SceneError message;
* access: a page opened without the printed token (or with a wrong one) gets the 403
  page and no app, with the token it gets the app; a save outside the viewer's root
  folder is refused in the page and no file appears, a save inside it is written.

Skipped when chromium or Bokeh is missing (``.ci/run`` installs both).
"""

from __future__ import annotations

import json
import os
import re
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from tests.browser import CHROMIUM, FLAGS, chromium

pytest.importorskip("bokeh")
pytestmark = pytest.mark.skipif(CHROMIUM is None, reason="needs Debian's chromium")

REPO = Path(__file__).resolve().parents[2]
LAYER_KEYS = ("partial_G", "partial_H", "complete_G", "complete_H", "recognizable")


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _chromium(tmp: Path, *args: str, timeout: float = 60) -> subprocess.CompletedProcess:
    return chromium(tmp, *args, timeout=timeout)


def _png(path: Path) -> np.ndarray:
    import matplotlib.image

    img = matplotlib.image.imread(path)
    return (img[..., :3] * 255).round().astype(np.uint8)


def _has_colour(img: np.ndarray, hex_colour: str, alpha: float, tol: int = 12) -> int:
    """Pixels whose colour is ``hex_colour`` blended over white with ``alpha``."""
    c = np.array([int(hex_colour[i : i + 2], 16) for i in (1, 3, 5)], dtype=float)
    want = alpha * c + (1 - alpha) * 255
    return int((np.abs(img.astype(float) - want).max(axis=2) <= tol).sum())


@pytest.fixture(scope="module")
def export_file(tmp_path_factory):
    from sensorplan_gym.core.world import load_scene
    from sensorplan_gym.viewer.export import export_html

    path = tmp_path_factory.mktemp("export") / "view.html"
    export_html(load_scene("lab"), path)
    return path


def test_export_is_self_contained(export_file):
    text = export_file.read_text(encoding="utf-8")
    # BokehJS inlined, nothing fetched from a CDN or a server
    assert "cdn.bokeh.org" not in text
    assert not re.search(r"<script[^>]*\bsrc=", text, flags=re.I)
    assert not re.search(r"<link[^>]*\bhref=", text, flags=re.I)
    # the document JSON carries the five layers, each with its exact region's vertices
    m = re.search(r'<script type="application/json" id="[^"]+">\s*(.*?)\s*</script>', text, re.S)
    assert m, "no Bokeh document JSON in the page"
    sources: dict[str, dict] = {}

    def walk(o):
        if isinstance(o, dict):
            if o.get("name") == "ColumnDataSource":
                sources[o["attributes"].get("name")] = dict(o["attributes"]["data"]["entries"])
            for v in o.values():
                walk(v)
        elif isinstance(o, list):
            for v in o:
                walk(v)

    walk(json.loads(m.group(1)))
    from geometry import recognizable_region
    from sensorplan_gym.core.world import load_scene

    for key in LAYER_KEYS:
        assert f'"layer:{key}"' in text
        data = sources[f"src:{key}"]
        assert len(data["xs"]) == 1 and len(data["xs"][0]) >= 1  # one row of polygons
    area = sources["src:recognizable"]["area"][0]
    assert area == pytest.approx(recognizable_region(load_scene("lab")).area, rel=1e-12)
    ring = np.column_stack(
        [sources["src:recognizable"]["xs"][0][0][0], sources["src:recognizable"]["ys"][0][0][0]]
    )
    assert ring.shape[0] >= 3


def test_export_renders_in_chromium(export_file, tmp_path):
    shot = tmp_path / "export.png"
    r = _chromium(
        tmp_path,
        "--window-size=1300,900",
        "--virtual-time-budget=10000",
        f"--screenshot={shot}",
        export_file.as_uri(),
    )
    assert shot.exists(), r.stderr[-2000:]
    img = _png(shot)
    # not blank: many colours, and the regions drawn in their colours
    assert len(np.unique(img.reshape(-1, 3), axis=0)) > 200
    assert _has_colour(img, "#454545", 1.0, tol=6) > 5000  # obstacles
    # the recognizable region lies over the other layers: look for its green hue
    g = img.astype(int)
    green = (g[..., 1] - np.maximum(g[..., 0], g[..., 2]) > 40).sum()
    assert green > 5000, green
    # the DOM: the Bokeh root element and the layer checkboxes were rendered by BokehJS
    dom = _chromium(tmp_path, "--virtual-time-budget=10000", "--dump-dom", export_file.as_uri())
    assert "data-root-id" in dom.stdout


# ---- the served app, over the DevTools protocol ------------------------------------------


class _CDP:
    """A minimal DevTools-protocol client over tornado's websocket."""

    def __init__(self, ws_url: str) -> None:
        from tornado.ioloop import IOLoop
        from tornado.websocket import websocket_connect

        self.loop = IOLoop()
        self.ws = self.loop.run_sync(lambda: websocket_connect(ws_url), timeout=20)
        self.n = 0

    def call(self, method: str, timeout: float = 30, **params):
        self.n += 1
        mid = self.n

        async def go():
            await self.ws.write_message(json.dumps({"id": mid, "method": method, "params": params}))
            while True:
                msg = await self.ws.read_message()
                if msg is None:
                    raise RuntimeError("devtools connection closed")
                d = json.loads(msg)
                if d.get("id") == mid:
                    return d

        d = self.loop.run_sync(go, timeout=timeout)
        if "error" in d:
            raise RuntimeError(f"{method}: {d['error']}")
        return d["result"]

    def js(self, expr: str):
        r = self.call("Runtime.evaluate", expression=expr, returnByValue=True, awaitPromise=True)
        if "exceptionDetails" in r:
            raise RuntimeError(f"JS error in {expr[:80]}: {r['exceptionDetails']}")
        return r["result"].get("value")

    def wait_js(self, expr: str, timeout: float = 30):
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            v = self.js(expr)
            if v:
                return v
            time.sleep(0.2)
        raise TimeoutError(f"timed out waiting for {expr}")

    def close(self) -> None:
        self.ws.close()
        self.loop.close()


def _wait_port(port: int, proc: subprocess.Popen, timeout: float = 60) -> None:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if proc.poll() is not None:
            raise RuntimeError(f"process exited: {proc.stdout.read() if proc.stdout else ''}")
        with socket.socket() as s:
            if s.connect_ex(("127.0.0.1", port)) == 0:
                return
        time.sleep(0.2)
    raise TimeoutError(f"nothing listens on port {port}")


@pytest.fixture
def browser(tmp_path):
    """A headless chromium with its DevTools client; stopped after the test."""
    dbg_port = _free_port()
    proc = subprocess.Popen(
        [CHROMIUM, *FLAGS, f"--user-data-dir={tmp_path / 'profile'}",
         f"--remote-debugging-port={dbg_port}", "--window-size=1300,900", "about:blank"],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )  # fmt: skip
    try:
        _wait_port(dbg_port, proc)
        from urllib.request import urlopen

        end = time.monotonic() + 20
        page = None
        while page is None and time.monotonic() < end:
            targets = json.loads(urlopen(f"http://127.0.0.1:{dbg_port}/json/list").read())
            page = next((t for t in targets if t.get("type") == "page"), None)
            time.sleep(0.1)
        assert page is not None, "no page target in chromium"
        cdp = _CDP(page["webSocketDebuggerUrl"])
        try:
            yield cdp
        finally:
            cdp.close()
    finally:
        _stop(proc)


def _stop(proc: subprocess.Popen) -> None:
    proc.terminate()
    try:
        proc.wait(timeout=10)
    except subprocess.TimeoutExpired:
        proc.kill()


@pytest.fixture
def served(tmp_path, browser):
    """(app url with its token, devtools client) with ``sensorplan view lab --root
    <tmp>/root`` served on a free port (started in ``tmp_path``); the URL is the one the
    command printed."""
    app_port = _free_port()
    env = dict(os.environ, PYTHONPATH=str(REPO), MPLBACKEND="Agg")
    env.pop("SENSORPLAN_VIEW_TOKEN", None)
    (tmp_path / "root").mkdir()
    app = subprocess.Popen(
        [sys.executable, "-m", "sensorplan_gym.viewer.cli", "lab", "--port", str(app_port),
         "--no-browser", "--root", "root"],
        cwd=tmp_path, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
    )  # fmt: skip
    try:
        url = None
        for line in app.stdout:  # the command prints its URL once it listens
            m = re.search(r"at (http://localhost:\d+/\?token=[0-9a-f]{48}) ", line)
            if m:
                url = m.group(1).replace("localhost", "127.0.0.1")
                break
        assert url is not None, f"no URL printed; exit code {app.poll()}"
        assert str((tmp_path / "root").resolve()) in line  # says where the page saves
        _wait_port(app_port, app)
        yield url, browser
    finally:
        _stop(app)


DOC = "Bokeh.documents[0]"
#: JS: copies of the obstacle columns of source ``s`` as plain arrays
COPY_XY = (
    "const xs = s.data.xs.map(a => Array.from(a)); const ys = s.data.ys.map(a => Array.from(a));"
)


def _model(name: str) -> str:
    return f"{DOC}.get_model_by_name({json.dumps(name)})"


#: JS: page pixel (CSS px) of a world point (x, y) in the scene figure
PIXEL = """(x, y) => { const fig = Bokeh.documents[0].get_model_by_name('scene_figure');
let found = null;
const walk = (v) => {
  if (v.model === fig) found = v;
  for (const c of (v.child_views || [])) walk(c) };
for (const r of Bokeh.index.roots) walk(r);
const f = found.frame; const el = found.el.getBoundingClientRect();
return [el.left + f.x_scale.compute(x), el.top + f.y_scale.compute(y)] }"""


def _pixel(cdp: _CDP, x: float, y: float) -> tuple[float, float]:
    px, py = cdp.js(f"({PIXEL})({x}, {y})")
    return float(px), float(py)


def test_served_app_edit_in_chromium(served, tmp_path):
    url, cdp = served
    cdp.call("Page.enable")
    cdp.call("Page.navigate", url=url)
    cdp.wait_js(f"window.Bokeh !== undefined && Bokeh.documents.length > 0 && !!{_model('status')}")
    timing = cdp.wait_js(
        f"(() => {{ const t = {_model('status')}.text; return t.includes('Exact') ? t : null }})()"
    )
    assert "ms" in timing
    # the page has been drawn: a screenshot that is not blank, obstacles and regions visible
    time.sleep(1.0)
    import base64

    shot = tmp_path / "app.png"
    shot.write_bytes(base64.b64decode(cdp.call("Page.captureScreenshot", format="png")["data"]))
    img = _png(shot)
    assert len(np.unique(img.reshape(-1, 3), axis=0)) > 200
    assert _has_colour(img, "#454545", 1.0, tol=6) > 3000
    # the recognizable region the server computed
    area_js = (
        f"(() => {{ const d = {_model('src:recognizable')}.data; "
        "return d.area.length ? d.area[0] : null })()"
    )
    a0 = cdp.wait_js(area_js)
    assert a0 == pytest.approx(16.381, abs=1e-3)  # lab, complete, translating
    # hovering the plot probes the placement under the cursor on the server
    for x, y in ((300, 330), (306, 334)):
        cdp.call("Input.dispatchMouseEvent", type="mouseMoved", x=x, y=y)
        time.sleep(0.3)
    info = cdp.wait_js(
        f"(() => {{ const t = {_model('probe')}.text; return t.includes('placement (') ? t "
        ": null })()"
    )
    assert "sees A in G" in info and "sees A in H" in info and "query" in info
    assert cdp.js(f"{_model('src:vis')}.data.xs.length") == 1  # its visibility polygon
    # edit with the mouse: the edit-vertices tool, press and hold obstacle 2
    # (3.6..5.6 x 2.4..3.2) until its vertices show, drag its corner (5.6, 2.4) one metre right
    cdp.js(
        f"{_model('scene_figure')}.toolbar.tools.find(t => t.type == 'PolyEditTool')"
        ".active = true; true"
    )
    cx, cy = _pixel(cdp, 4.6, 2.8)
    cdp.call("Input.dispatchMouseEvent", type="mouseMoved", x=cx, y=cy)
    cdp.call("Input.dispatchMouseEvent", type="mousePressed", x=cx, y=cy, button="left",
             clickCount=1)  # fmt: skip
    time.sleep(0.7)  # a press is a hold of > 300 ms
    cdp.call("Input.dispatchMouseEvent", type="mouseReleased", x=cx, y=cy, button="left",
             clickCount=1)  # fmt: skip
    cdp.wait_js(f"{_model('edit:vertices')}.data_source.data.x.length == 4")
    vx, vy = _pixel(cdp, 5.6, 2.4)
    tx, _ = _pixel(cdp, 6.6, 2.4)
    cdp.call("Input.dispatchMouseEvent", type="mouseMoved", x=vx, y=vy)
    cdp.call("Input.dispatchMouseEvent", type="mousePressed", x=vx, y=vy, button="left",
             clickCount=1)  # fmt: skip
    for i in range(1, 11):
        cdp.call("Input.dispatchMouseEvent", type="mouseMoved", x=vx + (tx - vx) * i / 10, y=vy,
                 button="left", buttons=1)  # fmt: skip
        time.sleep(0.03)
    cdp.call("Input.dispatchMouseEvent", type="mouseReleased", x=tx, y=vy, button="left",
             clickCount=1)  # fmt: skip
    a1 = cdp.wait_js(
        f"(() => {{ const a = {area_js}; return (a !== null && Math.abs(a - {a0}) > 1e-6) ? a "
        ": null })()"
    )
    xs = cdp.js(f"Array.from({_model('src:obstacles')}.data.xs[2])")
    ys = cdp.js(f"Array.from({_model('src:obstacles')}.data.ys[2])")
    assert xs[1] == pytest.approx(6.6, abs=0.05) and ys[1] == pytest.approx(2.4, abs=0.05)
    from geometry import recognizable_region
    from sensorplan_gym.core.world import load_scene

    scene = load_scene("lab")
    d = scene.to_dict()
    d["obstacles"][2] = [[x, y] for x, y in zip(xs, ys, strict=True)]
    moved = scene.from_dict(d)
    # the server's region is the exact region of the scene as edited in the browser
    assert a1 == pytest.approx(recognizable_region(moved).area, rel=1e-9)
    # an invalid edit: an obstacle over G is reported, not applied, and nothing crashes
    cdp.js(
        f"(() => {{ const s = {_model('src:obstacles')}; "
        f"{COPY_XY}"
        "xs.push([6.1, 6.7, 6.7, 6.1]); ys.push([8.2, 8.2, 8.8, 8.8]); s.data = {xs: xs, ys: ys};"
        "return true })()"
    )
    err = cdp.wait_js(
        f"(() => {{ const t = {_model('status')}.text; return t.includes('Invalid scene') ? t "
        ": null })()"
    )
    assert "goal" in err and "obstacles[9]" in err
    assert cdp.js(area_js) == pytest.approx(a1)  # the last valid region stays
    # switching the model recomputes on the server
    cdp.js(f"{_model('model')}.value = 'partial'; true")
    cdp.js(
        f"(() => {{ const s = {_model('src:obstacles')}; "
        "s.data = {xs: s.data.xs.slice(0, 9).map(a => Array.from(a)), "
        "ys: s.data.ys.slice(0, 9).map(a => Array.from(a))}; return true })()"
    )
    a2 = cdp.wait_js(
        f"(() => {{ const a = {area_js}; return (a !== null && Math.abs(a - {a1}) > 1e-6) ? a "
        ": null })()",
        timeout=60,
    )
    assert a2 == pytest.approx(recognizable_region(moved, model="partial").area, rel=1e-9)


def test_replay_tab_in_exported_file(browser, tmp_path):
    from agents import OraclePolicy
    from sensorplan_gym.core.world import load_scene
    from sensorplan_gym.viewer.export import export_html
    from sensorplan_gym.viewer.replay import record_rollout

    ro = record_rollout(
        "sensorplan/Recognize-v0", policy=OraclePolicy, policy_name="oracle", seed=1, scene="lab"
    )
    path = export_html(load_scene("lab"), tmp_path / "view.html", rollout=ro)
    cdp = browser
    cdp.call("Page.navigate", url=path.as_uri())
    cdp.wait_js(f"window.Bokeh !== undefined && Bokeh.documents.length > 0 && !!{_model('tabs')}")
    cdp.js(f"{_model('tabs')}.active = 1; true")
    k = len(ro["steps"]) // 2
    cdp.js(f"{_model('replay_step')}.value = {k}; true")
    caption = cdp.wait_js(
        f"(() => {{ const t = {_model('replay_caption')}.text; "
        f"return t.includes('step {k} of') ? t : null }})()"
    )
    assert f"of {len(ro['steps']) - 1}" in caption
    x = cdp.js(f"{_model('src:replay_robot')}.data.x[0]")
    assert x == pytest.approx(ro["steps"][k]["pose"][0])
    n_beams = cdp.js(f"{_model('src:replay_beams')}.data.x1.length")
    assert n_beams == len(ro["steps"][k]["beams"][0]) > 0


# ---- access: the token and the confined saves ---------------------------------------------

#: JS: the BokehJS view of the model named ``name`` (walks the views of every root)
VIEW_OF = """(name) => { const m = Bokeh.documents[0].get_model_by_name(name); let found = null;
const walk = (v) => {
  if (v.model === m) found = v;
  for (const c of (v.child_views || [])) walk(c) };
for (const r of Bokeh.index.roots) walk(r); return found }"""


def _page_state(cdp: _CDP) -> dict:
    """Wait for the page to load; what it shows: BokehJS documents, the 403 marker."""
    cdp.wait_js("document.readyState === 'complete'")
    time.sleep(1.0)  # a served app would have opened its websocket and built its document
    return cdp.js(
        "({bokeh: window.Bokeh !== undefined ? Bokeh.documents.length : -1, "
        "forbidden: !!document.getElementById('token-required'), "
        "text: document.body ? document.body.innerText : ''})"
    )


def test_served_app_needs_its_token(served):
    url, cdp = served
    base, token = url.split("?token=")
    cdp.call("Page.enable")
    wrong = token[:-1] + ("1" if token[-1] == "0" else "0")
    for bad in (base, f"{base}?token={wrong}", f"{base}?token=", f"{base}?bokeh-session-id=x"):
        cdp.call("Page.navigate", url=bad)
        st = _page_state(cdp)
        assert st["forbidden"] and st["bokeh"] == -1, (bad, st)  # no BokehJS, no session
        assert "needs its access token" in st["text"] and "?token=" in st["text"]
    cdp.call("Page.navigate", url=url)
    cdp.wait_js(f"window.Bokeh !== undefined && Bokeh.documents.length > 0 && !!{_model('tabs')}")
    cdp.wait_js(f"{_model('status')}.text.includes('Exact')")  # the server computed the regions


def _save_in_page(cdp: _CDP, path: str) -> str:
    """Type ``path`` into the save box, press "Save scene"; the file message shown."""
    cdp.js(f"{_model('file_status')}.text = ''; true")
    cdp.js(f"{_model('save_path')}.value = {json.dumps(path)}; true")
    cdp.js(f"(({VIEW_OF})('save')).button_el.click(); true")
    return cdp.wait_js(
        f"(() => {{ const t = {_model('file_status')}.text; return t.length ? t : null }})()"
    )


def test_served_app_saves_only_inside_its_root(served, tmp_path):
    url, cdp = served
    root = tmp_path / "root"
    (root / "link").symlink_to(tmp_path, target_is_directory=True)
    cdp.call("Page.enable")
    cdp.call("Page.navigate", url=url)
    cdp.wait_js(f"window.Bokeh !== undefined && Bokeh.documents.length > 0 && !!{_model('save')}")
    before = sorted(p.name for p in tmp_path.iterdir())
    for outside in ("../outside.json", str(tmp_path / "outside.json"), "link/outside.json"):
        msg = _save_in_page(cdp, outside)
        assert "save-refused" in msg and "outside the viewer" in msg, msg
        assert str(root.resolve()) in msg
        # the message is drawn on the page for the user to read
        shown = cdp.wait_js(
            f"(() => {{ const v = ({VIEW_OF})('file_status'); const t = (v.shadow_el || v.el)"
            ".textContent; return t.includes('Not saved') ? t : null })()"
        )
        assert "outside the viewer's folder" in shown
    assert not (tmp_path / "outside.json").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == before  # no file appeared
    msg = _save_in_page(cdp, "notes.txt")
    assert "save-refused" in msg and "scene files only" in msg
    assert sorted(p.name for p in root.iterdir()) == ["link"]
    # inside the root: written, relative to the root
    msg = _save_in_page(cdp, "edited.geojson")
    assert "id='saved'" in msg, msg
    from sensorplan_gym.core.world import load_scene

    saved, lab = load_scene(root / "edited.geojson"), load_scene("lab")
    assert saved.name == "lab" and len(saved.obstacles) == len(lab.obstacles)
    for got, want in zip(saved.obstacles, lab.obstacles, strict=True):
        assert np.allclose(got, want, atol=1e-9)
    assert np.allclose(saved.target, lab.target, atol=1e-9)
