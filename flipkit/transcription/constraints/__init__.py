"""Constraint blocks of the collocation NLP, one family per module.

Every block has a fixed sparsity pattern (``rows``, ``cols``) decided at construction, bounds
``lo ≤ c ≤ hi`` (equal for equalities) and a row scale; :meth:`Block.evaluate` returns the
values and the Jacobian entries in pattern order.
"""

from flipkit.transcription.constraints.base import Block, FixedValues
from flipkit.transcription.constraints.braking import BrakingMargin
from flipkit.transcription.constraints.dynamics import BezierOutput, Dynamics, HermiteSimpson
from flipkit.transcription.constraints.kinematic import KinematicBlock
from flipkit.transcription.constraints.quantities import QUANTITIES

__all__ = ["Block", "FixedValues", "BrakingMargin", "Dynamics", "HermiteSimpson", "BezierOutput",
           "KinematicBlock", "QUANTITIES"]
