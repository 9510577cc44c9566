//! The commands' own library path, end to end: what `deadreckon calibrate`,
//! `evaluate --outage`, `run` and `report` call in `deadreckon-api`, reading the drive
//! directory included (with the plausibility checks, as the command line
//! reads it). The command-line parsing and printing are left out: they cost
//! nothing next to these.

use std::path::Path;

use deadreckon_api::load::Loader;
use deadreckon_core::ekf::FilterOptions;
use deadreckon_core::timing::Which;

/// A command as the command line runs it with its defaults.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Command {
    /// `deadreckon calibrate DIR` (RTS, the default corrections: `auto`,
    /// each chosen on held-back GNSS).
    Calibrate,
    /// `deadreckon calibrate DIR --corrections gnss` (the GNSS delay's
    /// steps without the held-back choice).
    CalibrateGnss,
    /// `deadreckon calibrate DIR --corrections none`.
    CalibrateNone,
    /// `deadreckon evaluate DIR --outage 30 --step 10` (self-calibrating
    /// with the default corrections, then 30 s outages every 10 s).
    EvaluateOutage,
    /// `deadreckon run DIR --params nominal --out tracks.csv` (the
    /// dead-reckoned, filtered and smoothed tracks, and the wheel health).
    Run,
    /// `deadreckon report DIR --out report.html` (the default corrections,
    /// the calibrations, the filter health, dead reckoning and drift: the
    /// HTML page written to `out`).
    Report,
}

impl Command {
    /// Every command, in the order of the tables.
    pub const ALL: [Command; 6] = [
        Command::Calibrate,
        Command::CalibrateGnss,
        Command::CalibrateNone,
        Command::EvaluateOutage,
        Command::Run,
        Command::Report,
    ];

    /// The name on the example's command line (`calibrate`,
    /// `calibrate-gnss`, `calibrate-none`, `evaluate-outage`, `run`,
    /// `report`).
    pub fn name(self) -> &'static str {
        match self {
            Command::Calibrate => "calibrate",
            Command::CalibrateGnss => "calibrate-gnss",
            Command::CalibrateNone => "calibrate-none",
            Command::EvaluateOutage => "evaluate-outage",
            Command::Run => "run",
            Command::Report => "report",
        }
    }

    /// The command line it stands for.
    pub fn command_line(self) -> &'static str {
        match self {
            Command::Calibrate => "deadreckon calibrate DIR",
            Command::CalibrateGnss => "deadreckon calibrate DIR --corrections gnss",
            Command::CalibrateNone => "deadreckon calibrate DIR --corrections none",
            Command::EvaluateOutage => "deadreckon evaluate DIR --outage 30 --step 10",
            Command::Run => "deadreckon run DIR --params nominal --out tracks.csv",
            Command::Report => "deadreckon report DIR --out report.html",
        }
    }

    /// The command named `name` ([`Command::name`]).
    pub fn from_name(name: &str) -> Option<Command> {
        Command::ALL.into_iter().find(|c| c.name() == name)
    }

    /// Runs the command's library path on the drive directory `dir`
    /// (`out`: where `run` writes its tracks and `report` its page) and
    /// returns the drive's wheel epochs.
    pub fn run(self, dir: &Path, out: &Path) -> Result<usize, deadreckon_api::Error> {
        let load = Loader::default();
        match self {
            Command::Calibrate | Command::CalibrateGnss | Command::CalibrateNone => {
                let read = deadreckon_io::ReadOptions::default().without_truth();
                let drive = load.drive_with(dir, &read)?;
                let which = match self {
                    Command::CalibrateGnss => Which::Gnss,
                    Command::CalibrateNone => Which::None,
                    _ => Which::default(),
                };
                // As the command line: the drive handed over.
                let epochs = drive.wheels.len();
                let (cc, _) = deadreckon_api::calibration::calibrate_owned(
                    drive,
                    &deadreckon_api::calibration::CalibrationRequest::with_corrections(which),
                    "drive",
                )?;
                std::hint::black_box(cc.json());
                Ok(epochs)
            }
            Command::EvaluateOutage => {
                use deadreckon_api::evaluate;
                let drive = load.drive(dir)?;
                let epochs = drive.wheels.len();
                // As the command line: the drive handed over, so the drive
                // as read is dropped once the corrected one exists (holding
                // it put one more copy of the drive under `measure`'s peak).
                let (chosen, drive) = evaluate::parameters(
                    None,
                    drive,
                    Which::default(),
                    load.params_for_other_vehicle,
                )?;
                let ev = evaluate::measure(
                    &drive,
                    chosen,
                    deadreckon_core::ekf::Timing::WheelEpochs,
                    evaluate::Metric::Outages {
                        length_s: 30.0,
                        step_s: 10.0,
                        warmup_s: evaluate::OUTAGE_WARMUP_S,
                    },
                )?;
                std::hint::black_box(ev.json());
                Ok(epochs)
            }
            Command::Run => {
                let drive = load.drive(dir)?;
                let epochs = drive.wheels.len();
                let (params, drive) = deadreckon_api::load::params_corrected("nominal", drive)?;
                let written = deadreckon_api::tracks::write_car(
                    &drive,
                    &params,
                    &FilterOptions::default(),
                    None,
                    out,
                    &deadreckon_api::tracks::Selection::default(),
                    deadreckon_ros::McapOptions::FOXGLOVE,
                    &deadreckon_core::bound::BoundFit::FILTER,
                )?;
                std::hint::black_box(written.json());
                Ok(epochs)
            }
            Command::Report => {
                let drive = load.drive(dir)?;
                let epochs = drive.wheels.len();
                // As the command line's `report` with its defaults.
                let o = deadreckon_api::report::ReportOptions {
                    dir,
                    params: None,
                    model: None,
                    outage_s: None,
                    step_s: None,
                    corrections: Which::default(),
                    shape: None,
                };
                deadreckon_api::report::write(drive, &o, out, &(), &Default::default())?;
                Ok(epochs)
            }
        }
    }
}

/// Simulates the calibration scenario for `duration_s` seconds (seed 1,
/// as `deadreckon simulate --scenario calibration --duration D --seed 1`)
/// into the drive directory `dir`: the laps repeated until then, byte for
/// byte the command's drive.
pub fn write_drive(dir: &Path, duration_s: f64) -> Result<(), deadreckon_api::Error> {
    let sc = deadreckon_sim::Scenario::builtin("calibration").expect("built-in scenario");
    let laps = sc.laps_lasting(duration_s).expect("a lap count");
    let sc = sc.with_laps(laps).with_duration_s(duration_s);
    deadreckon_api::load::write_simulated(sc, "calibration", 1, dir).map(|_| ())
}
