"""A constraint term is one module: its numeric rows, its symbolic form and its independent
check, registered together (:mod:`flipkit.transcription.constraints.registry`)."""

import ast
import importlib

import numpy as np
import pytest

from flipkit.import_graph import PACKAGE, flipkit_imports, module_name, package_files
from flipkit.planning.plans.verify_checks import CHECKS
from flipkit.planning.plans.verify_report import GROUPS
from flipkit.transcription.constraints.base import Block
from flipkit.transcription.constraints.quantities import Quantity
from flipkit.transcription.constraints.registry import (BLOCK_TERMS, QUANTITY_TERMS, Check,
                                                        Registry, checked_groups)

# every module that may define a term: defining the class registers it
for path in package_files():
    name = module_name(path)
    if name.startswith(("flipkit.transcription", "flipkit.behaviors")):
        importlib.import_module(name)


def package_terms(registry):
    """The terms the package defines (test modules define their own)."""
    return [cls for cls in registry if cls.__module__.startswith("flipkit.")]


def test_every_term_of_the_package_has_its_three_parts():
    blocks, quantities = package_terms(BLOCK_TERMS), package_terms(QUANTITY_TERMS)
    assert len(blocks) == 13 and len(quantities) == 14
    assert BLOCK_TERMS.problems(blocks) == []
    assert QUANTITY_TERMS.problems(quantities) == []


def test_a_term_lacking_a_part_is_reported():
    """Terms planted in a registry of their own: each missing part is named."""
    local = Registry("constraint block", "evaluate", checked=True)

    class NoSymbolic(Block, registry=local):
        check = Check(("dynamics",))

        def evaluate(self, ev):
            return np.zeros(0), np.zeros(0)

    class NoCheck(Block, registry=local):
        no_symbolic_form = "planted"

        def evaluate(self, ev):
            return np.zeros(0), np.zeros(0)

    class NoRows(Block, registry=local):
        check = Check(none="planted")

        def symbolic(self, acc):
            return []

    class BothStated(NoSymbolic, registry=local):  # groups and a reason for none: not stated
        check = Check(("dynamics",), none="planted")

    class Complete(NoSymbolic, registry=local):
        no_symbolic_form = "planted"

    assert list(local) == [NoSymbolic, NoCheck, NoRows, BothStated, Complete]
    assert local.missing(NoSymbolic) == ["symbolic"]
    assert local.missing(NoCheck) == ["check"]
    assert local.missing(NoRows) == ["numeric"]
    assert local.missing(BothStated) == ["symbolic", "check"]
    assert local.missing(Complete) == []
    problems = local.problems()
    assert len(problems) == 4 and "NoSymbolic lacks symbolic" in problems[0]
    assert NoSymbolic not in BLOCK_TERMS.terms  # the planted terms stay out of the package's

    quantities = Registry("spatula quantity", "__call__", checked=False)

    class Bare(Quantity, registry=quantities):
        def __call__(self, st, ctx):
            return st.p, st.dp_dq

    assert quantities.problems() == [f"spatula quantity {__name__}."
                                     "test_a_term_lacking_a_part_is_reported.<locals>.Bare "
                                     "lacks symbolic"]


def test_every_named_group_has_an_independent_check_in_verify():
    """A group a block names is one of the report's and is filled by an entry of verify's
    table of checks; the table fills every group but the plan-wide completeness."""
    named = checked_groups()
    filled = {g for check in CHECKS for g in check.groups}
    assert set(named) <= filled
    assert filled | {"completeness"} == set(GROUPS)
    assert {"dynamics", "defects", "interpolant", "arm_clearance", "landing",
            "flight_clearance"} <= set(named)


def test_the_independent_checks_import_no_constraint_code():
    """verify's check modules never reach the rows: no import of the constraint blocks, the
    NLP or the symbolic forms."""
    rows = ("flipkit.transcription.constraints", "flipkit.transcription.nlp",
            "flipkit.transcription.symbolic_blocks", "flipkit.transcription.ocp_graph")
    checks = sorted((PACKAGE / "planning" / "plans").glob("verify*.py"))
    assert len(checks) >= 5
    for path in checks:
        bad = [i.target for i in flipkit_imports(path) if i.target.startswith(rows)]
        assert bad == [], f"{path.name} imports {bad}"


def test_the_symbolic_builder_dispatches_without_isinstance():
    tree = ast.parse((PACKAGE / "transcription" / "symbolic_blocks.py").read_text())
    calls = [n for n in ast.walk(tree) if isinstance(n, ast.Call)
             and getattr(n.func, "id", None) in ("isinstance", "type")]
    assert calls == []


@pytest.mark.parametrize("name", ["position", "height", "rpy", "pitch", "normal", "xaxis",
                                  "tip_height", "blade_heights", "velocity", "acceleration",
                                  "physical", "paper"])
def test_a_quantitys_symbolic_form_is_its_numeric_value(robot, cell, name):
    """At a random state the SX value equals the pinocchio one (every quantity that has a
    form, the two cone forms included)."""
    import casadi as ca

    from flipkit.model.casadi_dynamics import CasadiArm
    from flipkit.model.contact import make_cone
    from flipkit.transcription.constraints.quantities import QUANTITIES, Cone

    quantity = (Cone(make_cone(name, cell.burger.mu, cell.gravity)) if name in ("physical", "paper")
                else QUANTITIES[name]())
    ctx = {"length": cell.spatula.length, "width": cell.spatula.width}
    rng = np.random.default_rng(5)
    q, qd, qdd = (rng.uniform(-1.0, 1.0, robot.nq) for _ in range(3))
    sym = ca.SX.sym("x", 3 * robot.nq)
    parts = (sym[:robot.nq], sym[robot.nq:2 * robot.nq], sym[2 * robot.nq:])
    value = ca.Function("v", [sym], [quantity.symbolic(CasadiArm(robot).frame(*parts), ctx)])
    numeric = quantity(robot.state(q, qd, qdd), ctx)[0]
    np.testing.assert_allclose(np.asarray(value(np.concatenate([q, qd, qdd]))).ravel(),
                               np.ravel(numeric), atol=1e-9)
