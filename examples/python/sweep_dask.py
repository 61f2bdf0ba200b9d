#!/usr/bin/env python3
"""A parameter sweep of a stochastic L-system on a Dask cluster.

Runs the stochastic bush of ``bush.lsys`` (beside this file; any L-system
with ``#define``d parameters will do) over many seeds and values of its
parameters on ``dask.distributed``, gathers per-run statistics (module
counts, the bounding box of the drawing, branch counts) into a pandas
DataFrame, and plots a histogram.

By default it starts a ``LocalCluster`` on this machine; give a scheduler's
address to run on a real cluster (every worker needs ``pip install`` of this
package and the model file at the same path, or pass ``--model`` a path that
the workers see)::

    python examples/python/sweep_dask.py                       # LocalCluster
    python examples/python/sweep_dask.py --workers 8 --seeds 500
    python examples/python/sweep_dask.py tcp://scheduler:8786  # a running cluster
    python examples/python/sweep_dask.py --out sweep.csv --plot sweep.png

A run is one task: the model is loaded and derived on the worker (the GIL is
released while subgram works, so threads of a worker run in parallel too),
and only its statistics (a dict of numbers) come back.
"""

from __future__ import annotations

import argparse
import itertools
import os
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
MODEL = HERE / "bush.lsys"


def run_one(model: str, seed: int, p_branch: float, angle: float) -> dict:
    """One run of the model: its statistics as plain numbers."""
    import numpy as np

    import subgram

    system = subgram.load(model, seed=seed, defines={"P_BRANCH": p_branch, "ANGLE": angle})
    t = time.perf_counter()
    word = system.derive()
    derive_s = time.perf_counter() - t
    counts = word.counts()
    ids = word.symbol_ids
    alphabet = word.alphabet
    # Branches: each `SB` opens one; the apices still growing are the `A`s
    # with vigour above the threshold (their parameter, as numpy).
    apex = word.params("A")[:, 0] if "A" in counts else np.zeros(0)
    bounds = system.bounds()
    lo, hi = bounds if bounds is not None else (np.zeros(3), np.zeros(3))
    return {
        "seed": seed,
        "p_branch": p_branch,
        "angle": angle,
        "modules": len(word),
        "branches": int(np.count_nonzero(ids == alphabet.index("SB"))) if "SB" in alphabet else 0,
        "internodes": counts.get("I", 0),
        "live_apices": int(np.count_nonzero(apex >= 0.05)),
        "width": float(hi[0] - lo[0]),
        "height": float(hi[1] - lo[1]),
        "derive_s": derive_s,
    }


def sweep(client, model: str, seeds: int, p_values, angles) -> "pandas.DataFrame":
    import pandas as pd

    jobs = list(itertools.product(range(1, seeds + 1), p_values, angles))
    futures = [
        client.submit(run_one, model, seed, p, a, pure=False) for seed, p, a in jobs
    ]
    rows = client.gather(futures)
    return pd.DataFrame(rows).sort_values(["p_branch", "angle", "seed"], ignore_index=True)


def plot(df, path: str) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(10, 4))
    for p, group in df.groupby("p_branch"):
        axes[0].hist(group["branches"], bins=20, alpha=0.6, label=f"P_BRANCH={p}")
        axes[1].hist(group["height"], bins=20, alpha=0.6, label=f"P_BRANCH={p}")
    axes[0].set_xlabel("branches")
    axes[1].set_xlabel("height of the drawing")
    for ax in axes:
        ax.set_ylabel("runs")
        ax.legend()
    fig.suptitle(f"{len(df)} runs of the stochastic bush")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scheduler", nargs="?", help="a Dask scheduler's address (default: a LocalCluster)")
    ap.add_argument("--model", default=str(MODEL), help="the .lsys file (a path the workers see)")
    ap.add_argument("--seeds", type=int, default=100, help="seeds per parameter pair (default 100)")
    ap.add_argument("--p-branch", type=float, nargs="+", default=[0.5, 0.6, 0.7])
    ap.add_argument("--angle", type=float, nargs="+", default=[20.0, 30.0])
    ap.add_argument("--workers", type=int, default=2, help="LocalCluster: worker processes (default 2)")
    ap.add_argument("--threads", type=int, default=1, help="LocalCluster: threads per worker (default 1)")
    ap.add_argument("--out", help="write the DataFrame here (.csv)")
    ap.add_argument("--plot", help="write the histogram here (.png)")
    args = ap.parse_args(argv)

    from dask.distributed import Client, LocalCluster

    cluster = None
    if args.scheduler:
        client = Client(args.scheduler)
    else:
        cluster = LocalCluster(
            n_workers=args.workers,
            threads_per_worker=args.threads,
            processes=True,
            dashboard_address=None,
        )
        client = Client(cluster)
    try:
        t = time.perf_counter()
        df = sweep(client, os.path.abspath(args.model), args.seeds, args.p_branch, args.angle)
        took = time.perf_counter() - t
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    summary = df.groupby(["p_branch", "angle"])[["modules", "branches", "height", "width"]].mean()
    print(f"{len(df)} runs in {took:.1f} s")
    print(summary.round(2).to_string())
    if args.out:
        df.to_csv(args.out, index=False)
    if args.plot:
        plot(df, args.plot)
    return 0


if __name__ == "__main__":
    sys.exit(main())
