"""Shared pytest fixtures and hypothesis settings."""

from __future__ import annotations

import copy
import os
from typing import Any

import pytest
from hypothesis import HealthCheck, settings

# Geometry is deterministic but timing on the 2-core CI machine is not: no deadlines.
settings.register_profile("dev", deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.register_profile(
    "ci", deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow]
)
settings.load_profile("ci" if os.environ.get("CI") else "dev")

# Scene pools cache their regions on disk by default (sensorplan_gym.core.diskcache): tests
# compute every region and write nothing under the user's cache folder (the cache's own tests
# pass a temporary folder explicitly).
os.environ["SENSORPLAN_GYM_CACHE"] = "off"


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption(
        "--slow",
        action="store_true",
        help="also run the slow tier: the tests marked slow (end-to-end training and Ray-cluster "
        "runs of the benchmark commands; .ci/run runs them with `--slow -m slow`)",
    )


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Tests marked ``slow`` are skipped unless ``--slow`` is given (README, "Tests")."""
    if config.getoption("--slow"):
        return
    skip = pytest.mark.skip(reason="slow tier: run with --slow (.ci/run does)")
    for item in items:
        if "slow" in item.keywords:
            item.add_marker(skip)


#: A small valid scene (JSON form): a 10 x 10 room, two touching obstacles,
#: a unit-square target, a square goal and a point failure region.
LAB: dict[str, Any] = {
    "name": "lab",
    "bounds": [[0, 0], [10, 0], [10, 10], [0, 10]],
    "obstacles": [
        [[6, 6], [8, 6], [8, 8], [6, 8]],
        [[8, 6], [9, 6], [9, 7], [8, 7]],
    ],
    "target": [[-0.5, -0.5], [0.5, -0.5], [0.5, 0.5], [-0.5, 0.5]],
    "goal": [[2, 2], [3, 2], [3, 3], [2, 3]],
    "failure": [[5, 2]],
}


@pytest.fixture
def lab_dict() -> dict[str, Any]:
    """A fresh deep copy of :data:`LAB` (safe to mutate)."""
    return copy.deepcopy(LAB)


@pytest.fixture
def lab_scene(lab_dict):
    """:data:`LAB` as a validated :class:`geometry.scene.Scene`."""
    from geometry.scene import Scene

    return Scene.from_dict(lab_dict)
