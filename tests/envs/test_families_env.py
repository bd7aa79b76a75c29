"""``scene="random"`` with ``family=`` / ``difficulty=``: pools drawn from scene families,
the oracle solving them, seeding, and the unchanged default generator."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
import shapely

import sensorplan_gym  # noqa: F401  (registers the envs)
from agents.planning.oracle import OraclePolicy, plan_viewpoint
from geometry.families import DIFFICULTIES, FAMILIES, HARD, SceneFamily, scene_parameters
from geometry.generate import random_scene
from sensorplan_gym.core import fused
from tests.envs.test_fused import _episodes
from tests.planning.test_oracle import rollout

NAV = "sensorplan/Navigate-v0"


@pytest.mark.parametrize("name", ["easy", "medium"])
def test_oracle_solves_navigate_in_the_difficulty(name):
    level = DIFFICULTIES[name]
    env = gym.make(NAV, scene="random", difficulty=name, scene_pool_size=4)
    batch = env.unwrapped.batch
    assert batch.source.family is level.family
    assert batch.min_start_distance == level.min_start_distance
    policy = OraclePolicy(env)
    for seed in range(4):
        info = rollout(env, policy, seed)
        assert info["is_success"], (name, seed)
        assert level.family.contains(scene_parameters(env.unwrapped.world.scene))


def test_oracle_finds_a_placement_on_hard_scenes():
    env = gym.make(NAV, scene="random", difficulty="hard", scene_pool_size=4)
    world, start = env.unwrapped.batch.source.get(3)
    rng = np.random.default_rng(0)
    space = world.reachable_region(start[:2])
    x0, y0, x1, y1 = space.bounds
    pts = rng.uniform((x0, y0), (x1, y1), (4000, 2))
    pts = pts[shapely.contains_xy(space, pts[:, 0], pts[:, 1])][:200]
    aims = np.linspace(-np.pi, np.pi, 72, endpoint=False)
    good = sum(any(world.recognizing(x, y, a) for a in aims) for x, y in pts)
    assert good > len(pts) / 2  # most of the region has a recognizing aim ...
    # ... and the oracle finds a placement (a coarse aim grid alone found none: the region
    # is thin in a large bounding box)
    assert plan_viewpoint(world, start[:2]).status == "ok"


def test_pool_scenes_lie_in_the_family_and_far_enough():
    env = gym.make(NAV, scene="random", difficulty="hard", scene_pool_size=6)
    pool = env.unwrapped.batch.source.build()
    for k in range(pool.size):
        world, start = pool.get(k)
        assert HARD.contains(scene_parameters(world.scene)), k
        assert world.distance_to_region(*start[:2]) >= 0.35 * world.diameter


def test_seeding_is_deterministic():
    def trace(seed: int) -> list[np.ndarray]:
        env = gym.make(NAV, scene="random", family="medium", scene_pool_size=5)
        out = []
        for s in range(3):
            obs, _ = env.reset(seed=seed + s)
            env.action_space.seed(seed + s)
            out.append(obs)
            for _ in range(3):
                out.append(env.step(env.action_space.sample())[0])
        return out

    a, b = trace(0), trace(0)
    assert all(np.array_equal(x, y) for x, y in zip(a, b, strict=True))
    assert not all(np.array_equal(x, y) for x, y in zip(a, trace(10), strict=True))


def test_explicit_min_start_distance_wins_and_family_alone_keeps_zero():
    env = gym.make(
        NAV, scene="random", difficulty="hard", min_start_distance=0.1, scene_pool_size=2
    )
    assert env.unwrapped.batch.min_start_distance == 0.1
    env = gym.make(NAV, scene="random", family=FAMILIES["easy"], scene_pool_size=2)
    assert env.unwrapped.batch.min_start_distance == 0.0


def test_default_random_pool_is_todays_generator():
    env = gym.make(NAV, scene="random", scene_pool_size=2)
    pool = env.unwrapped.batch.source
    assert pool.family is None
    world, _ = pool.get(0)
    # scene 0 is the first draw of random_scene from [seed, 0] that hosts an episode
    rng = np.random.default_rng([0, 0])
    drawn = [random_scene(rng) for _ in range(pool.max_tries)]
    assert world.scene.to_dict() in drawn


@pytest.mark.parametrize(
    "kw, match",
    [
        (dict(scene="lab", family="easy"), "need scene='random'"),
        (dict(scene="random", family="easy", random_scene_kwargs={"notches": 0}), "not both"),
        (dict(scene="random", family="huge"), "unknown scene family 'huge'"),
        (dict(scene="random", difficulty="insane"), "unknown difficulty 'insane'"),
        (dict(scene="random", difficulty="easy", family="hard"), "has its own family"),
    ],
)
def test_bad_family_kwargs_fail_clearly(kw, match):
    with pytest.raises(ValueError, match=match):
        gym.make(NAV, **kw)


# ---- self_features: what the robot knows about its own sensor ----------------------------

RANGED = SceneFamily(
    "ranged", fov_deg=(45.0, 200.0), max_range=(0.3, 0.6), range_limited=0.6, shapes=("L",)
)


@pytest.mark.parametrize("env_id", [NAV, "sensorplan/Recognize-v0"])
def test_self_features_are_the_sensors_fov_and_reach(env_id):
    kw = dict(scene="random", family=RANGED, scene_pool_size=8)
    env = gym.make(env_id, self_features=True, **kw)
    plain = gym.make(env_id, **kw)
    assert env.observation_space.shape[0] == plain.observation_space.shape[0] + 2
    ranges = set()
    for seed in range(16):
        obs, _ = env.reset(seed=seed)
        ref, _ = plain.reset(seed=seed)
        assert env.observation_space.contains(obs)
        np.testing.assert_array_equal(obs[:-2], ref)
        scene = env.unwrapped.world.scene
        mr = scene.sensor.max_range
        reach = 1.0 if mr is None else min(mr / scene.diameter, 1.0)
        assert obs[-2] == pytest.approx(scene.sensor.fov_deg / 360.0, rel=1e-6)
        assert obs[-1] == pytest.approx(reach, rel=1e-6)
        ranges.add(mr is None)
    assert ranges == {True, False}  # both limited and unlimited sensors were seen
    fov_both = gym.make(env_id, self_features=True, sensor_fov=True, **kw)
    assert fov_both.observation_space.shape[0] == plain.observation_space.shape[0] + 3
    with pytest.raises(ValueError, match="self_features"):
        gym.make(env_id, self_features=1)
    with pytest.raises(ValueError, match="self_features=True needs obs_type='vector'"):
        gym.make(env_id, self_features=True, obs_type="grid")


def test_placement_self_features():
    """Placement-v0's vector observation ends with the same two values (issue 22 item 1)."""
    env_id = "sensorplan/Placement-v0"
    kw = dict(scene="random", family=RANGED, scene_pool_size=8)
    env = gym.make(env_id, self_features=True, **kw)
    plain = gym.make(env_id, **kw)
    assert env.observation_space.shape[0] == plain.observation_space.shape[0] + 2
    for seed in range(8):
        obs, _ = env.reset(seed=seed)
        ref, _ = plain.reset(seed=seed)
        np.testing.assert_array_equal(obs[:-2], ref)
        scene = env.unwrapped.world.scene
        mr = scene.sensor.max_range
        assert obs[-2] == pytest.approx(scene.sensor.fov_deg / 360.0, rel=1e-6)
        assert obs[-1] == pytest.approx(1.0 if mr is None else min(mr / scene.diameter, 1.0))
    with pytest.raises(ValueError, match="sensor_fov=True needs obs_type='vector' in Navigate"):
        gym.make(env_id, sensor_fov=True)
    with pytest.raises(ValueError, match=r"self_features=True needs .* \(or Placement\)"):
        gym.make(NAV, self_features=True, obs_type="grid")
    # Placement's grid observation carries them as two constant planes (times 255)
    grid = gym.make(env_id, self_features=True, obs_type="grid", **kw)
    obs, _ = grid.reset(seed=0)
    scene = grid.unwrapped.world.scene
    assert obs.shape[0] == 5 and (obs[3] == obs[3, 0, 0]).all()
    assert obs[3, 0, 0] == round(255 * min(scene.sensor.fov_deg / 360.0, 1.0))


def test_default_observation_shapes_are_unchanged():
    for env_id, n in ((NAV, 8 + 3 * 16), ("sensorplan/Recognize-v0", 8 + 3 * 16)):
        assert gym.make(env_id).observation_space.shape == (n,)
        assert gym.make(env_id, scene="random", difficulty="hard").observation_space.shape == (n,)


def test_self_features_batched_equals_single():
    kw = dict(scene="random", family=RANGED, scene_pool_size=6, self_features=True, max_steps=25)
    n = 3
    venv = gym.make_vec(NAV, num_envs=n, vectorization_mode="vector_entry_point", **kw)
    singles = [gym.make(NAV, **kw) for _ in range(n)]
    obs, _ = venv.reset(seed=11)
    for i, e in enumerate(singles):
        assert np.array_equal(e.reset(seed=11 + i)[0], obs[i])
    rng = np.random.default_rng(0)
    done, episodes = [False] * n, 0
    for _ in range(120):
        a = rng.uniform(-1, 1, (n, *venv.single_action_space.shape)).astype(np.float32)
        obs, rew, term, trunc, _ = venv.step(a)
        for i, e in enumerate(singles):
            o = e.reset()[0] if done[i] else e.step(a[i])[0]
            assert np.array_equal(o, obs[i])
            done[i] = bool(term[i] or trunc[i])
            episodes += done[i]
    assert episodes >= 3 * n  # resets (new scenes, new sensors) were compared too


@pytest.mark.skipif(not fused.FUSED, reason="numba not installed (the 'fast' extra)")
def test_self_features_compiled_equals_numpy_path():
    kw = dict(scene="random", family=RANGED, scene_pool_size=4, self_features=True)
    a = _episodes(NAV, 60, True, **kw)
    b = _episodes(NAV, 60, False, **kw)
    assert a == b


# ---- narrow sensors: family pools keep only scenes with a pose that sees G and H -----------

NARROW = SceneFamily(
    "narrow", fov_deg=(45.0, 90.0), shapes=("rectangle", "L", "rooms"), diameter=(9.0, 16.0)
)


def test_oracle_solves_navigate_with_narrow_sensors():
    env = gym.make(NAV, scene="random", family=NARROW, scene_pool_size=6, random_start=True)
    policy = OraclePolicy(env)
    wins = [bool(rollout(env, policy, seed)["is_success"]) for seed in range(6)]
    assert all(wins), wins


def test_has_view_is_a_real_check():
    from sensorplan_gym.core.cache import get_world
    from sensorplan_gym.core.scenes import load_scene
    from sensorplan_gym.core.world import WorldConfig
    from sensorplan_gym.envs.base import _has_view

    rng = np.random.default_rng(0)
    wide = get_world(load_scene("lab"), WorldConfig())
    state = rng.bit_generator.state
    assert _has_view(wide, wide.region, rng) and rng.bit_generator.state == state  # no draw
    assert _has_view(get_world(load_scene("edr"), WorldConfig()), wide.region, rng)
    lab = load_scene("lab")
    narrow = get_world(lab.replace(sensor={"fov_deg": 2.0}), WorldConfig())
    assert not _has_view(narrow, narrow.region, rng)
    short = get_world(lab.replace(sensor={"max_range": 0.5}), WorldConfig())
    assert not _has_view(short, short.region, rng)
