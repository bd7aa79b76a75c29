"""GeoJSON / WKT / shapely / obstacle-map import and export, and `sensorplan convert`."""

from __future__ import annotations

import copy
import json

import numpy as np
import pytest
import shapely

import sensorplan_gym
from agents.cli import main as cli_main
from geometry import Scene
from geometry.formats import (
    FormatError,
    load_scene_file,
    save_scene_file,
    scene_from_geojson,
    scene_from_obstacle_map,
    scene_from_shapely,
    scene_from_wkt,
    scene_to_geojson,
    scene_to_shapely,
    scene_to_wkt,
    simple_pieces,
)
from sensorplan_gym.core.world import load_scene

SQUARE = [[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]]


def _same(a: Scene, b: Scene) -> None:
    assert a.name == b.name
    np.testing.assert_array_equal(a.bounds, b.bounds)
    assert len(a.obstacles) == len(b.obstacles)
    for x, y in zip(a.obstacles, b.obstacles, strict=True):
        np.testing.assert_array_equal(x, y)
    for k in ("target", "goal", "failure"):
        np.testing.assert_array_equal(getattr(a, k), getattr(b, k))
    assert a.start == b.start and a.sensor == b.sensor


@pytest.mark.parametrize("name", sensorplan_gym.BUNDLED_SCENES)
def test_geojson_and_wkt_roundtrip_bundled(name):
    s = load_scene(name)
    g = scene_to_geojson(s)
    assert g["type"] == "FeatureCollection"
    # RFC 7946: closed rings, exterior counter-clockwise
    for f in g["features"]:
        if f["geometry"]["type"] == "Polygon":
            ring = f["geometry"]["coordinates"][0]
            assert ring[0] == ring[-1]
            assert shapely.Polygon(ring).exterior.is_ccw
    s2 = scene_from_geojson(json.loads(json.dumps(g)))
    _same(s, s2)
    _same(s, scene_from_wkt(scene_to_wkt(s)))
    parts = scene_to_shapely(s)
    s3 = scene_from_shapely(
        name=s.name,
        obstacles=parts["obstacles"],
        **{k: parts[k] for k in ("bounds", "target", "goal", "failure")},
        start=s.start,
        sensor=s.to_dict().get("sensor"),
    )
    _same(s, s3)


def test_geojson_roundtrip_cw_input_same_geometry(lab_dict):
    d = copy.deepcopy(lab_dict)
    d["bounds"] = d["bounds"][::-1]  # clockwise walls
    d["start"] = [1.0, 1.0, 0.25]
    d["sensor"] = {"fov_deg": 90, "max_range": 4.0, "eps_pos": 0.1, "eps_aim_deg": 2}
    s = Scene.from_dict(d)
    s2 = scene_from_geojson(scene_to_geojson(s))
    _same(s, s2)
    assert s2.start == (1.0, 1.0, 0.25) and s2.sensor.fov_deg == 90


def _fc(*features, **extra):
    return {"type": "FeatureCollection", "features": list(features), **extra}


def _f(role, geom, **props):
    return {"type": "Feature", "properties": {"role": role, **props}, "geometry": geom}


def _poly(*rings):
    return {"type": "Polygon", "coordinates": [list(r) + [r[0]] for r in rings]}


ROOM = [[0, 0], [20, 0], [20, 10], [0, 10]]


def _basic(extra=()):
    return _fc(
        _f("bounds", _poly(ROOM)),
        *extra,
        _f("target", _poly(SQUARE)),
        _f("goal", {"type": "Point", "coordinates": [2, 2]}),
        _f("failure", _poly([[15, 2], [17, 2], [17, 3], [15, 3]])),
        name="room",
    )


def test_geojson_holes_in_bounds_and_obstacles():
    # a courtyard building: an obstacle with a hole (enclosed free space), and a
    # pillar given as a hole of the bounds
    building = _poly([[6, 4], [12, 4], [12, 8], [6, 8]], [[8, 5], [8, 7], [10, 7], [10, 5]])
    fc = _fc(
        _f("bounds", _poly(ROOM, [[3, 7], [3, 8], [4, 8], [4, 7]])),
        _f("obstacle", building),
        _f("target", _poly([[9, 5], [10, 5], [10, 6], [9, 6]]), origin=[9.5, 5.5]),
        _f("goal", {"type": "Point", "coordinates": [2, 2]}),
        _f("failure", {"type": "Point", "coordinates": [17, 2]}),
        _f("start", {"type": "Point", "coordinates": [1, 9]}, theta=1.5),
    )
    s = scene_from_geojson(fc, name="courtyard")
    assert s.name == "courtyard" and s.start == (1.0, 9.0, 1.5)
    np.testing.assert_allclose(np.abs(s.target), 0.5)  # translated by -origin
    assert all(shapely.Polygon(o).is_valid for o in s.obstacles)
    expected = shapely.union_all([shapely.geometry.shape(building), shapely.box(3, 7, 4, 8)])
    assert s.obstacle_union.symmetric_difference(expected).area == 0.0
    # the courtyard is free space, enclosed: the free space has two components
    assert s.free_space.geom_type == "MultiPolygon" and len(s.free_space.geoms) == 2
    assert s.free_space.area == pytest.approx(200 - 24 + 4 - 1)


def test_simple_pieces_exact_union():
    rng = np.random.default_rng(3)
    outer = shapely.box(0, 0, 30, 30)
    holes = [
        shapely.box(x, y, x + 2, y + 1.5).exterior.coords for x, y in rng.uniform(1, 26, (12, 2))
    ]
    holes_u = shapely.union_all([shapely.Polygon(h) for h in holes])
    p = outer.difference(holes_u)
    assert len(p.interiors) > 3
    pieces = simple_pieces(p)
    assert all(len(q.interiors) == 0 and q.is_valid for q in pieces)
    assert shapely.union_all(pieces).symmetric_difference(p).area < 1e-9
    # no new vertices: every piece vertex is a vertex of p
    vp = {tuple(c) for c in shapely.get_coordinates(p)}
    assert {tuple(c) for c in shapely.get_coordinates(pieces)} <= vp


@pytest.mark.parametrize(
    ("mutate", "message"),
    [
        (
            lambda fc: fc["features"][1]["properties"].pop("role"),
            r"features\[1\]: missing properties.role",
        ),
        (
            lambda fc: fc["features"][1]["properties"].update(role="wall"),
            r"features\[1\]: unknown role 'wall'",
        ),
        (
            lambda fc: fc["features"][1].update(
                geometry={"type": "LineString", "coordinates": [[1, 1], [2, 2]]}
            ),
            r"features\[1\] \(role 'obstacle'\): expected a Polygon or MultiPolygon, got Line",
        ),
        (
            lambda fc: fc["features"][1].update(geometry=_poly([[5, 5], [7, 7], [7, 5], [5, 7]])),
            r"features\[1\] \(role 'obstacle'\): invalid polygon \(Self-intersection",
        ),
        (
            lambda fc: fc["features"][1].update(
                geometry=_poly([[18, 5], [25, 5], [25, 6], [18, 6]])
            ),
            r"features\[1\] \(role 'obstacle'\): lies \(partly\) outside the bounds",
        ),
        (
            lambda fc: fc["features"][1].update(
                geometry={"type": "Polygon", "coordinates": [[[1, "a"], [2, 2], [3, 1], [1, "a"]]]}
            ),
            r"features\[1\] \(role 'obstacle'\): malformed geometry",
        ),
        (lambda fc: fc["features"].pop(2), r"no feature with role 'target'"),
        (
            lambda fc: fc["features"].append(copy.deepcopy(fc["features"][3])),
            r"features 3, 5: more than one feature with role 'goal'",
        ),
        (
            lambda fc: fc["features"][2].update(
                geometry=_poly(SQUARE, [[-0.1, -0.1], [-0.1, 0.1], [0.1, 0.1]])
            ),
            r"features\[2\] \(role 'target'\): a polygon with 1 hole\(s\) is not allowed",
        ),
        (
            lambda fc: fc["features"][3].update(
                geometry={"type": "MultiPoint", "coordinates": [[1, 1], [2, 2]]}
            ),
            r"features\[3\] \(role 'goal'\): expected a Polygon or a Point, got MultiPoint",
        ),
        (
            lambda fc: fc["features"][1]["geometry"].update(
                coordinates=[[[5, 5], [7, 5], [7, float("nan")], [5, 5]]]
            ),
            r"features\[1\] \(role 'obstacle'\): non-finite coordinate",
        ),
        (
            lambda fc: fc.update(type="Feature"),
            r"expected a GeoJSON FeatureCollection, got 'Feature'",
        ),
        (lambda fc: fc["features"].__setitem__(0, 5), r"features\[0\]: expected a GeoJSON Feature"),
    ],
)
def test_geojson_bad_input_names_feature(mutate, message):
    fc = _basic([_f("obstacle", _poly([[5, 5], [7, 5], [7, 7], [5, 7]]))])
    scene_from_geojson(copy.deepcopy(fc))  # the unmutated collection is valid
    mutate(fc)
    with pytest.raises(FormatError, match=message):
        scene_from_geojson(fc)


def test_wkt_bad_input():
    s = load_scene("lab")
    text = scene_to_wkt(s)
    with pytest.raises(FormatError, match=r"line 3 \(obstacles\): invalid WKT"):
        scene_from_wkt(text.replace("obstacles: MULTIPOLYGON", "obstacles: MULTIPOLYGONN"))
    with pytest.raises(FormatError, match="missing line 'goal: <WKT>'"):
        scene_from_wkt("\n".join(ln for ln in text.splitlines() if not ln.startswith("goal")))
    with pytest.raises(FormatError, match="unknown key 'walls'"):
        scene_from_wkt(text + "walls: POINT (1 1)\n")


def test_obstacle_map_polygons_with_holes():
    donut = [
        [[2, 2], [8, 2], [8, 8], [2, 8]],
        [[4, 4], [4, 6], [6, 6], [6, 4]],
    ]
    s = scene_from_obstacle_map(
        [donut, shapely.box(10, 2, 12, 4)],
        bounds=shapely.box(0, 0, 14, 10),
        target=SQUARE,
        goal=(1, 1),
        failure=(13, 9),
    )
    assert s.obstacle_union.area == pytest.approx(36 - 4 + 4)
    assert len(s.free_space.geoms) == 2  # the donut's hole is enclosed free space
    # default bounds: the obstacles' bounding box grown by the margin
    s2 = scene_from_obstacle_map([donut], target=SQUARE, goal=(1, 1), failure=(9, 9), margin=2.0)
    assert s2.bounds_geom.equals(shapely.box(0, 0, 10, 10))
    with pytest.raises(FormatError, match=r"polygons\[1\]: invalid polygon"):
        scene_from_obstacle_map(
            [donut, [[[0, 0], [1, 1], [1, 0], [0, 1]]]], target=SQUARE, goal=(1, 1), failure=(9, 9)
        )


def test_convert_cli(tmp_path, capsys):
    s = load_scene("warehouse")
    src = tmp_path / "plan.geojson"
    save_scene_file(s, src)
    out_json = tmp_path / "scene.json"
    assert cli_main(["convert", str(src), str(out_json)]) == 0
    assert "scene 'warehouse'" in capsys.readouterr().out
    _same(s, Scene.load(out_json))
    out_wkt = tmp_path / "scene.wkt"
    assert cli_main(["convert", str(out_json), str(out_wkt), "--name", "w2"]) == 0
    s_wkt = load_scene_file(out_wkt)
    assert s_wkt.name == "w2"
    # the convert output loads as an env scene
    import gymnasium as gym

    env = gym.make("sensorplan/Placement-v0", scene=str(out_json))
    env.reset(seed=0)
    # bad input: exit code 2 and a message naming the feature
    bad = scene_to_geojson(s)
    bad["features"][1]["geometry"]["type"] = "Point"
    (tmp_path / "bad.geojson").write_text(json.dumps(bad))
    assert cli_main(["convert", str(tmp_path / "bad.geojson"), str(out_json)]) == 2
    err = capsys.readouterr().err
    assert "bad.geojson" in err and "features[1] (role 'obstacle')" in err
    assert cli_main(["convert", str(src), str(tmp_path / "x.shp")]) == 2
    assert "unknown extension '.shp'" in capsys.readouterr().err


# ---- one scene loader everywhere: load_scene dispatches on name, extension and content ----


@pytest.fixture(scope="module")
def wh_files(tmp_path_factory):
    """The warehouse scene as .geojson, GeoJSON in a .json, .wkt and scene JSON."""
    d = tmp_path_factory.mktemp("wh")
    s = load_scene("warehouse")
    save_scene_file(s, d / "plan.geojson")
    (d / "plan_geo.json").write_text(json.dumps(scene_to_geojson(s)))
    save_scene_file(s, d / "plan.wkt")
    s.save(d / "plan.json")
    return s, d


def test_load_scene_every_format(wh_files):
    s, d = wh_files
    for f in ("plan.geojson", "plan_geo.json", "plan.json"):
        _same(s, load_scene(d / f))  # a Path
        _same(s, load_scene(str(d / f)))  # a str
    w = load_scene(d / "plan.wkt")
    assert w.name == s.name and len(w.obstacles) == len(s.obstacles)
    _same(s, load_scene(scene_to_geojson(s)))  # a GeoJSON dict
    _same(s, load_scene(s.to_dict()))  # a scene dict
    assert load_scene(s) is s
    # name= renames whatever the source
    for spec in ("warehouse", d / "plan.geojson", d / "plan.wkt", s.to_dict(), s):
        assert load_scene(spec, name="renamed").name == "renamed"
    # a GeoJSON without a name takes the file's stem, as load_scene_file does
    g = scene_to_geojson(s)
    g.pop("name", None)
    (d / "nameless.geojson").write_text(json.dumps(g))
    assert load_scene(d / "nameless.geojson").name == "nameless"


def test_load_scene_errors(tmp_path):
    with pytest.raises(FileNotFoundError, match="scene file not found"):
        load_scene(tmp_path / "missing.geojson")
    with pytest.raises(ValueError, match="unknown scene 'nosuch'.*lab.*geojson"):
        load_scene("nosuch")
    (tmp_path / "plan.shp").write_text("x")
    with pytest.raises(FormatError, match=r"plan\.shp.*unknown extension '\.shp'"):
        load_scene(tmp_path / "plan.shp")
    # a GeoJSON object that is not a FeatureCollection: said so, not "unknown key 'type'"
    (tmp_path / "f.json").write_text('{"type": "Feature", "geometry": null}')
    with pytest.raises(FormatError, match="f.json: expected a GeoJSON FeatureCollection"):
        load_scene(tmp_path / "f.json")
    with pytest.raises(FormatError, match="expected a GeoJSON FeatureCollection, got 'Polygon'"):
        load_scene({"type": "Polygon", "coordinates": []})
    (tmp_path / "bin.json").write_bytes(b"\xff\xfe\x00")
    with pytest.raises(FormatError, match="bin.json: not a text file"):
        load_scene(tmp_path / "bin.json")


def test_geojson_scene_in_envs(wh_files):
    import gymnasium as gym

    s, d = wh_files
    env = gym.make("sensorplan/Placement-v0", scene=str(d / "plan.geojson"))
    env.reset(seed=0)
    _same(s, env.unwrapped.batch.source.world.scene)  # the GeoJSON file's scene, exactly
    env.close()


@pytest.mark.parametrize("name", sensorplan_gym.BUNDLED_SCENES)
def test_convert_bundled_names(name, tmp_path, capsys):
    out = tmp_path / f"{name}.geojson"
    assert cli_main(["convert", name, str(out)]) == 0
    assert f"scene {name!r}" in capsys.readouterr().out
    _same(load_scene(name), load_scene(out))


def test_convert_cli_errors(tmp_path, capsys):
    assert cli_main(["convert", "nosuch", str(tmp_path / "x.json")]) == 2
    assert "unknown scene 'nosuch'" in capsys.readouterr().err
    assert cli_main(["convert", "lab", str(tmp_path / "no" / "dir" / "x.json")]) == 2
    err = capsys.readouterr().err
    assert "cannot write" in err and "Traceback" not in err
    assert not (tmp_path / "no").exists()


def test_view_accepts_geojson(wh_files, tmp_path, capsys):
    pytest.importorskip("bokeh")
    s, d = wh_files
    for f in ("plan.geojson", "plan_geo.json", "plan.wkt"):
        out = tmp_path / f"{f}.html"
        assert cli_main(["view", str(d / f), "--export", str(out)]) == 0, capsys.readouterr()
        assert "layer:recognizable" in out.read_text(encoding="utf-8")
