"""Scene loading: the bundled scenes by name, scene JSON files, dicts and Scene objects."""

from __future__ import annotations

from pathlib import Path

from geometry import Scene

__all__ = ["BUNDLED_SCENES", "SCENE_DIR", "bundled_scene_path", "load_scene"]

SCENE_DIR = Path(__file__).resolve().parent.parent / "scenes"
BUNDLED_SCENES = tuple(sorted(p.stem for p in SCENE_DIR.glob("*.json")))


def bundled_scene_path(name: str) -> Path:
    """Path of the bundled scene JSON ``name`` (e.g. ``"lab"``)."""
    return SCENE_DIR / f"{name}.json"


def load_scene(spec: str | Path | Scene | dict) -> Scene:
    """A validated :class:`geometry.Scene` from a bundled scene name, a path to a scene JSON
    file, a scene dict or a Scene (returned as is).  Raises ``FileNotFoundError`` for a
    missing file, ``ValueError`` for an unknown name and :class:`geometry.SceneError` for
    an invalid scene."""
    if isinstance(spec, Scene):
        return spec
    if isinstance(spec, dict):
        return Scene.from_dict(spec)
    s = str(spec)
    if s in BUNDLED_SCENES:
        return Scene.load(bundled_scene_path(s))
    p = Path(s)
    if p.suffix == ".json" or p.exists():
        if not p.exists():
            raise FileNotFoundError(f"scene file not found: {p}")
        return Scene.load(p)
    raise ValueError(
        f"unknown scene {s!r}: use a bundled name ({', '.join(BUNDLED_SCENES)}), "
        "a path to a scene JSON file, or 'random'"
    )
