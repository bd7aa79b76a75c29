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
