"""Bundled scenes: valid, with a non-empty recognizable region (complete model, translating
target, theta = 0) reachable from the start, and the start outside it."""

from __future__ import annotations

import gymnasium as gym
import pytest
import shapely

import sensorplan_gym
from geometry import Scene, recognizable_region
from sensorplan_gym.core.world import bundled_scene_path, load_scene

SCENES = sensorplan_gym.BUNDLED_SCENES


def test_bundled_scene_set():
    assert {"lab", "edr"} <= set(SCENES) and len(SCENES) >= 4


@pytest.mark.parametrize("name", SCENES)
def test_region_nonempty_reachable_start_outside(name):
    scene = Scene.load(bundled_scene_path(name))
    assert scene.start is not None
    R = recognizable_region(scene, model="complete", theta=0.0)
    assert R.area > 0.1
    start = shapely.Point(scene.start[:2])
    assert not R.covers(start)
    comps = getattr(scene.free_space, "geoms", [scene.free_space])
    comp = next(c for c in comps if c.covers(start))
    assert comp.intersection(R).area > 0.1


@pytest.mark.parametrize("name", SCENES)
def test_scene_roundtrip_and_envs_build(name):
    scene = load_scene(name)
    assert Scene.from_dict(scene.to_dict()).to_dict() == scene.to_dict()
    for env_id in sensorplan_gym.ENV_IDS:
        env = gym.make(env_id, scene=name)
        env.reset(seed=0)
        env.step(env.action_space.sample())


def test_lab_start_sees_neither_like_tommy():
    """From TOMMY's start neither the doorway G nor the nook H is completely visible."""
    from geometry import complete_region

    scene = load_scene("lab")
    p = shapely.Point(scene.start[:2])
    assert not complete_region(scene, target_in="failure").covers(p)
    env = gym.make("sensorplan/Navigate-v0", scene="lab").unwrapped
    _, info = env.reset(seed=0)
    assert not info["recognizing"]


def test_scene_from_path(tmp_path):
    p = tmp_path / "mine.json"
    load_scene("edr").save(p)
    env = gym.make("sensorplan/Placement-v0", scene=str(p))
    env.reset(seed=0)
    with pytest.raises(FileNotFoundError):
        gym.make("sensorplan/Placement-v0", scene=str(tmp_path / "missing.json"))


@pytest.mark.parametrize("name", SCENES)
def test_some_pose_recognizes_with_scene_fov(name):
    """With the scene's own field of view, some reachable placement has a valid aim."""
    import numpy as np

    env = gym.make("sensorplan/Navigate-v0", scene=name).unwrapped
    env.reset(seed=0)
    w = env.world
    R = w.reachable_region(env.start[:2])
    rng = np.random.default_rng(0)
    minx, miny, maxx, maxy = R.bounds
    found = False
    for _ in range(4000):
        x, y = rng.uniform(minx, maxx), rng.uniform(miny, maxy)
        if not w.in_region(x, y):
            continue
        for psi in w.best_aim(x, y) + np.linspace(-1.5, 1.5, 13):
            if w.recognizing(x, y, psi):
                found = True
                break
        if found:
            break
    assert found


def test_random_scenes_with_drawn_fields_of_view():
    """``random_scene(fov_deg=(lo, hi))`` adds a drawn ``sensor.fov_deg`` and leaves the
    geometry as it was; a pool made with it gives each sub-env its scene's field of view."""
    import math

    import numpy as np

    from geometry.generate import random_scene

    plain = random_scene(np.random.default_rng(7))
    drawn = random_scene(np.random.default_rng(7), fov_deg=(90, 360))
    assert "sensor" not in plain
    assert {k: v for k, v in drawn.items() if k != "sensor"} == plain
    assert 90 <= drawn["sensor"]["fov_deg"] <= 360
    assert random_scene(np.random.default_rng(7), fov_deg=150)["sensor"] == {"fov_deg": 150.0}
    with pytest.raises(ValueError, match="fov_deg"):
        random_scene(np.random.default_rng(7), fov_deg=(200, 100))
    venv = gym.make_vec(
        "sensorplan/Navigate-v0",
        num_envs=8,
        vectorization_mode="vector_entry_point",
        scene="random",
        random_scene_kwargs={"fov_deg": [90, 360]},
        scene_pool_size=8,
    )
    venv.reset(seed=0)
    fov = np.degrees(venv.unwrapped.batch.fov)
    assert np.all((fov >= 90 - 1e-9) & (fov <= 360 + 1e-9)) and np.ptp(fov) > 30
    for i, w in enumerate(venv.unwrapped.batch.worlds):
        assert math.isclose(w.fov, math.radians(fov[i]))
        assert math.isclose(w.fov, math.radians(w.scene.sensor.fov_deg))


def test_random_scenes_with_large_notches_make_valid_l_shaped_rooms():
    """``notch_size`` widens the corner cut-outs (L-shaped rooms, corridors around a corner);
    its default draws exactly the old scenes, and a room split by its cut-outs is redrawn."""
    import numpy as np
    from shapely.geometry import Polygon

    from geometry.generate import random_scene

    for k in range(5):
        assert random_scene(np.random.default_rng(k)) == random_scene(
            np.random.default_rng(k), notch_size=(0.12, 0.3)
        )
    ratios = []
    for k in range(30):
        d = random_scene(np.random.default_rng(k), notch_size=(0.3, 0.75), notches=2)
        room = Polygon(d["bounds"])
        assert room.is_valid and not room.interiors
        x0, y0, x1, y1 = room.bounds
        ratios.append(room.area / ((x1 - x0) * (y1 - y0)))
    assert min(ratios) < 0.6  # some rooms are L-shaped
    with pytest.raises(ValueError, match="notch_size"):
        random_scene(np.random.default_rng(0), notch_size=(0.5, 1.2))
