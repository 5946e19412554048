"""A scene from numpy arrays and scipy.sparse matrices: what an FE program or a notebook
holds, written into the scene schema (docs/scenes.md) and checked by hbal like any file.

>>> import numpy as np, hbal
>>> scene = hbal.scene_from_matrices(
...     dofs=["x"], mass=np.eye(1), damping=np.array([[0.02]]),
...     elements=[{"name": "spring", "type": "cubic_spring", "connects": {"x": 1.0}, "k": 1.0, "alpha": 1.0}],
...     loads=[{"dof": "x", "order": 1, "cos": 0.1}],
...     fundamental={"rad_s": 1.2}, harmonics={"count": 7})
>>> scene.dofs
['x']
"""

from __future__ import annotations

from typing import Any, Callable, Mapping, Sequence

import numpy as np

from . import _hbal
from .scene import Scene

_MATRICES = ("mass", "damping", "stiffness", "hysteretic_damping")


def matrix_entry(name: str, matrix: Any, n: int) -> Any:
    """The scene form of one structural matrix: dense rows for a numpy array (or nested
    lists), 1-based triplets for a scipy.sparse matrix. A wrong shape or dtype, or a
    non-finite entry, is an :class:`hbal.InputError` naming ``name``."""
    if hasattr(matrix, "tocoo") and not isinstance(matrix, np.ndarray):
        coo = matrix.tocoo()
        coo.sum_duplicates()
        _check_shape(name, coo.shape, n)
        bad = np.flatnonzero(~np.isfinite(coo.data)) if np.issubdtype(coo.data.dtype, np.number) else []
        if len(bad):
            i = bad[0]
            raise _hbal.InputError(f"{name}[{coo.row[i]}][{coo.col[i]}]: must be a finite number, got {coo.data[i]}")
        values = _real(name, coo.data)
        rows = (np.asarray(coo.row) + 1).tolist()
        cols = (np.asarray(coo.col) + 1).tolist()
        return {"triplets": [[r, c, v] for r, c, v in zip(rows, cols, values.tolist())]}
    try:
        a = np.asarray(matrix)
    except Exception as e:  # ragged lists
        raise _hbal.InputError(f"{name}: not a matrix ({e})") from e
    if a.ndim != 2:
        raise _hbal.InputError(f"{name}: expected a 2-D matrix of shape ({n}, {n}), got shape {a.shape}")
    _check_shape(name, a.shape, n)
    return _real(name, a).tolist()


def _check_shape(name: str, shape: tuple, n: int) -> None:
    if tuple(shape) != (n, n):
        raise _hbal.InputError(f"{name}: expected shape ({n}, {n}) for {n} DOFs, got {tuple(shape)}")


def _real(name: str, a: np.ndarray) -> np.ndarray:
    if a.dtype == bool or not (np.issubdtype(a.dtype, np.floating) or np.issubdtype(a.dtype, np.integer)):
        raise _hbal.InputError(f"{name}: expected real numbers (float or int), got dtype {a.dtype}")
    a = a.astype(np.float64)
    bad = np.argwhere(~np.isfinite(a))
    if len(bad):
        where = "".join(f"[{int(i)}]" for i in bad[0])
        raise _hbal.InputError(f"{name}{where}: must be a finite number, got {a[tuple(bad[0])]}")
    return a


def scene_from_matrices(
    dofs: Sequence[str],
    mass: Any,
    *,
    damping: Any = None,
    stiffness: Any = None,
    hysteretic_damping: Any = None,
    elements: Sequence[Mapping] = (),
    loads: Sequence[Mapping] = (),
    fundamental: Mapping | None = None,
    harmonics: Mapping | None = None,
    engine: Mapping | None = None,
    solver: Mapping | None = None,
    description: str | None = None,
    laws: Mapping[str, Callable] | None = None,
) -> Scene:
    """A scene from DOF names and structural matrices (numpy arrays or scipy.sparse, SI
    units), with elements, gear stages (``{"type": "gear_stage", ...}``), loads, an engine
    table, the operating point and the solver in the scene schema's own form."""
    if isinstance(dofs, str) or not all(isinstance(d, str) for d in dofs):
        raise _hbal.InputError(f"dofs: expected a list of names (strings), got {dofs!r}")
    names = list(dofs)
    doc: dict[str, Any] = {"dofs": names}
    if description is not None:
        doc["description"] = description
    given = {"mass": mass, "damping": damping, "stiffness": stiffness, "hysteretic_damping": hysteretic_damping}
    for name in _MATRICES:
        if given[name] is not None:
            doc[name] = matrix_entry(name, given[name], len(names))
    for key, items in (("elements", elements), ("loads", loads)):
        if any(not isinstance(x, Mapping) for x in items):
            raise _hbal.InputError(f"{key}: expected a list of dicts (the scene schema's tables), got {list(items)!r}")
        if items:
            doc[key] = [dict(x) for x in items]
    for key, value in (("fundamental", fundamental), ("harmonics", harmonics), ("engine", engine), ("solver", solver)):
        if value is not None:
            if not isinstance(value, Mapping):
                raise _hbal.InputError(f"{key}: expected a dict (the scene schema's table), got {value!r}")
            doc[key] = dict(value)
    return Scene(doc, file="<matrices>", laws=laws)
