"""Robustness of the region functions (issue 10): local frames (translation and scale
invariance), degenerate contacts (an obstacle flush on the target's hull or on a wall),
input validation.  The fuzz suite is ``tests/geometry/test_fuzz.py``."""

from __future__ import annotations

import copy
import math

import numpy as np
import pytest
import shapely

from geometry import Scene, SceneError, complete_region, partial_region, recognizable_region

#: issue 10, ``min_touch``: a triangle shares an edge with the hexagonal target's hull.
MIN_TOUCH = {
    "name": "fz3002",
    "bounds": [
        [0, 0],
        [11.940975763408888, 0],
        [11.940975763408888, 12.733508312616124],
        [0, 12.733508312616124],
    ],
    "obstacles": [
        [
            [6.8506258873402075, 9.028583425517258],
            [6.769698407362169, 9.168753932567734],
            [6.688953117870094, 9.028688613243373],
        ]
    ],
    "target": [
        [0.16185495995607727, 0.0],
        [0.08092747997803865, 0.14017050705047596],
        [-0.08092747997803859, 0.14017050705047598],
        [-0.16185495995607727, 1.9821515863633304e-17],
        [-0.0809274799780387, -0.14017050705047593],
        [0.08092747997803865, -0.14017050705047596],
    ],
    "goal": [[6.931553367318246, 9.168753932567734]],
    "failure": [
        [8.737201516977096, 4.642072062404802],
        [8.846204250173543, 5.060052968248632],
        [9.51389161656509, 5.359702211512239],
        [9.618063841219916, 4.662511022983514],
        [9.318850493541047, 4.6520602692828295],
    ],
}  # noqa: E501
#: issue 10, ``crash_flush``: a 4-vertex obstacle lying flush on a slanted wall.
CRASH_FLUSH = {
    "name": "fz1192",
    "bounds": [
        [7.765742460615002, 6.420034204260446],
        [4.939750412246212, 8.089479499263689],
        [3.3640068464446813, 5.004976261174306],
        [3.5678040424827486, 4.164483529399149],
        [3.515871532028541, 2.415818998706527],
        [5.301813804311678, 1.822423773119226],
        [5.544583351700567, 0.3311856727814302],
        [6.225348801584914, 0.4261981163872406],
        [6.550051415804774, 0.6627927919616923],
        [7.5520982863381505, 0.5932793366955593],
    ],
    "obstacles": [
        [
            [6.225348801584914, 0.4261981163872406],
            [6.379922670079395, 0.5388284208020195],
            [5.797216473612934, 1.3385346053401008],
            [5.6426426051184535, 1.2259043009253219],
        ]
    ],
    "target": [
        [0.06613759397312571, 0.0],
        [0.1390962114571156, 0.08939170717544272],
        [0.027474549460259505, 0.06016087157372131],
        [-0.023530902475173934, 0.16366102157253745],
        [-0.04331091333061636, 0.04998345849400451],
        [-0.15864639177245662, 0.04658278363347259],
        [-0.06345855670898266, -0.018633113453389017],
        [-0.10827728332654094, -0.12495864623501125],
        [-0.00941236099006959, -0.06546440862901498],
        [0.0686863736506487, -0.1504021789343033],
        [0.055638484582846245, -0.03575668287017708],
    ],
    "goal": [
        [4.336638720240444, 3.998258044710383],
        [4.629182955482975, 3.998258044710383],
        [4.629182955482975, 4.144530162331648],
        [4.482910837861709, 4.144530162331648],
        [4.482910837861709, 4.2908022799529135],
        [4.336638720240444, 4.2908022799529135],
    ],
    "failure": [
        [6.426642220350914, 3.6106886017369106],
        [6.228904670570046, 3.679480522638187],
        [6.297387770842761, 3.7433395202970132],
        [6.626411308418028, 3.8539703955175355],
        [6.601359280874021, 3.6629805138800293],
    ],
}  # noqa: E501

ROOM = {
    "name": "room",
    "bounds": [[0, 0], [10, 0], [10, 8], [0, 8]],
    "obstacles": [[[4, 3], [6, 3], [6, 5], [4, 5]]],
    "target": [[-0.5, -0.3], [0.5, -0.3], [0.5, 0.3], [-0.5, 0.3]],
    "goal": [[2, 1.5]],
    "failure": [[8, 6.5]],
}


def shifted(d: dict, dx: float, dy: float, k: float = 1.0) -> dict:
    """``d`` with world coordinates mapped by ``p -> k p + (dx, dy)`` (target scaled by k)."""
    out = copy.deepcopy(d)

    def f(pts):
        return [[k * x + dx, k * y + dy] for x, y in pts]

    for key in ("bounds", "goal", "failure"):
        out[key] = f(d[key])
    out["obstacles"] = [f(o) for o in d["obstacles"]]
    out["target"] = [[k * x, k * y] for x, y in d["target"]]
    return out


def sees_whole(scene: Scene, target: shapely.Polygon, p: np.ndarray, nb: int = 48) -> bool:
    """Independent check: every segment from ``p`` to points of the target's convex hull
    boundary misses the obstacles' interiors (shrunk by 1e-9 D against rounding)."""
    hull = np.asarray(target.convex_hull.exterior.coords)
    ts = np.linspace(0, 1, nb, endpoint=False)
    pts = (hull[:-1, None, :] + ts[None, :, None] * (hull[1:] - hull[:-1])[:, None, :]).reshape(
        -1, 2
    )
    lines = shapely.linestrings(np.stack([np.broadcast_to(p, pts.shape), pts], axis=1))
    obs = scene.obstacle_union.buffer(-1e-9 * scene.diameter, join_style="mitre")
    walls = scene.bounds_geom.buffer(1e-9 * scene.diameter, join_style="mitre")
    return not (shapely.intersects(lines, obs).any() or (~shapely.covers(walls, lines)).any())


def sample(g: shapely.Geometry, n: int, seed: int = 0) -> np.ndarray:
    rng = np.random.default_rng(seed)
    x0, y0, x1, y1 = g.bounds
    p = np.column_stack([rng.uniform(x0, x1, 50 * n), rng.uniform(y0, y1, 50 * n)])
    return p[shapely.contains_xy(g, p[:, 0], p[:, 1])][:n]


# -- degenerate contacts ------------------------------------------------------------------------


def test_min_touch_complete_region_is_right_and_consistent():
    s = Scene.from_dict(MIN_TOUCH)
    q = (*MIN_TOUCH["goal"][0], 0.0)
    r_at = complete_region(s, target_at=q)
    r_in = complete_region(s, target_in="goal", theta=0.0)
    # the triangle moved off the target by ~1e-8: the answer must be continuous
    moved = copy.deepcopy(MIN_TOUCH)
    moved["obstacles"][0] = [[x - 8e-9, y - 5e-9] for x, y in moved["obstacles"][0]]
    r_moved = complete_region(Scene.from_dict(moved), target_at=q)
    assert r_at.area == pytest.approx(r_moved.area, rel=1e-6)
    assert shapely.symmetric_difference(r_at, r_in).area < 1e-9 * s.diameter**2
    target = s.target_at(*q)
    inside = sample(r_at, 150)
    assert all(sees_whole(s, target, p) for p in inside)
    rest = shapely.difference(shapely.difference(s.free_space, r_at.buffer(1e-6)), target)
    outside = sample(rest, 150, seed=1)
    assert not any(sees_whole(s, target, p) for p in outside)


def test_crash_flush_partial_region():
    s = Scene.from_dict(CRASH_FLUSH)
    q = (4.409774779051077, 4.217666221142281, 0.0)
    r = partial_region(s, target_at=q)
    assert r.is_valid and r.area > 0
    assert shapely.difference(r, s.free_space.buffer(1e-9 * s.diameter)).area == 0.0
    # complete is inside partial
    c = complete_region(s, target_at=q)
    assert shapely.difference(c, r).area <= 1e-9 * s.diameter**2


# -- local frames --------------------------------------------------------------------------------


QUERIES = [
    ("complete at", lambda s, o: complete_region(s, target_at=(2 + o, 1.5 + o, 0.7))),
    ("partial at", lambda s, o: partial_region(s, target_at=(2 + o, 1.5 + o, 0.7))),
    ("complete in", lambda s, o: complete_region(s, target_in="goal", theta=0.3)),
    ("complete any", lambda s, o: complete_region(s, target_in="goal", theta=None)),
    ("recognizable complete", lambda s, o: recognizable_region(s, model="complete")),
    ("recognizable partial", lambda s, o: recognizable_region(s, model="partial", theta=0.0)),
    ("partial eps", lambda s, o: partial_region(s, target_at=(2 + o, 1.5 + o, 0.0), eps_pos=0.2)),
]


@pytest.mark.parametrize("offset", [1e3, 1e6, -3.7e7, 1e9])
@pytest.mark.parametrize("name,query", QUERIES, ids=[q[0] for q in QUERIES])
def test_translation_invariance(offset, name, query):
    base = Scene.from_dict(ROOM)
    far = Scene.from_dict(shifted(ROOM, offset, offset))
    r0 = query(base, 0.0)
    r1 = shapely.affinity.translate(query(far, offset), -offset, -offset)
    # the only error left: the input's and the output's rounding at |offset|
    slack = 64 * np.spacing(abs(offset)) * base.diameter
    assert abs(r1.area - r0.area) <= slack + 1e-12
    assert shapely.symmetric_difference(r0, r1).area <= slack + 1e-12, name


@pytest.mark.parametrize("k", [1e-6, 3.0, 1e6])
def test_scale_invariance(k):
    base = Scene.from_dict(ROOM)
    big = Scene.from_dict(shifted(ROOM, 0.0, 0.0, k))
    r0 = partial_region(base, target_at=(2, 1.5, 0.7))
    r1 = partial_region(big, target_at=(2 * k, 1.5 * k, 0.7))
    assert r1.area / k**2 == pytest.approx(r0.area, rel=1e-9)
    c0 = complete_region(base, target_in="goal", theta=None)
    c1 = complete_region(big, target_in="goal", theta=None)
    assert c1.area / k**2 == pytest.approx(c0.area, rel=1e-9)


def test_small_room_far_away_is_valid():
    # issue 10: a 0.01 m square room at offset 1e6 was a "zero-area polygon"
    d = shifted(ROOM, 1e6, 1e6, 1e-3)
    s = Scene.from_dict(d)
    assert s.local.diameter == pytest.approx(ROOM_DIAM / s.frame.scale * 1e-3, rel=1e-7)
    r = complete_region(s, target_at=(1e6 + 2e-3, 1e6 + 1.5e-3, 0.0))
    r0 = complete_region(Scene.from_dict(ROOM), target_at=(2, 1.5, 0.0))
    assert r.area / 1e-6 == pytest.approx(r0.area, rel=1e-6)
    # a thin obstacle (1 x 1e-7) far away
    thin = copy.deepcopy(ROOM)
    thin["obstacles"] = [[[4, 3], [6, 3], [6, 3 + 1e-7], [4, 3 + 1e-7]]]
    Scene.from_dict(shifted(thin, 1e5, 1e5))


ROOM_DIAM = math.hypot(10, 8)


def test_errors_name_world_coordinates():
    d = shifted(ROOM, 1e6, 1e6)
    d["goal"] = [[1e6 + 5, 1e6 + 4]]  # inside the obstacle
    with pytest.raises(SceneError, match=r"goal: .*obstacles\[0\] at \(1000005, 1000004\)"):
        Scene.from_dict(d)


# -- input validation ----------------------------------------------------------------------------


def test_dict_scene_accepted():
    s = Scene.from_dict(ROOM)
    assert complete_region(ROOM, target_at=(2, 1.5, 0)).equals(
        complete_region(s, target_at=(2, 1.5, 0))
    )
    assert partial_region(ROOM, target_at=(2, 1.5, 0)).area > 0
    assert recognizable_region(ROOM).area > 0
    with pytest.raises(SceneError, match="scene must be"):
        complete_region("room.json", target_at=(2, 1.5, 0))


@pytest.mark.parametrize("bad", ["abc", "0", True, float("nan"), [0.0]])
def test_theta_type_errors_name_theta(bad):
    s = Scene.from_dict(ROOM)
    for f in (
        lambda: complete_region(s, target_in="goal", theta=bad),
        lambda: partial_region(s, target_in="goal", theta=bad),
        lambda: recognizable_region(s, theta=bad),
    ):
        with pytest.raises(ValueError, match="theta"):
            f()


def test_eps_aim_range():
    s = Scene.from_dict(ROOM)
    with pytest.raises(ValueError, match=r"eps_aim must be in \[0, pi\)"):
        partial_region(s, target_at=(2, 1.5, 0), eps_aim=math.pi)
    with pytest.raises(ValueError, match="eps_aim"):
        recognizable_region(s, model="partial", eps_aim=4.0)
    with pytest.raises(SceneError, match="eps_aim_deg"):
        Scene.from_dict({**ROOM, "sensor": {"eps_aim_deg": 200}})
    assert partial_region(s, target_at=(2, 1.5, 0), eps_aim=3.0).is_valid


def test_eps_pos_larger_than_room():
    s = Scene.from_dict(ROOM)
    with pytest.raises(ValueError, match="eps_pos.*diameter"):
        complete_region(s, target_at=(2, 1.5, 0), eps_pos=20.0)
    with pytest.raises(ValueError, match="eps_pos"):
        partial_region(s, target_at=(2, 1.5, 0), eps_pos=1e9)


def test_inputs_issue26_item10():
    """Issue 26 item 10 (and 25 item 6): strings are not numbers, degrees are not radians,
    huge coordinates are named as such, and query-time errors name world coordinates."""
    s = Scene.from_dict(ROOM)
    for kw in ({"eps_pos": "0.1"}, {"eps_aim": "0.1"}, {"eps_pos": True}):
        with pytest.raises(ValueError, match=r"must be a number, got"):
            partial_region(s, target_at=(2, 1.5, 0), **kw)
    with pytest.raises(ValueError, match="eps_pos must be a number"):
        complete_region(s, target_at=(2, 1.5, 0), eps_pos="0.1")
    # theta = 90 (degrees by mistake) is rejected like the JSON start's theta
    for f in (
        lambda: complete_region(s, target_at=(2, 1.5, 90)),
        lambda: partial_region(s, target_at=(2, 1.5, 90.0)),
        lambda: complete_region(s, target_in="goal", theta=90),
        lambda: partial_region(s, target_in="goal", theta=-90.0),
        lambda: recognizable_region(s, theta=90),
    ):
        with pytest.raises(ValueError, match=r"radians \(did you mean -?90(\.0)? degrees"):
            f()
    assert complete_region(s, target_at=(2, 1.5, 2 * math.pi - 1e-9)).area > 0
    with pytest.raises(SceneError, match=r"bounds\[0\]: coordinate 1e\+300 is beyond"):
        Scene.from_dict(shifted(ROOM, 1e300, 0.0))
    # a query-time error names the user's coordinates, not the local frame's
    d = shifted(ROOM, 512345.0, 5412345.0)
    far = Scene.from_dict(d)
    with pytest.raises(SceneError, match=r"target at \(512349\.2, 5412349, 0\).*meets"):
        complete_region(far, target_at=(512345.0 + 4.2, 5412345.0 + 4.0, 0.0))


def test_start_is_the_robots_pose_issue25_item5():
    """The robot's start is validated as a point, never as the target placed there."""
    d = copy.deepcopy(ROOM)
    d["target"] = [[1.0, 1.0], [2.0, 1.0], [2.0, 2.0]]  # reference point outside the target
    d["goal"], d["failure"] = [[1.0, 1.0]], [[6.5, 5.0]]
    d["start"] = [3.2, 2.5, 0.0]  # free, but the target placed there would meet the obstacle
    s = Scene.from_dict(d)
    assert s.start == (3.2, 2.5, 0.0)
    d["start"] = [5.0, 4.0, 0.0]
    with pytest.raises(SceneError, match=r"start: \(5, 4\) is not in the free space"):
        Scene.from_dict(d)


# -- sensor accuracy in confusability ---------------------------------------------------------

RECT = [[-1, -0.5], [1, -0.5], [1, 0.5], [-1, 0.5]]
SLIT = [
    [[-10, 2], [0.5, 2], [0.5, 2.5], [-10, 2.5]],
    [[0.7, 2], [10, 2], [10, 2.5], [0.7, 2.5]],
]


def slit_scene(h: tuple[float, float], size: float = 0.0, **sensor) -> Scene:
    def region(x: float, y: float) -> list[list[float]]:
        if size == 0:
            return [[x, y]]
        return [
            [x - size, y - size],
            [x + size, y - size],
            [x + size, y + size],
            [x - size, y + size],
        ]

    d = {
        "name": "slit",
        "bounds": [[-10, -10], [10, -10], [10, 10], [-10, 10]],
        "obstacles": SLIT,
        "target": RECT,
        "goal": region(0.0, 0.0),
        "failure": region(*h),
    }
    if sensor:
        d["sensor"] = sensor
    return Scene.from_dict(d)


@pytest.mark.parametrize("size", [0.0, 0.05], ids=["points (5.1)", "polygons (5.2)"])
def test_slit_with_rounded_h_is_confusable(size):
    """Through the slit only the overlapping top edges of A_g and A_h are seen: not
    recognizable.  H written to 6 decimals (edges collinear to ~4e-7) must not change that."""
    kw = {} if size == 0 else {"theta": 0.0}
    # polygons: H sits on top of G (touching), so only the top configurations of G
    # give top edges collinear with those of H
    y = 2 * size
    exact = recognizable_region(slit_scene((1.2, y), size), model="partial", **kw)
    rounded_scene = slit_scene((1.2000004, y + 0.0000004), size)
    rounded = recognizable_region(rounded_scene, model="partial", **kw)
    above = shapely.box(-10, 2.5, 10, 10)
    assert shapely.intersection(exact, above).area < 1e-9
    assert shapely.intersection(rounded, above).area < 1e-9
    assert rounded.area == pytest.approx(exact.area, rel=1e-3)
    # a sensor declared exact to the last bit tells them apart again (the old answer)
    bitexact = slit_scene((1.2000004, y + 0.0000004), size, range_acc=0.0, normal_acc_deg=0.0)
    r = recognizable_region(bitexact, model="partial", **kw)
    assert shapely.intersection(r, above).area > 0.1


def test_accuracy_fields_validated_and_scaled():
    with pytest.raises(SceneError, match="range_acc"):
        Scene.from_dict({**ROOM, "sensor": {"range_acc": -1}})
    with pytest.raises(SceneError, match="normal_acc_deg"):
        Scene.from_dict({**ROOM, "sensor": {"normal_acc_deg": 90}})
    s = Scene.from_dict({**ROOM, "sensor": {"range_acc": 0.016}})
    assert s.range_acc == 0.016 and s.local.range_acc == 0.016 / s.frame.scale
    assert Scene.from_dict(ROOM).range_acc == pytest.approx(1e-6 * ROOM_DIAM)


# -- time limits and progress of the swept queries ------------------------------------------


def test_swept_timeout_and_progress():
    from geometry.sweep import QueryTimeout

    d = {**ROOM, "goal": [[1.5, 1], [2.5, 1], [2.5, 2], [1.5, 2]]}
    d["failure"] = [[7.5, 6], [8.5, 6], [8.5, 7], [7.5, 7]]
    s = Scene.from_dict(d)
    seen: list[tuple[int, int]] = []
    r = partial_region(s, target_in="goal", theta=0.0, progress=lambda i, n: seen.append((i, n)))
    assert seen == [(1, 4), (2, 4), (3, 4), (4, 4)] and r.area > 0
    with pytest.raises(QueryTimeout, match=r"partial_region\(target_in=...\) ran past its "
                       r"timeout after sweeping 0 of the 4 edges"):  # fmt: skip
        partial_region(s, target_in="goal", theta=0.0, timeout=1e-9)
    assert issubclass(QueryTimeout, TimeoutError)
    seen.clear()
    recognizable_region(
        s, model="partial", theta=0.0, timeout=60, progress=lambda i, n: seen.append((i, n))
    )
    assert seen == [(k, 8) for k in range(1, 9)]
    with pytest.raises(QueryTimeout, match="recognizable_region"):
        recognizable_region(s, model="partial", theta=0.0, timeout=1e-9)
    for bad in (0, -1, "5", float("inf")):
        with pytest.raises(ValueError, match="timeout"):
            partial_region(s, target_in="goal", theta=0.0, timeout=bad)
    with pytest.raises(ValueError, match="progress"):
        partial_region(s, target_in="goal", theta=0.0, progress=3)
    with pytest.raises(ValueError, match="target_in"):
        partial_region(s, target_at=(2, 1.5, 0), timeout=5)


# -- reference point anywhere ---------------------------------------------------------------------

#: An L-shaped robot; ``c`` is where the reference point goes in each variant.
L_SHAPE = np.array([[0.0, 0.0], [0.6, 0.0], [0.6, 0.2], [0.2, 0.2], [0.2, 0.5], [0.0, 0.5]])


@pytest.mark.parametrize(
    "ref",
    [(0.1, 0.1), (0.2, 0.2), (0.4, 0.4), (-0.3, 0.25)],
    ids=["inside", "inner corner (on the outline)", "outside, in the notch", "outside, behind"],
)
def test_reference_point_anywhere(ref):
    """The regions depend on where the target *is*, not on its reference point: a target
    framed at ``ref`` with G/H at g + ref equals the same target framed inside."""
    c = np.asarray(ref)
    base_ref = np.array([0.1, 0.1])
    d = {**ROOM, "goal": [[2.0, 1.5], [2.4, 1.5], [2.4, 1.9], [2.0, 1.9]], "failure": [[8, 6.0]]}

    def framed(r: np.ndarray) -> Scene:
        out = copy.deepcopy(d)
        out["target"] = (L_SHAPE - r).tolist()
        out["goal"] = (np.asarray(d["goal"]) + r).tolist()
        out["failure"] = (np.asarray(d["failure"]) + r).tolist()
        return Scene.from_dict(out)

    s0, s1 = framed(base_ref), framed(c)
    rot = np.array([[math.cos(0.3), -math.sin(0.3)], [math.sin(0.3), math.cos(0.3)]])
    tiny = 1e-9 * s0.diameter**2
    pairs = [
        (complete_region(s0, target_in="goal", theta=0.0),
         complete_region(s1, target_in="goal", theta=0.0)),
        (partial_region(s0, target_at=(8.1, 6.1, 0.3)),
         partial_region(s1, target_at=(*(np.array([8.1, 6.1]) + rot @ (c - base_ref)), 0.3))),
        (partial_region(s0, target_in="goal", theta=0.0),
         partial_region(s1, target_in="goal", theta=0.0)),
    ]  # fmt: skip
    for a, b in pairs:
        assert a.area > 0 and shapely.symmetric_difference(a, b).area < 1e-6 * s0.diameter**2
    # rotating about a different point sweeps a different area: only containment in the
    # fixed-orientation region holds, and the any-orientation region is well defined
    any1 = complete_region(s1, target_in="goal", theta=None)
    assert shapely.difference(any1, pairs[0][1]).area < tiny
    assert recognizable_region(s1).is_valid


def test_disc_sum_contains_the_exact_minkowski_sum():
    """GEOS buffers cut into the disc (simplification, vertices on the circle): the
    rotating target's swept area and the eps_pos growth use geometry._shapes.disc_sum."""
    from geometry._shapes import disc_sum

    g = shapely.Polygon([(0, 0), (1, 0.1), (1.3, 1.0), (0.4, 0.6), (0.1, 1.2)])
    r = 0.37
    out = disc_sum(g, r)
    ring = shapely.get_coordinates(out.exterior)
    mids = 0.5 * (ring[1:] + ring[:-1])
    d = shapely.distance(g, shapely.points(np.vstack([ring, mids])))
    assert d.min() >= r * (1 - 1e-12) and d.max() <= r * 1.0013
    # the buffer this replaced: chords inside the disc
    b = shapely.get_coordinates(g.buffer(r / math.cos(math.pi / 64), quad_segs=16).exterior)
    assert shapely.distance(g, shapely.points(0.5 * (b[1:] + b[:-1]))).min() < r * (1 - 1e-5)
    assert disc_sum(shapely.Point(1, 2), 1.0).contains(shapely.Point(1, 2).buffer(0.999))
