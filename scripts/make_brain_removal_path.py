#!/usr/bin/python3
"""Writes a variant of scenes/brain_tumour_removal.json whose aspirator works through the whole
glioma as a surgeon debulks it: down the middle, then layer by layer from the top, a ring at
each depth `inset` inside the tumour's margin, the shaft pivoting about a point above the
opening; the brain farther than `box` from the tumour's axis, or below `zfix`, is held (the
far field barely moves and costs nothing). docs/suction.md ("Not yet") says what it gave.
Usage: make_brain_removal_path.py --out FILE.json [--spacing S --dt DT ...]. Write FILE.json
into scenes/ (the render keys name files relative to it). The shipped scene is the defaults;
scenes/demo.json (the README's demo: the first layer, 3 mm, mono) is
  --spacing 0.003 --dt 2.5e-4 --every 400 --layers 1 --mode mono --size 960x540 --no_video
  --points_at_end --out scenes/demo.json"""
import argparse
import json
import math
import sys
ap = argparse.ArgumentParser()
ap.add_argument('--spacing', type=float, default=0.002)
ap.add_argument('--dt', type=float, default=1.6e-4)
ap.add_argument('--pressure', type=float, default=25000)
ap.add_argument('--reach', type=float, default=0.004)
ap.add_argument('--inset', type=float, default=0.002)
ap.add_argument('--dz', type=float, default=0.0025)
ap.add_argument('--ztop', type=float, default=0.048)
ap.add_argument('--zbot', type=float, default=0.0365)
ap.add_argument('--chord', type=float, default=0.003)
ap.add_argument('--speed', type=float, default=0.025)
ap.add_argument('--pivot', type=float, default=0.062)
ap.add_argument('--box', type=float, default=0.022)
ap.add_argument('--zfix', type=float, default=0.025)
ap.add_argument('--brain_tear', type=float, default=2500)
ap.add_argument('--glioma_tear', type=float, default=900)
ap.add_argument('--every', type=int, default=208)
ap.add_argument('--layers', type=int, default=0, help='stop after this many layers (0: all)')
ap.add_argument('--mode', default=None, help='render mode (default: the base scene\'s)')
ap.add_argument('--size', default=None, help='frame size WxH (default: the base scene\'s)')
ap.add_argument('--points_at_end', action='store_true', help='write the points (.vtp) at the end')
ap.add_argument('--no_video', action='store_true', help='drop the video texture')
ap.add_argument('--base', default='scenes/brain_tumour_removal.json')
ap.add_argument('--out', required=True)
a = ap.parse_args()
C = (0.0, 0.0, 0.0435); R = 0.0075
keys = []; t = 0.0
def axis_for(p):
    if math.hypot(p[0], p[1]) < 1e-9: return [0.0, 0.0, 1.0]
    d = [0 - p[0], 0 - p[1], a.pivot - p[2]]
    n = math.sqrt(sum(x * x for x in d))
    return [round(x / n, 5) for x in d]
def add(p, dt=None):
    global t
    if keys:
        d = math.dist(p, keys[-1]['position'])
        t += dt if dt is not None else max(d / a.speed, 0.03)
    keys.append({'t': round(t, 4), 'position': [round(x, 6) for x in p], 'axis': axis_for(p)})
def ring(rr, z, start):
    n = max(3, int(math.ceil(2 * math.pi * rr / a.chord)))
    for k in range(n + 1):
        ang = start + 2 * math.pi * k / n
        add((rr * math.cos(ang), rr * math.sin(ang), z))
add((0.0, 0.0, 0.0555))
z = a.ztop; layer = 0
while z >= a.zbot - 1e-9 and (a.layers == 0 or layer < a.layers):
    add((0.0, 0.0, z))
    rmax = math.sqrt(max(R * R - (z - C[2]) ** 2, 0.0)) - a.inset
    if rmax > 0.001:
        add((rmax, 0.0, z)) if layer % 2 == 0 else add((-rmax, 0.0, z))
        ring(rmax, z, 0.0 if layer % 2 == 0 else math.pi)
        add((0.0, 0.0, z))
    z -= a.dz; layer += 1
add((0.0, 0.0, 0.062), 0.4)
T = t
src = json.load(open(a.base))
steps = int(round(T / a.dt)); steps -= steps % a.every
scene = {
  "simulation": {"dt": a.dt, "steps": steps, "gravity": [0, 0, -9.81], "courant": 0.5},
  "objects": [{
    "name": "brain",
    "shape": {"type": "ellipsoid", "center": [0, 0, 0.02], "radii": [0.04, 0.032, 0.03]},
    "spacing": a.spacing,
    "material": {"young": 3000, "poisson": 0.45, "density": 1040, "damping": 30, "tear_stress": a.brain_tear},
    "mirror": 0.1,
    "inclusions": [{"name": "glioma", "shape": {"type": "sphere", "center": list(C), "radius": R},
                    "material": {"young": 6000, "poisson": 0.45, "density": 1040, "tear_stress": a.glioma_tear},
                    "mirror": 0.6}],
    "fixed": [{"type": "box", "min": [-1, -1, -1], "max": [1, 1, a.zfix]},
              {"type": "box", "min": [-1, -1, -1], "max": [-a.box, 1, 1]},
              {"type": "box", "min": [a.box, -1, -1], "max": [1, 1, 1]},
              {"type": "box", "min": [-1, -1, -1], "max": [1, -a.box, 1]},
              {"type": "box", "min": [-1, a.box, -1], "max": [1, 1, 1]}]}],
  "tools": [{"name": "aspirator", "type": "suction",
             "shape": {"type": "capsule", "radius": 0.0015, "length": 0.08},
             "suction": {"pressure": a.pressure, "reach": a.reach, "from": keys[1]['t'] * 0.5},
             "friction": 0.1, "path": keys}],
  "camera": src['camera'],
  "render": src['render'],
  "output": {"every": 0, "format": "binary"}}
scene['render']['every'] = a.every
if a.mode: scene['render']['mode'] = a.mode
if a.size: scene['render']['width'], scene['render']['height'] = map(int, a.size.split('x'))
if a.points_at_end: scene['output']['every'] = steps
if a.no_video: scene['render'].pop('video_texture', None)
json.dump(scene, open(a.out, 'w'), indent=1)
print(f"{len(keys)} keys, {T:.2f} s, {steps} steps", file=sys.stderr)
