#!/usr/bin/python3
"""Times a cached render through the Python module: the Cornell box at 64x64 and 16 spp, its
program built and its scene uploaded by an untimed first render, then 50 renders from
scene.render to the image, split into the launches (the stats' seconds_render_wall) and the
rest (plan, device set-up, stats, numpy view). docs/PYTHON.md, "Measured".

    PYTHONPATH=build/python bench/cached_render_time.py
"""

import statistics
import time
from pathlib import Path

import mcrt

ROOT = Path(__file__).resolve().parents[1]
scene = mcrt.Context().load(str(ROOT / "scenes" / "cornell" / "CornellBox-Original.gltf"))
scene.render(width=64, height=64, spp=16)  # the variant's first render builds its program
total, wall = [], []
for i in range(50):
    start = time.perf_counter()
    r = scene.render(width=64, height=64, spp=16)
    image = r.image
    total.append(time.perf_counter() - start)
    wall.append(r.stats["seconds_render_wall"])
ms = lambda v: "%.1f ms" % (1e3 * v)
print("scene.render to image: median", ms(statistics.median(total)), "min", ms(min(total)))
print("of which the launches (seconds_render_wall): median", ms(statistics.median(wall)))
print("the rest (plan, setup, stats, numpy): median",
      ms(statistics.median(t - w for t, w in zip(total, wall))))
