"""``aim_features``: the arcs of directions K_G and K_H cover from the robot, checked against a
brute force over directions and against the env's own exact aim test."""

from __future__ import annotations

import math

import gymnasium as gym
import numpy as np
import pytest

import sensorplan_gym  # noqa: F401
from sensorplan_gym.core.queries import aim_ok_batch, hull_arcs, joint_arc

TAU = 2 * math.pi


def _covered(theta, start, width):
    return ((theta - start) % TAU) <= width + 1e-12


def test_joint_arc_is_the_shortest_cover():
    rng = np.random.default_rng(0)
    theta = np.linspace(0, TAU, 7200, endpoint=False)
    for _ in range(300):
        s = rng.uniform(0, TAU, 2)
        w = rng.uniform(0, 3.5, 2)
        js, jw = joint_arc(s[None], w[None])
        cov = _covered(theta, s[0], w[0]) | _covered(theta, s[1], w[1])
        assert not (cov & ~_covered(theta, js[0], jw[0] + 1e-9)).any()
        if cov.all():
            assert jw[0] == TAU
            continue
        # the complement's longest run (cyclic) is the gap the cover leaves out
        run = best = 0
        for v in np.concatenate([~cov, ~cov]):
            run = run + 1 if v else 0
            best = max(best, min(run, len(theta)))
        assert abs(jw[0] - (TAU - best * TAU / len(theta))) < 3 * TAU / len(theta)


def test_hull_arcs_brute_force():
    rng = np.random.default_rng(1)
    sq = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
    hulls = np.stack([sq * 1.5 + [2.0, -0.5], sq + [-3.0, 1.0]])[None]
    for _ in range(200):
        x, y = rng.uniform(-5, 5, 2)
        start, width = hull_arcs(hulls, np.array([x]), np.array([y]))
        for m in range(2):
            h = hulls[0, m]
            inside = (h[:, 0].min() <= x <= h[:, 0].max()) and (h[:, 1].min() <= y <= h[:, 1].max())
            if inside:
                assert width[0, m] == TAU
                continue
            ang = np.arctan2(h[:, 1] - y, h[:, 0] - x)
            assert _covered(ang, start[0, m] - 1e-12, width[0, m] + 2e-12).all()
            # tight: both ends of the arc are vertex directions
            ends = np.array([start[0, m], start[0, m] + width[0, m]])
            gap = np.abs((ang[None, :] - ends[:, None] + math.pi) % TAU - math.pi).min(axis=1)
            assert (gap < 1e-12).all()


@pytest.mark.parametrize("env_id", ["sensorplan/Navigate-v0", "sensorplan/Recognize-v0"])
def test_aim_features_in_the_env(env_id):
    env = gym.make(env_id, scene="lab", aim_features=True, fov_deg=120.0, eps_aim=0.0, eps_pos=0.0)
    base = gym.make(env_id, scene="lab", fov_deg=120.0, eps_aim=0.0, eps_pos=0.0)
    obs, _ = env.reset(seed=3)
    obs0, _ = base.reset(seed=3)
    assert obs.shape == (obs0.shape[0] + 10,)
    np.testing.assert_array_equal(obs[: obs0.shape[0]], obs0)
    w = env.unwrapped.world
    r = w.batch_rows()
    rng = np.random.default_rng(2)
    checked = 0
    for _ in range(60):
        a = rng.uniform(-1, 1, env.action_space.shape).astype(np.float32)
        a[3:] = 0.0  # Recognize: no declaration
        obs, _, term, trunc, _ = env.step(a)
        if term or trunc:
            break
        assert env.observation_space.contains(obs)
        x, y, psi = env.unwrapped.pose
        f = obs[-10:].astype(np.float64)
        centre = psi + math.atan2(f[1], f[0])
        width = f[2] * TAU
        ok = aim_ok_batch(
            np.array([x]), np.array([y]), np.array([centre]), r["hulls"][None],
            r["centers"][None], fov=w.fov, eps_aim=0.0, eps_pos=0.0, max_range=w.max_range,
        )[0]  # fmt: skip
        # aiming at the joint arc's centre keeps both hulls in view iff the arc fits the view
        if width < w.fov - 1e-4:
            assert ok
            checked += 1
        elif width > w.fov + 1e-4:
            assert not ok
            checked += 1
    assert checked > 20


def test_aim_features_need_vector_obs():
    with pytest.raises(ValueError, match="aim_features=True needs obs_type='vector'"):
        gym.make("sensorplan/Navigate-v0", obs_type="grid", aim_features=True)
    with pytest.raises(ValueError, match="aim_features=True needs"):
        gym.make("sensorplan/Placement-v0", aim_features=True)
