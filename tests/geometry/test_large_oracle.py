"""Exactness at 1,000+ edges: the grid-accelerated visibility (geometry.visindex) and the
regions built on it against the brute-force ray casts and CGAL (pyvispoly).

* ray shooting through the grid returns the same first segment as the brute force for
  random rays from free points, from domain vertices and with a target ring added;
* visibility polygons agree with CGAL's at random free points (symmetric difference
  below 1e-9 of the polygon's area);
* for sampled placements (those within 1e-4 of the diameter of a region boundary
  skipped), membership in complete_region / partial_region (stationary) and
  recognizable_region (complete model, polygonal G/H) agrees with the CGAL verdict on
  100 % of the placements, on a generated 1,200-edge scene and on the office floor.
"""

from __future__ import annotations

import functools
from pathlib import Path

import numpy as np
import pytest
import shapely

import sensorplan_gym
from geometry import Scene, _vis, complete_region, partial_region, recognizable_region, visindex
from geometry._common import scene_domain
from geometry.generate import scene_with_edges

OFFICE = Path(sensorplan_gym.__file__).resolve().parent / "scenes" / "large" / "office_floor.json"
SKIP_REL = 1e-4


@functools.cache
def _scenes() -> tuple[Scene, Scene]:
    return (Scene.from_dict(scene_with_edges(1200, 7)), Scene.load(OFFICE))


def _free_points(scene: Scene, n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    fs = scene.free_space
    shapely.prepare(fs)
    x0, y0, x1, y1 = fs.bounds
    out = np.empty((0, 2))
    while len(out) < n:
        c = rng.uniform([x0, y0], [x1, y1], (4 * n, 2))
        out = np.vstack([out, c[shapely.contains_xy(fs, c[:, 0], c[:, 1])]])
    return out[:n]


@pytest.mark.skipif(not visindex.available(), reason="numba not installed (fast extra)")
@pytest.mark.parametrize("which", [0, 1])
def test_grid_ray_shooting_equals_brute_force(which):
    scene = _scenes()[which]
    dom = scene_domain(scene)
    assert len(dom.seg) >= 1000
    rng = np.random.default_rng(which)
    q = np.vstack([np.repeat(_free_points(scene, 40, which), 50, axis=0), dom.vert])
    phi = rng.uniform(-np.pi, np.pi, len(q))
    # rays from vertices point into the free space (mid-wedge), as gaps_many casts them
    nv = len(dom.vert)
    w = dom.vert_wedge
    phi[-nv:] = w[:, 0] + rng.uniform(0.05, 0.95, nv) * w[:, 1]
    a = visindex.first_hits(dom, q, phi)
    b = _vis._first_hits(dom, q, phi, brute=True)
    assert np.array_equal(a, b)
    # a domain with the target added as a hole shares the grid, adds its ring
    c = scene.goal_geom.centroid
    ring = np.asarray(scene.target_at(c.x, c.y, 0.3).exterior.coords)[:-1]
    dom2 = dom.with_ring(ring[::-1], 2)
    assert visindex.grid_for(dom2)[0] is visindex.grid_for(dom)[0]
    a = visindex.first_hits(dom2, q[:-nv], phi[:-nv])
    b = _vis._first_hits(dom2, q[:-nv], phi[:-nv], brute=True)
    assert np.array_equal(a, b)
    # boundary tests from vertices and edge midpoints
    pts = np.vstack([dom.vert, 0.5 * (dom.seg[:, :2] + dom.seg[:, 2:])])
    for x, y in zip(visindex.blocking(dom, pts), _brute_blocking(dom, pts), strict=True):
        assert np.array_equal(x, y, equal_nan=True)


def _brute_blocking(dom, pts):
    """_vis._blocking with the index switched off."""
    saved = visindex._HAVE_NUMBA
    visindex._HAVE_NUMBA = False
    try:
        return _vis._blocking(dom, pts)
    finally:
        visindex._HAVE_NUMBA = saved


@pytest.fixture
def pv_oracle():
    """tests/oracle.py (CGAL via pyvispoly, dev extra); skips without pyvispoly."""
    pytest.importorskip("pyvispoly")
    try:
        from tests import oracle
    except ImportError:  # pragma: no cover - plain pytest from tests/
        import oracle  # type: ignore[no-redef]
    return oracle


@pytest.mark.parametrize("which", [0, 1])
def test_visibility_polygons_match_cgal(which, pv_oracle):
    scene = _scenes()[which]
    oracle = pv_oracle.VisOracle(scene)
    dom = scene_domain(scene)
    for p in _free_points(scene, 25, 10 + which):
        ours = _vis.visibility_polygon(dom, p)
        ref = oracle.visibility(p)
        assert ours.symmetric_difference(ref).area <= 1e-9 * ref.area


def _agree(scene: Scene, region, verdict, pts: np.ndarray) -> tuple[int, int]:
    """(checked, disagreements) over ``pts``, skipping those near the region's boundary."""
    shapely.prepare(region)
    bd = region.boundary
    checked = bad = 0
    for p in pts:
        pt = shapely.Point(p)
        if bd.distance(pt) < SKIP_REL * scene.diameter:
            continue
        checked += 1
        bad += bool(region.covers(pt)) != bool(verdict(p))
    return checked, bad


@pytest.mark.parametrize("which", [0, 1])
def test_regions_agree_with_cgal_at_1000_plus_edges(which, pv_oracle):
    scene = _scenes()[which]
    assert len(scene.bounds) + sum(len(o) for o in scene.obstacles) >= 1000
    oracle = pv_oracle.VisOracle(scene)
    c = scene.goal_geom.representative_point()
    th = 0.3 if which == 0 else 0.0
    target = scene.target_at(c.x, c.y, th)
    pts = _free_points(scene, 160, 20 + which)
    vis = {tuple(p): oracle.visibility(p) for p in pts}
    results = {}

    def outside(p, area):
        return not area.covers(shapely.Point(p))

    C = complete_region(scene, target_at=(c.x, c.y, th))
    results["complete"] = _agree(
        scene,
        C,
        lambda p: (
            outside(p, target) and pv_oracle.sees_completely(oracle, p, target, vis[tuple(p)])
        ),
        pts,
    )
    P = partial_region(scene, target_at=(c.x, c.y, th))
    results["partial"] = _agree(
        scene,
        P,
        lambda p: outside(p, target) and pv_oracle.sees_partially(oracle, p, target, vis[tuple(p)]),
        pts,
    )
    a = scene.target_at(0.0, 0.0, th)
    swept = [
        pv_oracle.minkowski_sum(a, scene.goal_geom),
        pv_oracle.minkowski_sum(a, scene.failure_geom),
    ]
    R = recognizable_region(scene, model="complete", theta=th)
    results["recognizable"] = _agree(
        scene,
        R,
        lambda p: all(
            outside(p, s) and pv_oracle.sees_completely(oracle, p, s, vis[tuple(p)]) for s in swept
        ),
        pts,
    )
    for name, (checked, bad) in results.items():
        assert checked >= 100, (name, checked)
        assert bad == 0, f"{name}: {bad} of {checked} placements disagree with CGAL"
    # the sample is not trivial: some placements inside and some outside each region
    assert 0 < sum(C.covers(shapely.Point(p)) for p in pts) < len(pts)
    assert 0 < sum(P.covers(shapely.Point(p)) for p in pts) < len(pts)


@pytest.mark.skipif(not visindex.available(), reason="numba not installed (fast extra)")
def test_compiled_sorted_gaps_equal_numpy():
    """visindex.sorted_gaps (narrow-sector pre-filter, compiled sort) returns exactly the
    gaps of the numpy reference _vis._sorted_gaps: reflex vertices as viewpoints, narrow
    and wide sectors, extra directions with NaNs, boundary and interior modes."""
    dom = scene_domain(_scenes()[0])
    rng = np.random.default_rng(5)
    q = np.vstack([dom.vert[dom.reflex][:300], _free_points(_scenes()[0], 50, 3)])
    n = len(q)
    start = rng.uniform(-4.0, 4.0, n)
    width = np.where(rng.random(n) < 0.6, rng.uniform(0.0, 0.5, n), rng.uniform(0.5, 7.0, n))
    width = np.minimum(width, 2 * np.pi)
    crit = rng.uniform(-7.0, 7.0, (n, 4))
    crit[rng.random((n, 4)) < 0.5] = np.nan
    tol = 1e-12 * dom.scale
    for interior in (False, True):
        a = _vis._sorted_gaps(q, start, width, dom.vert, crit, tol, interior)
        b = visindex.sorted_gaps(q, start, width, dom.vert, crit, tol, interior)
        c = visindex.sorted_gaps(q, start, width, dom.vert, crit, tol, interior, dom)
        assert len(a[0]) > 10 * n
        for x, y, z in zip(a, b, c, strict=True):
            assert np.array_equal(x, y) and np.array_equal(x, z)
    # a domain with an added ring: its vertices outside the grid are looped over
    ring = np.array([[0.0, 0.0], [0.3, 0.0], [0.3, 0.3]]) + q[-1]
    dom2 = dom.with_ring(ring[::-1], 2)
    a = _vis._sorted_gaps(q, start, width, dom2.vert, crit, tol, False)
    c = visindex.sorted_gaps(q, start, width, dom2.vert, crit, tol, False, dom2)
    for x, z in zip(a, c, strict=True):
        assert np.array_equal(x, z)


def _pentagon_goal_scene() -> dict:
    """A generated 60-edge scene with a pentagonal goal inside its own (for a swept query)."""
    d = scene_with_edges(60, 1)
    g = shapely.Polygon(d["goal"])
    c = g.representative_point()
    r = 0.8 * g.exterior.distance(c)
    ang = 0.3 + 2 * np.pi * np.arange(5) / 5
    d["goal"] = np.column_stack([c.x + r * np.cos(ang), c.y + r * np.sin(ang)]).tolist()
    return d


@pytest.mark.skipif(not visindex.available(), reason="numba not installed (fast extra)")
def test_compiled_sweep_windows_equal_numpy(monkeypatch):
    """The swept point test's window clipping (visindex.window_ranges) returns exactly what
    the numpy code of Sweeper._windows returns, on the probes of a real swept query."""
    from geometry import sweep

    d = _pentagon_goal_scene()
    scene = Scene.from_dict(d)
    calls = []
    orig = sweep.Sweeper._windows

    def spy(self, p, base, sectors):
        if len(calls) < 40:
            calls.append((self, p.copy(), base.copy(), sectors.copy()))
        return orig(self, p, base, sectors)

    monkeypatch.setattr(sweep.Sweeper, "_windows", spy)
    partial_region(scene, target_in="goal", theta=0.3)
    assert len(calls) >= 3
    # the probes of a sweep sit inside shadows and mostly see nothing of K: add free
    # points looking at K over the whole circle, which do see into it
    sw = calls[0][0]
    fs = sw.free  # the sweeper's frame (the queries may work in a local frame)
    shapely.prepare(fs)
    rng = np.random.default_rng(0)
    x0, y0, x1, y1 = fs.bounds
    pts = rng.uniform([x0, y0], [x1, y1], (400, 2))
    pts = pts[shapely.contains_xy(fs, pts[:, 0], pts[:, 1])]
    base = np.arctan2(*(sw.hull.mean(axis=0) - pts).T[::-1])
    full = np.stack([base - np.pi, np.full(len(pts), 2 * np.pi)], axis=1)
    calls.append((sw, pts, base, full))
    n_ranges = 0
    for sw, p, base, sectors in calls:
        fast = orig(sw, p, base, sectors)
        monkeypatch.setattr(visindex, "_HAVE_NUMBA", False)
        slow = orig(sw, p, base, sectors)
        monkeypatch.setattr(visindex, "_HAVE_NUMBA", True)
        for x, y in zip(fast, slow, strict=True):
            assert np.array_equal(x, y)
        n_ranges += len(fast[0])
    assert n_ranges > 50


@pytest.mark.skipif(not visindex.available(), reason="numba not installed (fast extra)")
def test_viewpoints_off_the_grid():
    """Viewpoints outside the grid's box (no query makes them; the kernels test every
    segment / every vertex there) give the brute force's answers."""
    dom = scene_domain(Scene.from_dict(scene_with_edges(400, 1)))
    grid, _ = visindex.grid_for(dom)
    lo = np.array([grid.x0, grid.y0])
    hi = lo + [grid.nx * grid.h, grid.ny * grid.h]
    mid = 0.5 * (lo + hi)
    q = np.array([lo - 5.0, [hi[0] + 3.0, mid[1]], [mid[0], lo[1] - 2.0]])
    rng = np.random.default_rng(2)
    q = np.repeat(q, 100, axis=0)
    aim = mid + rng.uniform(-0.2, 0.2, (len(q), 2)) * (hi - lo)
    phi = np.arctan2(aim[:, 1] - q[:, 1], aim[:, 0] - q[:, 0])
    a = visindex.first_hits(dom, q, phi)
    assert (a >= 0).all()
    assert np.array_equal(a, _vis._first_hits(dom, q, phi, brute=True))
    vq = q[::100]
    st = np.arctan2(mid[1] - vq[:, 1], mid[0] - vq[:, 0]) - 0.2
    w = np.full(len(vq), 0.4)
    crit = np.full((len(vq), 1), np.nan)
    tol = 1e-12 * dom.scale
    x = visindex.sorted_gaps(vq, st, w, dom.vert, crit, tol, True, dom)
    y = _vis._sorted_gaps(vq, st, w, dom.vert, crit, tol, True)
    assert len(x[0]) > 30
    for u, v in zip(x, y, strict=True):
        assert np.array_equal(u, v)


@pytest.mark.skipif(not visindex.available(), reason="numba not installed (fast extra)")
def test_compiled_line_candidates_equal_numpy(monkeypatch):
    """The label's candidate search (visindex.on_lines) returns exactly the pairs of the
    numpy code (geometry._sweep.shadow._on_lines), row-major: on the shadow edges of a
    real swept query's samples against their padded anchor tables, and on random lines
    with points on them (to rounding), off them by the tolerance, and NaN padding; and the
    labels of the sweep's shadows are those of the numpy path."""
    from geometry import sweep
    from geometry._sweep import shadow as SH

    d = _pentagon_goal_scene()
    calls = []
    orig = sweep.Sweeper._label_rows

    def spy(self, v, dd, tables, row_table):
        calls.append((self, v.copy(), dd.copy(), tables, row_table.copy()))
        return orig(self, v, dd, tables, row_table)

    monkeypatch.setattr(sweep.Sweeper, "_label_rows", spy)
    partial_region(Scene.from_dict(d), target_in="goal", theta=0.3)
    assert calls
    n_pairs = 0
    for sw, v, dd, tables, row_table in calls:
        fast = orig(sw, v, dd, tables, row_table)
        monkeypatch.setattr(visindex, "_HAVE_NUMBA", False)
        slow = orig(sw, v, dd, tables, row_table)
        monkeypatch.setattr(visindex, "_HAVE_NUMBA", True)
        assert np.array_equal(fast, slow) and (fast >= sw.n_fixed).any()
    rng = np.random.default_rng(4)
    for _ in range(20):
        n, t, k = 60, 50, 3
        v = rng.normal(size=(n, 2))
        dd = rng.normal(size=(n, 2)) * rng.choice([1.0, 1e-9, 0.0], size=(n, 1), p=[0.8, 0.1, 0.1])
        tab = rng.normal(size=(k, t, 2))
        row_table = rng.integers(0, k, n)
        for i in range(0, n, 3):  # points on (and near) each third row's line
            s = rng.normal(size=4)
            off = rng.choice([0.0, 1e-8, -1e-8, 1e-7], size=4)
            nrm = np.array([-dd[i, 1], dd[i, 0]]) / max(np.hypot(*dd[i]), 1e-300)
            cols = rng.integers(0, t, 4)
            tab[row_table[i], cols] = v[i] + s[:, None] * dd[i] + off[:, None] * nrm
        tab[:, -5:] = np.nan  # padding
        fast = visindex.on_lines(v, dd, tab, row_table, 1e-8)
        slow = SH._on_lines(v, dd, tab, row_table, 1e-8)
        for x, y in zip(fast, slow, strict=True):
            assert np.array_equal(x, y)
        n_pairs += len(fast[0])
    assert n_pairs > 100
