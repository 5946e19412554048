"""The analyses, with the command line's options (``hbal solve``, ``sweep``, ``modes``,
``compare``): each runs in the Rust library with the GIL released and returns a result
object. Bad input raises :class:`hbal.InputError` (a ``ValueError``) before any work; a
failure after the input was checked raises :class:`hbal.NumericalError`; a marked result
(not converged, a branch that stopped) is returned with ``exit_code == 1``.

Option names are the command line's, with ``_`` for ``-``; ``--from`` is ``start`` (``from``
is a Python keyword) and ``--start FILE`` is ``guess=`` (a previous solve's result).
``out=DIR`` writes the files of ``--out DIR`` (CSV tables and SVG plots): the directory is
checked before any work; a plot that cannot be drawn is a ``RuntimeWarning``.
"""

from __future__ import annotations

import os
from typing import Callable, Sequence

import numpy as np

from . import _hbal
from .results import (
    CompareResult,
    ModesResult,
    ParameterSweepResult,
    SolveResult,
    SweepResult,
    TorusSolveResult,
    TorusSweepResult,
)
from .scene import Scene


def _flag(name: str, value) -> bool:
    if not isinstance(value, (bool, np.bool_)):
        raise _hbal.InputError(f"{name}: expected True or False, got {value!r}")
    return bool(value)


def _count(name: str, value, *, optional: bool = True):
    """A whole number >= 0 (None where ``optional``), for the options the Rust side takes
    as unsigned."""
    if value is None and optional:
        return None
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, (int, np.integer)):
        raise _hbal.InputError(f"{name}: expected a whole number, got {value!r}")
    if not 0 <= int(value) < 2**63:
        raise _hbal.InputError(f"{name}: must be a whole number >= 0, got {value}")
    return int(value)


def _callback(name: str, value):
    if value is not None and not callable(value):
        raise _hbal.InputError(f"{name}: expected a function, got {type(value).__name__}")
    return value


def _names(name: str, value):
    """A comma-separated string of names from a string or a sequence of strings."""
    if value is None or isinstance(value, str):
        return value
    items = list(value)
    if not all(isinstance(x, str) for x in items):
        raise _hbal.InputError(f"{name}: expected names (strings), got {items!r}")
    return ",".join(items)


def _out(value):
    """``out=``: a directory path (str or path-like) or None."""
    if value is None:
        return None
    if not (isinstance(value, (str, bytes)) or hasattr(value, "__fspath__")):
        raise _hbal.InputError(f"out: expected a directory path, got {type(value).__name__}")
    try:
        path = os.fsdecode(value)
    except (UnicodeDecodeError, TypeError) as e:
        raise _hbal.InputError(f"out: not a usable path: {e}") from None
    if not path:
        raise _hbal.InputError("out: an empty path (give a directory, e.g. '.')")
    if "\0" in path:
        raise _hbal.InputError("out: the path contains a NUL character")
    return path


def _scene(scene) -> Scene:
    if isinstance(scene, Scene):
        return scene
    if isinstance(scene, dict):
        return Scene.from_dict(scene)
    if isinstance(scene, str) or hasattr(scene, "__fspath__"):
        return Scene.load(scene)
    raise TypeError(f"scene: expected an hbal.Scene, a dict or a path, got {type(scene).__name__}")


def solve(
    scene,
    *,
    method: str | None = None,
    harmonics: int | str | None = None,
    samples: int | None = None,
    tolerance: float | None = None,
    formulation: str | None = None,
    stability: bool = True,
    fallback: bool = True,
    guess: SolveResult | dict | None = None,
    out: str | os.PathLike | None = None,
) -> SolveResult | TorusSolveResult:
    """One periodic solution with its error estimate, Floquet stability and element outputs
    (``hbal solve``). ``harmonics`` is H or ``"auto"``, ``"auto:harmonics"``, ...;
    ``stability=False`` is ``--no-stability``, ``fallback=False`` ``--no-fallback``,
    ``guess`` (a previous solve's result or record) ``--start``."""
    s = _scene(scene)
    record, code, seconds = _hbal.solve(
        s._handle,
        method=method,
        harmonics=harmonics,
        samples=_count("samples", samples),
        tolerance=tolerance,
        formulation=formulation,
        stability=_flag("stability", stability),
        fallback=_flag("fallback", fallback),
        guess=guess,
        out=_out(out),
    )
    return (TorusSolveResult if s.on_torus else SolveResult)(record, code, seconds)


def sweep(
    scene,
    to: float,
    *,
    start: float | None = None,
    harmonics: int | str | None = None,
    samples: int | None = None,
    tolerance: float | None = None,
    formulation: str | None = None,
    stability: bool = True,
    stability_orbit: str = "exact",
    max_points: int | None = None,
    max_step: float = 0.5,
    points: int = 101,
    all_branches: bool = False,
    error_estimate: bool = True,
    output: str | None = None,
    dofs: str | Sequence[str] | None = None,
    progress: Callable[[float, str], None] | None = None,
    guess: SolveResult | dict | None = None,
    out: str | os.PathLike | None = None,
) -> SweepResult | TorusSweepResult:
    """The response over speed from ``start`` (default the scene's speed) to ``to``, in the
    scene's unit, through turning points, with stability (``hbal sweep``).
    ``progress(fraction, stage)`` is called along the way; Ctrl-C stops the sweep and raises
    ``KeyboardInterrupt``. ``guess`` (a solve's result or record) is ``--start``: the branch
    starts from it, at its speed unless ``start`` is given."""
    s = _scene(scene)
    record, code, seconds = _hbal.sweep(
        s._handle,
        float(to),
        start=None if start is None else float(start),
        harmonics=harmonics,
        samples=_count("samples", samples),
        tolerance=tolerance,
        formulation=formulation,
        stability=_flag("stability", stability),
        stability_orbit=stability_orbit,
        max_points=_count("max_points", max_points),
        max_step=max_step,
        points=_count("points", points, optional=False),
        all_branches=_flag("all_branches", all_branches),
        error_estimate=_flag("error_estimate", error_estimate),
        output=output,
        dofs=_names("dofs", dofs),
        progress=_callback("progress", progress),
        guess=guess,
        out=_out(out),
    )
    return (TorusSweepResult if s.on_torus else SweepResult)(record, code, seconds)


def parameter_sweep(
    scene,
    parameter: str,
    start: float,
    to: float,
    *,
    points: int = 101,
    harmonics: int | str | None = None,
    samples: int | None = None,
    formulation: str | None = None,
    stability: bool = True,
    dofs: str | Sequence[str] | None = None,
    progress: Callable[[float, str], None] | None = None,
    out: str | os.PathLike | None = None,
) -> ParameterSweepResult:
    """The response over one numeric scene field (``hbal sweep --parameter``), e.g.
    ``elements[0].k``, at ``points`` evenly spaced values."""
    s = _scene(scene)
    record, code, seconds = _hbal.parameter_sweep(
        s._handle,
        parameter,
        float(start),
        float(to),
        points=_count("points", points, optional=False),
        harmonics=harmonics,
        samples=_count("samples", samples),
        formulation=formulation,
        stability=_flag("stability", stability),
        dofs=_names("dofs", dofs),
        progress=_callback("progress", progress),
        out=_out(out),
    )
    return ParameterSweepResult(record, code, seconds)


def modes(
    scene,
    *,
    start: float | None = None,
    to: float | None = None,
    max_hz: float | None = None,
    formulation: str | None = None,
    out: str | os.PathLike | None = None,
) -> ModesResult:
    """Natural frequencies and mode shapes about the periodic solution and the critical
    speeds between ``start`` and ``to`` (``hbal modes``)."""
    s = _scene(scene)
    record, code, seconds = _hbal.modes(
        s._handle, start=start, to=to, max_hz=max_hz, formulation=formulation, out=_out(out)
    )
    return ModesResult(record, code, seconds)


def compare(
    scene,
    *,
    methods: Sequence[str] | None = None,
    harmonics: int | str | None = None,
    samples: int | None = None,
    tolerance: float | None = None,
    formulation: str | None = None,
    out: str | os.PathLike | None = None,
) -> CompareResult:
    """Every solver (or ``methods``) and the time-domain reference, with their errors
    (``hbal compare``)."""
    s = _scene(scene)
    if isinstance(methods, str):
        methods = [methods]
    record, code, seconds = _hbal.compare(
        s._handle,
        methods=None if methods is None else list(methods),
        harmonics=harmonics,
        samples=_count("samples", samples),
        tolerance=tolerance,
        formulation=formulation,
        out=_out(out),
    )
    return CompareResult(record, code, seconds)
