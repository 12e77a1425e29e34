"""Parameters the cell knows are planned for (flipkit.config.KNOWN_PARAMETERS): the position
commands of a cell whose controller streams at 500 Hz are made for 500 Hz; what the cell
cannot measure (latency, gains, friction) stays at the model's nominal value."""

from dataclasses import replace

import numpy as np
import pytest

from flipkit.config import (KNOWN_PARAMETERS, PHYSICAL_RANGES, PhysicsConfig, known_physics,
                            with_parameter)
from flipkit.errors import InvalidChoiceError
from flipkit.experiments import trials
from flipkit.experiments.perturbations import Perturbations
from flipkit.experiments.trial_jobs import trial_jobs
from flipkit.model.robot import Robot
from flipkit.planning.plans.servo_command import command_lead
from flipkit.simulation.control import plan_references
from flipkit.simulation.modes import POSITION


def test_known_parameters_are_ranges_of_the_study_and_the_blade_and_servo_rate():
    assert set(KNOWN_PARAMETERS) <= set(PHYSICAL_RANGES)
    assert "physics.servo_rate_hz" in KNOWN_PARAMETERS
    assert "burger.diameter" in KNOWN_PARAMETERS  # the camera that locates a burger sees it
    for unknown in ("burger.mu", "physics.mu_grill", "physics.latency_s",
                    "physics.servo_gain_scale"):
        assert unknown not in KNOWN_PARAMETERS


def test_known_physics_sets_only_what_the_cell_knows():
    ph = PhysicsConfig()
    model = known_physics(ph, {"physics.servo_rate_hz": 500.0, "physics.latency_s": 0.02,
                               "physics.mu_grill": 0.2})
    assert model.servo_rate_hz == 500.0
    assert model.latency_s == ph.latency_s and model.mu_grill == ph.mu_grill
    assert known_physics(ph, {}) is ph
    # a known burger parameter is planned for (PLANNED_PARAMETERS), not a servo's
    assert known_physics(ph, {"burger.diameter": 0.127}) is ph
    with pytest.raises(InvalidChoiceError, match="physical parameter"):
        known_physics(ph, {"physics.nonsense": 1.0})


def test_position_commands_use_the_servo_model_they_are_given(flip_plan):
    plant = replace(flip_plan.cell().physics, servo_rate_hz=500.0)
    robot = Robot(flip_plan.cell(), with_burger=False)
    args = (flip_plan, robot, plant, POSITION, "compensated", 1e-3, 0.0)
    nominal = plan_references(*args)
    known = plan_references(*args, servo=plant)
    assert command_lead(plant) < command_lead(flip_plan.cell().physics)
    assert not np.allclose(nominal.q_cmd, known.q_cmd)
    np.testing.assert_array_equal(nominal.q_des, known.q_des)  # the plan itself is the same
    same = plan_references(*args, servo=flip_plan.cell().physics)
    np.testing.assert_array_equal(same.q_cmd, nominal.q_cmd)


def test_a_trial_commands_with_the_known_servo_rate_and_the_nominal_latency(flip_plan_file,
                                                                            monkeypatch):
    seen = {}

    def fake_execute(plan, mode, draw, **kw):
        seen.update(kw)
        raise RuntimeError("stop here")

    monkeypatch.setattr(trials, "execute_plan", fake_execute)
    text = flip_plan_file.read_text()
    flip_plan = trials.plan_from_text(text)
    job = trial_jobs(text, 1, 0, Perturbations(), mode=POSITION,
                     physics={"physics.servo_rate_hz": 500.0, "physics.latency_s": 0.02})[0]
    with pytest.raises(RuntimeError, match="stop here"):
        trials.run_trial(job)
    nominal = flip_plan.cell().physics
    assert seen["servo"].servo_rate_hz == 500.0 and seen["servo"].latency_s == nominal.latency_s
    plant = with_parameter(with_parameter(flip_plan.cell(), "physics.servo_rate_hz", 500.0),
                           "physics.latency_s", 0.02)
    assert seen["cell"].physics == plant.physics
