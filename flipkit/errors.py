"""Exception hierarchy: every error flipkit raises derives from :class:`FlipkitError`.

Messages are one line and, where the error is a bad choice, list the valid choices, so the
command line can print them as they are (``flipkit: error: <message>``) and exit non-zero.
A message that quotes a value whose ``repr`` spans lines (a numpy array) is folded to one
line by :class:`FlipkitError` itself; :func:`brief` shortens such a value for a message.
"""

from __future__ import annotations

from typing import Any, Iterable


BRIEF_CHARS = 80  # characters of a value quoted in a message


def brief(value) -> str:
    """``repr(value)`` on one line, cut to :data:`BRIEF_CHARS` characters (``...`` marks a
    cut): how a message quotes a value it refuses."""
    text = " ".join(repr(value).split())
    return text if len(text) <= BRIEF_CHARS else text[:BRIEF_CHARS - 3] + "..."


class FlipkitError(Exception):
    """Root of every flipkit error. Its message is one line: every run of whitespace,
    line breaks included, reads as one space.

    Attributes:
        exit_status: The command line's exit status for it: 2, bad input refused.
    """

    exit_status = 2

    def __str__(self) -> str:
        return " ".join(super().__str__().split())


class ConfigError(FlipkitError, ValueError):
    """An invalid configuration value (wrong shape, non-finite, out of range)."""


class InvalidChoiceError(ConfigError):
    """A name that is not one of the allowed choices.

    Args:
        what: What is being chosen (e.g. ``"cone form"``).
        value: The rejected value.
        choices: The valid values, listed in the message.
    """

    def __init__(self, what: str, value: Any, choices: Iterable[Any]):
        self.what, self.value, self.choices = what, value, tuple(choices)
        valid = ", ".join(repr(c) for c in self.choices)
        super().__init__(f"unknown {what} {value!r}; valid choices: {valid}")

    def __reduce__(self):  # raised in a sweep's worker process, it travels back pickled
        return type(self), (self.what, self.value, self.choices)


class UnreachableError(FlipkitError):
    """A requested spatula pose that the robot cannot reach (IK failed or outside the area)."""


class PlanFileError(FlipkitError):
    """A plan file that is missing, not JSON, or not in a readable ``flipkit-plan`` format."""


class NoSolutionFound(FlipkitError):
    """A trajectory optimisation that did not converge to a feasible point.

    Attributes:
        problem: The NLP that was being solved.
        status: Solver status string.
        group: Name of the most violated constraint group (or ``None``).
        amount: Its maximum scaled violation.
        result: The solver result (iterate, log), for inspection.
    """

    def __init__(self, problem: Any, status: str, group: str | None, amount: float,
                 result: Any = None):
        self.problem, self.status, self.group, self.amount, self.result = (
            problem, status, group, amount, result)
        where = f"; worst constraint group {group!r} violated by {amount:.3g}" if group else ""
        super().__init__(f"no solution found ({status}){where}")

    def __reduce__(self):
        """Pickled (a worker process's error) without the NLP and the result, which hold
        compiled models: the status, group and amount travel, and the message with them."""
        return type(self), (None, self.status, self.group, self.amount)


class SolverError(FlipkitError):
    """A numerical solver that broke down, as opposed to a problem without a solution
    (:class:`NoSolutionFound`): OSQP failing inside cvxpy, or a factorisation that cannot be
    formed. The SQP reports it as the status ``qp_solver_error`` of its segment."""


class SingularBasisError(SolverError):
    """The condensed subproblem's equality-row Jacobian is rank deficient at the iterate: no
    basis of its columns can be factorised."""


class VerificationError(FlipkitError):
    """A plan that fails the independent residual check."""


class NoSymbolicFormError(FlipkitError):
    """A constraint block that cannot be stated as a CasADi symbolic expression (the arm's
    clearance rows, coal distances), asked for by an exact-derivative solver (FATROP,
    exact-Hessian IPOPT)."""


class AtlasError(FlipkitError):
    """A warm-start atlas that cannot be read, or was built for other planning options, another
    cell or an NLP that has changed since (rebuild it with ``flipkit atlas build``)."""


class ExportError(FlipkitError):
    """A verified plan that cannot be written in the asked export format: a streamed joint
    command outside the model's position limits, or a robot whose joints the format cannot
    name."""


class SweepError(FlipkitError):
    """Sweep items that could not be computed although their input was accepted: their
    worker died on every attempt, or the executor was lost. The items that finished are kept
    (in the sweep's cache), so the same command resumes."""

    exit_status = 1
