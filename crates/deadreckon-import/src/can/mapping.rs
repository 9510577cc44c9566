//! The mapping file: which DBC signals feed which drive stream, with the unit
//! conversion, and for wheel pulse counters the counter width (see
//! `data/toyota_rav4_comma2k19.toml` for a commented example), and the
//! decoding of frames into a [`Drive`].

use std::path::Path;

use deadreckon_core::drive::{Scalar, WheelSpeeds, WheelTicks, Wheels};
use deadreckon_core::{Drive, Vehicle};
use serde::Deserialize;

use super::dbc::{Database, SignalSpec};
use super::CanFrame;
use crate::stream::{Reject, StreamBuilder};
use crate::{Import, ImportError, ImportReport, TimeOrderPolicy};

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct MappingFile {
    bus: Option<String>,
    wheel_speeds: Option<WheelSection>,
    wheel_ticks: Option<WheelSection>,
    speed: Option<ScalarSection>,
    steering: Option<ScalarSection>,
    yaw_rate: Option<ScalarSection>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct WheelSection {
    bus: Option<String>,
    message: String,
    fl: String,
    fr: String,
    rl: String,
    rr: String,
    scale: Option<f64>,
    /// Width of cumulative pulse counters (`[wheel_ticks]`): each step is taken
    /// modulo 2^bits in (−2^(bits−1), 2^(bits−1)], so a counter that steps back
    /// gives negative ticks; the frame rate must keep steps well below half the
    /// range.
    counter_bits: Option<u32>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ScalarSection {
    bus: Option<String>,
    message: String,
    signals: Vec<String>,
    scale: Option<f64>,
}

/// Where a stream's frames come from.
#[derive(Debug, Clone, PartialEq)]
struct Route {
    bus: Option<String>,
    id: u32,
    extended: bool,
    message: String,
}

impl Route {
    fn matches(&self, f: &CanFrame) -> bool {
        !f.rtr
            && f.id == self.id
            && f.extended == self.extended
            && self.bus.as_ref().is_none_or(|b| *b == f.bus)
    }
}

/// What the wheel signals are.
#[derive(Debug, Clone, PartialEq)]
enum WheelKind {
    /// Speeds; physical value times `scale` is m/s.
    Speeds { scale: f64 },
    /// Wrapping pulse counters of `bits` bits (raw values are used).
    Ticks { bits: u32 },
}

#[derive(Debug, Clone, PartialEq)]
struct WheelMap {
    route: Route,
    kind: WheelKind,
    /// FL, FR, RL, RR.
    signals: [SignalSpec; 4],
}

#[derive(Debug, Clone, PartialEq)]
struct ScalarMap {
    route: Route,
    signals: Vec<SignalSpec>,
    scale: f64,
}

/// A mapping resolved against a DBC database: ready to decode frames.
#[derive(Debug, Clone, PartialEq)]
pub struct Mapping {
    wheels: WheelMap,
    speed: Option<ScalarMap>,
    steering: Option<ScalarMap>,
    yaw_rate: Option<ScalarMap>,
}

impl Mapping {
    /// Reads the mapping file at `path` and resolves it against `db`.
    pub fn read(path: &Path, db: &Database) -> Result<Self, ImportError> {
        let text = std::fs::read_to_string(path).map_err(|e| ImportError::io(path, e))?;
        Self::parse(&text, db, path)
    }

    /// Parses mapping TOML and resolves every message and signal in `db`;
    /// `path` only names it in errors.
    pub fn parse(text: &str, db: &Database, path: &Path) -> Result<Self, ImportError> {
        let merr = |message: String| ImportError::Mapping {
            path: path.to_path_buf(),
            message,
        };
        let file: MappingFile = toml::from_str(text).map_err(|e| merr(e.to_string()))?;
        let route = |section: &str,
                     bus: &Option<String>,
                     message: &str|
         -> Result<(Route, &super::MessageSpec), ImportError> {
            let m = db.message(message).ok_or_else(|| {
                merr(format!(
                    "[{section}]: message `{message}` is not in the DBC"
                ))
            })?;
            let route = Route {
                bus: bus.clone().or_else(|| file.bus.clone()),
                id: m.id,
                extended: m.extended,
                message: m.name.clone(),
            };
            Ok((route, m))
        };
        let signal = |section: &str,
                      m: &super::MessageSpec,
                      name: &str|
         -> Result<SignalSpec, ImportError> {
            let s = m.signal(name).ok_or_else(|| {
                merr(format!(
                    "[{section}]: signal `{name}` is not in message `{}`",
                    m.name
                ))
            })?;
            if s.multiplexed {
                return Err(merr(format!(
                    "[{section}]: signal `{name}` is multiplexed (not supported)"
                )));
            }
            let fits = s
                .bit_positions()
                .is_some_and(|p| p.iter().all(|&b| u64::from(b) < m.size * 8));
            if !fits {
                return Err(merr(format!(
                    "[{section}]: signal `{name}` does not fit in the {} bytes of `{}`",
                    m.size, m.name
                )));
            }
            Ok(s.clone())
        };
        let scale_of = |section: &str, s: Option<f64>| -> Result<f64, ImportError> {
            match s {
                None => Ok(1.0),
                Some(v) if v.is_finite() && v != 0.0 => Ok(v),
                Some(v) => Err(merr(format!(
                    "[{section}]: scale must be finite and non-zero, got {v}"
                ))),
            }
        };
        let wheels = match (&file.wheel_speeds, &file.wheel_ticks) {
            (Some(_), Some(_)) => {
                return Err(merr(
                    "give [wheel_speeds] or [wheel_ticks], not both".into(),
                ))
            }
            (None, None) => {
                return Err(merr(
                    "a [wheel_speeds] or [wheel_ticks] section is required".into(),
                ))
            }
            (Some(w), None) | (None, Some(w)) => {
                let section = if file.wheel_speeds.is_some() {
                    "wheel_speeds"
                } else {
                    "wheel_ticks"
                };
                let (route, m) = route(section, &w.bus, &w.message)?;
                let kind = if section == "wheel_speeds" {
                    if w.counter_bits.is_some() {
                        return Err(merr(
                            "[wheel_speeds]: counter_bits applies to [wheel_ticks] only".into(),
                        ));
                    }
                    WheelKind::Speeds {
                        scale: scale_of(section, w.scale)?,
                    }
                } else {
                    if w.scale.is_some() {
                        return Err(merr(
                            "[wheel_ticks]: raw counter values are used; scale does not apply"
                                .into(),
                        ));
                    }
                    match w.counter_bits {
                        Some(bits @ 1..=63) => WheelKind::Ticks { bits },
                        Some(b) => {
                            return Err(merr(format!(
                                "[wheel_ticks]: counter_bits must be 1 to 63, got {b}"
                            )))
                        }
                        None => return Err(merr("[wheel_ticks]: counter_bits is required".into())),
                    }
                };
                let signals = [
                    signal(section, m, &w.fl)?,
                    signal(section, m, &w.fr)?,
                    signal(section, m, &w.rl)?,
                    signal(section, m, &w.rr)?,
                ];
                WheelMap {
                    route,
                    kind,
                    signals,
                }
            }
        };
        let scalar =
            |section: &str, s: &Option<ScalarSection>| -> Result<Option<ScalarMap>, ImportError> {
                let Some(s) = s else { return Ok(None) };
                if s.signals.is_empty() {
                    return Err(merr(format!("[{section}]: `signals` is empty")));
                }
                let (route, m) = route(section, &s.bus, &s.message)?;
                let signals = s
                    .signals
                    .iter()
                    .map(|n| signal(section, m, n))
                    .collect::<Result<_, _>>()?;
                Ok(Some(ScalarMap {
                    route,
                    signals,
                    scale: scale_of(section, s.scale)?,
                }))
            };
        Ok(Mapping {
            wheels,
            speed: scalar("speed", &file.speed)?,
            steering: scalar("steering", &file.steering)?,
            yaw_rate: scalar("yaw_rate", &file.yaw_rate)?,
        })
    }
}

fn too_short(route: &Route, s: &SignalSpec, f: &CanFrame) -> Reject {
    Reject::Invalid(format!(
        "{} frame of {} bytes is too short for signal {}",
        route.message,
        f.data.len(),
        s.name
    ))
}

fn decode_scalar(
    name: &'static str,
    map: &Option<ScalarMap>,
    frames: &[CanFrame],
    policy: TimeOrderPolicy,
    path: &Path,
    report: &mut ImportReport,
) -> Result<Vec<Scalar>, ImportError> {
    let Some(map) = map else {
        return Ok(Vec::new());
    };
    let mut b = StreamBuilder::new(name, path, policy);
    for (i, f) in frames
        .iter()
        .enumerate()
        .filter(|(_, f)| map.route.matches(f))
    {
        let mut sum = 0.0;
        let mut short = None;
        for s in &map.signals {
            match s.decode(&f.data) {
                Some(v) => sum += v,
                None => short = Some(too_short(&map.route, s, f)),
            }
        }
        match short {
            Some(r) => b.reject(i, f.t_s, r)?,
            None => {
                let v = sum * map.scale;
                b.push(
                    i,
                    f.t_s,
                    &[v],
                    Scalar {
                        t_s: f.t_s,
                        value: v,
                    },
                )?;
            }
        }
    }
    let (v, r) = b.finish(|s| s.t_s);
    report.notes.push(format!(
        "{name}: sum of {} from {} × {}",
        map.signals
            .iter()
            .map(|s| s.name.as_str())
            .collect::<Vec<_>>()
            .join(" + "),
        map.route.message,
        map.scale
    ));
    report.streams.push(r);
    Ok(v)
}

/// Decodes `frames` with `mapping` into a drive for `vehicle`. Frames are taken
/// in the order given; each output stream must have strictly increasing times
/// (else error or, with [`TimeOrderPolicy::Gate`], dropped and counted). Wheel
/// counters give one row per frame after the first (baseline) frame, whose row
/// has zero ticks. `path` names the source in errors.
pub fn decode_frames(
    frames: &[CanFrame],
    mapping: &Mapping,
    vehicle: Vehicle,
    policy: TimeOrderPolicy,
    path: &Path,
) -> Result<Import, ImportError> {
    vehicle.validate().map_err(|source| ImportError::Invalid {
        path: path.to_path_buf(),
        source,
    })?;
    let mut report = ImportReport {
        format: "can".into(),
        ..Default::default()
    };
    let w = &mapping.wheels;
    let wheels = match w.kind {
        WheelKind::Speeds { scale } => {
            let mut b = StreamBuilder::new("wheel_speeds", path, policy);
            for (i, f) in frames
                .iter()
                .enumerate()
                .filter(|(_, f)| w.route.matches(f))
            {
                let mut v = [0.0; 4];
                let mut short = None;
                for (k, s) in w.signals.iter().enumerate() {
                    match s.decode(&f.data) {
                        Some(x) => v[k] = x * scale,
                        None => short = Some(too_short(&w.route, s, f)),
                    }
                }
                match short {
                    Some(r) => b.reject(i, f.t_s, r)?,
                    None => {
                        let ws = WheelSpeeds {
                            t_s: f.t_s,
                            fl_mps: v[0],
                            fr_mps: v[1],
                            rl_mps: v[2],
                            rr_mps: v[3],
                        };
                        b.push(i, f.t_s, &v, ws)?;
                    }
                }
            }
            let (v, r) = b.finish(|s| s.t_s);
            report.streams.push(r);
            report
                .notes
                .push(format!("wheel_speeds: {} × {scale}", w.route.message));
            Wheels::Speeds(v)
        }
        WheelKind::Ticks { bits } => {
            let modulus = 1i128 << bits;
            let mut b = StreamBuilder::new("wheel_ticks", path, policy);
            let mut prev: Option<[i128; 4]> = None;
            for (i, f) in frames
                .iter()
                .enumerate()
                .filter(|(_, f)| w.route.matches(f))
            {
                let mut cur = [0i128; 4];
                let mut short = None;
                for (k, s) in w.signals.iter().enumerate() {
                    match s.raw(&f.data) {
                        Some(x) => cur[k] = x.rem_euclid(modulus),
                        None => short = Some(too_short(&w.route, s, f)),
                    }
                }
                if let Some(r) = short {
                    b.reject(i, f.t_s, r)?;
                    continue;
                }
                // The step modulo the counter's range, taken in
                // (−range/2, range/2]: a counter that steps back (reversing,
                // or jitter by one) gives negative ticks, not a wrap.
                let d = |k: usize| -> i64 {
                    prev.map_or(0, |p| {
                        let step = (cur[k] - p[k]).rem_euclid(modulus);
                        (if step > modulus / 2 {
                            step - modulus
                        } else {
                            step
                        }) as i64
                    })
                };
                let row = WheelTicks {
                    t_s: f.t_s,
                    fl: d(0),
                    fr: d(1),
                    rl: d(2),
                    rr: d(3),
                };
                if b.push(i, f.t_s, &[], row)? {
                    prev = Some(cur);
                }
            }
            let (v, r) = b.finish(|s| s.t_s);
            report.streams.push(r);
            report.notes.push(format!(
                "wheel_ticks: {} counters modulo 2^{bits}; the first row is the zero-tick baseline",
                w.route.message
            ));
            Wheels::Ticks(v)
        }
    };
    let speed = decode_scalar("speed", &mapping.speed, frames, policy, path, &mut report)?;
    let steering = decode_scalar(
        "steering",
        &mapping.steering,
        frames,
        policy,
        path,
        &mut report,
    )?;
    let yaw_rate = decode_scalar(
        "yaw_rate",
        &mapping.yaw_rate,
        frames,
        policy,
        path,
        &mut report,
    )?;
    let drive = Drive {
        vehicle,
        wheels,
        yaw_rate,
        speed,
        steering,
        gnss: Vec::new(),
        truth: Vec::new(),
        imu: Default::default(),
    };
    Import::checked(drive, report, path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::can::{dbc::ByteOrder, TOYOTA_RAV4_DBC, TOYOTA_RAV4_MAP};

    fn db() -> Database {
        Database::parse(TOYOTA_RAV4_DBC, Path::new("t.dbc")).unwrap()
    }

    #[test]
    fn builtin_mapping_resolves() {
        let m = Mapping::parse(TOYOTA_RAV4_MAP, &db(), Path::new("m.toml")).unwrap();
        assert_eq!(m.wheels.route.id, 0xAA);
        assert_eq!(m.steering.as_ref().unwrap().signals.len(), 2);
    }

    #[test]
    fn mapping_errors_name_the_problem() {
        let db = db();
        let e = Mapping::parse(
            "[speed]\nmessage = \"NOPE\"\nsignals = [\"X\"]\n",
            &db,
            Path::new("m.toml"),
        );
        assert!(e.unwrap_err().to_string().contains("wheel"));
        let text = "[wheel_speeds]\nmessage = \"NOPE\"\nfl=\"a\"\nfr=\"b\"\nrl=\"c\"\nrr=\"d\"\n";
        assert!(Mapping::parse(text, &db, Path::new("m.toml"))
            .unwrap_err()
            .to_string()
            .contains("NOPE"));
        let e = Mapping::parse("bogus = 1", &db, Path::new("m.toml"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("m.toml") && e.contains("line 1"), "{e}");
    }

    /// A synthetic 8-bit pulse counter message, Intel order, byte k = wheel k.
    fn counter_db() -> Database {
        let text = "VERSION \"\"\n\nNS_ :\n\nBS_:\n\nBU_: XXX\n\nBO_ 256 PULSES: 4 XXX\n \
            SG_ FL : 0|8@1+ (1,0) [0|255] \"\" XXX\n SG_ FR : 8|8@1+ (1,0) [0|255] \"\" XXX\n \
            SG_ RL : 16|8@1+ (1,0) [0|255] \"\" XXX\n SG_ RR : 24|8@1+ (1,0) [0|255] \"\" XXX\n";
        Database::parse(text, Path::new("c.dbc")).unwrap()
    }

    /// The wheel ticks the 8-bit counter mapping decodes from frames of
    /// the four counters' bytes, 0.1 s apart.
    fn decode_counters(data: &[[u8; 4]]) -> Vec<deadreckon_core::drive::WheelTicks> {
        let db = counter_db();
        let map = "[wheel_ticks]\nmessage=\"PULSES\"\nfl=\"FL\"\nfr=\"FR\"\nrl=\"RL\"\nrr=\"RR\"\ncounter_bits=8\n";
        let m = Mapping::parse(map, &db, Path::new("m.toml")).unwrap();
        let frames: Vec<CanFrame> = data
            .iter()
            .enumerate()
            .map(|(k, d)| CanFrame {
                t_s: 0.1 * k as f64,
                bus: "can0".into(),
                id: 256,
                extended: false,
                rtr: false,
                data: d.to_vec(),
            })
            .collect();
        let imp = decode_frames(
            &frames,
            &m,
            crate::profiles::toyota_rav4(),
            TimeOrderPolicy::Error,
            Path::new("x"),
        )
        .unwrap();
        let Wheels::Ticks(t) = imp.drive.wheels else {
            panic!("wheel ticks expected")
        };
        t
    }

    #[test]
    fn wheel_counters_unwrap_modulo_their_width() {
        let db = counter_db();
        assert_eq!(
            db.message("PULSES")
                .unwrap()
                .signal("RL")
                .unwrap()
                .byte_order,
            ByteOrder::LittleEndian
        );
        let t = decode_counters(&[[250, 0, 10, 255], [4, 0, 20, 3], [9, 1, 20, 3]]);
        assert_eq!((t[0].fl, t[1].fl, t[2].fl), (0, 10, 5));
        assert_eq!((t[1].rr, t[2].fr, t[1].rl), (4, 1, 10));
    }

    #[test]
    fn a_counter_stepping_back_by_one_was_255_ticks() {
        // FL steps back by one, RR steps back across the wrap, FR reverses.
        let t = decode_counters(&[[10, 100, 0, 1], [9, 97, 0, 254], [11, 93, 0, 2]]);
        assert_eq!((t[1].fl, t[2].fl), (-1, 2));
        assert_eq!((t[1].fr, t[2].fr), (-3, -4));
        assert_eq!((t[1].rr, t[2].rr), (-3, 4));
    }

    #[test]
    fn duplicate_times_are_an_error_or_gated_and_counted() {
        let db = counter_db();
        let map = "[wheel_ticks]\nmessage=\"PULSES\"\nfl=\"FL\"\nfr=\"FR\"\nrl=\"RL\"\nrr=\"RR\"\ncounter_bits=8\n";
        let m = Mapping::parse(map, &db, Path::new("m.toml")).unwrap();
        let f = |t: f64, d: u8| CanFrame {
            t_s: t,
            bus: "can0".into(),
            id: 256,
            extended: false,
            rtr: false,
            data: vec![d; 4],
        };
        let frames = [
            f(0.0, 0),
            f(0.1, 1),
            f(0.1, 2),
            f(0.05, 3),
            f(0.2, 4),
            f(0.3, 5),
        ];
        let v = crate::profiles::toyota_rav4();
        let e = decode_frames(
            &frames,
            &m,
            v.clone(),
            TimeOrderPolicy::Error,
            Path::new("x"),
        )
        .unwrap_err();
        assert!(matches!(e, ImportError::Stream { index: 2, .. }), "{e}");
        let imp = decode_frames(&frames, &m, v, TimeOrderPolicy::Gate, Path::new("x")).unwrap();
        let r = imp.report.stream("wheel_ticks").unwrap();
        assert_eq!((r.kept, r.gated_time_order), (4, 2));
        let Wheels::Ticks(t) = &imp.drive.wheels else {
            panic!()
        };
        // The gated frames' ticks are not lost: the next kept row counts from the last kept one.
        assert_eq!(t.iter().map(|w| w.fl).collect::<Vec<_>>(), vec![0, 1, 3, 1]);
    }
}
