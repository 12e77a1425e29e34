"""Configuration: defaults with their sources, validation, and the sourced physics."""

from importlib import resources

import numpy as np
import pytest

from flipkit.config import (TABLE1_LOCATIONS, BurgerConfig, CellConfig, GrillConfig, RobotConfig,
                            SpatulaConfig, TaskLimits)
from flipkit.errors import ConfigError, FlipkitError
from flipkit.model.ik import solve_pose
from flipkit.model.orientation import rpy
from flipkit.model.robot import Robot


def test_q_home_puts_the_spatula_flat_above_the_grill():
    r = Robot()
    np.testing.assert_allclose(r.position(r.q_home), [0.62, -0.20, 0.30], atol=1e-4)
    np.testing.assert_allclose(rpy(r.rotation(r.q_home)), 0, atol=1e-4)
    assert np.all(r.q_home > r.q_min) and np.all(r.q_home < r.q_max)


def test_grill_contains_table1_and_csv_matches():
    g = GrillConfig()
    assert all(g.contains(p) for p in TABLE1_LOCATIONS)
    assert all(abs(p[2] - g.height) <= 0.0011 for p in TABLE1_LOCATIONS)
    text = resources.files("flipkit").joinpath("data", "paper_table1.csv").read_text()
    rows = [line for line in text.splitlines() if line and not line.startswith("#")][1:]
    csv = np.array([[float(v) for v in row.split(",")[:3]] for row in rows])
    np.testing.assert_array_equal(csv, np.array(TABLE1_LOCATIONS))


def test_table1_locations_are_reachable_scoop_ready():
    r = Robot()
    for p in TABLE1_LOCATIONS:
        q = solve_pose(r, p, (0.0, 0.314, 0.0))
        np.testing.assert_allclose(r.position(q), p, atol=1e-4)
        np.testing.assert_allclose(rpy(r.rotation(q)), (0.0, 0.314, 0.0), atol=1e-4)
        assert np.all(q >= r.q_min) and np.all(q <= r.q_max)


@pytest.mark.parametrize("make, match", [
    (lambda: BurgerConfig(mu=-0.1), "mu"),
    (lambda: BurgerConfig(diameter=float("nan")), "diameter"),
    (lambda: SpatulaConfig(length=0), "length"),
    (lambda: GrillConfig(x_range=(0.9, 0.6)), "lower bound"),
    (lambda: TaskLimits(p_min=(0, 0)), "shape"),
    (lambda: RobotConfig(urdf="/nonexistent.urdf"), "not found"),
    (lambda: RobotConfig(base_in_world=np.eye(4) * 2), "rigid"),
    (lambda: CellConfig(gravity=(0, 0, float("inf"))), "finite"),
])
def test_validation(make, match):
    with pytest.raises(ConfigError, match=match):
        make()
    assert issubclass(ConfigError, FlipkitError)


def test_configs_are_frozen():
    with pytest.raises(AttributeError):
        BurgerConfig().mu = 1.0


def test_tool_frame_must_exist():
    with pytest.raises(ConfigError, match="tool0"):
        Robot(CellConfig(robot=RobotConfig(tool_frame="flange")))


def test_blade_stiffness_is_the_cantilever_formula():
    from flipkit.config import PHYSICAL_RANGES, with_parameter

    cell = CellConfig()
    ph, sp = cell.physics, cell.spatula
    k = ph.blade_stiffness(sp)
    inertia = sp.width * ph.blade_thickness**3 / 12
    assert k == pytest.approx(3 * ph.blade_modulus * inertia / sp.length**3)
    assert k == pytest.approx(1413.6, rel=1e-3)  # 1 mm × 12 cm × 16 cm stainless blade
    assert ph.blade_damping(sp) == pytest.approx(2 * np.sqrt(k * ph.blade_tip_mass))
    thin = with_parameter(cell, "physics.blade_thickness", 0.00045)
    assert thin.physics.blade_stiffness(sp) == pytest.approx(k * 0.45**3)
    for name in ("physics.blade_modulus", "physics.blade_dampratio", "physics.blade_tip_mass"):
        lo, hi, source = PHYSICAL_RANGES[name]
        assert lo < hi and source
    assert "physics.steel_timeconst" not in PHYSICAL_RANGES
