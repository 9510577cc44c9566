//! Writing a [`Drive`] as a drive directory.

use std::fmt::Write as _;
use std::fs;
use std::path::{Path, PathBuf};

use deadreckon_core::drive::Wheels;
use deadreckon_core::Drive;

use crate::read::{
    parse_axes, parse_gnss, parse_gyro, parse_scalar, parse_speeds, parse_ticks, parse_truth,
};
use crate::table::Limit;
use crate::{atomic_write, files, IoError};

/// Writes `drive` into the directory `dir` (created if missing): `vehicle.toml`
/// and one CSV per non-empty stream, positions in east/north, every `f64` in
/// its shortest exact decimal form (so [`read_drive`](crate::read_drive) gives
/// back an equal drive).
///
/// Before anything is written, the drive must pass [`Drive::validate`] and each
/// CSV is re-read with the reader's checks (so what is written always reads
/// back; e.g. a yaw beyond ±(2π + 0.01) rad is refused: wrap it first). Each
/// file is written atomically. Drive files of the contract that this drive
/// does not have (the other wheel file, empty optional streams) are removed
/// from `dir`, so that reading the directory gives this drive and nothing else.
pub fn write_drive(dir: &Path, drive: &Drive) -> Result<(), IoError> {
    drive.validate().map_err(|source| IoError::Invalid {
        path: dir.to_path_buf(),
        source,
    })?;
    let mut out: Vec<(PathBuf, String)> = Vec::new();

    let (wheel_name, wheel_csv) = match &drive.wheels {
        Wheels::Ticks(v) => (
            files::WHEEL_TICKS,
            csv(
                &["t_s", "fl", "fr", "rl", "rr"],
                v.iter()
                    .map(|w| vec![num(w.t_s), int(w.fl), int(w.fr), int(w.rl), int(w.rr)]),
            ),
        ),
        Wheels::Speeds(v) => (
            files::WHEEL_SPEEDS,
            csv(
                &["t_s", "fl_mps", "fr_mps", "rl_mps", "rr_mps"],
                v.iter().map(|w| {
                    vec![
                        num(w.t_s),
                        num(w.fl_mps),
                        num(w.fr_mps),
                        num(w.rl_mps),
                        num(w.rr_mps),
                    ]
                }),
            ),
        ),
    };
    let path = dir.join(wheel_name);
    match &drive.wheels {
        Wheels::Ticks(_) => drop(parse_ticks(&path, wheel_csv.as_bytes())?),
        Wheels::Speeds(_) => drop(parse_speeds(&path, wheel_csv.as_bytes())?),
    }
    out.push((path, wheel_csv));

    // The three-axis gyro beside the yaw rate when it has the same times
    // (as the importers and the simulator give it).
    let g3 = &drive.imu.gyro;
    let three_axes = !g3.is_empty()
        && g3.len() == drive.yaw_rate.len()
        && g3.iter().zip(&drive.yaw_rate).all(|(a, s)| a.t_s == s.t_s);
    if three_axes {
        let text = csv(
            &["t_s", "yaw_rate_rps", "x_rps", "y_rps", "z_rps"],
            g3.iter()
                .zip(&drive.yaw_rate)
                .map(|(a, s)| vec![num(a.t_s), num(s.value), num(a.x), num(a.y), num(a.z)]),
        );
        let path = dir.join(files::YAW_RATE);
        parse_gyro(&path, text.as_bytes())?;
        out.push((path, text));
    }
    if !drive.imu.accel.is_empty() {
        let text = csv(
            &["t_s", "x_mps2", "y_mps2", "z_mps2"],
            drive
                .imu
                .accel
                .iter()
                .map(|a| vec![num(a.t_s), num(a.x), num(a.y), num(a.z)]),
        );
        let path = dir.join(files::ACCEL);
        parse_axes(
            &path,
            text.as_bytes(),
            ["x_mps2", "y_mps2", "z_mps2"],
            Limit::Accel,
        )?;
        out.push((path, text));
    }
    let one_axis: &[deadreckon_core::drive::Scalar] =
        if three_axes { &[] } else { &drive.yaw_rate };
    for (name, column, limit, stream) in [
        (files::YAW_RATE, "yaw_rate_rps", Limit::YawRate, one_axis),
        (files::SPEED, "speed_mps", Limit::Speed, &drive.speed),
        (
            files::STEERING,
            "steering_wheel_rad",
            Limit::SteeringWheel,
            &drive.steering,
        ),
    ] {
        if stream.is_empty() {
            continue;
        }
        let text = csv(
            &["t_s", column],
            stream.iter().map(|s| vec![num(s.t_s), num(s.value)]),
        );
        let path = dir.join(name);
        parse_scalar(&path, text.as_bytes(), column, limit)?;
        out.push((path, text));
    }

    if !drive.gnss.is_empty() {
        let course = drive.gnss.iter().any(|g| g.course_deg.is_some());
        let speed = drive.gnss.iter().any(|g| g.speed_mps.is_some());
        let mut header = vec!["t_s", "east_m", "north_m", "std_m"];
        if course {
            header.push("course_deg");
        }
        if speed {
            header.push("speed_mps");
        }
        let text = csv(
            &header,
            drive.gnss.iter().map(|g| {
                let mut row = vec![num(g.t_s), num(g.east_m), num(g.north_m), num(g.std_m)];
                if course {
                    row.push(opt(g.course_deg));
                }
                if speed {
                    row.push(opt(g.speed_mps));
                }
                row
            }),
        );
        let path = dir.join(files::GNSS);
        parse_gnss(&path, text.as_bytes())?;
        out.push((path, text));
    }

    if !drive.truth.is_empty() {
        let speed = drive.truth.iter().any(|t| t.speed_mps.is_some());
        let mut header = vec!["t_s", "east_m", "north_m", "yaw_rad"];
        if speed {
            header.push("speed_mps");
        }
        let text = csv(
            &header,
            drive.truth.iter().map(|t| {
                let mut row = vec![num(t.t_s), num(t.east_m), num(t.north_m), num(t.yaw_rad)];
                if speed {
                    row.push(opt(t.speed_mps));
                }
                row
            }),
        );
        let path = dir.join(files::TRUTH);
        parse_truth(&path, text.as_bytes())?;
        out.push((path, text));
    }

    fs::create_dir_all(dir).map_err(|e| IoError::io(dir, e))?;
    crate::write_vehicle(&dir.join(files::VEHICLE), &drive.vehicle)?;
    for (path, text) in &out {
        atomic_write(path, |w| w.write_all(text.as_bytes()))?;
    }
    for name in files::STREAMS {
        let path = dir.join(name);
        if !out.iter().any(|(p, _)| *p == path) {
            match fs::remove_file(&path) {
                Ok(()) => {}
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
                Err(e) => return Err(IoError::io(path, e)),
            }
        }
    }
    Ok(())
}

/// A `f64` in its shortest decimal form that parses back to the same bits.
fn num(v: f64) -> String {
    format!("{v}")
}

fn int(v: i64) -> String {
    format!("{v}")
}

/// An optional value: empty field for `None`.
fn opt(v: Option<f64>) -> String {
    v.map(num).unwrap_or_default()
}

/// A CSV text of numeric fields (no quoting needed).
fn csv(header: &[&str], rows: impl Iterator<Item = Vec<String>>) -> String {
    let mut s = header.join(",");
    s.push('\n');
    for row in rows {
        let _ = writeln!(s, "{}", row.join(","));
    }
    s
}
