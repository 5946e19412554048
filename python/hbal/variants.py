"""Variants of a scene for a study: each variant is a dict ``{path: value}`` of scene fields
(``elements[0].k``, ``fundamental.rpm``, ``loads[1].cos``; the paths of
:meth:`hbal.Scene.with_parameter`).

>>> from hbal import variants as v
>>> len(v.grid({"elements[0].k": [0.9, 1.0, 1.1], "damping[0][0]": [0.01, 0.02]}))
6
>>> rows = v.latin_hypercube({"elements[0].k": v.Uniform(0.9, 1.1)}, 4, seed=1)
>>> sorted(int((r["elements[0].k"] - 0.9) / 0.05) for r in rows)
[0, 1, 2, 3]
"""

from __future__ import annotations

import itertools
import re
from dataclasses import dataclass
from statistics import NormalDist
from typing import Any, Mapping, Sequence

import numpy as np


@dataclass(frozen=True)
class Uniform:
    """Uniform on ``[low, high]``."""

    low: float
    high: float

    def ppf(self, u: np.ndarray) -> np.ndarray:
        return self.low + u * (self.high - self.low)


@dataclass(frozen=True)
class Normal:
    """Normal with ``mean`` and ``std``, optionally cut to ``[low, high]`` (a tolerance band:
    the probability beyond it is put on its ends)."""

    mean: float
    std: float
    low: float = -np.inf
    high: float = np.inf

    def ppf(self, u: np.ndarray) -> np.ndarray:
        d = NormalDist(self.mean, self.std)
        # Open interval: 0 and 1 have no quantile.
        x = np.array([d.inv_cdf(min(max(p, 1e-12), 1 - 1e-12)) for p in np.ravel(u)])
        return np.clip(x, self.low, self.high).reshape(np.shape(u))


def _check(dists: Mapping[str, Any]) -> None:
    for path, d in dists.items():
        if not hasattr(d, "ppf"):
            raise TypeError(f"{path}: expected hbal.variants.Uniform or Normal (or anything with ppf), got {type(d).__name__}")


def grid(axes: Mapping[str, Sequence[float]]) -> list[dict]:
    """Every combination of the values of each path (the first path varies slowest)."""
    paths = list(axes)
    return [dict(zip(paths, map(float, values))) for values in itertools.product(*(axes[p] for p in paths))]


def latin_hypercube(dists: Mapping[str, Any], n: int, *, seed: int | None = None) -> list[dict]:
    """``n`` variants by Latin hypercube sampling: each path's range split into ``n`` strata of
    equal probability, one sample in each, strata paired at random."""
    _check(dists)
    rng = np.random.default_rng(seed)
    columns = {}
    for path, d in dists.items():
        u = (rng.permutation(n) + rng.random(n)) / n
        columns[path] = d.ppf(u)
    return [{p: float(columns[p][i]) for p in dists} for i in range(n)]


def monte_carlo(dists: Mapping[str, Any], n: int, *, seed: int | None = None) -> list[dict]:
    """``n`` independent random variants."""
    _check(dists)
    rng = np.random.default_rng(seed)
    columns = {path: d.ppf(rng.random(n)) for path, d in dists.items()}
    return [{p: float(columns[p][i]) for p in dists} for i in range(n)]


def value_at(document: Mapping, path: str) -> float:
    """The number at ``path`` in a scene document (``elements[0].k``)."""
    cur: Any = document
    for part in path.split("."):
        m = re.fullmatch(r"([^\[\]]*)((?:\[\d+\])*)", part)
        if m is None:
            raise KeyError(f"`{path}`: cannot read `{part}`")
        key, indices = m.groups()
        if key:
            if not isinstance(cur, Mapping) or key not in cur:
                raise KeyError(f"`{path}`: no field `{key}`")
            cur = cur[key]
        for i in map(int, re.findall(r"\[(\d+)\]", indices)):
            if not isinstance(cur, list) or i >= len(cur):
                raise KeyError(f"`{path}`: no entry [{i}]")
            cur = cur[i]
    if isinstance(cur, bool) or not isinstance(cur, (int, float)):
        raise KeyError(f"`{path}` is not a number in the scene")
    return float(cur)


def around(scene, spreads: Mapping[str, float], *, kind: str = "uniform") -> dict:
    """Distributions of relative tolerances about the scene's own values: ``{path: 0.1}`` is
    ±10 % (``kind="uniform"``), or a normal with that as its 3σ, cut there (``"normal"``)."""
    doc = scene.to_dict()
    out = {}
    for path, spread in spreads.items():
        x = value_at(doc, path)
        lo, hi = sorted((x * (1 - spread), x * (1 + spread)))
        out[path] = Uniform(lo, hi) if kind == "uniform" else Normal(x, abs(x) * spread / 3, lo, hi)
    return out
