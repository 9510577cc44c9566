//! What the receiver's slow error leaves in a calibrated distance scale.
//!
//! The RTS calibration's least squares (eq. 23–26) fit the wheels against the
//! smoothed states, which the wheels themselves dominate: their standard
//! errors say how well the wheels agree with the smoothed speed, not how well
//! the GNSS fixed the distance scale. With a receiver whose error wanders
//! (multipath, ionosphere, SBAS: a metre over a minute or two) the scale is
//! off by that wander over the distance the calibration could average it
//! over. On the simulator's car family (600 s drives) the circumferences were
//! 1–5 mm off, all four alike, where the least squares claimed 0.02–0.1 mm.
//!
//! Here the scale is checked against GNSS chords instead: the drive is cut
//! into blocks of [`BLOCK_S`]; in each, the fixes' displacement (the mean
//! fix over [`END_S`] at either end, lever arm removed) is compared with the
//! displacement dead-reckoned from the smoothed speed and yaw. Each block's
//! relative scale residual `rᵢ = (m·D)/|D|²` (m the fixes' displacement less
//! the dead-reckoned one, D the dead-reckoned one) is one independent look at
//! the distance scale, and the scatter of those looks is the scale's
//! uncertainty: the standard error of their mean, weighted by `|D|²`
//! (sandwich form). White fixes scatter little; a wandering receiver
//! scatters by its wander over a block.

use statrs::distribution::{ContinuousCDF, StudentsT};

use crate::drive::Drive;
use crate::model::{V, YAW};
use crate::reference::Reference;

/// Length of a chord block, s: about the correlation time of a receiver's
/// wander (20–120 s), so that neighbouring blocks are nearly independent
/// looks at it.
pub const BLOCK_S: f64 = 60.0;
/// Fixes averaged at each end of a block: those within this many seconds of
/// the end, s.
pub const END_S: f64 = 1.0;
/// Shortest dead-reckoned displacement of a block that is used, m.
pub const MIN_CHORD_M: f64 = 100.0;
/// Fewest blocks that give a scale error.
pub const MIN_BLOCKS: usize = 3;
/// A calibration is rejected when its chords' mean residual is both
/// significant at this level (two-sided, Student's t with one degree of
/// freedom fewer than the blocks) and larger than [`REJECT_MIN_REL`]: the
/// distance scale it found is not the GNSS's.
pub const REJECT_LEVEL: f64 = 0.001;
/// The smallest relative disagreement with the chords that rejects a
/// calibration: 1 %, what a tyre's pressure or wear moves its rolling
/// radius by. Below it the disagreement is in the widened standard errors.
/// (A 300 s drive of the built-in calibration scenario, its front-left tyre
/// new, read +0.08 % ± 0.02 % over 4 blocks: real, and harmless.)
pub const REJECT_MIN_REL: f64 = 0.01;

/// The GNSS chords' verdict on a distance scale.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ChordScale {
    /// Weighted mean relative scale residual (GNSS over dead reckoning, − 1).
    pub mean: f64,
    /// Its standard error: the relative standard error of the distance scale.
    pub std: f64,
    /// Blocks used.
    pub blocks: usize,
}

/// The chords of `drive`'s fixes against the dead reckoning of `smoothed`
/// (speed and yaw integrated); `None` with fewer than [`MIN_BLOCKS`] usable
/// blocks.
pub fn chord_scale(drive: &Drive, smoothed: &Reference) -> Option<ChordScale> {
    let (t, x) = (&smoothed.t, &smoothed.x);
    if t.len() < 2 {
        return None;
    }
    // The dead-reckoned track: the smoothed speed along the smoothed yaw.
    let mut dr = Vec::with_capacity(t.len());
    let (mut e, mut n) = (0.0, 0.0);
    dr.push((e, n));
    for k in 1..t.len() {
        let dt = t[k] - t[k - 1];
        let v = 0.5 * (x[k - 1][V] + x[k][V]);
        let yaw = 0.5 * (x[k - 1][YAW] + x[k][YAW]);
        e += v * dt * yaw.cos();
        n += v * dt * yaw.sin();
        dr.push((e, n));
    }
    let dr_at = |ts: f64| -> Option<(f64, f64)> {
        let k = t.partition_point(|&s| s <= ts);
        if k == 0 || k >= t.len() {
            return None;
        }
        let f = (ts - t[k - 1]) / (t[k] - t[k - 1]);
        let (a, b) = (dr[k - 1], dr[k]);
        Some((a.0 + f * (b.0 - a.0), a.1 + f * (b.1 - a.1)))
    };
    let lever = drive.vehicle.gnss_lever_arm_m;
    // Mean (fix at the rear axle − dead reckoning) and mean dead reckoning
    // over the fixes within END_S of `at`.
    let end = |at: f64| -> Option<((f64, f64), (f64, f64))> {
        let i = drive.gnss.partition_point(|g| g.t_s < at - END_S);
        let (mut m, mut d, mut k) = ((0.0, 0.0), (0.0, 0.0), 0.0);
        for g in drive.gnss[i..].iter().take_while(|g| g.t_s <= at + END_S) {
            let (Some(s), Some(p)) = (smoothed.state_at(g.t_s), dr_at(g.t_s)) else {
                continue;
            };
            let rear = (
                g.east_m - lever * s[YAW].cos(),
                g.north_m - lever * s[YAW].sin(),
            );
            m.0 += rear.0 - p.0;
            m.1 += rear.1 - p.1;
            d.0 += p.0;
            d.1 += p.1;
            k += 1.0;
        }
        (k > 0.0).then(|| ((m.0 / k, m.1 / k), (d.0 / k, d.1 / k)))
    };
    let (t0, t1) = (t[0], t[t.len() - 1]);
    let mut looks: Vec<(f64, f64)> = Vec::new(); // (rᵢ, wᵢ = |D|²)
    let mut a = t0 + END_S;
    while a + BLOCK_S <= t1 - END_S {
        let b = a + BLOCK_S;
        if let (Some((ma, da)), Some((mb, db))) = (end(a), end(b)) {
            let d = (db.0 - da.0, db.1 - da.1);
            let dd = d.0 * d.0 + d.1 * d.1;
            if dd >= MIN_CHORD_M * MIN_CHORD_M {
                let m = (mb.0 - ma.0, mb.1 - ma.1);
                looks.push(((m.0 * d.0 + m.1 * d.1) / dd, dd));
            }
        }
        a = b;
    }
    let g = looks.len();
    if g < MIN_BLOCKS {
        return None;
    }
    let sw: f64 = looks.iter().map(|l| l.1).sum();
    let mean = looks.iter().map(|l| l.0 * l.1).sum::<f64>() / sw;
    let s2: f64 = looks.iter().map(|l| (l.1 * (l.0 - mean)).powi(2)).sum();
    let std = (s2 * g as f64 / (g as f64 - 1.0)).sqrt() / sw;
    Some(ChordScale {
        mean,
        std,
        blocks: g,
    })
}

impl ChordScale {
    /// The mean residual in standard errors.
    pub fn sigmas(&self) -> f64 {
        if self.std > 0.0 {
            self.mean / self.std
        } else {
            0.0
        }
    }
    /// The two-sided p-value of the mean residual against 0 (Student's t
    /// with `blocks − 1` degrees of freedom).
    pub fn p_value(&self) -> f64 {
        let dof = self.blocks.saturating_sub(1).max(1) as f64;
        match StudentsT::new(0.0, 1.0, dof) {
            Ok(t) => 2.0 * (1.0 - t.cdf(self.sigmas().abs())),
            Err(_) => 1.0,
        }
    }
    /// True when the scale disagrees with the chords: by more than
    /// [`REJECT_MIN_REL`], at the level [`REJECT_LEVEL`].
    pub fn disagrees(&self) -> bool {
        self.mean.abs() > REJECT_MIN_REL && self.p_value() < REJECT_LEVEL
    }
}
