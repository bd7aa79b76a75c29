"""A fixed controller on the ``view_hint`` and ``aim_features`` observations (no learning).

Navigate-v0 made with ``view_hint=True`` and ``aim_features=True`` (:data:`ENV_KWARGS`) ends
its observation with the arcs of directions K_G and K_H cover from the robot and the way to the
nearest pose that sees every corner of both hulls with a passing aim
(:func:`sensorplan_gym.core.observations.view_hint`).  :class:`HintRulePolicy` moves along the
hint, slows down where the way ends and turns toward the centre of the joint arc.  It reads the
observation only, not the recognizable region, so it shows what those features give by
themselves: the baseline a learned policy on the same observation should beat.  ``sensorplan
evaluate`` / ``benchmark`` play it as the policy spec ``"hint-rule"``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["ENV_KWARGS", "HintRulePolicy"]

#: the observation kwargs the rule reads (merged under the user's env kwargs when played)
ENV_KWARGS: dict[str, Any] = {"view_hint": True, "aim_features": True}

#: the turn command per radian of heading error (a full turn at 0.5 rad)
TURN_GAIN = 2.0
#: the way's length (in scene diameters) below which the robot slows down (one step at full
#: speed is 0.03 diameters)
SLOW_BELOW = 0.03


class HintRulePolicy:
    """Move along the hint at ``min(1, way / SLOW_BELOW)`` of full speed, turn toward the
    joint arc's centre (SB3's ``predict`` signature; deterministic).

    ``env``: a Navigate-v0 env (or its vector env) made with :data:`ENV_KWARGS`; anything else
    raises ``ValueError`` naming what is missing."""

    def __init__(self, env: Any = None) -> None:
        if env is not None:
            obs = _obs_builder(env)
            if obs is not None:
                missing = [k for k in ENV_KWARGS if not getattr(obs, k, False)]
                if missing or getattr(_batch(env), "task_name", "NavigateEnv") != "NavigateEnv":
                    raise ValueError(
                        "the hint rule plays Navigate-v0 made with view_hint=True and "
                        f"aim_features=True (missing: {', '.join(missing) or 'none'}; env "
                        f"{getattr(_batch(env), 'task_name', '?')})"
                    )

    def predict(
        self,
        observation: np.ndarray,
        state: Any = None,
        episode_start: Any = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, Any]:
        """Actions ``(forward, lateral, turn)`` for one observation or a batch."""
        obs = np.asarray(observation, dtype=np.float64)
        one = obs.ndim == 1
        o = obs[None] if one else obs
        hx, hy, way = o[:, -3], o[:, -2], o[:, -1]
        jc, js = o[:, -13], o[:, -12]  # the joint arc's centre relative to the heading
        speed = np.minimum(1.0, way / SLOW_BELOW)
        turn = np.clip(TURN_GAIN * np.arctan2(js, jc), -1.0, 1.0)
        act = np.column_stack([hx * speed, hy * speed, turn]).astype(np.float32)
        return (act[0] if one else act), state


def _batch(env: Any) -> Any:
    e = env
    while not hasattr(e, "batch") and hasattr(e, "venv"):
        e = e.venv
    e = getattr(e, "unwrapped", e)
    if not hasattr(e, "batch") and hasattr(e, "envs"):
        e = e.envs[0].unwrapped
    return getattr(e, "batch", None)


def _obs_builder(env: Any) -> Any:
    b = _batch(env)
    return None if b is None else getattr(b, "obs", None)
