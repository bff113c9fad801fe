"""Shared fixtures of the Python module's tests (run by ctest as python_pytest)."""
import copy
import json
import os
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
BINARY = pathlib.Path(os.environ.get("PHYXEL_BINARY_DIR", ROOT / "build"))
PHYXEL = BINARY / "app" / "phyxel"

# A small probe scene (a coarse brain, the probe pressing into it from about step 80): quick
# on one thread.
PROBE_SCENE = {
    "simulation": {"dt": 2.4e-4, "steps": 200, "gravity": [0, 0, -9.81]},
    "objects": [{
        "name": "brain",
        "shape": {"type": "ellipsoid", "center": [0, 0, 0.025], "radii": [0.04, 0.03, 0.025]},
        "spacing": 0.006,
        "material": {"young": 3000, "poisson": 0.45, "density": 1040, "damping": 20},
        "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [1, 1, 0.0095]}],
    }],
    "tools": [{
        "name": "probe",
        "type": "probe",
        "shape": {"type": "capsule", "radius": 0.004, "length": 0.04},
        "path": [
            {"t": 0.0, "position": [0.0, 0.0, 0.052], "axis": [0, 0, 1]},
            {"t": 0.1, "position": [0.0, 0.0, 0.036], "axis": [0, 0, 1]},
        ],
        "friction": 0.2,
    }],
    "output": {"every": 0, "format": "binary"},
    "camera": {"position": [0.05, -0.075, 0.095], "target": [0.0, -0.006, 0.035]},
}


@pytest.fixture
def probe_scene():
    return copy.deepcopy(PROBE_SCENE)


@pytest.fixture
def out_dir(tmp_path):
    return tmp_path


def write_scene(path, scene):
    path.write_text(json.dumps(scene))
    return path
