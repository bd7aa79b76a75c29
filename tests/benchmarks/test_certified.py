"""``benchmarks.certified``: one row measured, and the fragment rendered from it."""

from __future__ import annotations

from benchmarks import certified
from sensorplan_gym.core.scenes import load_scene


def test_a_row_brackets_and_renders():
    s = load_scene("lab")
    row = certified._row("lab", "swept", s, {"target_in": "goal"})
    assert row["proven"] is not None
    assert row["proven"] <= row["outer"] + 1e-12 and row["inner"] <= row["outer"] + 1e-12
    assert 0 <= row["hausdorff_proven"] and 0 <= row["hausdorff_inner"]
    data = {
        "command": "python -m benchmarks.certified",
        "machine": {"cpus": 2, "load_average": 1.0},
        "densify": 0,
        "rows": [row, {**row, "query": "5.2", "proven": None, "hausdorff_proven": None}],
        "seconds": 1.0,
    }
    md = certified.render(data)
    assert "| lab | swept | 44 |" in md and "| lab | 5.2 | 44 |" in md and "| – |" in md


def test_only_scenes_with_a_polygonal_region():
    names = [n for n, _ in certified._scenes()]
    assert "lab" in names and "real/willow_north" in names and "corridor" not in names
    assert "real/heidelberg_l1" in names  # the GeoJSON floor plans too
