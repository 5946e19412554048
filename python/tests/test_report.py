"""`out=` and `hbal.report`: the files the command line's `--out DIR` and `hbal report`
write, from the same library code: every CSV and SVG equal to the byte, the page with the
same sections; bad input refused before anything is written."""

from __future__ import annotations

import filecmp
import os
import subprocess
from pathlib import Path

import pytest

import hbal
from conftest import REPO, scene_path


def cli_out(hbal_bin, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run([hbal_bin, *args], capture_output=True, text=True, cwd=REPO)


def files_of(directory: Path) -> list[str]:
    return sorted(str(p.relative_to(directory)) for p in directory.rglob("*") if p.is_file())


def assert_same_files(ours: Path, theirs: Path, skip=("report.html",)) -> None:
    names = files_of(ours)
    assert names == files_of(theirs)
    compared = [n for n in names if Path(n).name not in skip]
    assert compared, "nothing to compare"
    _, mismatch, errors = filecmp.cmpfiles(ours, theirs, compared, shallow=False)
    assert not mismatch and not errors, (mismatch, errors)


@pytest.mark.parametrize(
    ("analysis", "args", "call"),
    [
        ("solve", [], lambda s, out: hbal.solve(s, out=out)),
        ("sweep", ["--to", "0.9"], lambda s, out: hbal.sweep(s, 0.9, out=out)),
        ("modes", [], lambda s, out: hbal.modes(s, out=out)),
        ("compare", ["--method", "newton"], lambda s, out: hbal.compare(s, methods="newton", out=out)),
    ],
)
def test_out_writes_the_files_of_the_command_line(tmp_path, hbal_bin, analysis, args, call):
    path = scene_path("gear_backlash.toml")
    run = cli_out(hbal_bin, analysis, path, *args, "--out", str(tmp_path / "cli"))
    assert run.returncode == 0, run.stderr
    result = call(hbal.Scene.load(path), tmp_path / "py")
    assert result.exit_code == 0
    assert_same_files(tmp_path / "py", tmp_path / "cli")


def test_parameter_sweep_out_writes_the_files_of_the_command_line(tmp_path, hbal_bin):
    path = scene_path("duffing.toml")
    args = ["--parameter", "fundamental.rad_s", "--from", "0.8", "--to", "1.2", "--points", "9"]
    run = cli_out(hbal_bin, "sweep", path, *args, "--out", str(tmp_path / "cli"))
    assert run.returncode == 0, run.stderr
    r = hbal.parameter_sweep(hbal.Scene.load(path), "fundamental.rad_s", 0.8, 1.2, points=9, out=tmp_path / "py")
    assert r.exit_code == 0
    assert_same_files(tmp_path / "py", tmp_path / "cli")
    assert "parameter_response_x.svg" in files_of(tmp_path / "py")


def test_report_writes_the_page_and_the_files_of_the_command_line(tmp_path, hbal_bin):
    path = scene_path("gear_backlash.toml")
    run = cli_out(hbal_bin, "report", path, "--to", "0.9", "--out", str(tmp_path / "cli"))
    assert run.returncode == 0, run.stderr
    stages = []
    r = hbal.report(path, tmp_path / "py", to=0.9, progress=lambda f, stage: stages.append(stage))
    assert (r.exit_code, r.errors, r.warnings) == (0, [], [])
    assert r.path == tmp_path / "py" / "report.html"
    assert_same_files(tmp_path / "py", tmp_path / "cli")
    assert {"solve/harmonics.csv", "sweep/order_cuts.csv", "modes/campbell.svg"} <= set(files_of(tmp_path / "py"))
    page, theirs = r.path.read_text(), (tmp_path / "cli" / "report.html").read_text()
    headings = lambda html: [line for line in html.splitlines() if line.startswith("<h2")]
    assert headings(page) == headings(theirs) and len(headings(page)) >= 4
    assert page.count("<svg") == theirs.count("<svg") >= 5
    assert stages[0].startswith("solving") and "natural frequencies" in stages
    assert any(s.startswith("run-up to 0.9") for s in stages)


def test_report_of_a_torus_scene(tmp_path):
    r = hbal.report(scene_path("two_stage_train_torus.toml"), tmp_path)
    assert r.exit_code == 0, r.errors
    page = r.path.read_text()
    assert "several base frequencies" in page or "Element" in page
    assert (tmp_path / "solve" / "lines.csv").exists()


def test_bad_report_input_is_refused_before_anything_is_written(tmp_path):
    scene = hbal.Scene.load(scene_path("gear_backlash.toml"))
    for kwargs, says in [
        (dict(to=-1.0), "`to` must be"),
        (dict(start=0.5), "`start` needs `to`"),
        (dict(to=0.9, output="nothing"), "nothing"),
    ]:
        out = tmp_path / "r"
        with pytest.raises(hbal.InputError, match=says):
            hbal.report(scene, out, **kwargs)
        assert not (out / "report.html").exists()
    blocker = tmp_path / "file"
    blocker.write_text("")
    with pytest.raises(hbal.InputError, match="cannot create the directory"):
        hbal.report(scene, blocker / "sub")
    with pytest.raises(hbal.InputError, match="out: expected a directory path"):
        hbal.solve(scene, out=3)
    (tmp_path / "s" / "spectrum.svg").mkdir(parents=True)
    with pytest.raises(hbal.InputError, match="is a directory where hbal writes a file"):
        hbal.solve(scene, out=tmp_path / "s")
    assert not (tmp_path / "s" / "harmonics.csv").exists()


def test_a_failed_part_is_in_the_page_and_the_errors(tmp_path):
    # The gear pair without mean load: its contact never closes, the mean position is free
    # (a singular Jacobian): the solve fails, the page says so, exit code 1.
    doc = hbal.Scene.load(scene_path("gear_backlash.toml")).to_dict()
    doc["loads"][0]["cos"] = 0.0
    doc["solver"] = {"method": "newton"}
    r = hbal.report(hbal.Scene.from_dict(doc), tmp_path)
    assert r.exit_code == 1
    assert any("did not converge" in e for e in r.errors), r.errors
    assert "did not converge" in r.path.read_text() or "NOT CONVERGED" in r.path.read_text()


def test_a_torus_report_refuses_bad_speeds_before_any_work(tmp_path):
    scene = hbal.Scene.load(scene_path("two_stage_train_torus.toml"))
    for kwargs, says in [(dict(to=-1.0), "`to` must be a finite speed"), (dict(to=3000.0, start=0.0), "`start` must be")]:
        with pytest.raises(hbal.InputError, match=says):
            hbal.report(scene, tmp_path / "t", **kwargs)
        assert not (tmp_path / "t").exists()


def test_a_cancelled_report_writes_no_page(tmp_path):
    def fail(fraction, stage):
        if stage.startswith("sweep") or fraction > 0:
            raise ZeroDivisionError("stop here")

    with pytest.raises(ZeroDivisionError, match="stop here"):
        hbal.report(scene_path("gear_backlash.toml"), tmp_path, to=2.0, progress=fail)
    assert not (tmp_path / "report.html").exists()
    assert not (tmp_path / "modes" / "modes.csv").exists()


def test_modes_of_an_unconverged_operating_point_are_marked(tmp_path):
    doc = hbal.Scene.load(scene_path("gear_backlash.toml")).to_dict()
    doc["loads"][0]["cos"] = 0.0
    doc["solver"] = {"method": "newton"}
    r = hbal.modes(hbal.Scene.from_dict(doc), out=tmp_path)
    assert r.exit_code == 1 and not r.ok
    assert list(tmp_path.iterdir()) == []


def test_out_paths_that_cannot_be_used(tmp_path):
    scene = hbal.Scene.load(scene_path("duffing.toml"))
    for bad, says in [("", "empty path"), ("a\0b", "NUL")]:
        with pytest.raises(hbal.InputError, match=says):
            hbal.solve(scene, out=bad)
    r = hbal.solve(scene, out=os.fsencode(str(tmp_path / "bytes")))
    assert (tmp_path / "bytes" / "harmonics.csv").exists() and r.exit_code == 0


def test_the_report_run_up_resolution(tmp_path, hbal_bin):
    path = scene_path("gear_backlash.toml")
    run = cli_out(hbal_bin, "report", path, "--to", "0.9", "--max-step", "0.1", "--out", str(tmp_path / "cli"))
    assert run.returncode == 0, run.stderr
    r = hbal.report(path, tmp_path / "py", to=0.9, max_step=0.1)
    assert r.exit_code == 0
    assert_same_files(tmp_path / "py", tmp_path / "cli")
    coarse = hbal.report(path, tmp_path / "coarse", to=0.9)
    rows = lambda d: len((d / "sweep" / "branch.csv").read_text().splitlines())
    assert rows(tmp_path / "py") > rows(tmp_path / "coarse") and coarse.exit_code == 0
    with pytest.raises(hbal.InputError, match="`max_step`"):
        hbal.report(path, tmp_path / "bad", to=0.9, max_step=0.0)
    with pytest.raises(hbal.InputError, match="points"):
        hbal.report(path, tmp_path / "bad", to=0.9, max_points=0)
    assert not (tmp_path / "bad").exists()
