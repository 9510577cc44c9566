//! `deadreckon report` for a kinematic shape (issue 29, item 3): a tricycle
//! or a differential drive gets its own sections (the shape and why, its
//! kinematic calibration's parameters, the dead-reckoned track of a
//! tricycle, the sliding outages with `--outage`), not the car's
//! circumference table.

use std::path::Path;

use deadreckon_core::kinematics::diff_drive::{OutageStart, DEFAULT_WARMUP_S};
use deadreckon_core::kinematics::Shape;
use deadreckon_core::Drive;
use deadreckon_eval::report::header;
use deadreckon_eval::Progress;
use deadreckon_report as rp;

use crate::error::While;
use crate::kinematic::{self, CalibrateOptions};
use crate::report::ReportOptions;
use crate::shape::Found;
use crate::Error;

/// An east-north path of timed points `(t_s, east_m, north_m)`.
fn path(points: impl Iterator<Item = (f64, f64, f64)>) -> rp::EnPath {
    let mut p = rp::EnPath::default();
    for (t, e, n) in points {
        p.t_s.push(t);
        p.east_m.push(e);
        p.north_m.push(n);
    }
    p
}

/// Builds the report of a kinematic shape's drive and writes it to `out`.
pub fn write(
    drive: &Drive,
    found: &Found,
    o: &ReportOptions,
    out: &Path,
    steps: &dyn Progress,
    footer: &rp::Footer,
) -> Result<(), Error> {
    // A tricycle log is read through its own kinematics; a drive directory
    // through its drive.
    let own = (crate::shape::of_path(o.dir).is_none()).then_some(drive);
    let mut input = rp::ReportInput::default();
    let mut traj = rp::Trajectories::default();
    if !drive.truth.is_empty() {
        traj.truth = Some(path(
            drive.truth.iter().map(|p| (p.t_s, p.east_m, p.north_m)),
        ));
    }
    if !drive.gnss.is_empty() {
        traj.gnss = Some(path(
            drive.gnss.iter().map(|g| (g.t_s, g.east_m, g.north_m)),
        ));
    }
    steps.step("kinematic calibration");
    let (calibrated, evaluated) = match found.shape {
        Shape::Tricycle => {
            let c = kinematic::calibrate_tricycle(o.dir, own, &CalibrateOptions::default())?;
            let (tracks, source) = kinematic::tricycle_tracks(o.dir, own, o.params)?;
            if let Some(t) = tracks.iter().find(|t| t.name == "dead-reckoned") {
                traj.dead_reckoned.push(rp::MethodPath {
                    method: source,
                    path: path(t.points.iter().map(|p| (p.t_s, p.east_m, p.north_m))),
                });
            }
            steps.step("outages");
            let e = match o.outage_s {
                Some(len) => Some(kinematic::evaluate_tricycle(
                    o.dir,
                    own,
                    o.params,
                    len,
                    o.step_s.unwrap_or(len / 2.0),
                    None,
                    None,
                )?),
                None => None,
            };
            (c, e)
        }
        _ => {
            let yaw = kinematic::diff_yaw(o.params, None);
            let c = kinematic::calibrate_diff(drive, o.dir, yaw, &CalibrateOptions::default())?;
            steps.step("outages");
            let e = match o.outage_s {
                Some(len) => Some(kinematic::evaluate_diff(
                    drive,
                    o.params,
                    yaw,
                    len,
                    o.step_s.unwrap_or(len / 2.0),
                    DEFAULT_WARMUP_S,
                    &OutageStart::Filter(Default::default()),
                    None,
                    None,
                )?),
                None => None,
            };
            (c, e)
        }
    };
    let table = calibrated.lines();
    input.kinematic = Some(rp::Kinematic {
        shape: format!("{} ({})", crate::shape::words(found.shape), found.reason),
        method: calibrated.method.to_string(),
        params: calibrated
            .calibration
            .params
            .iter()
            .map(|p| rp::KinematicParam {
                name: p.name.clone(),
                value: p.value,
                std: p.std.filter(|_| p.estimated),
                status: if p.estimated {
                    "estimated".into()
                } else {
                    format!("not estimated: {}", p.reason.clone().unwrap_or_default())
                },
            })
            .collect(),
        fit: table.last().cloned().unwrap_or_default(),
    });
    input.trajectories = Some(traj);
    if let Some(m) = o.model {
        steps.step("TedriS");
        input.tedris = Some(crate::report::tedris_section(drive, m, o.outage_s)?);
    }
    input.outages = evaluated.map(|e| rp::OutageEvaluation {
        window_s: Some(e.length_s),
        methods: vec![rp::MethodSample {
            method: e.source.clone(),
            final_error_m: e
                .evaluation
                .windows
                .iter()
                .map(|w| w.final_error_m)
                .collect(),
        }],
        // A kinematic shape's windows carry their final error only, so the
        // bound's curve through time is not drawn (`evaluate` gives the
        // differential drive's bound at each window's end).
        bound: None,
    });
    let name = o
        .dir
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| o.dir.display().to_string());
    input.header = header(
        drive,
        &name,
        vec![("drive".into(), o.dir.display().to_string())],
    );
    input.footer = footer.clone();
    rp::write_report(out, &input).doing(|| format!("writing {}", out.display()))
}
