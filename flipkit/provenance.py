"""Provenance: the commit a plan or a figure was made from, read without a git process."""

from __future__ import annotations

from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[1]


def git_commit(root: Path = REPO_ROOT) -> str | None:
    """The checked-out commit of the repository at ``root``, read from ``.git`` (no git
    process), or None outside a git checkout."""
    gitdir = root / ".git"
    if gitdir.is_file():  # worktree or submodule: "gitdir: <path>"
        gitdir = (root / gitdir.read_text().split(":", 1)[1].strip()).resolve()
    try:
        head = (gitdir / "HEAD").read_text().strip()
        if not head.startswith("ref:"):
            return head or None
        ref = head.split(":", 1)[1].strip()
        common = gitdir / "commondir"
        base = (gitdir / common.read_text().strip()).resolve() if common.is_file() else gitdir
        for where in (gitdir, base):
            if (where / ref).is_file():
                return (where / ref).read_text().strip()
        for line in (base / "packed-refs").read_text().splitlines():
            if line.endswith(" " + ref):
                return line.split()[0]
    except (OSError, IndexError):
        pass
    return None
