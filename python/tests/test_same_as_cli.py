"""Item 2 of the Python API: the same numbers as `phyxel run`, bit for bit on the CPU; and a
checkpoint resumed from Python matches the run that went on."""
import json
import subprocess

import numpy as np
import pytest

import phyxel
from conftest import PHYXEL, write_scene


def cli_run(scene_path, out, steps, *extra):
    subprocess.run([str(PHYXEL), "run", str(scene_path), "--out", str(out), "--steps",
                    str(steps), "--threads", "1", "--quiet", *extra], check=True)
    return json.loads((out / "summary.json").read_text())


@pytest.mark.parametrize("steps", [137, 200])
def test_positions_and_tool_forces_match_phyxel_run_bit_for_bit(tmp_path, probe_scene, steps):
    path = write_scene(tmp_path / "probe.json", probe_scene)
    summary = cli_run(path, tmp_path / "cli", steps)
    sim = phyxel.Simulation(str(path), device="cpu", threads=1)
    assert sim.advance(steps) == steps
    # The points file of the same state is the same file, byte for byte.
    sim.write_points(tmp_path / "py.vtp")
    cli_points = (tmp_path / "cli" / f"points_{steps:06d}.vtp").read_bytes()
    assert (tmp_path / "py.vtp").read_bytes() == cli_points
    mine = sim.summary()
    assert mine["tools"] == summary["tools"]  # last_force, max_force, contacts ... exactly
    assert summary["tools"][0]["max_force"] > 0
    for key in ("kinetic_energy", "strain_energy", "max_displacement", "steps_done"):
        assert mine[key] == summary[key], key
    np.testing.assert_array_equal(sim.tool_force("probe"), summary["tools"][0]["force"])


def test_a_checkpoint_resumed_from_python_matches_the_uninterrupted_run(tmp_path, probe_scene):
    path = write_scene(tmp_path / "probe.json", probe_scene)
    whole = phyxel.Simulation(str(path), threads=1)
    whole.advance(60)
    whole.save_checkpoint(tmp_path / "at60.phx")
    whole.advance(90)
    resumed = phyxel.Simulation.resume(str(path), tmp_path / "at60.phx", threads=1)
    assert resumed.steps_done == 60
    resumed.advance(90)
    np.testing.assert_array_equal(resumed.positions(), whole.positions())
    np.testing.assert_array_equal(resumed.velocities(), whole.velocities())
    np.testing.assert_array_equal(resumed.tool_force("probe"), whole.tool_force("probe"))


def test_python_resumes_a_checkpoint_of_phyxel_run(tmp_path, probe_scene):
    path = write_scene(tmp_path / "probe.json", probe_scene)
    cli_run(path, tmp_path / "a", 100, "--checkpoint-every", "100")
    full = cli_run(path, tmp_path / "b", 100)
    sim = phyxel.Simulation.resume(str(path), tmp_path / "a" / "checkpoint.phx", threads=1)
    assert sim.steps_done == 100
    assert sim.summary()["max_displacement"] == full["max_displacement"]


def test_a_checkpoint_of_another_scene_is_refused(tmp_path, probe_scene):
    path = write_scene(tmp_path / "probe.json", probe_scene)
    sim = phyxel.Simulation(str(path), threads=1)
    sim.advance(5)
    sim.save_checkpoint(tmp_path / "c.phx")
    probe_scene["simulation"]["steps"] = 300
    other = write_scene(tmp_path / "other.json", probe_scene)
    with pytest.raises(phyxel.CheckpointError, match="c.phx"):
        phyxel.Simulation.resume(str(other), tmp_path / "c.phx")
