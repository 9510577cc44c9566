//! Per-message latency through the node: from the message's receipt (taken
//! from its subscription) to the publication of the first Odometry after it
//! was given to the filter. It includes the reorder window's wait and, for a
//! reading between wheel epochs, the wait for the next epoch. Messages received
//! before the first publication wait for the filter's GNSS start (the vehicle
//! has to move 10 m): they are summarised apart.

use std::time::{Duration, Instant};

/// Receipts waiting for a publication, and the latencies measured.
#[derive(Debug, Clone, Default)]
pub struct Latency {
    waiting: Vec<Instant>,
    first_publication: Option<Instant>,
    startup_s: Vec<f64>,
    measured_s: Vec<f64>,
}

/// The latencies' summary, s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LatencySummary {
    /// Messages received before the first publication (held until the
    /// filter's start).
    pub startup_count: usize,
    /// The largest latency among those, s.
    pub startup_max_s: f64,
    /// Messages measured, received after the first publication.
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
            "latency (receipt to publication) over {} messages: median {:.2} ms, p99 {:.2} ms, max {:.2} ms; {} messages before the filter's start, up to {:.2} s",
            self.count,
            1e3 * self.median_s,
            1e3 * self.p99_s,
            1e3 * self.max_s,
            self.startup_count,
            self.startup_max_s
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
        let first = *self.first_publication.get_or_insert(now);
        for at in self.waiting.drain(..) {
            let s = now.saturating_duration_since(at).as_secs_f64();
            if at < first {
                self.startup_s.push(s);
            } else {
                self.measured_s.push(s);
            }
        }
    }

    /// Messages fed since the last publication (none published after them yet).
    pub fn unpublished(&self) -> usize {
        self.waiting.len()
    }

    /// The summary (`None` before a message received after the first
    /// publication was measured).
    pub fn summary(&self) -> Option<LatencySummary> {
        if self.measured_s.is_empty() {
            return None;
        }
        let mut v = self.measured_s.clone();
        v.sort_by(f64::total_cmp);
        Some(LatencySummary {
            startup_count: self.startup_s.len(),
            startup_max_s: self.startup_s.iter().copied().fold(0.0, f64::max),
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
        let ms = Duration::from_millis;
        let t0 = Instant::now();
        let mut l = Latency::default();
        // Held until the start: 2 s.
        l.fed(t0);
        l.published(t0 + ms(2000));
        assert!(
            l.summary().is_none(),
            "nothing received after the start yet"
        );
        l.fed(t0 + ms(2010));
        l.fed(t0 + ms(2020));
        l.published(t0 + ms(2040));
        l.fed(t0 + ms(2050));
        assert_eq!(l.unpublished(), 1);
        l.published(t0 + ms(2051));
        let s = l.summary().unwrap();
        assert_eq!((s.startup_count, s.count), (1, 3));
        assert!((s.startup_max_s - 2.0).abs() < 1e-9, "{s}");
        // 30, 20 and 1 ms: the median is 20 ms, the largest 30 ms.
        assert!((s.median_s - 0.020).abs() < 1e-9, "{s}");
        assert!((s.max_s - 0.030).abs() < 1e-9, "{s}");
        assert!(s.p99_s <= s.max_s && s.p99_s > s.median_s);
    }
}
