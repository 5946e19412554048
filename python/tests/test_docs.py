"""The Python code blocks of README.md and docs/python.md run as they are, from the
repository's root."""

import os
import re

import pytest

from conftest import REPO

BLOCK = re.compile(r"```python\n(.*?)```", re.S)


def blocks(name):
    return BLOCK.findall((REPO / name).read_text())


@pytest.mark.parametrize("name", ["README.md", "docs/python.md"])
def test_the_python_examples_run(name, monkeypatch, capsys):
    found = blocks(name)
    assert found, f"{name} has no python code block"
    monkeypatch.chdir(REPO)
    for i, code in enumerate(found):
        exec(compile(code, f"{name}[python block {i}]", "exec"), {"__name__": "__doc__"})
    assert capsys.readouterr().out


def test_the_stubs_name_every_function_of_the_extension():
    """hbal/_hbal.pyi declares what the extension exports, and nothing else."""
    import ast

    import hbal._hbal as ext

    stubs = ast.parse((REPO / "python" / "hbal" / "_hbal.pyi").read_text())
    declared = {n.name for n in stubs.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    declared |= {t.id for n in stubs.body if isinstance(n, ast.AnnAssign) for t in [n.target]}
    exported = {name for name in dir(ext) if not name.startswith("_") or name == "__version__"}
    assert exported - {"_hbal"} <= declared | {"__version__"}, exported - declared
    assert declared - exported <= {"Returned"}, declared - exported
