"""The Simulation class: shapes and units, errors, tools, summary, files."""
import json
import subprocess

import numpy as np
import pytest

import phyxel
from conftest import PHYXEL, ROOT, write_scene


def test_state_arrays_have_their_shapes_and_units(probe_scene):
    sim = phyxel.Simulation(probe_scene, device="cpu", threads=1)
    n = sim.phyxels
    assert n > 100 and sim.steps_done == 0 and sim.time == 0.0
    assert sim.advance(20) == 20
    assert sim.steps_done == 20 and sim.time == pytest.approx(20 * 2.4e-4)
    x, x0, u = sim.positions(), sim.rest_positions(), sim.displacements()
    for a in (x, x0, u, sim.velocities()):
        assert a.shape == (n, 3) and a.dtype == np.float64
    np.testing.assert_array_equal(x, x0 + u)
    assert sim.von_mises().shape == (n,) and np.all(sim.von_mises() >= 0)
    assert sim.masses().shape == (n,) and sim.masses().sum() == pytest.approx(
        1040 * 4 / 3 * np.pi * 0.04 * 0.03 * 0.025, rel=0.15)
    flags = sim.flags()
    assert flags.shape == (n,) and flags.dtype == np.uint32
    assert np.any(flags & phyxel.FIXED) and np.any(flags & phyxel.SURFACE)
    assert not np.any(flags & phyxel.REMOVED)
    # The tissue moves (m): millimetres at most after 20 steps.
    assert 0 < np.abs(u).max() < 5e-3
    assert not x0.flags.writeable


def test_tool_force_and_pose(probe_scene):
    sim = phyxel.Simulation(probe_scene, threads=1)
    assert sim.tools == ["probe"]
    sim.advance(200)
    force = sim.tool_force("probe")
    assert force.shape == (3,)
    assert force[2] > 0.001  # the tissue pushes the probe up (N)
    position, axis = sim.tool_pose("probe")
    z = 0.052 + (0.036 - 0.052) * (200 * 2.4e-4 / 0.1)  # on its path
    np.testing.assert_allclose(position, [0, 0, z], atol=1e-12)
    np.testing.assert_allclose(axis, [0, 0, 1])


def test_set_tool_pose_takes_effect_over_one_step(probe_scene):
    sim = phyxel.Simulation(probe_scene, threads=1)
    sim.advance(10)
    sim.set_tool_pose("probe", position=(0.01, 0.0, 0.06), axis=(0, 0, 1))
    sim.advance(1)
    position, _ = sim.tool_pose("probe")
    np.testing.assert_allclose(position, [0.01, 0.0, 0.06], atol=1e-15)
    sim.advance(50)  # it stays there, off the path that would press it into the tissue
    position, _ = sim.tool_pose("probe")
    np.testing.assert_allclose(position, [0.01, 0.0, 0.06], atol=1e-15)
    np.testing.assert_array_equal(sim.tool_force("probe"), [0, 0, 0])


def test_unknown_tool_and_inclusion_raise_key_error(probe_scene):
    sim = phyxel.Simulation(probe_scene, threads=1)
    with pytest.raises(KeyError, match="no tool named 'scalpel'; the scene has probe"):
        sim.tool_force("scalpel")
    with pytest.raises(KeyError):
        sim.set_tool_pose("scalpel", (0, 0, 0))
    with pytest.raises(KeyError, match="no inclusion named 'tumour'"):
        sim.exposure("tumour")
    with pytest.raises(ValueError):
        sim.set_tool_pose("probe", (0, 0))


def test_bad_scene_raises_scene_error_with_the_command_lines_message(tmp_path, probe_scene):
    probe_scene["objects"][0]["material"]["poisson"] = 0.7
    path = write_scene(tmp_path / "bad.json", probe_scene)
    with pytest.raises(phyxel.SceneError) as error:
        phyxel.Simulation(str(path))
    cli = subprocess.run([str(PHYXEL), "run", str(path), "--out", str(tmp_path / "o")],
                         capture_output=True, text=True)
    assert cli.returncode == 1
    assert str(error.value) == cli.stderr.strip()
    assert "poisson" in str(error.value)
    with pytest.raises(phyxel.SceneError, match="no such file"):
        phyxel.Simulation(str(tmp_path / "missing.json"))
    with pytest.raises(phyxel.SceneError, match="<dict>"):
        phyxel.Simulation(probe_scene)


def test_summary_is_what_summary_json_holds(probe_scene):
    sim = phyxel.Simulation(probe_scene, threads=1)
    sim.advance(30)
    s = sim.summary()
    assert s["steps_done"] == 30 and s["phyxels"] == sim.phyxels
    assert s["tools"][0]["name"] == "probe"
    assert s["max_displacement"] == pytest.approx(np.linalg.norm(sim.displacements(), axis=1).max())
    json.dumps(s)


def test_write_points_writes_a_vtp_file(probe_scene, tmp_path):
    sim = phyxel.Simulation(probe_scene, threads=1)
    sim.advance(5)
    sim.write_points(tmp_path / "p.vtp")
    text = (tmp_path / "p.vtp").read_bytes()
    assert text.startswith(b"<?xml") and b"PolyData" in text
    assert f'NumberOfPoints="{sim.phyxels}"'.encode() in text


def test_a_failing_state_raises_simulation_error(probe_scene):
    # A huge load: the tissue soon moves faster than sound in it, which the checks stop.
    probe_scene["objects"][0]["loads"] = [{
        "region": {"type": "box", "min": [-1, -1, 0.03], "max": [1, 1, 1]},
        "force": [0, 0, -1e6]}]
    del probe_scene["tools"]
    sim = phyxel.Simulation(probe_scene, threads=1)
    with pytest.raises(phyxel.SimulationError, match="unstable|non-finite"):
        sim.advance(400)
    with pytest.raises(phyxel.SimulationError):
        sim.advance(1)


def test_examples_folder_exists():
    assert (ROOT / "examples" / "force_probe.py").exists()


def test_the_gpu_solver_follows_the_cpu_and_renders_from_its_buffers(probe_scene):
    # "gpu": the best Vulkan device, lavapipe on a machine without a GPU.
    gpu = phyxel.Simulation(probe_scene, device="gpu")
    assert "float32" in gpu.device
    cpu = phyxel.Simulation(probe_scene, threads=1)
    gpu.advance(100)
    cpu.advance(100)
    np.testing.assert_allclose(gpu.positions(), cpu.positions(), atol=1e-6)  # m, float32
    np.testing.assert_allclose(gpu.tool_force("probe"), cpu.tool_force("probe"), atol=1e-4)
    assert cpu.tool_force("probe")[2] > 0.01
    frame = gpu.render("mono", 96, 64)
    assert frame.shape == (64, 96, 3) and frame.std() > 1
