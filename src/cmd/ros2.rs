//! `deadreckon ros2`: the online filter as a live ROS 2 node
//! ([`deadreckon_ros2::run`]), started and resumed as `stream` is.

use std::sync::atomic::AtomicBool;

use anyhow::Result;
use deadreckon_api::stream::{self, StreamOptions};
use deadreckon_ros2::NodeOptions;

use super::common;
use crate::args::ros2::Ros2Args;

/// Runs `ros2` until `stop` is set (SIGINT/SIGTERM) or the idle time passes.
pub fn run(a: Ros2Args, load: &common::Loader, stop: &AtomicBool) -> Result<()> {
    let inputs = a.start.inputs();
    if let Some(out) = &a.state {
        common::check_output(out, &inputs)?;
    }
    let mut mapping = deadreckon_api::source::live_mapping(load.mapping.as_deref())?;
    let o = StreamOptions {
        filter: a.start.filter(),
        state: a.state.clone(),
        learn: a.learn,
        params_out: None,
        save_every_s: None,
        skip_bad_lines: false,
        last_part: false,
    };
    let (vehicle, mut online, warning) = stream::start(&a.start.vehicle, &a.start.params, &o)?;
    if let Some(n) = stream::corrections_note(&a.start.params, &online) {
        note!("{n}");
    }
    if let Some(w) = warning {
        note!("warning: {w}");
    }
    mapping.vehicle = vehicle;
    let node = NodeOptions {
        domain_id: a.domain_id,
        until_idle_s: a.until_idle,
        reorder_window_s: a.reorder_window,
        learned_every_s: a.learned_every_s,
        ..Default::default()
    };
    let summary = deadreckon_ros2::run(&mut online, &mapping, &node, stop)?;
    for line in summary.lines() {
        note!("{line}");
    }
    if let Some(why) = &summary.not_started {
        anyhow::bail!("the filter never started: {why}");
    }
    if let Some(path) = &a.state {
        stream::save_state(path, &online)?;
    }
    if let Some(l) = summary.learned {
        note!(
            "learned: {:.0}% calibrated, {}",
            l.calibrated_pct,
            if l.valid { "valid" } else { "not yet valid" }
        );
    }
    Ok(())
}
