//! DBC signals and our decoder. `can-dbc` parses the file; decoding (bit
//! layout in Intel or Motorola byte order, sign, factor, offset) is done here
//! and property-tested against [`SignalSpec::encode_raw`].
//!
//! Bit numbering is the DBC one: bit `b` of byte `B` is `8·B + b`, `b = 0` the
//! least significant. An Intel (little-endian, `@1`) signal starts at its least
//! significant bit and runs upward. A Motorola (big-endian, `@0`) signal starts
//! at its most significant bit and runs toward less significant bits in the
//! "sawtooth" order: down within a byte, then to the most significant bit of
//! the next byte (`8·(B+1) + 7`).

use std::collections::HashMap;
use std::path::Path;

use crate::ImportError;

/// Byte order of a signal.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ByteOrder {
    /// Intel, `@1`: start bit is the least significant bit.
    LittleEndian,
    /// Motorola, `@0`: start bit is the most significant bit.
    BigEndian,
}

/// One signal's layout and scaling.
#[derive(Debug, Clone, PartialEq)]
pub struct SignalSpec {
    /// Signal name.
    pub name: String,
    /// DBC start bit (see the module doc).
    pub start_bit: u32,
    /// Width, 1 to 64 bits.
    pub size: u32,
    /// Byte order.
    pub byte_order: ByteOrder,
    /// Two's-complement signed raw value.
    pub signed: bool,
    /// Physical = raw · factor + offset.
    pub factor: f64,
    /// Physical = raw · factor + offset.
    pub offset: f64,
    /// Unit as written in the DBC.
    pub unit: String,
    /// True when the signal is multiplexed (present only for some multiplexor values).
    pub multiplexed: bool,
}

/// Highest bit position a signal may touch (64-byte CAN FD payload).
const MAX_BIT: u32 = 64 * 8 - 1;

impl SignalSpec {
    /// The bit positions of the signal, from its least significant bit up, or
    /// `None` if the layout leaves the 64-byte payload or the width is not 1–64.
    pub fn bit_positions(&self) -> Option<Vec<u32>> {
        if self.size == 0 || self.size > 64 || self.start_bit > MAX_BIT {
            return None;
        }
        let mut pos = Vec::with_capacity(self.size as usize);
        match self.byte_order {
            ByteOrder::LittleEndian => {
                for k in 0..self.size {
                    pos.push(self.start_bit.checked_add(k).filter(|&p| p <= MAX_BIT)?);
                }
            }
            ByteOrder::BigEndian => {
                // Walk from the most significant bit down, then reverse.
                let mut p = self.start_bit;
                for k in 0..self.size {
                    pos.push(p);
                    if k + 1 < self.size {
                        p = if p & 7 == 0 { p + 15 } else { p - 1 };
                        if p > MAX_BIT {
                            return None;
                        }
                    }
                }
                pos.reverse();
            }
        }
        Some(pos)
    }

    /// The raw (unscaled, sign-extended) value in `data`, or `None` if the
    /// signal does not fit in `data`.
    pub fn raw(&self, data: &[u8]) -> Option<i128> {
        let mut v: u64 = 0;
        for (k, p) in self.bit_positions()?.into_iter().enumerate() {
            let byte = *data.get((p / 8) as usize)?;
            let bit = (byte >> (p % 8)) & 1;
            v |= u64::from(bit) << k;
        }
        Some(
            if self.signed && self.size < 64 && (v >> (self.size - 1)) & 1 == 1 {
                i128::from(v) - (1i128 << self.size)
            } else if self.signed {
                i128::from(v as i64)
            } else {
                i128::from(v)
            },
        )
    }

    /// The physical value `raw · factor + offset`, or `None` if the signal does
    /// not fit in `data`.
    pub fn decode(&self, data: &[u8]) -> Option<f64> {
        self.raw(data).map(|r| r as f64 * self.factor + self.offset)
    }

    /// Writes the low `size` bits of `raw` into `data` at the signal's place,
    /// leaving every other bit as it was (the inverse of [`SignalSpec::raw`]).
    /// Returns `None` if the signal does not fit in `data`.
    pub fn encode_raw(&self, raw: u64, data: &mut [u8]) -> Option<()> {
        let pos = self.bit_positions()?;
        if pos.iter().any(|&p| (p / 8) as usize >= data.len()) {
            return None;
        }
        for (k, p) in pos.into_iter().enumerate() {
            let byte = data.get_mut((p / 8) as usize)?;
            let mask = 1u8 << (p % 8);
            if (raw >> k) & 1 == 1 {
                *byte |= mask;
            } else {
                *byte &= !mask;
            }
        }
        Some(())
    }
}

/// One message of the database.
#[derive(Debug, Clone, PartialEq)]
pub struct MessageSpec {
    /// Identifier (without the extended flag).
    pub id: u32,
    /// True for a 29-bit identifier.
    pub extended: bool,
    /// Message name.
    pub name: String,
    /// Declared payload length, bytes.
    pub size: u64,
    /// Its signals.
    pub signals: Vec<SignalSpec>,
}

impl MessageSpec {
    /// The signal called `name`.
    pub fn signal(&self, name: &str) -> Option<&SignalSpec> {
        self.signals.iter().find(|s| s.name == name)
    }
}

/// The messages of a DBC file, by name.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Database {
    messages: HashMap<String, MessageSpec>,
}

impl Database {
    /// Reads and parses the DBC file at `path`.
    pub fn read(path: &Path) -> Result<Self, ImportError> {
        let bytes = std::fs::read(path).map_err(|e| ImportError::io(path, e))?;
        let text = String::from_utf8(bytes).map_err(|e| ImportError::Dbc {
            path: path.to_path_buf(),
            message: format!("not UTF-8 at byte {}", e.utf8_error().valid_up_to()),
        })?;
        Self::parse(&text, path)
    }

    /// Parses DBC text; `path` only names it in errors.
    pub fn parse(text: &str, path: &Path) -> Result<Self, ImportError> {
        let dbc = can_dbc::Dbc::try_from(text).map_err(|e| ImportError::Dbc {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        let mut messages = HashMap::new();
        for m in dbc.messages {
            let (id, extended) = match m.id {
                can_dbc::MessageId::Standard(id) => (u32::from(id), false),
                can_dbc::MessageId::Extended(id) => (id, true),
            };
            let signals = m
                .signals
                .into_iter()
                .map(|s| SignalSpec {
                    start_bit: u32::try_from(s.start_bit).unwrap_or(u32::MAX),
                    size: u32::try_from(s.size).unwrap_or(u32::MAX),
                    byte_order: match s.byte_order {
                        can_dbc::ByteOrder::LittleEndian => ByteOrder::LittleEndian,
                        can_dbc::ByteOrder::BigEndian => ByteOrder::BigEndian,
                    },
                    signed: matches!(s.value_type, can_dbc::ValueType::Signed),
                    factor: s.factor,
                    offset: s.offset,
                    unit: s.unit,
                    multiplexed: !matches!(
                        s.multiplexer_indicator,
                        can_dbc::MultiplexIndicator::Plain
                    ),
                    name: s.name,
                })
                .collect();
            messages.insert(
                m.name.clone(),
                MessageSpec {
                    id,
                    extended,
                    name: m.name,
                    size: m.size,
                    signals,
                },
            );
        }
        Ok(Database { messages })
    }

    /// The message called `name`.
    pub fn message(&self, name: &str) -> Option<&MessageSpec> {
        self.messages.get(name)
    }

    /// Number of messages.
    pub fn len(&self) -> usize {
        self.messages.len()
    }

    /// True when the file defines no message.
    pub fn is_empty(&self) -> bool {
        self.messages.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn db() -> Database {
        Database::parse(
            crate::can::TOYOTA_RAV4_DBC,
            Path::new("toyota_rav4_subset.dbc"),
        )
        .unwrap()
    }

    #[test]
    fn decodes_toyota_frames_from_the_comma2k19_segment() {
        let db = db();
        // First WHEEL_SPEEDS frame of the segment: processed_log says
        // [fl, fr, rl, rr] = [8.01667, 8.01667, 7.90556, 7.95833] m/s.
        let ws = db.message("WHEEL_SPEEDS").unwrap();
        let data = [0x25, 0xb5, 0x25, 0xb5, 0x25, 0xa0, 0x25, 0x8d];
        let kph = |n: &str| ws.signal(n).unwrap().decode(&data).unwrap();
        assert!((kph("WHEEL_SPEED_FL") / 3.6 - 8.016666666666667).abs() < 1e-9);
        assert!((kph("WHEEL_SPEED_RL") / 3.6 - 7.905555555555554).abs() < 1e-9);
        assert!((kph("WHEEL_SPEED_RR") / 3.6 - 7.958333333333336).abs() < 1e-9);
        // STEER_ANGLE_SENSOR: angle 0, fraction -0.4 deg (a signed 4-bit field).
        let st = db.message("STEER_ANGLE_SENSOR").unwrap();
        let data = [0x00, 0x00, 0x10, 0x00, 0xc0, 0x00, 0x00, 0xfd];
        assert_eq!(st.signal("STEER_ANGLE").unwrap().decode(&data), Some(0.0));
        assert!((st.signal("STEER_FRACTION").unwrap().decode(&data).unwrap() + 0.4).abs() < 1e-12);
        // SPEED 0x0b7a = 2938 -> 29.38 km/h.
        let sp = db.message("SPEED").unwrap();
        let data = [0, 0, 0, 0, 0x1d, 0x0b, 0x7a, 0x5e];
        assert!((sp.signal("SPEED").unwrap().decode(&data).unwrap() - 29.38).abs() < 1e-9);
        assert_eq!(sp.id, 0xB4);
    }

    #[test]
    fn known_layouts() {
        let s = |start_bit, size, byte_order, signed| SignalSpec {
            name: "S".into(),
            start_bit,
            size,
            byte_order,
            signed,
            factor: 1.0,
            offset: 0.0,
            unit: String::new(),
            multiplexed: false,
        };
        // Motorola 12 bits from bit 3: low nibble of byte 0, then byte 1.
        assert_eq!(
            s(3, 12, ByteOrder::BigEndian, false).raw(&[0x0A, 0xBC]),
            Some(0xABC)
        );
        assert_eq!(
            s(3, 12, ByteOrder::BigEndian, true).raw(&[0x0F, 0xFF]),
            Some(-1)
        );
        // Intel 12 bits from bit 4: high nibble of byte 0 is the low nibble of the value.
        assert_eq!(
            s(4, 12, ByteOrder::LittleEndian, false).raw(&[0xC0, 0xAB]),
            Some(0xABC)
        );
        // Does not fit in a 1-byte payload.
        assert_eq!(s(7, 16, ByteOrder::BigEndian, false).raw(&[0x12]), None);
        assert_eq!(s(0, 0, ByteOrder::BigEndian, false).raw(&[0x12]), None);
        assert_eq!(s(0, 65, ByteOrder::LittleEndian, false).raw(&[0; 16]), None);
    }

    fn spec() -> impl Strategy<Value = SignalSpec> {
        (0u32..64, 1u32..=64, any::<bool>(), any::<bool>()).prop_map(
            |(start_bit, size, be, signed)| SignalSpec {
                name: "S".into(),
                start_bit,
                size,
                byte_order: if be {
                    ByteOrder::BigEndian
                } else {
                    ByteOrder::LittleEndian
                },
                signed,
                factor: 0.5,
                offset: -3.0,
                unit: String::new(),
                multiplexed: false,
            },
        )
    }

    proptest! {
        // Seeded (issue 33); `PROPTEST_RNG_SEED=<n>` runs another seed.
        #![proptest_config(ProptestConfig { rng_seed: proptest::test_runner::RngSeed::Fixed(std::env::var("PROPTEST_RNG_SEED").ok().and_then(|s| s.parse().ok()).unwrap_or(101)), ..ProptestConfig::default() })]
        #[test]
        fn decode_inverts_encode(s in spec(), raw in any::<u64>(), background in any::<[u8; 16]>()) {
            let mut data = background;
            match s.encode_raw(raw, &mut data) {
                None => prop_assert_eq!(s.raw(&data), None),
                Some(()) => {
                    let mask = if s.size == 64 { u64::MAX } else { (1u64 << s.size) - 1 };
                    let want_u = raw & mask;
                    let want: i128 = if s.signed && (want_u >> (s.size - 1)) & 1 == 1 {
                        i128::from(want_u) - (1i128 << s.size)
                    } else {
                        i128::from(want_u)
                    };
                    prop_assert_eq!(s.raw(&data), Some(want));
                    prop_assert_eq!(s.decode(&data), Some(want as f64 * 0.5 - 3.0));
                    // Bits outside the signal are untouched.
                    let pos = s.bit_positions().unwrap();
                    for p in 0..128u32 {
                        if !pos.contains(&p) {
                            let (a, b) = (background[(p / 8) as usize], data[(p / 8) as usize]);
                            prop_assert_eq!((a >> (p % 8)) & 1, (b >> (p % 8)) & 1);
                        }
                    }
                }
            }
        }

        #[test]
        fn decode_never_panics(s in spec(), data in proptest::collection::vec(any::<u8>(), 0..16)) {
            let _ = s.decode(&data);
        }

        #[test]
        fn dbc_parser_never_panics(text in "\\PC{0,200}") {
            let _ = Database::parse(&text, Path::new("fuzz.dbc"));
        }
    }
}
