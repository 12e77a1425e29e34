"""Space limits of the whole arm: every link and the spatula keep a margin from the cell's boxes.

One row per node: the least distance (m) over the (shape, box) pairs the segment applies at
that node (:class:`~flipkit.model.collision.ArmShapes`: the arm's shapes, the cell's boxes),
bounded below by the margin. The row's Jacobian is the nearest pair's distance gradient, on
the node's q columns (a fixed pattern). Taking the minimum over pairs, rather than a row per
pair, keeps the QP small (20 rows per segment instead of 27 × 20 = 540; the condensed QP's
rows are dense, and 60 rows, one per box, double the QP time of the flip); the
minimum is continuous and its gradient switches between pairs where two are equally near,
which the SQP's line search handles as it does any kink. A row reads min(d, :data:`CAP`): a node whose shapes all lie
farther than CAP from a box costs no exact distance query (the broad phase proves it) and
gives the row a zero gradient; with CAP ≫ margin the constraint is the same.
"""

from __future__ import annotations

import numpy as np

from flipkit.errors import ConfigError
from flipkit.model.collision import ArmShapes
from flipkit.transcription.constraints.base import Block
from flipkit.transcription.constraints.registry import Check

NO_SX = "coal computes its distances; they have no CasADi form"

CAP = 0.25  # m: distances beyond it read as CAP (our choice; > 10 × the default margin)


class ArmClearance(Block):
    """margin ≤ min(CAP, min_{(s, b) ∈ P_i} d(shape s at q_i, box b)) for each node i.

    Args:
        layout: Variable layout.
        shapes: The arm's shapes and the cell's boxes.
        nodes: Node indices.
        excluded: (shape name, box name) pairs the segment does not apply (e.g. the blade
            and the grill in the scoop, which presses the blade into it), or a function of
            the node index giving them.
        margin: Least distance (m), one for all nodes or one per node of ``nodes``.
    """

    def __init__(self, layout, shapes: ArmShapes, nodes, excluded=(), margin: float = 0.02):
        super().__init__("arm_clearance", layout)
        self.shapes, self.nodes = shapes, [int(i) for i in nodes]
        rule = excluded if callable(excluded) else (lambda i, pairs=frozenset(excluded): pairs)
        self.pairs = []  # per node: array of (shape index, box index)
        for i in self.nodes:
            skip = set(rule(i))
            for shape, box in skip:  # names must exist: a typo would silently apply the pair
                shapes.shape_index(shape), shapes.box_index(box)
            self.pairs.append(np.array(
                [(k, b) for k, s in enumerate(shapes.names)
                 for b, box in enumerate(shapes.box_names) if (s, box) not in skip],
                dtype=int).reshape(-1, 2))
        margin = np.broadcast_to(np.asarray(margin, float), (len(self.nodes),))
        if not np.all(np.isfinite(margin)) or np.any(margin < 0) or np.any(margin >= CAP):
            raise ConfigError(f"arm clearance margin must be in [0, {CAP}) m, got {margin}")
        kept = [r for r, p in enumerate(self.pairs) if len(p)]
        self.nodes = [self.nodes[r] for r in kept]
        self.pairs = [self.pairs[r] for r in kept]
        margin = margin[kept]
        self.allowed = np.zeros((len(self.nodes), len(shapes.names), len(shapes.box_names)), bool)
        for r, pairs in enumerate(self.pairs):
            self.allowed[r, pairs[:, 0], pairs[:, 1]] = True
        for r, i in enumerate(self.nodes):
            self._add(r, 1, layout.iq(i))
        self.m = len(self.nodes)
        self.nearest = np.full((self.m, 2), -1)  # (shape, box) setting each row, last evaluate
        self._finish(margin, np.inf, 1.0)

    check = Check(("arm_clearance",))
    no_symbolic_form = NO_SX

    def evaluate(self, ev):
        if not self.m:
            return np.zeros(0), np.zeros(0)
        qs = self.layout.nodes(ev.x)[self.nodes, 0]
        vals, grad, self.nearest[:, 0], self.nearest[:, 1] = self.shapes.nearest_nodes(
            qs, self.allowed, CAP)
        return vals, grad.ravel()


class CoastingClearance(Block):
    """margin ≤ min(CAP, min_{(s, b) ∈ P} d(shape s at q_i + τ q̇_i, box b)) at one node i.

    The space limits at the configuration the arm would reach coasting for ``tau`` from node
    i's state: a segment that ends in motion (the flip) leaves the next segment, which starts
    from that state (29), room to keep the margin at its first node without braking, and to
    brake after it. It is to the cell's boxes what
    :class:`~flipkit.transcription.constraints.braking.BrakingMargin` is to the joint limits.
    The row's Jacobian is exact: ∂/∂q_i = g, ∂/∂q̇_i = τ g, g the nearest pair's distance
    gradient at q_i + τ q̇_i.

    Args:
        layout: Variable layout. shapes: The arm's shapes and the cell's boxes.
        node: Node index. tau: Coasting time (s, > 0).
        excluded: (shape name, box name) pairs not applied. margin: Least distance (m).
    """

    def __init__(self, layout, shapes: ArmShapes, node: int, tau: float, excluded=(),
                 margin: float = 0.02):
        super().__init__("coasting_clearance", layout)
        if not (np.isfinite(tau) and tau > 0):
            raise ConfigError(f"coasting time must be positive (s), got {tau!r}")
        if not (np.isfinite(margin) and 0 <= margin < CAP):
            raise ConfigError(f"arm clearance margin must be in [0, {CAP}) m, got {margin!r}")
        self.shapes, self.node, self.tau = shapes, int(node), float(tau)
        skip = set(excluded)
        for shape, box in skip:
            shapes.shape_index(shape), shapes.box_index(box)
        self.pairs = np.array([(k, b) for k, s in enumerate(shapes.names)
                               for b, box in enumerate(shapes.box_names) if (s, box) not in skip],
                              dtype=int).reshape(-1, 2)
        self._add(0, 1, np.concatenate([layout.iq(self.node), layout.iqd(self.node)]))
        self.m = 1
        self.nearest = np.full((1, 2), -1)
        self._finish(margin, np.inf, 1.0)

    check = Check(none="a margin the planner keeps for the next segment: what it protects, "
                       "that segment's arm_clearance from its continuous start, is checked there")
    no_symbolic_form = NO_SX

    def evaluate(self, ev):
        q, qd = ev.node(self.node)[:2]
        d, grad, *self.nearest[0] = self.shapes.nearest(q + self.tau * qd, self.pairs, CAP)
        return np.array([d]), np.concatenate([grad, self.tau * grad])
