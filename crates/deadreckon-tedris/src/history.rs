//! The recent wheel samples on the wheel clock, with the reference heading
//! synchronised onto them, and the formation of training blocks.
//!
//! Each wheel sample carries ω (right minus left rear wheel distance over the
//! sample, m), d (mean rear wheel distance, m) and, once synchronised, the
//! unwrapped reference heading θ (rad, counter-clockwise from east, of the
//! rear-axle centre). γ_j = θ_j − θ_{j−1} is defined where both are.

use std::collections::VecDeque;

use serde::{Deserialize, Serialize};

use crate::repository::Tuple;
use crate::stats::{mean, median};

/// One wheel sample.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Sample {
    /// Wheel sample index, counted from the first sample.
    pub idx: u64,
    /// Timestamp, s.
    pub t_s: f64,
    /// Time since the previous wheel sample, s (0 for the first sample).
    pub dt_s: f64,
    /// ω: right minus left rear wheel distance over the sample, m.
    pub omega_m: f64,
    /// d: mean rear wheel distance over the sample, m.
    pub dist_m: f64,
    /// Reference heading synchronised onto this sample, rad (unwrapped), when usable.
    pub theta_rad: Option<f64>,
    /// DR heading (before the anchor offset) after this sample, rad.
    pub theta_dr_rad: f64,
    /// The heading segment `theta_rad` belongs to: a continuous run of usable
    /// reference headings, never unwrapped across a gap, a stop, an unusable
    /// course or an outage. Heading fits give each segment its own intercept.
    #[serde(default)]
    pub segment: u32,
    /// The lever-arm angle atan(l·ψ̇/v) taken off the course to make
    /// `theta_rad` (0 for a gyro reference or a body-yaw course), rad.
    #[serde(default)]
    pub lever_rad: f64,
}

impl Sample {
    /// True when the wheels turned in this sample (more than 5 mm/s on
    /// average): the model turns the heading only then, as wheels do.
    pub fn moving(&self) -> bool {
        moving(self.omega_m, self.dist_m, self.dt_s)
    }
}

/// True when rear wheel distances (ω = right − left, d = mean) over `dt_s`
/// show motion: more than 5 mm/s at either wheel.
pub fn moving(omega_m: f64, dist_m: f64, dt_s: f64) -> bool {
    dist_m.abs() + 0.5 * omega_m.abs() > crate::tuning::STANDSTILL_SPEED_MPS * dt_s.max(1e-3)
}

/// Subtracts, in place, the mean of each column over the rows of each segment
/// (`segments[i]` is row i's segment): the least squares on the result equals
/// the one with an intercept per segment. Rows are in time order, so each
/// segment is one run of rows (segment numbers only grow). Returns the number
/// of segments.
pub fn centre_per_segment(rows: &mut [Vec<f64>], segments: &[u32]) -> usize {
    let mut runs = 0;
    let mut start = 0;
    while start < rows.len().min(segments.len()) {
        let end = start
            + segments[start..]
                .iter()
                .take_while(|&&g| g == segments[start])
                .count();
        let run = &mut rows[start..end];
        let n = run.len() as f64;
        let width = run[0].len();
        for c in 0..width {
            let mean = run.iter().map(|r| r[c]).sum::<f64>() / n;
            for r in run.iter_mut() {
                r[c] -= mean;
            }
        }
        runs += 1;
        start = end;
    }
    runs
}

/// The RMS of `values` about the mean of each segment's run (as
/// [`centre_per_segment`] on one column); NaN without values.
pub fn rms_about_segment_means(values: &[f64], segments: &[u32]) -> f64 {
    let mut sum_sq = 0.0;
    let mut start = 0;
    while start < values.len().min(segments.len()) {
        let end = start
            + segments[start..]
                .iter()
                .take_while(|&&g| g == segments[start])
                .count();
        let run = &values[start..end];
        let mean = run.iter().sum::<f64>() / run.len() as f64;
        sum_sq += run.iter().map(|v| (v - mean).powi(2)).sum::<f64>();
        start = end;
    }
    (sum_sq / values.len() as f64).sqrt()
}

/// A window of samples with contiguous indices, the last `span_s` seconds.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct History {
    samples: VecDeque<Sample>,
    span_s: f64,
}

impl History {
    /// An empty history keeping the samples of the last `span_s` seconds.
    pub fn new(span_s: f64) -> Self {
        History {
            samples: VecDeque::new(),
            span_s,
        }
    }

    /// Appends a sample (its index must follow the last one) and drops the
    /// samples older than the span.
    pub fn push(&mut self, s: Sample) {
        let newest = s.t_s;
        self.samples.push_back(s);
        while self
            .samples
            .front()
            .is_some_and(|f| newest - f.t_s > self.span_s)
        {
            self.samples.pop_front();
        }
    }

    /// The sample of index `idx`, if still held.
    pub fn get(&self, idx: u64) -> Option<&Sample> {
        let first = self.samples.front()?.idx;
        self.samples
            .get(usize::try_from(idx.checked_sub(first)?).ok()?)
    }

    /// Mutable access to the sample of index `idx`.
    pub fn get_mut(&mut self, idx: u64) -> Option<&mut Sample> {
        let first = self.samples.front()?.idx;
        self.samples
            .get_mut(usize::try_from(idx.checked_sub(first)?).ok()?)
    }

    /// γ_idx = θ_idx − θ_{idx−1}, rad per sample.
    pub fn gamma(&self, idx: u64) -> Option<f64> {
        let a = self.get(idx)?.theta_rad?;
        let b = self.get(idx.checked_sub(1)?)?.theta_rad?;
        Some(a - b)
    }

    /// Index of the first and last samples held.
    pub fn span(&self) -> Option<(u64, u64)> {
        Some((self.samples.front()?.idx, self.samples.back()?.idx))
    }

    /// The samples, oldest first.
    pub fn iter(&self) -> impl DoubleEndedIterator<Item = &Sample> + '_ {
        self.samples.iter()
    }

    /// Number of samples held.
    pub fn len(&self) -> usize {
        self.samples.len()
    }

    /// True when no sample is held.
    pub fn is_empty(&self) -> bool {
        self.samples.is_empty()
    }

    /// The time kept, s.
    pub fn span_s(&self) -> f64 {
        self.span_s
    }

    /// True when the samples held cover the whole span (the oldest are
    /// being dropped).
    pub fn full(&self) -> bool {
        match (self.samples.front(), self.samples.back()) {
            (Some(a), Some(b)) => b.t_s - a.t_s >= self.span_s - b.dt_s.max(0.0),
            _ => false,
        }
    }

    /// The last sample.
    pub fn last(&self) -> Option<&Sample> {
        self.samples.back()
    }

    /// Number of samples with a defined γ.
    pub fn gamma_count(&self) -> usize {
        self.samples
            .iter()
            .zip(self.samples.iter().skip(1))
            .filter(|(a, b)| a.theta_rad.is_some() && b.theta_rad.is_some())
            .count()
    }
}

/// Forms training blocks of τ lag-aligned samples from a history, incrementally.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BlockFormer {
    /// τ.
    pub tau: usize,
    /// h: γ_j is paired with ω_{j−h}.
    pub lag: i64,
    /// Samples over which the straight-line detector measures the heading change.
    pub slt_window: u64,
    /// Largest heading change over that window on a straight line, rad.
    pub slt_max_change_rad: f64,
    /// Block means (cumulative increments over τ) instead of medians: for
    /// quantised wheel ticks ([`crate::blocks`]).
    #[serde(default)]
    pub mean: bool,
    next: u64,
    last: Option<(u64, f64, f64)>,
}

impl BlockFormer {
    /// A former starting at sample `start`.
    pub fn new(tau: usize, lag: i64, slt_window: u64, slt_max_change_rad: f64, start: u64) -> Self {
        BlockFormer {
            tau: tau.max(1),
            lag,
            slt_window: slt_window.max(1),
            slt_max_change_rad,
            mean: false,
            next: start,
            last: None,
        }
    }

    /// Forms every block whose samples up to `final_upto` are synchronised.
    pub fn form(&mut self, h: &History, final_upto: u64) -> Vec<Tuple> {
        let mut out = Vec::new();
        let Some((first, newest)) = h.span() else {
            return out;
        };
        let tau = self.tau as u64;
        let min_start = (first as i64 + 1 + self.lag.max(0)) as u64;
        if self.next < min_start {
            self.next = min_start;
            self.last = None;
        }
        loop {
            let end = self.next + tau - 1;
            if end > final_upto || end as i64 - self.lag > newest as i64 {
                break;
            }
            let mut w = Vec::with_capacity(self.tau);
            let mut d = Vec::with_capacity(self.tau);
            let mut g = Vec::with_capacity(self.tau);
            let mut bad = None;
            for j in self.next..=end {
                let src = h.get((j as i64 - self.lag) as u64);
                match (h.gamma(j), src) {
                    (Some(gj), Some(s)) => {
                        g.push(gj);
                        w.push(s.omega_m);
                        d.push(s.dist_m);
                    }
                    _ => bad = Some(j),
                }
            }
            if let Some(j) = bad {
                self.next = j + 1;
                self.last = None;
                continue;
            }
            let (wm, dm, gm) = if self.mean {
                (mean(&w), mean(&d), mean(&g))
            } else {
                (median(&w), median(&d), median(&g))
            };
            let straight = match (
                h.get(end).and_then(|s| s.theta_rad),
                end.checked_sub(self.slt_window)
                    .and_then(|i| h.get(i))
                    .and_then(|s| s.theta_rad),
            ) {
                (Some(a), Some(b)) => (a - b).abs() <= self.slt_max_change_rad,
                _ => false,
            };
            let prev = self
                .last
                .filter(|l| l.0 + 1 == self.next)
                .map(|l| (l.1, l.2));
            out.push(Tuple {
                seq: self.next,
                omega_m: wm,
                dist_m: dm,
                gamma_rad: gm,
                prev,
                straight,
            });
            self.last = Some((end, wm, gm));
            self.next = end + 1;
        }
        out
    }
}

/// `corr(ω_{j−h}, γ_j)` over the samples of a history where γ is defined, for
/// `h ∈ −max_lag ..= max_lag`.
pub fn masked_ccf(h: &History, max_lag: usize) -> crate::ccf::CrossCorrelation {
    let mut lags = Vec::new();
    let mut values = Vec::new();
    let Some((first, last)) = h.span() else {
        return crate::ccf::CrossCorrelation { lags, values };
    };
    let ml = max_lag as i64;
    for lag in -ml..=ml {
        let (mut n, mut sw, mut sg, mut sww, mut sgg, mut swg) =
            (0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for j in first..=last {
            let src = j as i64 - lag;
            if src < first as i64 || src > last as i64 {
                continue;
            }
            if let (Some(g), Some(s)) = (h.gamma(j), h.get(src as u64)) {
                let w = s.omega_m;
                n += 1.0;
                sw += w;
                sg += g;
                sww += w * w;
                sgg += g * g;
                swg += w * g;
            }
        }
        let cov = swg - sw * sg / n.max(1.0);
        let vw = sww - sw * sw / n.max(1.0);
        let vg = sgg - sg * sg / n.max(1.0);
        lags.push(lag);
        values.push(if n > 2.0 && vw > 0.0 && vg > 0.0 {
            cov / (vw * vg).sqrt()
        } else {
            0.0
        });
    }
    crate::ccf::CrossCorrelation { lags, values }
}

#[cfg(test)]
mod segment_tests {
    use super::*;

    #[test]
    fn each_segment_run_is_centred_on_its_own_mean() {
        let mut rows = vec![
            vec![1.0, 10.0],
            vec![3.0, 30.0],
            vec![5.0, 0.0],
            vec![7.0, 4.0],
        ];
        let segs = [1, 1, 4, 4];
        assert_eq!(centre_per_segment(&mut rows, &segs), 2);
        assert_eq!(
            rows,
            vec![
                vec![-1.0, -10.0],
                vec![1.0, 10.0],
                vec![-1.0, -2.0],
                vec![1.0, 2.0]
            ]
        );
        // The same about-the-mean residuals, as an RMS: (1 + 1 + 1 + 1) / 4.
        let rms = rms_about_segment_means(&[1.0, 3.0, 5.0, 7.0], &segs);
        assert!((rms - 1.0).abs() < 1e-15, "{rms}");
        // One segment: the plain standard deviation about the mean.
        let rms = rms_about_segment_means(&[1.0, 3.0, 5.0, 7.0], &[2, 2, 2, 2]);
        assert!((rms - 5.0f64.sqrt()).abs() < 1e-15, "{rms}");
    }
}
