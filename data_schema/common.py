"""File identification and version checks common to every layout."""

from __future__ import annotations

from pathlib import Path

import h5py
import numpy as np


class DataFormatError(ValueError):
    """A file is not a readable file of the expected layout; the message names it."""


def check_file(path, file_type: str, major, other_major=None) -> None:
    """Check that ``path`` is an HDF5 file of ``file_type`` with format major version ``major`` (an int, or a
    tuple of the majors accepted). ``other_major(path, major, minor)`` may give the message (without the path)
    for a file of another major version, or None for the generic one.

    Raises
    ------
    FileNotFoundError
        The file does not exist.
    DataFormatError
        The path is a folder or not a regular file (a FIFO, a device), the file is not HDF5, is truncated or corrupt, has another file type,
        or another major format version.
    """
    path = Path(path)
    if path.is_dir():
        raise DataFormatError(f"{path}: is a folder; give a {file_type} file")
    if not path.exists():
        raise FileNotFoundError(f"{path}: no such file")
    if not path.is_file():      # a FIFO or a device would block or never end: refused without opening it
        raise DataFormatError(f"{path}: is not a regular file (a FIFO, a device or a socket); give a {file_type} file")
    try:
        with h5py.File(path, "r") as f:
            found_type = f.attrs.get("file_type")
            version = f.attrs.get("format_version")
    except OSError as exc:
        raise DataFormatError(f"{path}: not a readable HDF5 file (truncated or corrupt?): {exc}") from exc
    if isinstance(found_type, bytes):
        found_type = found_type.decode()
    if found_type != file_type:
        raise DataFormatError(f"{path}: file_type is {found_type!r}, expected {file_type!r}")
    if version is None or len(version) != 2:
        raise DataFormatError(f"{path}: missing or malformed 'format_version' attribute: {version!r}")
    majors = major if isinstance(major, tuple) else (major,)
    if int(version[0]) not in majors:
        text = other_major(path, int(version[0]), int(version[1])) if other_major is not None else None
        raise DataFormatError(f"{path}: " + (text or (
            f"format version {int(version[0])}.{int(version[1])} is not readable by this "
            f"version of the package, which reads major version {' or '.join(map(str, majors))}; make the file "
            f"again with this version (docs/format.md, 'Identification and versions')")))


def write_header(f: h5py.File, file_type: str, version: tuple[int, int]) -> None:
    """Write the identification attributes every file carries."""
    f.attrs["file_type"] = file_type
    f.attrs["format_version"] = np.array(version, dtype=np.int64)


def package_version() -> str:
    """Version of the installed package (recorded in every file written), or "unknown"."""
    from importlib.metadata import PackageNotFoundError, version
    try:
        return version("rebound-scatter")
    except PackageNotFoundError:
        return "unknown"
