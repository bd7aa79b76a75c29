"""Cross-check of the exact regions against an independent oracle (CGAL/pyvispoly).

For seeded random scenes (``geometry.generate.random_scene``) and random
placements p in the free space, membership of p in each returned region must
agree with the oracle's verdict on at least 99.9 % of the placements, pooled per
query type.  Placements closer than ``SKIP_REL * diameter`` to the region's
boundary are skipped (there the answer depends on floating-point rounding).

Oracle verdicts (V(p) = visibility polygon of p in the free space, the target
NOT an occluder; S = the target's (swept) area, which placements must avoid):

* complete, stationary / translating / rotating: p not in S and S subset of V(p)
  (S = A_q, A_theta (+) G, or G (+) disc(r)).  For a swept area this is the
  definition "every point of the swept area is visible"; the paper's convex-hull
  construction must reproduce it.
* partial, stationary: p not in A_q and A_q meets V(p) in positive area.
* eps_pos (documented semantics: shadows grown by the eps-disc): p is in the
  region iff no placement q within eps of p (q in the free space, outside S) is
  a non-seeing placement.  A claimed member is checked on 18 points of its disc;
  a claimed non-member must come with an oracle-verified witness q.
* eps_aim (partial): soundness only -- every claimed member partially sees the
  target (the aim rule is a construction, not a visibility predicate).
* recognizable, complete model: both A in G and A in H (or the swept areas for
  polygonal G, H) are completely visible, p outside both.
* recognizable, partial model, point G and H (paper 5.1): with A_g as occluder, a
  positive length of A_g's boundary minus its overlap segments with A_h
  (collinear, same-direction edge pieces) is visible, and likewise for A_h.
"""

from __future__ import annotations

import functools
import math
import os
from collections import defaultdict
from dataclasses import dataclass, field

import numpy as np
import pytest

pytest.importorskip("pyvispoly")

import shapely  # noqa: E402
import shapely.ops  # noqa: E402
from shapely.geometry import Point, Polygon  # noqa: E402

from geometry import Scene, complete_region, partial_region, recognizable_region  # noqa: E402
from geometry.generate import random_scene  # noqa: E402

try:  # rootdir on sys.path (python -m pytest) or tests/ itself (plain pytest)
    from tests.oracle import (  # noqa: E402
        VisOracle,
        minkowski_sum,
        non_overlap_segments,
        sees_completely,
        sees_partially,
        visible_length,
    )
except ImportError:  # pragma: no cover
    from oracle import (  # type: ignore[no-redef]  # noqa: E402
        VisOracle,
        minkowski_sum,
        non_overlap_segments,
        sees_completely,
        sees_partially,
        visible_length,
    )

SKIP_REL = 1e-4  # skip placements within this fraction of the diameter of a region boundary
AGREE = 0.999
N_SCENES = 30
N_POINTS = 350
N_EPS_POINTS = 12
SLOW_SCENES = 120
SLOW_POINTS = 1200


@dataclass
class Tally:
    agree: int = 0
    total: int = 0
    inside: int = 0
    skipped: int = 0
    bad: list = field(default_factory=list)

    def add(self, seed: int, p, expected: bool, actual: bool, note: str = "") -> None:
        self.total += 1
        self.inside += bool(actual)
        if expected == actual:
            self.agree += 1
        elif len(self.bad) < 8:
            self.bad.append((seed, (float(p[0]), float(p[1])), expected, actual, note))

    def check(self, what: str, min_total: int) -> None:
        assert self.total >= min_total, f"{what}: only {self.total} placements evaluated"
        assert 0 < self.inside < self.total, f"{what}: trivial sample (inside={self.inside})"
        rate = self.agree / self.total
        assert rate >= AGREE, (
            f"{what}: agreement {rate:.5f} ({self.total - self.agree} of {self.total}); "
            f"first disagreements (seed, p, oracle, region): {self.bad}"
        )


@dataclass
class SceneData:
    seed: int
    d: dict
    scene: Scene
    rng: np.random.Generator
    pts: np.ndarray
    vis: list
    oracle: VisOracle
    theta: float


def _scene_dict(seed: int) -> dict:
    rng = np.random.default_rng(10_000 + seed)
    if seed % 2 == 0:
        return random_scene(rng, goal="point", overlap=(seed % 4 == 0), name=f"oracle-{seed}")
    return random_scene(rng, goal="polygon", name=f"oracle-{seed}")


def _sample_free(scene: Scene, rng: np.random.Generator, n: int) -> np.ndarray:
    fs = scene.free_space
    x0, y0, x1, y1 = fs.bounds
    out = []
    while len(out) < n:
        cand = rng.uniform((x0, y0), (x1, y1), (2 * n, 2))
        ok = shapely.contains_xy(fs, cand[:, 0], cand[:, 1])
        out.extend(cand[ok])
    return np.asarray(out[:n])


@functools.cache
def scene_data(seed: int, n_points: int) -> SceneData:
    d = _scene_dict(seed)
    scene = Scene.from_dict(d)
    rng = np.random.default_rng(seed)
    pts = _sample_free(scene, rng, n_points)
    oracle = VisOracle(scene)
    vis = [oracle.visibility(p) for p in pts]
    theta = float(rng.uniform(0, 2 * math.pi))
    return SceneData(seed, d, scene, rng, pts, vis, oracle, theta)


def _random_in(geom, rng: np.random.Generator) -> np.ndarray:
    if geom.geom_type == "Point":
        return np.array([geom.x, geom.y])
    x0, y0, x1, y1 = geom.bounds
    while True:
        p = rng.uniform((x0, y0), (x1, y1))
        if geom.contains(Point(p)):
            return p


def _custom_region(sd: SceneData) -> Polygon:
    """A small triangle inside CH(G) (or within 1 % of r around a point G)."""
    g = sd.scene.goal_geom
    rng = np.random.default_rng(sd.seed + 77)
    if g.geom_type == "Point":
        s = 0.01 * sd.scene.target_radius
        c = np.array([g.x, g.y])
        ang = rng.uniform(0, 2 * math.pi) + np.array([0, 2.1, 4.2])
        return Polygon(c + s * np.column_stack([np.cos(ang), np.sin(ang)]))
    hull = g.convex_hull
    while True:
        tri = Polygon([_random_in(hull, rng) for _ in range(3)])
        if tri.is_valid and tri.area > 0.02 * hull.area:
            return tri


def _membership(region, pts: np.ndarray, diameter: float, extra_skip: float = 0.0):
    inside = shapely.contains_xy(region, pts[:, 0], pts[:, 1])
    if region.is_empty:
        near = np.zeros(len(pts), bool)
    else:
        dist = shapely.distance(region.boundary, shapely.points(pts))
        near = dist < SKIP_REL * diameter + extra_skip
    return inside, near


def _run(seeds, n_points, query):
    """query(sd) -> list of (region, expected_fn(i, p, vis) -> bool, tag); pooled tallies."""
    tallies: dict[str, Tally] = defaultdict(Tally)
    for seed in seeds:
        sd = scene_data(seed, n_points)
        for region, expected, tag in query(sd):
            inside, near = _membership(region, sd.pts, sd.scene.diameter)
            t = tallies[tag]
            for i, p in enumerate(sd.pts):
                if near[i]:
                    t.skipped += 1
                    continue
                t.add(seed, p, expected(i, p, sd.vis[i]), bool(inside[i]))
    return tallies


# -- query definitions --------------------------------------------------------------------------


def _q_complete_stationary(sd: SceneData):
    q = _random_in(sd.scene.goal_geom, np.random.default_rng(sd.seed + 1))
    a = sd.scene.target_at(q[0], q[1], sd.theta)
    region = complete_region(sd.scene, target_at=(q[0], q[1], sd.theta))

    def exp(i, p, v):
        return not a.covers(Point(p)) and sees_completely(sd.oracle, p, a, vis=v)

    yield region, exp, "complete stationary"


def _q_complete_translating(sd: SceneData):
    a0 = sd.scene.target_at(0.0, 0.0, sd.theta)
    regions = [("custom polygon", _custom_region(sd))]
    if sd.scene.goal_geom.geom_type == "Polygon":
        regions.append(("goal", "goal"))
    for _label, which in regions:
        x = sd.scene.region(which)
        swept = minkowski_sum(a0, x)
        region = complete_region(sd.scene, target_in=which, theta=sd.theta)

        def exp(i, p, v, swept=swept):
            return not swept.covers(Point(p)) and sees_completely(sd.oracle, p, swept, vis=v)

        yield region, exp, "complete translating"


def _q_complete_rotating(sd: SceneData):
    r = sd.scene.target_radius
    for which in ("goal", "failure"):
        x = sd.scene.region(which)
        swept = x.buffer(r, quad_segs=256)  # inscribed: within r * 5e-6 of the disc sum
        region = complete_region(sd.scene, target_in=which, theta=None)

        def exp(i, p, v, x=x, swept=swept):
            return x.distance(Point(p)) > r and sees_completely(sd.oracle, p, swept, vis=v)

        yield region, exp, "complete rotating"


def _q_partial_stationary(sd: SceneData):
    q = _random_in(sd.scene.failure_geom, np.random.default_rng(sd.seed + 2))
    a = sd.scene.target_at(q[0], q[1], sd.theta)
    region = partial_region(sd.scene, target_at=(q[0], q[1], sd.theta))

    def exp(i, p, v):
        return not a.covers(Point(p)) and sees_partially(sd.oracle, p, a, vis=v)

    yield region, exp, "partial stationary"


def _q_recognizable_complete(sd: SceneData):
    sc = sd.scene
    g, h = sc.goal_geom, sc.failure_geom
    for theta in (0.0, sd.theta):
        a0 = sc.target_at(0.0, 0.0, theta)
        sg, sh = minkowski_sum(a0, g), minkowski_sum(a0, h)
        region = recognizable_region(sc, model="complete", theta=theta)
        tag = (
            "recognizable complete (point G/H)"
            if g.geom_type == "Point"
            else "recognizable complete (polygon G/H)"
        )

        def exp(i, p, v, sg=sg, sh=sh):
            pt = Point(p)
            return (
                not sg.covers(pt)
                and not sh.covers(pt)
                and sees_completely(sd.oracle, p, sg, vis=v)
                and sees_completely(sd.oracle, p, sh, vis=v)
            )

        yield region, exp, tag
    if g.geom_type == "Polygon":
        r = sc.target_radius
        mg, mh = g.buffer(r, quad_segs=256), h.buffer(r, quad_segs=256)
        region = recognizable_region(sc, model="complete", theta=None)

        def exp_rot(i, p, v):
            pt = Point(p)
            return (
                g.distance(pt) > r
                and h.distance(pt) > r
                and sees_completely(sd.oracle, p, mg, vis=v)
                and sees_completely(sd.oracle, p, mh, vis=v)
            )

        yield region, exp_rot, "recognizable complete (polygon G/H, any orientation)"


def _q_recognizable_partial(sd: SceneData):
    sc = sd.scene
    g, h = sc.goal_geom, sc.failure_geom
    if g.geom_type != "Point":
        return
    theta = 0.0 if sd.seed % 4 == 0 else sd.theta  # overlap scenes are built at theta = 0
    a_g, a_h = sc.target_at(g.x, g.y, theta), sc.target_at(h.x, h.y, theta)
    tol = 1e-9 * sc.diameter
    seg_g = non_overlap_segments(a_g, a_h, tol)
    seg_h = non_overlap_segments(a_h, a_g, tol)
    og, oh = VisOracle(sc, occluders=[a_g]), VisOracle(sc, occluders=[a_h])
    # the oracle's overlaps are the exact ones: compare with an exact sensor (the default
    # range_acc of 1e-6 D and normal_acc of 0.01 degrees widen them; slow seed 40, G and H
    # 0.18 apart: 409 of 71,880 placements differed)
    exact = {**(sd.d.get("sensor") or {}), "range_acc": 0.0, "normal_acc_deg": 0.0}
    region = recognizable_region(
        Scene.from_dict({**sd.d, "sensor": exact}), model="partial", theta=theta
    )
    min_len = 1e-6 * sc.diameter

    def exp(i, p, v):
        pt = Point(p)
        if a_g.covers(pt) or a_h.covers(pt):
            return False
        return (
            visible_length(og, p, seg_g, tol) > min_len
            and visible_length(oh, p, seg_h, tol) > min_len
        )

    yield region, exp, "recognizable partial (point G/H)"


def _all_queries(sd: SceneData):
    for q in (
        _q_complete_stationary,
        _q_complete_translating,
        _q_complete_rotating,
        _q_partial_stationary,
        _q_recognizable_complete,
        _q_recognizable_partial,
    ):
        yield from q(sd)


# -- eps_pos / eps_aim ------------------------------------------------------------

_DISC = np.array(
    [(math.cos(t), math.sin(t)) for t in np.linspace(0, 2 * math.pi, 12, endpoint=False)]
    + [
        (0.5 * math.cos(t), 0.5 * math.sin(t))
        for t in np.linspace(0, 2 * math.pi, 6, endpoint=False)
    ]
)


def _eps_check(sd: SceneData, tally: Tally, kind: str, n: int) -> None:
    sc = sd.scene
    rng = np.random.default_rng(sd.seed + 5)
    q = _random_in(sc.goal_geom, rng)
    pose = (q[0], q[1], sd.theta)
    a = sc.target_at(*pose)
    eps = 0.01 * sc.diameter
    fn = complete_region if kind == "complete" else partial_region
    seen = sees_completely if kind == "complete" else sees_partially
    r0 = fn(sc, target_at=pose)
    r_eps = fn(sc, target_at=pose, eps_pos=eps)
    allowed = sc.free_space.difference(a)
    shadows = allowed.difference(r0)
    # the implementation's disc circumscribes the true one (radius eps / cos(pi / 64))
    extra = eps * 2e-3
    inside, near = _membership(r_eps, sd.pts, sc.diameter, extra)
    idx = [i for i in range(len(sd.pts)) if not near[i]]
    # half members, half non-members (when there are enough of each)
    ins = [i for i in idx if inside[i]][: n // 2]
    outs = [i for i in idx if not inside[i]][: n - len(ins)]

    def ok_placement(x) -> bool:
        return allowed.contains(Point(x))

    def sees(x) -> bool:
        return seen(sd.oracle, x, a)

    for i in ins + outs:
        p = sd.pts[i]
        if not ok_placement(p):  # in the target's area: never a placement
            expected = False
        elif inside[i]:
            disc = [p] + [p + 0.999 * eps * u for u in _DISC]
            expected = all(sees(x) for x in disc if ok_placement(x))
        else:
            witness = None
            if not sees(p):
                witness = p
            else:
                # candidates: an interior point of every piece of the implementation's shadows
                # within the disc (the oracle must confirm it), then points of the disc itself
                near = shapely.intersection(shadows, Point(p).buffer(0.999 * eps, quad_segs=32))
                # opened by 1e-7 D first: a shadow piece with a zero-width spike along an
                # obstacle edge (boolean noise) may otherwise offer a point on the spike
                near = shapely.buffer(near, -1e-7 * sc.diameter, join_style="mitre")
                cands = [
                    np.asarray(g.point_on_surface().coords[0])
                    for g in shapely.get_parts(near)
                    if g.geom_type == "Polygon" and not g.is_empty
                ]
                cands += [p + 0.999 * eps * u for u in _DISC]
                for x in cands:
                    if ok_placement(x) and not sees(x):
                        witness = x
                        break
            expected = witness is None  # in the region iff no non-seeing placement nearby
        tally.add(sd.seed, p, expected, bool(inside[i]), note=f"{kind} eps={eps:g} pose={pose}")


def _aim_check(sd: SceneData, tally: Tally) -> None:
    sc = sd.scene
    q = _random_in(sc.goal_geom, np.random.default_rng(sd.seed + 6))
    pose = (q[0], q[1], sd.theta)
    a = sc.target_at(*pose)
    for eps_aim in (math.radians(2), math.radians(10)):
        region = partial_region(sc, target_at=pose, eps_aim=eps_aim)
        inside, near = _membership(region, sd.pts, sc.diameter)
        for i, p in enumerate(sd.pts):
            if inside[i] and not near[i]:
                tally.add(
                    sd.seed,
                    p,
                    sees_partially(sd.oracle, p, a, vis=sd.vis[i]),
                    True,
                    note=f"eps_aim={eps_aim:g} pose={pose}",
                )


# -- tests ----------------------------------------------------------------------------------------


def _check_regions(seeds, n_points):
    tallies = _run(seeds, n_points, _all_queries)
    expected_tags = {
        "complete stationary",
        "complete translating",
        "complete rotating",
        "partial stationary",
        "recognizable complete (point G/H)",
        "recognizable complete (polygon G/H)",
        "recognizable complete (polygon G/H, any orientation)",
        "recognizable partial (point G/H)",
    }
    assert expected_tags <= set(tallies)
    failures = []
    for tag, t in sorted(tallies.items()):
        try:
            t.check(tag, min_total=len(seeds) * n_points // 4)
        except AssertionError as e:
            failures.append(str(e))
    assert not failures, "\n".join(failures)
    return tallies


def _check_eps(seeds, n_points, n_eps):
    tallies: dict[str, Tally] = defaultdict(Tally)
    for seed in seeds:
        sd = scene_data(seed, n_points)
        _eps_check(sd, tallies["complete eps_pos"], "complete", n_eps)
        _eps_check(sd, tallies["partial eps_pos"], "partial", n_eps)
        _aim_check(sd, tallies["partial eps_aim (soundness)"])
    failures = []
    for tag, t in sorted(tallies.items()):
        if tag.startswith("partial eps_aim"):
            t.inside = min(t.inside, t.total - 1)  # soundness: only members are evaluated
        try:
            t.check(tag, min_total=len(seeds) * n_eps // 3)
        except AssertionError as e:
            failures.append(str(e))
    assert not failures, "\n".join(failures)
    return tallies


def test_regions_agree_with_oracle():
    _check_regions(range(N_SCENES), N_POINTS)


def test_eps_regions_agree_with_oracle():
    _check_eps(range(N_SCENES), N_POINTS, N_EPS_POINTS)


@pytest.mark.slow
@pytest.mark.skipif(
    not os.environ.get("SENSORPLAN_SLOW"),
    reason="minutes long: set SENSORPLAN_SLOW=1 and pass --slow to run",
)
def test_regions_agree_with_oracle_many_scenes():
    seeds = range(N_SCENES, N_SCENES + SLOW_SCENES)
    _check_regions(seeds, SLOW_POINTS)
    _check_eps(seeds, SLOW_POINTS, 3 * N_EPS_POINTS)


# agreement report: python -m tests.geometry.test_regions_oracle [--slow]
if __name__ == "__main__":
    import argparse
    import time

    ap = argparse.ArgumentParser(
        prog="python -m tests.geometry.test_regions_oracle",
        description="Print the agreement table of the regions with the CGAL oracle.",
    )
    ap.add_argument("--slow", action="store_true", help="the long run's scenes and points")
    slow = ap.parse_args().slow
    seeds = range(N_SCENES, N_SCENES + SLOW_SCENES) if slow else range(N_SCENES)
    npts = SLOW_POINTS if slow else N_POINTS
    t0 = time.perf_counter()
    all_t = dict(_run(seeds, npts, _all_queries))
    for seed in seeds:
        sd = scene_data(seed, npts)
        for kind in ("complete", "partial"):
            _eps_check(sd, all_t.setdefault(f"{kind} eps_pos", Tally()), kind, N_EPS_POINTS)
        _aim_check(sd, all_t.setdefault("partial eps_aim (soundness)", Tally()))
    print("| query type | placements | inside | skipped | agreement |\n|---|---|---|---|---|")
    for tag, t in sorted(all_t.items()):
        print(
            f"| {tag} | {t.total} | {t.inside} | {t.skipped} | "
            f"{100 * t.agree / max(t.total, 1):.3f} % |"
        )
        for b in t.bad:
            print("    disagreement (seed, p, oracle, region, note):", b)
    print(f"({time.perf_counter() - t0:.1f} s)")
