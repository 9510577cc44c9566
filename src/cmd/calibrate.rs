//! `deadreckon calibrate`: RTS, ZUPT or truth calibration of the six
//! parameters of the four-wheel car; for a tricycle log, the kinematic
//! calibration of its seven parameters against the tracker.

use anyhow::Result;
use deadreckon_core::calibrate::Method;

use super::common;
use crate::args::kinematic::ShapeArg;
use deadreckon_api::kinematic;

use crate::args::calibrate::*;

/// Runs `calibrate`.
pub fn run(a: CalibrateArgs, load: &common::Loader) -> Result<()> {
    deadreckon_api::load::check_range(a.from_s, a.until_s)?;
    // A params.toml onto the drive's own files; the stack formats write new
    // files into a directory, which may be the drive's.
    if let (Some(out), OutFormat::Params) = (&a.out, a.format) {
        common::check_output(out, &[&a.dir])?;
    }
    let tricycle = kinematic::is_tricycle_log(&a.dir);
    if tricycle || a.shape == ShapeArg::DiffDrive {
        return run_kinematic(&a, load, tricycle);
    }
    let (method_name, opts) = a.car_options()?;
    // Only the truth calibration reads truth.csv.
    let read = deadreckon_io::ReadOptions::default();
    let read = if opts.method == Method::Truth {
        read
    } else {
        read.without_truth()
    };
    let drive = deadreckon_api::load::cut(load.drive_with(&a.dir, &read)?, a.from_s, a.until_s)?;
    let cc = deadreckon_api::calibrate::calibrate_car(
        &drive,
        &method_name,
        opts,
        a.corrections.into(),
        &a.dir.display().to_string(),
    )?;
    let written = match &a.out {
        Some(out) => cc.write(
            out,
            a.format.into(),
            &drive.vehicle.noise,
            &a.dir.display().to_string(),
        )?,
        None => Vec::new(),
    };
    if a.json {
        common::print_json(load, cc.json())?;
    } else {
        outln!("drive: {}", load.checks().span_text());
        for l in cc.lines(&a.state.to_string(), &a.iteration.to_string()) {
            outln!("{l}");
        }
        for w in &written {
            outln!("wrote {}", w.display());
        }
    }
    Ok(())
}

/// A tricycle log against its tracker, or a differential drive against its
/// GNSS fixes (`deadreckon_api::kinematic`).
fn run_kinematic(a: &CalibrateArgs, load: &common::Loader, tricycle: bool) -> Result<()> {
    let o = kinematic::CalibrateOptions {
        method: a.method.map(common::MethodArg::name),
        window_s: a.window,
        min_speed_mps: a.min_speed,
        from_s: a.from_s,
        until_s: a.until_s,
    };
    let c = if tricycle {
        kinematic::calibrate_tricycle(&a.dir, &o)?
    } else {
        let drive = load.drive(&a.dir)?;
        kinematic::calibrate_diff(&drive, &a.dir, a.yaw.into(), &o)?
    };
    if let Some(out) = &a.out {
        c.write(out)?;
    }
    match (a.json, tricycle) {
        // A tricycle log is not read through the plausibility checks.
        (true, true) => common::print_pretty(&c.json()),
        (true, false) => common::print_json(load, c.json()),
        (false, _) => {
            common::print_lines(c.lines())?;
            common::print_lines(a.out.iter().map(|o| format!("wrote {}", o.display())))
        }
    }
}
