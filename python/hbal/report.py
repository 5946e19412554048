"""The report (``hbal report SCENE --out DIR``): one self-contained ``report.html`` with
the scene, the solve at its speed (convergence, error estimate, stability, DOF and element
tables, time series and spectrum), with ``to`` the run-up (order cuts, waterfall, frequency
responses, contact loss), and the natural frequencies with the Campbell diagram; the parts'
files in ``DIR/solve``, ``DIR/sweep`` and ``DIR/modes``.
"""

from __future__ import annotations

import os
import pathlib
from typing import Callable

from . import _hbal
from .analyses import _callback, _count, _flag, _out, _scene


class ReportResult:
    """A written report: ``path`` (``DIR/report.html``), ``exit_code`` (0, or 1 where a part
    failed: the page says why), ``errors`` (those failures), ``warnings`` (plots that could
    not be drawn) and ``library_seconds``."""

    def __init__(self, path: str, exit_code: int, errors, warnings, seconds: float) -> None:
        self.path = pathlib.Path(path)
        self.exit_code = int(exit_code)
        self.errors = list(errors)
        self.warnings = list(warnings)
        self.library_seconds = seconds

    @property
    def ok(self) -> bool:
        """``exit_code == 0``."""
        return self.exit_code == 0

    def __repr__(self) -> str:
        return f"<hbal.ReportResult {str(self.path)!r} exit_code={self.exit_code}>"


def report(
    scene,
    out: str | os.PathLike,
    *,
    to: float | None = None,
    start: float | None = None,
    stability: bool = True,
    output: str | None = None,
    max_step: float | None = None,
    max_points: int | None = None,
    points: int | None = None,
    method: str | None = None,
    harmonics: int | str | None = None,
    samples: int | None = None,
    tolerance: float | None = None,
    formulation: str | None = None,
    progress: Callable[[float, str], None] | None = None,
) -> ReportResult:
    """Writes the report of ``scene`` into the directory ``out`` (``hbal report``); with
    ``to`` (and ``start``, default the scene's speed) a run-up, resolved by ``max_step`` (the
    largest continuation step, default 0.5: smaller gives more points), ``max_points`` and
    ``points`` (evenly spaced speeds on several base frequencies). ``stability=False`` is
    ``--no-stability``, ``output`` chooses the run-up's plotted output. ``progress(fraction,
    stage)`` hears the stages and the run-up; Ctrl-C stops the run-up and raises
    ``KeyboardInterrupt``. Bad input (the speeds, ``output``, an unusable ``out``) raises
    :class:`hbal.InputError` before any work; a part that fails later is shown failed in the
    page and listed in ``errors``."""
    s = _scene(scene)
    directory = _out(out)
    if directory is None:
        raise _hbal.InputError("out: the report needs a directory")
    path, code, errors, warnings, seconds = _hbal.report(
        s._handle,
        directory,
        to=None if to is None else float(to),
        start=None if start is None else float(start),
        stability=_flag("stability", stability),
        output=output,
        max_step=None if max_step is None else float(max_step),
        max_points=_count("max_points", max_points),
        points=_count("points", points),
        method=method,
        harmonics=harmonics,
        samples=_count("samples", samples),
        tolerance=tolerance,
        formulation=formulation,
        progress=_callback("progress", progress),
    )
    return ReportResult(path, code, errors, warnings, seconds)
