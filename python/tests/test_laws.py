"""Force laws written in Python: the same answers as the built-in laws, and every way a law
can go wrong is an exception naming the law."""

import math

import hbal
import numpy as np
import pytest

from conftest import scene_path


def duffing(theta, u, du):
    """The built-in `cubic_spring` with k = 1, alpha = 1: f = u + u³."""
    return u + u**3, 1.0 + 3.0 * u**2, 0.0


def with_python_spring(law, name="duffing", **extra):
    doc = hbal.Scene.load(scene_path("duffing.toml")).to_dict()
    doc["elements"][0] = {"name": "spring", "type": "python", "law": name, "connects": {"x": 1.0}, **extra}
    return hbal.Scene(doc, laws={name: law})


def test_a_python_duffing_law_gives_the_builtin_harmonics():
    builtin = hbal.solve(hbal.Scene.load(scene_path("duffing.toml")))
    python = hbal.solve(with_python_spring(duffing))
    assert python.converged and python.stable is True
    assert np.max(np.abs(python.harmonics - builtin.harmonics)) <= 1e-12 * np.max(np.abs(builtin.harmonics))
    assert abs(python.multipliers - builtin.multipliers).max() < 1e-9


def test_a_python_duffing_law_sweeps_through_both_folds_as_the_builtin():
    builtin = hbal.sweep(hbal.Scene.load(scene_path("duffing.toml")), 2.6, start=0.5, stability=False)
    python = hbal.sweep(with_python_spring(duffing), 2.6, start=0.5, stability=False)
    assert python.record["folds"] == builtin.record["folds"] == 2
    assert len(python.points) == len(builtin.points)
    scale = np.max(np.abs(builtin.harmonics))
    assert np.max(np.abs(python.harmonics - builtin.harmonics)) <= 1e-12 * scale


def test_a_law_is_called_once_per_pass_with_arrays():
    calls = []

    def counted(theta, u, du):
        calls.append(np.size(theta))
        return duffing(theta, u, du)

    scene = with_python_spring(counted)
    # The check of the law (3 samples), whether it takes floats (1 sample), its linear
    # part (64 samples).
    assert sorted(set(calls)) == [1, 3, 64] and calls.count(64) == 1
    calls.clear()
    hbal.solve(scene, stability=False)
    # The AFT passes on the scene's N samples, and those of the error estimate (on 2H and
    # a finer grid): arrays every time, never one sample (that is the time domain's).
    samples = hbal.Scene.load(scene_path("duffing.toml"))._info["samples"]
    assert calls.count(samples) >= 5 and min(calls) >= samples


def test_a_per_sample_law_is_refused_with_the_reason():
    def per_sample(theta, u, du):
        return math.sin(theta) * u, math.sin(theta), 0.0

    with pytest.raises(hbal.LawError, match="per_sample.*raised on arrays.*vectorised|per_sample.*raised on arrays") as e:
        with_python_spring(per_sample, name="per_sample")
    assert isinstance(e.value.__cause__, TypeError)


def test_a_law_raising_during_the_solve_is_a_law_error_with_its_cause():
    def fails_later(theta, u, du):
        if np.max(np.abs(u)) > 0.01:
            raise ZeroDivisionError("the law's own failure")
        return duffing(theta, u, du)

    with pytest.raises(hbal.LawError, match="fails_later.*raised") as e:
        hbal.solve(with_python_spring(fails_later, name="fails_later"))
    assert isinstance(e.value.__cause__, ZeroDivisionError)


@pytest.mark.parametrize(
    "bad, message",
    [
        (lambda t, u, du: (u[:-1] if len(u) > 3 else u, 1.0, 0.0), "f has .* values for .* samples"),
        (lambda t, u, du: (np.where(np.abs(u) > 0.01, np.nan, u), 1.0, 0.0), "f is NaN at theta"),
        (lambda t, u, du: (u, np.full_like(u, np.inf) if len(u) > 3 else 1.0, 0.0), "df_du is inf"),
        (lambda t, u, du: (u, 1.0) if len(u) > 3 else (u, 1.0, 0.0), "must return three values"),
        (lambda t, u, du: (u.reshape(-1, 1) if len(u) > 3 else u, 1.0, 0.0), "one-dimensional|values for"),
    ],
)
def test_a_law_returning_bad_arrays_is_a_law_error_naming_it(bad, message):
    # Found where the scene is built (its linear part calls the law) or in the solve.
    with pytest.raises(hbal.LawError, match="bad_law") as e:
        hbal.solve(with_python_spring(bad, name="bad_law"))
    assert e.value.args[0] and __import__("re").search(message, e.value.args[0]), e.value.args[0]


def test_an_element_naming_a_law_not_given_is_a_scene_error():
    doc = hbal.Scene.load(scene_path("duffing.toml")).to_dict()
    doc["elements"][0] = {"name": "spring", "type": "python", "law": "missing", "connects": {"x": 1.0}}
    with pytest.raises(hbal.SceneError, match="no Python law named `missing`") as e:
        hbal.Scene(doc, laws={"other": duffing})
    assert e.value.path == "elements[0]"


def test_a_law_that_is_not_a_function_is_refused():
    with pytest.raises(hbal.LawError, match="expected a function"):
        with_python_spring(42)


def test_a_law_that_needs_arrays_gets_arrays_for_one_sample_too():
    """The time domain and the Floquet analysis evaluate one sample at a time: as floats
    where the law gives the same for floats, else as arrays of one sample."""
    seen = set()

    def needs_arrays(theta, u, du):
        seen.add(type(u).__name__)
        assert u.shape == (len(u),)
        return duffing(theta, u, du)

    scene = with_python_spring(needs_arrays, name="needs_arrays")
    seen.clear()  # the check with floats, which this law fails
    result = hbal.solve(scene)
    assert result.converged and result.stable is True and seen == {"ndarray"}

    def takes_floats(theta, u, du):
        seen.add(type(u).__name__)
        return duffing(theta, u, du)

    seen.clear()
    result = hbal.solve(with_python_spring(takes_floats, name="takes_floats"))
    assert result.converged and result.stable is True and seen == {"ndarray", "float"}
