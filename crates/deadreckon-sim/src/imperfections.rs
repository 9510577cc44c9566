//! Sensor imperfections beyond white noise, each off by default:
//!
//! - **A stream's own clock** ([`ClockSpec`], `clock = { … }` in any stream's
//!   table): the sample describes the true time t, its stamp is the ECU's
//!   clock reading t + offset + drift·t + jitter (drift in ppm, jitter white,
//!   clamped to ±[`MAX_JITTER_PERIODS`] sample periods so the stamps stay in
//!   order). Wheel ticks are counted over the true intervals and stamped
//!   with the jittered stamps.
//! - **Tone-ring tooth-spacing error** (`tooth_error_std` in
//!   `[sensors.wheels]`): tooth k of each wheel's ring sits at (k + e_k)
//!   pitches instead of k, e_k fixed per wheel and tooth (white, mean removed,
//!   clamped to ±[`MAX_TOOTH_ERROR_PITCH`]). Tick counts count those edges;
//!   wheel speeds are the rotation the ECU infers from them (it assumes evenly
//!   spaced teeth).
//! - **Gyro bias drift** (`bias_drift_std_rps`, `bias_drift_tau_s` in
//!   `[sensors.gyro]`): a first-order Gauss–Markov bias added to the constant
//!   one, stationary from the first reading.
//! - **GNSS multipath bursts** ([`MultipathSpec`], `[sensors.gnss.multipath]`):
//!   bursts arriving as a Poisson process, each lasting a few seconds with
//!   one position offset (white per axis) for its duration.
//!
//! Each draws from its own seeded generator, so switching one on changes none
//! of the other streams' noise.

use serde::{Deserialize, Serialize};

use crate::sensors::Noise;

/// Largest stamp jitter applied, in sample periods (larger draws are clamped).
pub const MAX_JITTER_PERIODS: f64 = 0.4;
/// Largest tooth position error, in tooth pitches (larger draws are clamped).
pub const MAX_TOOTH_ERROR_PITCH: f64 = 0.45;

/// A stream's own clock (`clock = { offset_s = …, drift_ppm = …,
/// jitter_std_s = … }`): stamp = t + `offset_s` + `drift_ppm`·10⁻⁶·t + jitter.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClockSpec {
    /// The clock's offset from true time, s (default 0; positive: the
    /// stamps are late).
    #[serde(default)]
    pub offset_s: f64,
    /// The clock's rate error, parts per million (default 0; positive: it
    /// runs fast, so the stamps drift later).
    #[serde(default)]
    pub drift_ppm: f64,
    /// Standard deviation of the white stamp jitter, s (default 0), at most
    /// a tenth of the sample period.
    #[serde(default)]
    pub jitter_std_s: f64,
}

impl ClockSpec {
    /// The stamp of true time `t` without jitter, s.
    pub fn stamp_without_jitter(&self, t: f64) -> f64 {
        t + self.offset_s + self.drift_ppm * 1e-6 * t
    }

    /// `(key, message)` of the first invalid value; `key` is the stream's
    /// table, `rate_hz` its rate.
    pub(crate) fn check(&self, key: &str, rate_hz: f64) -> Result<(), (String, String)> {
        if !self.offset_s.is_finite() || self.offset_s.abs() > 10.0 {
            return Err((
                format!("{key}.clock.offset_s"),
                format!("{} must be within ±10 s", self.offset_s),
            ));
        }
        if !self.drift_ppm.is_finite() || self.drift_ppm.abs() > 1000.0 {
            return Err((
                format!("{key}.clock.drift_ppm"),
                format!("{} must be within ±1000 ppm", self.drift_ppm),
            ));
        }
        let most = 0.1 / rate_hz;
        if !(self.jitter_std_s.is_finite() && (0.0..=most).contains(&self.jitter_std_s)) {
            return Err((
                format!("{key}.clock.jitter_std_s"),
                format!(
                    "{} must be within 0..={most} s (a tenth of the sample period)",
                    self.jitter_std_s
                ),
            ));
        }
        Ok(())
    }
}

/// A clock being simulated: stamps true times.
#[derive(Debug)]
pub(crate) struct EcuClock {
    spec: ClockSpec,
    max_jitter_s: f64,
    noise: Noise,
}

impl EcuClock {
    pub(crate) fn new(spec: ClockSpec, rate_hz: f64, noise: Noise) -> Self {
        EcuClock {
            spec,
            max_jitter_s: MAX_JITTER_PERIODS / rate_hz,
            noise,
        }
    }

    /// The stamp of the sample describing true time `t`.
    pub(crate) fn stamp(&mut self, t: f64) -> f64 {
        let j = if self.spec.jitter_std_s > 0.0 {
            self.noise
                .gauss(self.spec.jitter_std_s)
                .clamp(-self.max_jitter_s, self.max_jitter_s)
        } else {
            0.0
        };
        self.spec.stamp_without_jitter(t) + j
    }
}

/// The four tone rings: each tooth's position error, in pitches.
#[derive(Debug, Clone)]
pub(crate) struct ToneRings {
    errors: [Vec<f64>; 4],
}

impl ToneRings {
    /// Rings of `teeth` teeth with position errors of std `std_pitch`
    /// pitches (white per tooth, mean removed per wheel, clamped).
    pub(crate) fn draw(teeth: u32, std_pitch: f64, noise: &mut Noise) -> Self {
        let n = teeth.max(1) as usize;
        let errors = [0, 1, 2, 3].map(|_| {
            let mut e: Vec<f64> = (0..n).map(|_| noise.gauss(std_pitch)).collect();
            let mean = e.iter().sum::<f64>() / n as f64;
            for x in &mut e {
                *x = (*x - mean).clamp(-MAX_TOOTH_ERROR_PITCH, MAX_TOOTH_ERROR_PITCH);
            }
            e
        });
        ToneRings { errors }
    }

    /// Tooth errors of `wheel` (FL, FR, RL, RR), pitches.
    pub(crate) fn errors(&self, wheel: usize) -> &[f64] {
        &self.errors[wheel]
    }

    fn e(&self, wheel: usize, k: i64) -> f64 {
        let ring = &self.errors[wheel];
        ring[k.rem_euclid(ring.len() as i64) as usize]
    }

    /// Edges passed at `u` pitches of rotation (signed, cumulative), with
    /// edge k at k + e_k: ⌊u⌋ when every tooth sits where it should.
    pub(crate) fn edges(&self, wheel: usize, u: f64) -> i64 {
        let j = u.floor();
        let f = u - j;
        let j = j as i64;
        // Edges up to j − 1 have passed (|e| < ½); edge j if e_j ≤ f, edge
        // j + 1 if it sits early enough.
        j - 1 + i64::from(self.e(wheel, j) <= f) + i64::from(self.e(wheel, j + 1) <= f - 1.0)
    }

    /// The rotation, in pitches, the ECU infers at true rotation `u`: it takes
    /// the edges to be evenly spaced, so it reads u less the tooth error
    /// interpolated between the neighbouring teeth.
    pub(crate) fn inferred(&self, wheel: usize, u: f64) -> f64 {
        let j = u.floor();
        let f = u - j;
        let j = j as i64;
        u - (self.e(wheel, j) + f * (self.e(wheel, j + 1) - self.e(wheel, j)))
    }
}

/// A first-order Gauss–Markov process (stationary from its first value).
#[derive(Debug)]
pub(crate) struct GaussMarkov {
    std: f64,
    tau_s: f64,
    last: Option<(f64, f64)>,
    noise: Noise,
}

impl GaussMarkov {
    pub(crate) fn new(std: f64, tau_s: f64, noise: Noise) -> Self {
        GaussMarkov {
            std,
            tau_s,
            last: None,
            noise,
        }
    }

    /// The value at `t` (times non-decreasing).
    pub(crate) fn at(&mut self, t: f64) -> f64 {
        let x = match self.last {
            None => self.noise.gauss(self.std),
            Some((t0, x0)) => {
                let a = (-(t - t0) / self.tau_s).exp();
                a * x0 + self.noise.gauss(self.std * (1.0 - a * a).sqrt())
            }
        };
        self.last = Some((t, x));
        x
    }
}

/// GNSS multipath bursts (`[sensors.gnss.multipath]`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MultipathSpec {
    /// Bursts per minute of clean reception, 1/min (default 0.5): the gaps
    /// between one burst's end and the next one's start are exponential
    /// with mean 60 / this, s (Poisson arrivals).
    #[serde(default = "default_rate")]
    pub bursts_per_min: f64,
    /// Mean length of a burst, s (default 3; each is drawn uniformly within
    /// ±50 % of it).
    #[serde(default = "default_duration")]
    pub mean_duration_s: f64,
    /// Standard deviation of a burst's position offset per axis (east,
    /// north), m (default 2).
    #[serde(default = "default_offset")]
    pub offset_std_m: f64,
}

fn default_rate() -> f64 {
    0.5
}
fn default_duration() -> f64 {
    3.0
}
fn default_offset() -> f64 {
    2.0
}

impl Default for MultipathSpec {
    fn default() -> Self {
        MultipathSpec {
            bursts_per_min: default_rate(),
            mean_duration_s: default_duration(),
            offset_std_m: default_offset(),
        }
    }
}

impl MultipathSpec {
    /// `(key, message)` of the first invalid value.
    pub(crate) fn check(&self) -> Result<(), (String, String)> {
        for (k, v) in [
            ("bursts_per_min", self.bursts_per_min),
            ("mean_duration_s", self.mean_duration_s),
            ("offset_std_m", self.offset_std_m),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err((
                    format!("sensors.gnss.multipath.{k}"),
                    format!("{v} must be a non-negative number"),
                ));
            }
        }
        Ok(())
    }
}

/// The bursts being simulated.
#[derive(Debug)]
pub(crate) struct Multipath {
    spec: MultipathSpec,
    noise: Noise,
    next_start_s: Option<f64>,
    current: Option<(f64, f64, f64)>,
    /// Bursts so far: `(start, end, east offset, north offset)`, s and m.
    pub(crate) bursts: Vec<(f64, f64, f64, f64)>,
}

impl Multipath {
    pub(crate) fn new(spec: MultipathSpec, noise: Noise) -> Self {
        Multipath {
            spec,
            noise,
            next_start_s: None,
            current: None,
            bursts: Vec::new(),
        }
    }

    fn gap(&mut self) -> f64 {
        if self.spec.bursts_per_min <= 0.0 {
            return f64::INFINITY;
        }
        -(60.0 / self.spec.bursts_per_min) * (1.0 - self.noise.uniform()).ln()
    }

    /// The offset (east, north) at `t`, m (times non-decreasing).
    pub(crate) fn at(&mut self, t: f64) -> (f64, f64) {
        if self.next_start_s.is_none() {
            let g = self.gap();
            self.next_start_s = Some(g);
        }
        if let Some((end, _, _)) = self.current {
            if t >= end {
                self.current = None;
            }
        }
        while self.current.is_none() && self.next_start_s.is_some_and(|s| t >= s) {
            let start = self.next_start_s.unwrap_or(t);
            let d = self.spec.mean_duration_s * (0.5 + self.noise.uniform());
            let (e, n) = (
                self.noise.gauss(self.spec.offset_std_m),
                self.noise.gauss(self.spec.offset_std_m),
            );
            self.bursts.push((start, start + d, e, n));
            let gap = self.gap();
            self.next_start_s = Some(start + d + gap);
            if t < start + d {
                self.current = Some((start + d, e, n));
            }
        }
        self.current.map_or((0.0, 0.0), |(_, e, n)| (e, n))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn even_teeth_count_like_the_floor_and_errors_move_the_edges() {
        let mut noise = Noise::new(1, 99);
        let even = ToneRings::draw(48, 0.0, &mut noise);
        for u in [-3.7, -1.0, 0.0, 0.2, 1.0, 47.99, 48.0, 1000.5] {
            assert_eq!(even.edges(0, u), u.floor() as i64, "{u}");
            assert_eq!(even.inferred(0, u), u);
        }
        let rings = ToneRings::draw(48, 0.2, &mut noise);
        let e = rings.errors(2);
        assert!(e.iter().sum::<f64>().abs() < 1e-9);
        // Edge 5 of wheel RL sits at 5 + e_5: passed just after, not before.
        assert_eq!(rings.edges(2, 5.0 + e[5] + 1e-9), 5);
        assert_eq!(rings.edges(2, 5.0 + e[5] - 1e-9), 4);
        // A whole revolution passes 48 edges wherever it starts.
        for u in [0.3, 7.9, -20.1] {
            assert_eq!(rings.edges(2, u + 48.0) - rings.edges(2, u), 48);
        }
    }

    #[test]
    fn bursts_arrive_at_the_asked_rate() {
        let spec = MultipathSpec {
            bursts_per_min: 2.0,
            mean_duration_s: 3.0,
            offset_std_m: 2.0,
        };
        let mut m = Multipath::new(spec, Noise::new(3, 77));
        let mut on = 0;
        let n = 360_000;
        for k in 0..n {
            let (e, _) = m.at(f64::from(k) * 0.1);
            on += i32::from(e != 0.0);
        }
        // 10 hours: about 1200 bursts of 3 s, on 3/33 of the time.
        let bursts = m.bursts.len() as f64;
        assert!((bursts - 1091.0).abs() < 100.0, "{bursts}");
        let share = f64::from(on) / f64::from(n);
        assert!((share - 3.0 / 33.0).abs() < 0.01, "{share}");
    }
}
