"""Hand-checked cases for the region functions (the random cross-checks against
the CGAL oracle live in test_regions_oracle.py)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely

from geometry import (
    Scene,
    SceneError,
    complete_region,
    overlap_segments,
    partial_region,
    recognizable_region,
)
from geometry._vis import domain_from_geometry, visibility_polygon

SQUARE = [[-1, -1], [1, -1], [1, 1], [-1, 1]]


def scene(**kw) -> Scene:
    d = {
        "name": "hand",
        "bounds": [[-10, -10], [10, -10], [10, 10], [-10, 10]],
        "obstacles": [],
        "target": SQUARE,
        "goal": [[0, 0]],
        "failure": [[6, -6]],
    }
    d.update(kw)
    return Scene.from_dict(d)


def inside(region, x, y) -> bool:
    return bool(region.contains(shapely.Point(x, y)))


def test_empty_room_everything_sees_the_target():
    sc = scene()
    r = complete_region(sc, target_at=(0, 0, 0))
    expected = sc.free_space.difference(sc.target_at(0, 0, 0))
    assert r.symmetric_difference(expected).area < 1e-9


def test_block_casts_tangent_bounded_shadow():
    # Block [-1,1]x[3,5] above the target [-1,1]^2: the inner tangents are the
    # lines through (1,3)-(-1,1) (y = x + 2) and (-1,3)-(1,1) (y = -x + 2).
    sc = scene(obstacles=[[[-1, 3], [1, 3], [1, 5], [-1, 5]]])
    r = complete_region(sc, target_at=(0, 0, 0))
    assert not inside(r, 0, 8)  # straight behind
    assert not inside(r, 5, 7.2)  # just above y = x + 2: the corner (-1,1) is hidden
    assert inside(r, 5, 6.8)  # just below: everything visible
    assert not inside(r, -5, 7.2)
    assert inside(r, -5, 6.8)
    # exact area of the shadow inside the room: the region y > x + 2, y > -x + 2, y > 3
    # minus the block, clipped to the room
    shadow = shapely.Polygon([(-8, 10), (-1, 3), (1, 3), (8, 10)]).difference(
        shapely.box(-1, 3, 1, 5)
    )
    assert abs(r.area - (sc.free_space.area - 4.0 - shadow.area)) < 1e-9


def test_shadow_is_not_the_union_of_corner_shadows():
    # (0, 9.5) sees all four target corners past the small block, yet the block
    # hides the middle of the target's top edge (paper 3.1.1)
    sc = scene(obstacles=[[[-0.2, 3], [0.2, 3], [0.2, 3.4], [-0.2, 3.4]]])
    r = complete_region(sc, target_at=(0, 0, 0))
    corners = sc.target_at(0, 0, 0).exterior.coords[:-1]
    block = shapely.box(-0.2, 3, 0.2, 3.4)
    assert not any(shapely.LineString([(0, 9.5), c]).intersects(block) for c in corners)
    assert not inside(r, 0, 9.5)
    assert inside(partial_region(sc, target_at=(0, 0, 0)), 0, 9.5)


def test_translating_region_is_inside_stationary_regions():
    sc = scene(
        obstacles=[[[-1, 3], [1, 3], [1, 5], [-1, 5]], [[4, -2], [5, -2], [5, 2]]],
        goal=[[-0.5, -0.5], [0.5, -0.5], [0.0, 0.4]],
    )
    moving = complete_region(sc, target_in="goal", theta=0.0)
    for q in [(-0.5, -0.5), (0.5, -0.5), (0.0, 0.4), (0.0, 0.0)]:
        fixed = complete_region(sc, target_at=(*q, 0.0))
        assert moving.difference(fixed).area < 1e-9


#: Fuzz scene 421105 (issue 10): an L-shaped room, one obstacle, a regular octagon
#: translating through a hexagon G at theta = 2.7223 rad.
FUZZ_421105 = {
    "name": "fuzz421105",
    "bounds": [[0.0, 0.0], [17560.178344726562, 0.0], [17560.178344726562, 7217.297073364258],
               [10932.060562133789, 7217.297073364258], [10932.060562133789, 19358.651344299316],
               [0.0, 19358.651344299316]],
    "obstacles": [
        [[4015.384651184082, 13206.549446105957], [626.6466979980469, 13342.866134643555],
         [666.4097900390625, 16756.04573059082], [3826.900100708008, 17448.713218688965]]
    ],
    "target": [[434.9283905029297, 65.37564849853516], [261.31324768066406, 353.7683792114258],
               [-65.37564849853516, 434.9283905029297], [-353.7683792114258, 261.31324768066406],
               [-434.9283905029297, -65.37564849853516], [-261.31324768066406, -353.7683792114258],
               [65.37564849853516, -434.9283905029297], [353.7683792114258, -261.31324768066406]],
    "goal": [[7926.815170288086, 8831.596633911133], [7801.542037963867, 9093.327354431152],
             [7428.7209396362305, 9104.028228759766], [7393.978088378906, 8863.581146240234],
             [7585.668212890625, 8525.86001586914], [7866.631088256836, 8547.19524383545]],
    "failure": [[8475.995529174805, 2983.683937072754]],
}  # fmt: skip


def test_swept_partial_region_lies_in_the_stationary_ones_at_the_vertices_of_g():
    """The swept shadows contain the stationary shadow at every vertex of G, so the swept
    partial region lies inside each stationary one.  Here GEOS's floating-point union of
    the sweep's 12 pieces (nearly coincident shadows, some with collapsed parts a few ulps
    wide) silently lost half a shadow: the region was 0.0144 D^2 too large (issue 10)."""
    sc = Scene.from_dict(FUZZ_421105)
    theta = 2.722259774894832
    swept = partial_region(sc, target_in="goal", theta=theta, conservative=True)
    assert swept.area > 0
    for x, y in sc.goal:
        fixed = partial_region(sc, target_at=(x, y, theta))
        assert swept.difference(fixed).area <= 1e-8 * sc.diameter**2


def test_sweeper_point_test_deduplicated_and_window_first_gives_the_row_by_row_answer(
    monkeypatch,
):
    """``Sweeper.blind`` tests byte-equal (p, q) rows once and computes the wanted
    directions only for rows with a window into K (issue 10, speed); the answer must be
    the plain test of every row: windows and wanted directions of all rows overlapped."""
    import geometry.sweep as sweep
    from geometry._sweep.blind import _overlaps

    got = []
    along_many = sweep.Sweeper.along_many

    def spy(self, segs, *rest):
        got.extend((self, np.asarray(a, dtype=float), np.asarray(b, dtype=float)) for a, b in segs)
        return along_many(self, segs, *rest)

    monkeypatch.setattr(sweep.Sweeper, "along_many", spy)
    sq = np.array([[-0.3, -0.3], [0.3, -0.3], [0.3, 0.3], [-0.3, 0.3]])
    sc = scene(
        target=[[-0.6, -0.4], [0.6, -0.4], [0.6, 0.4], [-0.6, 0.4]],
        obstacles=[[[2, 2], [4, 2], [4, 3], [2, 3]], [[-5, -3], [-3, -3], [-4, -1]]],
        goal=sq.tolist(),
        failure=(sq + [6.0, -6.0]).tolist(),
    )
    recognizable_region(sc, model="partial")  # paper 5.2: a target cut into wanted pieces
    sw, a, b = got[0]
    assert sw.strips is not None
    rng = np.random.default_rng(1)
    x0, y0, x1, y1 = sw.free.bounds
    p = rng.uniform([x0, y0], [x1, y1], (400, 2))
    q = a + rng.uniform(0, 1, (400, 1)) * (b - a)
    p, q = np.vstack([p, p[:150]]), np.vstack([q, q[:150]])  # repeated rows
    fast = sw.blind(p, q)
    # the plain test
    far = ~shapely.contains_xy(sw._hull_poly, p[:, 0], p[:, 1])
    far &= shapely.contains_xy(sw.free, p[:, 0], p[:, 1])
    pf, qf = p[far], q[far]
    base = np.arctan2(*(sw.hull.mean(axis=0) - pf).T[::-1])
    rel = sw.ring0[None, :, :] + (qf - pf)[:, None, :]
    ang = (np.arctan2(rel[..., 1], rel[..., 0]) - base[:, None] + np.pi) % (2 * np.pi) - np.pi
    lo, hi = ang.min(axis=1), ang.max(axis=1)
    windows = sw._windows(pf, base, np.stack([base + lo, hi - lo], axis=1))
    wanted = sw._wanted_dirs(pf, qf, base)
    plain = np.zeros(len(p), dtype=bool)
    plain[far] = ~_overlaps(*windows, *wanted, len(pf))
    assert 20 < plain.sum() < far.sum() - 20  # blind and seeing rows both tested
    assert len(np.unique(windows[2])) < far.sum()  # rows without a window occur
    np.testing.assert_array_equal(fast, plain)


def test_short_ring_edges_are_merged_before_labelling():
    """Snap-rounding nodes a corner at a hot pixel and floating overlays leave ulp-long
    edges; such an edge cannot be labelled and hid its neighbours from the tracing
    (fuzz seed 509765 lost a traced shadow of the 5.2 query), so ``_edges`` merges edges
    shorter than the labelling tolerance into a vertex, the closing edge included."""
    from geometry._sweep.shadow import _drop_short

    ring = np.array(
        [[0, 0], [1, 0], [1 + 1e-15, 3e-15], [1, 1], [0, 1], [2e-15, 1e-15]], dtype=float
    )
    out = _drop_short(ring, 1e-8)
    # the split corners merge where the lines on either side meet (geometry._sweep.shadow._corners)
    np.testing.assert_allclose(out, ring[[0, 1, 3, 4]], rtol=0, atol=1e-14)
    np.testing.assert_array_equal(_drop_short(out, 1e-8), out)


def test_rotating_target_uses_disc_tangents():
    # G is the point (0,0); with any orientation the target sweeps the disc of
    # radius sqrt(2).  The tangents from the block corner (1,3) to that disc.
    rect = [[-1, -0.5], [1, -0.5], [1, 0.5], [-1, 0.5]]
    sc = scene(target=rect, obstacles=[[[-1, 3], [1, 3], [1, 5], [-1, 5]]])
    r = complete_region(sc, target_in="goal", theta=None)
    rad = math.hypot(1, 0.5)
    d = math.hypot(1, 3)
    # the inner tangent from the block corner (1,3) to the disc, continued up-right:
    # placements below it see the whole disc, those above do not
    ang = math.atan2(3, 1) - math.asin(rad / d)
    direction = np.array([math.cos(ang), math.sin(ang)])
    normal = np.array([-direction[1], direction[0]])
    p = np.array([1, 3]) + 5 * direction
    assert inside(r, *(p - 1e-3 * normal))
    assert not inside(r, *(p + 1e-3 * normal))
    assert not inside(r, *(p + 1e-3 * normal)) or True
    fixed = complete_region(sc, target_at=(0, 0, 0.7))
    assert r.difference(fixed).area < 1e-9


def test_partial_sees_through_a_gap():
    # a wall with a narrow gap between the target and the top of the room
    wall = [
        [[-10, 3], [-0.2, 3], [-0.2, 3.5], [-10, 3.5]],
        [[0.2, 3], [10, 3], [10, 3.5], [0.2, 3.5]],
    ]
    sc = scene(obstacles=wall)
    part = partial_region(sc, target_at=(0, 0, 0))
    full = complete_region(sc, target_at=(0, 0, 0))
    assert inside(part, 0, 8)  # through the gap
    assert not inside(full, 0, 8)  # but not the whole target
    assert not inside(part, 6, 8)  # behind the wall
    # the lines through the gap's corners and the target's far corners bound the region
    # at y = 8: from (1,1) through (-0.2,3.5) lies at x = 1 + (-1.2)/2.5*7
    edge = 1 + (-1.2) / 2.5 * 7
    assert inside(part, edge + 1e-3, 8) and not inside(part, edge - 1e-3, 8)
    assert full.difference(part).area < 1e-9


def test_eps_aim_drops_narrow_fans():
    wall = [
        [[-10, 3], [-0.05, 3], [-0.05, 3.5], [-10, 3.5]],
        [[0.05, 3], [10, 3], [10, 3.5], [0.05, 3.5]],
    ]
    sc = scene(obstacles=wall)
    wide = partial_region(sc, target_at=(0, 0, 0))
    narrow = partial_region(sc, target_at=(0, 0, 0), eps_aim=0.2)
    # from (0, 8) the target is seen only through the 0.1-wide, 0.5-deep slit: the
    # fans anchored at the slit's corners open atan(0.1 / 0.5) = 0.197 rad
    assert inside(wide, 0, 8) and not inside(narrow, 0, 8)
    assert inside(partial_region(sc, target_at=(0, 0, 0), eps_aim=0.19), 0, 8)
    assert narrow.difference(wide).area < 1e-9


def test_eps_pos_keeps_a_margin_from_shadows():
    sc = scene(obstacles=[[[-1, 3], [1, 3], [1, 5], [-1, 5]]])
    r0 = complete_region(sc, target_at=(0, 0, 0))
    r1 = complete_region(sc, target_at=(0, 0, 0), eps_pos=0.3)
    assert r1.difference(r0).area < 1e-9
    assert inside(r0, 5, 6.8) and not inside(r1, 5, 6.8)  # 0.14 from the tangent
    assert inside(r1, 5, 6.0)  # 0.7 away


def test_overlap_segments_and_partial_recognition():
    rect = [[-1, -0.5], [1, -0.5], [1, 0.5], [-1, 0.5]]
    sc = scene(target=rect, goal=[[0, 0]], failure=[[1.2, 0]])
    exact = sc.replace(sensor={"range_acc": 0.0})
    segs = sorted(tuple(sorted(np.round(s.coords, 6).tolist())) for s in overlap_segments(exact))
    segs = [tuple(map(tuple, s)) for s in segs]
    assert segs == [((0.2, -0.5), (1.0, -0.5)), ((0.2, 0.5), (1.0, 0.5))]
    # the default range accuracy (1e-6 of the diameter) widens them by 2 range_acc
    rho = 2e-6 * sc.diameter
    grown = sorted(sorted(s.coords) for s in overlap_segments(sc))
    assert grown[0][0] == pytest.approx((0.2 - rho, -0.5), abs=1e-12)
    r = recognizable_region(sc, model="partial")
    # in an open room every placement outside both targets sees a non-overlap part
    both = sc.target_at(0, 0, 0).union(sc.target_at(1.2, 0, 0))
    assert r.symmetric_difference(sc.free_space.difference(both)).area < 1e-9
    # through a slit above the overlap only overlapping top edges are seen
    slit = [
        [[-10, 2], [0.5, 2], [0.5, 2.5], [-10, 2.5]],
        [[0.7, 2], [10, 2], [10, 2.5], [0.7, 2.5]],
    ]
    sc2 = scene(target=rect, goal=[[0, 0]], failure=[[1.2, 0]], obstacles=slit)
    r2 = recognizable_region(sc2, model="partial")
    assert inside(partial_region(sc2, target_at=(0, 0, 0)), 0.6, 8)
    assert inside(partial_region(sc2, target_at=(1.2, 0, 0)), 0.6, 8)
    assert not inside(r2, 0.6, 8)
    assert inside(r2, -5, 0)
    rc = recognizable_region(sc2, model="complete")
    assert rc.difference(r2).area < 1e-9


def test_separated_rooms_give_an_empty_answer():
    wall = [[[-10, -0.5], [10, -0.5], [10, 0.5], [-10, 0.5]]]
    sc = scene(
        obstacles=wall,
        target=[[-0.3, -0.3], [0.3, -0.3], [0.3, 0.3], [-0.3, 0.3]],
        goal=[[0, 3]],
        failure=[[0, -3]],
    )
    for model in ("complete", "partial"):
        r = recognizable_region(sc, model=model)
        assert r.is_empty and r.geom_type in ("Polygon", "MultiPolygon")


def test_symmetric_target_of_unknown_orientation_is_confusable():
    # square with its reference point off-centre: turning it by 90 degrees about its
    # centre moves the reference point by 2 |s| sin(45 deg) = 0.8
    tgt = [[-0.1, -0.1], [0.9, -0.1], [0.9, 0.9], [-0.1, 0.9]]
    sc = scene(target=tgt, goal=[[-3, -3]], failure=[[-2.2, -3]])
    assert recognizable_region(sc, model="complete", theta=None).is_empty
    far = scene(target=tgt, goal=[[-3, -3]], failure=[[3, -3]])
    assert not recognizable_region(far, model="complete", theta=None).is_empty


def test_bad_arguments_fail_clearly():
    sc = scene(goal=[[-2, -2], [-1, -2], [-1.5, -1]])
    with pytest.raises(ValueError, match="exactly one"):
        complete_region(sc)
    with pytest.raises(ValueError, match="exactly one"):
        complete_region(sc, target_at=(0, 0, 0), target_in="goal")
    with pytest.raises(ValueError, match="eps_pos"):
        complete_region(sc, target_at=(0, 0, 0), eps_pos=-1)
    with pytest.raises(ValueError, match="eps_aim"):
        partial_region(sc, target_at=(0, 0, 0), eps_aim=float("nan"))
    with pytest.raises(ValueError, match="target_in"):
        complete_region(sc, target_in="home")
    with pytest.raises(ValueError, match="model"):
        recognizable_region(sc, model="weak")
    with pytest.raises(ValueError, match="tol"):
        partial_region(sc, target_in="goal", tol=0.0)
    with pytest.raises(ValueError, match="tol"):
        partial_region(sc, target_at=(0, 0, 0), tol=0.1)
    with pytest.raises(NotImplementedError, match="orientation"):
        partial_region(sc, target_in="goal", theta=None)
    with pytest.raises(NotImplementedError, match="orientation"):
        recognizable_region(scene(), model="partial", theta=None)


def test_obstacle_in_hull_for_a_query_is_a_scene_error():
    sc = scene(
        obstacles=[[[1.6, -0.2], [2.5, -0.2], [2.5, 0.2], [1.6, 0.2]]],
        target=[[-0.5, -0.2], [1.5, -0.2], [1.5, 0.2], [-0.5, 0.2]],
    )
    complete_region(sc, target_at=(0, 0, 0))
    with pytest.raises(SceneError, match="assumption"):
        complete_region(sc, target_at=(0.5, 0, 0))


def test_visibility_polygon_of_a_point_in_a_room_with_a_pillar():
    free = shapely.box(0, 0, 4, 4).difference(shapely.box(1.5, 1.5, 2.5, 2.5))
    dom = domain_from_geometry(free)
    v = visibility_polygon(dom, np.array([0.5, 2.0]))
    # the pillar hides the part of the room behind it: a trapezoid from the
    # pillar's back face to the far wall, between the rays through (1.5, 1.5)
    # and (1.5, 2.5) -> at x = 4 they are at y = 2 -/+ 3.5 * 0.5 / 1.0
    hidden = shapely.Polygon([(1.5, 1.5), (4, 0.25), (4, 3.75), (1.5, 2.5)]).difference(
        shapely.box(1.5, 1.5, 2.5, 2.5)
    )
    assert abs(v.area - (free.area - hidden.area)) < 1e-9


def test_gaps_without_their_end_points_are_the_same_gaps():
    """``gaps_many(..., ends=False)`` (the sweep's point test, the corners that see K) skips
    the rays' boundary points, and ``interior=True`` the blocking test: the gaps (directions,
    segments hit) are those of the full call, the end points NaN."""
    from geometry._common import scene_domain
    from geometry._vis import gaps_many

    lab = Scene.load("sensorplan_gym/scenes/lab.json")
    dom = scene_domain(lab)
    rng = np.random.default_rng(5)
    x0, y0, x1, y1 = lab.free_space.bounds
    p = rng.uniform([x0, y0], [x1, y1], (600, 2))
    p = p[shapely.contains_xy(lab.free_space, p[:, 0], p[:, 1])][:300]
    n = len(p)
    sectors = np.stack([rng.uniform(-np.pi, np.pi, n), rng.uniform(0.1, 2 * np.pi, n)], axis=1)
    full, off = gaps_many(dom, p, sectors=sectors, flat=True)
    for interior in (False, True):
        bare, off2 = gaps_many(dom, p, sectors=sectors, flat=True, interior=interior, ends=False)
        np.testing.assert_array_equal(off2, off)
        for k in ("q", "lo", "hi", "seg"):
            np.testing.assert_array_equal(getattr(bare, k), getattr(full, k))
        assert np.isnan(bare.p0).all() and np.isnan(bare.p1).all()
    assert n > 200 and (full.seg >= 0).sum() > 1000 and np.isfinite(full.p0).all()


def test_unblocked_tests_only_the_viewpoints_on_the_boundary():
    """_vis._unblocked computes its wedge and segment tests only for the gaps of viewpoints
    that have a wedge or a segment (NaN rows are open): the answer is the definition's,
    every gap tested, bit for bit, on viewpoints with none, one or two wedges and a
    segment through them."""
    from geometry import _libm
    from geometry._vis import TAU, _unblocked

    rng = np.random.default_rng(5)
    n, g = 40, 4000
    w1, w2, along = (np.full((n, 2), np.nan) for _ in range(3))
    w1[:25] = np.stack([rng.uniform(-4, 4, 25), rng.uniform(0, TAU, 25)], axis=1)
    w2[:6] = np.stack([rng.uniform(-4, 4, 6), rng.uniform(0, TAU, 6)], axis=1)
    along[30:36] = rng.normal(size=(6, 2))
    owner = np.sort(rng.integers(0, n, g))
    mid = rng.uniform(-np.pi, 3 * np.pi, g)
    want = np.ones(g, dtype=bool)
    with np.errstate(invalid="ignore"):
        for w in (w1, w2):
            w0 = w[owner, 0]
            want &= np.isnan(w0) | (((mid - w0) % TAU) < w[owner, 1])
        ax, ay = along[owner, 0], along[owner, 1]
        want &= np.isnan(ax) | (ax * _libm.sin(mid) - ay * _libm.cos(mid) >= 0)
    got = _unblocked(mid, owner, w1, w2, along)
    assert np.array_equal(got, want)
    assert 0 < int((~got).sum()) < g  # both answers occur


def test_snap_to_boundary_looks_only_within_reach(monkeypatch):
    """weak.snap_to_boundary tests only the boundary within reach of the target (its
    bounding box grown by (NEAR_REL + 2) contact tolerances): the same ring and flags, bit
    for bit, as with the whole boundary, on targets of fuzz contact scenes (flush, touching,
    near-miss) moved about, and on targets far from every obstacle."""
    from geometry import weak
    from geometry._common import scene_domain
    from geometry._shapes import ccw_ring
    from geometry.fuzz import fuzz_scene

    rng = np.random.default_rng(9)
    cases = touched = 0
    whole = lambda env, ring, reach: (env.vert, env.seg)  # noqa: E731 - the reference
    for seed in range(104600, 104640):
        d = fuzz_scene(seed, contacts=True)
        if d is None:
            continue
        s = Scene.from_dict({k: v for k, v in d.items() if k != "features"})
        env = scene_domain(s)
        tol = weak.CONTACT_REL * env.scale
        pts = np.asarray(shapely.get_coordinates(s.goal_geom))[:4]
        # and the target's reference point put so that a vertex of it lands near a corner
        at = env.vert[rng.integers(0, len(env.vert), 4)]
        r0 = ccw_ring(s.target_at(0.0, 0.0, 0.0), clockwise=True)[0]
        pts = np.vstack([pts, at - r0])
        for x, y in pts:
            for th in (0.0, 0.4):
                for jit in (0.0, 0.5 * tol, 3 * tol, 40 * tol):
                    ring = ccw_ring(s.target_at(x, y, th), clockwise=True)
                    ring = ring + rng.normal(size=2) * jit
                    wanted = rng.random(len(ring)) < 0.8
                    got = weak.snap_to_boundary(env, ring, wanted)
                    monkeypatch.setattr(weak, "_within_reach", whole)
                    want = weak.snap_to_boundary(env, ring, wanted)
                    monkeypatch.undo()
                    assert np.array_equal(got[0], want[0]) and np.array_equal(got[1], want[1])
                    cases += 1
                    touched += not np.array_equal(want[0], ring)
    assert cases > 300 and touched > 100  # contacts were snapped in many of them
