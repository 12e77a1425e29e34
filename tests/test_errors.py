"""Errors raised in a worker process reach the parent: every FlipkitError pickles with its
type and message (an exception whose __init__ takes other arguments than its message broke
the process pool instead)."""

import pickle

import pytest

from flipkit import errors
from flipkit.config import with_parameter, CellConfig


def _instances():
    simple = [cls("a message") for cls in vars(errors).values()
              if isinstance(cls, type) and issubclass(cls, errors.FlipkitError)
              and cls not in (errors.InvalidChoiceError, errors.NoSolutionFound)]
    return simple + [errors.InvalidChoiceError("cone form", "round", ("physical", "paper")),
                     errors.NoSolutionFound(object(), "infeasible", "landing", 0.25, object())]


@pytest.mark.parametrize("exc", _instances(), ids=lambda e: type(e).__name__)
def test_every_flipkit_error_survives_pickling(exc):
    back = pickle.loads(pickle.dumps(exc))
    assert type(back) is type(exc) and str(back) == str(exc)


def test_an_unknown_parameter_in_a_worker_reaches_the_caller_as_itself():
    from concurrent.futures import ProcessPoolExecutor

    with ProcessPoolExecutor(1) as pool:
        future = pool.submit(with_parameter, CellConfig(), "physics.burger_strips", 3)
        with pytest.raises(errors.InvalidChoiceError, match="valid choices"):
            future.result()
