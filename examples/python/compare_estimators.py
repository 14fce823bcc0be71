#!/usr/bin/python3
"""Error against render time for four estimators on the Cornell box, in one process: the scene
is loaded once and every render reuses it (docs/PYTHON.md).

    PYTHONPATH=build/python examples/python/compare_estimators.py [out.png]
"""
import sys
from pathlib import Path

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import mcrt  # noqa: E402

scene = mcrt.Context().load(str(Path(__file__).resolve().parents[2] / "scenes" / "cornell" /
                                "CornellBox-Original.gltf"))
view = dict(width=64, height=64, max_depth=1, seed=1)
reference = scene.render(estimator="mis", spp=8192, sampler="sobol", **view).image
for estimator in ["light-area", "light-solid-angle", "bsdf", "mis"]:
    seconds, rmse = [], []
    for spp in [4, 16, 64, 256]:
        r = scene.render(estimator=estimator, spp=spp, **{**view, "seed": spp})
        seconds.append(r.stats["seconds_render"])
        rmse.append(np.sqrt(np.mean((r.image - reference) ** 2)))
    plt.loglog(seconds, rmse, "o-", label=estimator)
plt.xlabel("device seconds")
plt.ylabel("RMSE against 8192 spp of mis")
plt.legend()
plt.savefig(sys.argv[1] if len(sys.argv) > 1 else "compare_estimators.png", dpi=100)
