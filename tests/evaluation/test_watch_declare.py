"""``python -m agents.evaluation.watch_declare``: a learned watcher team against the oracle on
the same episodes, with bootstrap intervals over episodes."""

from __future__ import annotations

import json

import numpy as np
import pytest

pytest.importorskip("stable_baselines3")

from agents.evaluation.stats import wilson_interval  # noqa: E402
from agents.evaluation.watch_declare import METRICS, RATES, main, summarize  # noqa: E402
from agents.learning.watch_imitation import train_watch_imitation  # noqa: E402

CFG = {
    "env_kwargs": {"scene": "lab", "n_watchers": 2},
    "placement": "both",
    "n_envs": 2,
    "policy_kwargs": {"net_arch": [16]},
    "dagger": {"iterations": 1, "episodes": 2, "epochs": 1},
}


def test_summarize_means_and_intervals():
    rng = np.random.default_rng(0)
    ep = {
        "seed": list(range(50)),
        "watcher_success": list(rng.choice([0.0, 0.5, 1.0], 50)),
        "visible": list(rng.random(50)),
        "team_visible": list(rng.random(50)),
        "success": list(rng.random(50) < 0.7),
    }
    s = summarize(ep)
    assert s["episodes"] == 50
    for name, key in METRICS.items():
        est, lo, hi = s[name]
        assert est == pytest.approx(np.mean(np.asarray(ep[key], dtype=float)))
        assert lo < est < hi and hi - lo < 0.5
        if name in RATES:
            assert (lo, hi) == pytest.approx(wilson_interval(est * 50, 50))
    # all right: the Wilson interval stays informative where a bootstrap collapses to a point
    perfect = summarize({**ep, "watcher_success": [1.0] * 50})["per_watcher_right"]
    assert perfect[0] == 1.0 and perfect[1] < 0.95 and perfect[2] == 1.0


def test_cli_compares_with_the_oracle(tmp_path, capsys):
    train_watch_imitation(CFG, seed=0, out=tmp_path, verbose=False)
    out = tmp_path / "cmp.json"
    rc = main(["--policy", str(tmp_path / "final_model.pt"), "--episodes", "3", "--json", str(out)])
    assert rc == 0
    text = capsys.readouterr().out
    assert "| learned |" in text and "| oracle |" in text
    res = json.loads(out.read_text())
    assert res["env_kwargs"] == {"scene": "lab", "n_watchers": 2, "evidence": True}
    assert res["oracle"]["per_watcher_right"][0] == 1.0  # the oracle is right on lab
    assert res["per_episode"]["learned"]["seed"] == res["per_episode"]["oracle"]["seed"]
    assert main(["--policy", str(tmp_path / "final_model.pt"), "--episodes", "0"]) == 2
    assert main(["--policy", str(tmp_path / "missing.pt")]) == 2


def test_watch_cli_plays_a_watch_imitation_team(capsys):
    from pathlib import Path

    from agents.evaluation.watch import main as watch_main

    team = Path(__file__).resolve().parents[2] / "agents/pretrained/dagger_watch_lab2.pt"
    args = ["--scenes", "lab", "--watchers", "2", "--episodes", "2", "--policy", str(team)]
    assert watch_main(args) == 0
    assert "lab               2" in capsys.readouterr().out
