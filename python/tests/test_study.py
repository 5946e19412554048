"""Studies: variants, the tidy table (its numbers are the analyses'), failure records,
interruption and resumption, a Dask cluster that loses a worker, percentile bands."""

import os
import signal

import hbal
import numpy as np
import pandas as pd
import pytest
from hbal import study, variants as v

from conftest import assert_bitwise_equal, scene_path, without_times

SPEEDS = [5000.0, 7000.0]
QUANTITIES = ["gear", "u(mesh)"]
ORDERS = [4.0, 8.0]


@pytest.fixture(scope="module")
def two_shaft():
    return hbal.Scene.load(scene_path("two_shaft_6000rpm.toml"))


def mesh_variants(scene, n, seed=3):
    spreads = {"elements[0].profile.one_tooth": 0.1, "elements[0].profile.two_tooth": 0.1}
    return v.latin_hypercube(v.around(scene, spreads), n, seed=seed)


def run(scene, variants, **kw):
    return study.run(scene, variants, speeds=SPEEDS, quantities=QUANTITIES, orders=ORDERS, **kw)


def test_variants_grid_hypercube_and_monte_carlo(two_shaft):
    assert len(v.grid({"a": [1, 2, 3], "b": [4, 5]})) == 6
    d = v.around(two_shaft, {"elements[0].profile.one_tooth": 0.1})
    assert d["elements[0].profile.one_tooth"] == v.Uniform(225000.0, 275000.0)
    lhs = v.latin_hypercube(d, 50, seed=1)
    strata = sorted(int((x["elements[0].profile.one_tooth"] - 225000.0) / 1000.0) for x in lhs)
    assert strata == list(range(50))  # one sample in each of the 50 strata
    assert v.monte_carlo(d, 5, seed=7) == v.monte_carlo(d, 5, seed=7)
    normal = v.Normal(1.0, 0.1, 0.8, 1.2).ppf(np.array([0.0, 0.5, 1.0]))
    assert normal[1] == 1.0 and normal[0] == 0.8 and normal[2] == 1.2
    with pytest.raises(KeyError, match="no field `stiffness`"):
        v.around(two_shaft, {"elements[0].stiffness": 0.1})


def test_the_table_holds_the_analyses_numbers(two_shaft):
    variants = mesh_variants(two_shaft, 12)
    table = run(two_shaft, variants)
    assert len(table) == 12 * len(SPEEDS) * len(QUANTITIES) * len(ORDERS)
    assert (table["status"] == "ok").all() and table["stable"].all()
    # Variant 5 at 7000 rpm, solved directly:
    direct = hbal.solve(two_shaft.with_parameters(variants[5]).with_parameter("fundamental.rpm", 7000))
    row = table[(table.variant == 5) & (table.speed == 7000) & (table.quantity == "u(mesh)") & (table.order == 8)]
    q = direct.element("mesh")["coordinate"]["harmonics"][2]
    assert row["amplitude"].item() == abs(q) and row["phase"].item() == np.angle(q)
    assert row["error_estimate"].item() == direct.error_estimate
    assert row["elements[0].profile.one_tooth"].item() == variants[5]["elements[0].profile.one_tooth"]


def test_failed_variants_are_recorded_with_their_reason(two_shaft):
    good = mesh_variants(two_shaft, 3)
    variants = [good[0], {"elements[0].profile.three_tooth": 1.0}, good[1], {"elements[0].profile.one_tooth": -5.0}]
    table = run(two_shaft, variants)
    failed = table[table.status == "failed"]
    assert sorted(failed.variant.unique()) == [1, 3]
    assert len(failed[failed.variant == 1]) == 1  # nothing but its failure record
    assert "no field `three_tooth`" in failed[failed.variant == 1].reason.item()
    assert "one_tooth" in failed[failed.variant == 3].reason.iloc[0]
    assert len(table[table.status == "ok"]) == 2 * len(SPEEDS) * len(QUANTITIES) * len(ORDERS)


def test_bad_study_settings_are_refused(two_shaft):
    with pytest.raises(hbal.InputError, match="quantities: `crank`"):
        study.run(two_shaft, [{}], speeds=[6000], quantities=["crank"])
    with pytest.raises(hbal.InputError, match="either speeds"):
        study.run(two_shaft, [{}])


def test_an_interrupted_study_resumes_to_the_same_table(two_shaft, tmp_path):
    variants = mesh_variants(two_shaft, 40)
    reference = run(two_shaft, variants, chunk=2)

    def stop_half_way(done, total):
        if done >= total // 2:
            raise KeyboardInterrupt

    out = tmp_path / "study"
    with pytest.raises(KeyboardInterrupt):
        run(two_shaft, variants, out=out, chunk=2, progress=stop_half_way)
    partial = study.load(out)
    assert 0 < partial.variant.nunique() < 40
    resumed_counts = []
    table = run(two_shaft, variants, out=out, chunk=2, progress=lambda d, t: resumed_counts.append(d))
    assert resumed_counts[0] == partial.variant.nunique()  # it started where it stopped
    pd.testing.assert_frame_equal(table, reference, check_exact=True)
    # Another study in the same directory is refused.
    with pytest.raises(hbal.InputError, match="another scene, variants or settings"):
        run(two_shaft, variants[:10], out=out)


def test_a_dask_cluster_that_loses_a_worker_gives_every_variant_once(two_shaft):
    distributed = pytest.importorskip("distributed")
    variants = mesh_variants(two_shaft, 120)
    reference = run(two_shaft, variants, chunk=2)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            pids = list(client.run(os.getpid).values())
            killed = []

            def kill_one_half_way(done, total):
                if done >= total // 2 and not killed:
                    os.kill(pids[0], signal.SIGKILL)
                    killed.append(done)

            table = run(two_shaft, variants, executor=client.get_executor(), chunk=2, progress=kill_one_half_way)
    assert killed and killed[0] < 120
    assert table.variant.nunique() == 120 and not table.duplicated(["variant", "speed", "quantity", "order"]).any()
    pd.testing.assert_frame_equal(table, reference, check_exact=True)


def test_percentile_bands_and_their_plot(two_shaft, tmp_path):
    table = run(two_shaft, mesh_variants(two_shaft, 30))
    bands = hbal.percentile_bands(table, "u(mesh)", 4.0)
    assert list(bands.index) == SPEEDS and (bands["count"] == 30).all()
    at = table[(table.quantity == "u(mesh)") & (table.order == 4.0) & (table.speed == 5000)]
    assert bands.loc[5000.0, "p50"] == np.median(at.amplitude)
    assert bands.loc[5000.0, "p5"] < bands.loc[5000.0, "p50"] < bands.loc[5000.0, "p95"]
    path = tmp_path / "bands.svg"
    hbal.plot_bands(table, "u(mesh)", [4.0, 8.0], path, unit="rpm")
    assert path.read_text().startswith("<?xml") and path.stat().st_size > 5000


def test_a_study_of_sweeps_gives_the_transmission_error_from_the_dofs():
    """u(mesh) of a swept variant is w·q of its DOFs' harmonics: the element coordinate a
    solve at the same speed reports."""
    scene = hbal.Scene.load(scene_path("free_free_drivetrain.toml"))
    table = study.run(scene, [{}], sweep_to=3000.0, sweep_from=1000.0, quantities=["u(mesh)", "pinion"], orders=[20.0])
    assert (table.status == "ok").all()
    te = table[table.quantity == "u(mesh)"]
    row = te.iloc[len(te) // 2]
    direct = hbal.solve(scene.with_parameter("fundamental.rpm", row.speed), stability=False)
    k = int(np.flatnonzero(np.isclose(direct.orders, 20.0))[0])
    expected = abs(direct.element("mesh")["coordinate"]["harmonics"][k])
    assert abs(row.amplitude - expected) <= 1e-6 * expected
    with pytest.raises(hbal.InputError, match="f\\(mesh\\)"):
        study.run(scene, [{}], sweep_to=3000.0, quantities=["f(mesh)"])


def test_a_threaded_study_keeps_each_task_on_one_thread_and_leaves_the_caller_alone(two_shaft):
    import concurrent.futures as cf

    from hbal import _hbal

    variants = mesh_variants(two_shaft, 6)
    with cf.ThreadPoolExecutor(2) as pool:
        threaded = run(two_shaft, variants, executor=pool)
    # The limit is the task's thread's own, undone after it; the environment is untouched.
    assert _hbal.limit_threads_here(None) is None
    assert "HBAL_THREADS" not in os.environ
    # One thread or two for the stability's products: the same numbers to the bit.
    scene = two_shaft.with_parameters(variants[2])
    before = _hbal.limit_threads_here(1)
    one = hbal.solve(scene)
    _hbal.limit_threads_here(before)
    two = hbal.solve(scene)
    assert_bitwise_equal(without_times(one.record), without_times(two.record))
    assert pd.testing.assert_frame_equal(threaded, run(two_shaft, variants), check_exact=True) is None
