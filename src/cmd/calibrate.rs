//! `deadreckon calibrate`: RTS, ZUPT or truth calibration of the six
//! parameters of the four-wheel car; for a tricycle log, the kinematic
//! calibration of its seven parameters against the tracker.

use anyhow::Result;

use super::common;
use deadreckon_api::kinematic;
use deadreckon_core::kinematics::Shape;

use crate::args::calibrate::*;

/// Runs `calibrate`.
pub fn run(a: CalibrateArgs, load: &common::Loader) -> Result<()> {
    deadreckon_api::load::check_range(a.from_s, a.until_s)?;
    // A params.toml onto the drive's own files; the stack formats write new
    // files into a directory, which may be the drive's.
    if let (Some(out), OutFormat::Params) = (&a.out, a.format) {
        common::check_output(out, &[&a.dir])?;
    }
    // Only the truth calibration reads truth.csv (a tricycle's drive is read
    // again with it: its tracker is the reference).
    let read = deadreckon_io::ReadOptions::default();
    let read = if a.method == Some(common::MethodArg::Truth) {
        read
    } else {
        read.without_truth()
    };
    // The shape found from the data, read once (deadreckon_api::shape).
    let (drive, found) = deadreckon_api::shape::load(load, &a.dir, &read, a.shape.map(Into::into))?;
    if found.shape != Shape::FourWheel {
        return run_kinematic(&a, load, drive, &found);
    }
    let request = a.request()?;
    let drive = match drive {
        Some(d) => d,
        None => load.drive_with(&a.dir, &read)?,
    };
    let drive = deadreckon_api::load::cut(drive, a.from_s, a.until_s)?;
    // The drive handed over (held once: its corrections are applied in
    // place); the files written take the noise of the drive as read.
    let noise = drive.vehicle.noise;
    let (cc, _) = deadreckon_api::calibration::calibrate_owned(
        drive,
        &request,
        &a.dir.display().to_string(),
    )?;
    let written = match &a.out {
        Some(out) => cc.write(out, a.format.into(), &noise, &a.dir.display().to_string())?,
        None => Vec::new(),
    };
    if a.json {
        let mut v = cc.json();
        v["shape_found"] = found.json();
        common::print_json(load, v)?;
    } else {
        outln!("drive: {}", load.checks().span_text());
        outln!("{}", found.line());
        for l in cc.lines(&a.state.to_string(), &a.iteration.to_string()) {
            outln!("{l}");
        }
        for w in &written {
            outln!("wrote {}", w.display());
        }
    }
    Ok(())
}

/// A tricycle against its tracker (its log, or its drive directory), or a
/// differential drive against its GNSS fixes (`deadreckon_api::kinematic`).
fn run_kinematic(
    a: &CalibrateArgs,
    load: &common::Loader,
    drive: Option<deadreckon_core::Drive>,
    found: &deadreckon_api::shape::Found,
) -> Result<()> {
    let o = kinematic::CalibrateOptions {
        method: a.method.map(common::MethodArg::name),
        window_s: a.window,
        min_speed_mps: a.min_speed,
        from_s: a.from_s,
        until_s: a.until_s,
        every_param: a.every_param,
    };
    let c = if found.shape == Shape::Tricycle {
        kinematic::calibrate_tricycle(&a.dir, drive.as_ref(), &o)?
    } else {
        let drive = match drive {
            Some(d) => d,
            None => load.drive(&a.dir)?,
        };
        kinematic::calibrate_diff(&drive, &a.dir, a.yaw.into(), &o)?
    };
    if let Some(out) = &a.out {
        c.write(out)?;
    }
    let log = deadreckon_api::shape::of_path(&a.dir).is_some();
    match (a.json, log) {
        // A tricycle log is not read through the plausibility checks.
        (true, true) => {
            let mut v = c.json();
            v["shape_found"] = found.json();
            common::print_pretty(&v)
        }
        (true, false) => {
            let mut v = c.json();
            v["shape_found"] = found.json();
            common::print_json(load, v)
        }
        (false, _) => {
            outln!("{}", found.line());
            common::print_lines(c.lines())?;
            common::print_lines(a.out.iter().map(|o| format!("wrote {}", o.display())))
        }
    }
}
