#!/usr/bin/env python3
"""A force-controlled probe: it holds a force (0.1 N) on the tissue by moving along its axis
from the force it measures, instead of following a path.

    PYTHONPATH=build/python python3 examples/force_probe.py [--spacing 0.004]
"""
import argparse
import sys

import numpy as np

import phyxel


def scene(spacing, radius):
    """A slab of brain-like tissue 60 x 60 x 20 mm fixed at its base, a round-tipped probe
    (its tip `radius` wide) 5 mm above its middle, shaft up."""
    return {
        "simulation": {"dt": 2.4e-4, "steps": 1, "gravity": [0, 0, -9.81]},
        "objects": [{
            "name": "tissue",
            "shape": {"type": "box", "min": [-0.03, -0.03, 0.0], "max": [0.03, 0.03, 0.02]},
            "spacing": spacing,
            "material": {"young": 3000, "poisson": 0.45, "density": 1040, "damping": 20},
            "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [1, 1, 0.0015]}],
        }],
        "tools": [{
            "name": "probe",
            "type": "probe",
            "shape": {"type": "capsule", "radius": radius, "length": 0.04},
            "path": [{"t": 0.0, "position": [0.0, 0.0, 0.025 + radius], "axis": [0, 0, 1]}],
            "friction": 0.2,
        }],
    }


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--target", type=float, default=0.1, help="force to hold, N")
    p.add_argument("--steps", type=int, default=2500)
    p.add_argument("--spacing", type=float, default=0.003, help="tissue spacing, m")
    p.add_argument("--radius", type=float, default=0.008, help="probe tip radius, m")
    p.add_argument("--device", default="cpu")
    args = p.parse_args(argv)

    sim = phyxel.Simulation(scene(args.spacing, args.radius), device=args.device)
    position, axis = sim.tool_pose("probe")  # the centre of the rounded tip, and up the shaft
    every = 5                               # steps per control update
    gain = 5e-4                             # m of travel per N of force error per update
    max_move = 0.05 * every * sim.dt        # at most 5 cm/s
    history = []
    for _ in range(args.steps // every):
        sim.advance(every)
        # The tissue pushes the probe back up its axis: the force along +axis.
        force = float(np.dot(sim.tool_force("probe"), axis))
        history.append(force)
        # Too little force: press on, down the axis; too much: back off.
        move = float(np.clip(gain * (args.target - force), -max_move, max_move))
        position = position - axis * move
        sim.set_tool_pose("probe", position, axis)

    held = np.array(history[-len(history) // 5:])
    depth = 0.02 - (position[2] - args.radius)
    print(f"{sim.steps_done} steps ({sim.time:.3f} s): the probe holds {held.mean():.4f} N "
          f"(target {args.target} N, the last fifth of the run; spread {held.std():.4f} N), "
          f"{depth * 1e3:.2f} mm into the tissue")
    return 0 if abs(held.mean() - args.target) <= 0.1 * args.target else 1


if __name__ == "__main__":
    sys.exit(main())
