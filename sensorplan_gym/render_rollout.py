"""Render a short random-agent rollout to a PNG contact sheet.

    python -m sensorplan_gym.render_rollout --env sensorplan/Navigate-v0 --out rollout.png

Runs one episode (or ``--steps`` steps, whichever ends first) with random actions, keeps
``--frames`` evenly spaced frames (the first and the last included) and writes them side
by side in rows of ``--cols``, each panel numbered with the env step it shows.
Extra ``--kw key=value`` pairs go to ``gym.make`` (values
are parsed as JSON when possible, e.g. ``--kw fov_deg=120 --kw scene='"edr"'``).
For Recognize-v0 the random agent only declares in the last step.
"""

from __future__ import annotations

import argparse
import json

import gymnasium as gym
import numpy as np

import sensorplan_gym  # noqa: F401


def _kw(pairs):
    out = {}
    for p in pairs or []:
        k, _, v = p.partition("=")
        try:
            out[k] = json.loads(v)
        except json.JSONDecodeError:
            out[k] = v
    return out


def rollout_frames(env_id: str, *, steps: int = 60, seed: int = 0, **kwargs) -> list[np.ndarray]:
    env = gym.make(env_id, render_mode="rgb_array", **kwargs)
    env.reset(seed=seed)
    env.action_space.seed(seed)
    frames = [env.render()]
    for i in range(steps):
        a = env.action_space.sample()
        if a.shape == (4,):  # Recognize: keep looking, declare at the end
            a[3] = 0.0 if i < steps - 1 else (-1.0 if i % 2 else 1.0)
        _, _, te, tr, _ = env.step(a)
        frames.append(env.render())
        if te or tr:
            break
    env.close()
    return frames


def pick_frames(n_frames: int, n: int) -> np.ndarray:
    """Indices of ``n`` evenly spaced frames out of ``n_frames`` (first and last included)."""
    return np.unique(np.linspace(0, n_frames - 1, min(n, n_frames)).round().astype(int))


def contact_sheet(frames: list[np.ndarray], n: int, cols: int) -> np.ndarray:
    """``n`` evenly spaced frames in rows of ``cols``, each panel headed by its number and
    the env step it shows (``frames[0]`` is the frame after ``reset``: step 0).  Returns an
    RGB uint8 image."""
    fig = sheet_figure(frames, n, cols)
    fig.canvas.draw()
    return np.ascontiguousarray(np.asarray(fig.canvas.buffer_rgba())[:, :, :3])


def sheet_figure(frames: list[np.ndarray], n: int, cols: int):
    """The matplotlib Figure behind :func:`contact_sheet` (one titled axes per panel)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    idx = pick_frames(len(frames), n)
    h, w, _ = frames[idx[0]].shape
    ncol = min(cols, len(idx))
    rows = -(-len(idx) // cols)
    head = 22  # pixels above each panel for its caption
    dpi = 100
    fig = Figure(figsize=(ncol * (w + 4) / dpi, rows * (h + head + 4) / dpi), dpi=dpi)
    FigureCanvasAgg(fig)
    fig.set_facecolor("white")
    last = len(frames) - 1
    for k, i in enumerate(idx):
        r, c = divmod(k, cols)
        x0 = c * (w + 4) / (ncol * (w + 4))
        y0 = 1 - (r + 1) * (h + head + 4) / (rows * (h + head + 4))
        ax = fig.add_axes((x0, y0, w / (ncol * (w + 4)), h / (rows * (h + head + 4))))
        ax.imshow(frames[i])
        ax.set_axis_off()
        what = " (reset)" if i == 0 else (" (last)" if i == last else "")
        ax.set_title(f"{k + 1}/{len(idx)}: step {i} of {last}{what}", fontsize=9, pad=3)
    return fig


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(
        prog="python -m sensorplan_gym.render_rollout",
        description="Render a random-agent rollout to a PNG.",
    )
    ap.add_argument("--env", default="sensorplan/Navigate-v0")
    ap.add_argument("--scene", default="lab")
    ap.add_argument("--out", default="rollout.png")
    ap.add_argument("--steps", type=int, default=60)
    ap.add_argument("--frames", type=int, default=6)
    ap.add_argument("--cols", type=int, default=3)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--kw", action="append", help="extra gym.make kwarg key=value")
    args = ap.parse_args(argv)
    kwargs = {"scene": args.scene, **_kw(args.kw)}
    frames = rollout_frames(args.env, steps=args.steps, seed=args.seed, **kwargs)
    sheet = contact_sheet(frames, args.frames, args.cols)
    import matplotlib.image

    matplotlib.image.imsave(args.out, sheet)
    print(f"wrote {args.out} ({len(frames)} frames rendered, {sheet.shape[1]}x{sheet.shape[0]} px)")


if __name__ == "__main__":
    main()
