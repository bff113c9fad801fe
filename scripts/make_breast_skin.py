#!/usr/bin/python3
"""Writes scenes/breast_skin.png, the breast resection's skin texture (procedural, no photo):
mottled skin with faint veins and, at the middle of the image (where the point-based mapping
puts the top of the mound), the areola and nipple. Usage: make_breast_skin.py OUT.png [SIZE]."""
import struct
import sys
import zlib

import numpy as np


def smooth_noise(rng, size, cells):
    """Value noise: a cells x cells grid of random values, bilinearly interpolated."""
    grid = rng.random((cells + 1, cells + 1))
    t = np.linspace(0, cells, size, endpoint=False)
    i = t.astype(int)
    f = t - i
    f = f * f * (3 - 2 * f)
    a = grid[np.ix_(i, i)] * (1 - f)[None, :] + grid[np.ix_(i, i + 1)] * f[None, :]
    b = grid[np.ix_(i + 1, i)] * (1 - f)[None, :] + grid[np.ix_(i + 1, i + 1)] * f[None, :]
    return a * (1 - f)[:, None] + b * f[:, None]


def skin(size):
    rng = np.random.default_rng(7)
    y, x = np.mgrid[0:size, 0:size]
    u = (x + 0.5) / size * 2 - 1
    v = 1 - (y + 0.5) / size * 2
    r = np.hypot(u, v)
    mottle = sum(smooth_noise(rng, size, c) * w for c, w in ((6, 0.5), (24, 0.3), (96, 0.2)))
    base = np.array([0.87, 0.67, 0.57])
    img = base[None, None, :] * (0.92 + 0.16 * mottle[..., None])
    # Faint subcutaneous veins: thin bands along level lines of a smooth noise field.
    field = smooth_noise(rng, size, 5) + 0.5 * smooth_noise(rng, size, 11)
    vein = np.exp(-((np.mod(field * 9, 1.0) - 0.5) ** 2) / 0.0015) * (r > 0.2)
    img = img * (1 - 0.12 * vein[..., None]) + np.array([0.55, 0.6, 0.75]) * 0.12 * vein[..., None]
    # Areola (about 2 cm across the mound's top, r < 0.16 in the mapping) with small glands.
    ring = 0.16 + 0.012 * (smooth_noise(rng, size, 16) - 0.5)
    areola = np.clip((ring - r) / 0.015, 0, 1)
    glands = (smooth_noise(rng, size, 60) > 0.82) * (r > 0.07)
    areola_col = np.array([0.66, 0.42, 0.37]) * (0.9 + 0.15 * mottle[..., None])
    areola_col = areola_col * (1 + 0.12 * glands[..., None])
    img = img * (1 - areola[..., None]) + areola_col * areola[..., None]
    nipple = np.clip((0.045 - r) / 0.01, 0, 1)
    img = img * (1 - nipple[..., None]) + np.array([0.56, 0.33, 0.3]) * nipple[..., None]
    return (np.clip(img, 0, 1) * 255 + 0.5).astype(np.uint8)


def write_png(path, rgb):
    h, w, _ = rgb.shape
    raw = b"".join(b"\x00" + rgb[row].tobytes() for row in range(h))

    def chunk(kind, data):
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(png)


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit("usage: make_breast_skin.py OUT.png [SIZE]")
    write_png(sys.argv[1], skin(int(sys.argv[2]) if len(sys.argv) > 2 else 512))
