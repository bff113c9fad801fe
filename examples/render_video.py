#!/usr/bin/env python3
"""Frames into numpy, written as an MP4: renders the simulation every few steps into (H, W, 3)
uint8 arrays and encodes them with phyxel.VideoWriter (H.264, the encoder of phyxel run
--video).

    PYTHONPATH=build/python python3 examples/render_video.py --out out/probe.mp4
"""
import argparse
import json
import pathlib
import sys

import phyxel

ROOT = pathlib.Path(__file__).resolve().parent.parent


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scene", default=str(ROOT / "scenes" / "probe_indent.json"))
    p.add_argument("--out", default="out/python_video.mp4")
    p.add_argument("--frames", type=int, default=60)
    p.add_argument("--every", type=int, default=40, help="steps between frames")
    p.add_argument("--width", type=int, default=640)
    p.add_argument("--height", type=int, default=360)
    p.add_argument("--spacing", type=float, help="a coarser tissue, m (quicker)")
    p.add_argument("--device", default="cpu")
    args = p.parse_args(argv)

    scene = json.loads(pathlib.Path(args.scene).read_text())
    if args.spacing:
        for o in scene["objects"]:
            o["spacing"] = args.spacing
    sim = phyxel.Simulation(scene, device=args.device)
    out = pathlib.Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    fps = 1.0 / (args.every * sim.dt)  # simulated time's rate
    brightest = 0
    with phyxel.VideoWriter(out, args.width, args.height, fps) as video:
        for _ in range(args.frames):
            frame = sim.render("mono", args.width, args.height)  # (H, W, 3) uint8
            brightest = max(brightest, int(frame.max()))
            video.write(frame)
            sim.advance(args.every)
        frames = video.frames
    print(f"wrote {frames} frames of {args.width} x {args.height} at {fps:.1f} frames/s to {out}")
    return 0 if frames == args.frames and brightest > 0 else 1


if __name__ == "__main__":
    sys.exit(main())
