//! The JSON-lines event stream (`docs/events.md`): one measurement a line, as
//! `deadreckon events` prints and `deadreckon stream` reads.
//!
//! ```
//! let ev = deadreckon_io::events::parse_line(
//!     r#"{"t_s": 12.35, "sensor": "yaw_rate", "yaw_rate_rps": 0.01}"#,
//!     "stdin",
//!     1,
//! )
//! .unwrap();
//! assert_eq!(ev.t_s, 12.35);
//! assert_eq!(deadreckon_io::events::to_line(&ev), r#"{"t_s":12.35,"sensor":"yaw_rate","yaw_rate_rps":0.01}"#);
//! ```

use deadreckon_core::ekf::{Event, Measurement};

use crate::IoError;

/// Parses one line of the event stream; `source` and `line` (1-based) name
/// where it came from in the error.
pub fn parse_line(text: &str, source: &str, line: u64) -> Result<Event, IoError> {
    let bad = |column: usize, msg: String| IoError::BadEvent {
        source_name: source.to_string(),
        line,
        column,
        msg,
    };
    let ev: Event = serde_json::from_str(text).map_err(|e| bad(e.column(), e.to_string()))?;
    if !values_ok(&ev) {
        return Err(bad(1, NOT_FINITE.into()));
    }
    Ok(ev)
}

/// What [`parse_line`] says of an event whose [`values_ok`] is false.
pub const NOT_FINITE: &str = "a value is not finite (or std_m is not positive)";

/// True when every value of `ev` is finite and a GNSS `std_m` is positive:
/// the check of [`parse_line`], also made by the C API on its typed events.
pub fn values_ok(ev: &Event) -> bool {
    let finite = |v: f64| v.is_finite();
    finite(ev.t_s)
        && match ev.measurement {
            Measurement::WheelTicks { .. } => true,
            Measurement::WheelSpeeds {
                fl_mps,
                fr_mps,
                rl_mps,
                rr_mps,
            } => [fl_mps, fr_mps, rl_mps, rr_mps].into_iter().all(finite),
            Measurement::YawRate { yaw_rate_rps } => finite(yaw_rate_rps),
            Measurement::Speed { speed_mps } => finite(speed_mps),
            Measurement::Steering { steering_wheel_rad } => finite(steering_wheel_rad),
            Measurement::Gyro {
                x_rps,
                y_rps,
                z_rps,
            } => [x_rps, y_rps, z_rps].into_iter().all(finite),
            Measurement::Accel {
                x_mps2,
                y_mps2,
                z_mps2,
            } => [x_mps2, y_mps2, z_mps2].into_iter().all(finite),
            Measurement::Gnss {
                east_m,
                north_m,
                std_m,
                course_deg,
                speed_mps,
            } => {
                finite(east_m)
                    && finite(north_m)
                    && finite(std_m)
                    && std_m > 0.0
                    && course_deg.is_none_or(finite)
                    && speed_mps.is_none_or(finite)
            }
        }
}

/// One event as a JSON line (without the newline). Numbers are written with
/// the shortest representation that reads back to the same bits.
pub fn to_line(ev: &Event) -> String {
    // Serialising plain numbers and strings cannot fail.
    serde_json::to_string(ev).unwrap_or_default()
}
