"""Scene loading: the one function every scene argument goes through.

:func:`load_scene` takes a bundled scene name, a path to a scene file in any of the
formats of :mod:`geometry.formats` (scene JSON, GeoJSON, WKT; by extension, and for
``.json`` by content) or a ROS occupancy-grid map YAML with the scene's extra keys
(:func:`geometry.occupancy.scene_from_ros_map`), a parsed dict (scene JSON or a GeoJSON
FeatureCollection) or a :class:`geometry.Scene`.  The envs' ``scene=``, ``sensorplan view``,
``sensorplan convert`` and the tools that take scene names all call it.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from os import PathLike
from pathlib import Path

from geometry import Scene
from geometry.formats import SCENE_SUFFIXES, load_scene_file, scene_from_data
from geometry.occupancy import ROS_MAP_SUFFIXES, scene_from_ros_map

__all__ = [
    "BUNDLED_SCENES",
    "REAL_SCENES",
    "SCENE_DIR",
    "SCENE_SUFFIXES",
    "bundled_scene_path",
    "load_scene",
    "real_scene_provenance",
]

SCENE_DIR = Path(__file__).resolve().parent.parent / "scenes"
#: the hand-made bundled scenes
BUNDLED_SCENES = tuple(sorted(p.stem for p in SCENE_DIR.glob("*.json")))
#: the bundled real floor plans, by the names ``real/<stem>``: public ROS maps (scene JSON,
#: ``scenes/real/provenance.json``) and public OpenStreetMap floor plans (GeoJSON,
#: ``scenes/real/provenance_geojson.json``)
REAL_SCENES = tuple(
    sorted(
        f"real/{p.stem}"
        for p in (SCENE_DIR / "real").glob("*")
        if p.suffix in (".json", ".geojson") and not p.stem.startswith("provenance")
    )
)


def bundled_scene_path(name: str) -> Path:
    """Path of the bundled scene file ``name`` (e.g. ``"lab"`` or ``"real/willow_north"``):
    scene JSON, or GeoJSON (``.geojson``) for the floor plans imported from OpenStreetMap."""
    geo = SCENE_DIR / f"{name}.geojson"
    return geo if geo.exists() else SCENE_DIR / f"{name}.json"


def real_scene_provenance() -> dict[str, dict]:
    """Where each bundled real floor plan comes from, by stem (``"willow_north"``, ...):
    repository, path, commit, licence, SHA-256 of the source, conversion parameters and the
    edge count (``scenes/real/provenance*.json``, written by ``benchmarks.make_real_maps``
    and ``benchmarks.make_geojson_maps``)."""
    out: dict[str, dict] = {}
    for p in sorted((SCENE_DIR / "real").glob("provenance*.json")):
        out.update(json.loads(p.read_text(encoding="utf-8")))
    return out


def load_scene(spec: str | PathLike[str] | Scene | Mapping, *, name: str | None = None) -> Scene:
    """A validated :class:`geometry.Scene` from

    * a bundled scene name (:data:`BUNDLED_SCENES`: ``lab``, ``edr``, ``corridor``,
      ``warehouse``; :data:`REAL_SCENES`: ``real/willow_north``, ``real/willow_south``,
      ``real/heidelberg_l1``, ``real/heidelberg_l2``,
      ``real/lse_arena``);
    * a path to a scene file: ``.json`` (scene JSON, or GeoJSON when the object has a
      ``"type"`` member), ``.geojson`` or ``.wkt`` (see :mod:`geometry.formats`);
    * a dict: scene JSON, or a GeoJSON FeatureCollection (it has a ``"type"`` member);
    * a Scene (returned as is, unless renamed).

    ``name`` overrides the scene's name.  A bundled name wins over a file of that name in
    the current folder (write ``./lab`` for the file).  Raises ``FileNotFoundError`` for a
    missing file, ``ValueError`` for an unknown name and :class:`geometry.SceneError` (a
    ``ValueError``; :class:`geometry.formats.FormatError` for files) for an invalid scene,
    naming the file and the offending feature or key.
    """
    if isinstance(spec, Scene):
        scene = spec
    elif isinstance(spec, Mapping):
        return scene_from_data(spec, name=name)
    else:
        s = str(spec)
        if s in BUNDLED_SCENES or s in REAL_SCENES:
            scene = load_scene_file(bundled_scene_path(s))
        else:
            p = Path(s)
            suffixes = SCENE_SUFFIXES + ROS_MAP_SUFFIXES
            if p.suffix.lower() not in suffixes and not p.exists():
                raise ValueError(
                    f"unknown scene {s!r}: use a bundled name ({', '.join(BUNDLED_SCENES)}) "
                    f"or a path to a scene file ({', '.join(suffixes)}); the envs also "
                    "take 'random'"
                )
            if not p.exists():
                raise FileNotFoundError(f"scene file not found: {p}")
            if p.suffix.lower() in ROS_MAP_SUFFIXES:
                return scene_from_ros_map(p, name=name)
            return load_scene_file(p, name=name)
    return scene if name is None else scene.replace(name=name)
