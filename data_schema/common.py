"""File identification, version checks and atomic writes common to every layout."""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

import h5py
import numpy as np


class DataFormatError(ValueError):
    """A file is not a readable file of the expected layout; the message names it."""


def check_file(path, file_type: str, major: int) -> None:
    """Check that ``path`` is an HDF5 file of ``file_type`` with format major version ``major``.

    Raises
    ------
    FileNotFoundError
        The file does not exist.
    DataFormatError
        The file is not HDF5, is truncated or corrupt, has another file type,
        or another major format version.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"{path}: no such file")
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
    if int(version[0]) != major:
        raise DataFormatError(
            f"{path}: format version {int(version[0])}.{int(version[1])} is not readable by this "
            f"version of the package, which reads major version {major}; make the file again with this "
            f"version (docs/format.md, 'Identification and versions')")


def write_header(f: h5py.File, file_type: str, version: tuple[int, int]) -> None:
    """Write the identification attributes every file carries."""
    f.attrs["file_type"] = file_type
    f.attrs["format_version"] = np.array(version, dtype=np.int64)


@contextlib.contextmanager
def atomic_output(path, overwrite: bool = False):
    """Yield a temporary path next to ``path``; move it into place only on success.

    The target never holds a half-written file: the temporary file is in the
    same directory and replaces the target with :func:`os.replace`. An
    existing target is refused unless ``overwrite``; on error the temporary
    file is removed and the target is untouched.
    """
    path = Path(path)
    if path.exists() and not overwrite:
        raise FileExistsError(f"{path} exists; pass overwrite=True (CLI: --overwrite) to replace it")
    directory = path.parent if str(path.parent) else Path(".")
    if not directory.is_dir():
        raise FileNotFoundError(f"{directory}: output directory does not exist")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=directory)
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o666 & ~_umask())      # as an ordinary new file, not mkstemp's 0600
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.remove(tmp)
        raise


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def package_version() -> str:
    """Version of the installed package (recorded in every file written), or "unknown"."""
    from importlib.metadata import PackageNotFoundError, version
    try:
        return version("rebound-scatter")
    except PackageNotFoundError:
        return "unknown"
