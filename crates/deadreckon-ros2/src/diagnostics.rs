//! The learned parameters as ROS 2 diagnostics: `diagnostic_msgs/msg/DiagnosticArray`
//! on `/diagnostics` (what `rqt_runtime_monitor` and the diagnostic aggregator
//! read), one status named [`LEARNED_NAME`].
//!
//! Its `level` is OK (0) once every standard error is within its target
//! (`valid`), else WARN (1); `message` says the percentage calibrated; the
//! values are, as strings with full precision: `gyro_bias_rps`, `speed_scale`,
//! `circumference_fl_m`, `circumference_fr_m`, `circumference_rl_m`,
//! `circumference_rr_m`, each also with `_std` after it, then `valid` and
//! `calibrated_pct` — the keys and units of the params.toml that
//! `stream --params-out` writes.

use deadreckon_core::online::Learned;
use deadreckon_ros::ros2::{Header, Time};
use serde::{Deserialize, Serialize};

/// The status name of the learned parameters.
pub const LEARNED_NAME: &str = "deadreckon: learned parameters";

/// The topic the diagnostics are published on.
pub const TOPIC: &str = "/diagnostics";

/// `diagnostic_msgs/msg/KeyValue`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct KeyValue {
    /// The key.
    pub key: String,
    /// The value, as text.
    pub value: String,
}

/// `diagnostic_msgs/msg/DiagnosticStatus`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct DiagnosticStatus {
    /// 0 OK, 1 WARN, 2 ERROR, 3 STALE.
    pub level: u8,
    /// What the status is about.
    pub name: String,
    /// A human-readable summary.
    pub message: String,
    /// The hardware it concerns.
    pub hardware_id: String,
    /// The values.
    pub values: Vec<KeyValue>,
}

/// `diagnostic_msgs/msg/DiagnosticArray`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct DiagnosticArray {
    /// Header (the stamp of the last event applied).
    pub header: Header,
    /// The statuses.
    pub status: Vec<DiagnosticStatus>,
}

/// The learned parameters at `stamp` as a diagnostic array (see the module doc).
pub fn learned(l: &Learned, stamp: Time, hardware_id: &str) -> DiagnosticArray {
    let p = l.params.to_array();
    let s = l.std.to_array();
    let mut values = Vec::with_capacity(14);
    for (k, name) in deadreckon_core::Params::NAMES.iter().enumerate() {
        values.push(KeyValue {
            key: (*name).into(),
            value: p[k].to_string(),
        });
        values.push(KeyValue {
            key: format!("{name}_std"),
            value: s[k].to_string(),
        });
    }
    values.push(KeyValue {
        key: "valid".into(),
        value: l.valid.to_string(),
    });
    values.push(KeyValue {
        key: "calibrated_pct".into(),
        value: l.calibrated_pct.to_string(),
    });
    DiagnosticArray {
        header: Header {
            stamp,
            frame_id: String::new(),
        },
        status: vec![DiagnosticStatus {
            level: if l.valid { 0 } else { 1 },
            name: LEARNED_NAME.into(),
            message: format!(
                "{:.0}% calibrated, {}",
                l.calibrated_pct,
                if l.valid { "valid" } else { "not yet valid" }
            ),
            hardware_id: hardware_id.into(),
            values,
        }],
    }
}
