"""The frame checks (``frames=True``, issue 26): the scene scaled by 1e-3 and 1e3 and moved to
UTM coordinates, its regions mapped back and compared with the base frame's."""

from __future__ import annotations

import math
from collections.abc import Callable

import numpy as np
import shapely

from ..complete import complete_region
from ..partial import partial_region
from ..recognize import recognizable_region
from ..scene import Scene, SceneError
from .findings import Finding

#: The frames of :func:`_check_frames`: ``world = k * scene + (ox, oy)`` (for ``utm`` the
#: scene is first scaled by a power of two to a diameter of about 10).
FRAMES = {
    "scale1e-3": (1e-3, 0.0, 0.0),
    "scale1e3": (1e3, 0.0, 0.0),
    "utm": (1.0, 512345.0, 5412345.0),
}


def _mapped(d: dict, k: float, ox: float, oy: float) -> dict:
    out = dict(d)

    def f(pts: list) -> list:
        return [[k * x + ox, k * y + oy] for x, y in pts]

    for key in ("bounds", "goal", "failure"):
        out[key] = f(d[key])
    out["obstacles"] = [f(o) for o in d["obstacles"]]
    out["target"] = [[k * x, k * y] for x, y in d["target"]]
    if d.get("sensor"):
        sen = dict(d["sensor"])
        for key in ("range_acc", "max_range", "eps_pos"):
            if sen.get(key) is not None:
                sen[key] = sen[key] * k
        out["sensor"] = sen
    return out


def _sample_configs(g: shapely.Geometry, rng: np.random.Generator) -> list[tuple[float, float]]:
    """Two reference points on the boundary of the polygon ``g`` (not at a vertex) and
    one inside it."""
    b = g.exterior
    out = [b.interpolate(float(t), normalized=True) for t in rng.uniform(0.0, 1.0, 2)]
    out.append(g.representative_point())
    return [(float(p.x), float(p.y)) for p in out]


def _swept_differ(a: shapely.Geometry, b: shapely.Geometry, tol: float) -> float:
    """Area of ``a`` outside ``b`` grown by ``tol`` plus that of ``b`` outside ``a`` grown
    by ``tol``: two swept answers traced to within ``tol`` (each in its own frame, so
    their samples differ by rounding) agree up to that."""
    return (
        shapely.difference(a, shapely.buffer(b, tol)).area
        + shapely.difference(b, shapely.buffer(a, tol)).area
    )


def _check_frames(
    s: Scene,
    d: dict,
    q_at: tuple[float, float, float],
    theta: float,
    out: list[Finding],
    *,
    swept: bool = False,
    poly_gh: bool = False,
) -> None:
    """Issue 26 item 9: the regions of the scene mapped into another frame (inexactly:
    the inputs differ by rounding, ~1e-10 D), mapped back, equal the originals to
    1e-7 D^2 (findings ``frame``).  With ``swept`` also the swept partial region and
    (``poly_gh``) the 5.2 recognizable region (issue 25 item 7), compared up to their
    tracing tolerance ``tol`` (1e-4 D, :func:`_swept_differ`)."""
    D = s.diameter

    def exact(a: shapely.Geometry, b: shapely.Geometry) -> float:
        return shapely.symmetric_difference(a, b).area

    def traced(a: shapely.Geometry, b: shapely.Geometry) -> float:
        return _swept_differ(a, b, 1e-4 * D)

    # (name, query of a scene and the pose's reference point, how regions are compared)
    queries: list[tuple[str, Callable, Callable]] = [
        ("complete at", lambda sc, x, y: complete_region(sc, target_at=(x, y, theta)), exact),
        ("partial at", lambda sc, x, y: partial_region(sc, target_at=(x, y, theta)), exact),
        ("complete in", lambda sc, x, y: complete_region(sc, target_in="goal", theta=theta), exact),
    ]
    if swept and len(s.goal) > 1:
        swept_in = lambda sc, x, y: partial_region(sc, target_in="goal", theta=theta)  # noqa: E731
        queries.append(("partial in", swept_in, traced))
    if swept and poly_gh:
        queries.append(
            (
                "recognizable 5.2",
                lambda sc, x, y: recognizable_region(sc, model="partial", theta=theta),
                traced,
            )
        )
    base = {}  # each query once in the scene's own frame
    for name, fn, _ in queries:
        try:
            base[name] = fn(s, q_at[0], q_at[1])
        except (SceneError, NotImplementedError):
            continue
        except Exception as e:  # noqa: BLE001
            out.append(Finding("crash", name, f"{type(e).__name__}: {e}"))
    for fname, (k, ox, oy) in FRAMES.items():
        if fname == "utm":
            # a room of about 10 m first (an exact power-of-two scale): a 1e-6 m scene at
            # 5e6 m has no digits left, which is not the question
            k = math.ldexp(1.0, round(math.log2(10.0 / D)))
        try:
            t = Scene.from_dict(_mapped(d, k, ox, oy))
        except SceneError as e:
            out.append(Finding("frame", f"validation ({fname})", str(e)))
            continue
        qx, qy = q_at[0] * k + ox, q_at[1] * k + oy
        for name, fn, differ in queries:
            if name not in base:
                continue
            try:
                b = fn(t, qx, qy)
            except (SceneError, NotImplementedError):
                continue
            except Exception as e:  # noqa: BLE001
                out.append(Finding("crash", f"{name} ({fname})", f"{type(e).__name__}: {e}"))
                continue
            back = shapely.transform(b, lambda c, k=k, ox=ox, oy=oy: (c - [ox, oy]) / k)
            diff = differ(base[name], back)
            if diff > 1e-7 * D * D:
                out.append(Finding("frame", f"{name} ({fname})", f"{diff / D**2:.3g} D^2"))
