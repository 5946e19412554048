"""The Python package's costs and the study's must-shows, measured in one run (medians; the
machine is shared, so ratios within a run are what counts):

1. the binding's overhead around a two-shaft solve, against the library call alone;
2. a vectorised Python Duffing law against the built-in `cubic_spring` on a 1-DOF sweep;
3. a study of N variants (default 2000) on a Dask LocalCluster: 2 worker processes against 1,
   one worker killed half way (every variant exactly once), and the study interrupted half
   way and resumed (the same table).

Run from the repository's root: `python python/examples/benchmark.py [--variants N]`.
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import tempfile
import time

import numpy as np

import hbal
from hbal import study, variants as v

SCENES = os.path.join(os.path.dirname(__file__), "..", "..", "examples", "scenes")


def median_time(f, repeats):
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return float(np.median(times))


def overhead(rows):
    scene = hbal.Scene.load(os.path.join(SCENES, "two_shaft_6000rpm.toml"))
    wall, library = [], []
    for _ in range(600):
        t = time.perf_counter()
        r = hbal.solve(scene)
        wall.append(time.perf_counter() - t)
        library.append(r.library_seconds)
        del r
    w, lib = np.median(wall[100:]), np.median(library[100:])
    extra = np.median(np.array(wall[100:]) - np.array(library[100:]))
    rows.append(("two-shaft solve: hbal.solve wall time", f"{w * 1e3:.3f} ms", ""))
    rows.append(("  the library's call alone (the CLI's solve)", f"{lib * 1e3:.3f} ms", ""))
    rows.append(("  binding overhead", f"{extra * 1e6:.1f} us = {extra / lib * 100:.1f} %", "<= 5 %"))
    reads = []
    for _ in range(200):
        r = hbal.solve(scene)
        t = time.perf_counter()
        r.record
        reads.append(time.perf_counter() - t)
    rows.append(("  reading the record (614 values, once)", f"{np.median(reads) * 1e6:.0f} us", ""))
    cli = os.path.join(os.path.dirname(__file__), "..", "..", "target", "release", "hbal")
    if os.path.exists(cli):
        path = os.path.join(SCENES, "two_shaft_6000rpm.toml")
        p = median_time(lambda: subprocess.run([cli, "solve", path, "--json"], capture_output=True, check=False), 30)
        rows.append(("  the CLI as a process (`hbal solve --json`)", f"{p * 1e3:.2f} ms", ""))


def duffing(theta, u, du):
    """f = u + u³ (u * u rather than u**2: numpy's power is several times slower)."""
    u2 = u * u
    return u + u2 * u, 1.0 + 3.0 * u2, 0.0


def python_law(rows):
    builtin = hbal.Scene.load(os.path.join(SCENES, "duffing.toml"))
    doc = builtin.to_dict()
    doc["elements"][0] = {"name": "spring", "type": "python", "law": "duffing", "connects": {"x": 1.0}}
    mine = hbal.Scene(doc, laws={"duffing": duffing})
    for label, kw in (("no stability", {"stability": False}), ("Floquet stability (exact orbit)", {})):
        a = median_time(lambda: hbal.sweep(builtin, 2.6, start=0.5, **kw), 7)
        b = median_time(lambda: hbal.sweep(mine, 2.6, start=0.5, **kw), 7)
        rows.append((f"1-DOF Duffing sweep, {label}: built-in / Python law", f"{a * 1e3:.1f} / {b * 1e3:.1f} ms = {b / a:.1f}x", "<= 3x"))


SPEEDS = [4000.0, 5000.0, 6000.0, 7000.0, 8000.0]


def the_study(scene, variants, **kw):
    return study.run(scene, variants, speeds=SPEEDS, quantities=["gear", "u(mesh)"], orders=[4, 8], **kw)


def studies(rows, n):
    from dask.distributed import Client, LocalCluster

    scene = hbal.Scene.load(os.path.join(SCENES, "two_shaft_6000rpm.toml"))
    spreads = {"elements[0].profile.one_tooth": 0.1, "elements[0].profile.two_tooth": 0.1, "elements[0].damping.proportional": 0.3}
    variants = v.latin_hypercube(v.around(scene, spreads), n, seed=11)
    seconds, tables = {}, {}
    for workers in (1, 2):
        with LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, Client(cluster) as client:
            # The best of three runs: the machine is shared (the first also starts the workers).
            for _ in range(3):
                t = time.perf_counter()
                tables[workers] = the_study(scene, variants, executor=client.get_executor())
                seconds[workers] = min(seconds.get(workers, np.inf), time.perf_counter() - t)
    assert tables[1].equals(tables[2])
    rows.append((f"study of {n} variants x {len(SPEEDS)} speeds (two-shaft solves), Dask LocalCluster: 1 / 2 workers", f"{seconds[1]:.1f} / {seconds[2]:.1f} s = {seconds[1] / seconds[2]:.2f}x", ">= 1.8x"))
    # One worker killed half way.
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, Client(cluster) as client:
        pids = list(client.run(os.getpid).values())
        killed = []

        def kill(done, total):
            if done >= total // 2 and not killed:
                os.kill(pids[0], signal.SIGKILL)
                killed.append(done)

        table = the_study(scene, variants, executor=client.get_executor(), progress=kill)
    once = table.variant.nunique() == n and not table.duplicated(["variant", "speed", "quantity", "order"]).any()
    rows.append((f"  a worker killed after {killed[0]} variants", f"{table.variant.nunique()} variants, duplicates: {not once}, table {'equal' if table.equals(tables[1]) else 'DIFFERENT'}", f"exactly {n}"))
    # Interrupted half way, resumed.
    with tempfile.TemporaryDirectory() as out:

        def stop(done, total):
            if done >= total // 2:
                raise KeyboardInterrupt

        try:
            the_study(scene, variants, out=out, chunk=20, progress=stop)
        except KeyboardInterrupt:
            pass
        written = study.load(out).variant.nunique()
        resumed = the_study(scene, variants, out=out, chunk=20)
    rows.append((f"  interrupted after {written} variants, resumed", f"{resumed.variant.nunique()} variants, table {'equal' if resumed.equals(tables[1]) else 'DIFFERENT'}", "the same table"))
    return seconds


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--variants", type=int, default=2000)
    args = parser.parse_args()
    rows = []
    overhead(rows)
    python_law(rows)
    studies(rows, args.variants)
    print(f"| measured (hbal {hbal.__version__}, Python {sys.version.split()[0]}, {os.cpu_count()} cores) | value | target |")
    print("|---|---|---|")
    for r in rows:
        print(f"| {r[0]} | {r[1]} | {r[2]} |")


if __name__ == "__main__":
    main()
