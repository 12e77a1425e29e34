"""Cook windows: how far from its mark each burger event may fall.

A burger has two events (:mod:`flipkit.planning.kitchen.cook`): its flip, which must land
it on its second side at its 90 s mark (``t_drop`` + 90 s), and its serve, which must lift
it off the grill 60 s after that landing. A window ``(early, late)`` (s, both ≥ 0) lets an
event fall in [mark − early, mark + late]; the default is (0, 2) s for both events: never
early (no side cooked short), at most 2 s late. The serve's mark moves with its own flip's
landing, so a flip late by 1 s pushes its serve's mark 1 s later too.

:class:`Windows` holds both windows, :func:`parse_windows` reads the command line's
``--window flip=EARLY,LATE`` / ``--window serve=EARLY,LATE``, :func:`event_deviations`
gives a burger's deviations from its marks and :func:`worst_break` the event that breaks
its window by the most (:class:`WindowBreak`, one line).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from flipkit.errors import ConfigError, FlipkitError, InvalidChoiceError
from flipkit.planning.kitchen.cook import SECOND_SIDE_S

EVENTS = ("flip", "serve")
DEFAULT_WINDOW_S = (0.0, 2.0)  # s (early, late), both events: the kitchen's stated window
MAX_WINDOW_S = 30.0  # s: a bound beyond half a minute is no cook window (ours)


class WindowError(ConfigError):
    """A malformed window (``--window``): one line naming the text and the valid form."""


class WindowsBrokenError(FlipkitError):
    """No schedule keeps every event in its window; ``breach`` names the worst event."""

    def __init__(self, breach: "WindowBreak", policy: str, why: str = ""):
        self.breach, self.policy = breach, policy
        super().__init__(f"{policy}: {breach.message()}" + (f"; {why}" if why else ""))


@dataclass(frozen=True)
class Windows:
    """The windows of both events, ``(early, late)`` in s, each in [0, :data:`MAX_WINDOW_S`].

    Raises:
        WindowError: A bound that is not finite, negative or above :data:`MAX_WINDOW_S`.
    """

    flip: tuple = DEFAULT_WINDOW_S
    serve: tuple = DEFAULT_WINDOW_S

    def __post_init__(self):
        for event in EVENTS:
            bounds = tuple(getattr(self, event))
            if len(bounds) != 2 or not all(
                    isinstance(v, (int, float)) and math.isfinite(v) and 0 <= v <= MAX_WINDOW_S
                    for v in bounds):
                raise WindowError(f"{event} window must be two numbers EARLY,LATE in [0, "
                                  f"{MAX_WINDOW_S:g}] s, got {bounds}")
            object.__setattr__(self, event, tuple(float(v) for v in bounds))

    def of(self, event: str) -> tuple:
        """``(early, late)`` (s) of ``event`` ("flip" or "serve")."""
        if event not in EVENTS:
            raise InvalidChoiceError("event", event, EVENTS)
        return getattr(self, event)

    def excess(self, event: str, deviation: float) -> float:
        """How far (s, ≥ 0) a ``deviation`` (event − mark, s) lies outside the window."""
        early, late = self.of(event)
        return max(0.0, deviation - late, -early - deviation)

    def describe(self) -> str:
        """``flip [-0, +2] s, serve [-0, +2] s``."""
        return ", ".join(f"{e} [-{self.of(e)[0]:g}, +{self.of(e)[1]:g}] s" for e in EVENTS)

    def to_dict(self) -> dict:
        """``{"flip": [early, late], "serve": [early, late]}`` (s)."""
        return {e: list(self.of(e)) for e in EVENTS}


def parse_windows(texts, base: Windows = Windows()) -> Windows:
    """Windows from ``EVENT=EARLY,LATE`` texts (s), e.g. ``["flip=0,2", "serve=1,3"]``;
    events not named keep ``base``'s window.

    Raises:
        WindowError: A text not of that form, an unknown event, a bound out of range or an
            event named twice — one line.
    """
    found: dict[str, tuple] = {}
    for text in texts or ():
        event, sep, rest = str(text).partition("=")
        event = event.strip()
        form = "EVENT=EARLY,LATE (s), e.g. flip=0,2"
        if not sep:
            raise WindowError(f"window {text!r}: expected {form}")
        if event not in EVENTS:
            raise WindowError(f"window {text!r}: unknown event {event!r}; valid events: "
                              f"{', '.join(EVENTS)}")
        if event in found:
            raise WindowError(f"window {text!r}: the {event} window is given twice")
        parts = rest.split(",")
        try:
            bounds = tuple(float(p) for p in parts)
        except ValueError:
            bounds = ()
        if len(parts) != 2 or len(bounds) != 2:
            raise WindowError(f"window {text!r}: expected {form}")
        if not all(math.isfinite(v) and 0 <= v <= MAX_WINDOW_S for v in bounds):
            raise WindowError(f"window {text!r}: EARLY and LATE must be numbers of seconds "
                              f"in [0, {MAX_WINDOW_S:g}]")
        found[event] = bounds
    return Windows(**{e: found.get(e, base.of(e)) for e in EVENTS})


def event_deviations(record) -> dict:
    """Deviations (s) of a burger's events from their marks: the flip's landing − (t_drop +
    90 s) and the serve's lift-off − (landing + 60 s); ``None`` where not done.

    Args:
        record: Anything with ``burger`` (a :class:`~flipkit.planning.kitchen.cook.CookBurger`),
            ``flip_time`` and ``serve_time`` (s or ``None``), e.g. a schedule's burger record.
    """
    flip, serve = record.flip_time, record.serve_time
    return {"flip": None if flip is None else flip - record.burger.flip_mark,
            "serve": None if serve is None or flip is None else serve - flip - SECOND_SIDE_S}


@dataclass(frozen=True)
class WindowBreak:
    """The event that lies furthest outside its window."""

    burger: str
    event: str
    deviation_s: float
    excess_s: float
    window: tuple
    others: int = 0  # other events as far outside their windows

    def message(self) -> str:
        """One line: which burger, which event, by how much."""
        side = "late" if self.deviation_s > 0 else "early"
        also = (f" (and {self.others} other event{'s' if self.others > 1 else ''} by as much)"
                if self.others else "")
        return (f"burger {self.burger}: its {self.event} would be {abs(self.deviation_s):.2f} s "
                f"{side}, {self.excess_s:.2f} s beyond its window [-{self.window[0]:g}, "
                f"+{self.window[1]:g}] s{also}")


def worst_break(records, windows: Windows, tol: float = 2e-3) -> WindowBreak | None:
    """The event of ``records`` (burger records, :func:`event_deviations`) furthest outside
    its window, by more than ``tol`` s (default 2 ms, the optimiser's rounding); ``None``
    when every event done is in its window. Among events as far outside (within ``tol``),
    a late one of the last burger in ``records``, its serve before its flip."""
    found = []
    for k, rec in enumerate(records):
        for event, dev in event_deviations(rec).items():
            if dev is not None and (excess := windows.excess(event, dev)) > tol:
                found.append((excess, dev, k, event, rec.burger.burger))
    if not found:
        return None
    top = max(f[0] for f in found)
    ties = [f for f in found if f[0] >= top - tol]
    excess, dev, _, event, burger = max(ties, key=lambda f: (f[1] > 0, f[2], f[3] == "serve"))
    return WindowBreak(burger, event, dev, excess, windows.of(event), len(ties) - 1)


__all__ = ["DEFAULT_WINDOW_S", "EVENTS", "MAX_WINDOW_S", "WindowBreak", "WindowError",
           "Windows", "WindowsBrokenError", "event_deviations", "parse_windows",
           "worst_break"]
