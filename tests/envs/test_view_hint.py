"""``view_hint``: the way to the poses that see every corner of K_G and K_H with a passing aim
(map geometry, :meth:`World.hint_field`), at the end of Navigate/Recognize vector observations."""

from __future__ import annotations

import gymnasium as gym
import numpy as np
import pytest
import shapely
from gymnasium.utils.env_checker import check_env

import sensorplan_gym  # noqa: F401
from sensorplan_gym.core.world import HINT_SIZE

KW = {"self_features": True, "aim_features": True}


def _world(scene: str):
    env = gym.make("sensorplan/Navigate-v0", scene=scene, view_hint=True, **KW)
    env.reset(seed=0)
    return env, env.unwrapped.world


def test_space_and_check_env():
    plain = gym.make("sensorplan/Recognize-v0", scene="lab", **KW)
    env = gym.make("sensorplan/Recognize-v0", scene="lab", view_hint=True, **KW)
    check_env(env.unwrapped, skip_render_check=True)
    a, _ = plain.reset(seed=3)
    b, _ = env.reset(seed=3)
    assert b.shape[0] == a.shape[0] + 3 and np.array_equal(b[:-3], a)
    assert np.array_equal(env.observation_space.low[-3:], [-1, -1, 0])
    hx, hy, d = b[-3:]
    assert abs(np.hypot(hx, hy) - 1) < 1e-6 and 0 < d < 1


def test_field_targets_and_descent():
    """Distance 0 exactly on the target pixels (free, every hull corner seen, some aim
    passes, outside both hulls); elsewhere finite distances fall along the field's
    waypoints; the target pixels lie in the recognizable region (all but a sliver)."""
    _, w = _world("lab")
    ways, dist = w.hint_field()
    s = HINT_SIZE
    scale, ox, oy = w.grid_transform(s)
    ij = np.arange(s) + 0.5
    X, Y = np.meshgrid(ox + ij / scale, oy + (s - ij) / scale)
    space = shapely.contains_xy(w.robot_space, X, Y)
    hv = w.hull_view_raster(s)
    goal = space & (hv[0] > 0) & (hv[1] > 0) & (w.aim_raster(s, 16) > 0).any(axis=0)
    assert goal.sum() > 100
    assert np.array_equal(dist[space] == 0, goal[space])
    assert shapely.contains_xy(w.region, X[goal], Y[goal]).mean() > 0.99
    fin = space & np.isfinite(dist) & ~goal
    i, j = w.to_cell(s, ways[-1, ..., 0][fin], ways[-1, ..., 1][fin])
    assert (dist[i, j] < dist[fin]).all()  # one step of descent gets closer


@pytest.mark.parametrize("scene", ["lab", "warehouse"])
def test_following_the_hint_recognizes(scene):
    """A fixed controller -- move along the hint, slow down near its end, turn toward the
    joint arc of K_G and K_H (``aim_features``) -- reaches a recognizing pose from random
    starts: the hint leads where the exact reward says the pose tells G from H."""
    env = gym.make("sensorplan/Navigate-v0", scene=scene, random_start=True, view_hint=True, **KW)
    wins = 0
    for e in range(5):
        o, info = env.reset(seed=100 + e)
        for _ in range(200):
            hx, hy, d = o[-3:]
            jc, js = o[-13], o[-12]
            speed = min(1.0, d / 0.03)
            turn = np.clip(np.arctan2(js, jc) / 0.5, -1, 1)
            o, _, term, trunc, info = env.step(np.array([hx * speed, hy * speed, turn], "f4"))
            if term or trunc:
                break
        wins += bool(info["is_success"])
    assert wins == 5


def test_view_hint_needs_a_robot_vector_observation():
    with pytest.raises(ValueError, match="view_hint=True needs obs_type='vector'"):
        gym.make("sensorplan/Placement-v0", scene="edr", view_hint=True)
    with pytest.raises(ValueError, match="view_hint"):
        gym.make("sensorplan/Navigate-v0", scene="edr", obs_type="grid", view_hint=True)


def test_hint_rule_is_a_policy_spec():
    """``"hint-rule"`` is played by ``evaluate`` with its observation kwargs merged under the
    user's; it refuses an env without them."""
    pytest.importorskip("yaml")
    from agents.evaluation.evaluate import evaluate
    from agents.planning.hint_rule import HintRulePolicy

    res = evaluate(
        "sensorplan/Navigate-v0", ["hint-rule", "oracle"], episodes=4,
        env_kwargs={"scene": "lab", "random_start": True}, out=False, plot=False, verbose=False,
    )  # fmt: skip
    rule = res["policies"][0]
    assert rule["kind"] == "rule" and rule["success_rate"] == 1.0
    with pytest.raises(ValueError, match="view_hint=True and aim_features=True"):
        HintRulePolicy(gym.make("sensorplan/Navigate-v0", scene="lab", view_hint=True))
    with pytest.raises(ValueError, match="Recognize-v0 made with .*map_evidence=True"):
        HintRulePolicy(gym.make("sensorplan/Recognize-v0", scene="lab", view_hint=True,
                                aim_features=True))  # fmt: skip
    with pytest.raises(ValueError, match="Navigate-v0 and Recognize-v0"):
        HintRulePolicy(gym.make("sensorplan/Placement-v0", scene="lab"))


def test_hint_rule_declares_in_recognize():
    """In Recognize-v0 the rule drives along the hint and declares the side its evidence
    flags show: right on lab from random starts (16 beams over 360 degrees: it sweeps them
    over the gaps between them) and with a 75-degree sensor (the narrowest of the benchmark's
    ``narrow`` splits at which lab has a recognizing pose)."""
    pytest.importorskip("yaml")
    from agents.evaluation.evaluate import evaluate

    for extra in ({}, {"fov_deg": 75.0}):
        res = evaluate(
            "sensorplan/Recognize-v0", ["hint-rule"], episodes=12, out=False, plot=False,
            verbose=False, env_kwargs={"scene": "lab", "random_start": True, **extra},
        )  # fmt: skip
        assert res["policies"][0]["success_rate"] == 1.0, extra


def test_hint_rule_reads_the_evidence_flags():
    """The decide command follows the flags of the last frame: G only -> G, H only -> H,
    none or both (a beam in both hulls) -> go on, standing still while pointing."""
    from agents.planning.hint_rule import POINT_G, POINT_H, RECOGNIZE_KWARGS, HintRulePolicy

    env = gym.make("sensorplan/Recognize-v0", scene="lab", self_features=True,
                   **RECOGNIZE_KWARGS)  # fmt: skip
    rule = HintRulePolicy(env)
    o, _ = env.reset(seed=0)
    n = env.unwrapped.batch.sensor(0).n_beams
    o = np.tile(o, (4, 1))
    ev = rule.evidence
    flags = np.zeros((4, 2 * n))
    flags[0, 3] = 1  # a G beam
    flags[1, n + 5] = 1  # an H beam
    flags[3, [2, n + 2]] = 1  # one beam in both hulls
    o[:, ev] = flags
    a, _ = rule.predict(o)
    assert a[:, 3].tolist() == [POINT_G, POINT_H, 0.0, 0.0]
    assert np.all(a[:2, :3] == 0.0)
    # stacked frames: the rule reads the last one
    b, _ = rule.predict(np.concatenate([np.zeros_like(o), o], axis=1))
    np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize(
    ("env_id", "name"),
    [
        ("sensorplan/Navigate-v0", "ppo_navigate_hint"),
        ("sensorplan/Navigate-v0", "dagger_navigate_hint"),
        ("sensorplan/Recognize-v0", "ppo_recognize_hint"),
    ],
)
def test_shipped_hint_policies_play_with_their_observation(env_id, name):
    """The shipped ``view_hint`` policies are played with the observation kwargs of their
    configs (frame stacking too) on a bundled scene they never trained on, and succeed."""
    pytest.importorskip("stable_baselines3")
    from pathlib import Path

    from agents.evaluation.evaluate import evaluate

    model = Path(__file__).resolve().parents[2] / "agents" / "pretrained" / f"{name}.zip"
    res = evaluate(
        env_id, [str(model)], episodes=6, env_kwargs={"scene": "lab", "random_start": True},
        out=False, plot=False, verbose=False,
    )  # fmt: skip
    p = res["policies"][0]
    assert p["play_env_kwargs"]["view_hint"] is True and p["successes"] >= 5


def _thin_wall_scene(width: float = 0.02) -> dict:
    """A 20 x 10 room split by a wall ``width`` thick (a crack in the bounds, far thinner than
    a hint pixel of 20 / 128) from the floor up to y = 8; G and H on its left."""
    return {
        "name": "thin_wall",
        "bounds": [
            [0, 0],
            [10, 0],
            [10, 8],
            [10 + width, 8],
            [10 + width, 0],
            [20, 0],
            [20, 10],
            [0, 10],
        ],  # fmt: skip
        "obstacles": [],
        "target": [[-0.3, -0.2], [0.3, -0.2], [0.3, 0.2], [-0.3, 0.2]],
        "goal": [[3.0, 3.0]],
        "failure": [[3.0, 7.0]],
        "start": [10.3, 2.0, 0.0],
    }


def test_hint_does_not_lead_through_a_wall_thinner_than_a_pixel():
    """A wall holds no pixel centre when it is thinner than a pixel: the grid path must
    still go round it (through the opening at the top), the pose beside the wall must follow
    a pixel on its own side, and the hint rule must get there."""
    from agents.planning.hint_rule import HintRulePolicy

    env = gym.make("sensorplan/Navigate-v0", scene=_thin_wall_scene(), view_hint=True, **KW)
    o, _ = env.reset(seed=0)
    w = env.unwrapped.world
    assert 20 / HINT_SIZE > 5 * 0.02  # the wall is far thinner than a pixel
    hx, hy, d = o[-3:]
    # robot frame = world frame at heading 0: up toward the opening, not left through the wall
    assert hy > 0.7 and hx > -0.5, (hx, hy)
    # the way on is at least the way round the wall's end (up 6, across, down to the region)
    assert d * w.diameter > 6.0
    # the pixel followed lies on the start's side of the wall
    i, j = w.hint_cells(np.array([10.3]), np.array([2.0]))
    X, _ = w.pixel_centres(HINT_SIZE)
    assert X[i[0], j[0]] > 10.02
    policy = HintRulePolicy(env)
    for _ in range(200):
        a, _ = policy.predict(o)
        o, _, term, trunc, info = env.step(a)
        if term or trunc:
            break
    assert info["is_success"], info


def test_hint_aim_false_leads_to_views_without_a_joint_aim():
    """``hint_aim=False`` (Recognize-v0): on lab with a 50-degree sensor no pose sees both
    hulls in one aim, so the joint hint says "none reachable" (way 1, zero direction), while
    the hint with no joint aim asked leads somewhere, and the rule that turns to each hull in
    turn (``hint-rule-turn``) recognizes from there where the joint one cannot; Navigate-v0
    (whose success is a joint view) and a missing ``view_hint`` are refused."""
    pytest.importorskip("yaml")
    from agents.evaluation.evaluate import evaluate

    ways = []
    for aim in (True, False):
        env = gym.make("sensorplan/Recognize-v0", scene="lab", fov_deg=50.0, view_hint=True,
                       hint_aim=aim)  # fmt: skip
        o, _ = env.reset(seed=0)
        ways.append(o[-3:])
    assert ways[0].tolist() == [0.0, 0.0, 1.0]
    assert 0.0 < ways[1][2] < 1.0 and np.hypot(*ways[1][:2]) > 0.99
    rates = [
        evaluate(
            "sensorplan/Recognize-v0", [spec], episodes=8, out=False, plot=False, verbose=False,
            env_kwargs={"scene": "lab", "random_start": True, "fov_deg": 50.0},
        )["policies"][0]["success_rate"]
        for spec in ("hint-rule", "hint-rule-turn")
    ]  # fmt: skip
    assert rates[1] == 1.0 and rates[0] < 0.5, rates
    with pytest.raises(ValueError, match="NavigateEnv needs one aim at both hulls"):
        gym.make("sensorplan/Navigate-v0", scene="lab", view_hint=True, hint_aim=False)
    with pytest.raises(ValueError, match="hint_aim=False needs view_hint=True"):
        gym.make("sensorplan/Recognize-v0", scene="lab", hint_aim=False)
    with pytest.raises(ValueError, match="hint_aim must be True or False"):
        gym.make("sensorplan/Recognize-v0", scene="lab", view_hint=True, hint_aim="no")
