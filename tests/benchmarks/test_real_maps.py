"""`benchmarks.real_maps`: the fuzzer's slow reproductions are read with their own call, and
the previous implementation's anchor (every collinearity event sampled) is switched on only
inside its call."""

from __future__ import annotations

import math

import pytest

from benchmarks import _results
from benchmarks import real_maps as rm
from geometry import Scene, partial_region
from geometry import sweep as S


def test_the_slow_reproductions_come_with_their_orientation() -> None:
    cases = {name: (load, theta) for name, _, load, theta in rm._cases()}
    assert set(rm.SLOW_REPROS) <= set(cases)
    load, theta = cases["slow_1"]
    assert math.isclose(theta, 0.6831449051177683)
    assert cases["slow_2"][1] == 0.0
    assert isinstance(load(), Scene)


def test_eager_sampling_only_inside_the_anchor_call(monkeypatch) -> None:
    flags: list[bool] = []
    orig = S.Sweeper.along_many

    def along_many(self, *a, **k):
        flags.append(self.lazy_samples)
        return orig(self, *a, **k)

    monkeypatch.setattr(S.Sweeper, "along_many", along_many)
    lab = "sensorplan_gym/scenes/lab.json"
    rm._eager(lambda: partial_region(Scene.load(lab), target_in="goal", theta=0.0))
    assert S.LAZY_SAMPLES is True  # restored
    n = len(flags)
    partial_region(Scene.load(lab), target_in="goal", theta=0.0)
    assert n and not any(flags[:n]) and all(flags[n:])


def _run(stationary: float, swept: float, area: float = 2.0) -> dict:
    """One process's data as `_run_here` gives it, for one scene."""
    q = {name: 1.0 for name, _ in rm.QUERIES}
    q["partial, stationary"] = stationary
    q["partial, swept over G"] = swept
    row = {
        "scene": "lse_arena",
        "edges": 14,
        "source": "somewhere",
        "theta": 0.0,
        "anchor_s": 1e-4,
        "query_s": q,
        "area_m2": {name: area for name, _ in rm.QUERIES},
    }
    return {"reps": 3, "rows": [row]}


def test_several_processes_give_median_times_and_every_process_ratio() -> None:
    # the second process runs the stationary query slowly: its ratio is the low one
    data = rm.combine([_run(0.010, 0.100), _run(0.020, 0.120), _run(0.012, 0.110)])
    (row,) = data["rows"]
    assert data["processes"] == 3
    assert row["query_s"]["partial, stationary"] == 0.012
    assert row["query_s"]["partial, swept over G"] == 0.110
    assert row["ratios"]["swept / stationary partial"] == pytest.approx([10.0, 6.0, 110 / 12])
    data |= {"command": "python -m benchmarks.real_maps", "machine": _results.machine()}
    page = rm.render(data)
    assert "| 9.2x (6.0-10.0) |" in page
    assert "3 fresh Python processes" in page
    assert "slow reproductions" not in page  # no such row


def test_processes_that_disagree_on_an_area_are_an_error() -> None:
    with pytest.raises(ValueError, match=r"lse_arena 'complete, stationary': area 2\.5"):
        rm.combine([_run(0.01, 0.1), _run(0.01, 0.1, area=2.5)])


def test_bad_arguments_are_named() -> None:
    with pytest.raises(ValueError, match="unknown scene.*nowhere.*known: heidelberg_l1"):
        rm.run(1, scenes=("nowhere",))
    with pytest.raises(ValueError, match="processes must be at least 1, got 0"):
        rm.run(1, processes=0)


@pytest.mark.slow
def test_fresh_processes_measure_the_same_answers() -> None:
    data = rm.run(1, processes=2, scenes=("lse_arena",))
    (row,) = data["rows"]
    assert data["processes"] == 2
    assert all(len(r) == 2 and min(r) > 1.0 for r in row["ratios"].values())
    assert all(a > 0 for a in row["area_m2"].values())
