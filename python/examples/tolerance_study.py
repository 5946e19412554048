"""A tolerance study of the free-free car drivetrain (examples/scenes/free_free_drivetrain.toml
with 50 um of backlash in its gear stage): mesh stiffness +-10 %, backlash 20 to 80 um, mesh
damping +-30 %, by Latin hypercube; every variant solved at the speeds of a run-up; the
percentile bands of the order cuts of the transmission error, written as an SVG, and the
table as Parquet (resumable: run it again with the same --out and it goes on where it stopped).

Run from the repository's root:
    python python/examples/tolerance_study.py [--variants 32] [--out out/tolerance_study] [--dask]
With --dask it runs on a Dask LocalCluster of 2 worker processes (client.get_executor(); a
dask-jobqueue SLURMCluster is used the same way), else on a local process pool.
"""

import argparse
import os
import time

import numpy as np

import hbal
from hbal import study, variants


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--variants", type=int, default=32)
    parser.add_argument("--out", default="out/tolerance_study")
    parser.add_argument("--dask", action="store_true")
    args = parser.parse_args()

    nominal = hbal.Scene.load("examples/scenes/free_free_drivetrain.toml")
    doc = nominal.to_dict()
    mesh = doc["elements"].index(next(e for e in doc["elements"] if e["name"] == "mesh"))
    doc["elements"][mesh]["backlash"] = 50e-6
    scene = hbal.Scene(doc, file=nominal.file)

    m = f"elements[{mesh}]"
    spread = variants.around(scene, {f"{m}.stiffness.one_tooth": 0.1, f"{m}.stiffness.two_tooth": 0.1, f"{m}.damping.proportional": 0.3})
    spread[f"{m}.backlash"] = variants.Uniform(20e-6, 80e-6)
    cases = variants.latin_hypercube(spread, args.variants, seed=2026)
    speeds = np.arange(1000.0, 6001.0, 250.0)
    orders = [1.0, 2.0, 3.0, 20.0]  # engine orders and the mesh order (20 teeth on the pinion at engine speed)

    def run(executor=None):
        def progress(done, total):
            print(f"\r  {done}/{total} variants", end="", flush=True)

        table = study.run(scene, cases, speeds=speeds, quantities=["u(mesh)", "vehicle"], orders=orders,
                          out=os.path.join(args.out, "table"), executor=executor, progress=progress)
        print()
        return table

    start = time.perf_counter()
    if args.dask:
        from dask.distributed import Client, LocalCluster

        with LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None) as cluster, Client(cluster) as client:
            table = run(client.get_executor())
    else:
        table = run()
    seconds = time.perf_counter() - start
    failed = table[table.status == "failed"]
    print(f"{table.variant.nunique()} variants x {len(speeds)} speeds in {seconds:.1f} s; "
          f"{len(failed)} failed solves" + (f", e.g. {failed.reason.iloc[0]}" if len(failed) else ""))

    for order in (2.0, 20.0):
        bands = hbal.percentile_bands(table, "u(mesh)", order)
        worst = bands["p95"].idxmax()
        print(f"transmission error, order {order:g}: p5/p50/p95 at {worst:.0f} rpm = "
              f"{bands.loc[worst, 'p5']:.2e} / {bands.loc[worst, 'p50']:.2e} / {bands.loc[worst, 'p95']:.2e} m")
    path = os.path.join(args.out, "transmission_error_bands.svg")
    hbal.plot_bands(table, "u(mesh)", [2.0, 20.0], path, unit="rpm")
    print("wrote", path, "and", os.path.join(args.out, "table"))


# Dask's workers (and a process pool under spawn) import this module: the work runs only here.
if __name__ == "__main__":
    main()
