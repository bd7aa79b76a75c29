"""Occupancy-grid maps (ROS ``map_server`` format) as scene polygons.

A ROS map is an image (PGM, ``P5`` binary or ``P2`` text) plus a YAML file::

    image: willow-full.pgm        # relative to the YAML file
    resolution: 0.1               # metres per pixel (> 0)
    origin: [0.0, 0.0, 0.0]       # world pose of the lower-left pixel's corner (x, y, yaw)
    negate: 0                     # 1: white is occupied
    occupied_thresh: 0.65
    free_thresh: 0.196

Frames and units
----------------
The image's top row is the map's *top* edge (largest y): pixel ``(row, col)`` of an
``H x W`` image is the world square ``[ox + col r, ox + (col+1) r] x [oy + (H-1-row) r,
oy + (H-row) r]`` (``r`` the resolution in metres per pixel, ``(ox, oy)`` the origin),
as ``map_server`` reads it.  A nonzero yaw is rejected (``map_server`` ignores it too).

Classification (``map_server``'s trinary mode): with ``v`` the pixel value and ``m`` the
image's maxval, ``p = (m - v) / m`` (``p = v / m`` when negated) is the occupancy
probability; ``p > occupied_thresh`` is occupied, ``p < free_thresh`` free, the rest
unknown.  Occupied *and unknown* cells are not free space.

Vectorization (:func:`read_occupancy_grid`): the free cells, optionally cropped to a
world-frame box and opened (``min_width``) to cut off one-cell laser streaks, are split
into 4-connected components; the component holding ``seed`` (default: the largest) is
the room.  Enclosed non-free islands smaller than ``min_obstacle_area`` are filled (sensor
noise).  The room's cells are merged exactly (one box per row run, shapely union) into
one polygon with holes, simplified with shapely's topology-preserving Douglas-Peucker
(``simplify`` metres; the kept vertices are pixel corners), and returned as the boundary
(its exterior: the walls) and the obstacles (its holes).  Both are valid simple polygons
that :class:`geometry.Scene` accepts.  Every error is a :class:`geometry.formats.FormatError`
(a ``ValueError``) naming the file and what is wrong.
"""

from __future__ import annotations

import json
import math
import numbers
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from os import PathLike
from pathlib import Path
from typing import Any

import numpy as np
import shapely
from scipy import ndimage
from shapely.geometry import Polygon
from shapely.geometry.polygon import orient

from .formats import FormatError, scene_from_shapely
from .scene import Scene

__all__ = [
    "ROS_MAP_SUFFIXES",
    "RosMap",
    "free_mask",
    "read_occupancy_grid",
    "read_pgm",
    "read_ros_map_yaml",
    "scene_from_ros_map",
]

#: File extensions of a ROS map description (the YAML file).
ROS_MAP_SUFFIXES = (".yaml", ".yml")

#: Keys of the ROS ``map_server`` YAML that :func:`read_ros_map_yaml` understands.
ROS_KEYS = ("image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh", "mode")
#: Extra keys that make a ROS map YAML a scene (:func:`scene_from_ros_map`).
SCENE_KEYS = (
    "name",
    "target",
    "goal",
    "failure",
    "start",
    "sensor",
    "crop",
    "seed",
    "simplify",
    "min_obstacle_area",
    "min_width",
)


# ------------------------------------------------------------------------------------------
# PGM
# ------------------------------------------------------------------------------------------


def read_pgm(path: str | PathLike[str]) -> tuple[np.ndarray, int]:
    """The pixels of a PGM image (``P5`` binary, 8 or 16 bit big-endian; ``P2`` text) as an
    ``(H, W)`` integer array (row 0 is the image's top row) and its maxval."""
    p = Path(path)
    try:
        data = p.read_bytes()
    except OSError as e:
        raise FormatError(f"{p}: cannot read: {e.strerror or e}") from None
    magic = data[:2]
    if magic not in (b"P5", b"P2"):
        raise FormatError(f"{p}: not a PGM image (expected magic 'P5' or 'P2', got {magic[:2]!r})")
    # header: magic, width, height, maxval, separated by whitespace; '#' comments to EOL
    fields: list[int] = []
    i = 2
    n = len(data)
    while len(fields) < 3:
        while i < n and data[i : i + 1].isspace():
            i += 1
        if i >= n:
            raise FormatError(f"{p}: truncated PGM header ({len(fields)} of 3 numbers)")
        if data[i : i + 1] == b"#":
            while i < n and data[i : i + 1] not in (b"\n", b"\r"):
                i += 1
            continue
        j = i
        while j < n and not data[j : j + 1].isspace() and data[j : j + 1] != b"#":
            j += 1
        tok = data[i:j]
        if not tok.isdigit():
            raise FormatError(f"{p}: PGM header: expected a number, got {tok[:20]!r}")
        fields.append(int(tok))
        i = j
    w, h, maxval = fields
    if w <= 0 or h <= 0:
        raise FormatError(f"{p}: PGM size {w} x {h}: width and height must be positive")
    if not 0 < maxval < 65536:
        raise FormatError(f"{p}: PGM maxval {maxval} is outside 1..65535")
    if i >= n or not data[i : i + 1].isspace():
        raise FormatError(f"{p}: PGM header: no whitespace after maxval")
    i += 1  # exactly one whitespace character before the raster
    if magic == b"P5":
        size = 1 if maxval < 256 else 2
        need = w * h * size
        if n - i < need:
            raise FormatError(
                f"{p}: PGM raster too short: {w} x {h} pixels need {need} bytes, got {n - i}"
            )
        dt = np.dtype(np.uint8) if size == 1 else np.dtype(">u2")
        img = np.frombuffer(data, dtype=dt, count=w * h, offset=i).reshape(h, w)
    else:
        try:
            vals = np.array(data[i:].split(), dtype=np.int64)
        except ValueError:
            raise FormatError(f"{p}: P2 raster: non-numeric pixel value") from None
        if vals.size != w * h:
            raise FormatError(f"{p}: P2 raster: {w} x {h} pixels expected, got {vals.size} values")
        img = vals.reshape(h, w)
    if int(img.max()) > maxval:
        raise FormatError(f"{p}: pixel value {int(img.max())} exceeds maxval {maxval}")
    return img.astype(np.int64), maxval


def free_mask(
    img: np.ndarray,
    maxval: int,
    *,
    negate: bool = False,
    occupied_thresh: float = 0.65,
    free_thresh: float = 0.196,
) -> tuple[np.ndarray, np.ndarray]:
    """Boolean ``(free, occupied)`` masks of a map image by ``map_server``'s trinary rule
    (module docstring); cells that are neither are unknown."""
    v = np.asarray(img, dtype=np.float64)
    p = v / maxval if negate else (maxval - v) / maxval
    return p < free_thresh, p > occupied_thresh


# ------------------------------------------------------------------------------------------
# the ROS YAML
# ------------------------------------------------------------------------------------------


def _yaml_value(text: str, where: str) -> Any:
    """A value of the flat YAML subset ROS maps use: numbers, strings (quoted or not),
    flow lists (JSON syntax) and JSON objects."""
    t = text.strip()
    if " #" in t and not t.startswith(("[", "{", '"', "'")):
        t = t.split(" #", 1)[0].strip()
    if t.startswith(("[", "{")):
        try:
            return json.loads(t)
        except json.JSONDecodeError as e:
            if " #" in t:  # a trailing comment
                try:
                    return json.loads(t.rsplit(" #", 1)[0])
                except json.JSONDecodeError:
                    pass
            raise FormatError(f"{where}: expected a JSON-style list or object: {e}") from None
    if len(t) >= 2 and t[0] == t[-1] and t[0] in "\"'":
        return t[1:-1]
    if t in ("true", "True"):
        return True
    if t in ("false", "False"):
        return False
    try:
        return int(t)
    except ValueError:
        pass
    try:
        return float(t)
    except ValueError:
        return t


def read_ros_map_yaml(path: str | PathLike[str]) -> dict[str, Any]:
    """The ``key: value`` lines of a ROS map YAML file as a dict (blank lines and ``#``
    comments skipped; list values in JSON-style flow syntax, e.g. ``[0.0, 0.0, 0.0]``).
    The ``image`` path is resolved relative to the YAML file.  Unknown keys are kept
    (:func:`scene_from_ros_map` checks them)."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except OSError as e:
        raise FormatError(f"{p}: cannot read: {e.strerror or e}") from None
    except UnicodeDecodeError as e:
        raise FormatError(f"{p}: not a text file (UTF-8): {e}") from None
    out: dict[str, Any] = {}
    for ln, raw in enumerate(text.splitlines(), 1):
        line = raw.rstrip()
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        if line[:1].isspace():
            raise FormatError(f"{p}: line {ln}: nested YAML is not supported (one key a line)")
        key, sep, value = line.partition(":")
        key = key.strip()
        if not sep or not key:
            raise FormatError(f"{p}: line {ln}: expected 'key: value', got {line[:60]!r}")
        if key in out:
            raise FormatError(f"{p}: line {ln}: key {key!r} given twice")
        out[key] = _yaml_value(value, f"{p}: line {ln} ({key})")
    if "image" not in out:
        raise FormatError(f"{p}: missing 'image:' (the map's PGM file)")
    if not isinstance(out["image"], str):
        raise FormatError(f"{p}: image: expected a file name, got {out['image']!r}")
    out["image"] = str((p.parent / out["image"]).resolve())
    return out


# ------------------------------------------------------------------------------------------
# vectorization
# ------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class RosMap:
    """A vectorized occupancy map: ``boundary`` (the room's outline, the walls) and
    ``obstacles`` (its holes), world frame, metres; ``cells`` the room's free cells."""

    boundary: Polygon
    obstacles: list[Polygon]
    cells: int

    @property
    def n_edges(self) -> int:
        """Edges of the boundary and all obstacles."""
        return (
            len(self.boundary.exterior.coords)
            - 1
            + sum(len(o.exterior.coords) - 1 for o in self.obstacles)
        )


def _finite(v: Any, where: str) -> float:
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, numbers.Real) or not math.isfinite(v):
        raise FormatError(f"{where}: expected a finite number, got {v!r}")
    return float(v)


def _cells_polygon(mask: np.ndarray) -> Any:
    """Exact union of the True cells of ``mask`` in cell units (x = column, y = rows counted
    from the bottom, so the image's top row is the largest y): one box per row run."""
    h, w = mask.shape
    pad = np.zeros((h, w + 2), dtype=np.int8)
    pad[:, 1:-1] = mask
    d = np.diff(pad, axis=1)
    rs, cs = np.nonzero(d == 1)
    re_, ce = np.nonzero(d == -1)  # same row order as the starts (row-major scan)
    assert np.array_equal(rs, re_)
    y0 = (h - 1 - rs).astype(np.float64)
    boxes = shapely.box(cs.astype(np.float64), y0, ce.astype(np.float64), y0 + 1.0)
    return shapely.union_all(boxes)


def read_occupancy_grid(
    pgm_path: str | PathLike[str],
    *,
    resolution: float,
    origin: Sequence[float] = (0.0, 0.0),
    occupied_thresh: float = 0.65,
    free_thresh: float = 0.196,
    negate: bool = False,
    crop: Sequence[float] | None = None,
    seed: Sequence[float] | None = None,
    simplify: float = 0.0,
    min_obstacle_area: float = 0.0,
    min_width: float = 0.0,
) -> RosMap:
    """Vectorize a ROS occupancy-grid image into a room outline and obstacles.

    Args:
        pgm_path: the PGM image.
        resolution: metres per pixel (> 0).
        origin: world ``(x, y)`` of the lower-left corner of the lower-left pixel (metres);
            a third value (yaw) must be 0.
        occupied_thresh, free_thresh, negate: ``map_server``'s classification.
        crop: world-frame box ``(xmin, ymin, xmax, ymax)`` (metres) inside the map; the
            cells it meets are kept and its edges become walls.
        seed: a world point ``(x, y)`` in a free cell: the room is the free component that
            holds it (default: the component with most cells).
        simplify: Douglas-Peucker tolerance in metres (topology-preserving; 0: none).
        min_obstacle_area: enclosed non-free islands smaller than this (square metres) are
            filled as free space (scan noise).
        min_width: free passages narrower than this (metres) are cut off before the room
            is chosen (a morphological opening with a square of ``round(min_width /
            resolution)`` cells; removes laser streaks).

    Returns:
        A :class:`RosMap`: the boundary polygon (no holes) and the obstacle polygons (the
        boundary's former holes; simple, inside the boundary, possibly touching it or each
        other at a point), world frame, metres, counter-clockwise; and the room's number of
        free cells.
    """
    p = Path(pgm_path)
    res = _finite(resolution, f"{p}: resolution")
    if res <= 0:
        raise FormatError(f"{p}: resolution must be > 0 metres per pixel, got {resolution!r}")
    org = list(origin)
    if len(org) not in (2, 3):
        raise FormatError(f"{p}: origin must be [x, y] or [x, y, yaw], got {origin!r}")
    ox, oy = (_finite(v, f"{p}: origin") for v in org[:2])
    if len(org) == 3 and _finite(org[2], f"{p}: origin yaw") != 0.0:
        raise FormatError(f"{p}: origin yaw {org[2]!r}: rotated maps are not supported (use 0)")
    for nm, v in (("occupied_thresh", occupied_thresh), ("free_thresh", free_thresh)):
        if not 0.0 <= _finite(v, f"{p}: {nm}") <= 1.0:
            raise FormatError(f"{p}: {nm} must lie in [0, 1], got {v!r}")
    if free_thresh > occupied_thresh:
        raise FormatError(
            f"{p}: free_thresh {free_thresh!r} exceeds occupied_thresh {occupied_thresh!r}"
        )
    for nm, v in (
        ("simplify", simplify),
        ("min_obstacle_area", min_obstacle_area),
        ("min_width", min_width),
    ):
        if _finite(v, f"{p}: {nm}") < 0:
            raise FormatError(f"{p}: {nm} must be >= 0, got {v!r}")

    img, maxval = read_pgm(p)
    h, w = img.shape
    free, _ = free_mask(
        img, maxval, negate=bool(negate), occupied_thresh=occupied_thresh, free_thresh=free_thresh
    )
    # crop: cell index ranges (columns from the left, rows from the top of the image)
    c0, c1, r0, r1 = 0, w, 0, h
    if crop is not None:
        cb = list(crop)
        if len(cb) != 4:
            raise FormatError(f"{p}: crop must be (xmin, ymin, xmax, ymax), got {crop!r}")
        x0, y0, x1, y1 = (_finite(v, f"{p}: crop") for v in cb)
        if not (x0 < x1 and y0 < y1):
            raise FormatError(f"{p}: crop {crop!r}: need xmin < xmax and ymin < ymax")
        ext = (ox, oy, ox + w * res, oy + h * res)
        eps = 1e-9 * max(w, h) * res
        if x0 < ext[0] - eps or y0 < ext[1] - eps or x1 > ext[2] + eps or y1 > ext[3] + eps:
            raise FormatError(
                f"{p}: crop {tuple(cb)} is not inside the map extent "
                f"({ext[0]:g}, {ext[1]:g}, {ext[2]:g}, {ext[3]:g}) (metres)"
            )
        c0 = max(0, math.floor((x0 - ox) / res + 1e-9))
        c1 = min(w, math.ceil((x1 - ox) / res - 1e-9))
        b0 = max(0, math.floor((y0 - oy) / res + 1e-9))  # rows from the bottom
        b1 = min(h, math.ceil((y1 - oy) / res - 1e-9))
        r0, r1 = h - b1, h - b0
    sub = free[r0:r1, c0:c1]
    sh, sw = sub.shape
    k = int(round(min_width / res))
    if k >= 2:
        sub = ndimage.binary_opening(sub, structure=np.ones((k, k), dtype=bool))
    four = ndimage.generate_binary_structure(2, 1)
    labels, n = ndimage.label(sub, structure=four)
    if n == 0:
        raise FormatError(f"{p}: no free cell in the map{' crop' if crop is not None else ''}")
    if seed is not None:
        sd = list(seed)
        if len(sd) != 2:
            raise FormatError(f"{p}: seed must be a point (x, y), got {seed!r}")
        sx, sy = (_finite(v, f"{p}: seed") for v in sd)
        col = math.floor((sx - ox) / res) - c0
        row = (h - 1 - math.floor((sy - oy) / res)) - r0
        if not (0 <= col < sw and 0 <= row < sh):
            raise FormatError(f"{p}: seed ({sx:g}, {sy:g}) lies outside the map (crop)")
        lab = int(labels[row, col])
        if lab == 0:
            raise FormatError(f"{p}: seed ({sx:g}, {sy:g}) is not in a free cell")
    else:
        counts = np.bincount(labels.ravel())
        counts[0] = 0
        lab = int(np.argmax(counts))
    room = labels == lab
    # enclosed non-free islands (8-connected: the dual of 4-connected free space)
    if min_obstacle_area > 0:
        outside = np.ones((sh + 2, sw + 2), dtype=bool)
        outside[1:-1, 1:-1] = ~room
        eight = ndimage.generate_binary_structure(2, 2)
        olab, _ = ndimage.label(outside, structure=eight)
        sizes = np.bincount(olab.ravel())
        small = sizes * res * res < min_obstacle_area
        small[olab[0, 0]] = False  # the outside (it touches the padding)
        small[0] = False
        room = room | small[olab[1:-1, 1:-1]]
    poly = _cells_polygon(room)
    if not isinstance(poly, Polygon):  # pragma: no cover - a 4-connected set is one polygon
        raise FormatError(f"{p}: the room's cells did not merge into one polygon")
    # tolerance 0 still drops the collinear vertices the union of the runs leaves
    poly = shapely.simplify(poly, simplify / res, preserve_topology=True)
    if not isinstance(poly, Polygon) or not poly.is_valid:  # pragma: no cover
        raise FormatError(f"{p}: simplify={simplify!r} made the room invalid; use less")
    # to the world frame: the kept vertices are pixel corners, x = ox + (c0 + i) r
    dx, dy = c0, h - r1

    def world(c: np.ndarray) -> np.ndarray:
        return np.column_stack([ox + (c[:, 0] + dx) * res, oy + (c[:, 1] + dy) * res])

    poly = shapely.transform(shapely.normalize(poly), world)
    boundary = orient(Polygon(poly.exterior), 1.0)  # counter-clockwise rings
    obstacles = [orient(Polygon(r), 1.0) for r in poly.interiors]
    return RosMap(boundary=boundary, obstacles=obstacles, cells=int(room.sum()))


# ------------------------------------------------------------------------------------------
# scenes
# ------------------------------------------------------------------------------------------


def scene_from_ros_map(
    path: str | PathLike[str] | Mapping[str, Any],
    *,
    name: str | None = None,
    **overrides: Any,
) -> Scene:
    """A scene from a ROS map YAML (a path, or its parsed dict with an absolute ``image``).

    Besides the ROS keys (``image``, ``resolution``, ``origin``, ``negate``,
    ``occupied_thresh``, ``free_thresh``; ``mode`` must be ``trinary`` or ``scale``) the
    YAML -- or ``overrides`` -- gives the scene: ``target`` (polygon, target frame),
    ``goal`` and ``failure`` (polygon or ``[[x, y]]``, world frame, metres), optional
    ``start`` ``[x, y, theta]``, ``sensor`` (a JSON object), ``name``, and the
    vectorization options of :func:`read_occupancy_grid` (``crop``, ``seed``,
    ``simplify``, ``min_obstacle_area``, ``min_width``).  Lists use JSON syntax, e.g.
    ``goal: [[1.0, 2.0], [1.5, 2.0], [1.5, 2.5]]``.  ``seed`` defaults to the goal's
    representative point (the room is the free component holding G).
    """
    if isinstance(path, Mapping):
        d = dict(path)
        where = str(d.get("image", "ROS map"))
        default_name = Path(where).stem
    else:
        d = read_ros_map_yaml(path)
        where = str(path)
        default_name = Path(path).stem
    d.update(overrides)
    for k in d:
        if k not in ROS_KEYS and k not in SCENE_KEYS:
            raise FormatError(
                f"{where}: unknown key {k!r} (ROS: {', '.join(ROS_KEYS)}; scene: "
                f"{', '.join(SCENE_KEYS)})"
            )
    for k in ("resolution", "target", "goal", "failure"):
        if k not in d:
            raise FormatError(f"{where}: missing key {k!r}")
    mode = d.get("mode", "trinary")
    if mode not in ("trinary", "scale"):
        raise FormatError(f"{where}: mode {mode!r} is not supported (trinary or scale)")

    def region(v: Any, key: str) -> Any:
        if not isinstance(v, list) or not v:
            raise FormatError(f"{where}: {key}: expected a list of [x, y] points, got {v!r}")
        try:
            pts = np.asarray(v, dtype=float)
        except (TypeError, ValueError):
            raise FormatError(f"{where}: {key}: expected [[x, y], ...] numbers") from None
        if pts.ndim != 2 or pts.shape[1] != 2:
            raise FormatError(f"{where}: {key}: expected [[x, y], ...], got {v!r:.60}")
        return shapely.Point(pts[0]) if len(pts) == 1 else Polygon(pts)

    goal = region(d["goal"], "goal")
    failure = region(d["failure"], "failure")
    seed = d.get("seed")
    if seed is None:
        rp = goal.representative_point()
        seed = (rp.x, rp.y)
    m = read_occupancy_grid(
        d["image"],
        resolution=d["resolution"],
        origin=d.get("origin", (0.0, 0.0)),
        occupied_thresh=d.get("occupied_thresh", 0.65),
        free_thresh=d.get("free_thresh", 0.196),
        negate=bool(d.get("negate", 0)),
        crop=d.get("crop"),
        seed=seed,
        simplify=d.get("simplify", 0.0),
        min_obstacle_area=d.get("min_obstacle_area", 0.0),
        min_width=d.get("min_width", 0.0),
    )
    try:
        return scene_from_shapely(
            bounds=m.boundary,
            obstacles=m.obstacles,
            target=region(d["target"], "target"),
            goal=goal,
            failure=failure,
            name=name if name is not None else str(d.get("name", default_name)),
            sensor=d.get("sensor"),
            start=d.get("start"),
        )
    except FormatError as e:
        raise FormatError(f"{where}: {e}") from e
