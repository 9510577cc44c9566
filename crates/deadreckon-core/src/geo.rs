//! Latitude/longitude ↔ local east-north, on the WGS84 ellipsoid, through
//! `map_3d` (geodetic → ECEF → ENU about the origin, altitudes taken as 0).

use crate::vehicle::Origin;

/// East and north of `(lat_deg, lon_deg)` about `origin`, m (WGS84, both at
/// zero ellipsoidal height; the local frame is the origin's tangent plane).
pub fn geodetic_to_en(origin: &Origin, lat_deg: f64, lon_deg: f64) -> (f64, f64) {
    let (e, n, _up) = map_3d::geodetic2enu(
        lat_deg.to_radians(),
        lon_deg.to_radians(),
        0.0,
        origin.lat_deg.to_radians(),
        origin.lon_deg.to_radians(),
        0.0,
        map_3d::Ellipsoid::WGS84,
    );
    (e, n)
}

/// Latitude and longitude, degrees, of the point `(east_m, north_m)` of the
/// origin's tangent plane (the inverse of [`geodetic_to_en`] to well below a
/// millimetre within a few kilometres of the origin).
pub fn en_to_geodetic(origin: &Origin, east_m: f64, north_m: f64) -> (f64, f64) {
    let (lat, lon, _alt) = map_3d::enu2geodetic(
        east_m,
        north_m,
        0.0,
        origin.lat_deg.to_radians(),
        origin.lon_deg.to_radians(),
        0.0,
        map_3d::Ellipsoid::WGS84,
    );
    (lat.to_degrees(), lon.to_degrees())
}
