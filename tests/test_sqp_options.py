"""SQPOptions: four validated groups whose defaults are the flat settings' of before."""

from dataclasses import fields, replace

import pytest

from flipkit.errors import ConfigError
from flipkit.solvers.sqp_options import (QPOptions, RestorationOptions, SQPOptions,
                                         TerminationOptions, TrustRegionOptions)

# The flat SQPOptions' defaults, by their old name: (group, field, value).
FLAT_DEFAULTS = {
    "tol": ("termination", "tol", 1e-6),
    "ftol": ("termination", "ftol", 1e-3),
    "reject_ftol": ("termination", "reject_ftol", 1e-2),
    "max_iter": ("termination", "max_iter", 100),
    "stall_iterations": ("termination", "stall_iterations", 5),
    "stall_progress": ("termination", "stall_progress", 1e-2),
    "plateau_iterations": ("termination", "plateau_iterations", 4),
    "plateau_ftol": ("termination", "plateau_ftol", 1e-2),
    "trust0": ("trust_region", "radius0", 1.0),
    "trust_min": ("trust_region", "radius_min", 1e-6),
    "trust_max": ("trust_region", "radius_max", 1.0),
    "prox": ("trust_region", "prox", 1e-3),
    "prox_range": ("trust_region", "prox_range", (1e-5, 1.0)),
    "eta": ("trust_region", "eta", 0.1),
    "good_ratio": ("trust_region", "good_ratio", 0.5),
    "backtracks": ("trust_region", "backtracks", 5),
    "rho_min": ("trust_region", "rho_min", 1e-3),
    "restoration_trust": ("restoration", "radius", 4.0),
    "restoration_exit": ("restoration", "exit", 0.3),
    "restoration_prox": ("restoration", "prox", 1e-4),
    "slack_reg": ("restoration", "slack_reg", 1.0),
    "qp_eps": ("qp", "eps", (1e-9, 1e-4)),
    "qp_eps_factor": ("qp", "eps_factor", 0.1),
    "qp_max_iter": ("qp", "max_iter", (2000, 10000, 10000)),
    "condense": ("qp", "condense", True),
}
# Settings added since, with their defaults: (group, field, value).
ADDED = {("trust_region", "second_order_correction", False), ("qp", "quasi_newton", True)}


def test_defaults_are_the_flat_settings_of_before():
    o = SQPOptions()
    leaves = {(g.name, f.name) for g in fields(o) for f in fields(getattr(o, g.name))}
    assert leaves == {(g, f) for g, f, _ in FLAT_DEFAULTS.values()} | {(g, f) for g, f, _ in ADDED}
    for old, (group, name, value) in FLAT_DEFAULTS.items():
        got = getattr(getattr(o, group), name)
        assert got == value and type(got) is type(value), old
    for group, name, value in ADDED:
        assert getattr(getattr(o, group), name) is value


@pytest.mark.parametrize("make, name", [
    (lambda: TerminationOptions(tol=0.0), "termination.tol"),
    (lambda: TerminationOptions(ftol=float("nan")), "termination.ftol"),
    (lambda: TerminationOptions(reject_ftol=-1e-3), "termination.reject_ftol"),
    (lambda: TerminationOptions(plateau_iterations=1), "termination.plateau_iterations"),
    (lambda: TerminationOptions(plateau_ftol=1.0), "termination.plateau_ftol"),
    (lambda: TerminationOptions(stall_iterations=0), "termination.stall_iterations"),
    (lambda: TerminationOptions(stall_progress=-0.1), "termination.stall_progress"),
    (lambda: TerminationOptions(max_iter=0), "termination.max_iter"),
    (lambda: TerminationOptions(max_iter=2.5), "termination.max_iter"),
    (lambda: TrustRegionOptions(radius_min=0.0), "trust_region.radius_min"),
    (lambda: TrustRegionOptions(radius0=2.0), "trust_region.radius0"),
    (lambda: TrustRegionOptions(radius0=1e-7), "trust_region.radius0"),
    (lambda: TrustRegionOptions(prox_range=(0.0, 1.0)), "trust_region.prox_range"),
    (lambda: TrustRegionOptions(prox=2.0), "trust_region.prox"),
    (lambda: TrustRegionOptions(eta=1.0), "trust_region.eta"),
    (lambda: TrustRegionOptions(good_ratio=0.0), "trust_region.good_ratio"),
    (lambda: TrustRegionOptions(backtracks=-1), "trust_region.backtracks"),
    (lambda: TrustRegionOptions(rho_min=0.0), "trust_region.rho_min"),
    (lambda: RestorationOptions(radius=0.0), "restoration.radius"),
    (lambda: RestorationOptions(exit=1.0), "restoration.exit"),
    (lambda: RestorationOptions(prox=0.0), "restoration.prox"),
    (lambda: RestorationOptions(slack_reg=-1.0), "restoration.slack_reg"),
    (lambda: QPOptions(condense="yes"), "qp.condense"),
    (lambda: QPOptions(quasi_newton=1), "qp.quasi_newton"),
    (lambda: TrustRegionOptions(second_order_correction="no"),
     "trust_region.second_order_correction"),
    (lambda: QPOptions(eps=(1e-4, 1e-9)), "qp.eps"),
    (lambda: QPOptions(eps_factor=0.0), "qp.eps_factor"),
    (lambda: QPOptions(max_iter=(2000, 10000)), "qp.max_iter"),
    (lambda: SQPOptions(restoration=RestorationOptions(radius=0.5)), "trust_region.radius_max"),
    (lambda: SQPOptions(termination=QPOptions()), "termination"),
])
def test_an_out_of_range_setting_names_itself_and_its_range(make, name):
    with pytest.raises(ConfigError) as err:
        make()
    message = str(err.value)
    assert message.startswith(f"{name} must be ") and "got" in message and "\n" not in message


def test_groups_are_frozen_and_replaced_whole():
    o = SQPOptions()
    with pytest.raises(AttributeError):
        o.termination.tol = 1.0
    tight = replace(o, termination=replace(o.termination, ftol=1e-4))
    assert tight.termination.ftol == 1e-4 and tight.trust_region == o.trust_region
    with pytest.raises(ConfigError, match="termination.ftol"):
        replace(o.termination, ftol=0.0)
