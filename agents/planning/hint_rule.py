"""A fixed controller on the ``view_hint`` and ``aim_features`` observations (no learning).

Navigate-v0 and Recognize-v0 made with ``view_hint=True`` and ``aim_features=True``
(:data:`ENV_KWARGS`) end their observation with the arcs of directions K_G and K_H cover from
the robot and the way to the nearest pose that sees every corner of both hulls with a passing
aim (:func:`sensorplan_gym.core.observations.view_hint`).  :class:`HintRulePolicy` moves along
the hint, slows down where the way ends and turns toward the centre of the joint arc.  In
Recognize-v0 (made with ``map_evidence=True`` as well: :data:`RECOGNIZE_KWARGS`) it also
declares: it points at G while some beam reads the target inside K_G and none inside K_H
(beams whose end lies in both hulls count for neither), at H in the mirror case, and
otherwise goes on (:func:`sensorplan_gym.core.observations.map_evidence`; the env declares
after ``declare_hold`` such steps), standing still while it points.  Where the way has ended
and no beam reads the target, it sweeps its beams over the gaps between them (16 beams over
360 degrees are 22.5 degrees apart, wider than a far target): a sensor with a full circle of
view (``self_features`` or ``sensor_fov`` tell it) turns by :data:`SCAN_TURN` of a beam
spacing per step; one whose field of view exceeds the joint arc by more than a full turn step
(``max_turn``) turns the same way while the arc's centre lies less than half a turn step
behind the heading and turns back a full step otherwise, a saw-tooth of one turn step's width
around the arc's centre that keeps both hulls in view (memoryless: a function of the
observation, as a DAgger label must be); one narrower than the joint arc (a ``view_hint``
made with ``hint_aim=False`` leads to poses with no joint aim) turns round, a few beam
spacings per step, so that each hull comes into view in turn.  It reads the observation
only, not the recognizable region nor where the target is, so it shows what those features
give by themselves: the baseline a learned policy on the same observation should beat, and a
labeller for DAgger that a learner can fit exactly.  ``sensorplan evaluate`` / ``benchmark``
play it as the policy spec ``"hint-rule"``, and in Recognize-v0 with ``hint_aim=False`` as
``"hint-rule-turn"``.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["ENV_KWARGS", "RECOGNIZE_KWARGS", "HintRulePolicy"]

#: the observation kwargs the rule reads in Navigate-v0 (merged under the user's env kwargs
#: when played)
ENV_KWARGS: dict[str, Any] = {"view_hint": True, "aim_features": True}
#: ... and in Recognize-v0: the per-beam evidence flags too
RECOGNIZE_KWARGS: dict[str, Any] = {**ENV_KWARGS, "map_evidence": True}

#: the turn command per radian of heading error (a full turn at 0.5 rad)
TURN_GAIN = 2.0
#: the way's length (in scene diameters) below which the robot slows down (one step at full
#: speed is 0.03 diameters)
SLOW_BELOW = 0.03
#: Recognize-v0, a full circle of view, the way ended and nothing read: the turn per step as a
#: fraction of the beam spacing (not a simple fraction, so the beams sweep the whole gap)
SCAN_TURN = 0.37
#: the ``decide`` commands: point at G, at H, go on (Recognize-v0: thirds of [-1, 1])
POINT_G, POINT_H, GO_ON = -1.0, 1.0, 0.0


class HintRulePolicy:
    """Move along the hint at ``min(1, way / SLOW_BELOW)`` of full speed, turn toward the
    joint arc's centre and, in Recognize-v0, point at the side the evidence flags show (SB3's
    ``predict`` signature; deterministic).

    ``env``: a Navigate-v0 env made with :data:`ENV_KWARGS` or a Recognize-v0 env made with
    :data:`RECOGNIZE_KWARGS` (or their vector envs); anything else raises ``ValueError``
    naming what is missing.  Without ``env`` it plays Navigate-v0."""

    def __init__(self, env: Any = None) -> None:
        self.evidence: slice | None = None  # Recognize-v0: where the flags lie in an observation
        self.n_beams = 0
        self.fov_at: int | None = None  # where fov / 360 degrees lies (from the end)
        self.scan_turn = 0.0  # the turn command that sweeps the beams
        self.max_turn = 0.0  # radians per step at turn = 1
        if env is None:
            return
        obs = _obs_builder(env)
        task = getattr(_batch(env), "task_name", "?")
        if obs is None or task not in ("NavigateEnv", "RecognizeEnv"):
            raise ValueError(
                f"the hint rule plays Navigate-v0 and Recognize-v0 with vector observations "
                f"(env {task})"
            )
        need = RECOGNIZE_KWARGS if task == "RecognizeEnv" else ENV_KWARGS
        missing = [k for k in need if not getattr(obs, k, False)]
        if missing:
            name = "Recognize-v0" if task == "RecognizeEnv" else "Navigate-v0"
            raise ValueError(
                f"the hint rule plays {name} made with "
                + " and ".join(f"{k}=True" for k in need)
                + f" (missing: {', '.join(missing)})"
            )
        if task == "RecognizeEnv":
            # from the end: view_hint 3, aim_features 10, self_features 2, sensor_fov 1
            end = 13 + (2 if obs.self_features else 0) + (1 if obs.sensor_fov else 0)
            self.n_beams = int(obs.n)
            self.evidence = slice(-end - 2 * obs.n, -end)
            if obs.self_features:
                self.fov_at = -15
            elif obs.sensor_fov:
                self.fov_at = -14
            self.max_turn = float(_batch(env).max_turn)
            self.scan_turn = min(1.0, SCAN_TURN * (2.0 * np.pi / obs.n) / self.max_turn)

    def predict(
        self,
        observation: np.ndarray,
        state: Any = None,
        episode_start: Any = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, Any]:
        """Actions ``(forward, lateral, turn)`` (Navigate-v0) or ``(forward, lateral, turn,
        decide)`` (Recognize-v0) for one observation or a batch (stacked frames: the last
        frame is read)."""
        obs = np.asarray(observation, dtype=np.float64)
        one = obs.ndim == 1
        o = obs[None] if one else obs
        hx, hy, way = o[:, -3], o[:, -2], o[:, -1]
        jc, js = o[:, -13], o[:, -12]  # the joint arc's centre relative to the heading
        speed = np.minimum(1.0, way / SLOW_BELOW)
        turn = np.clip(TURN_GAIN * np.arctan2(js, jc), -1.0, 1.0)
        if self.evidence is None:
            act = np.column_stack([hx * speed, hy * speed, turn]).astype(np.float32)
            return (act[0] if one else act), state
        ev = o[:, self.evidence] > 0.5
        g, h = ev[:, : self.n_beams], ev[:, self.n_beams :]
        in_g, in_h = (g & ~h).any(axis=1), (h & ~g).any(axis=1)
        decide = np.where(in_g & ~in_h, POINT_G, np.where(in_h & ~in_g, POINT_H, GO_ON))
        if self.fov_at is not None:
            scan = (decide == GO_ON) & (way < SLOW_BELOW)
            fov = 2.0 * np.pi * o[:, self.fov_at]
            full = fov >= 2.0 * np.pi * (1.0 - 1e-6)
            err = np.arctan2(js, jc)  # the joint arc's centre relative to the heading
            slack = fov - 2.0 * np.pi * o[:, -11]  # the field of view less the joint arc
            saw = scan & ~full & (slack > self.max_turn * (1.0 + self.scan_turn))
            back = err <= -0.5 * self.max_turn
            turn = np.where(scan & full, self.scan_turn, turn)
            turn = np.where(saw, np.where(back, -1.0, self.scan_turn), turn)
            # the two hulls do not fit in the field of view at once: turn round, one hull
            # after the other, at SCAN_TURN past a whole number of beam spacings per step
            gap = fov / max(self.n_beams - 1, 1)
            step = (np.floor(0.8 * self.max_turn / gap) + SCAN_TURN) * gap
            turn = np.where(
                scan & ~full & (slack < 0.0), np.minimum(step / self.max_turn, 1.0), turn
            )
        still = decide != GO_ON  # keep the beams that read the target where they are
        act = np.column_stack(
            [
                np.where(still, 0.0, hx * speed),
                np.where(still, 0.0, hy * speed),
                np.where(still, 0.0, turn),
                decide,
            ]
        ).astype(np.float32)
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
