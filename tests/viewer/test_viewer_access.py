"""The live viewer's access rules without a browser: the path confinement of its saves
(:mod:`sensorplan_gym.viewer.files`), its token (:mod:`sensorplan_gym.viewer.auth`), and
the served app's HTTP and websocket answers to requests without the token.
(test_viewer_browser.py checks both in chromium.)"""

from __future__ import annotations

import os
import re
import socket
import subprocess
import sys
import time
from pathlib import Path
from urllib.error import HTTPError
from urllib.request import HTTPRedirectHandler, Request, build_opener

import pytest

from geometry.formats import load_scene_file
from sensorplan_gym.core.world import load_scene
from sensorplan_gym.viewer.files import OutsideRootError, confine, save_scene_confined

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture
def tree(tmp_path):
    """tmp/root (the root) with a sub folder, symlinks out of it and within it."""
    root = tmp_path / "root"
    (root / "sub").mkdir(parents=True)
    (root / "out_dir").symlink_to(tmp_path, target_is_directory=True)
    (root / "out_file.json").symlink_to(tmp_path / "victim.json")
    (root / "in_dir").symlink_to(root / "sub", target_is_directory=True)
    return root


# ---- confine ------------------------------------------------------------------------------


def test_confine_inside(tree):
    r = tree.resolve()
    assert confine("a.json", tree) == r / "a.json"  # relative to the root, not the cwd
    assert confine("sub/a.json", tree) == r / "sub" / "a.json"
    assert confine("sub/../a.json", tree) == r / "a.json"
    assert confine(str(r / "sub" / "a.json"), tree) == r / "sub" / "a.json"  # absolute inside
    assert confine("in_dir/a.json", tree) == r / "sub" / "a.json"  # a symlink that stays in
    assert confine(".", tree) == r
    assert confine(Path("sub") / "new" / "a.json", tree) == r / "sub" / "new" / "a.json"


@pytest.mark.parametrize(
    "path",
    ["../a.json", "sub/../../a.json", "/etc/passwd", "out_dir/a.json", "out_file.json",
     "out_dir/root/../a.json", "sub/nothere/../../../a.json", "//tmp/a.json"],
)  # fmt: skip
def test_confine_refuses_outside(tree, path):
    with pytest.raises(OutsideRootError, match="outside the viewer's folder") as e:
        confine(path, tree)
    msg = str(e.value)
    assert repr(path) in msg and str(tree.resolve()) in msg  # names the path and the root
    assert "--root" in msg  # and how to save elsewhere
    assert isinstance(e.value, ValueError)


def test_confine_root_itself_a_symlink(tmp_path):
    real = tmp_path / "real"
    real.mkdir()
    (tmp_path / "alias").symlink_to(real, target_is_directory=True)
    assert confine("a.json", tmp_path / "alias") == real.resolve() / "a.json"
    assert confine(str(tmp_path / "alias" / "a.json"), tmp_path / "alias") == real / "a.json"
    with pytest.raises(OutsideRootError):
        confine(str(tmp_path / "a.json"), tmp_path / "alias")


@pytest.mark.parametrize(
    ("path", "match"),
    [("", "no file name"), ("   ", "no file name"), ("~/a.json", "not expanded"),
     ("a\x00.json", "NUL")],
)  # fmt: skip
def test_confine_bad_names(tree, path, match):
    with pytest.raises(ValueError, match=match):
        confine(path, tree)


def test_confine_root_must_be_a_directory(tmp_path):
    f = tmp_path / "f"
    f.write_text("")
    with pytest.raises(NotADirectoryError, match="not a directory"):
        confine("a.json", f)
    with pytest.raises(NotADirectoryError):
        confine("a.json", tmp_path / "missing")


# ---- save_scene_confined ------------------------------------------------------------------


def test_save_confined_formats(tree):
    lab = load_scene("lab")
    for name in ("a.json", "sub/a.geojson", "in_dir/a.wkt"):
        out = save_scene_confined(lab, name, tree)
        assert out.is_file() and tree.resolve() in out.parents
        back = load_scene_file(out)
        if name.endswith(".wkt"):  # WKT writes the numbers as text: compare to a tolerance
            assert back.name == lab.name and len(back.obstacles) == len(lab.obstacles)
        else:
            assert back == lab
    assert (tree / "sub" / "a.wkt").is_file()  # written through the inside symlink


def test_save_confined_refusals_write_nothing(tree, tmp_path):
    lab = load_scene("lab")
    before = sorted(p.name for p in tmp_path.iterdir())
    for name in (
        "../victim.json",
        "out_dir/victim.json",
        "out_file.json",
        str(tmp_path / "x.json"),
    ):
        with pytest.raises(OutsideRootError):
            save_scene_confined(lab, name, tree)
    for name in ("notes.txt", "a.py", "sub", "a"):
        with pytest.raises(ValueError, match="scene files only"):
            save_scene_confined(lab, name, tree)
    (tree / "dir.json").mkdir()
    with pytest.raises(IsADirectoryError):
        save_scene_confined(lab, "dir.json", tree)
    with pytest.raises(FileNotFoundError):
        save_scene_confined(lab, "nothere/a.json", tree)
    assert sorted(p.name for p in tmp_path.iterdir()) == before
    assert not (tmp_path / "victim.json").exists()


def test_save_confined_does_not_follow_a_late_symlink(tree, tmp_path, monkeypatch):
    """A symlink swapped in after the check is refused by O_NOFOLLOW, not followed."""
    from sensorplan_gym.viewer import files

    real_confine = files.confine

    def racing_confine(path, root):
        out = real_confine(path, root)
        out.symlink_to(tmp_path / "victim.json")  # the race: the name becomes a symlink
        return out

    monkeypatch.setattr(files, "confine", racing_confine)
    with pytest.raises(OSError):
        files.save_scene_confined(load_scene("lab"), "race.json", tree)
    assert not (tmp_path / "victim.json").exists()


# ---- the token ----------------------------------------------------------------------------


def test_token_helpers(monkeypatch):
    pytest.importorskip("bokeh")
    from sensorplan_gym.viewer.auth import TOKEN_ENV, new_token, token_from, validate_token

    t = new_token()
    assert re.fullmatch(r"[0-9a-f]{48}", t) and t != new_token()
    monkeypatch.delenv(TOKEN_ENV, raising=False)
    assert re.fullmatch(r"[0-9a-f]{48}", token_from(None))
    monkeypatch.setenv(TOKEN_ENV, "from-the-environment-1")
    assert token_from(None) == "from-the-environment-1"
    assert token_from("from-the-command-line") == "from-the-command-line"  # --token wins
    for bad in ("short", "has space in it 12345", "slash/in/the/token/1234", "ünïcödé-token-123"):
        with pytest.raises(ValueError, match="at least 16 characters"):
            validate_token(bad)


def test_websocket_check_needs_a_signed_jwt_with_the_token():
    pytest.importorskip("bokeh")
    from bokeh.util.token import generate_jwt_token, generate_secret_key, generate_session_id

    from sensorplan_gym.viewer.auth import TokenAuth

    key, token = generate_secret_key(), "t" * 20
    auth = TokenAuth(token, key)

    def jwt(arguments, secret=key, signed=True):
        sid = generate_session_id(secret_key=secret, signed=signed)
        payload = {"headers": {}, "cookies": {}, "arguments": arguments}
        return generate_jwt_token(sid, secret_key=secret, signed=signed, extra_payload=payload)

    good = jwt({"token": [token.encode()]})
    assert auth.websocket_ok(f"bokeh, {good}")
    assert not auth.websocket_ok(f"bokeh, {jwt({})}")  # a page request without the token
    assert not auth.websocket_ok(f"bokeh, {jwt({'token': [b'x' * 20]})}")
    assert not auth.websocket_ok(f"bokeh, {jwt({'token': [token.encode()]}, signed=False)}")
    other = generate_secret_key()  # signed, with the token, by another server
    assert not auth.websocket_ok(f"bokeh, {jwt({'token': [token.encode()]}, secret=other)}")
    assert not auth.websocket_ok("bokeh, not-a-jwt")
    assert not auth.websocket_ok("bokeh, e30.e30")
    assert not auth.websocket_ok(good)  # no "bokeh" subprotocol
    assert not auth.websocket_ok("")


# ---- the served app -----------------------------------------------------------------------


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    """(base url, token) of ``sensorplan view corridor`` with a token from the environment."""
    pytest.importorskip("bokeh")
    tmp = tmp_path_factory.mktemp("served")
    port, token = _free_port(), "test-token-0123456789abcdef"
    env = dict(os.environ, PYTHONPATH=str(REPO), MPLBACKEND="Agg", SENSORPLAN_VIEW_TOKEN=token)
    proc = subprocess.Popen(
        [sys.executable, "-m", "sensorplan_gym.viewer.cli", "corridor", "--port", str(port),
         "--no-browser"],
        cwd=tmp, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
    )  # fmt: skip
    try:
        line = ""
        for line in proc.stdout:
            if "serving" in line:
                break
        assert f"http://localhost:{port}/?token={token} " in line, line
        yield f"http://127.0.0.1:{port}", token
    finally:
        proc.terminate()
        try:
            proc.wait(timeout=10)
        except subprocess.TimeoutExpired:
            proc.kill()


class _NoRedirect(HTTPRedirectHandler):
    def redirect_request(self, *args, **kwargs):
        return None


def _get(url: str, follow: bool = True) -> tuple[int, str, dict]:
    opener = build_opener() if follow else build_opener(_NoRedirect)
    for _ in range(50):
        try:
            with opener.open(Request(url), timeout=30) as r:
                return r.status, r.read().decode("utf-8", "replace"), dict(r.headers)
        except HTTPError as e:
            return e.code, e.read().decode("utf-8", "replace"), dict(e.headers)
        except (ConnectionError, OSError):
            time.sleep(0.2)
    raise TimeoutError(url)


def test_served_pages_need_the_token(server):
    base, token = server
    status, body, _ = _get(f"{base}/")
    assert status == 403 and "needs its access token" in body and "bokeh" not in body.lower()
    status, _, headers = _get(f"{base}/?token=wrong-{token}", follow=False)
    assert status == 302 and headers["Location"].startswith("/forbidden")
    for path in ("/?token=", f"/?token={token}&token={token}", f"/?TOKEN={token}",
                 "/autoload.js?bokeh-autoload-element=x", "/metadata", "/ws"):  # fmt: skip
        status, body, _ = _get(base + path)
        assert status == 403, (path, status)
    status, body, _ = _get(f"{base}/?token={token}")
    assert status == 200 and "sensorplan view: corridor" in body
    status, _, _ = _get(f"{base}/static/js/bokeh.min.js")  # public code needs no token
    assert status == 200


def _ws(base: str, subprotocols: list[str]):
    """Open the app's websocket with these subprotocols; the first message, or the error."""
    from tornado.httpclient import HTTPRequest
    from tornado.ioloop import IOLoop
    from tornado.websocket import websocket_connect

    url = base.replace("http://", "ws://") + "/ws"
    loop = IOLoop()
    try:

        async def go():
            conn = await websocket_connect(
                HTTPRequest(url, headers={"Origin": base}), subprotocols=subprotocols
            )
            msg = await conn.read_message()
            conn.close()
            return msg

        return loop.run_sync(go, timeout=30)
    except Exception as e:  # the handshake refused, or the connection closed
        return e
    finally:
        loop.close()


def test_served_websocket_needs_a_session_the_server_signed(server):
    from bokeh.util.token import generate_jwt_token, generate_session_id

    base, token = server
    # a forged session: unsigned, claiming the page request had the token
    sid = generate_session_id(signed=False)
    payload = {"headers": {}, "cookies": {}, "arguments": {"token": [token.encode()]}}
    forged = generate_jwt_token(sid, signed=False, extra_payload=payload)
    r = _ws(base, ["bokeh", forged])
    assert isinstance(r, Exception) and "403" in str(r), r
    r = _ws(base, ["bokeh", "garbage"])
    assert isinstance(r, Exception) and "403" in str(r), r
    # the JWT the server embedded in the page it served with the token opens a session
    status, body, _ = _get(f"{base}/?token={token}")
    m = re.search(r'"token":\s*"([^"]+)"', body) or re.search(r"token\W+([\w.-]{40,})", body)
    assert m, body[:2000]
    r = _ws(base, ["bokeh", m.group(1)])
    assert isinstance(r, (str, bytes)) and "ACK" in (r if isinstance(r, str) else r.decode()), r
