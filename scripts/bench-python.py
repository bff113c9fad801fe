#!/usr/bin/env python3
"""advance(N) from Python against `phyxel run --steps N` (its summary.json wall_seconds: the
run loop's time, as advance's), interleaved; the median and the fastest of each
(docs/performance.md, "Python API").

    PYTHONPATH=build/python python3 scripts/bench-python.py [--scene S] [--steps 100] [--runs 7]
"""
import argparse
import json
import pathlib
import statistics
import subprocess
import sys
import tempfile
import time

import phyxel

ROOT = pathlib.Path(__file__).resolve().parent.parent


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", default=str(ROOT / "scenes" / "probe_indent.json"))
    p.add_argument("--steps", type=int, default=100)
    p.add_argument("--runs", type=int, default=7)
    p.add_argument("--device", default="cpu")
    p.add_argument("--threads", type=int, default=0)
    p.add_argument("--phyxel", default=str(ROOT / "build" / "app" / "phyxel"))
    args = p.parse_args(argv)
    cli, py = [], []
    with tempfile.TemporaryDirectory() as out:
        for _ in range(args.runs):
            subprocess.run([args.phyxel, "run", args.scene, "--steps", str(args.steps), "--out",
                            out, "--device", args.device, "--threads", str(args.threads),
                            "--render", "none", "--quiet"], check=True)
            cli.append(json.loads((pathlib.Path(out) / "summary.json").read_text())["wall_seconds"])
            sim = phyxel.Simulation(args.scene, device=args.device, threads=args.threads)
            start = time.perf_counter()
            sim.advance(args.steps)
            py.append(time.perf_counter() - start)
            phyxels = sim.phyxels
    for name, pick in (("median", statistics.median), ("fastest", min)):
        c, q = pick(cli), pick(py)
        print(f"{args.scene}: {phyxels} phyxels, {args.steps} steps on {args.device}, {name} of "
              f"{args.runs}: phyxel run {c * 1e3:.1f} ms, advance {q * 1e3:.1f} ms "
              f"({100 * (q / c - 1):+.1f} %)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
