"""`benchmarks.real_maps`: the fuzzer's slow reproductions are read with their own call, and
the previous implementation's anchor (every collinearity event sampled) is switched on only
inside its call."""

from __future__ import annotations

import math

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
