#!/usr/bin/python3
"""Writes latitude-longitude HDR environment maps of a simple analytic sun and sky, in the
mapping of DESIGN.md "Environment map" (Mitsuba 3's envmap, +Y up, row 0 at the zenith), as
Radiance .hdr files (run-length RGBE, which stb_image reads):

  sun-sky.hdr    512 x 256: a blue sky brighter toward the horizon (a Rayleigh-like gradient), a
                 grey ground, and a sun of 0.53 degrees at 35 degrees elevation, its texels about
                 10^4 times the sky's radiance
  overcast.hdr   64 x 32: the CIE overcast sky, L(θ) = L_z (1 + 2 cos θ)/3 above the horizon,
                 ground dark

Usage: scripts/scenes/make_sky_maps.py [OUTPUT_DIR]   (default: build/out/sky-maps)
"""
import math
import sys
from pathlib import Path

import numpy as np


def directions(width, height):
    """Unit direction at each texel centre: u = atan2(x, -z)/2π, v = acos(y)/π."""
    u = (np.arange(width) + 0.5) / width
    v = (np.arange(height) + 0.5) / height
    phi, theta = np.meshgrid(2 * math.pi * u, math.pi * v)
    s = np.sin(theta)
    return s * np.sin(phi), np.cos(theta), -s * np.cos(phi)


def sun_sky(width=512, height=256, elevation_deg=35.0, azimuth_deg=60.0):
    x, y, z = directions(width, height)
    above = y > 0
    # Sky: brighter and whiter toward the horizon; ground: dim grey.
    zenith = np.array([0.25, 0.45, 1.0])
    horizon = np.array([0.9, 0.95, 1.0])
    t = np.clip(1.0 - y, 0.0, 1.0)[..., None] ** 3
    rgb = np.where(above[..., None], (1 - t) * zenith + t * horizon, np.array([0.15, 0.14, 0.12]))
    # Sun: a disk of 0.53° whose texels (about 0.7° wide here) each carry ~10^4 × the sky.
    el, az = math.radians(elevation_deg), math.radians(azimuth_deg)
    sun = np.array([math.cos(el) * math.sin(az), math.sin(el), -math.cos(el) * math.cos(az)])
    cos_to_sun = x * sun[0] + y * sun[1] + z * sun[2]
    texel = math.pi / height
    near = cos_to_sun > math.cos(max(math.radians(0.265), 0.75 * texel))
    if not near.any():
        near.flat[np.argmax(cos_to_sun)] = True
    rgb[near] = np.array([1.0, 0.95, 0.85]) * 1.0e4
    return rgb


def overcast(width=64, height=32):
    _, y, _ = directions(width, height)
    L = np.where(y > 0, (1 + 2 * y) / 3, 0.05)
    return np.repeat(L[..., None], 3, axis=2)


def to_rgbe(rgb):
    """Ward's RGBE: a shared exponent, mantissas in bytes (Graphics Gems II, "Real Pixels")."""
    m = rgb.max(axis=2)
    out = np.zeros(rgb.shape[:2] + (4,), dtype=np.uint8)
    ok = m > 1e-32
    mant, exp = np.frexp(m[ok])
    scale = mant * 256.0 / m[ok]
    out[ok, :3] = np.clip(rgb[ok] * scale[:, None], 0, 255).astype(np.uint8)
    out[ok, 3] = (exp + 128).astype(np.uint8)
    return out


def write_hdr(path, rgb):
    """Radiance .hdr, each scanline run-length encoded with literal runs only."""
    height, width, _ = rgb.shape
    assert 8 <= width < 32768
    rgbe = to_rgbe(rgb)
    with open(path, "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n")
        f.write(f"-Y {height} +X {width}\n".encode())
        for row in rgbe:
            f.write(bytes([2, 2, width >> 8, width & 255]))
            for c in range(4):
                channel = row[:, c].tobytes()
                for start in range(0, width, 128):
                    chunk = channel[start:start + 128]
                    f.write(bytes([len(chunk)]) + chunk)


def main():
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).resolve().parents[2] / "build/out/sky-maps"
    out.mkdir(parents=True, exist_ok=True)
    for name, rgb in (("sun-sky.hdr", sun_sky()), ("overcast.hdr", overcast())):
        write_hdr(out / name, rgb)
        print(out / name)


if __name__ == "__main__":
    main()
