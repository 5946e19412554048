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
