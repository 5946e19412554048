"""Percentile bands over a study: how an order's amplitude spreads across the variants, speed
by speed, and a plot of them.

Where the variants were solved at common speeds the percentiles are taken at those speeds;
a study of sweeps (each branch with its own points) is interpolated onto ``speeds`` first
(each variant's points in the order of speed; a branch that folds is taken as its points
sorted by speed).
"""

from __future__ import annotations

from typing import Sequence

import numpy as np


def percentile_bands(table, quantity: str, order: float, *, percentiles: Sequence[float] = (5, 50, 95), speeds=None):
    """A DataFrame indexed by speed with one column per percentile (``p5``, ``p50``, ...) of
    the amplitude of ``order`` of ``quantity`` over the variants that have it (failed rows
    are left out; ``count`` says how many variants each speed has)."""
    import pandas as pd

    ok = table[(table["status"] == "ok") & (table["quantity"] == quantity)]
    ok = ok[np.isclose(ok["order"].to_numpy(dtype=float), order, rtol=1e-9, atol=1e-12)]
    if ok.empty:
        raise KeyError(f"no rows of {quantity} at order {order}")
    if speeds is None:
        grouped = ok.groupby("speed")["amplitude"]
        frame = pd.DataFrame({f"p{p:g}": grouped.quantile(p / 100) for p in percentiles})
        frame["count"] = grouped.size()
        return frame
    speeds = np.asarray(speeds, dtype=float)
    curves = []
    for _, v in ok.groupby("variant"):
        v = v.sort_values("speed")
        x, y = v["speed"].to_numpy(), v["amplitude"].to_numpy()
        inside = (speeds >= x[0]) & (speeds <= x[-1])
        curves.append(np.where(inside, np.interp(speeds, x, y), np.nan))
    stack = np.array(curves)
    frame = pd.DataFrame({f"p{p:g}": np.nanpercentile(stack, p, axis=0) for p in percentiles}, index=pd.Index(speeds, name="speed"))
    frame["count"] = np.sum(np.isfinite(stack), axis=0)
    return frame


def plot_bands(table, quantity: str, orders: Sequence[float], path, *, percentiles=(5, 50, 95), speeds=None, unit: str = ""):
    """Writes a plot of the percentile bands of each order of ``quantity`` to ``path`` (SVG or
    PNG by its extension; needs matplotlib): the outer percentiles as a band, the middle one
    as a line."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(8, 4.5))
    lo, mid, hi = (f"p{p:g}" for p in (percentiles[0], percentiles[len(percentiles) // 2], percentiles[-1]))
    for order in orders:
        b = percentile_bands(table, quantity, order, percentiles=percentiles, speeds=speeds)
        line = ax.plot(b.index, b[mid], label=f"order {order:g} ({mid})")[0]
        ax.fill_between(b.index, b[lo], b[hi], color=line.get_color(), alpha=0.25, label=f"{lo}–{hi}")
    ax.set_xlabel(f"speed ({unit})" if unit else "speed")
    ax.set_ylabel(f"amplitude of {quantity}")
    ax.set_yscale("log")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
