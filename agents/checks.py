"""Checks of what a user hands the command lines, made before any work starts: output paths
that can be written, file paths made absolute, and the one-line install hint for an optional
dependency that is missing.  Imports nothing of the project (every layer of ``agents`` uses
it)."""

from __future__ import annotations

import os
from pathlib import Path

__all__ = [
    "EXTRA_OF_MODULE",
    "absolute_path",
    "check_writable_dir",
    "check_writable_file",
    "missing_extra",
    "missing_extra_message",
]

#: top-level modules of the optional extras -> the extra that installs them
EXTRA_OF_MODULE = {
    "yaml": "rl",
    "stable_baselines3": "rl",
    "sb3_contrib": "rl",
    "torch": "rl",
    "tqdm": "rl",
    "rich": "rl",
    "tensorboard": "rl",
    "pettingzoo": "multi",
    "ray": "multi",
    "bokeh": "viewer",
    "minari": "imitation",
    "h5py": "imitation",
}


def missing_extra(err: ImportError) -> str | None:
    """The extra (``"rl"``, ``"multi"``, ``"viewer"``) whose module ``err`` failed to import,
    or ``None`` when the missing module belongs to no extra."""
    name = (getattr(err, "name", None) or "").split(".")[0]
    return EXTRA_OF_MODULE.get(name)


def missing_extra_message(command: str, err: ImportError) -> str | None:
    """``"<command>: error: the Python module 'X' is missing; it comes with the "E" extra:
    pip install ..."`` for an ImportError of an optional dependency, or ``None`` when the
    missing module belongs to no extra (a real bug: the caller re-raises it)."""
    extra = missing_extra(err)
    if extra is None:
        return None
    name = (getattr(err, "name", None) or "").split(".")[0]
    return (
        f"{command}: error: the Python module {name!r} is missing; it comes with "
        f'the "{extra}" extra: pip install -e ".[{extra}]" in a checkout, '
        f'pip install "sensorplan-gym[{extra}]" otherwise'
    )


def absolute_path(path: str | os.PathLike) -> Path:
    """``path`` with ``~`` expanded, made absolute against the current directory (libraries
    such as Ray/pyarrow read a bare relative path as a URI and fail)."""
    return Path(path).expanduser().resolve()


def _nearest_existing(path: Path) -> Path:
    p = path
    while not p.exists():
        if p.parent == p:
            break
        p = p.parent
    return p


def check_writable_dir(path: str | os.PathLike, what: str = "--out") -> Path:
    """Raise ``ValueError`` naming ``what`` and ``path`` unless ``path`` is a folder that can
    be written, or a folder that can be created (its nearest existing ancestor is a writable
    folder).  Creates nothing; returns ``path`` as a :class:`Path`."""
    p = Path(path).expanduser()
    if p.exists() and not p.is_dir():
        raise ValueError(f"{what} {str(path)!r} exists and is not a folder")
    base = _nearest_existing(p.absolute())
    if not base.is_dir():
        raise ValueError(f"{what} {str(path)!r}: {str(base)!r} is a file, not a folder")
    if not os.access(base, os.W_OK | os.X_OK):
        where = "" if base == p.absolute() else f" (in {str(base)!r})"
        raise ValueError(f"{what} {str(path)!r} is not writable{where}: permission denied")
    return p


def check_writable_file(path: str | os.PathLike, what: str = "--out") -> Path:
    """Raise ``ValueError`` naming ``what`` and ``path`` unless a file can be written at
    ``path`` (an existing writable file, or a new file in a folder that exists or can be
    created).  Creates nothing; returns ``path`` as a :class:`Path`."""
    p = Path(path).expanduser()
    if p.is_dir():
        raise ValueError(f"{what} {str(path)!r} is a folder, not a file")
    if p.exists():
        if not os.access(p, os.W_OK):
            raise ValueError(f"{what} {str(path)!r} is not writable: permission denied")
        return p
    check_writable_dir(p.absolute().parent, what=f"{what} {str(path)!r}: folder")
    return p
