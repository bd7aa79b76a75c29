"""The viewer's computations and its app logic without a browser (test_viewer_browser.py
drives chromium)."""

from __future__ import annotations

import base64
import json
import math

import numpy as np
import pytest
import shapely

from geometry import complete_region, partial_region, recognizable_region
from sensorplan_gym.core.world import load_scene
from sensorplan_gym.viewer.layers import (
    LAYERS,
    Settings,
    compute_layers,
    effective_scene,
    geom_to_multipolygon,
    probe,
)


@pytest.fixture(scope="module")
def lab():
    return load_scene("lab")


def test_settings_validation(lab):
    with pytest.raises(ValueError, match="model"):
        Settings(model="half")
    with pytest.raises(ValueError, match="motion"):
        Settings(motion="flying")
    with pytest.raises(ValueError, match="eps_pos"):
        Settings(eps_pos=-1)
    with pytest.raises(ValueError, match="fov"):
        Settings(fov=7.0)
    with pytest.raises(ValueError, match="eps_aim"):
        Settings(eps_aim=float("nan"))
    s = Settings.from_scene(load_scene("edr"))
    assert s.fov == pytest.approx(math.radians(150))


def test_layers_are_the_exact_regions(lab):
    s = Settings(eps_pos=0.05)
    lay = compute_layers(lab, s, ("complete_G", "complete_H", "recognizable"))
    assert set(lay.geoms) == {"complete_G", "complete_H", "recognizable"}
    ref = complete_region(lab, target_in="goal", theta=0.0, eps_pos=0.05)
    assert shapely.equals_exact(lay.geoms["complete_G"], ref, tolerance=0)
    ref = recognizable_region(lab, eps_pos=0.05)
    assert lay.geoms["recognizable"].symmetric_difference(ref).area == 0
    assert all(ms >= 0 for ms in lay.ms.values())


def test_stationary_and_rotating(lab):
    st = compute_layers(lab, Settings(model="partial", motion="stationary"), LAYERS)
    eff = st.effective
    assert eff.goal_geom.geom_type == "Point" and eff.failure_geom.geom_type == "Point"
    c = lab.goal_geom.centroid
    ref = partial_region(lab, target_at=(c.x, c.y, 0.0))
    assert st.geoms["partial_G"].symmetric_difference(ref).area < 1e-9
    # rotating + partial is not supported by the geometry: reported, not raised
    rot = compute_layers(lab, Settings(model="partial", motion="rotating"), LAYERS)
    assert "recognizable" in rot.errors and "partial_G" in rot.errors
    assert "complete_G" in rot.geoms
    assert effective_scene(lab, Settings()) is lab


def test_unknown_layer(lab):
    with pytest.raises(ValueError, match="unknown layer"):
        compute_layers(lab, Settings(), ("everything",))


def test_multipolygon_coordinates_keep_holes():
    outer = shapely.box(0, 0, 4, 4)
    g = shapely.MultiPolygon([outer.difference(shapely.box(1, 1, 2, 2)), shapely.box(5, 5, 6, 6)])
    xs, ys = geom_to_multipolygon(g)
    assert len(xs) == 2 and len(xs[0]) == 2 and len(xs[1]) == 1  # exterior + hole; one ring
    assert len(xs[0][0]) == 4 and len(ys[0][1]) == 4  # rings are open
    assert geom_to_multipolygon(shapely.Polygon()) == ([], [])


def test_probe_matches_regions(lab):
    lay = compute_layers(lab, Settings(), LAYERS[2:])
    rng = np.random.default_rng(0)
    lo, hi = lab.bounds.min(axis=0), lab.bounds.max(axis=0)
    seen = set()
    for x, y in rng.uniform(lo, hi, size=(60, 2)):
        r = probe(lay, x, y)
        free = bool(lab.free_space.contains(shapely.Point(x, y)))
        assert r["free"] == free
        if not free:
            assert r["vis"].is_empty
            continue
        assert r["vis"].contains(shapely.Point(x, y).buffer(1e-6)) or r["vis"].area > 0
        assert r["sees_G"] == lay.geoms["complete_G"].contains(shapely.Point(x, y))
        assert r["sees_H"] == lay.geoms["complete_H"].contains(shapely.Point(x, y))
        assert r["recognizable"] == (r["sees_G"] and r["sees_H"])  # complete model: R(G)∩R(H)
        seen.add((r["sees_G"], r["sees_H"]))
    assert len(seen) >= 3  # the sample met several cases: the test can tell them apart


def test_probe_fov_uses_the_env_aim_check():
    edr = load_scene("edr")  # 150 degree field of view
    lay = compute_layers(edr, Settings.from_scene(edr), ("recognizable",))
    p = shapely.get_coordinates(lay.geoms["recognizable"].representative_point())[0]
    r = probe(lay, *p)
    assert r["aim"] is not None and isinstance(r["aim_ok"], bool)


# ---- the app (Bokeh, no browser) ---------------------------------------------------------


@pytest.fixture
def app(lab, tmp_path):
    pytest.importorskip("bokeh")
    from sensorplan_gym.viewer.app import ViewerApp

    (tmp_path / "root").mkdir()
    return ViewerApp(lab, root=tmp_path / "root")


def _obstacles(app):
    d = app.sf.sources["obstacles"].data
    return [list(x) for x in d["xs"]], [list(y) for y in d["ys"]]


def test_app_edit_recomputes_exactly(app, lab):
    a0 = app.layers.geoms["recognizable"].area
    xs, ys = _obstacles(app)
    xs[2] = [x + 1.0 for x in xs[2]]
    app.sf.sources["obstacles"].data = {"xs": xs, "ys": ys}
    d = lab.to_dict()
    d["obstacles"][2] = [[x + 1.0, y] for x, y in d["obstacles"][2]]
    ref = recognizable_region(lab.from_dict(d))
    assert app.layers.geoms["recognizable"].area == pytest.approx(ref.area, rel=1e-12)
    assert app.layers.geoms["recognizable"].area != pytest.approx(a0)
    assert "Exact recomputation" in app.status.text and app.recomputes == 2


def test_app_invalid_edit_shows_scene_error(app):
    a0 = app.layers.geoms["recognizable"].area
    xs, ys = _obstacles(app)
    xs.append([6.1, 6.7, 6.7, 6.1])
    ys.append([8.2, 8.2, 8.8, 8.8])
    app.sf.sources["obstacles"].data = {"xs": xs, "ys": ys}
    assert app.error and "goal" in app.error
    assert "Invalid scene" in app.status.text and "obstacles[9]" in app.status.text
    assert app.layers.geoms["recognizable"].area == a0  # the last valid region stays
    # a self-intersecting wall polygon is reported too
    app.sf.sources["bounds"].data = {"xs": [[0, 12, 0, 12]], "ys": [[0, 8, 8, 0]]}
    assert "bounds" in app.error


def test_app_moving_g_moves_the_target(app, lab):
    g = app.sf.sources["goal"].data
    app.sf.sources["goal"].data = {
        "xs": [[x - 0.1 for x in g["xs"][0]]],
        "ys": [list(g["ys"][0])],
    }
    assert app.error is None, app.error
    t = np.asarray(app.sf.sources["target"].data["xs"][0])
    assert np.allclose(t, lab.target[:, 0] + 6.4 - 0.1)  # drawn at G's new centre
    assert np.allclose(app.scene.target, lab.target)  # the target itself is unchanged


def test_app_settings_and_layers(app, lab):
    app.w_eps_pos.value = 0.1
    assert app.settings.eps_pos == 0.1
    # the same query on the viewer's copy of the scene: equal up to rounding (1e-12 D^2)
    tol = 1e-12 * float(np.ptp(lab.bounds, axis=0) @ np.ptp(lab.bounds, axis=0))
    ref = recognizable_region(lab, eps_pos=0.1)
    assert app.layers.geoms["recognizable"].symmetric_difference(ref).area < tol
    app.w_motion.value = "rotating"
    assert app.settings.motion == "rotating"
    ref = recognizable_region(lab, theta=None, eps_pos=0.1)
    assert app.layers.geoms["recognizable"].symmetric_difference(ref).area < tol
    app.w_layers.active = [LAYERS.index("complete_G")]
    assert set(app.layers.geoms) == {"complete_G"}
    assert app.sf.sources["recognizable"].data["xs"] == []


def test_app_probe_text(app):
    r = app.probe_at(7.0, 3.0)
    assert r["sees_G"] and r["sees_H"]
    assert "sees A in G (complete)" in app.info.text and "yes" in app.info.text
    assert len(app.vis_src.data["xs"]) == 1
    app.probe_at(2.0, 1.5)  # inside an obstacle
    assert "not in the free space" in app.info.text


def test_app_save_and_load(app, lab, tmp_path):
    root = tmp_path / "root"
    assert app.root_dir == root.resolve()
    xs, ys = _obstacles(app)
    app.sf.sources["obstacles"].data = {"xs": xs[:-1], "ys": ys[:-1]}
    app.w_save_path.value = "edited.json"  # relative to the root, not to the cwd
    app._on_save()
    out = root / "edited.json"
    assert "id='saved'" in app.file_status.text and str(out.resolve()) in app.file_status.text
    saved = load_scene(out)
    assert len(saved.obstacles) == len(lab.obstacles) - 1
    assert np.allclose(saved.target, lab.target)
    # GeoJSON and WKT by the name's extension
    assert app.save("edited.geojson") == (root / "edited.geojson").resolve()
    assert load_scene(root / "edited.geojson") == saved
    assert app.save("sub/x.wkt") is None  # no such folder: refused, said so
    assert "No such file or directory" in app.file_status.text
    # load it back through the file-input widget (base64 of the file's bytes)
    other = load_scene("corridor")
    app._on_load("value", None, base64.b64encode(json.dumps(other.to_dict()).encode()).decode())
    assert app.scene == other and app.error is None
    assert "id='loaded'" in app.file_status.text
    app._on_load("value", None, base64.b64encode(b"{not json").decode())
    assert "Not loaded" in app.file_status.text and "invalid JSON" in app.file_status.text
    # GeoJSON and WKT uploads (told apart by content: the browser sends no trustworthy name)
    from geometry.formats import scene_to_geojson, scene_to_wkt

    edr = load_scene("edr")
    app._on_load("value", None, base64.b64encode(json.dumps(scene_to_geojson(edr)).encode()))
    assert app.scene == edr, app.file_status.text
    app._on_load("value", None, base64.b64encode(scene_to_wkt(other).encode()).decode())
    assert app.scene == other, app.file_status.text
    # a GeoJSON Feature (not a collection) says so, instead of "unknown key 'type'"
    app._on_load("value", None, base64.b64encode(b'{"type": "Feature"}').decode())
    assert "FeatureCollection" in app.file_status.text


@pytest.mark.parametrize(
    "name",
    ["../outside.json", "{parent}/outside.json", "link/outside.json", "sneaky.json",
     "~/outside.json", "notes.txt", "", "a/../../outside.json"],
)  # fmt: skip
def test_app_save_outside_root_refused(app, tmp_path, name):
    root = tmp_path / "root"
    (root / "a").mkdir()
    (root / "link").symlink_to(tmp_path, target_is_directory=True)
    (root / "sneaky.json").symlink_to(tmp_path / "outside.json")
    before = sorted(p.name for p in tmp_path.iterdir())
    assert app.save(name.format(parent=tmp_path)) is None
    assert "id='save-refused'" in app.file_status.text and "Not saved" in app.file_status.text
    assert sorted(p.name for p in tmp_path.iterdir()) == before  # nothing written outside
    assert not (tmp_path / "outside.json").exists()
    assert sorted(p.name for p in root.iterdir()) == ["a", "link", "sneaky.json"]


def test_cli_export(tmp_path, capsys):
    pytest.importorskip("bokeh")
    from agents.cli import main

    out = tmp_path / "v.html"
    assert main(["view", "edr", "--export", str(out), "--motion", "stationary"]) == 0
    text = out.read_text(encoding="utf-8")
    assert "layer:recognizable" in text and "motion=stationary" in text
    assert main(["view", "nosuch", "--export", str(out)]) == 2
    assert "unknown scene" in capsys.readouterr().err


def test_cli_refuses_a_bad_token_or_root(tmp_path, capsys, monkeypatch):
    """Checked before the server starts (these calls would otherwise serve forever)."""
    pytest.importorskip("bokeh")
    from agents.cli import main

    monkeypatch.delenv("SENSORPLAN_VIEW_TOKEN", raising=False)
    base = ["view", "lab", "--no-browser", "--port", "0"]
    assert main([*base, "--token", "short"]) == 2
    assert "at least 16 characters" in capsys.readouterr().err
    assert main([*base, "--token", "a token with spaces 123"]) == 2
    assert "at least 16 characters" in capsys.readouterr().err
    monkeypatch.setenv("SENSORPLAN_VIEW_TOKEN", "weak")
    assert main(base) == 2
    assert "at least 16 characters" in capsys.readouterr().err
    monkeypatch.delenv("SENSORPLAN_VIEW_TOKEN")
    assert main([*base, "--root", str(tmp_path / "missing")]) == 2
    assert "--root" in capsys.readouterr().err
    # the export writes a file the user names on the command line: no token, no root
    monkeypatch.setenv("SENSORPLAN_VIEW_TOKEN", "weak")
    assert main(["view", "corridor", "--export", str(tmp_path / "v.html")]) == 0


# ---- rollouts and their replay -----------------------------------------------------------


@pytest.fixture(scope="module")
def rollout():
    from agents import OraclePolicy
    from sensorplan_gym.viewer.replay import record_rollout

    return record_rollout(
        "sensorplan/Recognize-v0", policy=OraclePolicy, policy_name="oracle", seed=0, scene="lab"
    )


def test_record_rollout(rollout, tmp_path):
    from sensorplan_gym.viewer.replay import FORMAT, load_rollout, save_rollout

    assert rollout["format"] == FORMAT
    steps = rollout["steps"]
    assert len(steps) >= 3 and steps[0]["reward"] is None
    assert all(s["pose"] is not None and len(s["pose"]) == 3 for s in steps)
    assert steps[-1]["recognizing"]  # the oracle ends at a recognizing pose
    assert any(s["target"] for s in steps)  # Recognize reveals the target to its renderer
    bx, by = steps[1]["beams"]
    assert len(bx) == len(by) == len(steps[1]["hits"]) > 0
    assert rollout["return"] == pytest.approx(sum(s["reward"] for s in steps[1:]))
    p = save_rollout(rollout, tmp_path / "ep.json")
    assert load_rollout(p) == json.loads(json.dumps(rollout))


def test_load_rollout_errors(tmp_path):
    from sensorplan_gym.viewer.replay import load_rollout

    with pytest.raises(FileNotFoundError):
        load_rollout(tmp_path / "none.json")
    bad = tmp_path / "bad.json"
    bad.write_text("{}")
    with pytest.raises(ValueError, match="not a rollout file"):
        load_rollout(bad)
    bad.write_text('{"format": "sensorplan-rollout/1", "scene": {}, "region": {}}')
    with pytest.raises(ValueError, match="missing key 'steps'"):
        load_rollout(bad)


def test_replay_layout_first_frame(rollout):
    pytest.importorskip("bokeh")
    from sensorplan_gym.viewer.replay import replay_layout

    lay = replay_layout(rollout)
    robot = lay.select_one({"name": "src:replay_robot"})
    assert robot.data["x"] == [rollout["steps"][0]["pose"][0]]
    slider = lay.select_one({"name": "replay_step"})
    assert slider.end == len(rollout["steps"]) - 1
    assert slider.js_property_callbacks["change:value"]  # the browser redraws each step


def test_app_has_a_replay_tab(lab, rollout):
    pytest.importorskip("bokeh")
    from sensorplan_gym.viewer.app import ViewerApp

    app = ViewerApp(lab, rollout=rollout)
    assert [t.title for t in app.root.tabs] == ["Scene and regions", "Replay"]
