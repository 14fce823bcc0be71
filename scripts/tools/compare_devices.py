#!/usr/bin/python3
"""Compares two renders of the same request made on different devices (a GPU against PoCL, say):
how many pixels are the same bits, and whether the images agree within their own noise.

    scripts/tools/compare_devices.py A.exr B.exr [more pairs ...]

For each pair: the share of bitwise-equal pixels (all three channels), the relative difference
of the image means with its standard error (each pixel's mean has its own samples, so the
pixels' differences are independent and the variance layers add), and the spread of the
per-pixel z-scores (difference / sqrt(var_A + var_B)): a mean near 0 and a standard deviation
near 1 say the two devices estimate the same image; where both use the same random numbers
the z-scores are far below 1.
"""

import sys

import numpy as np

from mcrt_exr import read_exr


def load(path):
    channels = read_exr(path)
    image = np.stack([channels[c] for c in "RGB"], axis=-1).astype(np.float64)
    variance = np.stack([channels["variance." + c] for c in "RGB"], axis=-1).astype(np.float64)
    return image, variance


def compare(a_path, b_path):
    a, va = load(a_path)
    b, vb = load(b_path)
    if a.shape != b.shape:
        return "%s vs %s: shapes %s and %s differ" % (a_path, b_path, a.shape, b.shape)
    same = np.all(a.astype(np.float32) == b.astype(np.float32), axis=-1).mean()
    difference = b - a
    mean_a = a.mean()
    relative = difference.mean() / mean_a
    standard_error = np.sqrt((va + vb).sum()) / a.size / mean_a
    spread = np.sqrt(va + vb)
    usable = spread > 0
    z = difference[usable] / spread[usable]
    return ("%s: bitwise-equal pixels %.4f%%, mean %.6g vs %.6g, relative difference %+.4f%% "
            "± %.4f%% (%.2f standard errors), per-pixel z mean %+.3f sd %.3f, max |difference| %.3g"
            % (a_path.split("/")[-1], 100 * same, mean_a, b.mean(), 100 * relative,
               100 * standard_error, relative / standard_error if standard_error else 0,
               z.mean(), z.std(), np.abs(difference).max()))


def main(argv):
    if len(argv) < 2 or len(argv) % 2:
        print(__doc__.strip(), file=sys.stderr)
        return 2
    for i in range(0, len(argv), 2):
        print(compare(argv[i], argv[i + 1]))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
