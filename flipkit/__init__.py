"""flipkit: fast joint-space direct collocation for nonprehensile manipulation.

Reproduces Kolathaya et al., "Direct Collocation for Dynamic Behaviors with Nonprehensile
Contacts: Application to Flipping Burgers" (RA-L 2018) and goes beyond it.

The entry points a user needs::

    import flipkit

    plan = flipkit.plan_flip((0.75, 0.0, 0.073))       # pickup-and-flip, verified
    report = flipkit.verify_plan(plan)                  # the independent check
    plan.to_json("flip.json")
    result = flipkit.validate("flip.json", trials=10)   # executed in the simulated cell

They load on first use, so that ``import flipkit`` (and the ``flipkit`` command's help and
refusals) stay fast.
"""

from __future__ import annotations

import importlib

__version__ = "0.1.0"

_LAZY = {
    "CellConfig": "flipkit.config",
    "FlipkitError": "flipkit.errors",
    "Plan": "flipkit.planning.plans.plan_file",
    "Planner": "flipkit.planning.planners.chain",
    "plan_translate": "flipkit.planning.planners.planner",
    "plan_flip": "flipkit.planning.planners.planner",
    "plan_batch": "flipkit.planning.planners.planner",
    "replan_flip": "flipkit.planning.planners.planner",
    "plan_serve": "flipkit.planning.planners.serve",
    "verify_plan": "flipkit.planning.plans.verify",
    "validate": "flipkit.experiments.trials",
    "schedule": "flipkit.planning.kitchen.schedule",
}
_ALIASES = {"schedule": "schedule_cook", "validate": "validate_plan_file"}

__all__ = ["__version__", *_LAZY]


def __getattr__(name: str):
    if name not in _LAZY:
        raise AttributeError(f"module 'flipkit' has no attribute {name!r}")
    value = getattr(importlib.import_module(_LAZY[name]), _ALIASES.get(name, name))
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(__all__)
