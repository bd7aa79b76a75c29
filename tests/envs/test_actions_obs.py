"""Action types (continuous / discrete), map-predicted ranges, Recognize's declare hold and
shaping, and the oracle under declare_hold."""

from __future__ import annotations

import math
import warnings

import gymnasium as gym
import numpy as np
import pytest

import sensorplan_gym  # noqa: F401
from sensorplan_gym.core.actions import ROBOT_MOTIONS
from sensorplan_gym.registration import ENV_IDS

IDS = sorted(ENV_IDS)


@pytest.mark.parametrize("env_id", IDS)
def test_discrete_actions_pass_checkers(env_id):
    from gymnasium.utils.env_checker import check_env

    env = gym.make(env_id, action_type="discrete")
    assert isinstance(env.action_space, gym.spaces.Discrete)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        check_env(env.unwrapped, skip_render_check=True)
    env.reset(seed=0)
    with pytest.raises(ValueError, match="range"):
        env.step(env.action_space.n)
    with pytest.raises(ValueError, match="integer"):
        env.step(0.5)


def test_discrete_motions_are_the_table():
    a = gym.make("sensorplan/Navigate-v0", action_type="discrete")
    b = gym.make("sensorplan/Navigate-v0")
    for k, (_, row) in enumerate(ROBOT_MOTIONS):
        a.reset(seed=1)
        b.reset(seed=1)
        oa = a.step(k)[0]
        ob = b.step(np.array(row, dtype=np.float32))[0]
        assert np.array_equal(oa, ob)
    p = gym.make(
        "sensorplan/Placement-v0", action_type="discrete", placement_grid=4, placement_aims=2
    )
    assert p.action_space.n == 32
    p.reset(seed=0)
    info = p.step(0)[4]
    w = p.unwrapped.world
    x0 = w.lo[0] + (w.hi[0] - w.lo[0]) / 8  # first cell centre
    assert info["pose"][0] == pytest.approx(x0) and info["pose"][2] == pytest.approx(-np.pi)
    with pytest.raises(TypeError, match="placement_grid"):
        gym.make("sensorplan/Navigate-v0", placement_grid=4)
    with pytest.raises(ValueError, match="action_type"):
        gym.make("sensorplan/Navigate-v0", action_type="mixed")


def _assert_vector_env_equals_single(env_id, actions, seed, **kw):
    """Step ``make_vec(..., "vector_entry_point")`` and one single env per sub-env with the same
    actions (``actions``: [step, env]); every observation and reward must agree.  Returns the
    vector env's ``terminated | truncated`` per step."""
    n = actions.shape[1]
    v = gym.make_vec(env_id, num_envs=n, vectorization_mode="vector_entry_point", **kw)
    s = [gym.make(env_id, **kw) for _ in range(n)]
    obs, _ = v.reset(seed=seed)
    for i, e in enumerate(s):
        assert np.array_equal(obs[i], e.reset(seed=seed + i)[0])
    ends = []
    for a in actions:
        obs, r, term, trunc, _ = v.step(a)
        ends.append(term | trunc)
        for i, e in enumerate(s):
            o, ri, *_ = e.step(a[i])
            assert np.array_equal(o, obs[i]) and ri == r[i]
    return np.array(ends)


def test_discrete_vector_env_equals_single():
    actions = np.random.default_rng(0).integers(0, 7, (30, 2))
    _assert_vector_env_equals_single(
        "sensorplan/Recognize-v0", actions, seed=5, action_type="discrete"
    )


def test_map_ranges_reveal_the_target():
    env = gym.make("sensorplan/Recognize-v0", map_ranges=True, n_beams=64)
    n = 64
    assert env.observation_space.shape == (8 + 4 * n,)
    env.reset(seed=0)
    u = env.unwrapped
    w = u.world
    p = w.region.representative_point()  # a recognizing placement sees the target
    u.pose = (p.x, p.y, 0.0)
    u.batch.sense(np.array([0]))
    obs = u.batch.observe(np.array([0]))[0]
    read, pred = obs[8 : 8 + n], obs[8 + 3 * n :]
    assert (read <= pred + 1e-6).all()  # the target only ever shortens a beam
    assert (read < pred - 1e-4).any()
    nav = gym.make("sensorplan/Navigate-v0", map_ranges=True)
    o, _ = nav.reset(seed=0)
    o = nav.step(nav.action_space.sample())[0]
    assert np.allclose(o[8:24], o[56:72])  # no target: the map predicts every reading
    with pytest.raises(ValueError, match="map_ranges"):
        gym.make("sensorplan/Navigate-v0", map_ranges=True, obs_type="grid")


def test_declare_hold_and_shaping():
    env = gym.make("sensorplan/Recognize-v0", declare_hold=3)
    env.reset(seed=0)
    a = np.array([0, 0, 0, -1], dtype=np.float32)
    z = np.zeros(4, dtype=np.float32)
    assert not env.step(a)[2]
    assert not env.step(z)[2]  # a pause starts the count again
    assert not env.step(a)[2] and not env.step(a)[2]
    _, r, term, _, info = env.step(a)
    assert term and info["declared"] == "G"
    with pytest.raises(ValueError, match="declare_hold"):
        gym.make("sensorplan/Recognize-v0", declare_hold=0)
    # shaping: potential-based, the shaped returns telescope to shaping * (d0 - dT) / D
    sh = gym.make("sensorplan/Recognize-v0", shaping=3.0, max_steps=15)
    base = gym.make("sensorplan/Recognize-v0", max_steps=15)
    _, i0 = sh.reset(seed=2)
    base.reset(seed=2)
    total = 0.0
    for _ in range(15):
        act = np.array([1.0, 0.3, 0.1, 0.0], dtype=np.float32)
        _, r1, *_, info = sh.step(act)
        _, r2, *_ = base.step(act)
        total += r1 - r2
    D = sh.unwrapped.world.diameter
    assert total == pytest.approx(3.0 * (i0["distance_to_region"] - info["distance_to_region"]) / D)
    assert total != 0.0


def test_oracle_with_declare_hold():
    from agents.planning.oracle import OraclePolicy

    env = gym.make("sensorplan/Recognize-v0", declare_hold=3)
    pol = OraclePolicy(env)
    ok = 0
    for seed in range(3):
        obs, _ = env.reset(seed=seed)
        pol.reset()
        for _ in range(200):
            obs, r, term, trunc, info = env.step(pol.predict(obs)[0])
            if term or trunc:
                break
        ok += bool(info["is_success"])
    assert ok == 3
    with pytest.raises(TypeError, match="continuous"):
        OraclePolicy(gym.make("sensorplan/Navigate-v0", action_type="discrete"))


@pytest.mark.parametrize("env_id", ["sensorplan/Navigate-v0", "sensorplan/Recognize-v0"])
def test_speed_limit_disc_caps_every_direction(env_id):
    """``speed_limit="box"`` moves sqrt(2) * max_speed along a diagonal; ``"disc"`` caps the
    translation's length at max_speed and leaves actions inside the disc alone."""
    moved = {}
    for limit in ("box", "disc"):
        env = gym.make(env_id, speed_limit=limit, max_speed=0.05)
        for a in ([1, 1], [0.6, -0.8], [0.3, 0.2], [-1, 0.5]):
            env.reset(seed=0)
            p0 = np.array(env.unwrapped.pose[:2])
            act = np.zeros(env.action_space.shape, dtype=np.float32)
            act[:2] = a
            info = env.step(act)[4]
            assert not info["collided"]
            moved[limit, tuple(a)] = np.hypot(*(np.array(env.unwrapped.pose[:2]) - p0)) / 0.05
    assert moved["box", (1, 1)] == pytest.approx(math.sqrt(2))
    assert moved["disc", (1, 1)] == pytest.approx(1.0)
    assert moved["box", (-1, 0.5)] == pytest.approx(math.hypot(1, 0.5))
    assert moved["disc", (-1, 0.5)] == pytest.approx(1.0)
    for a in ((0.6, -0.8), (0.3, 0.2)):  # inside the disc: the same motion under both
        assert moved["disc", a] == pytest.approx(moved["box", a]) == pytest.approx(math.hypot(*a))
    with pytest.raises(ValueError, match="speed_limit"):
        gym.make(env_id, speed_limit="square")


def test_disc_speed_limit_vector_env_equals_single():
    """The batched step applies ``speed_limit="disc"`` exactly as the single env does."""
    kw = {"speed_limit": "disc", "scene": "random", "min_start_distance": 0.35}
    kw["max_scene_tries"] = 200  # starts far from the region: 25 steps without an episode end
    actions = np.random.default_rng(2).uniform(-1.5, 1.5, (25, 3, 3)).astype(np.float32)
    ends = _assert_vector_env_equals_single("sensorplan/Navigate-v0", actions, seed=11, **kw)
    assert not ends.any()


def test_oracle_under_disc_speed_limit_drives_the_same_path():
    """The oracle knows the limit: under ``"disc"`` it drives the same shortest path in more
    steps (no diagonal shortcut) and still succeeds."""
    from agents.planning.oracle import OraclePolicy

    out = {}
    for limit in ("box", "disc"):
        env = gym.make("sensorplan/Navigate-v0", speed_limit=limit)
        pol = OraclePolicy(env)
        obs, _ = env.reset(seed=0)
        pol.reset()
        xy, path, steps, done = np.array(env.unwrapped.pose[:2]), 0.0, 0, False
        while not done:
            obs, r, term, trunc, info = env.step(pol.predict(obs)[0])
            nxt = np.array(info["pose"][:2])
            path, xy, steps, done = (
                path + float(np.hypot(*(nxt - xy))),
                nxt,
                steps + 1,
                term or trunc,
            )
        assert info["is_success"]
        out[limit] = (steps, path)
    assert out["disc"][0] > out["box"][0]
    assert out["disc"][1] == pytest.approx(out["box"][1], rel=0.02)


def test_map_evidence_points_at_the_right_region():
    """Driven by the oracle on lab, the evidence flags light up for the side the target is
    on, and never for the other (lab's swept hulls K_G and K_H are disjoint)."""
    import shapely

    from agents.planning.oracle import OraclePolicy

    env = gym.make("sensorplan/Recognize-v0", map_evidence=True, n_beams=32)
    n = 32
    assert env.observation_space.shape == (8 + 5 * n,)
    kg, kh = (shapely.Polygon(k) for k in env.unwrapped.world.must_see)
    assert not kg.intersects(kh)
    pol = OraclePolicy(env)
    right = 0
    for seed in range(4):
        obs, _ = env.reset(seed=seed)
        pol.reset()
        side = env.unwrapped._side
        for _ in range(200):
            ev = obs[8 + 3 * n :].reshape(2, n)
            assert not ev[1 if side == "G" else 0].any()
            right += ev[0 if side == "G" else 1].any()
            obs, _, term, trunc, _ = env.step(pol.predict(obs)[0])
            if term or trunc:
                break
    assert right >= 4


def test_noise_is_bounded_and_the_region_allows_for_it():
    """Range noise is a Gaussian truncated at 3 std (a sensor accurate to a known bound), and
    the world's region is computed for that accuracy (confusability allows for it)."""
    from sensorplan_gym.core.sensor import NOISE_BOUND

    sigma = 0.2
    noisy = gym.make("sensorplan/Navigate-v0", noise=sigma)
    clean = gym.make("sensorplan/Navigate-v0")
    w = noisy.unwrapped.world
    assert w.range_acc == pytest.approx(NOISE_BOUND * sigma)
    assert clean.unwrapped.world.range_acc == pytest.approx(1e-6 * w.diameter)
    noisy.reset(seed=0)
    clean.reset(seed=0)
    diffs = []
    for _ in range(60):
        a = np.array([0.3, 0.2, 0.4], dtype=np.float32)
        noisy.step(a)
        clean.step(a)
        d_n = noisy.unwrapped.scan[0]
        d_c = clean.unwrapped.scan[0]
        hit = noisy.unwrapped.scan[2] & (d_c < w.reach) & (d_n < w.reach)
        diffs.append(np.abs(d_n - d_c)[hit & (d_n > 0)])
    diffs = np.concatenate(diffs)
    assert diffs.max() <= NOISE_BOUND * sigma + 1e-12
    assert diffs.max() > 2 * sigma  # the tails are there, cut at the bound


def test_sensor_fov_observation_is_the_scenes_field_of_view():
    import math

    import gymnasium as gym

    for scene, fov in (("edr", 150.0), ("lab", None)):
        env = gym.make("sensorplan/Navigate-v0", scene=scene, sensor_fov=True)
        plain = gym.make("sensorplan/Navigate-v0", scene=scene)
        obs, _ = env.reset(seed=0)
        ref, _ = plain.reset(seed=0)
        assert env.observation_space.shape[0] == plain.observation_space.shape[0] + 1
        assert env.observation_space.contains(obs)
        np.testing.assert_array_equal(obs[:-1], ref)
        expect = math.degrees(env.unwrapped.world.fov) / 360.0
        assert obs[-1] == np.float32(expect)
        if fov is not None:
            assert math.isclose(expect, fov / 360.0)
    with pytest.raises(ValueError, match="sensor_fov"):
        gym.make("sensorplan/Navigate-v0", sensor_fov=1)
