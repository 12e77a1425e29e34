"""Input and output files of the command line and the library: checked before any work,
written atomically.

An input is read only if it is a regular file of bounded size (a device such as
``/dev/zero`` or a directory is refused by name, not reported as missing); text is decoded
as UTF-8 with an optional byte-order mark. An output path is checked before anything is
computed: its file names fit the file system (:data:`NAME_MAX`), its directory exists and a
file can be created in it (the permission bits, then a probe file created and removed), its
suffix names a format the command writes, and it is neither an input of the same command
(same file after resolving links) nor another of its outputs. Outputs are written to a temporary file in the same directory
and renamed over the target (:func:`os.replace`), so an interrupted run leaves the old file
or the new one, never a part.
"""

from __future__ import annotations

import os
import stat
import tempfile
from pathlib import Path
from typing import Callable, Iterable

from flipkit.errors import ConfigError

MAX_INPUT_BYTES = 256 * 2**20  # bytes: the largest input file read (plans are < 1 MB)
NAME_MAX = 255  # bytes in one file name: Linux's file systems (ext4, xfs, btrfs, tmpfs)


class InputFileError(ConfigError):
    """An input file that is missing, not a regular file, too large or not decodable."""


class OutputPathError(ConfigError):
    """An output path that cannot be written, has an unknown format or names an input."""


def check_input(path, what: str, max_bytes: int = MAX_INPUT_BYTES) -> Path:
    """The path of an input file, checked to be a readable regular file of at most
    ``max_bytes`` bytes.

    Args:
        path: The file. what: How the message names it (e.g. ``"--burgers"``).
        max_bytes: Largest size accepted (bytes).

    Raises:
        InputFileError: One line naming ``what`` and the path.
    """
    p = Path(path)
    try:
        st = p.stat()
    except OSError as exc:
        reason = "not found" if isinstance(exc, FileNotFoundError) else (exc.strerror or exc)
        raise InputFileError(f"{what} {p}: {reason}") from None
    if stat.S_ISDIR(st.st_mode):
        raise InputFileError(f"{what} {p}: is a directory, expected a file")
    if not stat.S_ISREG(st.st_mode):
        raise InputFileError(f"{what} {p}: not a regular file (a device, pipe or socket)")
    if st.st_size > max_bytes:
        raise InputFileError(f"{what} {p}: {st.st_size} bytes, more than the "
                             f"{max_bytes} bytes accepted")
    if not os.access(p, os.R_OK):
        raise InputFileError(f"{what} {p}: permission denied")
    return p


def read_text(path, what: str, max_bytes: int = MAX_INPUT_BYTES) -> str:
    """The text of an input file (UTF-8, a leading byte-order mark dropped).

    Raises:
        InputFileError: As :func:`check_input`, or the bytes are not UTF-8.
    """
    p = check_input(path, what, max_bytes)
    try:
        return p.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError as exc:
        raise InputFileError(f"{what} {p}: not UTF-8 text (byte {exc.start})") from None
    except OSError as exc:
        raise InputFileError(f"{what} {p}: cannot read ({exc.strerror or exc})") from None


def data_lines(text: str) -> list[tuple[int, str]]:
    """The lines of a CSV-like text that hold data, with their line numbers (from 1): blank
    lines and ``#`` comments left out."""
    return [(n, line) for n, line in enumerate(text.splitlines(), 1)
            if line.strip() and not line.lstrip().startswith("#")]


def _same_file(a: Path, b) -> bool:
    """Whether ``a`` and ``b`` name the same file (resolved; by inode where both exist)."""
    b = Path(b)
    try:
        if a.exists() and b.exists():
            return os.path.samefile(a, b)
    except OSError:
        pass
    return a.resolve() == b.resolve()


def _shown(path) -> str:
    """``path`` as a message shows it: at most 80 characters."""
    text = str(path)
    return text if len(text) <= 80 else f"{text[:60]}...({len(text)} characters)"


def _name_fits(p: Path, what: str) -> None:
    """Refuse a path with a component longer than the file system takes (NAME_MAX bytes,
    255 on Linux's file systems)."""
    for part in p.parts:
        size = len(os.fsencode(part))
        if size > NAME_MAX:
            raise OutputPathError(f"{what} {_shown(p)}: a file name of {size} bytes, longer "
                                  f"than the {NAME_MAX} bytes a file system takes")


def _writable_dir(directory: Path, what: str, path) -> None:
    """Refuse a directory that does not exist or where no file can be created: the
    permission bits (``os.access``), then a probe file created and removed (root passes
    the bits everywhere, and /proc, /sys or a read-only mount refuse only the creation)."""
    if not directory.is_dir():
        raise OutputPathError(f"{what} {_shown(path)}: directory {directory} does not exist")
    if not os.access(directory, os.W_OK | os.X_OK):
        raise OutputPathError(f"{what} {_shown(path)}: directory {directory} is not writable")
    try:
        fd, probe = tempfile.mkstemp(dir=directory, prefix=".flipkit-probe-")
    except OSError as exc:
        raise OutputPathError(f"{what} {_shown(path)}: directory {directory} is not writable "
                              f"({exc.strerror or exc})") from None
    os.close(fd)
    os.unlink(probe)


def check_output(path, what: str, suffixes: Iterable[str] | None, inputs: Iterable = (),
                 outputs: Iterable = ()) -> Path:
    """The path of an output file, checked before any work.

    Args:
        path: The output file. what: The flag that names it (e.g. ``"--json"``).
        suffixes: The formats written, by suffix (lower case, e.g. ``(".json",)``); ``None``
            accepts any.
        inputs: The command's input files: the output may be none of them.
        outputs: The command's other outputs: the output may be none of them.

    Raises:
        OutputPathError: One line naming ``what``, the path and what to change.
    """
    p = Path(path)
    _name_fits(p, what)
    if suffixes is not None:
        suffixes = tuple(suffixes)
        if p.suffix.lower() not in suffixes:
            raise OutputPathError(f"{what} {p}: unknown output format "
                                  f"{p.suffix or '(no suffix)'!r}; give a file ending in "
                                  f"{' or '.join(suffixes)}")
    if p.is_dir():
        raise OutputPathError(f"{what} {p}: is a directory; give a file name")
    if p.exists() and not p.is_file():
        raise OutputPathError(f"{what} {p}: not a regular file; give a file name")
    _writable_dir(p.parent if str(p.parent) else Path("."), what, p)
    for other in inputs:
        if other is not None and _same_file(p, other):
            raise OutputPathError(f"{what} {p}: is an input of this command ({other}); "
                                  "give another output path")
    for other in outputs:
        if other is not None and _same_file(p, other):
            raise OutputPathError(f"{what} {p}: is also another output of this command; "
                                  "give another path")
    return p


def check_output_dir(path, what: str, inputs: Iterable = (), names: Iterable[str] = ()) -> Path:
    """The path of an output directory (created when written), checked before any work:
    not an existing file, its nearest existing ancestor writable, and none of the files
    ``names`` that will be written in it an input.

    Raises:
        OutputPathError: One line naming ``what``, the path and what to change.
    """
    p = Path(path)
    _name_fits(p, what)
    for name in names:
        _name_fits(p / name, what)
    if p.exists() and not p.is_dir():
        raise OutputPathError(f"{what} {p}: exists and is not a directory; give a directory")
    base = p
    while not base.exists():
        if base.parent == base:
            break
        base = base.parent
    _writable_dir(base, what, p)
    inputs = [i for i in inputs if i is not None]
    for name in names:
        for other in inputs:
            if _same_file(p / name, other):
                raise OutputPathError(f"{what} {p}: would overwrite the input {other} with "
                                      f"{name}; give another directory")
    return p


def _file_mode(path: Path) -> int:
    """The permission bits a new ``path`` gets: those of the file it replaces, else 0o666
    less the umask (as :func:`open` would create it), not mkstemp's 0o600."""
    try:
        return stat.S_IMODE(path.stat().st_mode)
    except OSError:
        mask = os.umask(0o022)
        os.umask(mask)
        return 0o666 & ~mask


def replace_with(path, write: Callable[[Path], object]) -> Path:
    """Write ``path`` atomically: ``write(tmp)`` fills a temporary file in the same directory
    (with the same suffix, for writers that choose the format by it), which is then renamed
    over ``path``. On any exception the temporary file is removed and ``path`` is unchanged.

    Raises:
        OutputPathError: The file cannot be written (``OSError``).
    """
    path = Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent if str(path.parent) else ".",
                               prefix=f".{path.stem}.", suffix=f".tmp{path.suffix}")
    os.close(fd)
    tmp = Path(tmp)
    try:
        write(tmp)
        os.chmod(tmp, _file_mode(path))
        os.replace(tmp, path)
    except OSError as exc:
        raise OutputPathError(f"cannot write {path}: {exc.strerror or exc}") from None
    finally:
        if tmp.exists():
            tmp.unlink()
    return path


def write_text(path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically (:func:`replace_with`)."""
    return replace_with(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))


__all__ = ["MAX_INPUT_BYTES", "InputFileError", "OutputPathError", "check_input",
           "check_output", "check_output_dir", "data_lines", "read_text", "replace_with", "write_text"]
