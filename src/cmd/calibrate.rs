//! `deadreckon calibrate`: RTS, ZUPT or truth calibration of the six
//! parameters of the four-wheel car; for a tricycle log, the kinematic
//! calibration of its seven parameters against the tracker.

use anyhow::{Context, Result};
use deadreckon_core::calibrate::{CalibrationOptions, Iteration, Method, PassState};
use deadreckon_core::ekf::FilterOptions;

use deadreckon_core::kinematics::diff_drive::{calibrate_diff_drive, DiffDriveOptions};
use deadreckon_core::kinematics::{self, KinematicOptions, Shape};

use super::{common, kinematic};
use crate::args::kinematic::ShapeArg;

use crate::args::calibrate::*;

/// Runs `calibrate`.
pub fn run(a: CalibrateArgs, load: &common::Loader) -> Result<()> {
    kinematic::check_range(a.from_s, a.until_s)?;
    // A params.toml onto the drive's own files; the stack formats write new
    // files into a directory, which may be the drive's.
    if let (Some(out), OutFormat::Params) = (&a.out, a.format) {
        common::check_output(out, &[&a.dir])?;
    }
    if kinematic::is_tricycle_log(&a.dir) {
        return run_tricycle(&a);
    }
    if a.shape == ShapeArg::DiffDrive {
        return run_diff_drive(&a, load);
    }
    let method_name = a
        .method
        .unwrap_or(common::MethodArg::Rts)
        .name()
        .to_string();
    let method: Method = a.method.unwrap_or(common::MethodArg::Rts).car()?;
    // Only the truth calibration reads truth.csv.
    let read = deadreckon_io::ReadOptions::default();
    let read = if method == Method::Truth {
        read
    } else {
        read.without_truth()
    };
    let drive = load.drive_with(&a.dir, &read)?;
    let drive = if a.from_s.is_some() || a.until_s.is_some() {
        drive.time_range(a.from_s, a.until_s)
    } else {
        drive
    };
    let iteration = match a.iteration {
        IterationArg::Anderson => Iteration::Anderson,
        IterationArg::Plain => Iteration::Plain,
    };
    let state = match a.state {
        StateArg::Augmented => PassState::Augmented,
        StateArg::Paper => PassState::Paper,
    };
    let opts = CalibrationOptions {
        method,
        state,
        iteration,
        max_iterations: a.max_iterations as usize,
        min_speed_mps: a
            .min_speed
            .unwrap_or(Shape::FourWheel.default_min_speed_mps()),
        filter: FilterOptions {
            timing: a.timing.into(),
            wheel_monitor: common::wheel_monitor(a.no_wheel_monitor),
            ..Default::default()
        },
        ..Default::default()
    };
    let cc = deadreckon_api::calibrate::calibrate_car(
        &drive,
        &method_name,
        opts,
        a.corrections.into(),
        &a.dir.display().to_string(),
    )?;
    let mut written = Vec::new();
    if let Some(out) = &a.out {
        let export = || deadreckon_io::stack_params::StackExport {
            estimate: &cc.calibration.estimate,
            samples: cc.calibration.samples,
            noise: &drive.vehicle.noise,
            provenance: cc.provenance(&a.dir.display().to_string()),
        };
        let context = || format!("writing {}", out.display());
        match a.format {
            OutFormat::Params => {
                deadreckon_io::write_params(
                    out,
                    &cc.calibration.estimate,
                    Some(&cc.params_extra()),
                )
                .with_context(context)?;
                written.push(out.clone());
            }
            OutFormat::Autoware => written.extend(
                deadreckon_io::stack_params::write_autoware(out, &export())
                    .with_context(context)?,
            ),
            OutFormat::Eagleye => written.extend(
                deadreckon_io::stack_params::write_eagleye(out, &export()).with_context(context)?,
            ),
        }
    } else if a.format != OutFormat::Params {
        anyhow::bail!(
            "--format {} needs --out DIR",
            format!("{:?}", a.format).to_lowercase()
        );
    }
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

/// The tricycle: the seven kinematic parameters against the tracker.
fn run_tricycle(a: &CalibrateArgs) -> Result<()> {
    let method = a.method.map_or("truth", common::MethodArg::name);
    anyhow::ensure!(
        method == "truth",
        "a tricycle log has no GNSS and no gyro: it is calibrated against its tracker with --method truth (got `{method}`)"
    );
    let drive = kinematic::load_tricycle(&a.dir, a.from_s, a.until_s)?;
    let shape = Shape::Tricycle;
    let opts = KinematicOptions {
        window_s: a.window.unwrap_or(2.0),
        min_speed_mps: a.min_speed.unwrap_or(shape.default_min_speed_mps()),
        ..Default::default()
    };
    let c = kinematics::calibrate(&drive, &opts)
        .with_context(|| format!("calibrating {}", a.dir.display()))?;
    if let Some(out) = &a.out {
        kinematic::write_params(out, shape, method, None, &c)?;
    }
    if a.json {
        outln!(
            "{}",
            serde_json::to_string_pretty(&deadreckon_api::json::kinematic_calibration_json(
                shape, method, &c
            ))?
        );
    } else {
        kinematic::print_table(&c)?;
        if let Some(out) = &a.out {
            outln!("wrote {}", out.display());
        }
    }
    Ok(())
}

/// The differential drive: five parameters against the GNSS fixes.
fn run_diff_drive(a: &CalibrateArgs, load: &common::Loader) -> Result<()> {
    let method = a.method.map_or("gnss", common::MethodArg::name);
    anyhow::ensure!(
        method == "gnss",
        "a differential drive is calibrated against its GNSS fixes with --method gnss (got `{method}`)"
    );
    let drive = load.drive(&a.dir)?;
    let dd = kinematic::diff_drive(&drive, a.yaw, a.from_s, a.until_s)?;
    let shape = Shape::DiffDrive;
    let opts = DiffDriveOptions {
        window_s: a.window.unwrap_or(DiffDriveOptions::default().window_s),
        min_speed_mps: a.min_speed.unwrap_or(shape.default_min_speed_mps()),
        ..Default::default()
    };
    let c = calibrate_diff_drive(&dd, &opts)
        .with_context(|| format!("calibrating {}", a.dir.display()))?;
    if let Some(out) = &a.out {
        kinematic::write_params(out, shape, method, Some(a.yaw.name()), &c)?;
    }
    if a.json {
        let mut v = deadreckon_api::json::kinematic_calibration_json(shape, method, &c);
        v["yaw_source"] = a.yaw.name().into();
        common::print_json(load, v)?;
    } else {
        kinematic::print_table(&c)?;
        if let Some(out) = &a.out {
            outln!("wrote {}", out.display());
        }
    }
    Ok(())
}
