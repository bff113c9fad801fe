#!/usr/bin/env python3
"""A scripted resection: a scalpel, its blade across the tissue, is moved step by step
through a block of tissue fixed at its base, slicing its top off; then reports the mass the
cut freed (Simulation.resection).

    PYTHONPATH=build/python python3 examples/scripted_resection.py
"""
import argparse
import sys

import numpy as np

import phyxel


def scene(spacing):
    """A block of tissue 40 x 20 x 20 mm fixed at its base, and a scalpel beside it whose shaft
    (and 40 mm blade, its edge along +x) spans the block's width."""
    return {
        "simulation": {"dt": 2.4e-4, "steps": 1, "gravity": [0, 0, -9.81]},
        "objects": [{
            "name": "tissue",
            "shape": {"type": "box", "min": [-0.02, -0.01, 0.0], "max": [0.02, 0.01, 0.02]},
            "spacing": spacing,
            "material": {"young": 5000, "poisson": 0.45, "density": 1040, "damping": 20},
            "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [1, 1, 0.0015]}],
        }],
        "tools": [{
            "name": "scalpel",
            "type": "scalpel",
            "shape": {"type": "capsule", "radius": 0.0004, "length": 0.05},
            "blade": {"length": 0.04, "edge": [1, 0, 0]},
            "cut_force_threshold": 0.0,
            "path": [{"t": 0.0, "position": [-0.026, -0.02, 0.012], "axis": [0, 1, 0]}],
            "friction": 0.2,
        }],
    }


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--spacing", type=float, default=0.0025, help="tissue spacing, m")
    p.add_argument("--speed", type=float, default=0.2, help="scalpel speed, m/s")
    p.add_argument("--device", default="cpu")
    args = p.parse_args(argv)

    sim = phyxel.Simulation(scene(args.spacing), device=args.device)
    position, axis = sim.tool_pose("scalpel")
    end_x = 0.026
    step = args.speed * sim.dt  # m per step
    while position[0] < end_x:
        position = position + np.array([min(step, end_x - position[0]), 0.0, 0.0])
        sim.set_tool_pose("scalpel", position, axis)
        sim.advance(1)
    sim.advance(200)  # the freed piece settles

    cut = sim.resection()
    summary = sim.summary()
    total = float(np.sum(sim.masses()))
    print(f"{sim.steps_done} steps ({sim.time:.3f} s): the cut freed {cut['pieces']} piece(s), "
          f"{cut['freed_mass'] * 1e3:.2f} g of {total * 1e3:.2f} g; the scalpel cut for "
          f"{summary['tools'][0]['cutting_substeps']} substeps")
    return 0 if cut["freed_mass"] > 0 else 1


if __name__ == "__main__":
    sys.exit(main())
