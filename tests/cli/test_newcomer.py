"""What a new user runs into first: missing extras, help texts (issue 12, newcomer pass)."""

from __future__ import annotations

import re
import sys

import pytest

from agents.cli import main


@pytest.mark.parametrize("module", ["yaml", "stable_baselines3", "torch"])
def test_train_without_rl_extra_names_the_extra(module, monkeypatch, capsys, tmp_path):
    monkeypatch.setitem(sys.modules, module, None)  # import of it now raises ImportError
    for name in [m for m in sys.modules if m == "agents.learning.train"]:
        monkeypatch.delitem(sys.modules, name)
    rc = main(
        ["train", "--env", "sensorplan/Navigate-v0", "--algo", "ppo", "--timesteps", "8",
         "--out", str(tmp_path / "run"), "--no-progress", "--no-tensorboard"]
    )  # fmt: skip
    err = capsys.readouterr().err
    assert rc == 2
    assert repr(module) in err
    assert 'pip install -e ".[rl]"' in err


def test_missing_module_outside_the_extras_is_not_swallowed():
    from agents.cli import _missing_extra_message

    err = ModuleNotFoundError("No module named 'nosuchthing'", name="nosuchthing")
    assert _missing_extra_message("train", err) is None
    err = ModuleNotFoundError("No module named 'yaml'", name="yaml")
    assert '".[rl]"' in _missing_extra_message("train", err)


def test_demo_help_is_plain_text(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["demo", "--help"])
    assert exc.value.code == 0
    out = capsys.readouterr().out
    assert "``" not in out and ":func:" not in out
    assert 'pip install -e ".[rl]"' in out
    assert "Recognize-v0" in out


@pytest.mark.parametrize("random_start", [False, True])
def test_warehouse_partial_stationary_gets_a_usable_start(random_start):
    """The warehouse's own start already recognizes under the partial/stationary model: the
    env falls back to a start drawn from a fixed generator that does not recognize and from
    which the region is reachable (the same one every time)."""
    import gymnasium as gym

    from sensorplan_gym.core.world import load_scene

    kw = dict(scene="warehouse", model="partial", motion="stationary", random_start=random_start)
    env = gym.make("sensorplan_gym:sensorplan/Navigate-v0", **kw)
    u = env.unwrapped
    scene_start = tuple(float(v) for v in load_scene("warehouse").start)
    assert u.world.recognizing(*scene_start)  # why the fallback is needed
    assert u.start != scene_start
    assert not u.world.recognizing(*u.start)
    assert not u.world.reachable_region(u.start[:2]).is_empty
    again = gym.make("sensorplan_gym:sensorplan/Navigate-v0", **kw).unwrapped.start
    assert again == u.start
    for seed in range(3):
        env.reset(seed=seed)
        assert not u.world.recognizing(*u.pose)
        env.step(env.action_space.sample())
    env.close()


def test_fine_scene_start_is_kept():
    import gymnasium as gym

    from sensorplan_gym.core.world import load_scene

    for scene in ("lab", "warehouse"):
        u = gym.make("sensorplan_gym:sensorplan/Navigate-v0", scene=scene).unwrapped
        assert u.start == tuple(float(v) for v in load_scene(scene).start)


@pytest.mark.slow
def test_oracle_benchmark_leaves_the_tracked_results_alone(tmp_path, monkeypatch):
    import benchmarks._results as br
    import benchmarks.oracle as bo

    monkeypatch.setattr(br, "DATA_DIR", tmp_path / "data")
    monkeypatch.setattr(br, "FRAGMENT_DIR", tmp_path / "docs")
    monkeypatch.setattr(bo, "ENVS", ["sensorplan/Placement-v0"])
    monkeypatch.setattr(bo, "SCENES", ["lab"])
    out = tmp_path / "out"
    bo.main(["--episodes", "1", "--random-scenes", "0", "--out", str(out)])
    assert (out / "oracle.json").is_file() and not (tmp_path / "data").exists()
    assert "| Placement-v0 | 1/1 |" in (out / "oracle.md").read_text()
    (out / "oracle.json").unlink()
    bo.main(["--episodes", "1", "--random-scenes", "0", "--out", str(out), "--update-results"])
    assert (tmp_path / "data" / "oracle.json").is_file()
    assert (tmp_path / "docs" / "oracle.md").is_file() and not (out / "oracle.json").exists()
    assert br.DEFAULT_OUT.parts[0] == "runs"  # git-ignored


def test_scene_save_writes_one_vertex_per_line_and_round_trips_exactly(tmp_path):
    import json

    from geometry.scene import Scene
    from sensorplan_gym.core.world import load_scene

    d = load_scene("lab").to_dict()
    d["obstacles"][0][0] = [0.1 + 0.2, 1 / 3]  # floats that need all 17 digits
    scene = Scene.from_dict(d)
    path = tmp_path / "lab.json"
    scene.save(path)
    text = path.read_text()
    assert "    [0.30000000000000004, 0.3333333333333333],\n" in text
    n_vertices = len(d["bounds"]) + sum(len(o) for o in d["obstacles"])
    vertex_lines = [ln for ln in text.splitlines() if re.fullmatch(r"\s*\[[^\[\]]+\],?", ln)]
    assert len(vertex_lines) >= n_vertices
    assert json.loads(text) == d
    assert Scene.load(path).to_dict() == scene.to_dict()


def test_start_heading_in_degrees_is_caught():
    import math

    import gymnasium as gym

    from geometry.scene import SceneError
    from sensorplan_gym.core.world import load_scene

    lab = load_scene("lab")
    x, y, _ = lab.start
    with pytest.raises(SceneError, match=r"start\[2\] \(theta\).*radians.*1\.5708"):
        lab.replace(start=[x, y, 90])
    assert lab.replace(start=[x, y, -6.0]).start[2] == -6.0  # a valid angle in radians stays
    env = gym.make("sensorplan_gym:sensorplan/Navigate-v0", scene="lab")
    env.reset(seed=0, options={"start": (x, y, 90.0)})
    psi = env.unwrapped.pose[2]
    assert -math.pi <= psi <= math.pi and math.isclose(math.cos(psi), math.cos(90.0))
    with pytest.raises(ValueError, match="non-finite"):
        env.reset(seed=0, options={"start": (x, y, math.nan)})


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        (dict(target_at=("2", 2, 0)), "target_at must be"),
        (dict(target_in="goal", theta="0"), "theta must be"),
    ],
)
def test_region_queries_reject_strings(kwargs, match):
    from geometry import complete_region
    from sensorplan_gym.core.world import load_scene

    with pytest.raises(ValueError, match=match):
        complete_region(load_scene("lab"), **kwargs)


def test_eps_aim_of_pi_or_more_is_rejected():
    import math

    import gymnasium as gym

    from geometry import partial_region
    from geometry.scene import SceneError
    from sensorplan_gym.core.world import load_scene

    lab = load_scene("lab")
    with pytest.raises(ValueError, match=r"eps_aim must be in \[0, pi\)"):
        partial_region(lab, target_in="goal", eps_aim=math.pi)
    with pytest.raises(ValueError, match=r"eps_aim must be in \[0, pi\)"):
        gym.make("sensorplan_gym:sensorplan/Navigate-v0", eps_aim=4.0)
    with pytest.raises(SceneError, match=r"sensor\.eps_aim_deg: must be in \[0, 180\)"):
        lab.replace(sensor={**lab.to_dict()["sensor"], "eps_aim_deg": 180})


def test_training_says_its_returns_include_shaping(tmp_path, capsys):
    pytest.importorskip("stable_baselines3")
    yaml = pytest.importorskip("yaml")
    from agents.learning.train import train

    nav = "sensorplan/Navigate-v0"
    tiny = {
        "n_steps": 32,
        "batch_size": 32,
        "n_epochs": 1,
        "policy_kwargs": {"net_arch": [8]},
        "env_kwargs": {"scene": "lab", "shaping": 1.0},
    }
    cfg = tmp_path / "tiny.yaml"
    cfg.write_text(yaml.safe_dump({nav: tiny}))
    kw = dict(timesteps=32, seed=0, n_envs=1, vec_env="dummy", progress_bar=False)
    train(nav, "ppo", config=cfg, out=tmp_path / "a", tensorboard=False, eval_freq=10**6, **kw)
    out = capsys.readouterr().out
    assert "include the reward shaping (shaping=1.0)" in out
    assert "`sensorplan evaluate` reports the task's return without shaping" in out
    cfg.write_text(yaml.safe_dump({nav: {**tiny, "env_kwargs": {"scene": "lab"}}}))
    train(nav, "ppo", config=cfg, out=tmp_path / "b", tensorboard=False, eval_freq=10**6, **kw)
    assert "shaping" not in capsys.readouterr().out


@pytest.mark.parametrize("module", ["yaml", "stable_baselines3"])
def test_evaluate_model_without_rl_extra_names_the_extra(module, monkeypatch, capsys, tmp_path):
    from pathlib import Path

    zip_ = Path(__file__).resolve().parents[2] / "agents/pretrained/ppo_navigate_lab.zip"
    monkeypatch.setitem(sys.modules, module, None)
    rc = main(
        ["evaluate", "--env", "sensorplan/Navigate-v0", "--policies", str(zip_),
         "--episodes", "1", "--out", str(tmp_path / "ev"), "--no-plot"]
    )  # fmt: skip
    assert rc == 2
    assert 'pip install -e ".[rl]"' in capsys.readouterr().err


@pytest.mark.parametrize(
    ("env_id", "cls_path", "vec_len", "n_discrete"),
    [
        ("sensorplan/Placement-v0", "placement:PlacementEnv", lambda n: 8 + 2 * n, 16 * 16 * 8),
        ("sensorplan/Navigate-v0", "navigate:NavigateEnv", lambda n: 8 + 3 * n, 7),
        ("sensorplan/Recognize-v0", "recognize:RecognizeEnv", lambda n: 8 + 3 * n, 9),
    ],
)
def test_env_class_docstrings_match_the_spaces(env_id, cls_path, vec_len, n_discrete):
    """help(EnvClass) shows a Gymnasium-style docstring whose stated spaces are the real ones."""
    import importlib

    import gymnasium as gym

    mod, name = cls_path.split(":")
    cls = getattr(importlib.import_module(f"sensorplan_gym.envs.{mod}"), name)
    doc = cls.__doc__ or ""
    sections = ["Description", "Action Space", "Observation Space", "Rewards"]
    sections += ["Starting State", "Episode End", "Arguments", "Version History"]
    for section in sections:
        assert f"## {section}" in doc, section
    assert f"Discrete({n_discrete})" in doc or "Discrete(G * G * A)" in doc
    env = gym.make(env_id, n_beams=12)
    assert env.observation_space.shape == (vec_len(12),)
    dim = env.action_space.shape[0]
    assert f"Box(-1, 1, ({dim},), float32)" in doc
    denv = gym.make(env_id, action_type="discrete")
    assert denv.action_space.n == n_discrete
    if "Navigate" in env_id or "Recognize" in env_id:
        both = gym.make(env_id, n_beams=12, map_ranges=True, map_evidence=True)
        assert both.observation_space.shape == (8 + 6 * 12,)  # ranges n, then evidence 2n
        assert "| 8+3n ... 8+4n-1" in doc


def test_demo_runs_end_to_end_with_the_shipped_policies(tmp_path, capsys):
    """``sensorplan demo``: figures, the oracle's recognition, and both tables with the
    shipped learned policies (Navigate-v0 on lab; Recognize-v0 trained on procedural scenes)."""
    pytest.importorskip("stable_baselines3")
    assert main(["demo", "--episodes", "2", "--out", str(tmp_path)]) == 0
    out = capsys.readouterr().out
    assert "5. Recognize-v0" in out and "ppo_recognize_random" in out
    assert "ppo_navigate_lab" in out
    # both times: the warm call's, and the first call's that compiles the kernels (issue 25.6)
    assert re.search(r"computed exactly in [\d.]+ ms \(\d+ ms on the first call", out)
    for name in ("fig15_visibility.png", "fig16_placement.png"):
        assert (tmp_path / name).is_file()
    assert (tmp_path / "recognize_eval" / "results.json").is_file()
