//! Raw CAN: frames from candump logs or comma2k19 `raw_can` arrays, decoded
//! with a DBC file and routed into drive streams by a mapping file.
//!
//! ```text
//! candump log ──┐                 DBC (can-dbc) ─► dbc::Database (our decoder)
//!               ├─► Vec<CanFrame> ─────────────────────────┐
//! raw_can/ ─────┘                 mapping TOML ─► mapping::Mapping ─► Drive
//! ```

pub mod candump;
pub mod dbc;
pub mod mapping;
pub mod raw_can;

/// One CAN frame.
#[derive(Debug, Clone, PartialEq)]
pub struct CanFrame {
    /// Reception time, s (the log's clock).
    pub t_s: f64,
    /// The bus: a candump interface name (`can0`) or a comma2k19 `src` number (`0`).
    pub bus: String,
    /// Identifier (11 or 29 bits).
    pub id: u32,
    /// True for a 29-bit (extended) identifier.
    pub extended: bool,
    /// True for a remote-transmission request (no data).
    pub rtr: bool,
    /// Payload, 0 to 64 bytes.
    pub data: Vec<u8>,
}

/// The built-in DBC subset for the Toyota RAV4 (`data/toyota_rav4_subset.dbc`).
pub const TOYOTA_RAV4_DBC: &str = include_str!("../../data/toyota_rav4_subset.dbc");

/// The built-in mapping for the comma2k19 RAV4 (`data/toyota_rav4_comma2k19.toml`).
pub const TOYOTA_RAV4_MAP: &str = include_str!("../../data/toyota_rav4_comma2k19.toml");

pub use candump::{parse_candump, read_candump};
pub use dbc::{ByteOrder, Database, MessageSpec, SignalSpec};
pub use mapping::{decode_frames, Mapping};
pub use raw_can::read_raw_can;
