"""The demo's figures read like the paper's: every legend entry visible and distinct, the
aim a labelled arrow in its own colour, units on the axes, degenerate legs merged, the
rollout panels numbered, the env frame saved with a legend."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np
import pytest
from matplotlib.colors import to_rgba

from agents.demo import figure_15, figure_16, merge_short_legs


def test_merge_short_legs_drops_hairline_legs():
    path = np.array([[11.2, 6.2], [9.5006, 5.4986], [9.5003, 5.4985], [7.59, 5.09]])
    out = merge_short_legs(path, 0.0144)
    assert len(out) == 3  # the 0.0003 m leg is gone
    assert np.allclose(out[0], path[0]) and np.allclose(out[-1], path[-1])
    # a corner a hair from the end is replaced by the end
    out = merge_short_legs(np.array([[0, 0], [1, 0], [1, 1e-5]]), 1e-3)
    assert out.tolist() == [[0, 0], [1, 1e-5]]
    # real legs are kept
    sq = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], dtype=float)
    assert np.array_equal(merge_short_legs(sq, 1e-3), sq)


@pytest.fixture(scope="module")
def lab_plan():
    from agents.planning.oracle import plan_viewpoint
    from sensorplan_gym.core.world import World, WorldConfig, load_scene

    scene = load_scene("lab")
    world = World(scene, WorldConfig())
    margin = 2e-3 * world.diameter
    plan = plan_viewpoint(world, scene.start[:2], margin=margin)
    assert plan.status == "ok"
    return scene, world, plan, margin


def _legend(fig):
    ax = fig.axes[0]
    leg = ax.get_legend()
    assert leg is not None
    return ax, {t.get_text(): h for t, h in zip(leg.get_texts(), leg.legend_handles, strict=True)}


def _face(h):
    return np.array(to_rgba(h.get_facecolor() if hasattr(h, "get_facecolor") else h.get_color()))


def test_figure_16_legend_regions_aim_units(lab_plan):
    import matplotlib.pyplot as plt

    scene, world, plan, margin = lab_plan
    fig = figure_16(scene, world, plan, scene.start, margin)
    try:
        ax, entries = _legend(fig)
        labels = list(entries)
        rec = next(h for t, h in entries.items() if t.startswith("recognizable region"))
        shr = next(h for t, h in entries.items() if t.startswith("shrunk by"))
        # both regions visible in the legend and told apart: opaque enough, other colours,
        # the recognizable region outlined
        assert rec.get_alpha() is None or rec.get_alpha() >= 0.5
        assert shr.get_alpha() is None or shr.get_alpha() >= 0.5
        assert not np.allclose(_face(rec)[:3], _face(shr)[:3])
        assert rec.get_linewidth() > 0
        aim = next(t for t in labels if t.startswith("aim "))
        assert aim.endswith("°")
        path = next(t for t in labels if "path" in t or "motion" in t)
        assert "2 legs" in path  # the 0.0003 m corner leg of the lab plan is merged
        # the aim arrow has its own colour, not the path's
        path_color = to_rgba(entries[path].get_color())
        aim_color = to_rgba(entries[aim].get_color())
        assert not np.allclose(path_color, aim_color)
        # and a text label next to its head in the same colour
        texts = [t for t in ax.texts if t.get_text() == aim]
        assert texts and np.allclose(to_rgba(texts[0].get_color()), aim_color)
        for need in ("walls", "obstacles", "G: goal region", "H: failure region"):
            assert need in labels
        assert ax.get_xlabel() == "x (m)" and ax.get_ylabel() == "y (m)"
        # the zoom on the margin band exists and is much narrower than the scene
        zoom = ax.child_axes[0]
        x0, x1 = zoom.get_xlim()
        assert 2 * margin < x1 - x0 < 0.2 * world.diameter
    finally:
        plt.close(fig)


def test_figure_15_legend_and_units(lab_plan):
    import matplotlib.pyplot as plt

    from geometry import complete_region

    scene = lab_plan[0]
    region = complete_region(scene, target_in="goal", theta=0.0)
    fig = figure_15(scene, region)
    try:
        ax, entries = _legend(fig)
        assert any(t.startswith("complete visibility") for t in entries)
        assert "G: goal region" in entries and "H: failure region" in entries
        assert ax.get_xlabel() == "x (m)"
    finally:
        plt.close(fig)


def test_rollout_panels_numbered():
    import matplotlib.pyplot as plt

    from sensorplan_gym.render_rollout import contact_sheet, sheet_figure

    frames = [np.full((40, 50, 3), 10 * i, np.uint8) for i in range(11)]
    fig = sheet_figure(frames, 4, 2)
    try:
        titles = [ax.get_title() for ax in fig.axes]
        assert titles == [
            "1/4: step 0 of 10 (reset)",
            "2/4: step 3 of 10",
            "3/4: step 7 of 10",
            "4/4: step 10 of 10 (last)",
        ]
    finally:
        plt.close(fig)
    sheet = contact_sheet(frames, 4, 2)
    assert sheet.dtype == np.uint8 and sheet.shape[2] == 3
    assert sheet.shape[0] > 2 * 40 and sheet.shape[1] >= 2 * 50


def test_env_legend_matches_renderer_colours():
    from matplotlib.colors import to_hex

    from sensorplan_gym.core.rendering import legend_handles

    handles = legend_handles()
    labels = [h.get_label() for h in handles]
    assert len(set(labels)) == len(labels)
    region = handles[labels.index("recognizable region")]
    assert to_hex(region.get_facecolor()) == "#7fd37f"
    for need in ("obstacles", "G: goal region", "H: failure region", "range beams"):
        assert need in labels


def test_human_viewer_says_when_it_cannot_show():
    import warnings

    import matplotlib.pyplot as plt

    from sensorplan_gym.core.rendering import HumanViewer

    v = HumanViewer()
    frame = np.zeros((8, 8, 3), np.uint8)
    with pytest.warns(UserWarning, match="cannot open a window"):
        v.show(frame, 10)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        v.show(frame, 10)  # once per viewer
    v.close()
    plt.close("all")
