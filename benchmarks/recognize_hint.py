"""Recognize-v0 on the ``hard`` level with the ``view_hint`` observation against the policy
trained without it and the oracle.

    python -m benchmarks.recognize_hint [--episodes 100] [--seed 0] [--models PATH ...]

``sensorplan benchmark --env sensorplan/Recognize-v0 --level hard --splits test ood real narrow`` of
``agents/pretrained/ppo_recognize_hint.zip`` (PPO with 4 stacked frames, ``view_hint`` and
``aim_features``), ``ppo_recognize_hard`` (the same recipe without them) and the oracle, every
policy on the same episode seeds from random starts (:mod:`benchmarks.navigate_hint`, whose
table this shares).  Needs the ``rl`` extra.
"""

from __future__ import annotations

from typing import Any

from . import navigate_hint

MODELS = [
    navigate_hint.PRETRAINED / "ppo_recognize_hint.zip",
    navigate_hint.PRETRAINED / "ppo_recognize_hard.zip",
]


def main(argv: list[str] | None = None) -> int:
    return navigate_hint.main(
        argv,
        env="sensorplan/Recognize-v0",
        name="recognize_hint",
        models=MODELS,
        rules=(),
        doc=__doc__,
    )


def render(data: dict[str, Any]) -> str:
    """The page fragment: success [interval] per split and policy."""
    return navigate_hint.render(data)


if __name__ == "__main__":
    raise SystemExit(main())
