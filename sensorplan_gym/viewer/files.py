"""What the live viewer may write on this machine: scene files inside one folder.

The page's "save scene to" box names a path; the server writes there only when the
path, with symlinks and ``..`` resolved, lies inside the viewer's *root* (the folder
``sensorplan view`` was started in, or ``--root DIR``) and ends in a scene extension
(``.json``, ``.geojson``, ``.wkt``).  Relative paths are taken relative to the root,
``~`` is not expanded.  The file is opened with ``O_NOFOLLOW``, so a symlink put in
place of the checked name after the check is refused, not followed.

Loading needs no such rule: the page's "load a scene" button uploads the *content* of
a file the browser's user picked; the server opens no path for it.

No Bokeh needed here (the rules are unit-tested without a browser).
"""

from __future__ import annotations

import os
from os import PathLike
from pathlib import Path

from geometry import Scene
from geometry.formats import SCENE_SUFFIXES, scene_to_text

__all__ = ["OutsideRootError", "confine", "save_scene_confined"]


class OutsideRootError(ValueError):
    """A path the viewer was asked to write lies outside its root folder."""


def _root(root: str | PathLike[str]) -> Path:
    r = Path(root).resolve()
    if not r.is_dir():
        raise NotADirectoryError(f"the viewer's root folder {r} is not a directory")
    return r


def confine(path: str | PathLike[str], root: str | PathLike[str]) -> Path:
    """The absolute, symlink-free path that ``path`` names, checked to lie inside ``root``.

    ``path`` relative: relative to ``root`` (not to the current directory); absolute: as
    given.  Every symlink of the existing part of the path is followed and every ``..``
    collapsed (:meth:`pathlib.Path.resolve`) before the check, so neither a symlink inside
    the root pointing out of it nor ``../`` escapes.  Returns the resolved path (which
    may not exist yet).  Raises :class:`OutsideRootError` (a ``ValueError``) naming the
    path, where it resolves to and the root; ``ValueError`` for an empty path, one with a
    NUL character or one starting with ``~``; ``NotADirectoryError`` when ``root`` is not
    a directory.
    """
    text = os.fspath(path)
    if isinstance(text, bytes):
        text = os.fsdecode(text)
    r = _root(root)
    if not text.strip():
        raise ValueError(f"no file name given (a path inside {r})")
    if "\x00" in text:
        raise ValueError(f"{text!r}: a path cannot contain a NUL character")
    if text.startswith("~"):
        raise ValueError(f"{text!r}: '~' is not expanded; give a path inside {r}")
    p = Path(text)
    resolved = (p if p.is_absolute() else r / p).resolve()
    if resolved != r and r not in resolved.parents:
        raise OutsideRootError(
            f"{text!r} resolves to {resolved}, outside the viewer's folder {r}; the viewer "
            "writes only inside the folder it was started in (sensorplan view --root DIR "
            "picks another)"
        )
    return resolved


def save_scene_confined(scene: Scene, path: str | PathLike[str], root: str | PathLike[str]) -> Path:
    """Write ``scene`` to ``path`` (see :func:`confine`) in the format of its extension
    (``.json`` scene JSON, ``.geojson``, ``.wkt``) and return the absolute path written.

    Raises :class:`OutsideRootError` for a path outside ``root``, ``ValueError`` for an
    extension that is not a scene format (the viewer never writes other files) and
    ``OSError`` when the file cannot be written (a missing folder, a directory of that
    name, a symlink swapped in after the check, no permission).  Nothing is written
    unless every check passes.
    """
    target = confine(path, root)
    ext = target.suffix.lower()
    if ext not in SCENE_SUFFIXES:
        raise ValueError(
            f"{os.fspath(path)!r}: the viewer writes scene files only; the name must end in "
            f"{', '.join(SCENE_SUFFIXES)}"
        )
    text = scene_to_text(scene, ext)
    if target.is_dir():
        raise IsADirectoryError(f"{target} is a directory")
    flags = os.O_WRONLY | os.O_CREAT | os.O_TRUNC
    flags |= getattr(os, "O_NOFOLLOW", 0) | getattr(os, "O_CLOEXEC", 0)
    fd = os.open(target, flags, 0o666)
    with os.fdopen(fd, "w", encoding="utf-8") as f:
        f.write(text)
    return target
