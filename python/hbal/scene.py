"""Scenes: a model, its operating point and solver, as a document (the TOML/JSON schema of
docs/scenes.md) that hbal checks and builds once.

A :class:`Scene` comes from a file, a string, a dict, or numpy/scipy matrices
(:func:`hbal.model.scene_from_matrices`), and goes back to any of them. It may carry force
laws written in Python (``laws={"name": function}``; elements ``{"type": "python", "law":
"name"}``). It pickles through its JSON form (its laws by reference, as pickle does for
functions), so any executor can ship it.
"""

from __future__ import annotations

import copy
import json
import os
from typing import Any, Callable, Mapping

from . import _hbal
from .laws import check_law


class Scene:
    """A checked, built scene.

    >>> import hbal
    >>> scene = hbal.Scene.from_str('''
    ... dofs = ["x"]
    ... mass = [[1.0]]
    ... damping = [[0.02]]
    ... fundamental = { rad_s = 1.2 }
    ... harmonics = { count = 7 }
    ... loads = [{ dof = "x", order = 1, cos = 0.1 }]
    ... [[elements]]
    ... name = "spring"
    ... type = "cubic_spring"
    ... connects = { x = 1.0 }
    ... k = 1.0
    ... alpha = 1.0
    ... ''')
    >>> scene.dofs, scene.harmonics
    (['x'], 7)
    >>> stiffer = scene.with_parameter("elements[0].k", 2.0)
    >>> stiffer.to_dict()["elements"][0]["k"]
    2.0
    """

    def __init__(
        self,
        document: Mapping[str, Any],
        *,
        file: str = "<scene>",
        laws: Mapping[str, Callable] | None = None,
    ) -> None:
        if not isinstance(document, Mapping):
            raise TypeError(f"document: expected a dict, got {type(document).__name__}")
        self._info: dict = {"description": None, "dofs": [], "elements": []}
        self._document = {}
        self._laws = dict(laws or {})
        for name, law in self._laws.items():
            check_law(name, law)
        self.file = str(file)
        self._handle = _hbal.build_scene(dict(document), self.file, self._laws)
        # The document as hbal read it (numpy arrays and tuples as lists).
        self._document = _plain(document)
        self._info = self._handle.info()

    # --- construction -------------------------------------------------------------------
    @classmethod
    def load(cls, path: str | os.PathLike, *, laws: Mapping[str, Callable] | None = None) -> "Scene":
        """Reads a scene file (``.json`` is JSON, anything else TOML). Files the scene names
        (Matrix Market matrices, DOF lists) are relative to its directory."""
        path = os.fspath(path)
        return cls(_hbal.read_scene(path), file=path, laws=laws)

    @classmethod
    def from_str(
        cls,
        text: str,
        *,
        format: str = "toml",
        laws: Mapping[str, Callable] | None = None,
        file: str | None = None,
    ) -> "Scene":
        """Parses scene text, ``format`` ``"toml"`` or ``"json"``."""
        if format not in ("toml", "json"):
            raise ValueError(f"format: expected 'toml' or 'json', got {format!r}")
        file = file or f"<string>.{format}"
        if format == "json" and not file.endswith(".json"):
            file += ".json"
        return cls(_hbal.parse_scene(text, file), file=file, laws=laws)

    @classmethod
    def from_dict(
        cls, document: Mapping[str, Any], *, laws: Mapping[str, Callable] | None = None
    ) -> "Scene":
        """A scene from its document (the dict a TOML or JSON file parses to; numpy arrays
        and scalars are accepted where the schema has numbers)."""
        return cls(document, laws=laws)

    # --- back ---------------------------------------------------------------------------
    def to_dict(self) -> dict:
        """The document (a deep copy)."""
        return copy.deepcopy(self._document)

    def to_json(self, indent: int | None = 2) -> str:
        """The document as JSON text (floats exactly, by their shortest repr)."""
        return json.dumps(self._document, indent=indent)

    def to_toml(self) -> str:
        """The document as TOML text."""
        return _hbal.document_to_toml(self._document)

    def save(self, path: str | os.PathLike) -> None:
        """Writes the document, as JSON where ``path`` ends in ``.json``, else TOML."""
        path = os.fspath(path)
        text = self.to_json() if path.endswith(".json") else self.to_toml()
        with open(path, "w", encoding="utf-8") as f:
            f.write(text)

    # --- variants -----------------------------------------------------------------------
    def with_parameter(self, path: str, value: float) -> "Scene":
        """A new scene with the number at ``path`` (``elements[0].k``, ``loads[1].cos``,
        ``fundamental.rpm``, ``damping[0][0]``) set to ``value``. A path the scene does
        not have is an :class:`hbal.InputError` naming it."""
        return self.with_parameters({path: value})

    def with_parameters(self, values: Mapping[str, float]) -> "Scene":
        """A new scene with every ``path: value`` of ``values`` set."""
        doc = self._document
        for path, value in values.items():
            doc = _hbal.set_parameter(doc, str(path), float(value))
        return Scene(doc, file=self.file, laws=self._laws)

    # --- what it holds ------------------------------------------------------------------
    @property
    def laws(self) -> dict:
        """The Python force laws by name."""
        return dict(self._laws)

    @property
    def dofs(self) -> list[str]:
        """The DOF names."""
        return list(self._info["dofs"])

    @property
    def elements(self) -> list[str]:
        """The element names (a gear stage's mesh by the stage's name)."""
        return list(self._info["elements"])

    @property
    def speed(self) -> float:
        """The scene's speed, in :attr:`speed_unit` (as the scene gives it)."""
        given = self._document.get("fundamental", {})
        value = given.get(self.speed_unit) if isinstance(given, dict) else None
        return float(value) if isinstance(value, (int, float)) else self._info["speed"]

    @property
    def speed_unit(self) -> str:
        """``rpm``, ``hz`` or ``rad_s``."""
        return self._info["speed_unit"]

    @property
    def harmonics(self) -> int:
        """H (with automatic harmonics: the first H tried)."""
        return self._info["harmonics"]

    @property
    def on_torus(self) -> bool:
        """Solved on several base frequencies (docs/torus.md)."""
        return self._info["torus"]

    @property
    def notes(self) -> list[str]:
        """Things to know that are not errors."""
        return list(self._info["notes"])

    @property
    def description(self) -> str | None:
        return self._info["description"]

    def check(self) -> None:
        """Checks the scene as a solve would before its first iteration (``hbal check``)."""
        _hbal.check(self._handle)

    # --- pickling and display -----------------------------------------------------------
    def __reduce__(self):
        return (_restore, (self.to_json(indent=None), self.file, self._laws))

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Scene) and self._document == other._document and self._laws == other._laws

    def __repr__(self) -> str:
        what = self.description or self.file
        return f"<hbal.Scene {what!r}: {len(self.dofs)} DOFs, {len(self.elements)} elements>"


def _restore(text: str, file: str, laws: Mapping[str, Callable]) -> Scene:
    return Scene(json.loads(text), file=file, laws=laws)


def _plain(obj: Any) -> Any:
    """``obj`` with numpy arrays and scalars, tuples and mappings as plain Python values."""
    kind = type(obj)
    if kind is float or kind is str or kind is int or kind is bool or obj is None:
        return obj
    if kind is dict:
        return {str(k): _plain(v) for k, v in obj.items()}
    if kind is list:
        return [_plain(v) for v in obj]
    if isinstance(obj, Mapping):
        return {str(k): _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    if hasattr(obj, "tolist") and not isinstance(obj, (str, bytes)):
        return _plain(obj.tolist())
    return obj
