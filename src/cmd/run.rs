//! `deadreckon run`: write the dead-reckoned track (and, with GNSS, the filtered
//! and smoothed ones) with covariances.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use clap::Args;
use deadreckon_core::ekf::{self, FilterOptions, Init, SensorSet};
use deadreckon_core::model::{Mat, State};
use deadreckon_core::{rts, Drive, Params, Track};

use deadreckon_core::kinematics::tricycle::TricycleParams;
use deadreckon_core::kinematics::Shape;

use super::{common, kinematic};

/// Arguments of `run`.
#[derive(Args, Debug)]
pub struct RunArgs {
    /// The drive directory.
    pub dir: PathBuf,
    /// `nominal` or a params.toml.
    #[arg(long, default_value = "nominal")]
    pub params: String,
    /// Output file: .csv, .geojson or .mcap (by extension).
    #[arg(long)]
    pub out: PathBuf,
    /// Filter timing: wheel or each.
    #[arg(long, default_value = "wheel")]
    pub timing: String,
    /// Initial pose for dead reckoning `EAST_M,NORTH_M,YAW_RAD` (default: the truth, else the smoothed GNSS track).
    #[arg(long)]
    pub init_pose: Option<String>,
}

/// The tracks of a drive: dead-reckoned, and with GNSS the filtered and smoothed.
pub fn tracks(
    drive: &Drive,
    params: &Params,
    opts: &FilterOptions,
    init_pose: Option<(f64, f64, f64)>,
) -> Result<Vec<Track>> {
    let origin = drive.vehicle.origin;
    let mut out = Vec::new();
    let mut smoothed_start = None;
    if drive.gnss.len() >= 2 {
        let f = ekf::run(
            drive,
            params,
            &FilterOptions {
                record_epochs: true,
                ..opts.clone()
            },
            &mut (),
        )?;
        let s = rts::smooth(&f.epochs)?;
        smoothed_start = s.first().map(|s| (s.t_s, s.x, s.p));
        out.push(Track::from_epochs("filtered", &f.epochs, origin));
        out.push(Track::from_smoothed("smoothed", &s, origin));
    }
    let init = dead_reckoning_init(drive, init_pose, smoothed_start)?;
    out.insert(0, dead_reckoned(drive, params, opts, init)?);
    Ok(out)
}

/// Where dead reckoning starts: the given pose, else the truth, else the
/// start of the smoothed GNSS-aided track.
pub fn dead_reckoning_init(
    drive: &Drive,
    init_pose: Option<(f64, f64, f64)>,
    smoothed_start: Option<(f64, State, Mat)>,
) -> Result<Init> {
    Ok(if let Some((e, n, y)) = init_pose {
        Init::Given {
            t_s: drive.wheels.t_s(0),
            x: State::from([e, n, y, 0.0, 0.0]),
            p: Mat::from_diagonal(&State::from([1e-4, 1e-4, 1e-6, 4.0, 0.25])),
        }
    } else if !drive.truth.is_empty() {
        Init::Truth
    } else if let Some((t_s, x, p)) = smoothed_start {
        Init::Given { t_s, x, p }
    } else {
        anyhow::bail!("dead reckoning needs an initial pose: truth.csv, gnss.csv or --init-pose");
    })
}

/// The dead-reckoned track (proprioceptive sensors only) from `init`.
pub fn dead_reckoned(
    drive: &Drive,
    params: &Params,
    opts: &FilterOptions,
    init: Init,
) -> Result<Track> {
    let dr = ekf::run(
        drive,
        params,
        &FilterOptions {
            init,
            sensors: SensorSet::dead_reckoning(),
            record_epochs: true,
            ..opts.clone()
        },
        &mut (),
    )?;
    Ok(Track::from_epochs(
        "dead-reckoned",
        &dr.epochs,
        drive.vehicle.origin,
    ))
}

/// Writes tracks by the file's extension.
pub fn write_tracks(path: &Path, tracks: &[Track]) -> Result<()> {
    match path.extension().and_then(|e| e.to_str()) {
        Some("csv") => deadreckon_io::write_track_csv(path, tracks)?,
        Some("geojson") | Some("json") => deadreckon_io::write_track_geojson(path, tracks)?,
        Some("mcap") => super::write_mcap(path, tracks)?,
        _ => anyhow::bail!(
            "unknown output format for {} (use .csv, .geojson or .mcap)",
            path.display()
        ),
    }
    Ok(())
}

/// Runs `run`.
pub fn run(a: RunArgs) -> Result<()> {
    if kinematic::is_tricycle_log(&a.dir) {
        // The tricycle is dead-reckoned through its own kinematics (the car
        // filter's wheel and steering observations oscillate at its steering
        // angles near 1.1 rad), from the first tracker pose.
        anyhow::ensure!(
            a.init_pose.is_none(),
            "a tricycle log starts from its first tracker pose: --init-pose is not used"
        );
        let drive = kinematic::load_tricycle(&a.dir, None, None)?;
        let (p, _) = kinematic::load_params(&a.params, Shape::Tricycle, &drive)?;
        let params = TricycleParams::from_slice(&p)?;
        let t = drive.tracks(&params)?;
        write_tracks(&a.out, &t).with_context(|| format!("writing {}", a.out.display()))?;
        for tr in &t {
            println!("{:<14} {:>7} poses", tr.name, tr.points.len());
        }
        println!("wrote {}", a.out.display());
        return Ok(());
    }
    let drive = common::load_drive(&a.dir)?;
    let params = common::load_params(&a.params, &drive)?;
    let init_pose = match &a.init_pose {
        Some(s) => {
            let v: Vec<f64> = s
                .split(',')
                .map(|x| x.trim().parse::<f64>())
                .collect::<Result<_, _>>()
                .context("--init-pose EAST_M,NORTH_M,YAW_RAD")?;
            anyhow::ensure!(
                v.len() == 3 && v.iter().all(|x| x.is_finite()),
                "--init-pose needs three finite numbers EAST_M,NORTH_M,YAW_RAD"
            );
            Some((v[0], v[1], v[2]))
        }
        None => None,
    };
    let opts = FilterOptions {
        timing: common::parse_timing(&a.timing)?,
        ..Default::default()
    };
    let t = tracks(&drive, &params, &opts, init_pose)?;
    write_tracks(&a.out, &t).with_context(|| format!("writing {}", a.out.display()))?;
    for tr in &t {
        println!("{:<14} {:>7} poses", tr.name, tr.points.len());
    }
    println!("wrote {}", a.out.display());
    Ok(())
}
