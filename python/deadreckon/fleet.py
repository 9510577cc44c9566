"""Calibrations of many drives mapped over a Dask distributed cluster.

One task per drive: each worker reads its drive from a path it can see (a
shared file system, or object storage mounted on the workers) and calibrates
it with :func:`deadreckon.calibrate`, which runs in Rust without the GIL. A
failure is a row with its error, never the end of the batch.

On one machine::

    from dask.distributed import Client, LocalCluster
    with LocalCluster(n_workers=2, threads_per_worker=1) as cluster, Client(cluster) as client:
        rows = deadreckon.fleet.calibrate_many(paths, client)

On a real cluster, start a scheduler and workers on machines that have this
package installed (``pip install ./python`` in the same environment on each)
and see the drive paths::

    dask scheduler                                  # on the scheduler host, port 8786
    dask worker tcp://SCHEDULER:8786 --nworkers 8 --nthreads 1   # on each worker host

then ``Client("tcp://SCHEDULER:8786")`` in place of the local cluster (or a
``dask_jobqueue`` / ``dask_kubernetes`` cluster object). One thread per worker
process is the right shape: a calibration is one core's work.
"""

from __future__ import annotations

import os
import time
from typing import Any, Dict, Iterable, List, Optional

import pandas as pd

import deadreckon

__all__ = ["calibrate_one", "calibrate_many", "to_frame"]


def calibrate_one(path: str, method: str = "rts", **options: Any) -> Dict[str, Any]:
    """Calibrates one drive; the row is ``calibrate --json``'s object plus
    ``path``, ``ok``, ``error`` (the message, or None) and ``seconds``."""
    start = time.perf_counter()
    try:
        row = deadreckon.calibrate(path, method, **options)
        row.update(ok=True, error=None)
    except Exception as e:  # a failed drive is a row, never the end of the batch
        row = {"ok": False, "error": f"{type(e).__name__}: {e}", "method": method}
    row["path"] = path
    row["seconds"] = time.perf_counter() - start
    return row


def calibrate_many(
    paths: Iterable[os.PathLike[str] | str],
    client: Any,
    method: str = "rts",
    *,
    batch_size: Optional[int] = None,
    **options: Any,
) -> List[Dict[str, Any]]:
    """Calibrates every drive in ``paths`` on the Dask ``client``'s workers.

    Returns one row per path, in the order given (see :func:`calibrate_one`);
    ``options`` are :func:`deadreckon.calibrate`'s. ``batch_size`` submits at
    most that many tasks at a time (default: all at once).
    """
    paths = [os.fspath(p) for p in paths]
    if not paths:
        return []
    step = batch_size or len(paths)
    rows: List[Dict[str, Any]] = []
    for i in range(0, len(paths), step):
        chunk = paths[i : i + step]
        # pure=False: a path's drive may change between calls; never reuse a result.
        futures = client.map(calibrate_one, chunk, method=method, pure=False, **options)
        rows.extend(client.gather(futures))
    return rows


def to_frame(rows: List[Dict[str, Any]]) -> pd.DataFrame:
    """The rows as a table: path, ok, error, the six parameters and their
    standard errors (``std_<name>``), iterations, converged, seconds."""
    names = ["gyro_bias_rps", "speed_scale", "circumference_fl_m", "circumference_fr_m",
             "circumference_rl_m", "circumference_rr_m"]
    out = []
    for r in rows:
        flat = {"path": r["path"], "ok": r["ok"], "error": r["error"]}
        std = r.get("std", {})
        for n in names:
            flat[n] = r.get(n)
            flat["std_" + n] = std.get(n)
        flat.update(iterations=r.get("iterations"), converged=r.get("converged"), seconds=r["seconds"])
        out.append(flat)
    return pd.DataFrame(out)
