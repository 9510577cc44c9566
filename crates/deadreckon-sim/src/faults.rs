//! Wheel faults (`[sensors.wheel_faults]`): what the wheel-health monitor of
//! `deadreckon_core::wheel_health` has to find.
//!
//! - **Spin** ([`SpinSpec`]): one driven wheel turns faster than the ground
//!   under traction, in short bursts. A burst starts only while the car
//!   accelerates harder than `min_accel_mps2`, lasts `duration_s`, and the
//!   wheel then rolls `1 + slip` times the ground distance; the next burst is
//!   allowed after a gap drawn from an exponential law with mean
//!   `mean_gap_s` (seeded, from its own random stream).
//! - **Smaller wheel** ([`ShrinkSpec`]): from `from_s` on, one wheel's true
//!   circumference is `factor` times what it was (a spare tyre, a damaged
//!   sensor ring: 0.97 for 3 % smaller), so it reports `1/factor` times the
//!   rotation.
//!
//! Neither changes the truth or the drive's true parameters (the calibration
//! targets stay the fault-free ones): only what the wheel sensor reports.

use serde::{Deserialize, Serialize};

/// Bursts of wheel spin on one wheel (`[sensors.wheel_faults.spin]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SpinSpec {
    /// The spinning wheel, 0..4 (FL, FR, RL, RR): a driven one.
    pub wheel: usize,
    /// Extra rotation during a burst, as a fraction of the ground distance
    /// (default 0.3: the wheel turns 30 % faster than the car moves).
    #[serde(default = "default_slip")]
    pub slip: f64,
    /// Length of one burst, s (default 1).
    #[serde(default = "default_burst")]
    pub duration_s: f64,
    /// Mean gap between bursts, s (default 60).
    #[serde(default = "default_gap")]
    pub mean_gap_s: f64,
    /// A burst starts only above this longitudinal acceleration, m/s² (default 0.5).
    #[serde(default = "default_accel")]
    pub min_accel_mps2: f64,
}

fn default_slip() -> f64 {
    0.3
}
fn default_burst() -> f64 {
    1.0
}
fn default_gap() -> f64 {
    60.0
}
fn default_accel() -> f64 {
    0.5
}

/// One wheel smaller from some time on (`[sensors.wheel_faults.shrink]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShrinkSpec {
    /// The wheel, 0..4 (FL, FR, RL, RR).
    pub wheel: usize,
    /// From this time on, s.
    pub from_s: f64,
    /// Circumference factor (0.97: 3 % smaller).
    pub factor: f64,
}

/// The wheel faults of a scenario (`[sensors.wheel_faults]`); both optional.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WheelFaultsSpec {
    /// Spin bursts under traction.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spin: Option<SpinSpec>,
    /// A smaller wheel from mid-drive.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shrink: Option<ShrinkSpec>,
}

impl WheelFaultsSpec {
    /// `(key, message)` of the first invalid value.
    pub(crate) fn check(&self) -> Result<(), (String, String)> {
        if let Some(s) = &self.spin {
            let key = |k: &str| format!("sensors.wheel_faults.spin.{k}");
            if s.wheel > 3 {
                return Err((key("wheel"), format!("{} is not a wheel 0..3", s.wheel)));
            }
            for (k, v) in [
                ("slip", s.slip),
                ("duration_s", s.duration_s),
                ("mean_gap_s", s.mean_gap_s),
            ] {
                if !(v.is_finite() && v > 0.0) {
                    return Err((key(k), format!("{v} must be positive")));
                }
            }
            if !s.min_accel_mps2.is_finite() {
                return Err((key("min_accel_mps2"), "must be finite".into()));
            }
        }
        if let Some(s) = &self.shrink {
            let key = |k: &str| format!("sensors.wheel_faults.shrink.{k}");
            if s.wheel > 3 {
                return Err((key("wheel"), format!("{} is not a wheel 0..3", s.wheel)));
            }
            if !(s.factor.is_finite() && (0.5..=1.5).contains(&s.factor)) {
                return Err((key("factor"), format!("{} is not in 0.5..1.5", s.factor)));
            }
            if !s.from_s.is_finite() {
                return Err((key("from_s"), "must be finite".into()));
            }
        }
        Ok(())
    }
}

/// The faults being simulated: turns each wheel's ground distance into the
/// distance its sensor counts.
#[derive(Debug)]
pub(crate) struct WheelFaults {
    spec: WheelFaultsSpec,
    /// Extra distance counted by each wheel so far, m.
    extra_m: [f64; 4],
    last: Option<(f64, [f64; 4])>,
    burst_until: f64,
    next_burst_s: f64,
    /// Ground distance of the shrinking wheel when it shrank.
    shrunk_at_m: Option<f64>,
    /// Burst intervals `(start, end)`, s.
    pub bursts: Vec<(f64, f64)>,
}

impl WheelFaults {
    pub fn new(spec: WheelFaultsSpec) -> Self {
        WheelFaults {
            spec,
            extra_m: [0.0; 4],
            last: None,
            burst_until: f64::NEG_INFINITY,
            next_burst_s: 0.0,
            shrunk_at_m: None,
            bursts: Vec::new(),
        }
    }

    /// The distance each wheel's sensor counts at time `t` (ground distances
    /// `wheel_m`, speed-independent acceleration `accel`); `uniform` draws from
    /// the faults' own random stream.
    pub fn counted(
        &mut self,
        t: f64,
        accel: f64,
        wheel_m: [f64; 4],
        mut uniform: impl FnMut() -> f64,
    ) -> [f64; 4] {
        if let Some(spin) = &self.spec.spin {
            if let Some((_, last_m)) = self.last {
                if t < self.burst_until {
                    let i = spin.wheel;
                    self.extra_m[i] += spin.slip * (wheel_m[i] - last_m[i]);
                } else if t >= self.next_burst_s && accel > spin.min_accel_mps2 {
                    self.burst_until = t + spin.duration_s;
                    self.bursts.push((t, self.burst_until));
                    // Exponential gap: −mean · ln(1 − U).
                    let gap = -spin.mean_gap_s * (1.0 - uniform()).ln();
                    self.next_burst_s = self.burst_until + gap;
                }
            }
        }
        self.last = Some((t, wheel_m));
        let mut out = wheel_m;
        for (o, e) in out.iter_mut().zip(self.extra_m) {
            *o += e;
        }
        if let Some(s) = &self.spec.shrink {
            if t >= s.from_s {
                let at = *self.shrunk_at_m.get_or_insert(wheel_m[s.wheel]);
                // Past the change the wheel turns 1/factor times per metre.
                out[s.wheel] += (wheel_m[s.wheel] - at) * (1.0 / s.factor - 1.0);
            }
        }
        out
    }
}
