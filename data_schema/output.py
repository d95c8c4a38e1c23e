"""Outputs that never destroy what is not ours: what may be replaced, and writes that are whole or absent.

Every file or folder the project writes carries its kind: an HDF5 file its
``file_type`` attribute (docs/format.md), a generated text file a first line
``<!-- rebound-scatter KIND ... -->``, a report folder a marker file
:data:`FOLDER_MARKER` holding its kind. ``overwrite`` replaces only an
existing output of the kind being written (:func:`check_output`), and never a
file the command reads. Anything else is refused with :class:`OutputError`
naming the path and why, before any expensive work.

Writes go to a temporary name next to the target and are moved into place
when complete (:func:`write_output`, :func:`atomic_folder`), so a target is
either untouched or whole. Without ``overwrite`` the last step never replaces
anything: a file is published by a hard link (which fails if the name
exists), a folder by a rename that refuses to replace (``renameat2`` with
``RENAME_NOREPLACE``), so a file that appeared at the target while the work
ran is kept and the command fails naming it. Temporary names carry the writer's process id;
a later write to the same folder removes those of processes that no longer
run (left by a killed run). Content is made in memory and written with
ordinary file writes, so a full disk is an ``OSError``, not a crash of a
library mid-write.
"""

from __future__ import annotations

import contextlib
import ctypes
import errno
import os
import re
import secrets
import shutil
from pathlib import Path

import h5py

FOLDER_MARKER = ".rebound-scatter"          # file inside a folder we wrote, holding its kind
TEXT_MARKER = "<!-- rebound-scatter {kind}: generated, do not edit -->"
TOML_MARKER = "# rebound-scatter {kind}: "      # the start of a generated TOML file's first line (a comment)
PNG_KEY = "rebound-scatter"                     # the keyword of a generated PNG's text chunk, its kind the value
_PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
_TEMP = re.compile(r"^\.(?P<name>.+)\.rebound-scatter-(?P<pid>\d+)-[0-9a-f]+\.tmp$")
BYTES_PER_GIB = 2 ** 30


class OutputError(ValueError):
    """An output that cannot or must not be written; the message names the path and why."""


def text_marker(kind: str) -> str:
    """The first line of a generated text file of ``kind``."""
    return TEXT_MARKER.format(kind=kind)


def kind_of(path) -> str | None:
    """The kind of an existing output of ours at ``path``, or None if it is not one.

    An HDF5 file's ``file_type``; a folder's :data:`FOLDER_MARKER` content; a
    text file's kind from its first line (:func:`text_marker`, or :data:`TOML_MARKER` for TOML); a PNG's from its
    text chunk :data:`PNG_KEY`.
    """
    path = Path(path)
    if path.is_dir():
        marker = path / FOLDER_MARKER
        try:
            return marker.read_text(encoding="utf-8").strip() if marker.is_file() else None
        except (OSError, UnicodeDecodeError):
            return None
    try:
        if h5py.is_hdf5(path):
            with h5py.File(path, "r") as f:
                found = f.attrs.get("file_type")
            return found.decode() if isinstance(found, bytes) else (found if isinstance(found, str) else None)
        with open(path, "rb") as f:
            start = f.read(65536)         # the markers are at the start: a large file is not read whole
    except OSError:
        return None
    if start.startswith(_PNG_SIGNATURE):
        return _png_kind(start)
    first = start.split(b"\n", 1)[0].decode("utf-8", errors="replace").strip()
    match = (re.fullmatch(re.escape(TEXT_MARKER).replace(r"\{kind\}", r"(\S+)"), first)
             or re.match(re.escape(TOML_MARKER.rstrip()).replace(r"\{kind\}", r"(\S+)"), first))
    return match.group(1) if match else None


def _png_kind(blob: bytes) -> str | None:
    """The value of the PNG text chunk :data:`PNG_KEY` among the chunks in ``blob``, or None."""
    at = len(_PNG_SIGNATURE)
    while at + 8 <= len(blob):
        length, chunk = int.from_bytes(blob[at:at + 4], "big"), blob[at + 4:at + 8]
        key, _, value = blob[at + 8:at + 8 + length].partition(b"\0")
        if chunk == b"tEXt" and key == PNG_KEY.encode():
            return value.decode("latin-1")
        at += 12 + length
    return None


def check_output(path, kind: str, overwrite: bool = False, inputs=(), folder: bool = False) -> Path:
    """``path`` as a Path if an output of ``kind`` may be written there; :class:`OutputError` if not.

    Refused: an empty path; a missing or unwritable parent folder; an existing
    path without ``overwrite``; an existing path that is one of ``inputs`` (the
    command's own input files), of another kind than ``kind`` or not ours, a
    folder where a file is written (or the reverse), or a file that cannot be
    replaced (immutable).
    """
    if str(path) == "":
        raise OutputError("the output path is empty; give a file or folder name")
    path = Path(path)
    parent = path.parent
    what = "folder" if folder else "file"
    if not parent.is_dir():
        raise OutputError(f"{path}: the folder {parent} does not exist; create it first")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise OutputError(f"{path}: the folder {parent} is not writable")
    _probe(path)
    if not (path.exists() or path.is_symlink()):
        return path
    for item in inputs:
        if Path(item).exists() and os.path.samefile(path, item):
            raise OutputError(f"{path}: is this command's input {item}; write the output elsewhere")
    if path.is_dir() != folder:
        raise OutputError(f"{path}: is a {'folder' if path.is_dir() else 'file'}; the output is a {what}")
    if not overwrite:
        raise OutputError(f"{path}: exists; pass --overwrite (overwrite=True) to replace it")
    found = kind_of(path)
    if found != kind:
        now = f"a {found} output" if found else "not an output of rebound-scatter"
        raise OutputError(f"{path}: is {now}; --overwrite replaces only a {kind} {what} this package wrote")
    if not folder:
        try:
            os.close(os.open(path, os.O_WRONLY))    # opening for writing truncates nothing; refused if immutable
        except OSError as exc:
            raise OutputError(f"{path}: cannot be replaced: {exc.strerror}") from None
    return path


def _probe(path: Path) -> None:
    """OutputError unless a file can be made next to ``path`` (os.access says yes to root in /proc, where the
    write then fails after the work, naming the temporary file)."""
    probe = _temporary_name(path)
    try:
        os.close(os.open(probe, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600))
    except OSError as exc:
        raise OutputError(f"{path}: cannot write in the folder {path.parent}: {exc.strerror}") from None
    os.remove(probe)


def _temporary_name(path: Path) -> Path:
    return path.with_name(f".{path.name}.rebound-scatter-{os.getpid()}-{secrets.token_hex(4)}.tmp")


def remove_stale_temporaries(folder, name: str = "*") -> list:
    """Remove the temporary files or folders of writes in ``folder`` (to ``name``, or to any name) whose
    process no longer runs; return their paths."""
    removed = []
    for entry in Path(folder).glob(f".{name}.rebound-scatter-*.tmp"):
        match = _TEMP.match(entry.name)
        if match is None or (name != "*" and match["name"] != name) or _running(int(match["pid"])):
            continue
        if entry.is_dir() and not entry.is_symlink():
            shutil.rmtree(entry, ignore_errors=True)
        else:
            with contextlib.suppress(FileNotFoundError):
                entry.unlink()
        removed.append(entry)
    return removed


def _running(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:     # it runs, as another user
        pass
    return True


def _mode(bits: int) -> int:
    mask = os.umask(0)
    os.umask(mask)
    return bits & ~mask


def write_output(path, data: bytes, kind: str, overwrite: bool = False, inputs=()) -> Path:
    """Write ``data`` to ``path`` as an output of ``kind``: checked (:func:`check_output`), whole or not at all;
    without ``overwrite``, never over a file that appeared at ``path`` meanwhile (:func:`replace_file`)."""
    path = check_output(path, kind, overwrite, inputs)
    replace_file(path, data, overwrite)
    return path


def _taken(path) -> OutputError:
    return OutputError(f"{path}: appeared while this command ran and was kept; nothing was written (pass "
                       f"--overwrite (overwrite=True) to replace an output of this package)")


def _link_new(tmp: Path, path: Path) -> None:
    """Publish the file ``tmp`` as ``path`` only if ``path`` does not exist (a hard link, then ``tmp``
    removed); :class:`OutputError` if it does. Where the file system has no hard links, a rename that
    refuses to replace (:func:`_rename_new`)."""
    try:
        os.link(tmp, path)
    except FileExistsError:
        raise _taken(path) from None
    except OSError as exc:
        if exc.errno not in (errno.EPERM, errno.EOPNOTSUPP, errno.ENOTSUP, errno.EMLINK):
            raise
        _rename_new(tmp, path)
        return
    os.remove(tmp)


_RENAME_NOREPLACE = 1       # <linux/fs.h>
_AT_FDCWD = -100


def _rename_new(tmp: Path, path: Path) -> None:
    """Rename ``tmp`` to ``path`` only if ``path`` does not exist (Linux ``renameat2`` with RENAME_NOREPLACE;
    elsewhere, or where the file system lacks it, a check then a rename: a race window remains there);
    :class:`OutputError` if it exists."""
    renameat2 = getattr(ctypes.CDLL(None, use_errno=True), "renameat2", None)
    if renameat2 is not None:
        if renameat2(_AT_FDCWD, os.fsencode(tmp), _AT_FDCWD, os.fsencode(path), _RENAME_NOREPLACE) == 0:
            return
        code = ctypes.get_errno()
        if code == errno.EEXIST:
            raise _taken(path)
        if code not in (errno.EINVAL, errno.ENOSYS, errno.EOPNOTSUPP):
            raise OSError(code, os.strerror(code), str(path))
    if path.exists() or path.is_symlink():
        raise _taken(path)
    os.rename(tmp, path)


def replace_file(path, data: bytes, overwrite: bool = True) -> None:
    """Write ``data`` to a temporary file next to ``path``, flush it to disk and move it onto ``path``:
    renamed over it with ``overwrite``, else published only if ``path`` does not exist (:func:`_link_new`:
    :class:`OutputError` if it appeared meanwhile).

    No check of what ``path`` holds: for files inside a folder of ours (checkpoints) and after
    :func:`check_output`. On any error the temporary file is removed and ``path`` is untouched.
    """
    path = Path(path)
    remove_stale_temporaries(path.parent, path.name)
    tmp = _temporary_name(path)
    try:
        fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, _mode(0o666))
        with os.fdopen(fd, "wb") as f:
            f.write(data)
            f.flush()
            os.fsync(f.fileno())
        if overwrite:
            os.replace(tmp, path)
        else:
            _link_new(tmp, path)
    except BaseException as exc:
        with contextlib.suppress(FileNotFoundError):
            os.remove(tmp)
        if isinstance(exc, OSError) and not isinstance(exc, OutputError) and exc.errno:
            raise OSError(exc.errno, exc.strerror, str(path)) from None     # the user's path, not the temporary name
        raise


@contextlib.contextmanager
def atomic_folder(path, kind: str, overwrite: bool = False):
    """Yield a new temporary folder next to ``path``; on success it replaces ``path``, on error it is removed.

    ``path`` is checked first (:func:`check_output` with ``folder=True``): an existing folder is
    replaced only if it holds our marker of ``kind``. The new folder gets that marker. The swap is
    two renames (old folder aside, new one in), then the old folder is deleted.
    """
    path = check_output(path, kind, overwrite, folder=True)
    remove_stale_temporaries(path.parent, path.name)
    tmp = _temporary_name(path)
    tmp.mkdir(mode=_mode(0o777))
    try:
        yield tmp
        (tmp / FOLDER_MARKER).write_text(kind + "\n", encoding="utf-8")
        if overwrite and path.exists():
            old = _temporary_name(path)
            os.replace(path, old)
            os.replace(tmp, path)
            shutil.rmtree(old)
        else:
            _rename_new(tmp, path)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


def hdf5_bytes(write) -> bytes:
    """The bytes of an HDF5 file made in memory by ``write(h5py.File)``."""
    import io

    buffer = io.BytesIO()
    with h5py.File(buffer, "w") as f:
        write(f)
    return buffer.getvalue()


def available_memory() -> int:
    """Bytes of memory available to a new allocation (MemAvailable on Linux; else physical memory)."""
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")


def check_memory(count: int, bytes_each: int, what: str) -> None:
    """ValueError naming ``what`` if ``count`` items of ``bytes_each`` bytes do not fit in available memory."""
    need, have = count * bytes_each, available_memory()
    if need > have:
        largest = max(have // bytes_each, 0)
        raise ValueError(f"{what} = {count} needs {need / BYTES_PER_GIB:.1f} GiB of memory and "
                         f"{have / BYTES_PER_GIB:.1f} GiB is available; allowed: at most {largest}")


def check_free_space(path, need: int, what: str) -> None:
    """OutputError if the file system of ``path``'s folder has less than ``need`` bytes free."""
    free = shutil.disk_usage(Path(path).parent).free
    if need > free:
        raise OutputError(f"{path}: {what} needs about {need / BYTES_PER_GIB:.2f} GiB and the disk has "
                          f"{free / BYTES_PER_GIB:.2f} GiB free")
