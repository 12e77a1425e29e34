"""Warm-start atlas: pickup-and-flip solutions over a grid on the grill, as initial guesses.

An atlas holds, for each grid location where the chain was solved, every segment's solution
vector Z (go to burger … turn back). :meth:`Atlas.guess` returns the initial guess of a
segment at a new location: the inverse-distance-weighted mean (weights 1/d²) of the
entries among the ``K_NEAREST`` nearest whose joint angles lie within ``BRANCH_TOL`` of
the nearest entry's (entries on another IK branch or wrist turn are left out); an entry at
the location itself is returned as it is. The guess only seeds the solver: the start state
is fixed by the segment's own rows, and the plan is checked like every plan, so an atlas
can make a solve faster or slower, never a plan wrong.

Staleness. The file records the cell and the transcription options it was built with
(``SegmentOptions``) and their hash, and each segment's NLP structure key (sparsity and
bound types). :meth:`Atlas.load` refuses a file built for other options or another cell,
:meth:`Atlas.guess` one whose segment structure differs from the NLP it seeds (the code
changed since): :class:`~flipkit.errors.AtlasError`, one line, naming the fix
(``flipkit atlas build``). Built by :mod:`flipkit.experiments.atlas`.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
from importlib import resources
from pathlib import Path

import numpy as np

from flipkit.behaviors import targets as tg
from flipkit.behaviors.segments import SegmentOptions
from flipkit.config import CellConfig
from flipkit.errors import AtlasError

FORMAT = "flipkit-atlas/1"
# Segments the planners seed from the atlas. Not the flip: from the interpolated guess the SQP
# declared the flip infeasible after 8–12 iterations (2–3 s) at Table I locations 2 and 6
# (session 7, after the scoop's cone and the flip's coasting clearance), and then solved it
# cold in 19–21 iterations; its landing, cone and coasting rows are strongly curved, and a
# weighted mean of neighbours' flips satisfies none of them.
SEEDED = ("go_to_burger", "scoop", "pickup", "turn_back")
K_NEAREST = 4
BRANCH_TOL = 0.5  # rad: entries whose joint path departs more from the nearest one's are left out
DEFAULT_NAME = "atlas.npz"


def default_path() -> Path:
    """The atlas shipped with the package (``flipkit/data/atlas.npz``)."""
    return Path(str(resources.files("flipkit") / "data" / DEFAULT_NAME))


def options_hash(cell: CellConfig, options: SegmentOptions) -> str:
    """SHA-256 of the cell and transcription options (canonical JSON): equal hashes, same NLPs."""
    text = json.dumps({"format": FORMAT, "cell": dataclasses.asdict(cell),
                       "options": dataclasses.asdict(options)}, sort_keys=True, default=repr)
    return hashlib.sha256(text.encode()).hexdigest()


def default_atlas(cell: CellConfig | None = None, options: SegmentOptions = SegmentOptions()):
    """The package's atlas if it exists and serves ``cell`` and ``options``, else ``None``."""
    if not default_path().exists():
        return None
    try:
        return Atlas.load(default_path(), cell or CellConfig(), options)
    except AtlasError:
        return None


class Atlas:
    """Solved chains by location.

    Args:
        locations: (K, 3) burger locations p^b (m).
        solutions: Segment name -> (K, n) solution vectors (unscaled).
        structure: Segment name -> NLP structure key at build time.
        meta: JSON-able record: ``options_hash``, ``options``, ``cell``, ``grid``,
            ``failed`` locations, ``flipkit`` version and commit.

    Raises:
        AtlasError: Inconsistent shapes or missing segments.
    """

    def __init__(self, locations, solutions: dict, structure: dict, meta: dict):
        self.locations = np.asarray(locations, float).reshape(-1, 3)
        self.solutions = {k: np.asarray(v, float) for k, v in solutions.items()}
        self.structure, self.meta = dict(structure), dict(meta)
        for name in tg.SUBBEHAVIORS:
            if name not in self.solutions or name not in self.structure:
                raise AtlasError(f"atlas has no {name!r} solutions; segments: "
                                 f"{', '.join(sorted(self.solutions))}")
            if self.solutions[name].shape[0] != len(self.locations):
                raise AtlasError(f"atlas: {name!r} has {self.solutions[name].shape[0]} solutions "
                                 f"for {len(self.locations)} locations")
        if not len(self.locations):
            raise AtlasError("atlas has no entries")

    def __len__(self) -> int:
        return len(self.locations)

    # ----------------------------------------------------------------- files
    def save(self, path) -> Path:
        """Write one compressed ``.npz`` (float32 solutions: a guess needs no more)."""
        path = Path(path)
        arrays = {f"x_{k}": v.astype(np.float32) for k, v in self.solutions.items()}
        header = {"format": FORMAT, "structure": self.structure, **self.meta}
        np.savez_compressed(path, locations=self.locations, header=np.array(json.dumps(header)),
                            **arrays)
        return path

    @classmethod
    def load(cls, path, cell: CellConfig | None = None,
             options: SegmentOptions | None = None) -> "Atlas":
        """Read an atlas; with ``cell`` and ``options``, refuse one built for others.

        Raises:
            AtlasError: Unreadable, not an atlas, or stale (other options or cell).
        """
        try:
            with np.load(Path(path), allow_pickle=False) as data:
                header = json.loads(str(data["header"]))
                locations = data["locations"]
                solutions = {k[2:]: data[k] for k in data.files if k.startswith("x_")}
        except (OSError, ValueError, KeyError) as exc:
            raise AtlasError(f"cannot read atlas {path}: {' '.join(str(exc).split())}") from None
        if header.get("format") != FORMAT:
            raise AtlasError(f"{path}: not a {FORMAT} file (format {header.get('format')!r})")
        structure = header.pop("structure", {})
        atlas = cls(locations, solutions, structure, header)
        if cell is not None and options is not None:
            want = options_hash(cell, options)
            if header.get("options_hash") != want:
                raise AtlasError(f"stale atlas {path}: built for other planning options or "
                                 f"another cell (hash {str(header.get('options_hash'))[:12]}, "
                                 f"now {want[:12]}); rebuild it with `flipkit atlas build`")
        return atlas

    # ----------------------------------------------------------------- lookup
    def guess(self, name: str, location, nlp) -> np.ndarray:
        """Initial guess of segment ``name`` of the chain at ``location`` for ``nlp``.

        Raises:
            AtlasError: The atlas's ``name`` segment has another structure than ``nlp``
                (the NLP changed since the atlas was built).
        """
        if self.structure.get(name) != nlp.structure_key:
            raise AtlasError(f"stale atlas: the {name!r} segment's NLP has changed since the "
                             "atlas was built; rebuild it with `flipkit atlas build`")
        X = self.solutions[name]
        d = np.linalg.norm(self.locations[:, :2] - np.asarray(location, float)[:2], axis=1)
        near = np.argsort(d, kind="stable")[:K_NEAREST]
        if d[near[0]] < 1e-9:
            return X[near[0]].copy()
        q = nlp.layout.nodes(X[near[0]])[:, 0]
        keep = [k for k in near
                if np.abs(nlp.layout.nodes(X[k])[:, 0] - q).max() <= BRANCH_TOL]
        w = 1.0 / d[keep] ** 2
        return (w[:, None] * X[keep]).sum(0) / w.sum()


__all__ = ["Atlas", "FORMAT", "SEEDED", "default_atlas", "default_path", "options_hash"]
