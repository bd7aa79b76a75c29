"""``benchmarks.pixel_placement``'s per-scene table: every scene once, by its exact labels."""

from __future__ import annotations

import pytest

pytest.importorskip("torch")
pytest.importorskip("yaml")

from benchmarks import pixel_placement  # noqa: E402


def test_per_scene_counts_the_exact_labels(monkeypatch):
    monkeypatch.setattr(
        pixel_placement, "TEST_POOL", {**pixel_placement.TEST_POOL, "scene_pool_size": 2}
    )
    rows = pixel_placement.per_scene(pixel_placement.MODEL)
    by = {r["split"]: r for r in rows}
    assert by["test"]["scenes"] == 2 and "ood:lab" in by and "real:willow_north" in by
    for r in rows:
        assert 0 <= r["policy"] <= r["solvable"] <= r["scenes"]
        assert 0 <= r["rule"] <= r["solvable"]
    # the rule on the hull-view and aim channels is right on every bundled map
    assert all(by[f"ood:{s}"]["rule"] == 1 for s in ("corridor", "edr", "lab", "warehouse"))
    text = pixel_placement.render(
        {
            "rows": [
                {"split": "test", "policy": "pixel policy", "successes": 1, "episodes": 2,
                 "distinct": 2, "ci95": [0.1, 0.9]},
            ],
            "scenes": rows,
            "iqm": [{"split": "test", "runs": 5, "train_seeds": [0, 1, 2, 3, 4], "iqm": 0.9,
                     "ci95": [0.8, 0.95]}],
            "training": {},
            "model": "m.pt",
            "command": "python -m benchmarks.pixel_placement",
            "seconds": 1.0,
        }
    )  # fmt: skip
    assert "| ood:lab | 1 | 1 | 1 | 1 |" in text and "channel rule" in text
    assert "over 5 training seeds (0, 1, 2, 3, 4)" in text and "test 0.90 [0.80, 0.95]" in text
