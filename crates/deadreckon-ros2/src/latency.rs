//! Per-message latency through the node: from the message's receipt (taken
//! from its subscription) to the publication of the first Odometry after it
//! was given to the filter. It includes the reorder window's wait.

use std::time::{Duration, Instant};

/// Receipts waiting for a publication, and the latencies measured.
#[derive(Debug, Clone, Default)]
pub struct Latency {
    waiting: Vec<Instant>,
    measured_s: Vec<f64>,
}

/// The latencies' summary, s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LatencySummary {
    /// Messages measured.
    pub count: usize,
    /// Median, s.
    pub median_s: f64,
    /// 99th percentile, s.
    pub p99_s: f64,
    /// Largest, s.
    pub max_s: f64,
}

impl std::fmt::Display for LatencySummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "latency (receipt to publication) over {} messages: median {:.2} ms, p99 {:.2} ms, max {:.2} ms",
            self.count,
            1e3 * self.median_s,
            1e3 * self.p99_s,
            1e3 * self.max_s
        )
    }
}

impl Latency {
    /// A message received at `at` was given to the filter.
    pub fn fed(&mut self, at: Instant) {
        self.waiting.push(at);
    }

    /// A pose was published at `now`: every message fed since the last
    /// publication is measured.
    pub fn published(&mut self, now: Instant) {
        for at in self.waiting.drain(..) {
            self.measured_s
                .push(now.saturating_duration_since(at).as_secs_f64());
        }
    }

    /// Messages fed since the last publication (none published after them yet).
    pub fn unpublished(&self) -> usize {
        self.waiting.len()
    }

    /// The summary (`None` before the first measurement).
    pub fn summary(&self) -> Option<LatencySummary> {
        if self.measured_s.is_empty() {
            return None;
        }
        let mut v = self.measured_s.clone();
        v.sort_by(f64::total_cmp);
        Some(LatencySummary {
            count: v.len(),
            median_s: deadreckon_core::metrics::quantile(&v, 0.5),
            p99_s: deadreckon_core::metrics::quantile(&v, 0.99),
            max_s: v[v.len() - 1],
        })
    }
}

/// A duration in seconds from an option's value.
pub(crate) fn seconds(s: f64) -> Duration {
    Duration::from_secs_f64(s.max(0.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_message_is_measured_at_the_first_publication_after_it() {
        let t0 = Instant::now();
        let mut l = Latency::default();
        l.fed(t0);
        l.fed(t0 + Duration::from_millis(10));
        l.published(t0 + Duration::from_millis(30));
        l.fed(t0 + Duration::from_millis(40));
        assert_eq!(l.unpublished(), 1);
        l.published(t0 + Duration::from_millis(41));
        let s = l.summary().unwrap();
        assert_eq!(s.count, 3);
        // 30, 20 and 1 ms: the median is 20 ms, the largest 30 ms.
        assert!((s.median_s - 0.020).abs() < 1e-9, "{s}");
        assert!((s.max_s - 0.030).abs() < 1e-9, "{s}");
        assert!(s.p99_s <= s.max_s && s.p99_s > s.median_s);
    }
}
