"""Render the documentation's animated rollouts of the oracle: ``python docs/make_gifs.py``.

For every environment page one episode of the analytic oracle on a bundled scene, each frame
rendered by the environment itself (``render_mode="rgb_array"``), written as a looping GIF to
``docs/assets/<env>.gif``.  Deterministic: fixed seeds, no timing involved, so running it again
gives the same frames.  ``--out DIR`` writes elsewhere, ``--only NAME`` renders one of them.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))  # this checkout's packages, also without `pip install -e .`

import gymnasium as gym  # noqa: E402
import numpy as np  # noqa: E402
from PIL import Image  # noqa: E402

import sensorplan_gym  # noqa: E402, F401
from agents import OraclePolicy  # noqa: E402

#: name -> (env id, gym.make kwargs, episode seed)
ROLLOUTS = {
    "placement": ("sensorplan/Placement-v0", {"scene": "lab"}, 0),
    "navigate": ("sensorplan/Navigate-v0", {"scene": "lab"}, 0),
    "recognize": ("sensorplan/Recognize-v0", {"scene": "lab"}, 0),
    "watch": ("sensorplan/Watch-v0", {"scene": "lab"}, 0),
}


def oracle_frames(env_id: str, kwargs: dict, seed: int) -> list[np.ndarray]:
    """The rendered frames (RGB uint8) of one oracle episode: the reset frame, then one per
    step."""
    env = gym.make(env_id, render_mode="rgb_array", **kwargs)
    obs, _ = env.reset(seed=seed)
    frames = [env.render()]
    if env_id == "sensorplan/Watch-v0":
        from agents.planning.watch_oracle import WatchOracle

        par = env.unwrapped.par
        oracle = WatchOracle(par)
        agent = par.possible_agents[0]
        done = False
        while not done:
            act = oracle.act({agent: obs})[agent]
            obs, _, term, trunc, _ = env.step(act)
            frames.append(env.render())
            done = term or trunc
    else:
        policy = OraclePolicy(env)
        start, done = True, False
        while not done:
            action, _ = policy.predict(obs, episode_start=start)
            start = False
            obs, _, term, trunc, _ = env.step(action)
            frames.append(env.render())
            done = term or trunc
    env.close()
    return frames


def write_gif(frames: list[np.ndarray], path: Path, width: int = 360, ms: int = 120) -> None:
    """A looping GIF ``width`` pixels wide, ``ms`` per frame, the last frame held 1.5 s."""
    imgs = []
    for f in frames:
        im = Image.fromarray(np.asarray(f)[..., :3])
        h = round(im.height * width / im.width)
        imgs.append(im.resize((width, h), Image.LANCZOS).quantize(colors=64, method=2))
    durations = [ms] * (len(imgs) - 1) + [1500]
    if len(imgs) == 1:
        durations = [1500]
    path.parent.mkdir(parents=True, exist_ok=True)
    imgs[0].save(
        path, save_all=True, append_images=imgs[1:], duration=durations, loop=0, optimize=True
    )


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(prog="python docs/make_gifs.py", description=__doc__)
    ap.add_argument("--out", type=Path, default=ROOT / "docs" / "assets")
    ap.add_argument("--only", nargs="+", choices=sorted(ROLLOUTS), default=None)
    args = ap.parse_args(argv)
    for name in args.only or ROLLOUTS:
        env_id, kw, seed = ROLLOUTS[name]
        frames = oracle_frames(env_id, kw, seed)
        path = args.out / f"{name}.gif"
        write_gif(frames, path)
        print(f"{path}: {len(frames)} frames, {path.stat().st_size / 1024:.0f} KiB")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
