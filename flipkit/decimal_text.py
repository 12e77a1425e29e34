"""Numbers typed by a user (command-line words, CSV cells) read as decimals only.

Python's :func:`float` also reads spellings that are Python's own: digit separators
(``0.6_9`` is 0.69), other scripts' digits, surrounding whitespace. A typo such as
``0.6_9`` must be refused, not planned for. :func:`decimal` accepts ``[+-]digits[.digits]
[e[+-]digits]`` and the words ``nan``, ``inf`` and ``infinity`` (which the callers refuse as
not finite, naming the option).
"""

from __future__ import annotations

import re

_DECIMAL = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?"
                      r"|[+-]?(?:nan|inf|infinity)", re.IGNORECASE)


def decimal(text: str) -> float:
    """The number ``text`` spells in decimal notation (surrounding blanks ignored).

    Raises:
        ValueError: Any other spelling (digit separators, non-ASCII digits, hex, empty).
    """
    word = str(text).strip()
    if not _DECIMAL.fullmatch(word):
        raise ValueError(f"not a decimal number: {text!r}")
    return float(word)


__all__ = ["decimal"]
