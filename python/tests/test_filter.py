"""The step API: one update per sensor, each returning innovation, NIS and
whether the χ² gate accepted it; the online filter of `deadreckon stream`."""

from __future__ import annotations

import json
import subprocess

import numpy as np
import pytest

import deadreckon
from conftest import _find_cli


def test_gyro_innovation_is_reading_minus_predicted_yaw_rate(sim_drive):
    d = deadreckon.read_drive(sim_drive)
    f = deadreckon.Filter.from_drive(d)
    gyro = d.to_frames()["yaw_rate"]
    t0 = f.time_s
    rows = gyro[gyro["t_s"] > t0].head(50)
    for t, z in zip(rows["t_s"], rows["yaw_rate_rps"]):
        f.predict_to(t)
        before = f.state.copy()
        p = f.covariance
        u = f.update_gyro(z)
        # Nominal parameters: gyro bias 0, h(x) = yaw rate (eq. 4).
        assert u.sensor == "gyro"
        assert u.innovation == pytest.approx(z - before[4], abs=1e-15)
        r = d.vehicle["noise"]["gyro_rps"] ** 2
        assert u.variance == pytest.approx(p[4, 4] + r, rel=1e-12)
        assert u.nis == pytest.approx(u.innovation**2 / u.variance, rel=1e-12)
        assert u.accepted
    assert f.time_s == rows["t_s"].iloc[-1]
    c = f.covariance
    assert np.allclose(c, c.T, atol=0) and np.all(np.linalg.eigvalsh(c) > 0)
    assert f.gates["gyro"] == {"accepted": 50, "rejected": 0, "recovered": 0}


def test_a_gross_fault_is_gated_and_leaves_the_state(sim_drive):
    d = deadreckon.read_drive(sim_drive)
    f = deadreckon.Filter.from_drive(d)
    f.predict_to(f.time_s + 0.02)
    x = f.state.copy()
    u = f.update_wheel_ticks(0, 1e6, 0.02)
    assert u.sensor == "wheel_fl" and not u.accepted and u.nis > 1000
    assert np.array_equal(f.state, x)
    g = f.update_gnss(x[0] + 5000.0, x[1], 1.0)
    assert g.sensor == "gnss" and not g.accepted
    assert f.gates["wheel_fl"]["rejected"] == 1 and f.gates["gnss"]["rejected"] == 1
    assert f.update_course(x[2], 1.0) is None  # below 3 m/s: not used
    with pytest.raises(deadreckon.DeadreckonError, match="wheel index 4"):
        f.update_wheel_speed(4, 1.0)


def test_the_augmented_filter_learns_parameters_with_their_std(sim_drive):
    d = deadreckon.read_drive(sim_drive)
    f = deadreckon.Filter.from_drive(d, augmented=True)
    assert f.state.shape == (11,) and f.covariance.shape == (11, 11)
    std0 = f.params_std["gyro_bias_rps"]
    gyro = d.to_frames()["yaw_rate"]
    for t, z in zip(gyro["t_s"][gyro["t_s"] > f.time_s].head(200), gyro["yaw_rate_rps"][gyro["t_s"] > f.time_s].head(200)):
        f.predict_to(t)
        f.update_gyro(z)
    assert f.params_std["gyro_bias_rps"] <= std0
    assert deadreckon.Filter.from_drive(d).params_std is None


def test_a_filter_from_vehicle_and_state(sim_drive):
    v = deadreckon.read_drive(sim_drive).vehicle
    x0 = np.array([0.0, 0.0, 0.5, 10.0, 0.0])
    f = deadreckon.Filter(v, 0.0, x0, np.diag([1.0, 1.0, 0.01, 1.0, 0.01]))
    f.predict_to(1.0)
    s = f.state
    assert s[0] == pytest.approx(10.0 * np.cos(0.5), rel=1e-9)
    assert s[1] == pytest.approx(10.0 * np.sin(0.5), rel=1e-9)
    u = f.update_speed(10.0)
    assert u.sensor == "speed" and u.innovation == pytest.approx(0.0, abs=1e-12)
    with pytest.raises(deadreckon.DeadreckonError, match="x0 must have 5"):
        deadreckon.Filter(v, 0.0, np.zeros(4), np.eye(5))
    with pytest.raises(deadreckon.DeadreckonError):
        deadreckon.Filter({**v, "wheelbase_m": -1.0}, 0.0, x0, np.eye(5))


def test_online_on_event_lines_equals_stream(sim_drive, cli):
    events = cli("events", sim_drive).stdout.splitlines()
    stream = subprocess.run(
        [str(_find_cli()), "--quiet", "stream", "--vehicle", str(sim_drive / "vehicle.toml")],
        input="\n".join(events) + "\n", capture_output=True, text=True, check=True,
    ).stdout.splitlines()
    theirs = [json.loads(l) for l in stream]
    o = deadreckon.Online(deadreckon.read_drive(sim_drive))
    # In two parts, with a stop and resume through the state in between.
    half = len(events) // 2
    a = o.push_lines(events[:half])
    o = deadreckon.Online.from_json(o.to_json())
    b = o.push_lines(events[half:])
    c = o.finish()
    ours = {k: np.concatenate([a[k], b[k], c[k]]) for k in a}
    assert len(ours["t_s"]) == len(theirs) > 1000
    for k in ("t_s", "east_m", "north_m", "yaw_rad", "speed_mps", "yaw_rate_rps", "bound_95_m"):
        assert np.array_equal(ours[k], np.array([p[k] for p in theirs])), k
    assert o.is_started and o.learned() is None
    with pytest.raises(deadreckon.DeadreckonError, match="line 1"):
        deadreckon.Online(deadreckon.read_drive(sim_drive)).push_lines(["{not json"])


def test_online_learning_reports_parameters_with_std(sim_drive, cli):
    events = cli("events", sim_drive).stdout.splitlines()
    o = deadreckon.Online(deadreckon.read_drive(sim_drive), learn=True)
    o.push_lines(events)
    o.finish()
    l = o.learned()
    assert set(l) >= {"speed_scale", "std", "valid", "calibrated_pct"}
    assert 0 < l["std"]["speed_scale"] < 0.01
    assert 0.0 <= l["calibrated_pct"] <= 100.0
