"""Hostile use from Python: every case an exception naming the problem, never a crash, a hang
or a silent wrong answer (found by an independent review of the package)."""

import subprocess
import sys
import threading
import time

import hbal
import numpy as np
import pytest

from conftest import scene_path
from test_laws import duffing, with_python_spring

DUFFING = scene_path("duffing.toml")


def run_isolated(code: str, timeout: float = 60.0) -> str:
    """Runs `code` in a fresh interpreter (a crash or hang there cannot take the suite down)."""
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=timeout)
    assert p.returncode == 0, f"exit {p.returncode}: {p.stderr[-2000:]}"
    return p.stdout


def test_a_document_that_holds_itself_is_refused():
    doc = hbal.Scene.load(DUFFING).to_dict()
    loop = []
    loop.append(loop)
    doc["loads"] = loop
    with pytest.raises(hbal.InputError, match="loads.*nested more than 64 levels"):
        hbal.Scene.from_dict(doc)
    doc["loads"] = [{"dof": "x", "order": 1, "cos": float("nan")}]
    with pytest.raises(hbal.InputError, match=r"loads\[0\]\.cos: must be a finite number"):
        hbal.Scene.from_dict(doc)


def test_freeing_a_scene_whose_law_holds_another_scene_does_not_hang():
    out = run_isolated(f"""
import hbal
inner = hbal.Scene.load({DUFFING!r})
def law(t, u, du, _k=inner):
    return u, 1.0, 0.0
outer = hbal.Scene.load({DUFFING!r}, laws={{"unused": law}})
del inner, law
del outer
print("freed")
""")
    assert "freed" in out


def test_a_law_may_run_an_analysis_of_its_own_scene():
    out = run_isolated(f"""
import hbal
from hbal import Scene
doc = Scene.load({DUFFING!r}).to_dict()
doc["elements"][0] = {{"name": "spring", "type": "python", "law": "k", "connects": {{"x": 1.0}}}}
calls = []
armed = []
def law(t, u, du):
    if armed and not calls:
        calls.append(None)
        calls.append(hbal.solve(scene, stability=False).converged)
    u2 = u * u
    return u + u2 * u, 1.0 + 3.0 * u2, 0.0
scene = Scene(doc, laws={{"k": law}})
armed.append(1)
r = hbal.solve(scene, stability=False)
print(r.converged, True in calls)
def endless(t, u, du):
    if armed:
        hbal.solve(endless_scene, stability=False)
    return u, 1.0, 0.0
armed.clear()
doc["elements"][0]["law"] = "e"
endless_scene = Scene(doc, laws={{"e": endless}})
armed.append(1)
try:
    hbal.solve(endless_scene, stability=False)
except hbal.LawError as e:
    print("nested" in str(e))
""")
    assert out.split() == ["True", "True", "True"]


def test_ctrl_c_inside_a_law_is_raised_as_it_is_and_stops_the_sweep():
    calls = []

    def interrupted(theta, u, du):
        calls.append(1)
        if len(calls) == 40:
            raise KeyboardInterrupt
        return duffing(theta, u, du)

    scene = with_python_spring(interrupted, name="interrupted")
    start = time.perf_counter()
    with pytest.raises(KeyboardInterrupt):
        hbal.sweep(scene, 2.6, start=0.5)
    assert time.perf_counter() - start < 5.0
    assert len(calls) < 400  # stopped at the next point, not after the whole branch


def test_a_failure_belongs_to_its_own_analysis():
    """A law's failure in one analysis is not raised by the next one, nor by another thread's."""
    state = {"fail": False}

    def sometimes(theta, u, du):
        if state["fail"]:
            raise ValueError("this analysis only")
        return duffing(theta, u, du)

    scene = with_python_spring(sometimes, name="sometimes")
    state["fail"] = True
    with pytest.raises(hbal.LawError, match="this analysis only"):
        hbal.solve(scene)
    state["fail"] = False
    assert hbal.solve(scene).converged
    with pytest.raises(RuntimeError, match="stop"):
        hbal.sweep(scene, 2.6, start=0.5, progress=lambda f, s: (_ for _ in ()).throw(RuntimeError("stop")))
    assert hbal.solve(scene).converged


def test_reading_a_record_from_two_threads():
    result = hbal.solve(hbal.Scene.load(DUFFING))
    got, errors = [], []

    def read():
        try:
            got.append(result.record["converged"])
        except Exception as e:  # noqa: BLE001 - collected for the assertion
            errors.append(e)

    threads = [threading.Thread(target=read) for _ in range(8)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors and got == [True] * 8


def test_bad_options_name_themselves():
    scene = hbal.Scene.load(DUFFING)
    cases = [
        (lambda: hbal.sweep(scene, 2.0, tolerance=-1.0), "tolerance: must be in"),
        (lambda: hbal.sweep(scene, 2.0, tolerance=float("inf")), "tolerance: must be in"),
        (lambda: hbal.sweep(scene, 2.0, points=-1), "points: must be a whole number >= 0"),
        (lambda: hbal.sweep(scene, 2.0, points=10**30), "points: must be a whole number >= 0"),
        (lambda: hbal.solve(scene, samples=-1), "samples: must be a whole number >= 0"),
        (lambda: hbal.solve(scene, stability="no"), "stability: expected True or False"),
        (lambda: hbal.sweep(scene, 2.0, progress=42), "progress: expected a function"),
        (lambda: hbal.Scene.from_dict(scene.to_dict()) and hbal.Scene(scene.to_dict(), laws={5: duffing}), "laws: the names must be strings"),
        (lambda: hbal.scene_from_matrices("xy", np.eye(2)), "dofs: expected a list of names"),
        (lambda: hbal.scene_from_matrices(["x"], np.eye(1), elements=[1]), "elements: expected a list of dicts"),
    ]
    for call, message in cases:
        with pytest.raises(hbal.InputError, match=message):
            call()
    assert hbal.compare(scene, methods="newton").record["methods"][0]["method"] == "newton"


def test_torus_sweeps_refuse_what_applies_to_one_fundamental():
    scene = hbal.Scene.load(scene_path("two_stage_train_torus.toml"))
    for option in ({"all_branches": True}, {"max_points": 5}, {"dofs": "crank"}, {"stability_orbit": "harmonic"}):
        with pytest.raises(hbal.InputError, match="applies to one fundamental"):
            hbal.sweep(scene, 1200, start=1000, points=3, **option)


def test_odd_law_returns_are_refused_with_the_reason():
    for bad, message in [
        (lambda t, u, du: (u + 0j, 1.0, 0.0), "f must hold real numbers, got dtype complex"),
        (lambda t, u, du: (u, "1.0", 0.0), "df_du must hold real numbers"),
        (lambda t, u, du: {"f": u, "k": 1.0, "c": 0.0}, "must return three values"),
    ]:
        with pytest.raises(hbal.LawError, match=message):
            with_python_spring(bad, name="odd")


def test_a_document_cannot_name_another_scenes_law():
    doc = hbal.Scene.load(DUFFING).to_dict()
    doc["elements"][0] = {"name": "spring", "type": "python", "law": "k#law0", "connects": {"x": 1.0}}
    with pytest.raises(hbal.InputError, match="may not contain `#`"):
        hbal.Scene.from_dict(doc)


def test_a_hash_in_a_name_stays_in_messages():
    doc = hbal.Scene.load(DUFFING).to_dict()
    doc["loads"][0]["dof"] = "shaft#3"
    with pytest.raises(hbal.SceneError, match="shaft#3"):
        hbal.Scene.from_dict(doc)


def test_bad_variants_are_refused_before_any_work(tmp_path):
    scene = hbal.Scene.load(scene_path("two_shaft_6000rpm.toml"))
    for variants, message in [
        ([{"elements[0].profile.one_tooth": None}], r"variants\[0\]\['elements\[0\].profile.one_tooth'\]: expected a finite number"),
        ([{"elements[0].profile.one_tooth": "abc"}], "expected a finite number"),
        ([{"fundamental.rpm": 5000.0}], "is the speed, which `speeds` sets"),
    ]:
        with pytest.raises(hbal.InputError, match=message):
            hbal.study.run(scene, variants, speeds=[6000])
    with pytest.raises(hbal.InputError, match="options:"):
        hbal.study.run(scene, [{}], speeds=[6000], options={"no_such_option": 1})
    table = hbal.study.run(scene, [{"elements[0].profile.one_tooth": np.int64(250000)}], speeds=[6000], out=tmp_path / "s")
    assert (table.status == "ok").all()


def test_two_threads_reading_a_record_while_finalisers_run():
    """Building the record holds no lock while Python runs (a finaliser may let the GIL go)."""
    out = run_isolated(f"""
import gc, threading, hbal
class Noisy:
    def __init__(self):
        self.me = self
    def __del__(self):
        import time; time.sleep(0)
r = hbal.sweep(hbal.Scene.load({DUFFING!r}), 2.6, start=0.5, stability=False)
junk = [Noisy() for _ in range(3000)]
del junk
got = []
threads = [threading.Thread(target=lambda: got.append(len(r.record["points"]))) for _ in range(4)]
for t in threads: t.start()
for t in threads: t.join()
print(len(set(got)), len(got))
""", timeout=60)
    assert out.split() == ["1", "4"]


def test_a_scene_built_inside_a_law_keeps_its_own_failures():
    inner_doc = hbal.Scene.load(DUFFING).to_dict()
    inner_doc["elements"][0] = {"name": "spring", "type": "python", "law": "bad", "connects": {"x": 1.0}}
    seen = []

    def builds_another(theta, u, du):
        if armed and not seen:
            def bad(t, u, du):
                if np.size(u) == 64:
                    raise ValueError("the inner scene's law")
                return duffing(t, u, du)

            try:
                hbal.Scene(inner_doc, laws={"bad": bad})
            except hbal.LawError as e:
                seen.append(str(e))
        return duffing(theta, u, du)

    armed = []
    scene = with_python_spring(builds_another, name="outer")
    armed.append(1)
    assert hbal.solve(scene).converged
    assert seen and "the inner scene's law" in seen[0]
