"""The execution modes: the two joint controllers that run a plan in the simulated cell
(:func:`flipkit.simulation.execute.execute_plan`), named once here.

This module imports nothing, so that the command line and the experiments can name the modes
without loading MuJoCo.
"""

from __future__ import annotations

__all__ = ["FEEDFORWARD", "MODES", "POSITION"]

FEEDFORWARD = "feedforward"
"""Feed-forward torque control: the plan's torques plus joint PD (the default mode)."""

POSITION = "position"
"""The robot's own PD position control on servo-rate, delayed position commands, with gravity
compensation from its controller's model (paper, footnote 2)."""

MODES = (FEEDFORWARD, POSITION)
"""Every execution mode, the default first."""
