"""Shared fixtures: the repository's example scenes and the `hbal` command line built from
the same sources (target/release/hbal, or $HBAL_BIN), the reference every result is
compared with bit for bit."""

from __future__ import annotations

import json
import math
import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
SCENES = REPO / "examples" / "scenes"


def scene_path(name: str) -> str:
    return str(SCENES / name)


@pytest.fixture(scope="session")
def hbal_bin() -> str:
    path = os.environ.get("HBAL_BIN", str(REPO / "target" / "release" / "hbal"))
    if not os.path.exists(path):
        pytest.fail(f"the hbal command line is not built at {path} (cargo build --release, or set HBAL_BIN)")
    return path


@pytest.fixture(scope="session")
def cli(hbal_bin):
    """Runs `hbal ARGS --json` and returns (record, exit code)."""

    def run(*args: str):
        p = subprocess.run([hbal_bin, *args, "--json"], capture_output=True, text=True, cwd=REPO)
        assert p.stdout, f"hbal {' '.join(args)} printed nothing (exit {p.returncode}): {p.stderr}"
        return json.loads(p.stdout), p.returncode

    return run


def without_times(x):
    """A record without its wall times (every key with `seconds` in it)."""
    if isinstance(x, dict):
        return {k: without_times(v) for k, v in x.items() if "seconds" not in k}
    if isinstance(x, list):
        return [without_times(v) for v in x]
    return x


def assert_bitwise_equal(a, b, path="record"):
    """Equal to the last bit: floats by their bits (so -0.0 differs from 0.0), every other
    value by ==, dict keys and list lengths alike."""
    if isinstance(a, float) or isinstance(b, float):
        assert isinstance(a, float) and isinstance(b, float), f"{path}: {a!r} vs {b!r}"
        assert a.hex() == b.hex() or (math.isnan(a) and math.isnan(b)), f"{path}: {a!r} vs {b!r}"
    elif isinstance(a, dict):
        assert isinstance(b, dict) and a.keys() == b.keys(), f"{path}: keys {sorted(a)} vs {sorted(b) if isinstance(b, dict) else b}"
        for k in a:
            assert_bitwise_equal(a[k], b[k], f"{path}.{k}")
    elif isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), f"{path}: lengths differ"
        for i, (x, y) in enumerate(zip(a, b)):
            assert_bitwise_equal(x, y, f"{path}[{i}]")
    else:
        assert a == b and type(a) is type(b), f"{path}: {a!r} vs {b!r}"
