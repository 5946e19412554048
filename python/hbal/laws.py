"""Force laws written in Python.

A law is a *vectorised* function ``law(theta, u, du) -> (f, df_du, df_ddu)``: ``theta`` (the
angle of the fundamental, rad), ``u`` and ``du`` (the element coordinate and its rate) are
float64 arrays of one length, and each returned value is an array of that length or one
number for all samples. hbal calls it once per element and AFT pass (and with one sample at a
time in the time-domain reference and the Floquet analysis). A scene uses it as an element
``{"type": "python", "law": "name", "connects": {...}}`` with ``laws={"name": law}``;
``"kinks": [...]`` lists the values of u where the law is not smooth (contact edges), for the
Floquet analysis.

>>> import numpy as np
>>> def duffing(theta, u, du):
...     return u + u**3, 1 + 3 * u**2, 0.0
>>> check_law("duffing", duffing)
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from . import _hbal


def check_law(name: str, law: Callable) -> None:
    """Refuses a law that is not callable or not vectorised: it is called once with three
    samples and must return three values, each an array of three finite numbers or one
    number. A law written for one sample at a time (``math.sin``, ``if u > 0``) fails here,
    with the reason."""
    if not callable(law):
        raise _hbal.LawError(f"laws[{name!r}]: expected a function, got {type(law).__name__}")
    theta = np.array([0.0, 2.0, 4.0])
    u = np.array([0.0, 1e-3, -1e-3])
    du = np.array([0.0, 1e-2, -1e-2])
    try:
        returned = law(theta, u, du)
    except Exception as e:  # the law's own failure, with its type and message
        raise _hbal.LawError(
            f"Python law `{name}` raised on arrays of 3 samples ({type(e).__name__}: {e}); "
            "a law takes numpy arrays theta, u, du and returns (f, df_du, df_ddu) of their length "
            "(use numpy functions such as np.where, np.sin instead of if/math)"
        ) from e
    try:
        parts = list(returned)
    except TypeError:
        parts = []
    if len(parts) != 3:
        raise _hbal.LawError(
            f"Python law `{name}` must return three values (f, df_du, df_ddu), got {type(returned).__name__}"
        )
    if isinstance(returned, dict):
        raise _hbal.LawError(f"Python law `{name}` must return three values (f, df_du, df_ddu), got a dict")
    for what, part in zip(("f", "df_du", "df_ddu"), parts):
        if isinstance(part, np.ma.MaskedArray):
            raise _hbal.LawError(f"Python law `{name}`: {what} is a masked array: return plain values")
        try:
            raw = np.asarray(part)
        except Exception as e:
            raise _hbal.LawError(f"Python law `{name}`: {what} is not an array of numbers ({e})") from e
        if raw.dtype.kind not in "fiu":
            raise _hbal.LawError(f"Python law `{name}`: {what} must hold real numbers, got dtype {raw.dtype}")
        a = raw.astype(float)
        if a.ndim == 0:
            a = np.full(3, float(a))
        if a.shape != (3,):
            raise _hbal.LawError(f"Python law `{name}`: {what} has shape {a.shape} for 3 samples")
        if not np.all(np.isfinite(a)):
            raise _hbal.LawError(f"Python law `{name}`: {what} is not finite at rest: {a}")
