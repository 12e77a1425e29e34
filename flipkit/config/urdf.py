"""URDF files named portably: the arm's model as another machine can find it.

A plan file names its URDF so that a plan written on one machine verifies on another. A URDF
shipped by example-robot-data (the default UR10) is named by its place in that package,
``example-robot-data:ur_description/urdf/ur10_joint_limited_robot.urdf``, which each machine
resolves in its own installation; any other URDF is named by its absolute path. The file's
sha256 travels beside the name, so a different file under the same name is detected.
"""

from __future__ import annotations

import hashlib
import sysconfig
from pathlib import Path, PurePosixPath

from flipkit.errors import ConfigError

ERD_PREFIX = "example-robot-data:"
ERD_ROBOTS = ("cmeel.prefix", "share", "example-robot-data", "robots")  # under site-packages
UR10_URDF = "ur_description/urdf/ur10_joint_limited_robot.urdf"  # in ERD_ROBOTS


def robots_dir() -> Path | None:
    """example-robot-data's ``robots`` directory in this Python, or None if not installed."""
    for key in ("purelib", "platlib"):
        path = Path(sysconfig.get_paths()[key]).joinpath(*ERD_ROBOTS)
        if path.is_dir():
            return path
    return None


def resolve_urdf(name: str) -> str:
    """The absolute path of a URDF named portably (``example-robot-data:<path>``) or by path.

    Raises:
        ConfigError: example-robot-data is not installed, the name escapes its directory, or
            the file does not exist or is not a regular file (a device, a directory).
    """
    if not name.startswith(ERD_PREFIX):
        path = Path(name)
        try:
            found, regular = path.exists(), path.is_file()
        except OSError as exc:  # a name too long for the file system, a loop of links
            shown = name if len(name) <= 80 else name[:60] + "..."
            raise ConfigError(f"URDF {shown}: cannot be looked up "
                              f"({exc.strerror or exc})") from None
        if not found:
            raise ConfigError(f"URDF file not found: {name}")
        if not regular:
            raise ConfigError(f"URDF {name}: not a regular file; give the path of a .urdf file")
        return str(path.resolve())
    rel = PurePosixPath(name[len(ERD_PREFIX):])
    if rel.is_absolute() or ".." in rel.parts or not rel.parts:
        raise ConfigError(f"URDF name {name!r}: expected example-robot-data:<path inside its "
                          "robots directory>")
    base = robots_dir()
    if base is None:
        raise ConfigError(f"URDF {name!r}: example-robot-data is not installed here "
                          "(install the environment.lock)")
    path = base.joinpath(*rel.parts)
    if not path.is_file():
        raise ConfigError(f"URDF {name!r}: no such file in example-robot-data ({path})")
    return str(path)


def portable_urdf(path: str) -> str:
    """The portable name of the URDF at ``path``: ``example-robot-data:<path>`` if the file is
    one of that package's, else its absolute path."""
    path = Path(path).resolve()
    base = robots_dir()
    if base is not None and path.is_relative_to(base.resolve()):
        return ERD_PREFIX + path.relative_to(base.resolve()).as_posix()
    return str(path)


def default_urdf() -> str:
    """Absolute path of the UR10 joint-limited URDF shipped by example-robot-data (pip).

    Raises:
        ConfigError: example-robot-data is not installed.
    """
    return resolve_urdf(ERD_PREFIX + UR10_URDF)


MAX_URDF_BYTES = 16 * 2**20  # bytes: the UR10's URDF is 10 kB


def urdf_sha256(path: str) -> str:
    """sha256 (hex) of the URDF file's bytes."""
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def check_urdf_text(path: str) -> None:
    """Refuse a file that cannot be a URDF before a model is built from it: larger than
    :data:`MAX_URDF_BYTES`, not UTF-8 text, or without a ``<robot`` element.

    Raises:
        ConfigError: One line naming the file.
    """
    p = Path(path)
    try:
        if p.stat().st_size > MAX_URDF_BYTES:
            raise ConfigError(f"URDF {path}: larger than {MAX_URDF_BYTES} bytes")
        text = p.read_bytes().decode("utf-8")
    except OSError as exc:
        raise ConfigError(f"URDF {path}: cannot read ({exc.strerror or exc})") from None
    except UnicodeDecodeError:
        raise ConfigError(f"URDF {path}: not a URDF (not UTF-8 text)") from None
    if "<robot" not in text:
        raise ConfigError(f"URDF {path}: not a URDF (no <robot> element)")
