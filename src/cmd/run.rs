//! `deadreckon run`: write the dead-reckoned track (and, with GNSS, the filtered
//! and smoothed ones, and the truth) with covariances, or one of them as TUM or
//! KITTI for `evo` ([`deadreckon_api::tracks`]).

use std::path::Path;

use anyhow::Result;
use deadreckon_api::{kinematic, tracks};
use deadreckon_core::ekf::FilterOptions;

use super::common;
use crate::args::run::RunArgs;

/// Runs `run`.
pub fn run(a: RunArgs, load: &common::Loader) -> Result<()> {
    common::check_output(&a.out, &[&a.dir, Path::new(&a.params)])?;
    let tricycle = kinematic::is_tricycle_log(&a.dir);
    let written = if tricycle {
        // The tricycle is dead-reckoned through its own kinematics (the car
        // filter's wheel and steering observations oscillate at its steering
        // angles near 1.1 rad), from the first tracker pose.
        anyhow::ensure!(
            a.init_pose.is_none(),
            "a tricycle log starts from its first tracker pose: --init-pose is not used"
        );
        tracks::write_tricycle(&a.dir, &a.params, &a.out, &a.selection(), a.mcap.into())?
    } else {
        let drive = load.drive(&a.dir)?;
        let (params, drive) = deadreckon_api::load::params_corrected(&a.params, drive)?;
        let init_pose = a.init_pose()?;
        let opts = FilterOptions {
            timing: a.timing.into(),
            wheel_monitor: common::wheel_monitor(a.no_wheel_monitor),
            ..Default::default()
        };
        let s = a.selection();
        tracks::write_car(&drive, &params, &opts, init_pose, &a.out, &s, a.mcap.into())?
    };
    match (a.json, tricycle) {
        // A tricycle log is not read through the plausibility checks.
        (true, true) => common::print_pretty(&written.json()),
        (true, false) => common::print_json(load, written.json()),
        (false, _) => common::print_lines(written.lines()),
    }
}
