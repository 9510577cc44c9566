"""deadreckon.fleet over a Dask LocalCluster with two worker processes."""

from __future__ import annotations

import pytest

import deadreckon
import deadreckon.fleet

distributed = pytest.importorskip("dask.distributed")


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    )
    c = distributed.Client(cluster)
    yield c
    c.close()
    cluster.close()


def test_calibrate_many_equals_one_by_one_and_records_failures(client, fleet_drives, tmp_path):
    missing = tmp_path / "no-such-drive"
    paths = [*fleet_drives, missing]
    # The task stream records which worker ran each task.
    with distributed.get_task_stream(client) as stream:
        rows = deadreckon.fleet.calibrate_many(paths, client)
    assert [r["path"] for r in rows] == [str(p) for p in paths]
    for p, r in zip(fleet_drives, rows):
        assert r["ok"] and r["error"] is None
        expected = deadreckon.calibrate(p)
        assert {k: r[k] for k in expected} == expected
    bad = rows[-1]
    assert not bad["ok"]
    assert "reading drive" in bad["error"] and "vehicle.toml" in bad["error"]
    # Both workers took part: each ran at least one of the calibrations (the
    # test used to check only the cluster's size).
    ran = {t["worker"] for t in stream.data if "calibrate_one" in str(t["key"])}
    assert len(ran) == 2, stream.data
    table = deadreckon.fleet.to_frame(rows)
    assert list(table["ok"]) == [True] * 4 + [False]
    assert table["std_speed_scale"].iloc[:4].gt(0).all()


def test_calibrate_many_passes_options_and_batches(client, fleet_drives):
    rows = deadreckon.fleet.calibrate_many(fleet_drives[:3], client, "zupt", batch_size=2)
    assert [r["method"] for r in rows] == ["zupt"] * 3
    assert rows[1] == {**deadreckon.calibrate(fleet_drives[1], "zupt"), "ok": True, "error": None,
                       "path": str(fleet_drives[1]), "seconds": rows[1]["seconds"]}
