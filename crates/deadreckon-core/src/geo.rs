//! Latitude/longitude/height ↔ local east-north, on the WGS84 ellipsoid,
//! through `map_3d` (geodetic → ECEF → ENU about the origin at its height),
//! with an inverse that is exact at any distance.
//!
//! The local frame is the tangent plane at the origin ([`Origin`], with its
//! ellipsoidal height). A position with a height of its own (a GNSS fix with
//! its altitude) converts with it, [`geodetic_height_to_en`]; one without is
//! taken at the origin's height, [`geodetic_to_en`]. Going back, a planar
//! position becomes the point at the origin's height, [`en_to_geodetic`]:
//! the exact inverse of [`geodetic_to_en`].

use crate::vehicle::Origin;

/// East and north of `(lat_deg, lon_deg)` at the origin's height, m, in the
/// tangent plane at `origin`.
pub fn geodetic_to_en(origin: &Origin, lat_deg: f64, lon_deg: f64) -> (f64, f64) {
    geodetic_height_to_en(origin, lat_deg, lon_deg, origin.height_m)
}

/// East and north of `(lat_deg, lon_deg, height_m)` (height above the
/// WGS84 ellipsoid, m) in the tangent plane at `origin`, m; the up
/// component is dropped (the frame is planar).
pub fn geodetic_height_to_en(
    origin: &Origin,
    lat_deg: f64,
    lon_deg: f64,
    height_m: f64,
) -> (f64, f64) {
    let (e, n, _up) = map_3d::geodetic2enu(
        lat_deg.to_radians(),
        lon_deg.to_radians(),
        height_m,
        origin.lat_deg.to_radians(),
        origin.lon_deg.to_radians(),
        origin.height_m,
        map_3d::Ellipsoid::WGS84,
    );
    (e, n)
}

/// Latitude and longitude, degrees, of the point at the origin's height
/// whose [`geodetic_to_en`] is `(east_m, north_m)`: its exact inverse at any
/// distance. The tangent-plane point itself lies above that surface away
/// from the origin (about 785 m at 100 km), so the height along the local
/// vertical is solved for, not taken as 0 (which was 12 m off at 100 km).
pub fn en_to_geodetic(origin: &Origin, east_m: f64, north_m: f64) -> (f64, f64) {
    let (lat0, lon0) = (origin.lat_deg.to_radians(), origin.lon_deg.to_radians());
    let mut up = 0.0;
    let mut out = (lat0, lon0);
    for _ in 0..MAX_ITERATIONS {
        let (lat, lon, alt) = map_3d::enu2geodetic(
            east_m,
            north_m,
            up,
            lat0,
            lon0,
            origin.height_m,
            map_3d::Ellipsoid::WGS84,
        );
        out = (lat, lon);
        let above = alt - origin.height_m;
        if !above.is_finite() || above.abs() < HEIGHT_TOLERANCE_M {
            break;
        }
        // Up is nearly along the ellipsoid normal there: step down by the height.
        up -= above;
    }
    (out.0.to_degrees(), out.1.to_degrees())
}

/// Iterations of the height solve (each gains about four orders of
/// magnitude at 100 km: 3 reach the tolerance).
const MAX_ITERATIONS: usize = 8;
/// Height above the ellipsoid taken as on it, m.
const HEIGHT_TOLERANCE_M: f64 = 1e-7;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn en_to_geodetic_was_12_m_off_at_100_km_and_is_now_the_exact_inverse() {
        for origin in [
            Origin::new(48.1, 11.6),
            Origin::new(-33.9, 151.2),
            Origin::new(69.6, 18.9),
            // A highland origin: the inverse holds at its height.
            Origin {
                lat_deg: -16.5,
                lon_deg: -68.15,
                height_m: 3_640.0,
            },
        ] {
            for (e, n) in [
                (100e3, 0.0),
                (0.0, 100e3),
                (-70_710.0, 70_710.0),
                (-30e3, -95e3),
                (1500.0, -2500.0),
            ] {
                let (lat, lon) = en_to_geodetic(&origin, e, n);
                let (e2, n2) = geodetic_to_en(&origin, lat, lon);
                assert!(
                    (e2 - e).abs() < 1e-6 && (n2 - n).abs() < 1e-6,
                    "{origin:?} ({e}, {n}) -> ({lat}, {lon}) -> ({e2}, {n2})"
                );
                let (lat2, lon2) = en_to_geodetic(&origin, e2, n2);
                assert!((lat2 - lat).abs() < 1e-11 && (lon2 - lon).abs() < 1e-11);
            }
        }
    }

    #[test]
    fn a_point_100_km_north_is_about_0_9_degrees_of_latitude_away() {
        // One degree of latitude at 48° is 111.2 km (WGS84 meridian arc).
        let o = Origin::new(48.0, 11.0);
        let (lat, lon) = en_to_geodetic(&o, 0.0, 100e3);
        assert!((lat - 48.0 - 100.0 / 111.2).abs() < 0.002, "{lat}");
        assert!((lon - 11.0).abs() < 1e-9);
    }

    #[test]
    fn heights_were_taken_as_0_by_the_csv_reader_and_the_writers() {
        // An origin 2,000 m above the ellipsoid: a fix 100 km north at the
        // same height lies 100 km × 2000 / 6.37e6 ≈ 31 m further out in the
        // tangent plane than the same latitude/longitude on the ellipsoid.
        let high = Origin {
            lat_deg: 46.0,
            lon_deg: 8.0,
            height_m: 2_000.0,
        };
        let (lat, lon) = en_to_geodetic(&high, 0.0, 100e3);
        let (e, n) = geodetic_height_to_en(&high, lat, lon, 2_000.0);
        assert!(e.abs() < 1e-6 && (n - 100e3).abs() < 1e-6, "({e}, {n})");
        let (_, n0) = geodetic_height_to_en(&high, lat, lon, 0.0);
        let low = Origin::new(46.0, 8.0);
        let (lat_low, _) = en_to_geodetic(&low, 0.0, 100e3);
        let shift_m = (lat_low - lat).abs() * 111.2e3;
        assert!((25.0..40.0).contains(&shift_m), "{shift_m} m");
        assert!((n - n0 - 31.4).abs() < 1.0, "{}", n - n0);
        // A fix 100 m above the origin and 10 km away moves about 16 cm
        // in the plane (the plane tilts away from the local level).
        let (lat, lon) = en_to_geodetic(&high, 10e3, 0.0);
        let (e100, _) = geodetic_height_to_en(&high, lat, lon, 2_100.0);
        assert!((e100 - 10e3 - 0.157).abs() < 0.01, "{}", e100 - 10e3);
    }
}
