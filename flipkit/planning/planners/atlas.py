"""Warm-start atlas: pickup-and-flip solutions over a grid on the grill, as initial guesses.

An atlas holds, for each grid location and scoop heading where the chain was solved, every
segment's solution vector Z (go to burger … turn back). :meth:`Atlas.guess` returns the
initial guess of a segment at a new location and heading: the inverse-distance-weighted mean
(weights 1/d²) of the entries among the ``K_NEAREST`` nearest (:func:`entry_distance`: the
burger's move and the heading's turn, as far as it moves the tool flange) whose joint angles
lie within ``BRANCH_TOL`` of
the nearest entry's (entries on another IK branch or wrist turn are left out, and so are
entries whose duration lies outside the NLP's bounds: solved with the bound stretched); an
entry at the location itself is returned as it is. The guess only seeds the solver: the start state
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

from flipkit.behaviors.library import FLIP_NAMES, PICKUP_AND_FLIP
from flipkit.behaviors.options import SegmentOptions
from flipkit.behaviors.targets import default_heading
from flipkit.config import CellConfig
from flipkit.config.physics import SIMULATION_ONLY
from flipkit.errors import AtlasError
from flipkit.fileio import replace_with
from flipkit.jsonread import strict_loads
from flipkit.planning.planners.inputs import check_atlas_file
from flipkit.transcription.guess import fit_guess

FORMAT = "flipkit-atlas/1"
# Segments the planners seed from the atlas.
SEEDED = FLIP_NAMES  # the atlas holds every segment of the pickup-and-flip
# Segments seeded by their neighbours' joint paths *anchored* at the segment's actual start
# state, then refitted (:func:`anchored_guess`), rather than by the interpolated vector itself.
# The flip and the turn back start where the previous segment of *this* chain ended, which an
# interpolated solution misses: the flip's landing, cone and coasting rows are strongly curved,
# and a weighted mean of neighbours' flips satisfies none of them, where a neighbour's flip
# anchored at the actual start is close to a solution (docs/history.md has the measurements).
# "shift": q(t) = q_atlas(t) + (q_start − q_atlas(0)) (the flip's free end moves with its
# start); "blend": the offset fades out by a smoothstep (the turn back ends at q_home).
ANCHORED = {s.name: s.atlas_anchor for s in PICKUP_AND_FLIP.steps if s.atlas_anchor}
# The atlas's headings are each location's default scoop heading (radial from the base,
# flipkit.behaviors.targets.default_heading) turned by each of its ``turns``; the hash names
# the rule, so an atlas built with another one is refused as stale.
HEADING_RULE = "radial+turns"
K_NEAREST = 4
BRANCH_TOL = 0.5  # rad: entries whose joint path departs more from the nearest one's are left out
DEFAULT_NAME = "atlas.npz"


def default_path() -> Path:
    """The atlas shipped with the package (``flipkit/data/atlas.npz``)."""
    return Path(str(resources.files("flipkit") / "data" / DEFAULT_NAME))


def options_hash(cell: CellConfig, options: SegmentOptions) -> str:
    """SHA-256 of the cell, the heading rule and the transcription options (canonical JSON):
    equal hashes, same NLPs.
    The simulation's numerical settings (:data:`flipkit.config.physics.SIMULATION_ONLY`) are
    left out: no NLP depends on them."""
    record = dataclasses.asdict(cell)
    for name in SIMULATION_ONLY:
        record["physics"].pop(name)
    text = json.dumps({"format": FORMAT, "cell": record, "heading": HEADING_RULE,
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


def entry_distance(locations, headings, location, heading, flange: float) -> np.ndarray:
    """Distance (m) of atlas entries (``locations`` (K, 3) m, ``headings`` (K,) rad) from a
    burger at ``location`` scooped along ``heading`` (rad): √(|Δxy|² + (flange · Δψ)²), Δψ
    wrapped to (−π, π]. Turning the heading by Δψ about the burger moves the tool flange,
    ``flange`` (m, the spatula's handle) from the blade centre, by flange · Δψ: a turn counts
    as the move of the joints' end that it makes."""
    dxy = np.linalg.norm(np.asarray(locations, float)[:, :2] - np.asarray(location, float)[:2],
                         axis=1)
    dpsi = np.angle(np.exp(1j * (np.asarray(headings, float) - float(heading))))
    return np.hypot(dxy, flange * dpsi)


class Atlas:
    """Solved chains by location and scoop heading.

    Args:
        locations: (K, 3) burger locations p^b (m).
        headings: (K,) scoop headings ψ (rad) the entries were solved at.
        solutions: Segment name -> (K, n) solution vectors (unscaled).
        structure: Segment name -> NLP structure key at build time.
        meta: JSON-able record: ``options_hash``, ``options``, ``cell``, ``grid``,
            ``turns`` (rad, from each location's default heading), ``flange`` (m, the
            spatula's handle, :func:`entry_distance`), ``failed`` entries, ``flipkit``
            version and commit.

    Raises:
        AtlasError: Inconsistent shapes or missing segments.
    """

    def __init__(self, locations, headings, solutions: dict, structure: dict, meta: dict):
        self.locations = np.asarray(locations, float).reshape(-1, 3)
        self.headings = np.asarray(headings, float).reshape(-1)
        self.solutions = {k: np.asarray(v, float) for k, v in solutions.items()}
        self.structure, self.meta = dict(structure), dict(meta)
        if self.headings.shape != (len(self.locations),) or not np.all(
                np.isfinite(self.headings)):
            raise AtlasError(f"atlas: {self.headings.size} headings for "
                             f"{len(self.locations)} locations; each entry needs a finite one")
        flange = self.meta.get("flange")
        if not (isinstance(flange, (int, float)) and np.isfinite(flange) and flange > 0):
            raise AtlasError(f"atlas: meta 'flange' must be a positive length (m), got {flange!r}")
        for name in FLIP_NAMES:
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
        """Write one compressed ``.npz`` (float32 solutions: a guess needs no more),
        atomically (:func:`flipkit.fileio.replace_with`)."""
        path = Path(path)
        arrays = {f"x_{k}": v.astype(np.float32) for k, v in self.solutions.items()}
        header = {"format": FORMAT, "structure": self.structure, **self.meta}
        return replace_with(path, lambda tmp: np.savez_compressed(
            tmp, locations=self.locations, headings=self.headings,
            header=np.array(json.dumps(header)), **arrays))

    @classmethod
    def load(cls, path, cell: CellConfig | None = None,
             options: SegmentOptions | None = None) -> "Atlas":
        """Read an atlas; with ``cell`` and ``options``, refuse one built for others.

        Raises:
            AtlasError: Unreadable, not an atlas, or stale (other options or cell).
        """
        check_atlas_file(path)
        try:
            with np.load(Path(path), allow_pickle=False) as data:
                header = strict_loads(str(data["header"]))
                locations = data["locations"]
                if "headings" not in data.files:
                    raise AtlasError(f"stale atlas {path}: it holds no scoop headings; rebuild "
                                     "it with `flipkit atlas build`")
                headings = data["headings"]
                solutions = {k[2:]: data[k] for k in data.files if k.startswith("x_")}
        except (OSError, ValueError, KeyError, RecursionError) as exc:
            reason = ("an array holds Python objects, which are never loaded"
                      if "allow_pickle" in str(exc) else " ".join(str(exc).split())[:200])
            raise AtlasError(f"cannot read atlas {path}: {reason}; give a file written by "
                             "`flipkit atlas build`") from None
        if not isinstance(header, dict):
            raise AtlasError(f"{path}: not a {FORMAT} file (its header is not an object)")
        if header.get("format") != FORMAT:
            raise AtlasError(f"{path}: not a {FORMAT} file (format {header.get('format')!r})")
        structure = header.pop("structure", {})
        atlas = cls(locations, headings, solutions, structure, header)
        if cell is not None and options is not None:
            want = options_hash(cell, options)
            if header.get("options_hash") != want:
                raise AtlasError(f"stale atlas {path}: built for other planning options or "
                                 f"another cell (hash {str(header.get('options_hash'))[:12]}, "
                                 f"now {want[:12]}); rebuild it with `flipkit atlas build`")
        return atlas

    # ----------------------------------------------------------------- lookup
    def solved_turns(self, location, cell: CellConfig) -> np.ndarray:
        """The turns (rad) from the default heading that were solved at the atlas location
        nearest ``location`` (m, its x-y): where a turned plan is likely to solve."""
        xy = np.asarray(location, float)[:2]
        d = np.hypot(*(self.locations[:, :2] - xy).T)
        near = np.flatnonzero(d <= d.min() + 1e-9)
        at = self.locations[near[0]]
        return np.sort(self.headings[near] - default_heading(cell, at))

    def distance(self, location, heading: float) -> np.ndarray:
        """Each entry's :func:`entry_distance` (m) from ``location`` and ``heading``."""
        return entry_distance(self.locations, self.headings, location, heading,
                              self.meta["flange"])

    def stretched(self, name: str, location, nlp, heading: float) -> bool:
        """Whether most of the atlas's ``K_NEAREST`` entries nearest to ``location`` and
        ``heading`` (rad) solved
        segment ``name`` with its duration bound stretched (their T above ``nlp``'s upper
        bound): the planner then tries the stretched bound first. Where the neighbourhood
        needs the stretch, the warm SQP within the bound, seeded from the few entries that
        fit it, mostly ends infeasible, and it is slow to prove that. A minority of stretched
        neighbours leaves the usual order, within the bound first, so that a segment that
        fits its bound is not made slower than it need be."""
        X = self.solutions.get(name)
        if X is None or self.structure.get(name) != nlp.structure_key:
            return False
        d = self.distance(location, heading)
        near = np.argsort(d, kind="stable")[:K_NEAREST]
        i = nlp.layout.T_index
        return bool(2 * np.count_nonzero(X[near, i] > nlp.x_ub[i] + 1e-6) > len(near))

    def guess(self, name: str, location, nlp, heading: float, start=None) -> np.ndarray:
        """Initial guess of segment ``name`` of the chain at ``location`` and ``heading`` for
        ``nlp``.

        Args:
            name, location, nlp: The segment, the burger's location p^b (m) and its NLP.
            heading: The scoop heading ψ (rad).
            start: Optional (q, q̇) the segment starts from (rad, rad/s); for the segments of
                :data:`ANCHORED`, the guess is then anchored there (:func:`anchored_guess`).

        Raises:
            AtlasError: The atlas's ``name`` segment has another structure than ``nlp``
                (the NLP changed since the atlas was built).
        """
        if self.structure.get(name) != nlp.structure_key:
            raise AtlasError(f"stale atlas: the {name!r} segment's NLP has changed since the "
                             "atlas was built; rebuild it with `flipkit atlas build`")
        X = self.solutions[name]
        d = self.distance(location, heading)
        # An entry whose duration lies outside this NLP's bounds was solved with the bound
        # stretched (the planner's retry, ×1.5): clipped to the bound it violates every
        # defect row, so it seeds nothing (an SQP started there declares the segment
        # infeasible).
        i = nlp.layout.T_index
        inside = (X[:, i] >= nlp.x_lb[i] - 1e-6) & (X[:, i] <= nlp.x_ub[i] + 1e-6)
        d = np.where(inside, d, np.inf) if inside.any() else d
        near = np.argsort(d, kind="stable")[:K_NEAREST]
        near = near[np.isfinite(d[near])]
        if d[near[0]] < 1e-9:
            x = X[near[0]].copy()
        else:
            q = nlp.layout.nodes(X[near[0]])[:, 0]
            keep = [k for k in near
                    if np.abs(nlp.layout.nodes(X[k])[:, 0] - q).max() <= BRANCH_TOL]
            w = 1.0 / d[keep] ** 2
            x = (w[:, None] * X[keep]).sum(0) / w.sum()
        if start is None or name not in ANCHORED:
            return x
        return anchored_guess(nlp, x, start[0], start[1], ANCHORED[name])


def check_atlas(atlas, cell: CellConfig, options: SegmentOptions) -> None:
    """Raise :class:`~flipkit.errors.AtlasError` if ``atlas`` (or ``None``) was built for
    other planning options or another cell, or is not an :class:`Atlas`."""
    if atlas is not None and not isinstance(atlas, Atlas):
        raise AtlasError(f"atlas: expected an Atlas (Atlas.load(path)) or None, got "
                         f"{type(atlas).__name__}")
    if atlas is not None and atlas.meta.get("options_hash") != options_hash(cell, options):
        raise AtlasError("stale atlas: built for other planning options or another cell; "
                         "rebuild it with `flipkit atlas build`")


class Seeding:
    """A :meth:`~flipkit.planning.planners.chain.Planner.chain` ``guess`` from an atlas for
    the burger at ``location`` scooped along ``heading`` (rad): called as
    ``guess(name, nlp, q, qd)``, the atlas's interpolated solution for the segments it holds
    (:data:`SEEDED`), else ``None``; :meth:`stretched` tells the planner to try the
    stretched bound first."""

    def __init__(self, atlas: Atlas, location, heading: float):
        self.atlas, self.location, self.heading = atlas, location, float(heading)

    def __call__(self, name: str, nlp, q, qd):
        if name not in SEEDED:
            return None
        return self.atlas.guess(name, self.location, nlp, self.heading, (q, qd))

    def stretched(self, name: str, nlp) -> bool:
        return name in SEEDED and self.atlas.stretched(name, self.location, nlp, self.heading)


def seeding(atlas, location, heading: float):
    """A :class:`Seeding` from ``atlas`` for the burger at ``location`` scooped along
    ``heading`` (rad); ``None`` without an atlas."""
    return None if atlas is None else Seeding(atlas, location, heading)


def anchored_guess(nlp, x, q_start, qd_start, how: str) -> np.ndarray:
    """A guess for ``nlp`` from another solution ``x`` of its structure, anchored at the
    segment's start state: the joint path of ``x`` offset by q_start − q_x(0) ("shift": the
    whole path; "blend": fading out by a smoothstep, so the end is kept), then refitted by the
    Bezier polynomial from (q_start, q̇_start) with u = RNEA (:func:`~flipkit.transcription.guess.fit_guess`),
    at the duration of ``x``. A start that is ``x``'s own (to 1e-9) returns ``x``."""
    L, robot = nlp.layout, nlp.robot
    nodes = L.nodes(x)
    offset = np.asarray(q_start, float) - nodes[0, 0]
    if np.abs(offset).max() < 1e-9 and np.abs(nodes[0, 1] - qd_start).max() < 1e-9:
        return np.asarray(x, float).copy()
    s = L.s
    fade = np.ones_like(s) if how == "shift" else 1.0 - s * s * (3 - 2 * s)
    waypoints = np.clip(nodes[:, 0] + np.outer(fade, offset), robot.q_min, robot.q_max)
    T = float(np.clip(x[L.T_index], nlp.x_lb[L.T_index], nlp.x_ub[L.T_index]))
    return fit_guess(L, robot, waypoints, T, qd_start, rest_at_end=how == "blend")


__all__ = ["ANCHORED", "Atlas", "FORMAT", "SEEDED", "Seeding", "anchored_guess", "check_atlas", "seeding", "default_atlas", "default_path", "options_hash"]
