//! Building a stream sample by sample under the time-order policy.

use std::path::{Path, PathBuf};

use crate::{ImportError, StreamReport};

/// What to do with a sample whose time is not strictly after the previous kept
/// sample, or whose value is non-finite or implausible.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TimeOrderPolicy {
    /// Stop with an [`ImportError::Stream`] naming the sample (the default).
    #[default]
    Error,
    /// Drop the sample and count it in the [`crate::ImportReport`].
    Gate,
}

/// Why a sample is refused.
pub(crate) enum Reject {
    /// Its time is not after the previous kept sample's.
    TimeOrder,
    /// A value is non-finite or implausible.
    Invalid(String),
}

/// Accumulates the samples of one stream, enforcing strictly increasing finite
/// times and counting what the policy gates.
pub(crate) struct StreamBuilder<T> {
    name: &'static str,
    path: PathBuf,
    policy: TimeOrderPolicy,
    samples: Vec<T>,
    last_t: f64,
    gated_time_order: usize,
    gated_invalid: usize,
}

impl<T> StreamBuilder<T> {
    pub(crate) fn new(name: &'static str, path: &Path, policy: TimeOrderPolicy) -> Self {
        StreamBuilder {
            name,
            path: path.to_path_buf(),
            policy,
            samples: Vec::new(),
            last_t: f64::NEG_INFINITY,
            gated_time_order: 0,
            gated_invalid: 0,
        }
    }

    /// Offers sample `index` of the source at time `t_s` whose values are
    /// `values` (all must be finite).
    pub(crate) fn push(
        &mut self,
        index: usize,
        t_s: f64,
        values: &[f64],
        sample: T,
    ) -> Result<bool, ImportError> {
        let reject = if !t_s.is_finite() {
            Some(Reject::Invalid("non-finite time".into()))
        } else if let Some(v) = values.iter().find(|v| !v.is_finite()) {
            Some(Reject::Invalid(format!("non-finite value {v}")))
        } else if t_s <= self.last_t {
            Some(Reject::TimeOrder)
        } else {
            None
        };
        match reject {
            None => {
                self.last_t = t_s;
                self.samples.push(sample);
                Ok(true)
            }
            Some(r) => self.reject(index, t_s, r).map(|()| false),
        }
    }

    /// Refuses sample `index` for reason `r` under the policy.
    pub(crate) fn reject(&mut self, index: usize, t_s: f64, r: Reject) -> Result<(), ImportError> {
        match (self.policy, r) {
            (TimeOrderPolicy::Gate, Reject::TimeOrder) => {
                self.gated_time_order += 1;
                Ok(())
            }
            (TimeOrderPolicy::Gate, Reject::Invalid(_)) => {
                self.gated_invalid += 1;
                Ok(())
            }
            (TimeOrderPolicy::Error, Reject::TimeOrder) => Err(ImportError::Stream {
                path: self.path.clone(),
                stream: self.name.into(),
                index,
                t_s,
                message: format!(
                    "time is not after the previous sample's ({} s): duplicate or unsorted sample \
                     (use the gate policy to drop and count such samples)",
                    self.last_t
                ),
            }),
            (TimeOrderPolicy::Error, Reject::Invalid(message)) => Err(ImportError::Stream {
                path: self.path.clone(),
                stream: self.name.into(),
                index,
                t_s,
                message,
            }),
        }
    }

    /// The samples and the stream's report.
    pub(crate) fn finish(self, first_t: impl Fn(&T) -> f64) -> (Vec<T>, StreamReport) {
        let report = StreamReport {
            name: self.name.into(),
            kept: self.samples.len(),
            gated_time_order: self.gated_time_order,
            gated_invalid: self.gated_invalid,
            first_t_s: self.samples.first().map(&first_t),
            last_t_s: self.samples.last().map(&first_t),
        };
        (self.samples, report)
    }
}
