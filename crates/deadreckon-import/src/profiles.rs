//! Built-in vehicle profiles, each value with its source.

use deadreckon_core::vehicle::Noise;
use deadreckon_core::Vehicle;

/// Forward distance from the rear-axle centre to the comma device (camera and
/// u-blox antenna) in the comma2k19 RAV4, m.
///
/// An estimate, not a measurement: the device hangs at the top centre of the
/// windshield behind the mirror, about 1.1 m behind the front axle of a
/// 2.65 m wheelbase (±0.3 m). The data cannot pin it: on this nearly straight
/// segment a forward offset only shifts the track along itself.
pub const RAV4_DEVICE_FORWARD_M: f64 = 1.5;

/// The Toyota RAV4 2016–18 (XA40) of comma2k19.
///
/// | value | source |
/// |---|---|
/// | `wheelbase_m` 2.65 | openpilot/opendbc `TOYOTA_RAV4` `CarSpecs(wheelbase=2.65)` (Toyota's spec sheet: 2,660 mm) |
/// | `track_front_m`, `track_rear_m` 1.6 | approximate: Toyota gives about 1.57 m; the shared data README measures the rear track at about 1.6 m on this segment |
/// | `steering_ratio` 14.5 | openpilot's RAV4 interface: `steerRatio = 16.88  # 14.5 is spec end-to-end`; 16.88 is openpilot's fitted ratio for its dynamic bicycle model (it absorbs tyre compliance), 14.5 is the geometric ratio the kinematic model wants |
/// | `wheel_circumference_m` 2.275 | 225/65R17 tyre: diameter 17 × 25.4 + 2 × 0.65 × 225 = 724.3 mm, circumference π × 0.7243 m (unloaded; the rolling value is a few per cent less and is what calibration estimates) |
/// | `ticks_per_rev` 48 | placeholder: comma2k19 gives wheel speeds, not pulse counts, so it is unused |
/// | `gnss_lever_arm_m` 1.5 | the u-blox antenna is taken at the device, [`RAV4_DEVICE_FORWARD_M`] ahead of the rear axle (estimate) |
///
/// Noise is the core defaults (the paper's tables I and II).
pub fn toyota_rav4() -> Vehicle {
    Vehicle {
        wheelbase_m: 2.65,
        track_front_m: 1.6,
        track_rear_m: 1.6,
        gnss_lever_arm_m: RAV4_DEVICE_FORWARD_M,
        ticks_per_rev: 48,
        wheel_circumference_m: std::f64::consts::PI * (17.0 * 0.0254 + 2.0 * 0.65 * 0.225),
        steering_ratio: 14.5,
        wheels_present: [true; 4],
        origin: None,
        noise: Noise::default(),
        vehicle_id: None,
        recorded_at: None,
        steering_offset_rad: 0.0,
        understeer_gradient_rad_per_mps2: 0.0,
        rear_slip_gradient_rad_per_mps2: 0.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rav4_profile_is_valid_and_tyre_circumference_is_2_275_m() {
        let v = toyota_rav4();
        v.validate().unwrap();
        assert!(
            (v.wheel_circumference_m - 2.2755).abs() < 1e-3,
            "{}",
            v.wheel_circumference_m
        );
    }
}
