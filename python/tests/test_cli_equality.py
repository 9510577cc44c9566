"""The Python results are the command line's, exactly: same keys, same numbers."""

from __future__ import annotations

import math
import re

import numpy as np
import pandas as pd
import pytest

import deadreckon
from conftest import COMMA2K19


def test_calibrate_comma2k19_equals_cli_json(cli_json):
    # The "done" line: deadreckon.calibrate("../shared/data/comma2k19-rav4")
    # returns the CLI's numbers exactly.
    ours = deadreckon.calibrate(str(COMMA2K19))
    theirs = cli_json("calibrate", COMMA2K19, "--json")
    assert ours == theirs
    assert ours["converged"] is True
    assert set(ours) >= {"gyro_bias_rps", "speed_scale", "std", "iterations", "gates"}


def test_calibrate_with_a_drive_object_equals_the_path(sim_drive):
    by_path = deadreckon.calibrate(sim_drive)
    by_drive = deadreckon.calibrate(deadreckon.read_drive(sim_drive))
    assert by_path == by_drive


@pytest.mark.parametrize(
    "method,extra",
    [
        ("rts", ["--state", "paper", "--iteration", "plain", "--max-iterations", "3"]),
        ("zupt", []),
        ("truth", []),
    ],
)
def test_calibrate_options_equal_cli(sim_drive, cli_json, method, extra):
    opts = {}
    it = iter(extra)
    for flag in it:
        key = flag[2:].replace("-", "_")
        value = next(it)
        opts[key] = float(value) if key == "min_speed" else int(value) if key == "max_iterations" else value
    ours = deadreckon.calibrate(sim_drive, method, **opts)
    theirs = cli_json("calibrate", sim_drive, "--method", method, "--json", *extra)
    assert ours == theirs


def test_calibrate_dict_equals_batch_row(sim_drive, cli, tmp_path):
    # Issue 30: one car calibration. Python's dict and `batch`'s row of the
    # same drive are the same numbers (batch's corrections default to none),
    # and Python's defaults are the command's (None: the library's request).
    import csv

    out = tmp_path / "batch.csv"
    cli("batch", sim_drive, "--out", out)
    (row,) = list(csv.DictReader(out.open()))
    ours = deadreckon.calibrate(sim_drive, corrections="none")
    assert int(row["iterations"]) == ours["iterations"]
    assert (row["converged"] == "true") == ours["converged"]
    names = ["gyro_bias_rps", "speed_scale", "circumference_fl_m", "circumference_fr_m",
             "circumference_rl_m", "circumference_rr_m"]
    for i, name in enumerate(names):
        assert float(row[name]) == ours[name], name
        assert float(row[f"std_{name}"]) == ours["std"][name], name
        assert int(row[f"samples_{name}"]) == ours["samples"][i], name
        status = "not-estimated" if name in ours["not_estimated"] else "estimated"
        assert row[f"status_{name}"] == status, name


def test_calibrate_per_reading_refused_then_equal_to_cli(drive_copy, cli, cli_json):
    # Table I's process noise per reading lets the GNSS fixes set the speed:
    # both refuse it, with the same message.
    needle = "noise.process_speed_mps = 10 (at most 0.5)"
    with pytest.raises(deadreckon.DeadreckonError, match=re.escape(needle)):
        deadreckon.calibrate(drive_copy, timing="each")
    p = cli("calibrate", drive_copy, "--timing", "each", "--json", check=False)
    assert p.returncode != 0 and needle in p.stderr
    # Within the bounds both calibrate, equally.
    vt = drive_copy / "vehicle.toml"
    text = vt.read_text()
    text = text.replace("process_speed_mps = 10.0", "process_speed_mps = 0.5")
    text = text.replace("process_yaw_rate_rps = 1.0", "process_yaw_rate_rps = 0.03")
    vt.write_text(text)
    ours = deadreckon.calibrate(drive_copy, timing="each", min_speed=3.0)
    theirs = cli_json("calibrate", drive_copy, "--json", "--timing", "each", "--min-speed", "3")
    assert ours == theirs
    assert ours["converged"] is True


@pytest.mark.parametrize(
    "args,kwargs",
    [
        (["--metric", "drift"], dict(metric="drift")),
        (["--metric", "reset-1m", "--threshold-m", "2"], dict(metric="reset-1m", threshold_m=2.0)),
        (["--metric", "rpe", "--delta-m", "50"], dict(metric="rpe", delta_m=50.0)),
        (["--metric", "ape", "--track", "filtered"], dict(metric="ape", track="filtered")),
        (["--outage", "30", "--step", "40"], dict(outage=30.0, step=40.0)),
    ],
)
def test_evaluate_equals_cli_json(sim_drive, cli_json, args, kwargs):
    ours = deadreckon.evaluate(sim_drive, **kwargs)
    theirs = cli_json("evaluate", sim_drive, "--json", *args)
    assert ours == theirs


def test_evaluate_with_calibrated_params_equals_cli(sim_drive, cli, cli_json, tmp_path):
    params = tmp_path / "params.toml"
    cli("calibrate", sim_drive, "--out", params)
    theirs = cli_json("evaluate", sim_drive, "--params", params, "--json")
    assert deadreckon.evaluate(sim_drive, params=params) == theirs
    # The dict calibrate returns works as parameters too: the same six numbers
    # as params.toml, which writes them exactly. A dict carries no timing or
    # mounting corrections (params.toml's [delays]/[imu]/[gyro_scale] tables),
    # so it equals a params.toml calibrated without them.
    plain = tmp_path / "plain.toml"
    cli("calibrate", sim_drive, "--corrections", "none", "--out", plain)
    theirs = cli_json("evaluate", sim_drive, "--params", plain, "--json")
    cal = deadreckon.calibrate(sim_drive, corrections="none")
    ours = deadreckon.evaluate(sim_drive, params=cal)
    # Named for where they came from: the file, or a dict given.
    assert (ours.pop("params"), theirs.pop("params")) == ("given", str(plain))
    assert (ours.pop("params_source"), theirs.pop("params_source")) == ("given", str(plain))
    assert ours == theirs


def test_run_tracks_equal_the_cli_csv(sim_drive, cli, tmp_path):
    out = tmp_path / "track.csv"
    cli("run", sim_drive, "--out", out, "--track", "dead-reckoned", "--track", "filtered",
        "--track", "smoothed", "--track", "truth")
    csv = pd.read_csv(out)
    ours = deadreckon.run(sim_drive)
    assert list(ours) == ["dead-reckoned", "filtered", "smoothed", "truth"]
    for name, df in ours.items():
        theirs = csv[csv["track"] == name].drop(columns="track").reset_index(drop=True)
        assert list(df.columns) == list(theirs.columns)
        assert len(df) == len(theirs) > 100
        # The CSV has a fixed precision per column (docs/drive-format.md):
        # times, positions and angles to 1e-9, speed to 1e-6, uncertainties to
        # 7 significant digits; the DataFrames carry the full doubles.
        for c in df.columns:
            ours_c, theirs_c = df[c].to_numpy(), theirs[c].to_numpy()
            if c.startswith("std_") or c.startswith("cov_") or c == "bound_95_m":
                # A track without uncertainty (the truth) has none: NaN here, empty in the CSV
                # (the 95 % bound: dead-reckoned and filtered tracks only).
                ok = np.allclose(ours_c, theirs_c, rtol=1e-6, atol=0.0, equal_nan=True)
            else:
                atol = 1e-6 if c == "speed_mps" else 1e-9
                ok = np.allclose(ours_c, theirs_c, rtol=0.0, atol=atol * 0.51)
            assert ok, (name, c, np.max(np.abs(ours_c - theirs_c)))


def test_tedris_train_and_run_equal_cli(sim_drive, cli, cli_json, tmp_path):
    model_path = tmp_path / "model.json"
    theirs = cli_json("tedris", "train", sim_drive, "--out", model_path, "--json")
    model = deadreckon.tedris_train(sim_drive)
    assert model.summary == theirs
    with open(model_path, encoding="utf-8") as f:
        assert model.json == f.read()
    ran = deadreckon.tedris_run(sim_drive, model, [(100.0, 140.0), (180.0, 200.0)])
    track = ran.pop("track")
    theirs = cli_json("tedris", "run", sim_drive, "--model", model_path,
                      "--outage", "100:140", "--outage", "180:200", "--json")
    theirs.pop("track")
    assert ran == theirs
    assert len(ran["outages"]) == 2
    assert all(math.isfinite(o["final_error_m"]) for o in ran["outages"])
    assert {"t_s", "east_m", "north_m", "yaw_rad"} <= set(track.columns)
