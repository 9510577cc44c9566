//! The simulation's sensor suite: one seeded noise source and one clock per
//! stream ([`Noise`], `Clock`), and [`Suite`], which samples every stream
//! from the truth as the simulation steps.

use deadreckon_core::drive::{Axes, GnssFix, Scalar, TruthPose, WheelSpeeds, WheelTicks, Wheels};
use deadreckon_core::{angle, drive::yaw_rad_to_course_deg, Drive, Params, Vehicle};
use rand::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use rand_pcg::Pcg64;

use super::{
    tilt_rotation, CourseConvention, LowSpeedCourse, SensorsSpec, WheelKind, ACCEL_NOISE_STD_MPS2,
};
use crate::faults::WheelFaults;
use crate::imperfections::{EcuClock, GaussMarkov, Multipath, ToneRings};
use crate::truth::{Kinematics, State};

/// Sample times `offset + i / rate`.
#[derive(Debug)]
struct Clock {
    rate: f64,
    offset: f64,
    i: u64,
}

impl Clock {
    fn new(rate: f64, offset: f64) -> Self {
        Clock { rate, offset, i: 0 }
    }
    fn t(&self) -> f64 {
        self.offset + self.i as f64 / self.rate
    }
}

/// SplitMix64 finaliser: decorrelates the per-stream seeds.
fn mix(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// A seeded Gaussian source for one stream.
#[derive(Debug)]
pub(crate) struct Noise(Pcg64);

impl Noise {
    pub(crate) fn new(seed: u64, stream: u64) -> Self {
        Noise(Pcg64::seed_from_u64(mix(seed ^ mix(stream))))
    }
    pub(crate) fn gauss(&mut self, std: f64) -> f64 {
        let z: f64 = StandardNormal.sample(&mut self.0);
        std * z
    }
    /// Uniform in [0, 1).
    pub(crate) fn uniform(&mut self) -> f64 {
        rand::RngExt::random::<f64>(&mut self.0)
    }
}

/// The receiver's memory between fixes.
#[derive(Debug, Default)]
struct GnssState {
    /// Time of the previous fix, s.
    last_t: Option<f64>,
    /// The Gauss–Markov position error, east and north, m.
    markov: (f64, f64),
    /// The last course reported at speed, degrees.
    last_course_deg: Option<f64>,
}

#[derive(Debug)]
enum WheelState {
    Ticks {
        out: Vec<WheelTicks>,
        emitted: [i64; 4],
    },
    Speeds {
        out: Vec<WheelSpeeds>,
        last_rot: [f64; 4],
        last_t: Option<f64>,
        last_jitter: [f64; 4],
    },
}

/// Every stream being simulated.
#[derive(Debug)]
pub(crate) struct Suite {
    spec: SensorsSpec,
    t_end: f64,
    circ: [f64; 4],
    nominal_circ: f64,
    ticks_per_rev: f64,
    params: Params,
    steering_ratio: f64,
    wheelbase: f64,
    lever_arm: f64,
    clocks: [Option<Clock>; 6],
    noise: [Noise; 5],
    wheels: WheelState,
    yaw_rate: Vec<Scalar>,
    speed: Vec<Scalar>,
    steering: Vec<Scalar>,
    gnss: Vec<GnssFix>,
    gnss_state: GnssState,
    truth: Vec<TruthPose>,
    imu_gyro: Vec<Axes>,
    imu_accel: Vec<Axes>,
    faults: Option<(WheelFaults, Noise)>,
    /// Whether the truth has side slip (`[dynamics]`).
    dynamic: bool,
    /// Each stream's own clock, by stream index (wheels to GNSS).
    stamps: [Option<EcuClock>; 5],
    /// Tone rings with tooth-spacing errors.
    rings: Option<ToneRings>,
    /// Where each wheel's ring stands at the start (FL, FR, RL, RR), in
    /// pitches past an edge, uniform in [0, 1) from its own stream (15): a
    /// parked wheel stops anywhere between two edges. Tick counters count
    /// the edges passed from there ([`edges_passed`]). With every ring
    /// starting at an edge, the counted distance trailed the true one by
    /// half a pitch on average through a whole drive (2 cm on 48 teeth),
    /// which the GNSS delay read as −5.7, −5.7 and −1.7 ms on the
    /// evaluation scenario's ticks at 25, 50 and 100 Hz. Speeds do not use
    /// it: they are differences of the rotation, which where a ring starts
    /// does not bias.
    ring_phase: [f64; 4],
    /// The gyro's drifting bias.
    gyro_drift: Option<GaussMarkov>,
    /// The receiver's multipath bursts.
    multipath: Option<Multipath>,
}

/// Edges of `wheel`'s ring passed at `u` pitches of rotation (signed,
/// cumulative from edge 0): ⌊u⌋ on an even ring, the misplaced edges on one
/// with tooth errors.
fn edges_passed(rings: Option<&ToneRings>, wheel: usize, u: f64) -> i64 {
    match rings {
        None => u.floor() as i64,
        Some(r) => r.edges(wheel, u),
    }
}

const WHEELS: usize = 0;
const GYRO: usize = 1;
const SPEED: usize = 2;
const STEERING: usize = 3;
const GNSS: usize = 4;
const TRUTH: usize = 5;

impl Suite {
    pub fn new(
        spec: &SensorsSpec,
        vehicle: &Vehicle,
        params: &Params,
        seed: u64,
        t_end: f64,
        dynamic: bool,
    ) -> Self {
        let clocks = [
            Some(Clock::new(spec.wheels.rate_hz, spec.wheels.offset_s)),
            spec.gyro
                .as_ref()
                .map(|g| Clock::new(g.rate_hz, g.offset_s)),
            spec.speed
                .as_ref()
                .map(|g| Clock::new(g.rate_hz, g.offset_s)),
            spec.steering
                .as_ref()
                .map(|g| Clock::new(g.rate_hz, g.offset_s)),
            spec.gnss
                .as_ref()
                .map(|g| Clock::new(g.rate_hz, g.offset_s)),
            Some(Clock::new(spec.truth_rate_hz, 0.0)),
        ];
        let noise = [1, 2, 3, 4, 5].map(|k| Noise::new(seed, k));
        let rings = (spec.wheels.tooth_error_std > 0.0).then(|| {
            ToneRings::draw(
                vehicle.ticks_per_rev,
                spec.wheels.tooth_error_std,
                &mut Noise::new(seed, 12),
            )
        });
        let ring_phase = {
            let mut n = Noise::new(seed, 15);
            [0; 4].map(|_| n.uniform())
        };
        let wheels = match spec.wheels.kind {
            WheelKind::Ticks => WheelState::Ticks {
                out: Vec::new(),
                // The edges already passed where each ring stands at the
                // start: the counters count from there.
                emitted: [0, 1, 2, 3].map(|i| edges_passed(rings.as_ref(), i, ring_phase[i])),
            },
            WheelKind::Speeds => WheelState::Speeds {
                out: Vec::new(),
                last_rot: [0.0; 4],
                last_t: None,
                last_jitter: [0.0; 4],
            },
        };
        Suite {
            spec: spec.clone(),
            t_end,
            circ: params.circumferences(),
            nominal_circ: vehicle.wheel_circumference_m,
            ticks_per_rev: f64::from(vehicle.ticks_per_rev),
            params: *params,
            steering_ratio: spec
                .steering
                .as_ref()
                .and_then(|g| g.true_ratio)
                .unwrap_or(vehicle.steering_ratio),
            wheelbase: vehicle.wheelbase_m,
            lever_arm: vehicle.gnss_lever_arm_m,
            clocks,
            noise,
            wheels,
            yaw_rate: Vec::new(),
            speed: Vec::new(),
            steering: Vec::new(),
            gnss: Vec::new(),
            gnss_state: GnssState::default(),
            truth: Vec::new(),
            imu_gyro: Vec::new(),
            imu_accel: Vec::new(),
            faults: spec
                .wheel_faults
                .clone()
                .map(|f| (WheelFaults::new(f), Noise::new(seed, 6))),
            dynamic,
            stamps: {
                let ecu = spec.ecu_clocks();
                let mut k = 0u64;
                [WHEELS, GYRO, SPEED, STEERING, GNSS].map(|stream| {
                    k += 1;
                    // Only streams present are in `ecu`; match them by key.
                    let key = [
                        "sensors.wheels",
                        "sensors.gyro",
                        "sensors.speed",
                        "sensors.steering",
                        "sensors.gnss",
                    ][stream];
                    ecu.iter()
                        .find(|(name, _, _)| *name == key)
                        .and_then(|(_, rate, c)| {
                            c.map(|c| EcuClock::new(*c, *rate, Noise::new(seed, 6 + k)))
                        })
                })
            },
            rings,
            ring_phase,
            gyro_drift: spec
                .gyro
                .as_ref()
                .filter(|g| g.bias_drift_std_rps > 0.0)
                .map(|g| {
                    GaussMarkov::new(
                        g.bias_drift_std_rps,
                        g.bias_drift_tau_s,
                        Noise::new(seed, 13),
                    )
                }),
            multipath: spec
                .gnss
                .as_ref()
                .and_then(|g| g.multipath.clone())
                .map(|m| Multipath::new(m, Noise::new(seed, 14))),
        }
    }

    /// Emits every sample due in (`a.t`, `b.t`] (and at or before `b.t` on the first call).
    pub fn sample(&mut self, kin: &Kinematics<'_>, a: &State, b: &State) {
        for stream in 0..self.clocks.len() {
            while let Some(t) = self.clocks[stream].as_ref().map(Clock::t) {
                if t > b.t || t > self.t_end {
                    break;
                }
                let st = kin.between(t, a, b);
                self.emit(stream, &st);
                if let Some(c) = &mut self.clocks[stream] {
                    c.i += 1;
                }
            }
        }
    }

    /// The stamp `stream` puts on the sample describing true time `t`.
    fn stamp(&mut self, stream: usize, t: f64) -> f64 {
        match self.stamps.get_mut(stream) {
            Some(Some(c)) => c.stamp(t),
            _ => t,
        }
    }

    fn emit(&mut self, stream: usize, st: &State) {
        let t_s = st.t;
        match stream {
            WHEELS => self.emit_wheels(st),
            GYRO => {
                let Some(g) = self.spec.gyro.clone() else {
                    return;
                };
                let t_s = self.stamp(GYRO, t_s) + g.latency_s;
                let k = 1.0 + g.scale_error;
                let bias = match &mut self.gyro_drift {
                    Some(d) => self.params.gyro_bias_rps + d.at(st.t),
                    None => self.params.gyro_bias_rps,
                };
                match g.tilt_deg {
                    None => {
                        let value = k * st.yaw_rate + bias + self.noise[GYRO].gauss(g.noise_std);
                        self.yaw_rate.push(Scalar { t_s, value });
                    }
                    Some([p, r]) => {
                        let m = tilt_rotation(p.to_radians(), r.to_radians());
                        let n = &mut self.noise[GYRO];
                        let w = [0, 1, 2].map(|i| {
                            k * m[i][2] * st.yaw_rate
                                + if i == 2 { bias } else { 0.0 }
                                + n.gauss(g.noise_std)
                        });
                        let f_v = if self.dynamic {
                            // M's acceleration (a along the course, v·χ̇
                            // across it) in the body frame, turned by β_r.
                            // The road's pitch tips gravity into x.
                            let (sb, cb) = st.beta.sin_cos();
                            let across = st.v * st.v * st.kappa;
                            let (sp, cp) = st.pitch_rad.sin_cos();
                            let g = deadreckon_core::imu::GRAVITY_MPS2;
                            [
                                st.a * cb - across * sb + g * sp,
                                st.a * sb + across * cb,
                                g * cp,
                            ]
                        } else {
                            [st.a, st.v * st.yaw_rate, deadreckon_core::imu::GRAVITY_MPS2]
                        };
                        let f = [0, 1, 2].map(|i| {
                            (0..3).map(|j| m[i][j] * f_v[j]).sum::<f64>()
                                + n.gauss(ACCEL_NOISE_STD_MPS2)
                        });
                        self.yaw_rate.push(Scalar { t_s, value: w[2] });
                        self.imu_gyro.push(Axes {
                            t_s,
                            x: w[0],
                            y: w[1],
                            z: w[2],
                        });
                        self.imu_accel.push(Axes {
                            t_s,
                            x: f[0],
                            y: f[1],
                            z: f[2],
                        });
                    }
                }
            }
            SPEED => {
                let (std, lat) = self
                    .spec
                    .speed
                    .as_ref()
                    .map_or((0.0, 0.0), |g| (g.noise_std, g.latency_s));
                let value = self.params.speed_scale * st.v + self.noise[SPEED].gauss(std);
                let t_s = self.stamp(SPEED, t_s) + lat;
                self.speed.push(Scalar { t_s, value });
            }
            STEERING => {
                let (std, offset, lat) = self.spec.steering.as_ref().map_or((0.0, 0.0, 0.0), |g| {
                    (g.noise_std, g.wheel_offset_rad, g.latency_s)
                });
                // The road-wheel angle's tangent: L·κ kinematically, with
                // the understeer under dynamics.
                let exact = if self.dynamic {
                    st.road_wheel_rad.tan()
                } else {
                    self.wheelbase * st.kappa
                };
                let tan = exact + self.noise[STEERING].gauss(std);
                let t_s = self.stamp(STEERING, t_s) + lat;
                self.steering.push(Scalar {
                    t_s,
                    value: self.steering_ratio * tan.atan() + offset,
                });
            }
            GNSS => self.emit_gnss(st),
            TRUTH => self.truth.push(TruthPose {
                t_s,
                east_m: st.x,
                north_m: st.y,
                yaw_rad: angle::wrap(st.psi),
                speed_mps: Some(st.v),
            }),
            _ => {}
        }
    }

    fn emit_wheels(&mut self, st: &State) {
        let counted = match &mut self.faults {
            Some((f, n)) => f.counted(st.t, st.a, st.wheel_m, || n.uniform()),
            None => st.wheel_m,
        };
        let mut rot = [0, 1, 2, 3].map(|i| counted[i] / self.circ[i]);
        let stamp = self.stamp(WHEELS, st.t);
        let n = self.ticks_per_rev;
        match &mut self.wheels {
            WheelState::Ticks { out, emitted } => {
                let mut d = [0i64; 4];
                for i in 0..4 {
                    // Cumulative edges passed from where the ring stood at
                    // the start: fractions of a tick carry over.
                    let cum = edges_passed(self.rings.as_ref(), i, rot[i] * n + self.ring_phase[i]);
                    d[i] = cum - emitted[i];
                    emitted[i] = cum;
                }
                out.push(WheelTicks {
                    t_s: stamp,
                    fl: d[0],
                    fr: d[1],
                    rl: d[2],
                    rr: d[3],
                });
            }
            WheelState::Speeds {
                out,
                last_rot,
                last_t,
                last_jitter,
            } => {
                if let Some(r) = &self.rings {
                    // The rotation the ECU infers from misplaced edges.
                    for (i, x) in rot.iter_mut().enumerate() {
                        *x = r.inferred(i, *x * n) / n;
                    }
                }
                let period = 1.0 / self.spec.wheels.rate_hz;
                let dt = last_t.map_or(period, |t0| st.t - t0);
                let (std, q) = (
                    self.spec.wheels.noise_std_mps,
                    self.spec.wheels.resolution_mps,
                );
                let jitter = self.spec.wheels.edge_jitter_m;
                let mut v = [0.0; 4];
                for i in 0..4 {
                    // Edge-timing error of the rotation counted at this sample.
                    let e = if jitter > 0.0 {
                        self.noise[WHEELS].gauss(jitter)
                    } else {
                        0.0
                    };
                    // The ECU's speed: rotation over the last period times the nominal circumference.
                    let raw = (rot[i] - last_rot[i]) * self.nominal_circ / dt
                        + (e - last_jitter[i]) / dt
                        + self.noise[WHEELS].gauss(std);
                    last_jitter[i] = e;
                    // A wheel at rest passes no edge: its speed reads 0, with
                    // neither jitter nor noise (the draws above are made all
                    // the same, so the noise of the moving samples does not
                    // depend on the stops).
                    let raw = if rot[i] == last_rot[i] { 0.0 } else { raw };
                    v[i] = if q > 0.0 { (raw / q).round() * q } else { raw };
                }
                *last_rot = rot;
                *last_t = Some(st.t);
                out.push(WheelSpeeds {
                    t_s: stamp,
                    fl_mps: v[0],
                    fr_mps: v[1],
                    rl_mps: v[2],
                    rr_mps: v[3],
                });
            }
        }
    }

    fn emit_gnss(&mut self, st: &State) {
        let Some(spec) = self.spec.gnss.clone() else {
            return;
        };
        let (sin, cos) = st.psi.sin_cos();
        let l = self.lever_arm;
        let n = &mut self.noise[GNSS];
        let gs = &mut self.gnss_state;
        let mut east_m = st.x + l * cos + n.gauss(spec.std_m);
        let mut north_m = st.y + l * sin + n.gauss(spec.std_m);
        if spec.markov_std_m > 0.0 {
            // First-order Gauss–Markov, stationary from the first fix.
            let (e, nn) = match gs.last_t {
                None => (n.gauss(spec.markov_std_m), n.gauss(spec.markov_std_m)),
                Some(t0) => {
                    let a = (-(st.t - t0) / spec.markov_tau_s).exp();
                    let q = spec.markov_std_m * (1.0 - a * a).sqrt();
                    (a * gs.markov.0 + n.gauss(q), a * gs.markov.1 + n.gauss(q))
                }
            };
            gs.markov = (e, nn);
            east_m += e;
            north_m += nn;
        }
        gs.last_t = Some(st.t);
        if let Some(m) = &mut self.multipath {
            let (e, nn) = m.at(st.t);
            east_m += e;
            north_m += nn;
        }
        let (mut course_deg, mut speed_mps) = (None, None);
        if let Some(vstd) = spec.velocity_std_mps {
            // Antenna velocity: v·(cos ψ, sin ψ) + l·ψ̇·(−sin ψ, cos ψ).
            // A body-yaw course is the direction the car faces: it does not
            // turn round when the car reverses.
            let (lat, fwd) = match spec.course_convention {
                CourseConvention::AntennaVelocity if self.dynamic => {
                    let (sb, cb) = st.beta.sin_cos();
                    (st.v * sb + l * st.yaw_rate, st.v * cb)
                }
                CourseConvention::AntennaVelocity => (l * st.yaw_rate, st.v),
                CourseConvention::BodyYaw => (0.0, st.v.abs()),
            };
            let ve = fwd * cos - lat * sin + n.gauss(vstd);
            let vn = fwd * sin + lat * cos + n.gauss(vstd);
            let sp = ve.hypot(vn);
            speed_mps = Some(sp);
            if sp >= spec.min_course_speed_mps {
                let c = yaw_rad_to_course_deg(vn.atan2(ve));
                gs.last_course_deg = Some(c);
                course_deg = Some(c);
            } else {
                course_deg = match spec.low_speed_course {
                    LowSpeedCourse::Dropped => None,
                    LowSpeedCourse::Random => Some(360.0 * n.uniform()),
                    LowSpeedCourse::Frozen => gs.last_course_deg,
                };
            }
        }
        let t_s = match &mut self.stamps[GNSS] {
            Some(c) => c.stamp(st.t),
            None => st.t,
        } + spec.latency_s;
        self.gnss.push(GnssFix {
            t_s,
            east_m,
            north_m,
            std_m: spec.std_m,
            course_deg,
            speed_mps,
        });
    }

    /// The multipath bursts simulated, `(start, end, east, north)` in s and m.
    pub fn multipath_bursts(&self) -> Vec<(f64, f64, f64, f64)> {
        self.multipath
            .as_ref()
            .map(|m| m.bursts.clone())
            .unwrap_or_default()
    }

    /// The tone rings' tooth errors per wheel (FL, FR, RL, RR), pitches.
    pub fn tooth_errors(&self) -> Option<[Vec<f64>; 4]> {
        self.rings
            .as_ref()
            .map(|r| [0, 1, 2, 3].map(|i| r.errors(i).to_vec()))
    }

    /// The spin bursts simulated, `(start, end)` in s.
    pub fn spin_bursts(&self) -> Vec<(f64, f64)> {
        self.faults
            .as_ref()
            .map(|(f, _)| f.bursts.clone())
            .unwrap_or_default()
    }

    /// The drive with every stream.
    pub fn finish(self, vehicle: Vehicle) -> Drive {
        let wheels = match self.wheels {
            WheelState::Ticks { out, .. } => Wheels::Ticks(out),
            WheelState::Speeds { out, .. } => Wheels::Speeds(out),
        };
        Drive {
            vehicle,
            wheels,
            yaw_rate: self.yaw_rate,
            speed: self.speed,
            steering: self.steering,
            gnss: self.gnss,
            truth: self.truth,
            imu: deadreckon_core::drive::Imu {
                gyro: self.imu_gyro,
                accel: self.imu_accel,
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Noise;
    use crate::{simulate, Scenario};
    use deadreckon_core::drive::Wheels;

    /// A 2 km straight at up to 50 km/h, 48-tooth ticks at 100 Hz sampled
    /// with the truth, tooth errors of `tooth_error_std` pitches.
    fn straight(tooth_error_std: f64) -> Scenario {
        Scenario::from_toml_str(&format!(
            "name = \"straight\"\nvehicle = \"paper-car\"\n\
             [route]\nstart_yaw_deg = 0.0\nsegments = [{{ kind = \"straight\", length_m = 2000 }}]\n\
             [speed]\nstart_stop_s = 2\nend_stop_s = 2\n\
             [sensors]\ntruth_rate_hz = 100\n\
             [sensors.wheels]\nkind = \"ticks\"\nrate_hz = 100\ntooth_error_std = {tooth_error_std}\n"
        ))
        .unwrap()
    }

    /// Per wheel (FL, FR, RL, RR), the mean of the counted rotation less the
    /// true one while the car moves, in pitches, and every count emitted.
    fn counted_less_true(scenario: &Scenario, seed: u64) -> ([f64; 4], Vec<[i64; 4]>) {
        let out = simulate(scenario, seed).unwrap();
        let Wheels::Ticks(ticks) = &out.drive.wheels else {
            panic!("ticks expected");
        };
        let n = f64::from(out.drive.vehicle.ticks_per_rev);
        let circ = out.truth_params.circumferences();
        let (mut sum, mut count, mut cum) = ([0.0; 4], 0usize, [0i64; 4]);
        let mut counts = Vec::new();
        // The wheel clock and the truth's tick at the same instants.
        for (w, p) in ticks.iter().zip(&out.drive.truth) {
            assert!((w.t_s - p.t_s).abs() < 1e-9, "{} vs {}", w.t_s, p.t_s);
            let d = [w.fl, w.fr, w.rl, w.rr];
            counts.push(d);
            for i in 0..4 {
                cum[i] += d[i];
            }
            if p.speed_mps.unwrap() > 1.0 {
                // On a straight every wheel rolls what M drives.
                let driven = p.east_m.hypot(p.north_m);
                for i in 0..4 {
                    sum[i] += cum[i] as f64 - driven / circ[i] * n;
                }
                count += 1;
            }
        }
        assert!(count > 10_000, "{count}");
        (sum.map(|s| s / count as f64), counts)
    }

    /// Over 40 wheels (10 drives) the counters' mean offset is 0 (±0.05 for
    /// 1σ of 40 uniform draws), not the −½ pitch of rings started at an edge.
    fn assert_zero_on_average(offsets: &[f64]) {
        assert_eq!(offsets.len(), 40);
        let mean = offsets.iter().sum::<f64>() / offsets.len() as f64;
        assert!(mean.abs() < 0.15, "{mean:+.3} pitch: {offsets:?}");
    }

    /// Regression: every simulated tick counter started standing exactly at
    /// a tone-ring edge, so through a whole drive the counted distance
    /// trailed the true one by half a pitch on average (2 cm on 48 teeth),
    /// on every wheel of every drive, and the GNSS delay read it as −5.7,
    /// −5.7 and −1.7 ms on the evaluation scenario's ticks at 25, 50 and
    /// 100 Hz. Now each ring stands at its own phase φ in [0, 1) pitch: a
    /// counter is φ − ½ pitch ahead on average, −½ to +½ from wheel to
    /// wheel, zero over wheels and drives.
    #[test]
    fn tick_counters_trailed_the_true_distance_by_half_a_pitch() {
        let even = straight(0.0);
        let mut all = Vec::new();
        for seed in 1..=10 {
            let (offsets, counts) = counted_less_true(&even, seed);
            let mut phase = Noise::new(seed, 15);
            for (i, m) in offsets.into_iter().enumerate() {
                // φ − ½: the ring's own phase, not a drift (its mean over
                // some 14 000 moving samples is within a few thousandths).
                let expected = phase.uniform() - 0.5;
                assert!(
                    (m - expected).abs() < 0.03,
                    "seed {seed} wheel {i}: {m:+.3} pitch, expected {expected:+.3}"
                );
                all.push(m);
            }
            // Standing at the start, no count.
            assert_eq!(counts[0], [0; 4], "seed {seed}");
        }
        // Some wheels count ahead, which none could before.
        assert_zero_on_average(&all);
        assert!(all.iter().any(|&m| m > 0.1), "{all:?}");
        assert!(all.iter().any(|&m| m < -0.1), "{all:?}");
    }

    /// With tooth errors the counters start at the misplaced edges already
    /// passed: a ring standing short of its edge 0, placed late, counts no
    /// −1 at the first sample (counted from 0, seed 8 did), and a forward
    /// drive counts nothing backwards.
    #[test]
    fn tick_counters_start_at_the_misplaced_edges_already_passed() {
        let rough = straight(0.1);
        let mut all = Vec::new();
        for seed in 1..=10 {
            let (offsets, counts) = counted_less_true(&rough, seed);
            assert_eq!(counts[0], [0; 4], "seed {seed}");
            assert!(
                counts.iter().flatten().all(|&d| d >= 0),
                "seed {seed}: a negative count"
            );
            all.extend(offsets);
        }
        assert_zero_on_average(&all);
    }
}
