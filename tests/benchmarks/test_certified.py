"""``benchmarks.certified``: one row measured, and the fragment rendered from it."""

from __future__ import annotations

from benchmarks import certified
from geometry import Scene


def test_a_row_brackets_and_renders():
    s = Scene.load(certified.SCENES / "lab.json")
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
    names = [p.stem for p in certified._paths()]
    assert "lab" in names and "willow_north" in names and "corridor" not in names
