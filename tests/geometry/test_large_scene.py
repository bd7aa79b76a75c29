"""The bundled large scene (an office floor of about 1,250 edges, loaded by path: it is
kept out of BUNDLED_SCENES so the per-scene env tests stay fast)."""

from __future__ import annotations

import json
from pathlib import Path

import gymnasium as gym
import numpy as np
import shapely

import sensorplan_gym
from benchmarks.make_office_floor import n_edges, office_floor
from geometry import Scene, recognizable_region

LARGE = Path(sensorplan_gym.__file__).resolve().parent / "scenes" / "large" / "office_floor.json"


def test_office_floor_file_is_generated_and_large():
    d = json.loads(LARGE.read_text())
    assert d == office_floor()  # the file is exactly what the generator writes
    assert 1000 <= n_edges(d) <= 2000
    assert "office_floor" not in sensorplan_gym.BUNDLED_SCENES


def test_office_floor_region_nonempty_reachable_start_outside():
    scene = Scene.load(LARGE)
    R = recognizable_region(scene, model="complete", theta=0.0)
    assert R.area > 1.0
    start = shapely.Point(scene.start[:2])
    assert not R.covers(start)
    comps = getattr(scene.free_space, "geoms", [scene.free_space])
    comp = next(c for c in comps if c.covers(start))
    assert comp.intersection(R).area > 1.0


def test_office_floor_navigate_env_smoke():
    env = gym.make("sensorplan_gym:sensorplan/Navigate-v0", scene=str(LARGE))
    obs, info = env.reset(seed=0)
    assert env.observation_space.contains(obs) and not info["recognizing"]
    for _ in range(5):
        obs, reward, terminated, truncated, info = env.step(env.action_space.sample())
        assert env.observation_space.contains(obs) and np.isfinite(reward)
    obs2, _ = env.reset(seed=1)
    assert env.observation_space.contains(obs2)
    env.close()
