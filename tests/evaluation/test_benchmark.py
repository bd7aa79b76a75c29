"""``sensorplan benchmark``: named splits (disjoint procedural pools, bundled scenes), the
difficulty knob, and the combined table files."""

from __future__ import annotations

import json

import gymnasium as gym
import numpy as np
import pytest

import sensorplan_gym  # noqa: F401
from agents.evaluation.benchmark import TEST_POOL_SEED, TRAIN_POOL_SEED, benchmark, splits


def test_splits_are_disjoint_and_named():
    sp = splits(["train", "test", "ood"], 0.3, needs_start=True)
    assert sp["train"]["scene_pool_seed"] == TRAIN_POOL_SEED != TEST_POOL_SEED
    assert sp["test"]["min_start_distance"] == 0.3
    assert {"ood:lab", "ood:edr"} <= set(sp)
    assert "min_start_distance" not in splits(["test"], 0.3, needs_start=False)["test"]
    with pytest.raises(ValueError, match="unknown split"):
        splits(["holdout"], 0.3, True)


def test_difficulty_knob_moves_the_start_away():
    kw = dict(scene="random", scene_pool_size=4, scene_pool_seed=7)
    easy = gym.make("sensorplan/Navigate-v0", **kw)
    hard = gym.make("sensorplan/Navigate-v0", min_start_distance=0.3, max_scene_tries=200, **kw)
    d_hard = []
    for s in range(6):
        _, i = hard.reset(seed=s)
        d_hard.append(i["distance_to_region"] / hard.unwrapped.world.diameter)
    assert min(d_hard) >= 0.3
    d_easy = [easy.reset(seed=s)[1]["distance_to_region"] for s in range(6)]
    assert np.mean(d_easy) / easy.unwrapped.world.diameter < np.mean(d_hard)
    with pytest.raises(ValueError, match="min_start_distance"):
        gym.make("sensorplan/Navigate-v0", min_start_distance=1.5)


def test_benchmark_writes_one_table(tmp_path):
    res = benchmark(
        "sensorplan/Navigate-v0",
        ["oracle", "random"],
        episodes=3,
        split_names=["test", "ood:corridor"],
        env_kwargs={"scene_pool_size": 4},
        out=tmp_path,
        verbose=False,
    )
    rows = res["rows"]
    assert [(r["split"], r["policy"]) for r in rows] == [
        ("test", "oracle"),
        ("test", "random"),
        ("ood:corridor", "oracle"),
        ("ood:corridor", "random"),
    ]
    assert rows[0]["success_rate"] == 1.0 and rows[0]["normalized_score"] == 1.0
    assert rows[0]["start_distance"] >= 0.35
    saved = json.loads((tmp_path / "benchmark.json").read_text())
    assert saved["difficulty"]["min_start_distance"] == 0.35
    assert (tmp_path / "benchmark.csv").read_text().count("\n") == 5


def test_procedural_splits_draw_a_start_per_episode_and_count_distinct_episodes(tmp_path):
    assert splits(["train", "test"], 0.3, needs_start=True)["test"]["random_start"] is True
    assert "random_start" not in splits(["test"], 0.3, needs_start=False)["test"]
    res = benchmark(
        "sensorplan/Navigate-v0",
        ["random"],
        episodes=8,
        split_names=["test", "ood:corridor"],
        env_kwargs={"scene_pool_size": 4},
        out=tmp_path,
        verbose=False,
    )
    test, corridor = res["rows"]
    # 4 pool scenes, 8 episodes: every episode has its own start
    assert test["distinct_episodes"] == 8
    # bundled scenes too: a start per episode, not the scene's one fixed start
    assert corridor["distinct_episodes"] == 8
    assert splits(["ood:lab"], 0.3, needs_start=True)["ood:lab"]["random_start"] is True
    assert "random_start" not in splits(["ood"], 0.3, needs_start=False)["ood:lab"]


def test_wilson_interval_is_sized_by_distinct_episodes():
    from agents.evaluation.evaluate import _summary
    from agents.evaluation.stats import wilson_interval

    ep = {
        "success": [True, False] * 50,
        "return": [0.0] * 100,
        "steps": [1] * 100,
        "path_length": [0.0] * 100,
        "episode_key": [f"s{i % 10}" for i in range(100)],
    }
    s = _summary("p", "random", ep, {})
    assert s["distinct_episodes"] == 10 and s["episodes"] == 100
    assert s["success_ci95"] == list(wilson_interval(5, 10))
    wide = s["success_ci95"][1] - s["success_ci95"][0]
    lo, hi = wilson_interval(50, 100)
    assert wide > hi - lo


def _pool_fingerprint(env_id: str, kw: dict) -> list[tuple]:
    env = gym.make(env_id, **kw)
    src = env.unwrapped.batch.source
    out = []
    for k in range(src.size):
        w, start = src.get(k)
        out.append((round(w.region.area, 9), tuple(np.round(w.lo, 9)), tuple(np.round(w.hi, 9))))
    env.close()
    return out


def test_train_split_is_the_training_pool():
    from pathlib import Path

    from agents.evaluation.benchmark import training_pool
    from agents.learning.policies import model_config

    shipped = Path(__file__).resolve().parents[2] / "agents" / "pretrained"
    rec = str(shipped / "ppo_recognize_random.zip")
    trained = model_config(rec)["env_kwargs"]
    pool = training_pool(["oracle", rec])
    assert pool["min_start_distance"] == trained["min_start_distance"]
    sp = splits(["train", "test"], 0.35, needs_start=True, train_pool=pool)
    env_id = "sensorplan/Recognize-v0"
    train_kw = {k: trained[k] for k in ("scene", "min_start_distance", "max_scene_tries")}
    assert _pool_fingerprint(env_id, sp["train"]) == _pool_fingerprint(env_id, train_kw)
    # without a model trained on random scenes: the default pool of seed TRAIN_POOL_SEED
    assert training_pool(["oracle", "random"]) is None
    # models of different pools have no one training pool
    nav = str(shipped / "ppo_navigate_random.zip")
    if training_pool([nav]) != pool:
        with pytest.raises(ValueError, match="different scene pools"):
            training_pool([rec, nav])


def test_level_draws_the_procedural_splits_from_its_family(tmp_path):
    from geometry.families import get_difficulty

    sp = splits(["train", "test", "ood:lab"], None, needs_start=True, level="hard")
    assert sp["test"]["difficulty"] == sp["train"]["difficulty"] == "hard"
    assert "difficulty" not in sp["ood:lab"]  # bundled scenes are what they are
    # an explicit knob wins over the level's own start distance
    assert splits(["test"], 0.5, True, level="hard")["test"]["min_start_distance"] == 0.5
    env = gym.make("sensorplan/Navigate-v0", scene_pool_size=2, **sp["test"])
    _, info = env.reset(seed=0)
    d = info["distance_to_region"] / env.unwrapped.world.diameter
    assert d >= get_difficulty("hard").min_start_distance
    env.close()
    with pytest.raises(ValueError, match="unknown difficulty 'nightmare'"):
        benchmark(
            "sensorplan/Navigate-v0",
            ["random"],
            episodes=1,
            level="nightmare",
            split_names=["test"],
            out=tmp_path / "never",
            verbose=False,
        )
    assert not (tmp_path / "never").exists()


def test_narrow_splits_replace_the_scenes_field_of_view(tmp_path):
    """``narrow``: the bundled scenes and real maps with a narrow sensor (the issue's lab-like
    room with a narrow field of view), each at the narrowest of 60/75/90 degrees from which
    the oracle finds a recognizing pose; the env plays that sensor and the oracle recognizes."""
    from agents.evaluation.benchmark import NARROW_FOV_DEG
    from agents.planning.oracle import plan_viewpoint

    sp = splits(["narrow"], None, needs_start=True)
    assert set(sp) == {"narrow:lab", "narrow:edr", "narrow:corridor", "narrow:lse_arena",
                       "narrow:willow_north", "narrow:willow_south", "narrow:heidelberg_l1",
                       "narrow:heidelberg_l2"}  # fmt: skip
    assert sp["narrow:willow_north"]["scene"] == "real/willow_north"
    assert sp["narrow:lab"]["fov_deg"] == 75.0 and sp["narrow:edr"]["fov_deg"] == 60.0
    with pytest.raises(ValueError, match="narrow:<scene or map>"):
        splits(["narrow:warehouse"], None, True)
    # every scene has a recognizing pose at its field of view; lab's 75 is the narrowest
    cases = [("lab", 60.0, "no_placement"), *((s, f, "ok") for s, f in NARROW_FOV_DEG.items())]
    for scene, fov, status in cases:
        env = gym.make("sensorplan/Navigate-v0", scene=scene, fov_deg=fov)
        _, info = env.reset(seed=0)
        assert env.unwrapped.world.fov == pytest.approx(np.radians(fov))
        assert plan_viewpoint(env.unwrapped.world, np.array(info["pose"][:2])).status == status
    res = benchmark("sensorplan/Navigate-v0", ["oracle"], episodes=2, split_names=["narrow:lab"],
                    out=tmp_path, verbose=False)  # fmt: skip
    assert res["rows"][0]["success_rate"] == 1.0
