"""Scene families (:mod:`geometry.families`): valid, in-support, deterministic samples; the
measured parameters of a scene; the bundled scenes inside ``hard``'s support."""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import pytest

from geometry import Scene
from geometry.families import (
    DIFFICULTIES,
    FAMILIES,
    HARD,
    ROOM_SHAPES,
    SceneFamily,
    get_difficulty,
    get_family,
    scene_parameters,
)
from sensorplan_gym.core.scenes import BUNDLED_SCENES, load_scene

N = 40  # samples per family


@pytest.mark.parametrize("name", sorted(FAMILIES))
def test_samples_are_valid_scenes_inside_their_family(name):
    fam = FAMILIES[name]
    t0 = time.perf_counter()
    for k in range(N):
        d = fam.sample_dict(np.random.default_rng([11, k]))
        scene = Scene.from_dict(d)  # validates (paper's assumptions included)
        scene.check_clear(scene.swept_hull("goal"), "CH(A + G)")
        scene.check_clear(scene.swept_hull("failure"), "CH(A + H)")
        p = scene_parameters(scene)
        assert fam.violations(p) == [], (name, k, p)
    per_scene = (time.perf_counter() - t0) / N
    assert per_scene < 1.0, f"{name}: {per_scene:.3f} s per scene"


def test_every_room_shape_is_drawn_and_classified_as_such():
    for shape in ROOM_SHAPES:
        fam = dataclasses.replace(HARD, name=shape, shapes=(shape,))
        for k in range(8):
            p = scene_parameters(fam.sample(np.random.default_rng([3, k])))
            assert p["room_shape"] == shape, (shape, k, p)
    seen = {
        scene_parameters(HARD.sample(np.random.default_rng([5, k])))["room_shape"]
        for k in range(40)
    }
    assert seen == set(ROOM_SHAPES)


def test_kinds_convexity_fov_and_range_follow_the_family():
    fam = SceneFamily(
        "narrow",
        fov_deg=(45.0, 60.0),
        max_range=(0.4, 0.6),
        range_limited=1.0,
        region_kinds=("polygon",),
        target_convex=(False,),
        target_vertices=(5, 6),
    )
    for k in range(10):
        p = scene_parameters(fam.sample(np.random.default_rng([9, k])))
        assert 45 <= p["fov_deg"] <= 60
        assert 0.4 - 1e-9 <= p["max_range_rel"] <= 0.6 + 1e-9
        assert p["goal_kind"] == p["failure_kind"] == "polygon"
        assert p["target_convex"] is False and 5 <= p["target_vertices"] <= 6
    assert fam.contains(p)
    assert not FAMILIES["easy"].contains(p)  # support checks can fail
    v = FAMILIES["easy"].violations(p)
    assert any(m.startswith("fov_deg=") for m in v) and any("goal_kind" in m for m in v)


def test_sampling_is_deterministic_in_the_generator():
    for fam in FAMILIES.values():
        a = fam.sample_dict(np.random.default_rng([2, 7]))
        b = fam.sample_dict(np.random.default_rng([2, 7]))
        c = fam.sample_dict(np.random.default_rng([2, 8]))
        assert a == b and a != c


@pytest.mark.parametrize("name", BUNDLED_SCENES)
def test_bundled_scenes_lie_inside_hard(name):
    p = scene_parameters(load_scene(name))
    assert HARD.violations(p) == [], (name, p)


def test_scene_parameters_of_a_known_scene():
    p = scene_parameters(load_scene("edr"))
    assert p["fov_deg"] == 150 and p["max_range"] is None and p["max_range_rel"] is None
    assert p["room_shape"] == "rectangle" and p["reflex_corners"] == 0
    assert p["goal_kind"] == "polygon" and p["target_convex"] is False
    assert p["clutter"] == pytest.approx(0.15475)
    assert p["diameter"] == pytest.approx(200**0.5)


def test_difficulties_and_lookup():
    assert [DIFFICULTIES[k].min_start_distance for k in ("easy", "medium", "hard")] == [
        0.0,
        0.2,
        0.35,
    ]
    assert get_difficulty("hard").family is HARD and get_family("hard") is HARD
    with pytest.raises(ValueError, match="unknown scene family 'huge'"):
        get_family("huge")
    with pytest.raises(ValueError, match="unknown difficulty"):
        get_difficulty("insane")


def test_bad_ranges_and_impossible_families_fail_clearly():
    with pytest.raises(ValueError, match="SceneFamily.fov_deg"):
        SceneFamily("x", fov_deg=(90.0, 400.0))
    with pytest.raises(ValueError, match="SceneFamily.shapes"):
        SceneFamily("x", shapes=("circle",))
    with pytest.raises(ValueError, match="SceneFamily.max_range"):
        SceneFamily("x", range_limited=0.5)
    with pytest.raises(ValueError, match="SceneFamily.clutter"):
        SceneFamily("x", clutter=(0.3, 0.1))
    tight = SceneFamily("tight", diameter=(4.0, 4.2), clutter=(0.5, 0.6), max_tries=5)
    with pytest.raises(RuntimeError, match="'tight': no valid scene in 5 draws"):
        tight.sample(np.random.default_rng(0))


def test_g_and_h_share_a_kind_unless_mixed():
    kinds = [scene_parameters(HARD.sample(np.random.default_rng([4, k]))) for k in range(30)]
    assert {(p["goal_kind"], p["failure_kind"]) for p in kinds} == {
        ("point", "point"),
        ("polygon", "polygon"),
    }
    mixed = dataclasses.replace(HARD, name="mixed", mixed_regions=True)
    pairs = [scene_parameters(mixed.sample(np.random.default_rng([4, k]))) for k in range(30)]
    odd = [p for p in pairs if p["goal_kind"] != p["failure_kind"]]
    assert odd and mixed.contains(odd[0]) and not HARD.contains(odd[0])
