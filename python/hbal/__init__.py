"""hbal: harmonic balance for powertrains, from Python.

The periodic steady state of gear meshes with time-varying stiffness, backlash contacts,
springs and force laws of your own, computed in the frequency domain by the Rust library
``hbal``, with an error estimate and the Floquet stability of every answer.

>>> import hbal
>>> scene = hbal.Scene.load("examples/scenes/duffing.toml")   # doctest: +SKIP
>>> result = hbal.solve(scene)                                  # doctest: +SKIP
>>> result.converged, result.stable, abs(result.harmonics[0, 1])  # doctest: +SKIP

- :class:`Scene`: from a file, a string, a dict or matrices (:func:`scene_from_matrices`);
  Python force laws (:mod:`hbal.laws`).
- :func:`solve`, :func:`sweep`, :func:`parameter_sweep`, :func:`modes`, :func:`compare`:
  the command line's analyses, returning result objects (:mod:`hbal.results`), with
  ``out=DIR`` their files; :func:`report` the HTML report.
- :mod:`hbal.study` and :mod:`hbal.variants`: many variants through any executor (a process
  pool, Dask), one tidy table written to Parquet as it goes, resumable;
  :func:`percentile_bands` and :func:`plot_bands` over it.
- Errors: :class:`InputError` (bad input, a ``ValueError``), :class:`SceneError` (names
  the field), :class:`LawError` (a Python law), :class:`NumericalError` (a failure after
  the input was checked, a ``RuntimeError``).
"""

from ._hbal import (
    SCHEMA_VERSION,
    InputError,
    LawError,
    NumericalError,
    SceneError,
    __version__,
)
from . import study, variants
from .analyses import compare, modes, parameter_sweep, solve, sweep
from .bands import percentile_bands, plot_bands
from .laws import check_law
from .model import scene_from_matrices
from .report import ReportResult, report
from .results import (
    CompareResult,
    ModesResult,
    ParameterSweepResult,
    Result,
    SolveResult,
    SweepResult,
    TorusSolveResult,
    TorusSweepResult,
)
from .scene import Scene

__all__ = [
    "SCHEMA_VERSION",
    "CompareResult",
    "InputError",
    "LawError",
    "ModesResult",
    "NumericalError",
    "ParameterSweepResult",
    "ReportResult",
    "Result",
    "Scene",
    "SceneError",
    "SolveResult",
    "SweepResult",
    "TorusSolveResult",
    "TorusSweepResult",
    "__version__",
    "check_law",
    "compare",
    "modes",
    "parameter_sweep",
    "percentile_bands",
    "plot_bands",
    "report",
    "scene_from_matrices",
    "solve",
    "study",
    "sweep",
    "variants",
]
