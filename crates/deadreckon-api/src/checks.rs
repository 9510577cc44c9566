//! The cross-stream plausibility checks of a drive
//! ([`deadreckon_core::plausibility`]) as the commands and the Python
//! bindings apply them: an error refuses the drive (every error listed, with
//! how to read it anyway), a warning is kept and reported, on standard error
//! by the command line and under `"checks"` in every `--json` object.

use std::path::Path;

use deadreckon_core::plausibility::{self, Finding, Severity};
use deadreckon_core::Drive;
use serde_json::{json, Value};

use crate::Error;

/// What the checks said of a drive that passed them.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Checks {
    /// The checks were not run (`--skip-checks`).
    pub skipped: bool,
    /// The warnings (suspicious, not refused).
    pub warnings: Vec<Finding>,
}

impl Checks {
    /// The checks as the `"checks"` object of `--json`:
    /// `{"skipped": bool, "warnings": [{"check", "severity", "message"}]}`.
    pub fn json(&self) -> Value {
        json!({
            "skipped": self.skipped,
            "warnings": self.warnings,
        })
    }
}

/// Runs the checks on the drive read from `path` (`skip`: not at all).
/// Errors refuse it; warnings are returned.
pub fn check(path: &Path, drive: &Drive, skip: bool) -> Result<Checks, Error> {
    if skip {
        return Ok(Checks {
            skipped: true,
            warnings: Vec::new(),
        });
    }
    let (errors, warnings): (Vec<Finding>, Vec<Finding>) = plausibility::check(drive)
        .into_iter()
        .partition(|f| f.severity == Severity::Error);
    if !errors.is_empty() {
        return Err(Error::Implausible {
            path: path.to_path_buf(),
            findings: errors
                .iter()
                .map(|f| format!("  {} ({})", f.message, f.check))
                .collect::<Vec<_>>()
                .join("\n"),
        });
    }
    Ok(Checks {
        skipped: false,
        warnings,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_drive_that_never_moves_passes_with_no_warning() {
        let drive = parked();
        let c = check(Path::new("d"), &drive, false).unwrap();
        assert_eq!(c, Checks::default());
        assert_eq!(c.json(), json!({"skipped": false, "warnings": []}));
        let s = check(Path::new("d"), &drive, true).unwrap();
        assert_eq!(s.json(), json!({"skipped": true, "warnings": []}));
    }

    /// A RAV4 with two wheel rows at standstill.
    fn parked() -> Drive {
        use deadreckon_core::drive::{WheelTicks, Wheels};
        let mut d = Drive::empty(deadreckon_import::profiles::toyota_rav4());
        let row = |t_s| WheelTicks {
            t_s,
            fl: 0,
            fr: 0,
            rl: 0,
            rr: 0,
        };
        d.wheels = Wheels::Ticks(vec![row(0.0), row(0.01)]);
        d
    }

    #[test]
    fn an_error_refuses_the_drive_and_names_every_finding() {
        let mut drive = parked();
        // Millimetres: every length a thousand times too long.
        drive.vehicle.wheelbase_m *= 1000.0;
        let e = check(Path::new("d"), &drive, false)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("d: the streams disagree") && e.contains("vehicle_lengths"),
            "{e}"
        );
        assert!(e.contains("--skip-checks"), "{e}");
        assert!(check(Path::new("d"), &drive, true).is_ok());
    }
}
