"""The pixel policy of Placement (agents.learning.pixel_bc): labels, symmetries, learning."""

from __future__ import annotations

import json
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

torch = pytest.importorskip("torch")
pytest.importorskip("yaml")

import sensorplan_gym  # noqa: E402, F401
from agents.learning import pixel_bc  # noqa: E402
from sensorplan_gym.envs.placement import PlacementBatch  # noqa: E402

SCENES = Path(__file__).resolve().parents[2] / "sensorplan_gym" / "scenes"


def _turned(d: dict, k: int, flip: bool) -> dict:
    """The scene dict turned ``k`` quarter turns counter-clockwise about its bounding box's
    centre, then mirrored in x (the target's shape about its reference point too)."""
    b = np.asarray(d["bounds"], dtype=float)
    c = 0.5 * (b.min(axis=0) + b.max(axis=0))

    def ring(pts, about=c):
        p = np.asarray(pts, dtype=float) - about
        for _ in range(k):
            p = np.stack([-p[:, 1], p[:, 0]], axis=1)
        if flip:
            p[:, 0] = -p[:, 0]
            p = p[::-1]
        return (p + about).tolist()

    out = dict(d)
    out["bounds"] = ring(d["bounds"])
    out["obstacles"] = [ring(o) for o in d["obstacles"]]
    out["target"] = ring(d["target"], np.zeros(2))
    out["goal"] = ring(d["goal"])
    out["failure"] = ring(d["failure"])
    out.pop("start", None)
    return out


@pytest.mark.parametrize(("k", "flip", "aims"), [(1, False, False), (2, True, False),
                                               (1, True, True), (3, False, True)])  # fmt: skip
def test_augmentation_is_the_labels_of_the_turned_scene(k, flip, aims):
    """A symmetry of the square applied to a scene's observation and valid-action mask (the
    aims follow: a quarter turn adds A / 4, a mirror maps aim k to A / 2 - k) equals the
    observation and the exact labels of the scene turned the same way; with ``aim_views``
    the aim planes are permuted like the aims."""
    d = json.loads((SCENES / "edr.json").read_text())
    d["sensor"] = {**d["sensor"], "fov_deg": 120}
    extra = {"aim_views": True, "hull_views": True} if aims else {}
    aim = pixel_bc.aim_channels(extra)
    assert (aim is not None) == aims
    o0, m0 = pixel_bc.scene_data({"scene": d, **extra})
    o1, m1 = pixel_bc.scene_data({"scene": _turned(d, k, flip), **extra})
    oa, ma = pixel_bc._augment(o0[0], m0[0], k, flip, aim)
    if aims:
        lo, hi = aim
        assert hi - lo == m0.shape[-1] == 16 and o0.shape[1] == hi + 2
        assert 0 < (oa[lo:hi] > 0).mean() < 0.9
        assert (oa[lo:hi] != o1[0, lo:hi]).mean() < 0.01
    assert 0 < m0.sum() < m0.size // 4
    # pixel centres on a region's edge can go either way after the turn's rounding
    assert (ma != m1[0]).mean() < 2e-4
    assert (oa != o1[0]).mean() < 0.01


def test_valid_actions_are_the_env_rewards():
    """The mask is the env's reward of each pixel action, played one by one."""
    env = gym.make(
        "sensorplan/Placement-v0", scene="edr", disable_env_checker=True, **pixel_bc.ENV_KWARGS
    )
    env.reset(seed=0)
    mask = pixel_bc.valid_actions(env.unwrapped.batch, 0).reshape(-1)
    rng = np.random.default_rng(0)
    picks = np.concatenate(
        [rng.choice(np.flatnonzero(mask), 20), rng.choice(np.flatnonzero(~mask), 20)]
    )
    for a in picks:
        env.reset()
        _, r, *_ = env.step(int(a))
        assert (r > 0.5) == mask[a]


def test_fit_learns_a_small_pool_and_round_trips(tmp_path):
    """On a tiny pool the set likelihood drives the arg-max into the valid set of the
    training scenes; the saved policy loads and acts the same."""
    kw = {"scene": "random", "scene_pool_size": 6, "scene_pool_seed": 3}
    obs, masks = pixel_bc.scene_data(kw)
    solvable = masks.reshape(len(masks), -1).any(axis=1)
    assert solvable.sum() >= 3
    net = pixel_bc.fit(obs, masks, epochs=60, batch_size=6, width=16, augment=False, log=None)
    pol = pixel_bc.PixelPolicy(net)
    act, _ = pol.predict(obs)
    hit = masks.reshape(len(masks), -1)[np.arange(len(obs)), act]
    assert hit[solvable].mean() >= 0.8
    cfg = {"env_id": pixel_bc.ENV_ID, "env_kwargs": {**kw, **pixel_bc.ENV_KWARGS}}
    path = pol.save(tmp_path / "m.pt", cfg)
    again, _ = pixel_bc.PixelPolicy.load(path).predict(obs)
    assert np.array_equal(act, again)


def test_pixel_actions_reject_bad_input():
    with pytest.raises(ValueError, match="Placement's"):
        gym.make("sensorplan/Navigate-v0", action_type="pixel")
    with pytest.raises(ValueError, match="grid_size, not placement_grid"):
        PlacementBatch(1, scene="edr", action_type="pixel", placement_grid=8)
    with pytest.raises(ValueError, match="grid_views=True needs obs_type='grid'"):
        PlacementBatch(1, scene="edr", grid_views=True)


def test_evaluate_loads_a_pixel_policy(tmp_path):
    """``sensorplan evaluate`` / ``benchmark`` play a saved pixel policy with its own
    observation and action kwargs (from the config beside it); a ``.pt`` without that
    config is refused by name."""
    from agents.evaluation.evaluate import evaluate
    from agents.learning.policies import check_policies, load_policy

    kw = {"scene": "random", "scene_pool_size": 4, "scene_pool_seed": 5, "grid_size": 40}
    obs, masks = pixel_bc.scene_data(kw)
    net = pixel_bc.fit(obs, masks, epochs=2, batch_size=4, width=8, log=None)
    cfg = {"env_id": pixel_bc.ENV_ID, "env_kwargs": {**pixel_bc.ENV_KWARGS, **kw}}
    path = pixel_bc.PixelPolicy(net).save(tmp_path / "final_model.pt", cfg)
    res = evaluate(
        pixel_bc.ENV_ID, [str(path), "oracle"], episodes=3, env_kwargs={"scene": "edr"},
        out=False, plot=False, verbose=False,
    )  # fmt: skip
    assert [p["episodes"] for p in res["policies"]] == [3, 3]
    env = gym.make(pixel_bc.ENV_ID, scene="edr", disable_env_checker=True, **pixel_bc.ENV_KWARGS)
    assert isinstance(load_policy(str(path), env), pixel_bc.PixelPolicy)
    bare = tmp_path / "bare.pt"
    bare.write_bytes(path.read_bytes())
    with pytest.raises(ValueError, match="algo: pixel_bc"):
        check_policies([str(bare)])


@pytest.mark.parametrize("aims", [False, True])
def test_symmetric_policy_is_equivariant(aims):
    """With ``symmetries`` the policy's log-probabilities of a turned and mirrored scene are
    the scene's own, turned and mirrored (aims too, and the aim planes with them); without, a
    fresh net is not."""
    extra = {"aim_views": True, "fov_deg": 90.0} if aims else {}
    aim = pixel_bc.aim_channels(extra)
    obs, masks = pixel_bc.scene_data({"scene": "edr", "grid_size": 40, **extra})
    torch.manual_seed(0)
    net = pixel_bc.PixelNet(obs.shape[1], masks.shape[-1], width=8)
    shape = masks.shape  # (1, S, S, A)
    for sym in (True, False):
        pol = pixel_bc.PixelPolicy(net, symmetries=sym, aim=aim)
        lp = pol.log_probs(obs).reshape(shape)
        o2, _ = pixel_bc._augment(obs[0], masks[0], 1, True, aim)
        lp2 = pol.log_probs(o2[None]).reshape(shape)
        _, want = pixel_bc._augment(obs[0], lp[0], 1, True)
        assert np.allclose(lp2[0], want, atol=1e-4) == sym


def test_cli_fits_on_the_device_asked(tmp_path):
    """``--device auto`` takes CUDA where there is one and the CPU here; the config beside
    the model says which, and the model loads on the CPU either way."""
    import torch
    import yaml

    pixel_bc.main(
        ["--difficulty", "easy", "--pool-size", "2", "--epochs", "1", "--width", "8",
         "--device", "auto", "--aim-views", "--out", str(tmp_path)]
    )  # fmt: skip
    cfg = yaml.safe_load((tmp_path / "final_model.yaml").read_text())
    assert cfg["fit_device"] == ("cuda" if torch.cuda.is_available() else "cpu")
    assert cfg["env_kwargs"]["aim_views"] is True and cfg["net"]["aim_channels"] == [5, 21]
    pol = pixel_bc.PixelPolicy.load(tmp_path / "final_model.pt")
    assert next(pol.net.parameters()).device.type == "cpu"
    assert pol.aim == (5, 21)


def test_channel_rule_plays_right_actions_from_the_channels():
    """The fixed rule over the hull-view and aim planes picks a right action on the bundled
    scenes (every right action there sees both hulls' corners), and action 0 where no pixel
    qualifies."""
    kw = {"hull_views": True, "aim_views": True}
    aim = pixel_bc.aim_channels(kw)
    for scene in ("lab", "edr"):
        obs, masks = pixel_bc.scene_data({"scene": scene, **kw})
        act = pixel_bc.channel_rule(obs, aim)
        assert masks.reshape(1, -1)[0, act[0]]
    blank = obs.copy()
    blank[:, aim[0] : aim[1]] = 0
    assert pixel_bc.channel_rule(blank, aim).tolist() == [0]


def test_cli_fits_several_seeds_on_one_pool(tmp_path):
    """``--seeds`` labels the pool once and fits once per seed, into ``seed_<s>/``."""
    import yaml

    pixel_bc.main(
        ["--difficulty", "easy", "--pool-size", "2", "--epochs", "1", "--width", "8",
         "--seeds", "3", "4", "--out", str(tmp_path)]
    )  # fmt: skip
    cfgs = [
        yaml.safe_load((tmp_path / f"seed_{s}" / "final_model.yaml").read_text()) for s in (3, 4)
    ]
    assert [c["seed"] for c in cfgs] == [3, 4]
    assert cfgs[0]["wall_time_s"]["label"] == cfgs[1]["wall_time_s"]["label"]
