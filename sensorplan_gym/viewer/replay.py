"""Saved rollouts and their replay (the viewer's second tab).

Record an episode to JSON (``sensorplan record`` passes the oracle, a trained model or random
actions to :func:`record_rollout`; this module knows no agent)::

    sensorplan record --env sensorplan/Recognize-v0 --policy oracle \\
        --scene lab --seed 0 --out episode.json
    sensorplan view lab --rollout episode.json            # live app, "Replay" tab
    sensorplan view lab --rollout episode.json --export view.html   # also in the HTML file

The file (``"format": "sensorplan-rollout/1"``) holds the scene the env used (its JSON),
the env's recognizable region, and per step (step 0 is the state after ``reset``): the
robot pose ``[x, y, psi]`` and the sensor pose (world frame, radians), the beam end
points of the range scan, the target polygon when the env reveals it to its renderer
(Recognize-v0), whether the pose recognizes, the reward and the env's caption.

The replay is drawn in the browser alone (a slider and a play button in BokehJS), so it
works in the self-contained export too.
"""

from __future__ import annotations

import json
import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["FORMAT", "load_rollout", "record_rollout", "replay_layout", "save_rollout"]

FORMAT = "sensorplan-rollout/1"


def _state(env) -> dict[str, Any]:
    """What the env shows its renderer for sub-environment 0."""
    u = env.unwrapped
    batch = getattr(u, "batch", None)
    if batch is not None and hasattr(batch, "render_state"):
        return batch.render_state(0)
    return {  # pragma: no cover - envs without a batch core
        "pose": u.pose,
        "sensor_pose": u.sensor_pose,
        "scan": u.scan,
        "target": getattr(u, "_target_poly", None),
        "recognizing": False,
        "title": type(u).__name__,
    }


def _step_record(st: dict[str, Any], reward: float | None) -> dict[str, Any]:
    pose = st.get("pose")
    sensor = st.get("sensor_pose") or pose
    rec: dict[str, Any] = {
        "pose": None if pose is None else [float(v) for v in pose],
        "sensor": None if sensor is None else [float(v) for v in sensor],
        "beams": [[], []],
        "hits": [],
        "target": None,
        "recognizing": bool(st.get("recognizing", False)),
        "reward": None if reward is None else float(reward),
        "title": str(st.get("title", "")),
    }
    scan = st.get("scan")
    if scan is not None and sensor is not None:
        dist, _, hit, ang = scan
        dist, ang = np.asarray(dist, float), np.asarray(ang, float)
        rec["beams"] = [
            (sensor[0] + dist * np.cos(ang)).round(6).tolist(),
            (sensor[1] + dist * np.sin(ang)).round(6).tolist(),
        ]
        rec["hits"] = np.asarray(hit, bool).tolist()
    tgt = st.get("target")
    if tgt is not None:
        rec["target"] = np.asarray(tgt, float).round(6).tolist()
    return rec


def record_rollout(
    env_id: str,
    *,
    policy: str | Callable[[Any], Any] = "random",
    policy_name: str | None = None,
    seed: int = 0,
    max_steps: int | None = None,
    **env_kwargs: Any,
) -> dict[str, Any]:
    """Run one episode of ``env_id`` (made with ``env_kwargs``, reset with ``seed``) and return
    the rollout dictionary (see the module docstring).

    ``policy``: ``"random"`` (the env's action space, seeded with ``seed``) or a factory called
    once with the env that returns an object with SB3's ``predict(obs, state=None,
    episode_start=None, deterministic=True) -> (action, state)``, e.g. ``agents.OraclePolicy``.
    ``policy_name`` is what the file and the replay's caption call it (default ``"random"`` or
    the factory's ``__name__``)."""
    import gymnasium as gym

    import sensorplan_gym  # noqa: F401

    from .layers import geom_to_multipolygon

    if policy != "random" and not callable(policy):
        raise ValueError(
            f"policy must be 'random' or a callable env -> policy (e.g. agents.OraclePolicy), "
            f"got {policy!r}"
        )
    if policy_name is None:
        policy_name = "random" if policy == "random" else getattr(policy, "__name__", "policy")
    env = gym.make(env_id, **env_kwargs)
    try:
        obs, _ = env.reset(seed=seed)
        env.action_space.seed(seed)
        actor = None if policy == "random" else policy(env)
        world = env.unwrapped.world
        steps = [_step_record(_state(env), None)]
        done, total, state = False, 0.0, None
        start = np.ones(1, dtype=bool)
        limit = max_steps if max_steps is not None else 10_000
        while not done and len(steps) <= limit:
            if actor is not None:
                action, state = actor.predict(obs, state=state, episode_start=start)
            else:
                action = env.action_space.sample()
            start = np.zeros(1, dtype=bool)
            obs, r, term, trunc, info = env.step(action)
            total += r
            steps.append(_step_record(_state(env), r))
            done = term or trunc
        xs, ys = geom_to_multipolygon(world.region)
        return {
            "format": FORMAT,
            "env_id": env_id,
            "env_kwargs": {k: v for k, v in env_kwargs.items() if _jsonable(v)},
            "policy": policy_name,
            "seed": seed,
            "scene": world.scene.to_dict(),
            "region": {"xs": xs, "ys": ys},
            "return": total,
            "steps": steps,
        }
    finally:
        env.close()


def _jsonable(v: Any) -> bool:
    try:
        json.dumps(v)
    except TypeError:
        return False
    return True


def save_rollout(rollout: dict[str, Any], path: str | Path) -> Path:
    p = Path(path)
    p.write_text(json.dumps(rollout, separators=(",", ":")) + "\n", encoding="utf-8")
    return p


def load_rollout(path: str | Path) -> dict[str, Any]:
    """Read and check a rollout file (raises ``ValueError`` naming what is wrong)."""
    p = Path(path)
    if not p.exists():
        raise FileNotFoundError(f"rollout file not found: {p}")
    try:
        d = json.loads(p.read_text(encoding="utf-8"))
    except json.JSONDecodeError as e:
        raise ValueError(f"{p}: invalid JSON: {e}") from None
    if not isinstance(d, dict) or d.get("format") != FORMAT:
        raise ValueError(f'{p}: not a rollout file (expected "format": "{FORMAT}")')
    for k in ("scene", "region", "steps"):
        if k not in d:
            raise ValueError(f"{p}: missing key {k!r}")
    if not d["steps"]:
        raise ValueError(f"{p}: no steps")
    return d


def replay_layout(rollout: dict[str, Any] | str | Path, *, unit: str = "m"):
    """A Bokeh layout replaying ``rollout`` with a step slider and a play button (all in
    BokehJS: no server needed)."""
    from bokeh.layouts import column, row
    from bokeh.models import Button, ColumnDataSource, CustomJS, Div, Slider

    from geometry import Scene

    from .figure import build_figure

    ro = rollout if isinstance(rollout, dict) else load_rollout(rollout)
    scene = Scene.from_dict(ro["scene"])
    sf = build_figure(scene, None, visible=(), unit=unit, hover=False, width=900)
    fig = sf.fig
    fig.name = "replay_figure"
    # no precomputed layers and no target drawn at G: the replay shows the env's region and
    # the target where the env put it
    for key in ("partial_G", "partial_H", "complete_G", "complete_H", "recognizable", "target"):
        fig.renderers.remove(sf.renderers[key])
    items = [it for it in fig.legend[0].items if it.renderers[0] in fig.renderers]
    fig.legend[0].items = items
    region = ColumnDataSource(
        {"xs": [ro["region"]["xs"]], "ys": [ro["region"]["ys"]]}, name="src:replay_region"
    )
    r = fig.multi_polygons(
        "xs",
        "ys",
        source=region,
        fill_color="#7fd37f",
        fill_alpha=0.55,
        line_color="#2e8b2e",
        name="replay:region",
        legend_label="recognizable region (the env's)",
    )
    fig.renderers.remove(r)
    fig.renderers.insert(1, r)  # above the room, below obstacles
    steps = ro["steps"]
    poses = [s["pose"] for s in steps if s["pose"] is not None]
    path = ColumnDataSource(
        {"x": [p[0] for p in poses], "y": [p[1] for p in poses]}, name="src:replay_path"
    )
    fig.line(
        "x",
        "y",
        source=path,
        line_color="#ff7f0e",
        line_width=2,
        name="replay:path",
        legend_label="robot path",
    )
    beams = ColumnDataSource({"x0": [], "y0": [], "x1": [], "y1": []}, name="src:replay_beams")
    fig.segment(
        "x0",
        "y0",
        "x1",
        "y1",
        source=beams,
        line_color="#e08a00",
        line_alpha=0.8,
        line_width=1,
        name="replay:beams",
        legend_label="range beams",
    )
    target = ColumnDataSource({"xs": [], "ys": []}, name="src:replay_target")
    fig.patches(
        "xs",
        "ys",
        source=target,
        fill_alpha=0.0,
        line_color="#7a2fbf",
        line_dash="dashed",
        line_width=2,
        name="replay:target",
        legend_label="hidden target",
    )
    robot = ColumnDataSource(
        {"x": [], "y": [], "hx": [], "hy": [], "c": []}, name="src:replay_robot"
    )
    fig.segment("x", "y", "hx", "hy", source=robot, line_color="black", line_width=2)
    fig.scatter(
        "x",
        "y",
        source=robot,
        size=13,
        fill_color="c",
        line_color="black",
        name="replay:robot",
        legend_label="robot (green: recognizing)",
    )
    data = ColumnDataSource(
        {
            "pose": [s["pose"] or [] for s in steps],
            "sensor": [s["sensor"] or [] for s in steps],
            "bx": [s["beams"][0] for s in steps],
            "by": [s["beams"][1] for s in steps],
            "target": [s["target"] or [] for s in steps],
            "rec": [bool(s["recognizing"]) for s in steps],
            "reward": [math.nan if s["reward"] is None else s["reward"] for s in steps],
            "title": [s["title"] for s in steps],
        },
        name="src:replay_steps",
    )
    n = len(steps)
    slider = Slider(
        start=0,
        end=max(n - 1, 1),
        value=0,
        step=1,
        title="step",
        width=600,
        name="replay_step",
        disabled=n < 2,
    )
    caption = Div(text="", width=900, name="replay_caption")
    span = 0.025 * scene.diameter
    update = CustomJS(
        args=dict(
            data=data,
            beams=beams,
            target=target,
            robot=robot,
            caption=caption,
            slider=slider,
            span=span,
            n=n,
            ret=float(ro.get("return", math.nan)),
        ),
        code="""
const i = Math.round(slider.value);
const d = data.data;
const p = d.pose[i], s = d.sensor[i];
if (p.length) {
  robot.data = {x: [p[0]], y: [p[1]], hx: [p[0] + span * Math.cos(p[2])],
                hy: [p[1] + span * Math.sin(p[2])], c: [d.rec[i] ? '#2e8b2e' : '#ff8c1a']};
} else { robot.data = {x: [], y: [], hx: [], hy: [], c: []}; }
const bx = d.bx[i], by = d.by[i];
const x0 = [], y0 = [];
for (let k = 0; k < bx.length; k++) { x0.push(s[0]); y0.push(s[1]); }
beams.data = {x0: x0, y0: y0, x1: Array.from(bx), y1: Array.from(by)};
const t = d.target[i];
target.data = t.length ? {xs: [t.map(q => q[0])], ys: [t.map(q => q[1])]} : {xs: [], ys: []};
const r = d.reward[i];
caption.text = `<b>step ${i} of ${n - 1}</b>` + (i == 0 ? ' (reset)' : '') +
  ` &nbsp; ${d.title[i]} &nbsp; reward ${Number.isNaN(r) ? '–' : r.toFixed(3)}` +
  ` &nbsp; recognizing: ${d.rec[i] ? 'yes' : 'no'} &nbsp; episode return ${ret.toFixed(3)}`;
""",
    )
    slider.js_on_change("value", update)
    play = Button(label="▶ play", width=90, name="replay_play")
    play.js_on_click(
        CustomJS(
            args=dict(slider=slider, button=play, n=n),
            code="""
if (window._sp_timer) { clearInterval(window._sp_timer); window._sp_timer = null;
  button.label = '▶ play'; return; }
if (slider.value >= n - 1) { slider.value = 0; }
button.label = '❚❚ pause';
window._sp_timer = setInterval(() => {
  if (slider.value >= n - 1) { clearInterval(window._sp_timer); window._sp_timer = null;
    button.label = '▶ play'; return; }
  slider.value = slider.value + 1;
}, 150);
""",
        )
    )
    # the first frame, drawn in Python so that the page is right before any JS runs
    first = steps[0]
    if first["pose"] is not None:
        x, y, psi = first["pose"]
        robot.data = {
            "x": [x],
            "y": [y],
            "hx": [x + span * math.cos(psi)],
            "hy": [y + span * math.sin(psi)],
            "c": ["#2e8b2e" if first["recognizing"] else "#ff8c1a"],
        }
    if first["sensor"] is not None and first["beams"][0]:
        sx, sy = first["sensor"][:2]
        k = len(first["beams"][0])
        beams.data = {
            "x0": [sx] * k,
            "y0": [sy] * k,
            "x1": first["beams"][0],
            "y1": first["beams"][1],
        }
    if first["target"]:
        t = np.asarray(first["target"])
        target.data = {"xs": [t[:, 0].tolist()], "ys": [t[:, 1].tolist()]}
    caption.text = (
        f"<b>step 0 of {n - 1}</b> (reset) &nbsp; {first['title']} &nbsp; "
        f"{ro.get('env_id', '')} with the {ro.get('policy', '?')} policy, seed {ro.get('seed')}"
    )
    return column(caption, row(play, slider), fig, name="replay")
