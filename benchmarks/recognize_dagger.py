"""Recognize-v0 on the ``hard`` level learned from the hint rule (DAgger) beside the shipped PPO
policy, the rule itself and the oracle.

    python -m benchmarks.recognize_dagger [--episodes 100] [--seed 0] [--models PATH ...]
        [--seed-models PATH ...]

``sensorplan benchmark --env sensorplan/Recognize-v0 --level hard --splits test ood real
narrow`` of ``agents/pretrained/dagger_recognize_hint.zip`` (DAgger from the hint rule that
turns to each hull, on ``view_hint`` with ``hint_aim=False``: ``sensorplan imitate --env
sensorplan/Recognize-v0 --method dagger --config agents/configs/imitation_hint.yaml``),
``ppo_recognize_hint.zip`` (PPO with 4 stacked frames, whose five training seeds
:mod:`benchmarks.recognize_hint` measures), the hint rule (:mod:`agents.planning.hint_rule`:
drive along ``view_hint``, declare from the evidence flags) on the joint hint
(``hint-rule``) and on the hint with no joint aim asked (``hint-rule-turn``), and the oracle,
every policy on the same episode seeds from random starts (:mod:`benchmarks.navigate_hint`,
whose table this shares).  ``--seed-models``: more training seeds of the ``--models'`` configs,
summarized by their IQM.  Needs the ``rl`` extra.
"""

from __future__ import annotations

from typing import Any

from . import navigate_hint

MODELS = [
    navigate_hint.PRETRAINED / "dagger_recognize_hint.zip",
    navigate_hint.PRETRAINED / "ppo_recognize_hint.zip",
]


def main(argv: list[str] | None = None) -> int:
    return navigate_hint.main(
        argv,
        env="sensorplan/Recognize-v0",
        name="recognize_dagger",
        models=MODELS,
        rules=("hint-rule", "hint-rule-turn"),
        doc=__doc__,
    )


def render(data: dict[str, Any]) -> str:
    """The page fragment: success [interval] per split and policy."""
    return navigate_hint.render(data)


if __name__ == "__main__":
    raise SystemExit(main())
