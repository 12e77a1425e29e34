"""The API refuses like the command line: ``plan_flip``, ``plan_serve``, ``plan_translate``,
``verify_plan``, ``validate`` (and ``validate_locations``) and ``Plan.load`` raise a
:class:`~flipkit.errors.FlipkitError` with a one-line message on a wrong type or value,
before any solve or simulation.

Hypothesis draws the wrong values: None, booleans, text, bytes, mappings, complex numbers,
plain objects, NaN and infinities, sequences of the wrong length, of the wrong element
types or nested, 2-D arrays, negative and out-of-range counts. Every other argument is
valid, and the solvers and the simulation are replaced by a function that fails the test:
a value that got through would reach them.
"""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

import flipkit
from flipkit.errors import FlipkitError, brief
from flipkit.experiments import trials
from flipkit.experiments.perturbations import MAX_TRIALS
from flipkit.planning.planners import chain
from flipkit.planning.plans.plan_file import Plan

LOC = (0.69, -0.16, 0.072)  # a burger on the grill (Table I)
SPOT = (0.40, 0.60)  # on the table
EXAMPLES = settings(max_examples=40, deadline=None, derandomize=True)

NOT_A_NUMBER = st.one_of(
    st.none(), st.booleans(), st.text(max_size=6), st.binary(max_size=4),
    st.dictionaries(st.text(max_size=3), st.integers(), max_size=2),
    st.complex_numbers(allow_nan=False, allow_infinity=False).filter(lambda z: z.imag != 0),
    st.builds(object))
NON_FINITE = st.sampled_from([math.nan, math.inf, -math.inf])
SMALL = st.floats(-1.0, 1.0)


def not_a_vector(n: int):
    """Anything but ``n`` finite real numbers."""
    return st.one_of(
        NOT_A_NUMBER, NON_FINITE, SMALL,
        st.lists(SMALL, max_size=7).filter(lambda v: len(v) != n),
        st.tuples(st.lists(SMALL, min_size=n, max_size=n), st.integers(0, n - 1),
                  NON_FINITE).map(lambda t: t[0][:t[1]] + [t[2]] + t[0][t[1] + 1:]),
        st.lists(NOT_A_NUMBER, min_size=n, max_size=n),
        st.lists(st.lists(SMALL, min_size=2, max_size=2), min_size=n, max_size=n),
        arrays(np.float64, (n, n), elements=SMALL))


def off_the_grill():
    """Burger locations with x short of the grill (x < 0.6 m), or at the wrong height."""
    return st.one_of(
        st.tuples(st.floats(-5.0, 0.59), st.floats(-0.5, 0.16), st.just(0.072)),
        st.tuples(st.just(0.69), st.just(-0.16), st.floats(0.1, 5.0)))


NOT_A_COUNT = st.one_of(NOT_A_NUMBER.filter(lambda v: v is not None), NON_FINITE,
                        st.floats(0.5, 50.0), st.integers(max_value=0),
                        st.integers(min_value=MAX_TRIALS + 1), arrays(np.int64, (2,)))
NOT_A_SEED = st.one_of(NOT_A_NUMBER, NON_FINITE, st.floats(0.5, 50.0),
                       st.integers(max_value=-1))
NOT_A_SOLVER = st.one_of(NOT_A_NUMBER, st.text(min_size=1, max_size=8).filter(
    lambda s: s not in ("auto", "sqp", "ipopt")), arrays(np.float64, (2,)))
NOT_A_PATH = st.one_of(st.none(), st.booleans(), st.integers(), st.floats(), st.binary(),
                       st.lists(st.text(max_size=3), max_size=3),
                       st.dictionaries(st.text(max_size=3), st.integers(), max_size=2),
                       st.builds(object))
NOT_A_CONFIG = st.one_of(st.booleans(), st.integers(), st.floats(), st.text(max_size=4),
                         st.lists(st.integers(), max_size=3),
                         st.dictionaries(st.text(max_size=3), st.integers(), max_size=2),
                         st.builds(object))


@pytest.fixture(scope="module")
def translate_file(tmp_path_factory):
    """A solved translate plan file (one short NLP, about 1 s), planned before the solvers
    are replaced."""
    plan = flipkit.plan_translate((0.6, -0.1, 0.2), (0.7, 0.0, 0.25))
    assert plan.status == "solved", plan.failure
    return plan.to_json(tmp_path_factory.mktemp("api") / "translate.json")


@pytest.fixture(scope="module")
def translate_plan(translate_file):
    return Plan.load(translate_file)


@pytest.fixture(scope="module", autouse=True)
def nothing_runs(translate_file):
    """The solvers and the simulated trials fail the test if a value reaches them."""
    def ran(*args, **kwargs):
        raise AssertionError("a refused input reached a solve or a simulation")

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(chain, "solve_segment", ran)
        mp.setattr(trials, "run_sweep", ran)
        yield


def refused(call, *args, **kwargs) -> str:
    """Call; assert a FlipkitError with a one-line message; return the message."""
    with pytest.raises(FlipkitError) as exc:
        call(*args, **kwargs)
    message = str(exc.value)
    assert message and "\n" not in message, message
    return message


# ------------------------------------------------------------------ planning
@EXAMPLES
@given(value=st.one_of(not_a_vector(3), off_the_grill()))
def test_plan_flip_refuses_a_location(value):
    refused(flipkit.plan_flip, value)


@EXAMPLES
@given(name=st.sampled_from(["q_start", "qd_start", "land", "on_blade"]), value=st.data())
def test_plan_flip_refuses_a_malformed_vector(name, value):
    n = {"q_start": 6, "qd_start": 6, "land": 2, "on_blade": 2}[name]
    refused(flipkit.plan_flip, LOC, **{name: value.draw(not_a_vector(n).filter(
        lambda v: v is not None))})


@EXAMPLES
@given(name=st.sampled_from(["cell", "options", "atlas", "solver", "approach_height"]),
       value=st.data())
def test_plan_flip_refuses_a_wrong_type(name, value):
    strategy = {"solver": NOT_A_SOLVER,
                "approach_height": st.one_of(NOT_A_NUMBER, NON_FINITE,
                                             st.floats(max_value=-1e-6))}.get(name, NOT_A_CONFIG)
    refused(flipkit.plan_flip, LOC, **{name: value.draw(strategy.filter(
        lambda v: v is not None))})


@EXAMPLES
@given(burger=st.one_of(not_a_vector(3), off_the_grill()))
def test_plan_serve_refuses_a_burger(burger):
    refused(flipkit.plan_serve, burger, SPOT)


@EXAMPLES
@given(spot=st.one_of(not_a_vector(2), st.tuples(st.floats(-5, 0.2), st.floats(0.45, 0.8))))
def test_plan_serve_refuses_a_table_spot(spot):
    refused(flipkit.plan_serve, LOC, spot)


@EXAMPLES
@given(which=st.sampled_from(["start", "goal", "yaw", "q_start"]), value=st.data())
def test_plan_translate_refuses_a_malformed_argument(which, value):
    start, goal = (0.6, -0.1, 0.2), (0.7, 0.0, 0.25)
    if which == "yaw":
        refused(flipkit.plan_translate, start, goal, yaw=value.draw(st.one_of(
            NOT_A_NUMBER, NON_FINITE, arrays(np.float64, (2,)))))
    elif which == "q_start":
        refused(flipkit.plan_translate, None, goal, q_start=value.draw(not_a_vector(6).filter(
            lambda v: v is not None)))
    else:
        args = {"start": start, "goal": goal}
        args[which] = value.draw(not_a_vector(3).filter(lambda v: v is not None))
        refused(flipkit.plan_translate, args["start"], args["goal"])


# ------------------------------------------------------------------ plan files and verify
@EXAMPLES
@given(path=NOT_A_PATH)
def test_plan_load_refuses_what_is_not_a_path(path):
    assert "plan file" in refused(Plan.load, path)


@EXAMPLES
@given(plan=st.one_of(NOT_A_PATH, st.text(max_size=10)))
def test_verify_plan_refuses_what_is_not_a_plan(plan):
    refused(flipkit.verify_plan, plan)


@EXAMPLES
@given(tol=st.one_of(NOT_A_NUMBER.filter(lambda v: v is not None), NON_FINITE,
                     st.floats(1e-3, 1e6), st.floats(-1.0, 1e-10),
                     arrays(np.float64, (3, 3))),
       cell=st.one_of(st.none(), NOT_A_CONFIG))
def test_verify_plan_refuses_a_tolerance_or_cell(translate_plan, tol, cell):
    refused(flipkit.verify_plan, translate_plan, tol=tol, cell=cell)


# ------------------------------------------------------------------ validate
@EXAMPLES
@given(path=NOT_A_PATH)
def test_validate_refuses_what_is_not_a_path(path):
    refused(flipkit.validate, path, 1)


@EXAMPLES
@given(which=st.sampled_from(["trials", "seed"]), value=st.data())
def test_validate_refuses_a_count_or_seed(translate_file, which, value):
    """Refused before the plan is read: the same file validates as far as its behaviour."""
    args = {"trials": 1, "seed": 0}
    args[which] = value.draw(NOT_A_COUNT if which == "trials" else NOT_A_SEED)
    message = refused(flipkit.validate, translate_file, args["trials"], args["seed"])
    assert which in message, message


@EXAMPLES
@given(which=st.sampled_from(["locations", "trials", "seed", "solver"]), value=st.data())
def test_validate_locations_refuses_a_malformed_argument(which, value):
    args = {"locations": [LOC], "trials": 1, "seed": 0, "solver": "sqp"}
    args[which] = value.draw({
        "locations": st.one_of(NOT_A_NUMBER.filter(lambda v: not isinstance(v, str)),
                               st.lists(st.one_of(not_a_vector(3), off_the_grill()),
                                        min_size=1, max_size=3)),
        "trials": NOT_A_COUNT, "seed": NOT_A_SEED, "solver": NOT_A_SOLVER}[which])
    refused(trials.validate_locations, args["locations"], args["trials"],
            solver=args["solver"], seed=args["seed"])


# ------------------------------------------------------------------ the one-line rule
def test_a_message_quoting_an_array_is_one_line():
    """FlipkitError folds a multi-line repr (a numpy array's) to one line, and brief() cuts
    a long one."""
    value = np.zeros((3, 3))
    assert "\n" in repr(value)
    assert str(FlipkitError(f"got {value!r}")) == "got " + " ".join(repr(value).split())
    assert "\n" not in brief(value) and len(brief(np.zeros(1000))) <= 80
