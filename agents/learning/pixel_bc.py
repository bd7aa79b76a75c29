"""Placement learned from the exact answer, pixel by pixel: a fully convolutional policy.

``python -m agents.learning.pixel_bc [--difficulty hard] [--pool-size 2048] [--epochs 40]
[--seed 0] [--out DIR]``

Placement-v0 is a contextual bandit: one decision per scene, and the exact geometry says, for
every candidate pose, whether it tells G from H.  So the teacher here is not one expert action
(the oracle's, which a regression averages over the many right answers: issue 22's BC on
continuous actions reached 0.10) but the whole *set* of right actions of each training scene:

* the env is ``sensorplan/Placement-v0`` with ``obs_type="grid"``, ``grid_views=True``,
  ``self_features=True`` (channels: not free, G, H, the free space seen from G's and H's
  anchors, field of view and reach planes; ``--hull-views``: also the free space seen from
  every corner of K_G and of K_H, before the planes; ``--aim-views``: then one channel per aim,
  where that aim passes the reward's aim test, which the symmetries permute like the actions'
  aims) and ``action_type="pixel"`` (one action per
  pixel and aim, :mod:`sensorplan_gym.core.actions`), so that an output map lines up with
  the input map;
* :func:`valid_actions` labels every pixel action of a scene by the env's own exact reward
  (the recognizable region's ``contains_xy`` and the aim test, :meth:`PlacementBatch.evaluate`);
* :class:`PixelNet` maps the observation to one logit per action (dilated residual
  convolutions with coordinate channels; receptive field wider than the grid);
* :func:`fit` maximises the log-probability of the *set* of valid actions, ``log sum_{a
  valid} softmax(logits)_a`` (the likelihood of "some right answer", which does not average
  modes), over the scenes of a training pool with the eight symmetries of the square (a
  quarter turn shifts the aims by ``A / 4``, a mirror maps aim ``k`` to ``A / 2 - k``);
* :class:`PixelPolicy` plays the arg-max action; it has SB3's ``predict`` signature, and
  ``sensorplan evaluate`` / ``benchmark`` load it from its ``.pt`` file and the resolved config
  beside it (``algo: pixel_bc``).

Frames and units: observations and actions are the env's (:mod:`sensorplan_gym.envs.placement`).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np
import torch
import yaml
from torch import nn

__all__ = [
    "ENV_ID",
    "ENV_KWARGS",
    "PixelNet",
    "PixelPolicy",
    "aim_channels",
    "channel_rule",
    "fit",
    "scene_data",
    "valid_actions",
]

ENV_ID = "sensorplan/Placement-v0"

#: The observation and action kwargs of the pixel policy (the scene kwargs are the caller's).
ENV_KWARGS: dict[str, Any] = {
    "obs_type": "grid",
    "grid_views": True,
    "self_features": True,
    "action_type": "pixel",
    "grid_size": 64,
    "placement_aims": 16,
}


def valid_actions(batch, i: int = 0) -> np.ndarray:
    """``(S, S, A)`` bool: which pixel actions earn reward 1 in sub-environment ``i`` of the
    Placement batch ``batch`` (made with ``action_type="pixel"``), by the env's exact test."""
    tab = batch.actions.table
    idx = np.full(len(tab), i, dtype=np.int64)
    pose = batch.action_to_pose(batch.square_to_box(tab, idx), idx)
    reward, _ = batch.evaluate(pose, idx)
    s = batch.obs.size
    return (reward > 0.5).reshape(s, s, -1)


def scene_data(
    env_kwargs: dict[str, Any], *, jobs: int | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Observations ``(N, C, S, S)`` uint8 and valid-action masks ``(N, S, S, A)`` of every
    scene of the pool that ``env_kwargs`` (``scene="random"``, its pool kwargs, and
    :data:`ENV_KWARGS`) describes, or of its one scene."""
    from sensorplan_gym.envs.placement import PlacementBatch

    kw = {**env_kwargs, **ENV_KWARGS}
    if jobs is not None and kw.get("scene") == "random":
        kw["scene_pool_jobs"] = jobs
    batch = PlacementBatch(1, **kw)
    random = kw.get("scene") == "random"
    worlds = (
        (batch.source.get(k)[0] for k in range(int(kw.get("scene_pool_size", 64))))
        if random
        else [batch.source.world]
    )
    obs, masks = [], []
    for world in worlds:
        batch.load_world(0, world)
        obs.append(batch.obs.of_world(world))
        masks.append(valid_actions(batch, 0))
    return np.stack(obs), np.stack(masks)


class _Block(nn.Module):
    def __init__(self, ch: int, dilation: int) -> None:
        super().__init__()
        self.conv1 = nn.Conv2d(ch, ch, 3, padding=dilation, dilation=dilation)
        self.conv2 = nn.Conv2d(ch, ch, 3, padding=1)
        self.norm = nn.GroupNorm(8, ch)

    def forward(self, x: torch.Tensor) -> torch.Tensor:
        return x + self.conv2(torch.relu(self.norm(self.conv1(torch.relu(x)))))


class PixelNet(nn.Module):
    """Observation ``(B, C, S, S)`` (uint8 scale) -> logits ``(B, S * S * A)`` in the pixel
    action order ``(row, col, aim)``."""

    def __init__(
        self,
        channels: int,
        aims: int,
        width: int = 48,
        dilations: tuple[int, ...] = (1, 2, 4, 8, 16, 1),
    ) -> None:
        super().__init__()
        self.aims = int(aims)
        self.stem = nn.Conv2d(channels + 2, width, 3, padding=1)
        self.blocks = nn.Sequential(*[_Block(width, d) for d in dilations])
        self.head = nn.Conv2d(width, self.aims, 1)

    def forward(self, obs: torch.Tensor) -> torch.Tensor:
        x = obs.float() / 255.0
        b, _, h, w = x.shape
        ys = torch.linspace(-1.0, 1.0, h, device=x.device).view(1, 1, h, 1).expand(b, 1, h, w)
        xs = torch.linspace(-1.0, 1.0, w, device=x.device).view(1, 1, 1, w).expand(b, 1, h, w)
        x = self.blocks(self.stem(torch.cat([x, ys, xs], dim=1)))
        return self.head(torch.relu(x)).permute(0, 2, 3, 1).reshape(b, -1)  # (B, S*S*A)


def aim_channels(env_kwargs: dict[str, Any]) -> tuple[int, int] | None:
    """The channels ``[lo, hi)`` of the ``aim_views`` planes in the grid observation that
    ``env_kwargs`` (with :data:`ENV_KWARGS`) makes, or ``None`` without them (the order of
    :class:`sensorplan_gym.core.observations.PlacementGridObs`)."""
    kw = {**env_kwargs, **ENV_KWARGS}
    if not kw.get("aim_views"):
        return None
    lo = 3 + 2 * bool(kw.get("grid_views")) + 2 * bool(kw.get("hull_views"))
    return lo, lo + int(kw["placement_aims"])


def _turn(obs: np.ndarray, k: int, flip: bool, aim: tuple[int, int] | None) -> np.ndarray:
    """Observations ``(..., C, S, S)`` turned ``k`` quarter turns counter-clockwise, then
    mirrored left-right if ``flip``; the aim planes ``aim`` (channels ``[lo, hi)``, one per
    aim) are permuted as the actions' aims are (a quarter turn adds ``A / 4``, the mirror maps
    ``k`` to ``A / 2 - k``)."""
    o = np.rot90(obs, k, axes=(-2, -1))
    if flip:
        o = o[..., ::-1]
    if aim is not None:
        lo, hi = aim
        a = hi - lo
        perm = (np.arange(a) - k * a // 4) % a  # plane j of the turned scene is plane j - kA/4
        if flip:
            perm = perm[(a // 2 - np.arange(a)) % a]
        o = np.concatenate([o[..., :lo, :, :], o[..., lo + perm, :, :], o[..., hi:, :, :]], -3)
    return np.ascontiguousarray(o)


def _augment(
    obs: np.ndarray, mask: np.ndarray, k: int, flip: bool, aim: tuple[int, int] | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """The scene turned ``k`` quarter turns counter-clockwise, then mirrored left-right if
    ``flip``: observation ``(C, S, S)`` (:func:`_turn`; ``aim``: its aim planes) and mask
    ``(S, S, A)`` alike (aims follow)."""
    a = mask.shape[-1]
    m = np.roll(np.rot90(mask, k, axes=(0, 1)), k * a // 4, axis=2)
    if flip:
        m = m[:, ::-1, (a // 2 - np.arange(a)) % a]
    return _turn(obs, k, flip, aim), np.ascontiguousarray(m)


def set_nll(logits: torch.Tensor, valid: torch.Tensor) -> torch.Tensor:
    """Mean over the batch of ``-log sum_{a valid} softmax(logits)_a`` (rows with no valid
    action must be left out by the caller)."""
    logp = torch.log_softmax(logits, dim=1)
    return -(torch.logsumexp(logp.masked_fill(~valid, -torch.inf), dim=1)).mean()


def fit(
    obs: np.ndarray,
    masks: np.ndarray,
    *,
    epochs: int = 40,
    batch_size: int = 32,
    lr: float = 2e-3,
    seed: int = 0,
    width: int = 48,
    augment: bool = True,
    log: Any = print,
    device: str = "cpu",
    aim: tuple[int, int] | None = None,
) -> PixelNet:
    """A :class:`PixelNet` trained on the scenes ``obs`` ``(N, C, S, S)`` with valid-action
    masks ``masks`` ``(N, S, S, A)`` (scenes with no valid action are skipped): Adam with a
    cosine schedule, the set likelihood :func:`set_nll`, a random symmetry of the square per
    sample and epoch when ``augment``.  ``device``: where to train (a torch device name,
    e.g. ``"cuda"``; the same draws on every device); the net is returned on the CPU.
    ``aim``: the observation's aim planes (:func:`aim_channels`), permuted by the symmetries."""
    torch.manual_seed(seed)
    rng = np.random.default_rng(seed)
    keep = masks.reshape(len(masks), -1).any(axis=1)
    obs, masks = obs[keep], masks[keep]
    net = PixelNet(obs.shape[1], masks.shape[-1], width=width).to(device)
    opt = torch.optim.Adam(net.parameters(), lr=lr)
    steps = epochs * max(1, -(-len(obs) // batch_size))
    sched = torch.optim.lr_scheduler.CosineAnnealingLR(opt, steps)
    for ep in range(epochs):
        order = rng.permutation(len(obs))
        total = 0.0
        for s in range(0, len(order), batch_size):
            rows = order[s : s + batch_size]
            if augment:
                pairs = [
                    _augment(obs[r], masks[r], int(rng.integers(4)), bool(rng.integers(2)), aim)
                    for r in rows
                ]
                o = np.stack([p[0] for p in pairs])
                m = np.stack([p[1] for p in pairs])
            else:
                o, m = obs[rows], masks[rows]
            valid = torch.from_numpy(m.reshape(len(rows), -1)).to(device)
            loss = set_nll(net(torch.from_numpy(o).to(device)), valid)
            opt.zero_grad()
            loss.backward()
            opt.step()
            sched.step()
            total += float(loss.detach()) * len(rows)
        if log is not None:
            log(f"epoch {ep + 1}/{epochs}: set NLL {total / len(obs):.3f}")
    net.eval()
    return net.cpu()


def _untransform(m: np.ndarray, k: int, flip: bool) -> np.ndarray:
    """Maps ``(B, S, S, A)`` of a scene transformed by :func:`_augment` ``(k, flip)`` back to
    the scene's own pixels and aims (the inverse symmetry: the mirror, then ``-k`` turns)."""
    a = m.shape[-1]
    if flip:
        m = m[:, :, ::-1, :][..., (a // 2 - np.arange(a)) % a]
    back = (4 - k) % 4
    return np.roll(np.rot90(m, back, axes=(1, 2)), back * a // 4, axis=3)


class PixelPolicy:
    """The arg-max action of a :class:`PixelNet` (SB3's ``predict`` signature).  With
    ``symmetries`` (the default) the log-probabilities are averaged over the eight symmetries
    of the square (each observation turned and mirrored, the answer mapped back), so that the
    policy is exactly equivariant.  Measured with the shipped policy: 47 against 43 right of the
    hard level's 64 test-pool scenes (each once), and 0.77 against 0.79 on the benchmark's 100
    test episodes (52 distinct scenes): no difference the samples can tell."""

    def __init__(
        self,
        net: PixelNet,
        *,
        symmetries: bool = True,
        aim: tuple[int, int] | None = None,
    ) -> None:
        self.net = net.eval()
        self.symmetries = bool(symmetries)
        self.aim = None if aim is None else (int(aim[0]), int(aim[1]))

    def log_probs(self, obs: np.ndarray) -> np.ndarray:
        """``(B, S * S * A)`` log-probabilities of the pixel actions for observations ``(B, C,
        S, S)`` (averaged over the symmetries when :attr:`symmetries`)."""
        b, _, s, _ = obs.shape
        a = self.net.aims
        views = [(k, f) for k in range(4) for f in (False, True)] if self.symmetries else [(0, 0)]
        acc = np.zeros((b, s, s, a))
        with torch.no_grad():
            for k, flip in views:
                o = _turn(obs, k, bool(flip), self.aim)
                lp = torch.log_softmax(self.net(torch.from_numpy(o)), dim=1)
                acc += _untransform(lp.numpy().reshape(b, s, s, a), k, bool(flip))
        return (acc / len(views)).reshape(b, -1)

    def predict(
        self,
        observation: np.ndarray,
        state: Any = None,
        episode_start: Any = None,
        deterministic: bool = True,
    ) -> tuple[np.ndarray, Any]:
        """Actions (ints) for one observation ``(C, S, S)`` or a batch ``(B, C, S, S)``."""
        obs = np.asarray(observation)
        one = obs.ndim == 3
        lp = self.log_probs(obs[None] if one else obs)
        if deterministic:
            out = lp.argmax(axis=1)
        else:
            logits = torch.from_numpy(lp)
            out = torch.distributions.Categorical(logits=logits).sample().numpy()
        out = out.astype(np.int64)
        return (out[0] if one else out), state

    def save(self, path: str | Path, config: dict[str, Any]) -> Path:
        """Write the weights to ``path`` (``.pt``) and ``config`` (with the net's shape) beside
        it (``.yaml``); returns the ``.pt`` path."""
        path = Path(path).with_suffix(".pt")
        path.parent.mkdir(parents=True, exist_ok=True)
        head = self.net.head
        shape = {
            "channels": int(self.net.stem.in_channels - 2),
            "aims": int(head.out_channels),
            "width": int(head.in_channels),
            "aim_channels": None if self.aim is None else list(self.aim),
        }
        torch.save({"state_dict": self.net.state_dict(), "shape": shape}, path)
        with open(path.with_suffix(".yaml"), "w") as f:
            yaml.safe_dump({**config, "algo": "pixel_bc", "net": shape}, f, sort_keys=False)
        return path

    @classmethod
    def load(cls, path: str | Path) -> PixelPolicy:
        """The policy saved by :meth:`save` at ``path``."""
        got = torch.load(Path(path), map_location="cpu", weights_only=True)
        shape = got["shape"]
        net = PixelNet(shape["channels"], shape["aims"], width=shape["width"])
        net.load_state_dict(got["state_dict"])
        aim = shape.get("aim_channels")
        return cls(net, aim=None if aim is None else (aim[0], aim[1]))


def channel_rule(obs: np.ndarray, aim: tuple[int, int]) -> np.ndarray:
    """The pixel actions ``(B,)`` of a fixed rule on grid observations ``(B, C, S, S)`` made
    with ``hull_views`` and ``aim_views`` (``aim``: the aim planes, :func:`aim_channels`):
    among the pixels that are free and see every corner of K_G and of K_H, and the aims that
    pass the aim test there, the pixel deepest inside that seen set (Euclidean distance
    transform, in pixels) with the aim farthest from a failing aim.  No learning: a baseline
    for what those channels give by themselves.  A scene with no such pixel gets action 0."""
    from scipy import ndimage

    lo, hi = aim
    a = hi - lo
    hv = lo - 2  # the hull views precede the aim planes
    b, _, s, _ = obs.shape
    out = np.zeros(b, dtype=np.int64)
    for i in range(b):
        seen = (obs[i, 0] == 0) & (obs[i, hv] > 0) & (obs[i, hv + 1] > 0)
        ok = (obs[i, lo:hi] > 0) & seen[None]  # (A, S, S)
        if not ok.any():
            continue
        run = ok.astype(np.float64)  # how far each passing aim is from a failing one
        both = ok.copy()
        for d in range(1, a // 2 + 1):
            both &= np.roll(ok, d, axis=0) & np.roll(ok, -d, axis=0)
            run += both
        score = np.where(ok, ndimage.distance_transform_edt(seen)[None] * (a + 1) + run, -1.0)
        k, r, c = np.unravel_index(int(np.argmax(score)), score.shape)
        out[i] = (r * s + c) * a + k
    return out


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="python -m agents.learning.pixel_bc", description=__doc__.split("\n")[0]
    )
    p.add_argument("--difficulty", default="hard", help="the scene family's level")
    p.add_argument("--pool-size", type=int, default=2048, help="training scenes")
    p.add_argument(
        "--pool-seed",
        type=int,
        default=0,
        help="the pool's seed (0: the benchmark's train)",
    )
    p.add_argument(
        "--hull-views",
        action="store_true",
        help="two more channels: the free space seen from every corner of K_G and of K_H",
    )
    p.add_argument(
        "--aim-views",
        action="store_true",
        help="one more channel per aim: where that aim passes the reward's aim test",
    )
    p.add_argument("--epochs", type=int, default=40)
    p.add_argument("--width", type=int, default=48)
    p.add_argument("--seed", type=int, default=0)
    p.add_argument(
        "--seeds",
        type=int,
        nargs="+",
        default=None,
        help="fit once per seed on the one labelled pool (outputs OUT/seed_<s>/)",
    )
    p.add_argument("--jobs", type=int, default=None, help="processes that build the pool")
    p.add_argument("--threads", type=int, default=None, help="torch threads")
    p.add_argument(
        "--device", default="cpu", help='where to fit: "cpu" (default), "cuda" or "auto"'
    )
    p.add_argument("--out", default="runs/pixel_bc", help="folder for final_model.pt / .yaml")
    a = p.parse_args(argv)
    if a.threads:
        torch.set_num_threads(a.threads)
    pool = {
        "scene": "random",
        "difficulty": a.difficulty,
        "scene_pool_size": a.pool_size,
        "scene_pool_seed": a.pool_seed,
    }
    if a.hull_views:
        pool["hull_views"] = True
    if a.aim_views:
        pool["aim_views"] = True
    aim = aim_channels(pool)
    t0 = time.perf_counter()
    obs, masks = scene_data(pool, jobs=a.jobs)
    t1 = time.perf_counter()
    solvable = float(masks.reshape(len(masks), -1).any(axis=1).mean())
    print(
        f"{len(obs)} scenes labelled in {t1 - t0:.0f} s ({solvable:.3f} with a valid pixel action)"
    )
    device = a.device
    if device == "auto":
        device = "cuda" if torch.cuda.is_available() else "cpu"
    seeds = a.seeds if a.seeds else [a.seed]
    label_s = round(t1 - t0, 1)
    for seed in seeds:
        t1 = time.perf_counter()
        net = fit(obs, masks, epochs=a.epochs, seed=seed, width=a.width, device=device, aim=aim)
        t2 = time.perf_counter()
        config = {
            "env_id": ENV_ID,
            "env_kwargs": {**pool, **ENV_KWARGS},
            "seed": seed,
            "epochs": a.epochs,
            "command": "python -m agents.learning.pixel_bc "
            + " ".join(sys.argv[1:] if argv is None else argv),
            "labelled_scenes": len(obs),
            "solvable_fraction": solvable,
            "wall_time_s": {"label": label_s, "fit": round(t2 - t1, 1)},
            "fit_device": device,
        }
        out = Path(a.out) / f"seed_{seed}" if a.seeds else Path(a.out)
        path = PixelPolicy(net, aim=aim).save(out / "final_model.pt", config)
        print(json.dumps({"model": str(path), **config["wall_time_s"]}), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
