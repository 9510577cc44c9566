//! Reading a drive directory into a [`Drive`].

use std::fs;
use std::path::Path;

use deadreckon_core::drive::{Axes, GnssFix, Scalar, TruthPose, WheelSpeeds, WheelTicks, Wheels};
use deadreckon_core::vehicle::Origin;
use deadreckon_core::Drive;

use crate::table::{Col, Limit, Table};
use crate::{files, geo, IoError};

/// Which wheel file a drive's wheel stream comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WheelFile {
    /// `wheel_ticks.csv`: encoder ticks.
    Ticks,
    /// `wheel_speeds.csv`: wheel speeds.
    Speeds,
}

impl WheelFile {
    /// The file name in a drive directory.
    pub fn file_name(self) -> &'static str {
        match self {
            WheelFile::Ticks => files::WHEEL_TICKS,
            WheelFile::Speeds => files::WHEEL_SPEEDS,
        }
    }
}

/// Options of [`read_drive_with`].
#[derive(Debug, Clone, Default)]
#[non_exhaustive]
pub struct ReadOptions {
    /// The wheel file to use when a directory has both (`None`: having both is
    /// an error). When only one exists, that one is used whatever this says.
    pub prefer_wheels: Option<WheelFile>,
    /// Do not read `truth.csv` (commands that never use it: the RTS and ZUPT
    /// calibrations); the drive's `truth` is then empty.
    pub skip_truth: bool,
}

impl ReadOptions {
    /// Leaves `truth.csv` unread.
    pub fn without_truth(mut self) -> Self {
        self.skip_truth = true;
        self
    }

    /// Uses `wheels` when both wheel files exist.
    pub fn prefer_wheels(mut self, wheels: WheelFile) -> Self {
        self.prefer_wheels = Some(wheels);
        self
    }
}

/// Reads the drive directory `dir` (see `docs/drive-format.md`); having both
/// wheel files is an error.
pub fn read_drive(dir: &Path) -> Result<Drive, IoError> {
    read_drive_with(dir, &ReadOptions::default())
}

/// Reads the drive directory `dir` with options.
///
/// Every CSV field is checked (number, finite, plausible range of its unit,
/// increasing time), latitude/longitude files are converted to east-north
/// about `[origin]` of `vehicle.toml` or, when absent, the first fix (recorded
/// in the returned `vehicle.origin`), and the result passes [`Drive::validate`].
pub fn read_drive_with(dir: &Path, options: &ReadOptions) -> Result<Drive, IoError> {
    if !dir.is_dir() {
        return Err(IoError::NoDirectory {
            dir: dir.to_path_buf(),
            what: if dir.exists() {
                "not a directory"
            } else {
                "no such directory"
            },
        });
    }
    let vehicle_path = dir.join(files::VEHICLE);
    if !vehicle_path.exists() {
        return Err(IoError::MissingFile {
            path: vehicle_path,
            note: "every drive needs vehicle.toml".into(),
        });
    }
    let mut vehicle = crate::toml_files::read_vehicle(&vehicle_path)?;

    let ticks = read_optional(&dir.join(files::WHEEL_TICKS))?;
    let speeds = read_optional(&dir.join(files::WHEEL_SPEEDS))?;
    let use_file = match (&ticks, &speeds, options.prefer_wheels) {
        (Some(_), Some(_), None) => {
            return Err(IoError::AmbiguousWheels {
                dir: dir.to_path_buf(),
            })
        }
        (Some(_), Some(_), Some(w)) => w,
        (Some(_), None, _) => WheelFile::Ticks,
        (None, Some(_), _) => WheelFile::Speeds,
        (None, None, _) => {
            return Err(IoError::MissingFile {
                path: dir.join(files::WHEEL_TICKS),
                note: "a drive needs wheel_ticks.csv or wheel_speeds.csv".into(),
            })
        }
    };
    let wheels_path = dir.join(use_file.file_name());
    let wheels = match (use_file, ticks, speeds) {
        (WheelFile::Ticks, Some(b), _) => Wheels::Ticks(parse_ticks(&wheels_path, &b)?),
        (WheelFile::Speeds, _, Some(b)) => Wheels::Speeds(parse_speeds(&wheels_path, &b)?),
        // Unreachable by the match above; reported rather than panicking.
        _ => {
            return Err(IoError::MissingFile {
                path: wheels_path,
                note: "the wheel file chosen does not exist".into(),
            })
        }
    };
    if wheels.len() < 2 {
        return Err(IoError::TooFewRows {
            file: wheels_path,
            found: wheels.len(),
            min: 2,
        });
    }

    let scalar = |name: &str, column: &'static str, limit| -> Result<Vec<Scalar>, IoError> {
        let path = dir.join(name);
        match read_optional(&path)? {
            Some(b) => parse_scalar(&path, &b, column, limit),
            None => Ok(Vec::new()),
        }
    };
    let yaw_path = dir.join(files::YAW_RATE);
    let (yaw_rate, imu_gyro) = match read_optional(&yaw_path)? {
        Some(b) => parse_gyro(&yaw_path, &b)?,
        None => (Vec::new(), Vec::new()),
    };
    let accel_path = dir.join(files::ACCEL);
    let imu_accel = match read_optional(&accel_path)? {
        Some(b) => parse_axes(
            &accel_path,
            &b,
            ["x_mps2", "y_mps2", "z_mps2"],
            Limit::Accel,
        )?,
        None => Vec::new(),
    };
    let speed = scalar(files::SPEED, "speed_mps", Limit::Speed)?;
    let steering = scalar(files::STEERING, "steering_wheel_rad", Limit::SteeringWheel)?;

    let gnss_path = dir.join(files::GNSS);
    let (mut gnss, gnss_heights) = match read_optional(&gnss_path)? {
        Some(b) => parse_gnss(&gnss_path, &b)?,
        None => (Vec::new(), None),
    };
    let truth_path = dir.join(files::TRUTH);
    let truth_bytes = if options.skip_truth {
        None
    } else {
        read_optional(&truth_path)?
    };
    let (mut truth, truth_heights) = match truth_bytes {
        Some(b) => parse_truth(&truth_path, &b)?,
        None => (Vec::new(), None),
    };

    // Geodetic files: pick the origin, then convert.
    let gnss_geo = gnss_heights.is_some() && !gnss.is_empty();
    let truth_geo = truth_heights.is_some() && !truth.is_empty();
    if gnss_geo || truth_geo {
        let origin = match vehicle.origin {
            Some(o) => o,
            None => {
                // Without [origin], geodetic and east-north files cannot share a frame.
                if gnss_geo != truth_geo && !gnss.is_empty() && !truth.is_empty() {
                    let (geo_file, en_file) = if gnss_geo {
                        (&gnss_path, files::TRUTH)
                    } else {
                        (&truth_path, files::GNSS)
                    };
                    return Err(IoError::NeedsOrigin {
                        file: geo_file.clone(),
                        message: format!(
                            "latitude/longitude here but east/north in {en_file}: \
                             vehicle.toml needs an [origin] (lat_deg, lon_deg) to relate them"
                        ),
                    });
                }
                let first = if gnss_geo {
                    gnss.first().map(|g| (g.east_m, g.north_m))
                } else {
                    truth.first().map(|t| (t.east_m, t.north_m))
                };
                let first_height = if gnss_geo {
                    gnss_heights
                        .as_ref()
                        .and_then(|h| h.first().copied().flatten())
                } else {
                    truth_heights
                        .as_ref()
                        .and_then(|h| h.first().copied().flatten())
                };
                let Some((lat_deg, lon_deg)) = first else {
                    return Err(IoError::NeedsOrigin {
                        file: dir.to_path_buf(),
                        message: "no fix to take as the origin".into(),
                    });
                };
                Origin {
                    lat_deg,
                    lon_deg,
                    height_m: first_height.unwrap_or(0.0),
                }
            }
        };
        // Each position at its own height where the file gives one, else at
        // the origin's.
        let to_en = |lat: f64, lon: f64, h: Option<f64>| {
            geo::geodetic_height_to_en(&origin, lat, lon, h.unwrap_or(origin.height_m))
        };
        if let (true, Some(h)) = (gnss_geo, &gnss_heights) {
            for (g, &h) in gnss.iter_mut().zip(h) {
                (g.east_m, g.north_m) = to_en(g.east_m, g.north_m, h);
            }
        }
        if let (true, Some(h)) = (truth_geo, &truth_heights) {
            for (t, &h) in truth.iter_mut().zip(h) {
                (t.east_m, t.north_m) = to_en(t.east_m, t.north_m, h);
            }
        }
        vehicle.origin = Some(origin);
    }

    let drive = Drive {
        vehicle,
        wheels,
        yaw_rate,
        speed,
        steering,
        gnss,
        truth,
        imu: deadreckon_core::drive::Imu {
            gyro: imu_gyro,
            accel: imu_accel,
        },
    };
    drive.validate().map_err(|source| IoError::Invalid {
        path: dir.to_path_buf(),
        source,
    })?;
    Ok(drive)
}

/// The content of `path`, or `None` when it does not exist.
fn read_optional(path: &Path) -> Result<Option<Vec<u8>>, IoError> {
    match fs::read(path) {
        Ok(b) => Ok(Some(b)),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(IoError::io(path, e)),
    }
}

/// Parses `wheel_ticks.csv`.
pub(crate) fn parse_ticks(file: &Path, bytes: &[u8]) -> Result<Vec<WheelTicks>, IoError> {
    let t = Table::new(file, bytes)?;
    let (ts, fl, fr, rl, rr) = (
        t.col("t_s")?,
        t.col("fl")?,
        t.col("fr")?,
        t.col("rl")?,
        t.col("rr")?,
    );
    t.rows(|r| {
        Ok(WheelTicks {
            t_s: r.f64(ts)?,
            fl: r.i64(fl)?,
            fr: r.i64(fr)?,
            rl: r.i64(rl)?,
            rr: r.i64(rr)?,
        })
    })
}

/// Parses `wheel_speeds.csv`.
pub(crate) fn parse_speeds(file: &Path, bytes: &[u8]) -> Result<Vec<WheelSpeeds>, IoError> {
    let t = Table::new(file, bytes)?;
    let ts = t.col("t_s")?;
    let (fl, fr) = (t.col("fl_mps")?, t.col("fr_mps")?);
    let (rl, rr) = (t.col("rl_mps")?, t.col("rr_mps")?);
    t.rows(|r| {
        Ok(WheelSpeeds {
            t_s: r.f64(ts)?,
            fl_mps: r.checked(fl, Limit::Speed)?,
            fr_mps: r.checked(fr, Limit::Speed)?,
            rl_mps: r.checked(rl, Limit::Speed)?,
            rr_mps: r.checked(rr, Limit::Speed)?,
        })
    })
}

/// Parses a `t_s,<column>` stream.
/// Three columns `[x, y, z]` of a CSV as [`Axes`].
pub(crate) fn parse_axes(
    file: &Path,
    bytes: &[u8],
    columns: [&'static str; 3],
    limit: Limit,
) -> Result<Vec<Axes>, IoError> {
    let t = Table::new(file, bytes)?;
    let ts = t.col("t_s")?;
    let c = [t.col(columns[0])?, t.col(columns[1])?, t.col(columns[2])?];
    t.rows(|r| {
        Ok(Axes {
            t_s: r.f64(ts)?,
            x: r.checked(c[0], limit)?,
            y: r.checked(c[1], limit)?,
            z: r.checked(c[2], limit)?,
        })
    })
}

/// `yaw_rate.csv`: one axis (`yaw_rate_rps`), or three (`x_rps`, `y_rps`,
/// `z_rps`, with `yaw_rate_rps` optional: the z axis when absent).
pub(crate) fn parse_gyro(file: &Path, bytes: &[u8]) -> Result<(Vec<Scalar>, Vec<Axes>), IoError> {
    let t = Table::new(file, bytes)?;
    if !(t.has("x_rps") || t.has("y_rps") || t.has("z_rps")) {
        return Ok((
            parse_scalar(file, bytes, "yaw_rate_rps", Limit::YawRate)?,
            Vec::new(),
        ));
    }
    let axes = parse_axes(file, bytes, ["x_rps", "y_rps", "z_rps"], Limit::YawRate)?;
    let yaw = if t.has("yaw_rate_rps") {
        parse_scalar(file, bytes, "yaw_rate_rps", Limit::YawRate)?
    } else {
        axes.iter()
            .map(|a| Scalar {
                t_s: a.t_s,
                value: a.z,
            })
            .collect()
    };
    Ok((yaw, axes))
}

pub(crate) fn parse_scalar(
    file: &Path,
    bytes: &[u8],
    column: &'static str,
    limit: Limit,
) -> Result<Vec<Scalar>, IoError> {
    let t = Table::new(file, bytes)?;
    let (ts, v) = (t.col("t_s")?, t.col(column)?);
    t.rows(|r| {
        Ok(Scalar {
            t_s: r.f64(ts)?,
            value: r.checked(v, limit)?,
        })
    })
}

/// Whether a position file is in east/north (preferred when both are present)
/// or latitude/longitude; `MissingColumn` names what east/north needs.
fn position_columns(t: &Table<'_>) -> Result<bool, IoError> {
    if t.has("east_m") || t.has("north_m") || !(t.has("lat_deg") || t.has("lon_deg")) {
        t.col("east_m")?;
        t.col("north_m")?;
        Ok(false)
    } else {
        t.col("lat_deg")?;
        t.col("lon_deg")?;
        Ok(true)
    }
}

/// The two position columns and their range checks: latitude/longitude or
/// east/north.
fn position_indices(
    t: &Table,
    geodetic: bool,
) -> Result<(Col, Col, Option<Limit>, Option<Limit>), IoError> {
    Ok(if geodetic {
        (
            t.col("lat_deg")?,
            t.col("lon_deg")?,
            Some(Limit::Lat),
            Some(Limit::Lon),
        )
    } else {
        (t.col("east_m")?, t.col("north_m")?, None, None)
    })
}

/// Per-row ellipsoidal heights of a file in latitude/longitude (`None`
/// where it gives none), or `None` for a file in east/north.
pub(crate) type Heights = Option<Vec<Option<f64>>>;

/// The rows' heights as [`Heights`].
fn heights(geodetic: bool, h: Vec<Option<f64>>) -> Heights {
    geodetic.then_some(h)
}

/// Parses `gnss.csv`; with latitude/longitude (heights `Some`) the fixes
/// carry latitude in `east_m` and longitude in `north_m` until converted.
pub(crate) fn parse_gnss(file: &Path, bytes: &[u8]) -> Result<(Vec<GnssFix>, Heights), IoError> {
    let t = Table::new(file, bytes)?;
    let geodetic = position_columns(&t)?;
    let ts = t.col("t_s")?;
    let std = t.col("std_m")?;
    let (a, b, la, lb) = position_indices(&t, geodetic)?;
    let (course, speed) = (t.opt_col("course_deg"), t.opt_col("speed_mps"));
    let height = if geodetic {
        t.opt_col("height_m")
    } else {
        None
    };
    let rows = t.rows(|r| {
        let fix = GnssFix {
            t_s: r.f64(ts)?,
            east_m: position(r, a, la)?,
            north_m: position(r, b, lb)?,
            std_m: r.checked(std, Limit::Std)?,
            course_deg: r.opt_checked(course, Limit::Course)?,
            speed_mps: r.opt_checked(speed, Limit::Speed)?,
        };
        Ok((fix, r.opt_checked(height, Limit::Height)?))
    })?;
    let (fixes, h): (Vec<_>, Vec<_>) = rows.into_iter().unzip();
    Ok((fixes, heights(geodetic, h)))
}

/// Parses `truth.csv`, like [`parse_gnss`].
pub(crate) fn parse_truth(file: &Path, bytes: &[u8]) -> Result<(Vec<TruthPose>, Heights), IoError> {
    let t = Table::new(file, bytes)?;
    let geodetic = position_columns(&t)?;
    let ts = t.col("t_s")?;
    let yaw = t.col("yaw_rad")?;
    let (a, b, la, lb) = position_indices(&t, geodetic)?;
    let speed = t.opt_col("speed_mps");
    let height = if geodetic {
        t.opt_col("height_m")
    } else {
        None
    };
    let rows = t.rows(|r| {
        let pose = TruthPose {
            t_s: r.f64(ts)?,
            east_m: position(r, a, la)?,
            north_m: position(r, b, lb)?,
            yaw_rad: r.checked(yaw, Limit::Yaw)?,
            speed_mps: r.opt_checked(speed, Limit::Speed)?,
        };
        Ok((pose, r.opt_checked(height, Limit::Height)?))
    })?;
    let (poses, h): (Vec<_>, Vec<_>) = rows.into_iter().unzip();
    Ok((poses, heights(geodetic, h)))
}

fn position(
    r: &crate::table::Row<'_>,
    col: crate::table::Col,
    limit: Option<Limit>,
) -> Result<f64, IoError> {
    match limit {
        Some(l) => r.checked(col, l),
        None => r.f64(col),
    }
}
