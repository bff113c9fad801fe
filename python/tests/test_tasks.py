"""phyxel.tasks.Resection in the Gymnasium convention."""
import numpy as np
import pytest

import phyxel


def test_resection_reset_and_step():
    task = phyxel.tasks.Resection(steps_per_action=5, max_actions=3, threads=1)
    observation, info = task.reset()
    assert observation.shape == task.observation_shape and observation.dtype == np.float64
    np.testing.assert_allclose(observation[:3], [-0.009, 0.0, 0.021])  # the tip, m
    np.testing.assert_allclose(observation[3:6], [0, 0, 1])
    assert observation[9] == 0.0 and info["time"] == 0.0
    for k in range(3):
        observation, reward, terminated, truncated, info = task.step([0.0, 0.0, -1.0])
        assert np.isfinite(reward) and not terminated
        assert truncated == (k == 2)
    # Clipped to max_speed (0.1 m/s) for 3 x 5 steps of 0.24 ms.
    assert observation[2] == pytest.approx(0.021 - 3 * 0.1 * 5 * 2.4e-4, abs=1e-12)
    assert info["time"] == pytest.approx(15 * 2.4e-4)


def test_cutting_beside_and_through_the_tumour_exposes_it():
    task = phyxel.tasks.Resection(steps_per_action=20, max_speed=0.15, threads=1)
    task.reset()
    rewards = []
    # Down into the tissue beside the tumour, 11 mm, then along +x (the edge) through it.
    for action in [(0, 0, -0.15)] * 16 + [(0.15, 0, 0)] * 14:
        observation, reward, terminated, truncated, info = task.step(action)
        rewards.append(reward)
        assert not terminated and not truncated
    assert 0.05 < info["exposure"] < 1
    assert observation[9] == info["exposure"]
    # The rewards add up to the exposure, less the force penalty.
    assert sum(rewards) <= info["exposure"] + 1e-12
    assert sum(rewards) > info["exposure"] - 0.01 * 30 * 0.5
