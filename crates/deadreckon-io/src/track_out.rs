//! Writers of estimated tracks: one CSV for any number of tracks, and GeoJSON
//! for maps.

use std::path::Path;

use deadreckon_core::Track;
use geojson::{Feature, FeatureCollection, Geometry, JsonObject, JsonValue, Position};

use crate::{atomic_write, geo, IoError};

/// The columns of [`write_track_csv`], in order.
pub const TRACK_CSV_COLUMNS: [&str; 12] = [
    "t_s",
    "track",
    "east_m",
    "north_m",
    "yaw_rad",
    "speed_mps",
    "yaw_rate_rps",
    "std_east_m",
    "std_north_m",
    "std_yaw_rad",
    "cov_en_m2",
    "bound_95_m",
];

/// Writes `tracks` into one CSV file (atomically), track after track, with the
/// columns of [`TRACK_CSV_COLUMNS`]: the `track` column holds the track's name
/// (quoted when needed), the standard deviations are the square roots of the
/// covariance diagonal, and `cov_en_m2` is its east-north term. A track
/// that carries no uncertainty ([`carries_no_covariance`]: TedriS, the
/// kinematic shapes' integration, a reference) leaves those four columns
/// empty rather than writing 0, which would read as certainty. The
/// `bound_95_m` column is empty ([`write_track_csv_with_bounds`] fills it).
pub fn write_track_csv(path: &Path, tracks: &[Track]) -> Result<(), IoError> {
    write_track_csv_with_bounds(path, tracks, &[])
}

/// [`write_track_csv`] with the 95 % bound of each pose in `bound_95_m`
/// (7 significant digits): `bounds[i][k]` for pose `k` of track `i`; a
/// track without (a missing or empty `bounds[i]`) leaves it empty.
pub fn write_track_csv_with_bounds(
    path: &Path,
    tracks: &[Track],
    bounds: &[Vec<f64>],
) -> Result<(), IoError> {
    // Written row by row into the temporary file that replaces `path`
    // (no copy of the whole file in memory: 81 MB for an hour's three
    // tracks at 50 Hz).
    atomic_write(path, |out| {
        let mut w = csv::Writer::from_writer(out);
        w.write_record(TRACK_CSV_COLUMNS)?;
        for (i, track) in tracks.iter().enumerate() {
            let none = carries_no_covariance(track);
            let bound = bounds.get(i).filter(|b| b.len() == track.points.len());
            let unc = |v: f64| {
                if none {
                    String::new()
                } else {
                    format!("{v:.6e}")
                }
            };
            for (k, p) in track.points.iter().enumerate() {
                // Fixed precision per column (the shortest round-trip form of a
                // tiny number runs to 40 digits): times, positions and angles to
                // 1e-9 (what `events | stream` is checked against), speeds to
                // 1e-6 m/s, uncertainties to 7 significant digits.
                w.write_record([
                    format!("{:.9}", p.t_s),
                    track.name.clone(),
                    format!("{:.9}", p.east_m),
                    format!("{:.9}", p.north_m),
                    format!("{:.9}", p.yaw_rad),
                    format!("{:.6}", p.speed_mps),
                    format!("{:.9}", p.yaw_rate_rps),
                    unc(p.std_east_m()),
                    unc(p.std_north_m()),
                    unc(p.std_yaw_rad()),
                    unc(p.cov_pose[1]),
                    bound.map_or(String::new(), |b| format!("{:.6e}", b[k])),
                ])?;
            }
        }
        w.flush()
    })
}

/// Whether `track` has no uncertainty at all: a pose covariance of exactly
/// zero at every pose (what estimators without one, TedriS and the kinematic
/// integration, leave in it; a filter's covariance is never exactly zero).
pub fn carries_no_covariance(track: &Track) -> bool {
    track
        .points
        .iter()
        .all(|p| p.cov_pose.iter().all(|&c| c == 0.0))
}

/// Options of [`write_track_geojson_with`].
#[derive(Debug, Clone, Default)]
#[non_exhaustive]
pub struct GeoJsonOptions {
    /// Also write a Point feature for the first pose and then every pose at
    /// least this many seconds after the previous marker (`None`: no points).
    pub point_every_s: Option<f64>,
}

impl GeoJsonOptions {
    /// Adds Point features every `seconds`.
    pub fn point_every_s(mut self, seconds: f64) -> Self {
        self.point_every_s = Some(seconds);
        self
    }
}

/// Writes `tracks` as a GeoJSON FeatureCollection (atomically): one LineString
/// feature per track, coordinates `[lon, lat]` in degrees (WGS84) computed from
/// the track's `origin`, with properties `name`, `t_start_s`, `t_end_s` and
/// `points`. A track with one pose becomes a Point, one with none a feature
/// with a null geometry. Every track needs a geodetic origin.
pub fn write_track_geojson(path: &Path, tracks: &[Track]) -> Result<(), IoError> {
    write_track_geojson_with(path, tracks, &GeoJsonOptions::default())
}

/// [`write_track_geojson`] with options. The Point features of
/// [`GeoJsonOptions::point_every_s`] have properties `name`, `t_s`, `yaw_rad`,
/// `speed_mps`, `std_east_m` and `std_north_m`.
pub fn write_track_geojson_with(
    path: &Path,
    tracks: &[Track],
    options: &GeoJsonOptions,
) -> Result<(), IoError> {
    let mut features = Vec::new();
    for track in tracks {
        let origin = track.origin.ok_or_else(|| IoError::NeedsOrigin {
            file: path.to_path_buf(),
            message: format!(
                "track `{}` has no geodetic origin: GeoJSON needs latitude/longitude \
                 (set [origin] in vehicle.toml or read a drive with lat/lon fixes)",
                track.name
            ),
        })?;
        let mut coords = Vec::with_capacity(track.points.len());
        for p in &track.points {
            let (lat, lon) = geo::en_to_geodetic(&origin, p.east_m, p.north_m);
            if !(lat.is_finite() && lon.is_finite()) {
                return Err(IoError::Unwritable {
                    path: path.to_path_buf(),
                    message: format!(
                        "track `{}`: non-finite position at t = {} s",
                        track.name, p.t_s
                    ),
                });
            }
            coords.push(Position::from([degrees(lon), degrees(lat)]));
        }
        let mut props = JsonObject::new();
        props.insert("name".into(), JsonValue::from(track.name.clone()));
        props.insert(
            "t_start_s".into(),
            number(track.points.first().map(|p| p.t_s)),
        );
        props.insert("t_end_s".into(), number(track.points.last().map(|p| p.t_s)));
        props.insert("points".into(), JsonValue::from(track.points.len()));
        let geometry = match coords.len() {
            0 => None,
            1 => coords.pop().map(Geometry::new_point),
            _ => Some(Geometry::new_line_string(coords.iter().cloned())),
        };
        features.push(Feature {
            geometry,
            properties: Some(props),
            ..Feature::default()
        });
        if let Some(every) = options.point_every_s.filter(|s| *s > 0.0) {
            let mut next = f64::NEG_INFINITY;
            let none = carries_no_covariance(track);
            for p in &track.points {
                if p.t_s < next {
                    continue;
                }
                next = p.t_s + every;
                let (lat, lon) = geo::en_to_geodetic(&origin, p.east_m, p.north_m);
                let mut props = JsonObject::new();
                props.insert("name".into(), JsonValue::from(track.name.clone()));
                props.insert("t_s".into(), number(Some(p.t_s)));
                props.insert("yaw_rad".into(), number(Some(p.yaw_rad)));
                props.insert("speed_mps".into(), number(Some(p.speed_mps)));
                let unc = |v: f64| number((!none).then_some(v));
                props.insert("std_east_m".into(), unc(p.std_east_m()));
                props.insert("std_north_m".into(), unc(p.std_north_m()));
                features.push(Feature {
                    geometry: Some(Geometry::new_point([degrees(lon), degrees(lat)])),
                    properties: Some(props),
                    ..Feature::default()
                });
            }
        }
    }
    let collection = FeatureCollection::new(features);
    // Compact: one line (an hour at 50 Hz is a few MB, not tens).
    let text = serde_json::to_string(&collection).map_err(|e| IoError::Unwritable {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    atomic_write(path, |w| {
        w.write_all(text.as_bytes())?;
        w.write_all(b"\n")
    })
}

/// Degrees rounded to 1e-8° (about 1 mm): the shortest form of the result
/// prints at most 8 decimals.
fn degrees(v: f64) -> f64 {
    (v * 1e8).round() / 1e8
}

/// A JSON number, or null for `None` and non-finite values.
fn number(v: Option<f64>) -> JsonValue {
    v.and_then(serde_json::Number::from_f64)
        .map_or(JsonValue::Null, JsonValue::Number)
}
