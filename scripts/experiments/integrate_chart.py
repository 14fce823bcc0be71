#!/usr/bin/python3
"""Convergence chart of `mcrt integrate` (∫ cosθ dω = π with uniform, cosine and Fibonacci
directions): log-log |error| and rmse against N, a reference N^-1/2 slope, and the fitted
log-log slopes printed on stdout.

    scripts/experiments/integrate_chart.py                      # runs build/mcrt integrate, writes the PNG
    scripts/experiments/integrate_chart.py --csv integrate.csv  # reads a CSV written by `mcrt integrate`
"""
import argparse
import csv
import io
import math
import os
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tools"))  # mcrt_run, mcrt_exr
import mcrt_run  # noqa: E402

mcrt_run.require("numpy", "matplotlib")
import numpy as np  # noqa: E402

ROOT = str(mcrt_run.ROOT)
FLOOR = 1e-9  # the cosine estimator's error is float rounding (~1e-7) or exactly 0: plotted at max(·, FLOOR)
STYLE = {"uniform": "tab:blue", "cosine": "tab:green", "fibonacci": "tab:red"}


def read_rows(text):
    rows = {}
    for r in csv.DictReader(io.StringIO(text)):
        rows.setdefault(r["estimator"], []).append(
            (int(r["n"]), float(r["error"]), float(r["std_error"]), float(r["rmse"])))
    return {e: np.array(sorted(v)) for e, v in rows.items()}


def fitted_slope(n, y, n_min):
    """Least-squares slope of log y against log n over n >= n_min (points with y > 0)."""
    keep = (n >= n_min) & (y > 0)
    if keep.sum() < 2:
        return float("nan")
    return float(np.polyfit(np.log(n[keep]), np.log(y[keep]), 1)[0])


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--csv", help="read this CSV instead of running mcrt")
    mcrt_run.add_mcrt_option(parser)
    parser.add_argument("--repeats", type=int, default=32, help="--repeats passed to mcrt integrate")
    parser.add_argument("--seed", type=int, default=0, help="--seed passed to mcrt integrate")
    parser.add_argument("--save-csv", help="also keep the CSV that mcrt wrote here")
    parser.add_argument("--fit-min", type=int, default=100, help="fit slopes over N >= this")
    parser.add_argument("--out", default=os.path.join(ROOT, "docs", "figures", "integrate.png"))
    args = parser.parse_args()

    if args.csv:
        try:
            with open(args.csv) as f:
                text = f.read()
        except OSError as e:
            raise mcrt_run.ScriptError("cannot read %s: %s" % (args.csv, e.strerror))
    else:
        cmd = [mcrt_run.mcrt_binary(args.mcrt), "integrate", "--repeats", str(args.repeats),
               "--seed", str(args.seed)]
        print("running:", " ".join(cmd), file=sys.stderr)
        text = mcrt_run.run(cmd).stdout
        if args.save_csv:
            with open(args.save_csv, "w") as f:
                f.write(text)
    try:
        data = read_rows(text)
    except (KeyError, ValueError) as e:
        raise mcrt_run.ScriptError("not a CSV of `mcrt integrate`: %s" % e)
    if not data:
        raise mcrt_run.ScriptError("no rows in the CSV of `mcrt integrate`")

    plt = mcrt_run.pyplot()
    fig, ax = plt.subplots(figsize=(10, 5.5), dpi=100)
    print(f"fitted log-log slopes over N >= {args.fit_min}:")
    for estimator, rows in data.items():
        n, error, rmse = rows[:, 0], np.abs(rows[:, 1]), rows[:, 3]
        color = STYLE.get(estimator, None)
        slope_rmse = fitted_slope(n, rmse, args.fit_min)
        slope_error = fitted_slope(n, error, args.fit_min)
        print(f"  {estimator:10s} rmse {slope_rmse:+.3f}   |error| (repeat 0) {slope_error:+.3f}")
        label = f"{estimator}: rmse (slope {slope_rmse:+.2f})"
        if estimator == "cosine":
            label = f"cosine: rmse, float rounding floor (plotted as max(·, {FLOOR:g}))"
        ax.loglog(n, np.maximum(rmse, FLOOR), "o-", color=color, ms=4, label=label)
        ax.loglog(n, np.maximum(error, FLOOR), "x:", color=color, ms=5, alpha=0.6,
                  label=f"{estimator}: |error| of one run")

    all_n = np.unique(np.concatenate([rows[:, 0] for rows in data.values()]))
    sigma = 2 * math.pi / math.sqrt(12)  # standard deviation of 2π·cosθ under uniform directions
    ax.loglog(all_n, sigma * all_n ** -0.5, "k--", lw=1, label=r"reference $N^{-1/2}$ ($2\pi/\sqrt{12N}$)")
    ax.loglog(all_n, sigma * all_n ** -1.0, "k-.", lw=1, alpha=0.5, label=r"reference $N^{-1}$ ($2\pi/(\sqrt{12}N)$)")
    ax.set_xlabel("N (directions per estimate)")
    ax.set_ylabel(r"error of the estimate of $\int_\Omega \cos\theta\, d\omega = \pi$")
    ax.set_title("mcrt integrate: uniform, cosine and Fibonacci directions")
    ax.grid(True, which="major", alpha=0.3)
    ax.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0), borderaxespad=0)
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    fig.savefig(args.out, dpi=100)
    print(f"wrote {args.out} ({os.path.getsize(args.out) // 1024} KiB)")


if __name__ == "__main__":
    sys.exit(mcrt_run.script_main(main))
