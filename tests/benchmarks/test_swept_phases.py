"""`benchmarks.swept_phases`: the phases of a sweep add up to the query, and the table renders
from its data (one scene, one call: a smoke run of the benchmark)."""

from __future__ import annotations

from benchmarks import real_maps as rm
from benchmarks import swept_phases as sp


def test_one_scene_runs_and_renders(monkeypatch) -> None:
    cases = [c for c in rm._cases() if c[0] == "lse_arena"]
    monkeypatch.setattr(sp, "_cases", lambda: cases)
    data = sp.run(reps=1, slow=False)
    (row,) = data["rows"]
    assert set(row["phase_s"]) == set(sp.PHASES)
    assert 0 < sum(row["phase_s"].values()) <= row["swept_s"]
    # every sample belongs to one phase; G's five vertices are sampled first
    assert row["phase_samples"]["vertex samples"] == 5
    assert row["samples"] == sum(row["phase_samples"].values())
    assert 0 < row["no_events_s"]
    assert 0 < row["bare_s"]
    # lse_arena: the safety nets find nothing there (docs/performance.md)
    assert 0 <= row["bare_depth_tol"] <= 2
    data.update(command="python -m benchmarks.swept_phases", machine=rm._results.machine())
    text = sp.render(data)
    assert text.count("\n| lse_arena | 14 |") == 1
    assert text.splitlines()[0].endswith(
        "| rest | without event samples | without event samples or birth checks |"
    )
