"""The Gymnasium environments: API conformance, determinism, rendering, bad actions,
clipping, pickling, vectorisation, and the Placement reward against an independent
visibility oracle (pyvispoly, test-only)."""

from __future__ import annotations

import math
import pickle
import warnings

import gymnasium as gym
import numpy as np
import pytest
import shapely

import sensorplan_gym  # noqa: F401  (registers the ids)
from sensorplan_gym.registration import ENV_IDS

IDS = sorted(ENV_IDS)
OBS = ["vector", "grid"]

# Warnings we accept (message regexes), each with its reason.  Currently none: both
# checkers run clean for every id and observation type.  Add entries here only with a reason.
ALLOWED_WARNINGS: list[str] = []


def _make(env_id, **kw):
    return gym.make(env_id, **kw)


def _strict():
    warnings.simplefilter("error")
    for w in ALLOWED_WARNINGS:
        warnings.filterwarnings("ignore", message=f".*{w}.*")


@pytest.mark.parametrize("obs_type", OBS)
@pytest.mark.parametrize("env_id", IDS)
def test_gymnasium_check_env(env_id, obs_type):
    from gymnasium.utils.env_checker import check_env

    env = _make(env_id, obs_type=obs_type)
    with warnings.catch_warnings():
        _strict()
        check_env(env.unwrapped, skip_render_check=True)


@pytest.mark.parametrize("obs_type", OBS)
@pytest.mark.parametrize("env_id", IDS)
def test_sb3_check_env(env_id, obs_type):
    pytest.importorskip("stable_baselines3")
    from stable_baselines3.common.env_checker import check_env

    env = _make(env_id, obs_type=obs_type)
    with warnings.catch_warnings():
        _strict()
        check_env(env, warn=True)


def _rollout(env, seed, n=40):
    obs, info = env.reset(seed=seed)
    env.action_space.seed(seed)
    traj = [obs.copy()]
    for _ in range(n):
        obs, r, te, tr, info = env.step(env.action_space.sample())
        traj.append((obs.copy(), r, te, tr, info.get("is_success")))
        if te or tr:
            obs, info = env.reset()
            traj.append(obs.copy())
    return traj


def _same(a, b):
    assert len(a) == len(b)
    for x, y in zip(a, b, strict=True):
        if isinstance(x, tuple):
            np.testing.assert_array_equal(x[0], y[0])
            assert x[1:] == y[1:]
        else:
            np.testing.assert_array_equal(x, y)


@pytest.mark.parametrize("env_id", IDS)
def test_same_seed_same_trajectory(env_id):
    kw = dict(eps_pos=0.05, eps_aim=0.02, noise=0.01)
    a = _rollout(_make(env_id, **kw), seed=7)
    b = _rollout(_make(env_id, **kw), seed=7)
    _same(a, b)


def test_random_scene_deterministic():
    a = _rollout(_make("sensorplan/Navigate-v0", scene="random"), seed=3, n=10)
    b = _rollout(_make("sensorplan/Navigate-v0", scene="random"), seed=3, n=10)
    _same(a, b)


@pytest.mark.parametrize("env_id", IDS)
def test_render_rgb_array(env_id):
    env = _make(env_id, render_mode="rgb_array")
    env.reset(seed=0)
    env.step(env.action_space.sample())
    frame = env.render()
    assert frame.ndim == 3 and frame.shape[2] == 3 and frame.dtype == np.uint8
    assert frame.std() > 10  # not blank
    env.close()


def test_render_human_non_interactive():
    import matplotlib

    matplotlib.use("Agg")
    env = _make("sensorplan/Navigate-v0", render_mode="human")
    env.reset(seed=0)
    assert env.step(env.action_space.sample())[0] is not None
    assert env.render() is None
    env.close()


@pytest.mark.filterwarnings("ignore:.*render_mode.*:UserWarning")  # gymnasium's own notice
def test_bad_render_mode():
    with pytest.raises(ValueError, match="render_mode"):
        _make("sensorplan/Navigate-v0", render_mode="ascii")


@pytest.mark.parametrize("env_id", IDS)
def test_bad_actions_raise(env_id):
    env = _make(env_id).unwrapped
    env.reset(seed=0)
    n = env.action_space.shape[0]
    with pytest.raises(ValueError, match="NaN"):
        env.step(np.full(n, np.nan))
    with pytest.raises(ValueError, match="NaN or infinite"):
        env.step(np.r_[np.inf, np.zeros(n - 1)])
    with pytest.raises(ValueError, match="shape"):
        env.step(np.zeros(n + 1))
    with pytest.raises(ValueError, match="shape"):
        env.step(np.zeros((1, n)))
    with pytest.raises(ValueError):
        env.step("left")


@pytest.mark.parametrize("env_id", IDS)
def test_out_of_range_actions_are_clipped(env_id):
    a, b = _make(env_id).unwrapped, _make(env_id).unwrapped
    a.reset(seed=1)
    b.reset(seed=1)
    n = a.action_space.shape[0]
    big = np.array([5.0, -7.0, 3.0, 0.0][:n])
    clipped = np.clip(big, -1, 1)
    ra = a.step(big)
    rb = b.step(clipped)
    np.testing.assert_array_equal(ra[0], rb[0])
    assert ra[1:4] == rb[1:4]


@pytest.mark.parametrize("env_id", IDS)
def test_pickle_roundtrip(env_id):
    env = _make(env_id)
    env.reset(seed=5)
    env2 = pickle.loads(pickle.dumps(env))
    act = env.action_space.sample()
    o1 = env.step(act)
    o2 = env2.step(act)
    np.testing.assert_array_equal(o1[0], o2[0])
    assert o1[1:4] == o2[1:4]


def test_make_vec_async():
    envs = gym.make_vec(
        "sensorplan_gym:sensorplan/Navigate-v0", num_envs=2, vectorization_mode="async"
    )
    try:
        obs, info = envs.reset(seed=0)
        assert obs.shape == (2, *envs.single_observation_space.shape)
        for _ in range(5):
            obs, r, te, tr, info = envs.step(envs.action_space.sample())
        assert r.shape == (2,)
    finally:
        envs.close()


def test_sb3_subproc_vec_env():
    pytest.importorskip("stable_baselines3")
    from stable_baselines3.common.env_util import make_vec_env
    from stable_baselines3.common.vec_env import SubprocVecEnv

    venv = make_vec_env(
        "sensorplan_gym:sensorplan/Recognize-v0", n_envs=2, vec_env_cls=SubprocVecEnv
    )
    try:
        venv.reset()
        for _ in range(5):
            venv.step(np.stack([venv.action_space.sample() for _ in range(2)]))
    finally:
        venv.close()


def test_make_without_prior_import():
    import subprocess
    import sys

    code = (
        "import gymnasium as gym; e = gym.make('sensorplan_gym:sensorplan/Placement-v0'); "
        "e.reset(seed=0); print('ok')"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.stdout.strip() == "ok", out.stderr


# ---- semantics --------------------------------------------------------------------------


def test_unsupported_combination_fails_at_construction():
    with pytest.raises(NotImplementedError):
        _make("sensorplan/Navigate-v0", scene="corridor", model="partial", motion="rotating")
    with pytest.raises(ValueError, match="motion"):
        _make("sensorplan/Navigate-v0", motion="flying")
    with pytest.raises(ValueError, match="obs_type"):
        _make("sensorplan/Navigate-v0", obs_type="pixels")
    with pytest.raises(ValueError, match="unknown scene"):
        _make("sensorplan/Navigate-v0", scene="no-such-scene")


def test_partial_model_with_points_works():
    env = _make("sensorplan/Placement-v0", scene="lab", model="partial", motion="stationary")
    env.reset(seed=0)
    assert not env.unwrapped.world.region.is_empty
    env = _make("sensorplan/Navigate-v0", scene="corridor", model="partial")
    env.reset(seed=0)


@pytest.mark.parametrize("env_id", ["sensorplan/Navigate-v0", "sensorplan/Recognize-v0"])
@pytest.mark.parametrize("radius", [0.0, 0.25])
def test_no_passing_through_walls(env_id, radius):
    env = _make(env_id, scene="lab", robot_radius=radius, max_speed=1.5).unwrapped
    env.reset(seed=2)
    w = env.world
    rng = np.random.default_rng(0)
    space = w.free_space.buffer(-radius + 1e-9) if radius else w.free_space
    for _ in range(300):
        a = rng.uniform(-1, 1, env.action_space.shape)
        if a.shape[0] == 4:
            a[3] = 0.0
        x0, y0, _ = env.pose
        env.step(a)
        x, y, _ = env.pose
        path = shapely.LineString([(x0, y0), (x, y)]) if (x, y) != (x0, y0) else shapely.Point(x, y)
        assert space.covers(path), (x0, y0, x, y)
        if env_id.endswith("Recognize-v0"):
            tgt = shapely.Polygon(env._target_poly)
            assert tgt.distance(shapely.Point(x, y)) >= radius - 1e-9


def test_navigate_success_terminates_with_bonus():
    env = _make("sensorplan/Navigate-v0", scene="lab").unwrapped
    env.reset(seed=0)
    p = env.world.region.representative_point()
    _, info = env.reset(options={"start": (p.x, p.y, 0.0)})
    assert info["distance_to_region"] == 0.0
    obs, r, te, tr, info = env.step(np.zeros(3))
    assert info["recognizing"] and te and info["is_success"]
    assert r == pytest.approx(1.0 - 0.01)
    with pytest.raises(ValueError, match="free space"):
        env.reset(options={"start": (-5.0, -5.0, 0.0)})


def test_navigate_start_not_recognizing():
    for scene in sensorplan_gym.BUNDLED_SCENES:
        env = _make("sensorplan/Navigate-v0", scene=scene).unwrapped
        _, info = env.reset(seed=0)
        assert not info["recognizing"] and info["distance_to_region"] >= 0


def test_recognize_rewards_and_no_leak():
    env = _make("sensorplan/Recognize-v0", scene="lab").unwrapped
    for seed in range(6):
        obs, info = env.reset(seed=seed)
        assert "target_in" not in info
        side = env._side
        act = np.array([0.0, 0.0, 0.0, -1.0 if side == "G" else 1.0])
        _, r, te, tr, info = env.step(act)
        assert te and info["is_success"] and r == pytest.approx(1.0 - 0.01)
        env.reset(seed=seed)
        act[3] = -act[3]
        _, r, te, tr, info = env.step(act)
        assert te and not info["is_success"] and r == pytest.approx(-1.0 - 0.01)
    # the observation does not depend on the hidden side when the target is out of sight
    e = _make("sensorplan/Recognize-v0", scene="lab", fov_deg=30, n_beams=4).unwrapped
    seen = {}
    for seed in range(40):
        o, _ = e.reset(seed=seed)
        if not (e.scan[2] & (e.scan[0] < e.world.reach)).any():
            continue
        seen.setdefault(e._side, o)
    if len(seen) == 2:
        np.testing.assert_array_equal(seen["G"], seen["H"])


def test_recognize_timeout_is_wrong():
    env = _make("sensorplan/Recognize-v0", scene="lab", max_steps=5)
    env.reset(seed=0)
    for _ in range(5):
        _, r, te, tr, info = env.step(np.array([0.0, 0.0, 0.1, 0.0]))
    assert tr and not te and r == pytest.approx(-1.0 - 0.01) and not info["is_success"]
    assert info["target_in"] in ("G", "H")


def test_target_reflects_beams():
    env = _make("sensorplan/Recognize-v0", scene="corridor", n_beams=64).unwrapped
    env.reset(seed=0)
    w = env.world
    # put the robot in the recognizable region and compare with a scan of the empty scene
    p = w.region.representative_point()
    env.pose = (p.x, p.y, 0.0)
    env.batch.sense(np.array([0]))
    with_target = env.scan[0].copy()
    empty = env.sensor.read(env.pose, w.seg_set)[0]
    assert (with_target < empty - 1e-9).any()
    assert (with_target <= empty + 1e-9).all()


# ---- Placement reward vs an independent oracle ------------------------------------------


def _pv_visibility(free, p):
    import pyvispoly as pv

    comp = free
    if comp.geom_type == "MultiPolygon":
        comp = next(g for g in comp.geoms if g.covers(shapely.Point(p)))
    comp = shapely.geometry.polygon.orient(comp, 1.0)
    ext = [pv.Point(float(x), float(y)) for x, y in np.asarray(comp.exterior.coords)[:-1]]
    holes = [
        [pv.Point(float(x), float(y)) for x, y in np.asarray(r.coords)[:-1]] for r in comp.interiors
    ]
    P = pv.PolygonWithHoles(ext, holes) if holes else pv.PolygonWithHoles(ext)
    vp = pv.VisibilityPolygonCalculator(P).compute_visibility_polygon(pv.Point(*p))
    return shapely.Polygon([(float(q.x()), float(q.y())) for q in vp.boundary()])


def _oracle_reward(scene, p, psi, fov, tgt, G, H):
    """1 iff the convex hulls CH(A + G) and CH(A + H) lie in V(p) and, for every aim in the
    field of view, all hull vertices' bearings are inside psi +- fov / 2."""
    hulls = []
    for g in (G, H):
        pts = np.asarray(shapely.get_coordinates(g.convex_hull))
        pts = (pts[:, None, :] + tgt[None]).reshape(-1, 2)
        hulls.append(shapely.MultiPoint(pts).convex_hull)
    if any(h.intersects(shapely.Point(p)) for h in hulls):
        return 0
    V = _pv_visibility(scene.free_space, p).buffer(1e-9 * scene.diameter)
    if not all(V.covers(h) for h in hulls):
        return 0
    if fov < 2 * math.pi:
        for h in hulls:
            c = np.asarray(h.exterior.coords)
            b = np.arctan2(c[:, 1] - p[1], c[:, 0] - p[0]) - psi
            b = (b + math.pi) % (2 * math.pi) - math.pi
            if np.abs(b).max() > fov / 2:
                return 0
    return 1


@pytest.mark.parametrize("scene", ["lab", "edr"])
def test_placement_reward_matches_pyvispoly(scene):
    pytest.importorskip("pyvispoly")
    env = _make("sensorplan/Placement-v0", scene=scene).unwrapped
    env.reset(seed=0)
    w = env.world
    sc = w.scene
    rng = np.random.default_rng(42)
    boundary = w.region.boundary
    hulls_b = [shapely.Polygon(K).boundary for K in w.must_see]
    tol = 1e-3 * w.diameter
    checked = agree = positives = 0
    while checked < 150:
        a = rng.uniform(-1, 1, 3)
        x, y, psi = env.action_to_pose(a)
        if rng.random() < 0.5:  # aim near the middle of G and H half of the time
            psi = w.best_aim(x, y) + rng.uniform(-0.4, 0.4)
            a = env.pose_to_action((x, y, psi)).astype(np.float64)
            x, y, psi = env.action_to_pose(a)
        pt = shapely.Point(x, y)
        if not w.free_space.contains(pt) or boundary.distance(pt) < tol:
            continue
        if any(hb.distance(pt) < tol for hb in hulls_b):
            continue
        # stay away from the field-of-view edges too
        if w.fov < 2 * math.pi:
            near_edge = False
            for K in w.must_see:
                b = np.arctan2(K[:, 1] - y, K[:, 0] - x) - psi
                b = (b + math.pi) % (2 * math.pi) - math.pi
                if np.any(np.abs(np.abs(b) - w.fov / 2) < 1e-3):
                    near_edge = True
            if near_edge:
                continue
        env.reset()
        _, r, *_ = env.step(a)
        want = _oracle_reward(sc, (x, y), psi, w.fov, w.target, w.goal_geom, w.failure_geom)
        checked += 1
        agree += int(r == want)
        positives += want
    assert agree == checked, f"{checked - agree} of {checked} placements disagree"
    assert positives > 0


def test_placement_reward_positive_at_best_aim():
    env = _make("sensorplan/Placement-v0", scene="edr").unwrapped
    env.reset(seed=0)
    w = env.world
    p = w.region.representative_point()
    pose = (p.x, p.y, w.best_aim(p.x, p.y))
    assert env.evaluate(pose)["in_region"]
    shaped = _make("sensorplan/Placement-v0", scene="edr", shaping=1.0).unwrapped
    shaped.reset(seed=0)
    _, r, *_ = shaped.step(np.array([-1.0, -1.0, 0.0]))
    assert r < 0


def test_render_rollout_png(tmp_path):
    from sensorplan_gym.render_rollout import main

    out = tmp_path / "rollout.png"
    main(["--env", "sensorplan/Recognize-v0", "--out", str(out), "--steps", "3", "--frames", "2"])
    import matplotlib.image

    img = matplotlib.image.imread(out)
    assert img.ndim == 3 and img.shape[0] > 100 and img.shape[1] > 200


@pytest.mark.parametrize("motion", ["stationary", "translating", "rotating"])
def test_motions_complete_model(motion):
    env = _make("sensorplan/Recognize-v0", scene="lab", motion=motion, eps_pos=0.05).unwrapped
    sides = set()
    for seed in range(6):
        env.reset(seed=seed)
        sides.add(env._side)
        tgt = shapely.Polygon(env._target_poly)
        region = env.world.goal_geom if env._side == "G" else env.world.failure_geom
        # the target's reference point lies in its region: A_q within r_A of the region
        assert region.buffer(env.world.target_radius + 1e-9).covers(tgt)
        env.step(np.array([0.5, 0.0, 0.2, 0.0]))
    assert sides == {"G", "H"}
    if motion == "stationary":
        assert env.world.goal_geom.geom_type == "Point"
    assert (env.world.theta is None) == (motion == "rotating")
