"""Frames into numpy (Vulkan: the GPU, or lavapipe on the CPU)."""
import numpy as np

import phyxel


def test_mono_and_stereo_frames(probe_scene):
    sim = phyxel.Simulation(probe_scene, threads=1)
    sim.advance(10)
    frame = sim.render("mono", width=96, height=64)
    assert frame.shape == (64, 96, 3) and frame.dtype == np.uint8
    assert frame.std() > 1  # the tissue and the probe, not a blank image
    left, right = sim.render(mode="stereo", width=80, height=48)
    assert left.shape == right.shape == (48, 80, 3)
    assert np.any(left != right)  # two eyes, two views
    again = sim.render("mono", width=96, height=64)
    np.testing.assert_array_equal(frame, again)  # the same state draws the same frame
