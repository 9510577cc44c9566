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
    /// The drive's time span on its own clock, s (`None`: no sample).
    pub time_span_s: Option<(f64, f64)>,
}

impl Checks {
    /// Adds `"checks"` ([`Checks::json`]) and `"time_span_s"` (`[start,
    /// end]` on the drive's clock, or null) to a `--json` object.
    pub fn annotate(&self, v: &mut Value) {
        if let Some(o) = v.as_object_mut() {
            o.insert("checks".into(), self.json());
            o.insert(
                "time_span_s".into(),
                self.time_span_s.map_or(Value::Null, |(a, b)| json!([a, b])),
            );
        }
    }

    /// The time span as a summary line: `drive clock 46408.580 to
    /// 46468.580 s (60.0 s)` (bag clocks are UNIX time).
    pub fn span_text(&self) -> String {
        match self.time_span_s {
            Some((a, b)) => format!("drive clock {a:.3} to {b:.3} s ({:.1} s)", b - a),
            None => "no samples".into(),
        }
    }

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
    let time_span_s = drive.time_span();
    if skip {
        return Ok(Checks {
            skipped: true,
            warnings: Vec::new(),
            time_span_s,
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
        time_span_s,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_drive_that_never_moves_passes_with_no_warning() {
        let drive = parked();
        let c = check(Path::new("d"), &drive, false).unwrap();
        assert_eq!(c.json(), json!({"skipped": false, "warnings": []}));
        assert_eq!(c.time_span_s, Some((0.0, 0.01)));
        let mut v = json!({"x": 1});
        c.annotate(&mut v);
        assert_eq!(
            v,
            json!({"x": 1, "checks": {"skipped": false, "warnings": []}, "time_span_s": [0.0, 0.01]})
        );
        assert_eq!(c.span_text(), "drive clock 0.000 to 0.010 s (0.0 s)");
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
