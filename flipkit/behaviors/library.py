"""The catalogue: every behaviour and subbehaviour by name."""

from __future__ import annotations

from flipkit.behaviors.flip import FLIP, PICKUP_AND_FLIP, TURN_BACK
from flipkit.behaviors.pick import GO_TO_BURGER, PICKUP, SCOOP
from flipkit.behaviors.spec import Behavior, Subbehavior
from flipkit.behaviors.table import CARRY, PLACE, RETURN_HOME, SERVE
from flipkit.behaviors.translate import TRANSLATE, TRANSLATE_BEHAVIOR
from flipkit.errors import InvalidChoiceError

BEHAVIORS: dict[str, Behavior] = {b.name: b for b in (TRANSLATE_BEHAVIOR, PICKUP_AND_FLIP, SERVE)}
SUBBEHAVIORS: dict[str, Subbehavior] = {s.name: s for s in (
    TRANSLATE, GO_TO_BURGER, SCOOP, PICKUP, FLIP, TURN_BACK, CARRY, PLACE, RETURN_HOME)}
FLIP_NAMES = PICKUP_AND_FLIP.names  # the paper's five subbehaviours, in order
SERVE_NAMES = SERVE.names


def behavior(name: str) -> Behavior:
    """The behaviour ``name``, or :class:`~flipkit.errors.InvalidChoiceError`."""
    if name not in BEHAVIORS:
        raise InvalidChoiceError("behaviour", name, tuple(BEHAVIORS))
    return BEHAVIORS[name]


def subbehavior(name: str) -> Subbehavior:
    """The subbehaviour ``name``, or :class:`~flipkit.errors.InvalidChoiceError`."""
    if name not in SUBBEHAVIORS:
        raise InvalidChoiceError("subbehaviour", name, tuple(SUBBEHAVIORS))
    return SUBBEHAVIORS[name]
