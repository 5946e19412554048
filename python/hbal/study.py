"""Studies: many independent analyses of variants of one scene, through any
``concurrent.futures.Executor`` — a local process pool by default, a Dask client's
(``client.get_executor()``: a LocalCluster, or dask-jobqueue's Slurm cluster) for many machines.

The result is one tidy table, a row per variant, speed, quantity and order: ``variant``, the
varied fields (one column per path), ``speed`` (the scene's unit), ``quantity`` (a DOF, or
``u(element)``/``f(element)``: an element's coordinate, e.g. a gear stage's transmission error,
or its force, which only solves at ``speeds`` give), ``order`` (shaft order), ``amplitude``, ``phase`` (rad, of ``c − i s``),
``stable``, ``error_estimate``, ``status`` (``ok`` or ``failed``) and ``reason``. A variant that
fails (a field the scene does not have, a law that raises, a solve that does not converge, a
branch that stops) has a row with ``status == "failed"`` and the reason, never dropped.

With ``out`` the rows are written to Parquet as tasks finish (``part-*.parquet``, each written
once, atomically): a study that is interrupted resumes where it stopped with the same call,
and a task a killed worker had started is redone by the executor and written once.
"""

from __future__ import annotations

import concurrent.futures as cf
import hashlib
import json
import os
from typing import Any, Callable, Mapping, Sequence

import numpy as np

from . import _hbal
from .analyses import solve, sweep
from .scene import Scene

COLUMNS = ["speed", "quantity", "order", "amplitude", "phase", "stable", "error_estimate", "status", "reason"]


def run(
    scene: Scene,
    variants: Sequence[Mapping[str, float]],
    *,
    speeds: Sequence[float] | None = None,
    sweep_to: float | None = None,
    sweep_from: float | None = None,
    quantities: Sequence[str] | None = None,
    orders: Sequence[float] | None = None,
    options: Mapping[str, Any] | None = None,
    out: str | os.PathLike | None = None,
    executor: cf.Executor | None = None,
    chunk: int | None = None,
    progress: Callable[[int, int], None] | None = None,
):
    """Runs every variant and returns the table (a pandas DataFrame).

    Each variant is solved at each of ``speeds`` (independent solves), or swept from
    ``sweep_from`` (default the scene's speed) to ``sweep_to``. ``quantities`` default to every
    DOF; ``orders`` to the first ten harmonics' shaft orders. ``options`` go to
    :func:`hbal.solve` or :func:`hbal.sweep`. ``chunk`` variants make one task (default: about
    sixteen tasks per worker, at most 25 variants a task). ``progress(done, total)`` counts variants."""
    import pandas as pd

    if not isinstance(scene, Scene):
        raise TypeError(f"scene: expected an hbal.Scene, got {type(scene).__name__}")
    if scene.on_torus:
        raise _hbal.InputError("studies of scenes on several base frequencies are not supported yet")
    if (speeds is None) == (sweep_to is None):
        raise _hbal.InputError("give either speeds (a solve at each) or sweep_to (a sweep per variant)")
    variants = _checked_variants(variants)
    paths = sorted({p for v in variants for p in v})
    if speeds is not None and f"fundamental.{scene.speed_unit}" in paths:
        raise _hbal.InputError(
            f"variants: `fundamental.{scene.speed_unit}` is the speed, which `speeds` sets; sweep it with speeds instead"
        )
    _check_options(options, sweep_to is not None)
    spec = {
        "speeds": None if speeds is None else [float(s) for s in speeds],
        "sweep": None if sweep_to is None else {"to": float(sweep_to), "start": None if sweep_from is None else float(sweep_from)},
        "quantities": list(quantities) if quantities is not None else list(scene.dofs),
        "orders": None if orders is None else [float(o) for o in orders],
        "options": dict(options or {}),
        "unit": scene.speed_unit,
        "paths": paths,
    }
    _check_quantities(scene, spec)
    store = _Store(out, scene, variants, spec) if out is not None else None
    todo = [i for i in range(len(variants)) if store is None or i not in store.done]
    own = executor is None
    if own:
        executor = cf.ProcessPoolExecutor()
    workers = _workers(executor)
    chunk = chunk or max(1, min(25, len(todo) // (16 * workers) or 1))
    payload = (scene.to_json(indent=None), scene.file, scene.laws, spec)
    parts: list = []
    done = len(variants) - len(todo)
    futures = {}
    try:
        for start in range(0, len(todo), chunk):
            items = [(i, variants[i]) for i in todo[start : start + chunk]]
            futures[executor.submit(run_chunk, payload, items)] = items
        if progress:
            progress(done, len(variants))
        for f in cf.as_completed(futures):
            part = f.result()
            if store is not None:
                store.write(futures[f], part)
            else:
                parts.append(part)
            done += len(futures[f])
            if progress:
                progress(done, len(variants))
    except BaseException:
        for f in futures:
            f.cancel()
        raise
    finally:
        if own:
            executor.shutdown(wait=True, cancel_futures=True)
    if store is not None:
        return store.table()
    return _sorted(pd.concat(parts, ignore_index=True)) if parts else _frame([], paths)


def _workers(executor) -> int:
    """How many tasks the executor runs at once: a pool's size, a Dask cluster's threads."""
    client = getattr(executor, "_client", None)
    if client is not None and hasattr(client, "nthreads"):
        try:
            return max(1, sum(client.nthreads().values()))
        except Exception:  # noqa: BLE001 - a client that cannot say: the local count
            pass
    return getattr(executor, "_max_workers", None) or os.cpu_count() or 1


def _checked_variants(variants) -> list[dict]:
    """Each variant a dict of field paths and finite real numbers (numpy numbers as floats)."""
    if hasattr(variants, "to_dict") and hasattr(variants, "columns"):
        variants = variants.to_dict("records")  # a pandas DataFrame: one variant per row
    checked = []
    for i, v in enumerate(variants):
        if not isinstance(v, Mapping):
            raise _hbal.InputError(f"variants[{i}]: expected a dict of field paths and numbers, got {type(v).__name__}")
        row = {}
        for path, x in v.items():
            if not isinstance(path, str):
                raise _hbal.InputError(f"variants[{i}]: field paths must be strings, got {path!r}")
            number = isinstance(x, (int, float, np.integer, np.floating)) and not isinstance(x, (bool, np.bool_))
            try:
                value = float(x) if number else np.nan
            except OverflowError:
                value = np.nan
            if not np.isfinite(value):
                raise _hbal.InputError(f"variants[{i}][{path!r}]: expected a finite number, got {x!r}")
            row[path] = value
        checked.append(row)
    return checked


def _check_options(options, sweeping: bool) -> None:
    """The options are those of :func:`hbal.sweep` or :func:`hbal.solve`, checked before any work."""
    import inspect

    target = sweep if sweeping else solve
    taken = {"to", "start", "progress"} if sweeping else set()
    bad = sorted(set(options or {}) & taken)
    if bad:
        raise _hbal.InputError(f"options: {bad} are set by the study (sweep_to, sweep_from)")
    try:
        inspect.signature(target).bind(None, *([0.0] if sweeping else []), **dict(options or {}))
    except TypeError as e:
        raise _hbal.InputError(f"options: {e} (the options of hbal.{target.__name__})") from e
    from .analyses import _count, _flag

    for name, value in (options or {}).items():
        if name in ("stability", "fallback", "all_branches", "error_estimate"):
            _flag(f"options[{name!r}]", value)
        elif name in ("samples", "points", "max_points"):
            _count(f"options[{name!r}]", value)
        elif name in ("tolerance", "max_step") and value is not None:
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value) or value <= 0:
                raise _hbal.InputError(f"options[{name!r}]: expected a finite number > 0, got {value!r}")


def load(out: str | os.PathLike):
    """The table of a study written to ``out`` (complete or not)."""
    import pandas as pd

    parts = sorted(p for p in os.listdir(out) if p.startswith("part-") and p.endswith(".parquet"))
    frames = [pd.read_parquet(os.path.join(out, p)) for p in parts]
    if not frames:
        return pd.DataFrame(columns=["variant", *COLUMNS])
    return _sorted(pd.concat(frames, ignore_index=True))


def _sorted(table):
    return table.sort_values(["variant", "speed", "quantity", "order"], kind="stable", na_position="first").reset_index(drop=True)


def _frame(rows: list[tuple], paths: Sequence[str]):
    import pandas as pd

    table = pd.DataFrame.from_records(rows, columns=["variant", *paths, *COLUMNS])
    table["variant"] = table["variant"].astype("int64")
    for c in (*paths, "speed", "order", "amplitude", "phase", "error_estimate"):
        table[c] = table[c].astype("float64")
    table["stable"] = table["stable"].astype("boolean")
    for c in ("quantity", "status", "reason"):
        table[c] = table[c].astype("string")
    return _sorted(table)


def _check_quantities(scene: Scene, spec: dict) -> None:
    dofs, elements = set(scene.dofs), set(scene.elements)
    for q in spec["quantities"]:
        element = q[2:-1] if q[:2] in ("u(", "f(") and q.endswith(")") else None
        if q in dofs or (element in elements and (spec["sweep"] is None or q.startswith("u("))):
            continue
        what = "a DOF or u(element)" if spec["sweep"] is not None else "a DOF, u(element) or f(element)"
        raise _hbal.InputError(f"quantities: `{q}` is not {what} of the scene (DOFs: {sorted(dofs)})")


class _Store:
    """The study's directory: its settings (``study.json``) and one Parquet part per task."""

    def __init__(self, out, scene: Scene, variants: list[dict], spec: dict) -> None:
        self.out = os.fspath(out)
        self.paths = spec["paths"]
        os.makedirs(self.out, exist_ok=True)
        # The laws by name and function (an edited law body is not seen: use another out then).
        laws = {n: f"{getattr(f, '__module__', '')}.{getattr(f, '__qualname__', repr(f))}" for n, f in scene.laws.items()}
        settings = {"scene": scene.to_dict(), "laws": laws, "variants": variants,
                    "spec": {**spec, "options": repr(spec["options"])}}
        digest = hashlib.sha256(json.dumps(settings, sort_keys=True).encode()).hexdigest()
        meta = os.path.join(self.out, "study.json")
        if os.path.exists(meta):
            with open(meta, encoding="utf-8") as f:
                if json.load(f).get("digest") != digest:
                    raise _hbal.InputError(
                        f"out: {self.out} holds a study of another scene, variants or settings; choose another directory or remove it"
                    )
        else:
            with open(meta, "w", encoding="utf-8") as f:
                json.dump({"digest": digest, "variants": len(variants), "paths": self.paths}, f)
        self.done = set(load(self.out)["variant"].astype(int).tolist())

    def write(self, items, part) -> None:
        ids = [i for i, _ in items]
        name = f"part-{min(ids):07d}-{max(ids):07d}"
        tmp = os.path.join(self.out, f".{name}.tmp")
        part.to_parquet(tmp, index=False)
        os.replace(tmp, os.path.join(self.out, name + ".parquet"))

    def table(self):
        return load(self.out)


def run_chunk(payload, items):
    """A task: the table of the variants ``items`` (pairs of index and fields), built where
    it runs (a DataFrame ships back in a few buffers, light for the client). A study runs one
    task per core, so each analysis keeps to its own (no second thread for the stability's
    products; on this thread only) unless ``HBAL_THREADS`` says otherwise; the results are
    the same to the bit either way."""
    limit = None if "HBAL_THREADS" in os.environ else 1
    before = _hbal.limit_threads_here(limit)
    try:
        text, file, laws, spec = payload
        base = Scene(json.loads(text), file=file, laws=laws)
        rows = []
        for index, fields in items:
            rows.extend(_variant_rows(base, index, fields, spec))
        return _frame(rows, spec["paths"])
    finally:
        _hbal.limit_threads_here(before)


def _head(index, fields, spec) -> tuple:
    return (index, *(fields.get(p, np.nan) for p in spec["paths"]))


def _failure(index, fields, speed, reason, spec) -> tuple:
    return (*_head(index, fields, spec), speed, None, np.nan, np.nan, np.nan, None, np.nan, "failed", reason)


def _variant_rows(base: Scene, index: int, fields: dict, spec: dict) -> list[tuple]:
    try:
        scene = base.with_parameters(fields)
    except (_hbal.InputError, KeyError, TypeError, ValueError) as e:
        return [_failure(index, fields, np.nan, f"{type(e).__name__}: {e}", spec)]
    rows: list[tuple] = []
    if spec["sweep"] is not None:
        try:
            branch = sweep(scene, spec["sweep"]["to"], start=spec["sweep"]["start"], **spec["options"])
        except (_hbal.InputError, _hbal.NumericalError) as e:
            return [_failure(index, fields, np.nan, f"{type(e).__name__}: {e}", spec)]
        dofs = branch.record["harmonics_dofs"]
        weights = scene._info["element_weights"]
        for p in branch.points:
            entries = {d: h for d, h in zip(dofs, p["harmonics"])}
            try:
                for q in spec["quantities"]:
                    if q not in entries:
                        entries[q] = _coordinate(q[2:-1], weights, entries, scene.dofs)
            except KeyError as e:
                return [_failure(index, fields, np.nan, str(e.args[0]), spec)]
            rows += _rows(index, fields, p["speed"], entries, spec, p["stable"], p["error_estimate"])
        if not branch.ok:
            rows.append(_failure(index, fields, np.nan, f"branch: {branch.stop}", spec))
        return rows
    for speed in spec["speeds"]:
        try:
            at = scene.with_parameter(f"fundamental.{spec['unit']}", speed)
            r = solve(at, **spec["options"])
        except (_hbal.InputError, _hbal.NumericalError) as e:
            rows.append(_failure(index, fields, speed, f"{type(e).__name__}: {e}", spec))
            continue
        if not r.converged:
            rows.append(_failure(index, fields, speed, f"not converged: {r.termination}", spec))
            continue
        entries = {d["name"]: d["harmonics"] for d in r.record["dofs"]}
        for e in r.record["elements"] if isinstance(r.record["elements"], list) else []:
            entries[f"u({e['name']})"] = e["coordinate"]["harmonics"]
            entries[f"f({e['name']})"] = e["force"]["harmonics"]
        rows += _rows(index, fields, speed, entries, spec, r.stable, r.error_estimate)
    return rows


def _coordinate(element: str, weights: dict, entries: dict, dofs: list) -> list[dict]:
    """The harmonics of an element's coordinate u = Σ w_i q_i from its DOFs' harmonics."""
    total = None
    for i, w in weights[element]:
        if dofs[i] not in entries:
            raise KeyError(f"u({element}) needs the harmonics of DOF `{dofs[i]}`, which the sweep did not report (options dofs=)")
        part = np.array([complex(h["cos"], -h["sin"]) for h in entries[dofs[i]]]) * w
        total = part if total is None else total + part
    first = next(iter(entries.values()))
    return [{"harmonic": h["harmonic"], "shaft_order": h["shaft_order"], "cos": z.real, "sin": -z.imag}
            for h, z in zip(first, total)]


def _rows(index, fields, speed, entries, spec, stable, error_estimate) -> list[tuple]:
    rows = []
    head = _head(index, fields, spec)
    estimate = np.nan if error_estimate is None else error_estimate
    wanted = None if spec["orders"] is None else {round(o, 9) for o in spec["orders"]}
    for q in spec["quantities"]:
        for h in entries[q]:
            if wanted is None:
                keep = 1 <= h["harmonic"] <= 10
            else:
                keep = round(h["shaft_order"], 9) in wanted
            if keep:
                z = complex(h["cos"], -h["sin"])
                rows.append((*head, speed, q, h["shaft_order"], abs(z), float(np.angle(z)), stable, estimate, "ok", ""))
    return rows
