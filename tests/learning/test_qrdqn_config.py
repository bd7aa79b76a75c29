"""The shipped QR-DQN config stays trainable: every section's distributional output layer
(actions x quantiles outputs) is bounded."""

from pathlib import Path

import gymnasium as gym
import pytest
import yaml

import sensorplan_gym  # noqa: F401

CONFIG = Path(__file__).resolve().parents[2] / "agents" / "configs" / "qrdqn.yaml"
# sb3-contrib's QRDQN default when policy_kwargs has no n_quantiles
DEFAULT_QUANTILES = 200
# weights of the last layer (hidden x actions x quantiles): 13.1 M for Placement's 2,048
# actions x 25 quantiles behind 256 units; version 1 (200 quantiles) had 105 M (~3 GB trained)
MAX_OUTPUT_WEIGHTS = 16_000_000


def _sections():
    cfg = yaml.safe_load(CONFIG.read_text())
    return [(k, v) for k, v in cfg.items() if k != "default"]


@pytest.mark.parametrize("env_id,section", _sections(), ids=[k for k, _ in _sections()])
def test_qrdqn_output_layer_is_bounded(env_id, section):
    kw = {k: v for k, v in (section.get("env_kwargs") or {}).items()}
    env = gym.make(env_id, **kw)
    space = env.action_space
    env.close()
    assert isinstance(space, gym.spaces.Discrete), f"{env_id}: QR-DQN needs Discrete actions"
    pk = section.get("policy_kwargs") or {}
    quantiles = int(pk.get("n_quantiles", DEFAULT_QUANTILES))
    hidden = int((pk.get("net_arch") or [64])[-1])
    weights = hidden * int(space.n) * quantiles
    assert weights <= MAX_OUTPUT_WEIGHTS, (
        f"{env_id}: {space.n} actions x {quantiles} quantiles x {hidden} units = {weights:,} "
        f"output weights > {MAX_OUTPUT_WEIGHTS:,}"
    )
