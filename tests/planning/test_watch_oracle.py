"""The oracle watchers of watch_v0 (issue 11): placements in the exact swept regions, the
declaration from the readings, and the evaluation harness."""

from __future__ import annotations

import numpy as np
import pytest
import shapely

from agents.evaluation.watch import evaluate_watch, format_rows, run_watch_episodes
from agents.planning.watch_oracle import WatchOracle
from sensorplan_gym import watch_v0
from sensorplan_gym.core.world import BUNDLED_SCENES


@pytest.mark.parametrize("scene", BUNDLED_SCENES)
def test_oracle_declares_right_with_one_and_two_watchers(scene):
    rows = evaluate_watch([scene], [1, 2], episodes=3, seed=0)
    for r in rows:
        assert r["success_rate"] == 1.0, (scene, r["n_watchers"], r["per_episode"])
        assert r["team_visible_fraction"] > 0.3
    assert "success" in format_rows(rows)


def test_oracle_placements_lie_in_the_exact_regions():
    from sensorplan_gym.multiagent.rendering import watch_region

    env = watch_v0.parallel_env(scene="lab", n_watchers=2)
    oracle = WatchOracle(env)
    env.reset(seed=0)
    oracle.reset()
    covers = sorted(p.covers for p in oracle.plans)
    assert covers == ["G", "H"]
    for p in oracle.plans:
        R = watch_region(env.world, p.covers)
        assert R.contains(shapely.Point(p.point))
        # from there A is completely visible wherever it ends in the covered region
        region = env.world.goal_geom if p.covers == "G" else env.world.failure_geom
        for q in shapely.get_coordinates(region):
            assert env.world.sees((*p.point, p.aim), q)
    env1 = watch_v0.parallel_env(scene="lab", n_watchers=1)
    o1 = WatchOracle(env1)
    env1.reset(seed=0)
    o1.reset()
    assert o1.plans[0].covers == "both"


def test_oracle_ignores_the_hidden_outcome():
    """The oracle's actions are the same whatever A's hidden outcome says, up to the step
    where A's motion itself differs (the oracle reads the map, its pose and its readings)."""
    env = watch_v0.parallel_env(scene="edr", n_watchers=2)
    oracle = WatchOracle(env)
    obs, _ = env.reset(seed=4)
    oracle.reset()
    true = env.traj.outcome
    acts = oracle.act(obs)
    env.traj.outcome = "H" if true == "G" else "G"
    oracle.reset()
    acts2 = oracle.act(obs)
    env.traj.outcome = true
    for a in acts:
        assert np.array_equal(acts[a], acts2[a])


def test_random_episodes_do_not_depend_on_the_split():
    kw = {"scene": "corridor", "n_watchers": 2, "max_steps": 20, "move_steps": 10}
    whole = run_watch_episodes(kw, "random", [7, 8, 9])
    parts = [run_watch_episodes(kw, "random", [s]) for s in (7, 8, 9)]
    for k in whole:
        assert whole[k] == [p[k][0] for p in parts]


def test_cli_train_backends_check_their_arguments(capsys):
    from agents.cli import main

    assert main(["train", "--seed", "0"]) == 2
    assert "--env and --algo are required" in capsys.readouterr().err
    with pytest.raises(SystemExit):
        main(
            [
                "evaluate",
                "--env",
                "sensorplan/Navigate-v0",
                "--policies",
                "random",
                "--backend",
                "x",
            ]
        )
