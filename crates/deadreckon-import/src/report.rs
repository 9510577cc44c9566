//! What an import kept, gated and decided.

use std::fmt;

/// Counts for one output stream.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StreamReport {
    /// Stream name (`wheel_speeds`, `yaw_rate`, `gnss`, ...).
    pub name: String,
    /// Samples kept.
    pub kept: usize,
    /// Samples dropped because their time was not after the previous kept one
    /// (only with [`crate::TimeOrderPolicy::Gate`]).
    pub gated_time_order: usize,
    /// Samples dropped because a value was non-finite or implausible (only with
    /// [`crate::TimeOrderPolicy::Gate`]).
    pub gated_invalid: usize,
    /// First kept timestamp, s.
    pub first_t_s: Option<f64>,
    /// Last kept timestamp, s.
    pub last_t_s: Option<f64>,
}

impl StreamReport {
    /// Duration between the first and last kept samples, s.
    pub fn duration_s(&self) -> f64 {
        match (self.first_t_s, self.last_t_s) {
            (Some(a), Some(b)) => b - a,
            _ => 0.0,
        }
    }
}

/// The report of one import.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ImportReport {
    /// Input format (`comma2k19`, `can`, `tricycle`).
    pub format: String,
    /// One entry per output stream, in drive order.
    pub streams: Vec<StreamReport>,
    /// Decisions taken (sources chosen, offsets applied, defaults used).
    pub notes: Vec<String>,
}

impl ImportReport {
    /// The report of stream `name`, if the import produced it.
    pub fn stream(&self, name: &str) -> Option<&StreamReport> {
        self.streams.iter().find(|s| s.name == name)
    }

    /// Total samples gated over all streams.
    pub fn total_gated(&self) -> usize {
        self.streams
            .iter()
            .map(|s| s.gated_time_order + s.gated_invalid)
            .sum()
    }
}

impl fmt::Display for ImportReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "format: {}", self.format)?;
        writeln!(
            f,
            "{:<14} {:>8} {:>10} {:>10} {:>12} {:>12}",
            "stream", "kept", "duration_s", "gated_time", "gated_value", "first_t_s"
        )?;
        for s in &self.streams {
            writeln!(
                f,
                "{:<14} {:>8} {:>10.3} {:>10} {:>12} {:>12}",
                s.name,
                s.kept,
                s.duration_s(),
                s.gated_time_order,
                s.gated_invalid,
                s.first_t_s
                    .map(|t| format!("{t:.3}"))
                    .unwrap_or_else(|| "-".into())
            )?;
        }
        for n in &self.notes {
            writeln!(f, "note: {n}")?;
        }
        Ok(())
    }
}
