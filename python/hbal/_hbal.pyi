"""Type stubs of the extension module ``hbal._hbal`` (the Rust core; use the package ``hbal``)."""

from typing import Any, Callable, Mapping, Sequence

SCHEMA_VERSION: int
__version__: str

class InputError(ValueError):
    """Bad input (exit code 2), refused before any work."""

class SceneError(InputError):
    file: str
    path: str | None
    position: tuple[int, int] | None
    reason: str

class LawError(InputError):
    """A Python force law raised or returned arrays of the wrong length or non-finite values."""

class NumericalError(RuntimeError):
    """A numerical failure after the input was checked (exit code 1)."""

class SceneHandle:
    def info(self) -> dict[str, Any]: ...

class Record:
    def to_python(self) -> dict[str, Any]: ...

Returned = tuple[Record, int, float]

def build_scene(document: Mapping[str, Any], file: str, laws: Mapping[str, Callable[..., Any]] | None = None) -> SceneHandle: ...
def parse_scene(text: str, file: str) -> dict[str, Any]: ...
def read_scene(path: str) -> dict[str, Any]: ...
def document_to_toml(document: Mapping[str, Any]) -> str: ...
def set_parameter(document: Mapping[str, Any], path: str, value: float) -> dict[str, Any]: ...
def check(scene: SceneHandle) -> None: ...
def solve(
    scene: SceneHandle,
    *,
    method: str | None = None,
    harmonics: int | str | None = None,
    samples: int | None = None,
    tolerance: float | None = None,
    formulation: str | None = None,
    stability: bool = True,
    fallback: bool = True,
    guess: Any = None,
    out: str | None = None,
) -> Returned: ...
def sweep(
    scene: SceneHandle,
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
    dofs: str | None = None,
    progress: Callable[[float, str], Any] | None = None,
    guess: Any = None,
    out: str | None = None,
) -> Returned: ...
def parameter_sweep(
    scene: SceneHandle,
    parameter: str,
    start: float,
    to: float,
    *,
    points: int = 101,
    harmonics: int | str | None = None,
    samples: int | None = None,
    formulation: str | None = None,
    stability: bool = True,
    dofs: str | None = None,
    progress: Callable[[float, str], Any] | None = None,
    out: str | None = None,
) -> Returned: ...
def modes(
    scene: SceneHandle,
    *,
    start: float | None = None,
    to: float | None = None,
    max_hz: float | None = None,
    formulation: str | None = None,
    out: str | None = None,
) -> Returned: ...
def compare(
    scene: SceneHandle,
    *,
    methods: Sequence[str] | None = None,
    harmonics: int | str | None = None,
    samples: int | None = None,
    tolerance: float | None = None,
    formulation: str | None = None,
    out: str | None = None,
) -> Returned: ...
def report(
    scene: SceneHandle,
    out: str,
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
    progress: Callable[[float, str], Any] | None = None,
) -> tuple[str, int, list[str], list[str], float]: ...
def limit_threads_here(limit: int | None = None) -> int | None: ...
