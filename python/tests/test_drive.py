"""Drives: every source the command line reads, DataFrames in and out, and
errors carrying the command line's messages."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import deadreckon
from conftest import COMMA2K19, DATA


@pytest.mark.parametrize(
    "path,rows",
    [
        (COMMA2K19, 4974),
        (DATA / "husky-gps-bag" / "husky_gps.bag", None),
        (DATA / "tricycle-tracker" / "dataset.txt", None),
    ],
)
def test_read_drive_reads_every_source(path, rows):
    d = deadreckon.read_drive(path)
    frames = d.to_frames()
    wheels = frames.get("wheel_ticks", frames.get("wheel_speeds"))
    assert len(d) == len(wheels) > 100
    if rows is not None:
        assert len(d) == rows
    assert np.all(np.diff(wheels["t_s"].to_numpy()) > 0)


def test_frames_round_trip_to_the_same_calibration(sim_drive):
    d = deadreckon.read_drive(sim_drive)
    frames = d.to_frames()
    assert set(frames) >= {"wheel_ticks", "yaw_rate", "speed", "steering", "gnss", "truth"}
    assert frames["wheel_ticks"]["fl"].dtype == np.int64
    again = deadreckon.Drive.from_frames(d.vehicle, **frames)
    for name, df in again.to_frames().items():
        pd.testing.assert_frame_equal(df, frames[name], check_exact=True)
    assert deadreckon.calibrate(again) == deadreckon.calibrate(sim_drive)


def test_from_frames_takes_a_vehicle_toml_and_csv_frames(sim_drive):
    frames = {
        name: pd.read_csv(sim_drive / f"{name}.csv")
        for name in ("wheel_ticks", "yaw_rate", "speed", "steering", "gnss")
    }
    frames["gnss"]["note"] = "extra columns are ignored"
    d = deadreckon.Drive.from_frames(sim_drive / "vehicle.toml", **frames)
    assert deadreckon.calibrate(d) == deadreckon.calibrate(sim_drive)


def test_from_frames_lat_lon_gnss_is_converted_about_the_first_fix(sim_drive):
    frames = deadreckon.read_drive(sim_drive).to_frames()
    g = frames["gnss"]
    lat = 48.0 + g["north_m"] / 111_200.0
    lon = 11.0 + g["east_m"] / 74_400.0
    geo = pd.DataFrame({"t_s": g["t_s"], "lat_deg": lat, "lon_deg": lon, "std_m": g["std_m"]})
    vehicle = deadreckon.read_drive(sim_drive).vehicle
    d = deadreckon.Drive.from_frames(vehicle, wheel_ticks=frames["wheel_ticks"], gnss=geo)
    out = d.to_frames()["gnss"]
    assert out["east_m"].iloc[0] == 0.0 and out["north_m"].iloc[0] == 0.0
    # Away from the origin: within 0.5% of the flat-earth offsets used above.
    de = out["east_m"].iloc[-1] - 0.0
    ref = (g["east_m"].iloc[-1] - g["east_m"].iloc[0])
    assert abs(de - ref) < 0.005 * abs(ref) + 1.0
    assert d.vehicle["origin"] == pytest.approx({"lat_deg": lat.iloc[0], "lon_deg": lon.iloc[0]})


def test_from_frames_errors_name_stream_column_and_row(sim_drive):
    frames = deadreckon.read_drive(sim_drive).to_frames()
    vehicle = deadreckon.read_drive(sim_drive).vehicle
    bad = frames["wheel_ticks"].drop(columns="rr")
    with pytest.raises(deadreckon.DeadreckonError, match=r"wheel_ticks: missing column `rr`"):
        deadreckon.Drive.from_frames(vehicle, wheel_ticks=bad)
    bad = frames["wheel_ticks"].astype({"fl": "float64"})
    bad.loc[5, "fl"] = 2.5
    with pytest.raises(deadreckon.DeadreckonError, match=r"wheel_ticks: row 5: column `fl` is not an integer"):
        deadreckon.Drive.from_frames(vehicle, wheel_ticks=bad)
    bad = frames["gnss"].copy()
    bad.loc[3, "std_m"] = np.nan
    with pytest.raises(deadreckon.DeadreckonError, match=r"gnss: row 3: column `std_m` is empty"):
        deadreckon.Drive.from_frames(vehicle, wheel_ticks=frames["wheel_ticks"], gnss=bad)
    bad = frames["yaw_rate"].copy()
    bad.loc[10, "t_s"] = bad.loc[9, "t_s"]
    with pytest.raises(deadreckon.DeadreckonError, match=r"invalid drive"):
        deadreckon.Drive.from_frames(vehicle, wheel_ticks=frames["wheel_ticks"], yaw_rate=bad)
    with pytest.raises(deadreckon.DeadreckonError, match=r"vehicle"):
        deadreckon.Drive.from_frames({**vehicle, "wheelbase_mm": 2.7}, wheel_ticks=frames["wheel_ticks"])


def test_errors_carry_the_cli_message(drive_copy, cli):
    lines = (drive_copy / "yaw_rate.csv").read_text().splitlines()
    lines[7] = lines[7].split(",")[0] + ",abc"
    (drive_copy / "yaw_rate.csv").write_text("\n".join(lines) + "\n")
    p = cli("calibrate", drive_copy, check=False)
    assert p.returncode == 1
    message = p.stderr.strip().removeprefix("error: ")
    assert "yaw_rate.csv: line 8, column `yaw_rate_rps`" in message, message
    with pytest.raises(deadreckon.DeadreckonError) as e:
        deadreckon.read_drive(drive_copy)
    assert str(e.value) == message
    with pytest.raises(deadreckon.DeadreckonError) as e:
        deadreckon.calibrate(drive_copy)
    assert str(e.value) == message


def test_a_calibration_error_carries_the_cli_message(drive_copy, cli):
    (drive_copy / "truth.csv").unlink()
    p = cli("calibrate", drive_copy, "--method", "truth", check=False)
    assert p.returncode == 1
    with pytest.raises(deadreckon.DeadreckonError) as e:
        deadreckon.calibrate(drive_copy, "truth")
    assert str(e.value) == p.stderr.strip().removeprefix("error: ")


def test_bad_options_are_exceptions_not_crashes(sim_drive):
    with pytest.raises(deadreckon.DeadreckonError, match="unknown timing `every`"):
        deadreckon.calibrate(sim_drive, timing="every")
    with pytest.raises(deadreckon.DeadreckonError, match="unknown calibration method"):
        deadreckon.calibrate(sim_drive, "magic")
    with pytest.raises(deadreckon.DeadreckonError, match="unknown metric"):
        deadreckon.evaluate(sim_drive, metric="rmse")
    with pytest.raises(TypeError):
        deadreckon.calibrate(42)
    with pytest.raises(deadreckon.DeadreckonError, match="not a drive directory"):
        deadreckon.read_drive(sim_drive / "vehicle.toml")
