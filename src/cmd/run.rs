//! `deadreckon run`: write the dead-reckoned track (and, with GNSS, the filtered
//! and smoothed ones, and the truth) with covariances, or one of them as TUM or
//! KITTI for `evo` ([`deadreckon_api::tracks`]).

use std::path::Path;

use anyhow::Result;
use deadreckon_api::{evaluate, tracks};
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::kinematics::Shape;

use super::common;
use crate::args::run::RunArgs;

/// Runs `run`.
pub fn run(a: RunArgs, load: &common::Loader) -> Result<()> {
    let params_path = a.params.as_deref().map(Path::new);
    let inputs: Vec<&Path> = std::iter::once(a.dir.as_path())
        .chain(params_path)
        .collect();
    common::check_output(&a.out, &inputs)?;
    // The shape found from the data, read once (deadreckon_api::shape).
    let read = deadreckon_io::ReadOptions::default();
    let (drive, found) = deadreckon_api::shape::load(load, &a.dir, &read, a.shape.map(Into::into))?;
    if !a.json {
        outln!("{}", found.line());
    }
    let log = deadreckon_api::shape::of_path(&a.dir).is_some();
    let (written, source) = if found.shape == Shape::Tricycle {
        // The tricycle is dead-reckoned through its own kinematics (the car
        // filter's wheel and steering observations oscillate at its steering
        // angles near 1.1 rad), from the first tracker pose.
        anyhow::ensure!(
            a.init_pose.is_none(),
            "a tricycle starts from its first tracker pose: --init-pose is not used"
        );
        let (tracks, source) = deadreckon_api::kinematic::tricycle_tracks(
            &a.dir,
            drive.as_ref(),
            a.params.as_deref(),
        )?;
        let w = tracks::write_tracks(tracks, &a.out, &a.selection(), a.mcap.into())?;
        (w, source)
    } else {
        if found.shape == Shape::DiffDrive {
            note!("note: run writes the four-wheel filter's tracks: a differential drive's own are not written yet (--shape car runs it as a car without this note)");
        }
        let drive = match drive {
            Some(d) => d,
            None => load.drive(&a.dir)?,
        };
        // One rule for "no --params" (deadreckon_api::evaluate::RULE).
        let (chosen, drive) = evaluate::parameters(
            a.params.as_deref(),
            drive,
            a.corrections.into(),
            load.params_for_other_vehicle,
        )?;
        if let Some(n) = &chosen.note {
            note!("note: {n}");
        }
        let init_pose = a.init_pose()?;
        let opts = FilterOptions {
            timing: a.timing.into(),
            wheel_monitor: common::wheel_monitor(a.no_wheel_monitor),
            ..Default::default()
        };
        let s = a.selection();
        let w = tracks::write_car(
            &drive,
            &chosen.params,
            &opts,
            init_pose,
            &a.out,
            &s,
            a.mcap.into(),
            &chosen.bound,
        )?;
        (w, chosen.source)
    };
    let mut v = written.json();
    v["params_source"] = source.clone().into();
    v["shape_found"] = found.json();
    match (a.json, log) {
        // A tricycle log is not read through the plausibility checks.
        (true, true) => common::print_pretty(&v),
        (true, false) => common::print_json(load, v),
        (false, _) => {
            outln!("parameters: {source}");
            common::print_lines(written.lines())
        }
    }
}
