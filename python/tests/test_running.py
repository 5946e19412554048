"""Long analyses from Python: the GIL is released while they run, progress reaches a
callback, an interruption stops a sweep cleanly, marked results keep their exit code."""

import threading
import time

import hbal
import pytest

from conftest import scene_path


def test_progress_reaches_the_callback():
    seen = []
    result = hbal.sweep(hbal.Scene.load(scene_path("duffing.toml")), 2.6, start=0.5, progress=lambda f, stage: seen.append((f, stage)))
    assert result.ok and len(seen) >= 10
    fractions = [f for f, _ in seen]
    assert 0.0 <= min(fractions) and max(fractions) <= 1.0 and fractions[-1] > 0.9


@pytest.mark.parametrize("error", [KeyboardInterrupt, RuntimeError])
def test_an_interruption_stops_the_sweep_and_is_raised(error):
    """Ctrl-C arrives as KeyboardInterrupt at the next progress report (signals are checked
    there); an exception of the callback itself stops the sweep the same way."""
    calls = []

    def stop_half_way(fraction, stage):
        calls.append(fraction)
        if fraction > 0.5:
            raise error("stop")

    scene = hbal.Scene.load(scene_path("duffing.toml"))
    with pytest.raises(error, match="stop"):
        hbal.sweep(scene, 2.6, start=0.5, progress=stop_half_way)
    # It stopped at once: no report after the one that raised.
    assert calls[-1] > 0.5 and all(f <= 0.5 for f in calls[:-1])


def test_the_gil_is_released_during_a_sweep():
    """Another Python thread keeps running while a sweep is in Rust."""
    scene = hbal.Scene.load(scene_path("free_free_drivetrain.toml"))
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    t = threading.Thread(target=count)
    t.start()
    start = time.perf_counter()
    try:
        hbal.sweep(scene, 3000, start=800, stability=False)
    finally:
        done.set()
        t.join()
    elapsed = time.perf_counter() - start
    during = [x for x in ticks if start < x < start + elapsed]
    assert elapsed > 0.05 and len(during) > 0.2 * elapsed / 0.001, (elapsed, len(during))


def test_a_solve_that_does_not_converge_is_returned_marked():
    scene = hbal.Scene.load(scene_path("two_shaft_6000rpm.toml"))
    result = hbal.solve(scene, method="fixed_point", fallback=False, stability=False)
    assert not result.converged and result.exit_code == 1 and not result.ok
    assert result.termination


def test_bad_options_are_input_errors_before_any_work():
    scene = hbal.Scene.load(scene_path("duffing.toml"))
    with pytest.raises(hbal.InputError, match="harmonics"):
        hbal.solve(scene, harmonics="many")
    with pytest.raises(hbal.InputError, match="formulation"):
        hbal.solve(scene, formulation="dense")
    with pytest.raises(hbal.InputError, match="points"):
        hbal.sweep(scene, 2.0, points=1)
    with pytest.raises(hbal.InputError, match="`to` must be a finite speed"):
        hbal.sweep(scene, float("nan"))
    with pytest.raises(hbal.InputError, match="stability_orbit"):
        hbal.sweep(scene, 2.0, stability_orbit="hill")
    with pytest.raises(hbal.InputError):
        hbal.solve(scene, method="magic")


def test_ctrl_c_stops_a_long_sweep():
    """SIGINT (here from a timer thread, as Ctrl-C would) stops the sweep at its next point."""
    import _thread

    scene = hbal.Scene.load(scene_path("free_free_drivetrain.toml"))
    timer = threading.Timer(0.05, _thread.interrupt_main)
    start = time.perf_counter()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            hbal.sweep(scene, 6000, start=800)
    finally:
        timer.cancel()
    assert time.perf_counter() - start < 5.0
