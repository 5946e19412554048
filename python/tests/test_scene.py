"""Scenes from files, strings, dicts and matrices, and back; variants; pickling; bad input
named where it is."""

import pickle

import hbal
import numpy as np
import pytest

from conftest import REPO, assert_bitwise_equal, scene_path, without_times

DUFFING_TOML = (REPO / "examples" / "scenes" / "duffing.toml").read_text()


def test_file_string_dict_json_and_toml_give_the_same_scene_and_answer():
    loaded = hbal.Scene.load(scene_path("duffing.toml"))
    variants = [
        hbal.Scene.from_str(DUFFING_TOML),
        hbal.Scene.from_dict(loaded.to_dict()),
        hbal.Scene.from_str(loaded.to_json(), format="json"),
        hbal.Scene.from_str(loaded.to_toml()),
    ]
    reference = without_times(hbal.solve(loaded).record)
    for v in variants:
        assert v.to_dict() == loaded.to_dict()
        assert_bitwise_equal(without_times(hbal.solve(v).record), reference)


def test_save_writes_a_file_the_command_line_reads(tmp_path, cli):
    scene = hbal.Scene.load(scene_path("two_shaft_6000rpm.toml"))
    for name in ("copy.toml", "copy.json"):
        scene.save(tmp_path / name)
        expected, _ = cli("solve", str(tmp_path / name))
        assert_bitwise_equal(without_times(hbal.solve(scene).record), without_times(expected))


def test_with_parameter_sets_a_field_and_names_a_missing_one():
    scene = hbal.Scene.load(scene_path("duffing.toml"))
    stiffer = scene.with_parameters({"elements[0].k": 2.0, "fundamental.rad_s": 1.5})
    assert stiffer.to_dict()["elements"][0]["k"] == 2.0 and stiffer.speed == 1.5
    assert scene.to_dict()["elements"][0]["k"] == 1.0
    with pytest.raises(hbal.InputError, match="elements\\[0\\].stiffness.*no field `stiffness`"):
        scene.with_parameter("elements[0].stiffness", 2.0)
    with pytest.raises(hbal.InputError, match="elements\\[3\\]"):
        scene.with_parameter("elements[3].k", 2.0)
    with pytest.raises(hbal.InputError, match="finite"):
        scene.with_parameter("elements[0].k", float("nan"))


def test_scene_errors_name_the_field():
    doc = hbal.Scene.load(scene_path("duffing.toml")).to_dict()
    doc["elements"][0]["alhpa"] = doc["elements"][0].pop("alpha")
    with pytest.raises(hbal.SceneError) as e:
        hbal.Scene.from_dict(doc)
    assert "elements[0].alhpa" in str(e.value) and e.value.path.startswith("elements[0]")
    assert isinstance(e.value, ValueError) and isinstance(e.value, hbal.InputError)
    with pytest.raises(hbal.SceneError) as e:
        hbal.Scene.from_str("dofs = [", file="broken.toml")
    assert e.value.position is not None and e.value.file == "broken.toml"
    with pytest.raises(hbal.SceneError, match="cannot read the file"):
        hbal.Scene.load(REPO / "no_such_scene.toml")


def test_nan_in_a_document_is_named():
    doc = hbal.Scene.load(scene_path("duffing.toml")).to_dict()
    doc["damping"] = np.array([[np.nan]])
    with pytest.raises(ValueError, match="damping\\[0\\]\\[0\\]: must be a finite number"):
        hbal.Scene.from_dict(doc)


def test_scenes_and_results_pickle_through_their_json():
    scene = hbal.Scene.load(scene_path("duffing.toml"))
    copy = pickle.loads(pickle.dumps(scene))
    assert copy == scene and copy.dofs == ["x"]
    result = hbal.solve(scene)
    back = pickle.loads(pickle.dumps(result))
    assert type(back) is hbal.SolveResult and back.exit_code == result.exit_code
    assert_bitwise_equal(back.record, result.record)
    assert np.array_equal(back.harmonics, result.harmonics)


def test_a_scene_with_a_python_law_pickles_with_the_law():
    from test_laws import duffing, with_python_spring

    scene = with_python_spring(duffing)
    copy = pickle.loads(pickle.dumps(scene))
    assert copy.laws["duffing"] is duffing
    assert np.array_equal(hbal.solve(copy).harmonics, hbal.solve(scene).harmonics)


def chain_matrices():
    """examples/scenes/chain_backlash.toml's matrices."""
    doc = hbal.Scene.load(scene_path("chain_backlash.toml")).to_dict()
    return doc, {k: np.array(doc[k], dtype=float) for k in ("mass", "damping", "stiffness")}


def test_a_scene_from_numpy_and_scipy_matrices_solves_as_the_file():
    import scipy.sparse as sp

    doc, m = chain_matrices()
    reference = hbal.solve(hbal.Scene.load(scene_path("chain_backlash.toml")))
    rest = {k: doc[k] for k in ("elements", "loads", "fundamental", "harmonics") if k in doc}
    dense = hbal.scene_from_matrices(doc["dofs"], m["mass"], damping=m["damping"], stiffness=m["stiffness"], **rest)
    sparse = hbal.scene_from_matrices(
        doc["dofs"], sp.csr_matrix(m["mass"]), damping=sp.coo_matrix(m["damping"]), stiffness=sp.csc_matrix(m["stiffness"]), **rest
    )
    assert "triplets" in sparse.to_dict()["stiffness"]
    for scene in (dense, sparse):
        r = hbal.solve(scene)
        assert r.converged
        assert np.max(np.abs(r.harmonics - reference.harmonics)) <= 1e-12 * np.max(np.abs(reference.harmonics))


@pytest.mark.parametrize(
    "mass, message",
    [
        (np.eye(2), "mass: expected shape \\(3, 3\\) for 3 DOFs, got \\(2, 2\\)"),
        (np.ones(3), "mass: expected a 2-D matrix"),
        (np.eye(3).astype(complex), "mass: expected real numbers .* dtype complex128"),
        (np.diag([1.0, np.nan, 1.0]), "mass\\[1\\]\\[1\\]: must be a finite number"),
        (np.eye(3, dtype=bool), "dtype bool"),
    ],
)
def test_bad_matrices_are_named(mass, message):
    doc, m = chain_matrices()
    with pytest.raises(hbal.InputError, match=message):
        hbal.scene_from_matrices(doc["dofs"], mass, stiffness=m["stiffness"])
