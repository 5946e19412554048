"""Results of the analyses: the library's record (what ``hbal ... --json`` prints, read bit
for bit) with numpy views of what an engineer reads.

Every result has ``record`` (the dict), ``exit_code`` (0, or 1 where it is marked: not
converged, a branch that stopped, a failed stability), ``to_dict()``, ``to_json()`` and
``to_pandas()`` (where pandas is installed), and pickles through its JSON form.

Harmonics are complex amplitudes ``Q_k = c_k - i s_k`` of ``q(t) = Σ_k c_k cos kθ + s_k sin kθ``
(``θ = Ω t``, Ω the fundamental), so that ``q(t) = Re Σ_k Q_k e^{ikθ}``.
"""

from __future__ import annotations

import copy
import json
from typing import Any

import numpy as np


class Result:
    """An analysis's record and exit code."""

    def __init__(self, record, exit_code: int, library_seconds: float | None = None) -> None:
        # A dict, or the library's record not yet converted (built when first read).
        self._record = record
        self.exit_code = int(exit_code)
        #: The wall time of the Rust library's call alone (None for a result read back).
        self.library_seconds = library_seconds

    @property
    def record(self) -> dict:
        """The analysis's record: what ``hbal ... --json`` prints, as Python objects."""
        if not isinstance(self._record, dict):
            self._record = self._record.to_python()
        return self._record

    @property
    def ok(self) -> bool:
        """``exit_code == 0``."""
        return self.exit_code == 0

    def __getitem__(self, key: str) -> Any:
        return self.record[key]

    def to_dict(self) -> dict:
        return copy.deepcopy(self.record)

    def to_json(self, indent: int | None = None) -> str:
        return json.dumps(self.record, indent=indent)

    def __reduce__(self):
        return (_restore, (type(self).__name__, self.to_json(), self.exit_code))

    def __repr__(self) -> str:
        return f"<hbal.{type(self).__name__} exit_code={self.exit_code}>"


def _complex(harmonics: list[dict]) -> np.ndarray:
    return np.array([h["cos"] - 1j * h["sin"] for h in harmonics], dtype=complex)


def _multipliers(pairs: list | None) -> np.ndarray | None:
    if pairs is None:
        return None
    return np.array([re + 1j * im for re, im in pairs], dtype=complex)


def _synthesize(harmonics: np.ndarray, samples: int) -> np.ndarray:
    """``Re Σ_k Q_k e^{ikθ_j}`` at ``θ_j = 2π j / samples`` for each row of ``harmonics``."""
    k = np.arange(harmonics.shape[-1])
    theta = 2 * np.pi * np.arange(samples) / samples
    return np.real(harmonics @ np.exp(1j * np.outer(k, theta)))


class SolveResult(Result):
    """One periodic solution (``hbal.solve``)."""

    @property
    def converged(self) -> bool:
        return self.record["converged"]

    @property
    def termination(self) -> str:
        return self.record["termination"]

    @property
    def fundamental_rad_s(self) -> float:
        return self.record["fundamental_rad_s"]

    @property
    def dof_names(self) -> list[str]:
        return [d["name"] for d in self.record["dofs"]]

    @property
    def harmonics(self) -> np.ndarray:
        """Complex harmonics, shape (DOFs, H + 1)."""
        return np.array([_complex(d["harmonics"]) for d in self.record["dofs"]])

    @property
    def orders(self) -> np.ndarray:
        """The shaft order of each harmonic (k times the fundamental's order)."""
        return np.array([h["shaft_order"] for h in self.record["dofs"][0]["harmonics"]])

    @property
    def max_abs(self) -> np.ndarray:
        """``max |q_i|`` over the period, per DOF."""
        return np.array([d["max_abs"] for d in self.record["dofs"]])

    @property
    def error_estimate(self) -> float | None:
        """The estimated relative error of the solution (against 2H), where computed."""
        e = self.record.get("error_estimate")
        return e.get("relative") if isinstance(e, dict) else None

    @property
    def stable(self) -> bool | None:
        s = self.record.get("stability")
        return s.get("stable") if isinstance(s, dict) else None

    @property
    def multipliers(self) -> np.ndarray | None:
        """The Floquet multipliers, where computed."""
        s = self.record.get("stability")
        return _multipliers(s.get("multipliers")) if isinstance(s, dict) else None

    def element(self, name: str) -> dict:
        """An element's output: ``coordinate`` and ``force`` harmonics (complex arrays) and
        their ``min``, ``max``, ``mean``, ``peak_to_peak``."""
        elements = self.record["elements"]
        if isinstance(elements, dict):
            raise KeyError(f"element outputs unavailable: {elements.get('error')}")
        for e in elements:
            if e["name"] == name:
                out = {"name": name, "type": e["type"]}
                for part in ("coordinate", "force"):
                    p = dict(e[part])
                    p["harmonics"] = _complex(p["harmonics"])
                    out[part] = p
                return out
        raise KeyError(f"no element `{name}`; elements: {[e['name'] for e in elements]}")

    def time_series(self, samples: int = 256) -> tuple[np.ndarray, np.ndarray]:
        """Times (s) over one period and the DOFs' values there, shape (DOFs, samples)."""
        period = 2 * np.pi / self.fundamental_rad_s
        t = period * np.arange(samples) / samples
        return t, _synthesize(self.harmonics, samples)

    def to_pandas(self):
        """One row per DOF and harmonic: dof, harmonic, shaft_order, cos, sin, amplitude,
        phase (rad, of ``Q_k``)."""
        import pandas as pd

        rows = []
        for d in self.record["dofs"]:
            for h in d["harmonics"]:
                q = h["cos"] - 1j * h["sin"]
                rows.append(
                    {
                        "dof": d["name"],
                        "harmonic": h["harmonic"],
                        "shaft_order": h["shaft_order"],
                        "cos": h["cos"],
                        "sin": h["sin"],
                        "amplitude": abs(q),
                        "phase": float(np.angle(q)),
                    }
                )
        return pd.DataFrame(rows)


class SweepResult(Result):
    """A speed sweep (``hbal.sweep``): the branch's points in order along it."""

    @property
    def points(self) -> list[dict]:
        return self.record["points"]

    @property
    def reached(self) -> bool:
        return self.record["reached"]

    @property
    def stop(self) -> str:
        return self.record["stop"]

    @property
    def speed(self) -> np.ndarray:
        """Each point's speed, in the scene's unit."""
        return np.array([p["speed"] for p in self.points])

    @property
    def omega(self) -> np.ndarray:
        return np.array([p["omega_rad_s"] for p in self.points])

    @property
    def stable(self) -> np.ndarray:
        """1.0 stable, 0.0 unstable, NaN not computed."""
        return np.array([np.nan if p["stable"] is None else float(p["stable"]) for p in self.points])

    @property
    def error_estimate(self) -> np.ndarray:
        return np.array([np.nan if p["error_estimate"] is None else p["error_estimate"] for p in self.points])

    @property
    def max_abs(self) -> np.ndarray:
        """``max |q_i|`` per point and DOF, shape (points, DOFs)."""
        return np.array([p["max_abs"] for p in self.points])

    @property
    def harmonics_dofs(self) -> list[str]:
        """The DOFs whose harmonics the points hold."""
        return list(self.record["harmonics_dofs"])

    @property
    def harmonics(self) -> np.ndarray:
        """Complex harmonics, shape (points, harmonics DOFs, H + 1)."""
        return np.array([[_complex(d) for d in p["harmonics"]] for p in self.points])

    @property
    def orders(self) -> np.ndarray:
        return np.array([h["shaft_order"] for h in self.points[0]["harmonics"][0]])

    def order_cut(self, dof: str, order: float) -> np.ndarray:
        """The amplitude of one shaft order of one DOF along the branch."""
        i = self.harmonics_dofs.index(dof)
        k = int(np.flatnonzero(np.isclose(self.orders, order))[0])
        return np.abs(self.harmonics[:, i, k])

    def to_pandas(self):
        """One row per point: speed, omega_rad_s, stable, error_estimate, residual, fold,
        bifurcation, and ``max_abs(<dof>)`` per DOF."""
        import pandas as pd

        dofs = self.record["dofs"]
        rows = []
        for p in self.points:
            row = {
                "speed": p["speed"],
                "omega_rad_s": p["omega_rad_s"],
                "stable": p["stable"],
                "error_estimate": p["error_estimate"],
                "residual": p["residual"],
                "fold": p["fold"],
                "bifurcation": p["bifurcation"],
            }
            row.update({f"max_abs({d})": x for d, x in zip(dofs, p["max_abs"])})
            rows.append(row)
        return pd.DataFrame(rows)


class ParameterSweepResult(Result):
    """A sweep of one scene field (``hbal.parameter_sweep``)."""

    def to_pandas(self):
        import pandas as pd

        return pd.json_normalize(self.record.get("points", []))


class ModesResult(Result):
    """Natural frequencies, mode shapes and critical speeds (``hbal.modes``)."""

    def to_pandas(self):
        import pandas as pd

        return pd.json_normalize(self.record.get("modes", []))


class CompareResult(Result):
    """Every solver against the time-domain reference (``hbal.compare``)."""

    def to_pandas(self):
        import pandas as pd

        return pd.json_normalize(self.record.get("methods", []))


class TorusSolveResult(Result):
    """A solution on several base frequencies (``hbal.solve`` of a torus scene)."""

    @property
    def converged(self) -> bool:
        return self.record["converged"]


class TorusSweepResult(Result):
    """A sweep on several base frequencies (``hbal.sweep`` of a torus scene)."""

    def to_pandas(self):
        import pandas as pd

        return pd.json_normalize(self.record.get("points", []))


_KINDS = {
    cls.__name__: cls
    for cls in (
        Result,
        SolveResult,
        SweepResult,
        ParameterSweepResult,
        ModesResult,
        CompareResult,
        TorusSolveResult,
        TorusSweepResult,
    )
}


def _restore(kind: str, text: str, exit_code: int) -> Result:
    return _KINDS[kind](json.loads(text), exit_code)
