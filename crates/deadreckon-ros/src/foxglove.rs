//! MCAP output of tracks for Foxglove: JSON messages with Foxglove's well-known
//! JSON schemas, so the 3D and Map panels show them without configuration.
//!
//! Per track `<name>` (non-alphanumeric characters replaced by `_`):
//!
//! - `/deadreckon/<name>/pose`: `foxglove.PoseInFrame` in frame [`FRAME_ID`]
//!   (x east, y north, z 0; the yaw as a rotation about z);
//! - `/deadreckon/<name>/fix`: `foxglove.LocationFix` (latitude, longitude and the
//!   east/north covariance), when the track has a geodetic origin.
//!
//! With GNSS fixes, `/deadreckon/gnss/fix` carries them as `foxglove.LocationFix`.
//! [`write_mcap_with`] can add, or write instead, each track as ROS 2
//! `nav_msgs/msg/Odometry` on `/deadreckon/<name>/odom` (see [`crate::ros2_out`]).
//! The file is written next to its destination and renamed into place, so a
//! reader never sees half a file.

use std::collections::BTreeMap;
use std::io::{BufWriter, Write};
use std::path::Path;

use serde_json::{json, Value};

use deadreckon_core::drive::GnssFix;
use deadreckon_core::vehicle::Origin;
use deadreckon_core::Track;

use crate::error::RosError;

pub use crate::ros2_out::FRAME_ID;

fn time_schema(description: &str) -> Value {
    json!({
        "type": "object",
        "title": "time",
        "properties": {
            "sec": {"type": "integer", "minimum": 0},
            "nsec": {"type": "integer", "minimum": 0, "maximum": 999_999_999}
        },
        "required": ["sec", "nsec"],
        "description": description
    })
}

fn xyz(title: &str, names: &[&str]) -> Value {
    let props: serde_json::Map<String, Value> = names
        .iter()
        .map(|n| (n.to_string(), json!({"type": "number"})))
        .collect();
    json!({"title": title, "type": "object", "properties": props, "required": names})
}

/// The JSON schema of `foxglove.PoseInFrame` (as published in Foxglove's schemas).
pub fn pose_in_frame_schema() -> Value {
    json!({
        "title": "foxglove.PoseInFrame",
        "description": "A timestamped pose for an object or reference frame in 3D space",
        "type": "object",
        "properties": {
            "timestamp": time_schema("Timestamp of pose"),
            "frame_id": {"type": "string", "description": "Frame of reference for pose position and orientation"},
            "pose": {
                "title": "foxglove.Pose",
                "description": "Pose in 3D space",
                "type": "object",
                "properties": {
                    "position": xyz("foxglove.Vector3", &["x", "y", "z"]),
                    "orientation": xyz("foxglove.Quaternion", &["x", "y", "z", "w"])
                },
                "required": ["position", "orientation"]
            }
        },
        "required": ["timestamp", "frame_id", "pose"]
    })
}

/// The JSON schema of `foxglove.LocationFix` (as published in Foxglove's schemas).
pub fn location_fix_schema() -> Value {
    let kinds: Vec<Value> = ["UNKNOWN", "APPROXIMATED", "DIAGONAL_KNOWN", "KNOWN"]
        .iter()
        .enumerate()
        .map(|(i, t)| json!({"title": t, "const": i}))
        .collect();
    json!({
        "title": "foxglove.LocationFix",
        "description": "A navigation satellite fix for any Global Navigation Satellite System",
        "type": "object",
        "properties": {
            "frame_id": {"type": "string"},
            "timestamp": time_schema("Timestamp of the message"),
            "latitude": {"type": "number", "description": "Latitude in degrees"},
            "longitude": {"type": "number", "description": "Longitude in degrees"},
            "altitude": {"type": "number", "description": "Altitude in meters"},
            "position_covariance": {"type": "array", "items": {"type": "number"}, "minItems": 9, "maxItems": 9},
            "position_covariance_type": {"title": "foxglove.PositionCovarianceType", "oneOf": kinds}
        },
        "required": [
            "timestamp", "frame_id", "latitude", "longitude", "altitude",
            "position_covariance", "position_covariance_type"
        ]
    })
}

/// The topic-safe form of a track name.
pub fn topic_name(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if s.is_empty() {
        "track".into()
    } else {
        s
    }
}

fn stamp(t_s: f64, file: &str) -> Result<(u64, Value), RosError> {
    let ns = (t_s * 1e9).round();
    if !(ns.is_finite() && ns >= 0.0 && ns < u64::MAX as f64) {
        return Err(RosError::Write {
            file: file.into(),
            what: format!("time {t_s} s cannot be an MCAP timestamp"),
        });
    }
    let ns = ns as u64;
    Ok((
        ns,
        json!({"sec": ns / 1_000_000_000, "nsec": ns % 1_000_000_000}),
    ))
}

fn geodetic(origin: Origin, east_m: f64, north_m: f64) -> (f64, f64, f64) {
    // Planar tracks lie at the origin's height.
    let (lat, lon) = deadreckon_core::geo::en_to_geodetic(&origin, east_m, north_m);
    (lat, lon, origin.height_m)
}

/// `foxglove.PositionCovarianceType` DIAGONAL_KNOWN: per-axis variances (a
/// GNSS fix's isotropic standard deviation).
const COVARIANCE_DIAGONAL_KNOWN: u8 = 2;
/// `foxglove.PositionCovarianceType` KNOWN: the full east/north covariance of
/// a filtered or dead-reckoned position (the up row and column are 0: the
/// tracks are planar).
const COVARIANCE_KNOWN: u8 = 3;

/// Chunk compression of the MCAP files written: zstd with the `zstd-write`
/// feature (default; mcap's C zstd), none without it.
#[cfg(feature = "zstd-write")]
const CHUNK_COMPRESSION: Option<mcap::Compression> = Some(mcap::Compression::Zstd);
#[cfg(not(feature = "zstd-write"))]
const CHUNK_COMPRESSION: Option<mcap::Compression> = None;

fn location_fix(
    ts: Value,
    origin: Origin,
    (e, n): (f64, f64),
    cov_en: [f64; 4],
    covariance_type: u8,
    file: &str,
) -> Result<Vec<u8>, RosError> {
    let (lat, lon, alt) = geodetic(origin, e, n);
    let cov = [
        cov_en[0], cov_en[1], 0.0, cov_en[2], cov_en[3], 0.0, 0.0, 0.0, 0.0,
    ];
    let v = json!({
        "timestamp": ts,
        "frame_id": FRAME_ID,
        "latitude": lat,
        "longitude": lon,
        "altitude": alt,
        "position_covariance": cov,
        "position_covariance_type": covariance_type
    });
    serde_json::to_vec(&v).map_err(|e| RosError::Write {
        file: file.into(),
        what: e.to_string(),
    })
}

/// What an MCAP file of tracks carries.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct McapOptions {
    /// Foxglove's JSON messages (`foxglove.PoseInFrame`, `foxglove.LocationFix`).
    pub foxglove: bool,
    /// ROS 2 `nav_msgs/msg/Odometry` in CDR ([`crate::ros2_out`]). Alone, the
    /// file has the `ros2` profile, as `ros2 bag` expects.
    pub ros2_odometry: bool,
}

impl McapOptions {
    /// Foxglove's messages only (what [`write_mcap`] writes).
    pub const FOXGLOVE: McapOptions = McapOptions {
        foxglove: true,
        ros2_odometry: false,
    };
    /// ROS 2 Odometry only, `ros2` profile.
    pub const ROS2: McapOptions = McapOptions {
        foxglove: false,
        ros2_odometry: true,
    };
    /// Both.
    pub const BOTH: McapOptions = McapOptions {
        foxglove: true,
        ros2_odometry: true,
    };
}

/// Writes tracks to an MCAP file for Foxglove (see the module doc).
pub fn write_tracks_mcap(path: impl AsRef<Path>, tracks: &[Track]) -> Result<(), RosError> {
    write_mcap(path, tracks, None)
}

/// Writes tracks and, optionally, GNSS fixes with their geodetic origin to an
/// MCAP file for Foxglove (see the module doc).
pub fn write_mcap(
    path: impl AsRef<Path>,
    tracks: &[Track],
    gnss: Option<(&[GnssFix], Origin)>,
) -> Result<(), RosError> {
    write_mcap_with(path, tracks, gnss, McapOptions::FOXGLOVE)
}

/// [`write_mcap`] choosing what the file carries: Foxglove's messages, ROS 2
/// Odometry (one `/deadreckon/<name>/odom` per track), or both. GNSS fixes
/// are written as Foxglove messages only.
pub fn write_mcap_with(
    path: impl AsRef<Path>,
    tracks: &[Track],
    gnss: Option<(&[GnssFix], Origin)>,
    options: McapOptions,
) -> Result<(), RosError> {
    let path = path.as_ref();
    if !(options.foxglove || options.ros2_odometry) {
        return Err(RosError::Write {
            file: path.display().to_string(),
            what: "an MCAP file of tracks needs Foxglove or ROS 2 messages".into(),
        });
    }
    let gnss = gnss.filter(|_| options.foxglove);
    let file = path.display().to_string();
    let mut names: Vec<String> = Vec::new();
    for t in tracks {
        let n = topic_name(&t.name);
        if names.contains(&n) || (gnss.is_some() && n == "gnss") {
            return Err(RosError::Write {
                file,
                what: format!("two topics named /deadreckon/{n}"),
            });
        }
        names.push(n);
    }
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let base = path
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let tmp = dir.join(format!(".{base}.tmp{}", std::process::id()));
    let io = |e: std::io::Error| RosError::Io {
        file: file.clone(),
        source: e,
    };
    let _registered = deadreckon_io::temporaries::register(&tmp);
    let result = (|| -> Result<(), RosError> {
        let f = std::fs::File::create(&tmp).map_err(io)?;
        let mut w = BufWriter::new(f);
        write_into(&mut w, tracks, &names, gnss, options, &file)?;
        let f = w.into_inner().map_err(|e| io(e.into_error()))?;
        f.sync_all().map_err(io)?;
        Ok(())
    })();
    match result.and_then(|()| std::fs::rename(&tmp, path).map_err(io)) {
        Ok(()) => Ok(()),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(e)
        }
    }
}

fn write_into<W: Write + std::io::Seek>(
    w: W,
    tracks: &[Track],
    names: &[String],
    gnss: Option<(&[GnssFix], Origin)>,
    options: McapOptions,
    file: &str,
) -> Result<(), RosError> {
    let werr = |e: mcap::McapError| RosError::Write {
        file: file.into(),
        what: e.to_string(),
    };
    let profile = if options.foxglove { "" } else { "ros2" };
    let opts = mcap::WriteOptions::new()
        .compression(CHUNK_COMPRESSION)
        .profile(profile)
        .library("deadreckon-ros");
    let mut out = opts.create(w).map_err(werr)?;
    let pose_schema = serde_json::to_vec(&pose_in_frame_schema()).map_err(|e| RosError::Write {
        file: file.into(),
        what: e.to_string(),
    })?;
    let fix_schema = serde_json::to_vec(&location_fix_schema()).map_err(|e| RosError::Write {
        file: file.into(),
        what: e.to_string(),
    })?;
    let pose_id = if options.foxglove {
        Some(
            out.add_schema("foxglove.PoseInFrame", "jsonschema", &pose_schema)
                .map_err(werr)?,
        )
    } else {
        None
    };
    // Schemas first, then channels, then messages: add every channel up front.
    let fix_sid =
        if options.foxglove && (tracks.iter().any(|t| t.origin.is_some()) || gnss.is_some()) {
            Some(
                out.add_schema("foxglove.LocationFix", "jsonschema", &fix_schema)
                    .map_err(werr)?,
            )
        } else {
            None
        };
    let odom_sid = if options.ros2_odometry {
        Some(
            out.add_schema(
                crate::ros2_out::ODOMETRY_SCHEMA_NAME,
                "ros2msg",
                crate::ros2_out::odometry_schema().as_bytes(),
            )
            .map_err(werr)?,
        )
    } else {
        None
    };
    let mut plans = Vec::new();
    let meta = BTreeMap::new();
    // The ros2 profile requires the QoS metadata; empty means the defaults.
    let ros2_meta = BTreeMap::from([("offered_qos_profiles".to_string(), String::new())]);
    for (t, n) in tracks.iter().zip(names) {
        let pose_ch = match pose_id {
            Some(sid) => Some(
                out.add_channel(sid, &format!("/deadreckon/{n}/pose"), "json", &meta)
                    .map_err(werr)?,
            ),
            None => None,
        };
        let fix_ch = match (t.origin, fix_sid) {
            (Some(_), Some(sid)) => Some(
                out.add_channel(sid, &format!("/deadreckon/{n}/fix"), "json", &meta)
                    .map_err(werr)?,
            ),
            _ => None,
        };
        let odom_ch = match odom_sid {
            Some(sid) => Some(
                out.add_channel(sid, &format!("/deadreckon/{n}/odom"), "cdr", &ros2_meta)
                    .map_err(werr)?,
            ),
            None => None,
        };
        plans.push((t, pose_ch, fix_ch, odom_ch));
    }
    let gnss_ch = match (gnss, fix_sid) {
        (Some(_), Some(sid)) => Some(
            out.add_channel(sid, "/deadreckon/gnss/fix", "json", &meta)
                .map_err(werr)?,
        ),
        _ => None,
    };
    let jerr = |e: serde_json::Error| RosError::Write {
        file: file.into(),
        what: e.to_string(),
    };
    for (t, pose_ch, fix_ch, odom_ch) in plans {
        for (seq, p) in t.points.iter().enumerate() {
            let (ns, ts) = stamp(p.t_s, file)?;
            let half = 0.5 * p.yaw_rad;
            let msg = json!({
                "timestamp": ts,
                "frame_id": FRAME_ID,
                "pose": {
                    "position": {"x": p.east_m, "y": p.north_m, "z": 0.0},
                    "orientation": {"x": 0.0, "y": 0.0, "z": half.sin(), "w": half.cos()}
                }
            });
            let header = |channel_id| mcap::records::MessageHeader {
                channel_id,
                sequence: seq as u32,
                log_time: ns,
                publish_time: ns,
            };
            if let Some(ch) = pose_ch {
                out.write_to_known_channel(&header(ch), &serde_json::to_vec(&msg).map_err(jerr)?)
                    .map_err(werr)?;
            }
            if let Some(ch) = odom_ch {
                let odom = crate::ros2_out::odometry(p).ok_or_else(|| RosError::Write {
                    file: file.into(),
                    what: format!(
                        "track `{}`: time {} s has no ROS 2 stamp (int32 seconds)",
                        t.name, p.t_s
                    ),
                })?;
                let data = crate::ros2::encode_cdr(&odom).map_err(|e| RosError::Write {
                    file: file.into(),
                    what: e,
                })?;
                out.write_to_known_channel(&header(ch), &data)
                    .map_err(werr)?;
            }
            if let (Some(ch), Some(origin)) = (fix_ch, t.origin) {
                let c = p.cov_pose;
                let data = location_fix(
                    ts,
                    origin,
                    (p.east_m, p.north_m),
                    [c[0], c[1], c[3], c[4]],
                    COVARIANCE_KNOWN,
                    file,
                )?;
                out.write_to_known_channel(&header(ch), &data)
                    .map_err(werr)?;
            }
        }
    }
    if let (Some(ch), Some((fixes, origin))) = (gnss_ch, gnss) {
        for (seq, g) in fixes.iter().enumerate() {
            let (ns, ts) = stamp(g.t_s, file)?;
            let v = g.std_m * g.std_m;
            let data = location_fix(
                ts,
                origin,
                (g.east_m, g.north_m),
                [v, 0.0, 0.0, v],
                COVARIANCE_DIAGONAL_KNOWN,
                file,
            )?;
            let header = mcap::records::MessageHeader {
                channel_id: ch,
                sequence: seq as u32,
                log_time: ns,
                publish_time: ns,
            };
            out.write_to_known_channel(&header, &data).map_err(werr)?;
        }
    }
    out.finish().map_err(werr)?;
    Ok(())
}
