"""The header line of a CSV input (a cook order, a batch of burgers), one rule for every
reader.

A header names exactly the columns of one of the reader's documented headers, each once, in
any order; the rows are read by column name. A column the reader does not know is refused,
not ignored: a misspelt column (``t_dorp``) or one meant for another program would otherwise
be dropped without a word, and the file read as if it said something it does not.
"""

from __future__ import annotations

import csv
from collections.abc import Sequence

from flipkit.errors import ConfigError


def expected_headers(headers: Sequence[Sequence[str]]) -> str:
    """The documented headers as a user types them: ``x,y,z or px,py,pz``."""
    return " or ".join(",".join(h) for h in headers)


def header_columns(line: str, headers: Sequence[Sequence[str]], where: str,
                   error: type[ConfigError] = ConfigError) -> dict[str, int]:
    """The position of each column named in the header ``line``.

    Names are compared stripped and in lower case. The header matched is the one of
    ``headers`` that shares the most columns with ``line``.

    Args:
        line: The header line of the file (CSV).
        headers: The documented headers, each a sequence of column names.
        where: The start of an error message (the file and the line).
        error: The error class raised (a :class:`~flipkit.errors.ConfigError`).

    Returns:
        ``{column: index}`` for the columns of the matched header.

    Raises:
        ConfigError: (``error``) One line: ``where``, the expected header and the first
            problem — a column not in it, one of its columns missing, or a column twice.
    """
    names = [h.strip().lower() for h in next(csv.reader([line]), [])]
    best = max(headers, key=lambda h: len(set(h) & set(names)))
    problem = None
    for name in names:
        if name not in best:
            problem = f"unknown column {name!r}"
            break
        if names.count(name) > 1:
            problem = f"column {name!r} appears twice"
            break
    else:
        missing = [c for c in best if c not in names]
        if missing:
            problem = f"missing column {missing[0]!r}"
    if problem:
        raise error(f"{where}: header must be {expected_headers(headers)} (in any order); "
                    f"{problem}")
    return {name: names.index(name) for name in best}


__all__ = ["expected_headers", "header_columns"]
