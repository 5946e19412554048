"""Every result of the Python package equals the Rust library's, as the command line prints
it (`hbal ... --json`), to the last bit: the same analysis runs, and its record crosses into
Python number by number."""

import hbal
import pytest

from conftest import assert_bitwise_equal, scene_path, without_times

SOLVES = [
    "duffing.toml",
    "two_shaft_6000rpm.toml",
    "gear_backlash.toml",
    "free_free_drivetrain.toml",
    "nlvib_07_jenkins.toml",
    "two_stage_train_torus.toml",
]


@pytest.mark.parametrize("name", SOLVES)
def test_solve_equals_the_command_line(cli, name):
    path = scene_path(name)
    expected, code = cli("solve", path)
    result = hbal.solve(hbal.Scene.load(path))
    assert result.exit_code == code
    assert_bitwise_equal(without_times(result.record), without_times(expected))


def test_solve_with_overrides_equals_the_command_line(cli):
    path = scene_path("two_shaft_6000rpm.toml")
    expected, code = cli("solve", path, "--harmonics", "16", "--method", "anderson", "--no-stability")
    result = hbal.solve(hbal.Scene.load(path), harmonics=16, method="anderson", stability=False)
    assert code == result.exit_code == 0
    assert result.record["harmonics"] == 16 and result.stable is None
    assert_bitwise_equal(without_times(result.record), without_times(expected))


def test_sweep_equals_the_command_line(cli):
    path = scene_path("duffing.toml")
    expected, code = cli("sweep", path, "--from", "0.5", "--to", "2.6")
    result = hbal.sweep(hbal.Scene.load(path), 2.6, start=0.5)
    assert result.exit_code == code == 0
    assert result.record["folds"] == 2
    assert_bitwise_equal(without_times(result.record), without_times(expected))


def test_torus_sweep_equals_the_command_line(cli):
    path = scene_path("two_stage_train_torus.toml")
    expected, code = cli("sweep", path, "--from", "1000", "--to", "1200", "--points", "3")
    result = hbal.sweep(hbal.Scene.load(path), 1200, start=1000, points=3)
    assert isinstance(result, hbal.TorusSweepResult)
    assert result.exit_code == code
    assert_bitwise_equal(without_times(result.record), without_times(expected))


def test_parameter_sweep_equals_the_command_line(cli):
    path = scene_path("duffing.toml")
    expected, code = cli("sweep", path, "--parameter", "elements[0].alpha", "--from", "0.5", "--to", "1.5", "--points", "5")
    result = hbal.parameter_sweep(hbal.Scene.load(path), "elements[0].alpha", 0.5, 1.5, points=5)
    assert result.exit_code == code == 0
    assert_bitwise_equal(without_times(result.record), without_times(expected))


def test_modes_equal_the_command_line(cli):
    path = scene_path("free_free_drivetrain.toml")
    expected, code = cli("modes", path, "--from", "800", "--to", "6000")
    result = hbal.modes(hbal.Scene.load(path), start=800, to=6000)
    assert result.exit_code == code == 0
    assert_bitwise_equal(without_times(result.record), without_times(expected))


def test_compare_equals_the_command_line(cli):
    path = scene_path("duffing.toml")
    expected, code = cli("compare", path)
    result = hbal.compare(hbal.Scene.load(path))
    assert result.exit_code == code
    assert_bitwise_equal(without_times(result.record), without_times(expected))


def test_the_numpy_views_are_the_records_numbers():
    result = hbal.solve(hbal.Scene.load(scene_path("two_shaft_6000rpm.toml")))
    dof = result.record["dofs"][0]
    q = result.harmonics
    assert q.shape == (1, result.record["harmonics"] + 1)
    for k, h in enumerate(dof["harmonics"]):
        assert q[0, k].real == h["cos"] and q[0, k].imag == -h["sin"]
    # The time series is the harmonics' sum; its extremes are those the library reports (up
    # to the sampling of the peak: the mesh stiffness jumps, so the peak is a corner).
    t, x = result.time_series(4096)
    assert abs(t[1] - t[0] - 2 * 3.141592653589793 / result.fundamental_rad_s / 4096) < 1e-15
    assert 0 <= result.max_abs[0] - x.max() < 1e-5 * result.max_abs[0]
    moduli = result.record["stability"]["moduli"]
    assert sorted(abs(result.multipliers)) == pytest.approx(sorted(moduli), rel=1e-15)


def test_a_guess_is_the_command_lines_start_file(cli, tmp_path):
    """`guess=` a previous result is `--start FILE` with that result's JSON."""
    path = scene_path("gear_backlash.toml")
    first = hbal.solve(hbal.Scene.load(path), harmonics=16)
    start = tmp_path / "start.json"
    start.write_text(first.to_json())
    expected, code = cli("solve", path, "--start", str(start))
    result = hbal.solve(hbal.Scene.load(path), guess=first)
    assert result.exit_code == code and result.record["start"] == "guess"
    expected["start"] = "guess"  # the label: the file's name there
    assert_bitwise_equal(without_times(result.record), without_times(expected))
    swept, code = cli("sweep", path, "--start", str(start), "--to", "1.2")
    branch = hbal.sweep(hbal.Scene.load(path), 1.2, guess=first.record)
    assert branch.exit_code == code
    assert_bitwise_equal(without_times(branch.record)["points"], without_times(swept)["points"])
    with pytest.raises(hbal.InputError, match="guess: DOF `x` is not in the scene"):
        hbal.solve(hbal.Scene.load(scene_path("two_shaft_6000rpm.toml")), guess={"dofs": [{"name": "x", "harmonics": [{"order": 1, "cos": 1.0, "sin": 0.0}]}]})
