"""The documentation site in a real browser: built with ``mkdocs build --strict`` into a
temporary folder, served on 127.0.0.1 by a bounded ``http.server`` thread and loaded in
Debian's headless chromium (:mod:`tests.browser`).

Checks that the home page renders (title, navigation), that the navigation's link to an
environment page leads to a rendered page, and that the environment page's figure is fetched by
the browser (the server saw the GIF requested and served it). Skipped when mkdocs (``docs``
extra) or chromium is missing.
"""

from __future__ import annotations

import functools
import http.server
import re
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from tests.browser import CHROMIUM, chromium

pytest.importorskip("mkdocs")
pytest.importorskip("material")
pytest.importorskip("mkdocstrings")
pytestmark = pytest.mark.skipif(CHROMIUM is None, reason="needs Debian's chromium")

ROOT = Path(__file__).resolve().parents[1]


class _Handler(http.server.SimpleHTTPRequestHandler):
    served: list[tuple[str, int]] = []

    def log_request(self, code="-", size="-"):  # record instead of printing
        type(self).served.append((self.path, int(code) if str(code).isdigit() else 0))


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    out = tmp_path_factory.mktemp("site")
    r = subprocess.run(
        [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(out)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert r.returncode == 0, f"mkdocs build --strict failed:\n{r.stderr[-3000:]}"
    handler = type("H", (_Handler,), {"served": []})
    srv = http.server.ThreadingHTTPServer(
        ("127.0.0.1", 0), functools.partial(handler, directory=str(out))
    )
    srv.timeout = 1
    t = threading.Thread(target=srv.serve_forever, kwargs={"poll_interval": 0.2}, daemon=True)
    t.start()
    try:
        yield f"http://127.0.0.1:{srv.server_address[1]}/", handler, out
    finally:
        srv.shutdown()
        srv.server_close()
        t.join(timeout=10)


def _dom(tmp: Path, url: str) -> str:
    r = chromium(tmp, "--virtual-time-budget=5000", "--dump-dom", url, timeout=90)
    assert r.returncode == 0, r.stderr[-2000:]
    return r.stdout


def test_home_renders_with_navigation(site, tmp_path):
    base, _, _ = site
    dom = _dom(tmp_path, base)
    assert re.search(r"<title>\s*sensorplan-gym", dom)
    assert "md-nav" in dom  # Material's navigation was rendered
    for label in ("Getting started", "Concepts", "Geometry API", "Reference results", "Design"):
        assert label in dom, f"navigation lacks {label!r}"


def test_navigation_leads_to_an_environment_page_with_its_figure(site, tmp_path):
    base, handler, out = site
    home = _dom(tmp_path, base)
    m = re.search(r'href="([^"]*environments/navigate/)"[^>]*>\s*(?:<[^>]+>\s*)*Navigate-v0', home)
    assert m, "no navigation link to Navigate-v0 on the home page"
    url = base + m.group(1).removeprefix("./").lstrip("/")
    handler.served.clear()
    page = _dom(tmp_path, url)
    assert re.search(r"<h1[^>]*>\s*Navigate-v0", page)
    assert "Action space" in page and "Version history" in page
    img = re.search(r'<img[^>]+src="([^"]*navigate\.gif)"', page)
    assert img, "the environment page shows no figure"
    gif = [(p, c) for p, c in handler.served if p.endswith("/assets/navigate.gif")]
    assert gif and all(c == 200 for _, c in gif), f"the figure was not loaded: {handler.served}"
    assert (out / "assets" / "navigate.gif").stat().st_size > 1000


def test_api_page_renders_the_docstrings(site, tmp_path):
    base, _, _ = site
    page = _dom(tmp_path, base + "geometry-api/")
    for name in ("complete_region", "partial_region", "recognizable_region", "Scene"):
        assert f'id="geometry.{name}"' in page, f"no API entry for geometry.{name}"


def test_environment_figure_is_painted(site, tmp_path):
    """A screenshot of the environment page shows the figure: the renderer's grey frame
    (RGB 153, 153, 153) covers a large patch of the page, which without the image is white."""
    import numpy as np
    from PIL import Image

    base, _, _ = site
    shot = tmp_path / "navigate.png"
    r = chromium(
        tmp_path,
        "--window-size=1280,1000",
        "--virtual-time-budget=5000",
        f"--screenshot={shot}",
        base + "environments/navigate/",
        timeout=90,
    )
    assert r.returncode == 0 and shot.is_file(), r.stderr[-2000:]
    img = np.asarray(Image.open(shot).convert("RGB")).astype(int)
    grey = (np.abs(img - 153).max(axis=2) <= 6).sum()
    assert grey > 20_000, f"the figure is not painted ({grey} grey pixels)"
