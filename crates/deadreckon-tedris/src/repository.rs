//! The training repositories: tuples (median ω, median d, median γ) of blocks of
//! τ samples, binned by median ω around the straight-line band `[W_L, W_H]`
//! (section 3.1 of the paper).
//!
//! Bin of a block median ω (ε = k·(W_H − W_L)):
//! - R0 for ω ∈ [W_L, W_H];
//! - Rn, n ≥ 1, for ω ∈ (W_H + (n − 1)ε, W_H + nε], i.e. n = ⌈(ω − W_H)/ε⌉;
//! - Rn, n ≤ −1, for ω ∈ [W_L + nε, W_L + (n + 1)ε), i.e. n = ⌊(ω − W_L)/ε⌋;
//! - everything in R0 when ε = ∞ (the paper's robot).

use std::collections::{BTreeMap, VecDeque};

use serde::{Deserialize, Serialize};

/// One training tuple: the medians of a block of τ lag-aligned samples.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Tuple {
    /// Index of the first wheel sample of the block (orders tuples in time).
    pub seq: u64,
    /// Median of ω over the block (lagged by h), m per sample.
    pub omega_m: f64,
    /// Median of the distance travelled per sample over the block, m.
    pub dist_m: f64,
    /// Median of γ over the block, rad per sample.
    pub gamma_rad: f64,
    /// (median ω, median γ) of the block just before, when it is contiguous (for ARX).
    pub prev: Option<(f64, f64)>,
    /// The block lies on a straight line (straight-line detector).
    pub straight: bool,
}

/// The straight-line parameters of the paper (figure 2), in ω units (m per sample).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct StraightLine {
    /// µ: mean of the block medians of ω on straight lines.
    pub mu_m: f64,
    /// W_L: smallest block median of ω on straight lines.
    pub w_low_m: f64,
    /// W_H: largest block median of ω on straight lines.
    pub w_high_m: f64,
    /// ε = k·(W_H − W_L); `None` is ε = ∞ (one repository).
    pub epsilon_m: Option<f64>,
    /// Number of straight-line blocks the values come from.
    pub blocks: usize,
    /// True when no straight line was found and the quietest blocks stood in for one.
    pub fallback: bool,
}

impl StraightLine {
    /// Computes µ, W_L, W_H, ε from the ω medians of straight blocks.
    /// Returns `None` for an empty set.
    pub fn from_omegas(
        omegas: &[f64],
        epsilon_factor: Option<f64>,
        fallback: bool,
    ) -> Option<Self> {
        if omegas.is_empty() {
            return None;
        }
        let lo = omegas.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = omegas.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let width = (hi - lo).max(1e-9);
        Some(StraightLine {
            mu_m: crate::stats::mean(omegas),
            w_low_m: lo,
            w_high_m: hi,
            epsilon_m: epsilon_factor.map(|k| k * width),
            blocks: omegas.len(),
            fallback,
        })
    }

    /// The repository index of a block median ω (`None` when ω is not finite).
    pub fn bin(&self, omega_m: f64) -> Option<i32> {
        if !omega_m.is_finite() {
            return None;
        }
        let Some(eps) = self.epsilon_m else {
            return Some(0);
        };
        let n = if omega_m > self.w_high_m {
            ((omega_m - self.w_high_m) / eps).ceil()
        } else if omega_m < self.w_low_m {
            ((omega_m - self.w_low_m) / eps).floor()
        } else {
            0.0
        };
        Some(n.clamp(-10_000.0, 10_000.0) as i32)
    }

    /// The ω interval of repository `n`, m per sample (infinite for ε = ∞).
    pub fn interval(&self, n: i32) -> (f64, f64) {
        let Some(eps) = self.epsilon_m else {
            return (f64::NEG_INFINITY, f64::INFINITY);
        };
        let n_f = f64::from(n);
        match n {
            0 => (self.w_low_m, self.w_high_m),
            n if n > 0 => (self.w_high_m + (n_f - 1.0) * eps, self.w_high_m + n_f * eps),
            _ => (self.w_low_m + n_f * eps, self.w_low_m + (n_f + 1.0) * eps),
        }
    }
}

/// The repositories R_n with their fill limits.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Repositories {
    /// The binning.
    pub straight: StraightLine,
    /// Tuples of each repository, oldest first.
    pub bins: BTreeMap<i32, VecDeque<Tuple>>,
    /// Minimum fill of a required repository.
    pub min_fill: usize,
    /// Maximum fill of any repository.
    pub max_fill: usize,
}

/// Fill of one repository, for reports.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Fill {
    /// Repository index n.
    pub index: i32,
    /// Lower ω bound, m per sample.
    pub low_m: f64,
    /// Upper ω bound, m per sample.
    pub high_m: f64,
    /// Tuples stored.
    pub tuples: usize,
    /// At least `min_fill` tuples.
    pub filled: bool,
}

impl Repositories {
    /// Empty repositories for a binning.
    pub fn new(straight: StraightLine, min_fill: usize, max_fill: usize) -> Self {
        Repositories {
            straight,
            bins: BTreeMap::new(),
            min_fill,
            max_fill,
        }
    }

    /// Stores a tuple in its repository, dropping the oldest beyond `max_fill`.
    pub fn insert(&mut self, t: Tuple) {
        let Some(n) = self.straight.bin(t.omega_m) else {
            return;
        };
        let q = self.bins.entry(n).or_default();
        q.push_back(t);
        while q.len() > self.max_fill {
            q.pop_front();
        }
    }

    /// True when every repository R−required … R+required holds `min_fill` tuples
    /// (only R0 when ε = ∞).
    pub fn complete(&self, required: i32) -> bool {
        let r = if self.straight.epsilon_m.is_none() {
            0
        } else {
            required
        };
        (-r..=r).all(|n| self.bins.get(&n).is_some_and(|q| q.len() >= self.min_fill))
    }

    /// The fill of every non-empty repository and of the required ones.
    pub fn fill(&self, required: i32) -> Vec<Fill> {
        let r = if self.straight.epsilon_m.is_none() {
            0
        } else {
            required
        };
        let mut idx: Vec<i32> = self.bins.keys().copied().collect();
        idx.extend(-r..=r);
        idx.sort_unstable();
        idx.dedup();
        idx.into_iter()
            .map(|n| {
                let tuples = self.bins.get(&n).map_or(0, VecDeque::len);
                let (low_m, high_m) = self.straight.interval(n);
                Fill {
                    index: n,
                    low_m,
                    high_m,
                    tuples,
                    filled: tuples >= self.min_fill,
                }
            })
            .collect()
    }

    /// All tuples in time order.
    pub fn all_sorted(&self) -> Vec<Tuple> {
        let mut v: Vec<Tuple> = self.bins.values().flatten().copied().collect();
        v.sort_by_key(|t| t.seq);
        v
    }

    /// Total number of tuples.
    pub fn len(&self) -> usize {
        self.bins.values().map(VecDeque::len).sum()
    }

    /// True when no tuple is stored.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn binning_follows_the_paper() {
        // The paper's car: W_L = −0.0581, W_H = −0.01, ε = 1.5 (W_H − W_L) = 0.07215.
        let s = StraightLine::from_omegas(&[-0.0581, -0.01, -0.0352], Some(1.5), false).unwrap();
        assert!((s.epsilon_m.unwrap() - 0.07215).abs() < 1e-12);
        assert_eq!(s.bin(-0.03), Some(0));
        assert_eq!(s.bin(-0.01), Some(0));
        assert_eq!(s.bin(0.0), Some(1));
        assert_eq!(s.bin(-0.01 + 0.0721), Some(1));
        assert_eq!(s.bin(-0.01 + 0.0722), Some(2));
        assert_eq!(s.bin(-0.06), Some(-1));
        assert_eq!(s.bin(-0.0581 - 0.07215 - 1e-6), Some(-2));
        assert_eq!(s.bin(f64::NAN), None);
        for n in -3..=3 {
            let (lo, hi) = s.interval(n);
            let mid = 0.5 * (lo + hi);
            assert_eq!(s.bin(mid), Some(n));
        }
        let inf = StraightLine::from_omegas(&[0.0, 1.0], None, false).unwrap();
        assert_eq!(inf.bin(100.0), Some(0));
    }

    #[test]
    fn fill_limits() {
        let s = StraightLine::from_omegas(&[-0.01, 0.01], Some(1.5), false).unwrap();
        let mut r = Repositories::new(s, 3, 5);
        for i in 0..10 {
            r.insert(Tuple {
                seq: i,
                omega_m: 0.0,
                dist_m: 0.1,
                gamma_rad: 0.0,
                prev: None,
                straight: true,
            });
        }
        assert_eq!(r.bins[&0].len(), 5);
        assert_eq!(r.bins[&0][0].seq, 5);
        assert!(r.complete(0));
        assert!(!r.complete(1));
        for i in 0..3 {
            r.insert(Tuple {
                seq: 20 + i,
                omega_m: 0.02,
                dist_m: 0.1,
                gamma_rad: 0.0,
                prev: None,
                straight: false,
            });
            r.insert(Tuple {
                seq: 30 + i,
                omega_m: -0.02,
                dist_m: 0.1,
                gamma_rad: 0.0,
                prev: None,
                straight: false,
            });
        }
        assert!(r.complete(1));
        assert_eq!(r.fill(2).len(), 5);
    }
}
