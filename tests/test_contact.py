"""Contact forces on hand-worked cases."""

import numpy as np
import pytest

from flipkit.model.contact import make_cone, specific_force
from flipkit.errors import InvalidChoiceError
from flipkit.model.orientation import rpy_matrix
from flipkit.model.robot import SpatulaState

G = (0.0, 0.0, -9.81)


def still(R, a=(0, 0, 0)):
    z = np.zeros((3, 6))
    return SpatulaState(p=np.zeros(3), R=np.asarray(R), v=np.zeros(3), a=np.asarray(a, float),
                        dp_dq=z, Jw=z, dv_dq=z, dv_dqd=z, da_dq=z, da_dqd=z, da_dqdd=z)


def test_flat_still_spatula_carries_the_weight():
    f = specific_force(np.eye(3), np.zeros(3), G)
    np.testing.assert_allclose(f, [0, 0, 9.81])  # F_n/m = g, no tangential force
    for form in ("physical", "paper"):
        assert make_cone(form, 0.5, G).margin(still(np.eye(3))) > 0


def test_tilt_past_friction_angle_violates_physical_cone():
    mu = 0.5
    cone = make_cone("physical", mu, G)
    ok = still(rpy_matrix([0, np.arctan(mu) - 0.02, 0]))
    bad = still(rpy_matrix([0, np.arctan(mu) + 0.02, 0]))
    assert cone.margin(ok) > 0 > cone.margin(bad)
    roll = still(rpy_matrix([np.arctan(mu) + 0.02, 0, 0]))  # across the blade too
    assert cone.margin(roll) < 0


def test_paper_cone_uses_mu_as_an_angle():
    mu = 0.5
    cone = make_cone("paper", mu, G)
    assert cone.margin(still(rpy_matrix([0, mu - 0.01, 0]))) > 0
    assert cone.margin(still(rpy_matrix([0, mu + 0.01, 0]))) < 0


def test_horizontal_acceleration_limit_is_mu_g():
    mu, g = 0.5, 9.81
    cone = make_cone("physical", mu, G)
    assert cone.margin(still(np.eye(3), (0.95 * mu * g, 0, 0))) > 0
    assert cone.margin(still(np.eye(3), (1.05 * mu * g, 0, 0))) < 0
    assert cone.margin(still(np.eye(3), (0, 0, -1.01 * g))) < 0  # spatula drops faster than g


def test_unknown_cone_lists_choices():
    with pytest.raises(InvalidChoiceError, match="'physical', 'paper'"):
        make_cone("cosine", 0.5)
