//! The turn gain: a correction of the regression's turning part estimated from
//! the heading change over whole segments of the history, not from blocks.
//!
//! Used when `joint_calibration` is off (the joint calibration estimates g
//! together with the DCF). The block regression of eq. (3) sees the heading
//! through short, smoothed and noisy increments; on the simulated car its slope
//! came out about 1.5 % low (mostly the lagged lever-arm conversion, since fixed),
//! and the straight-line dead band clips the ends of every turn, so each 90° turn
//! loses a few hundredths of a radian. Over segments of `gain_segment_s` the
//! reference heading change Δθ is accurate, so the residual of the model's summed
//! increments is regressed on their turning part:
//!
//! `Δθ_ref − Σ γ̂ = c·N + (g − 1)·Σ (γ̂(ω) − γ̂(straight))`
//!
//! (N samples; c, like the DCF, absorbs a constant rate). This is the update
//! phase of eq. (6) applied to the slope instead of the offset.

use crate::history::Sample;
use crate::model::TedrisModel;
use crate::predict::Predictor;
use crate::stats::ols;

/// Estimates g over `samples` (contiguous, oldest first) with segments of
/// `segment` samples; `None` with fewer than 8 segments that turn by 0.05 rad.
/// The result is clamped to [0.8, 1.2].
pub fn estimate_turn_gain(model: &TedrisModel, samples: &[Sample], segment: usize) -> Option<f64> {
    let segment = segment.max(2);
    let mut unit = model.clone();
    unit.turn_gain = 1.0;
    let mut p = Predictor::default();
    let mut cum = Vec::with_capacity(samples.len() + 1);
    let mut cum_turn = Vec::with_capacity(samples.len() + 1);
    let (mut a, mut b) = (0.0, 0.0);
    cum.push(0.0);
    cum_turn.push(0.0);
    for s in samples {
        let r = p.step(&unit, s.omega_m, s.dist_m, 0.0);
        a += r.base_rad;
        b += r.turn_rad;
        cum.push(a);
        cum_turn.push(b);
    }
    let lag = model.lag_samples;
    let (mut x, mut y) = (Vec::new(), Vec::new());
    let mut turning = 0;
    let mut j0 = model.config.tau_samples + lag.unsigned_abs() as usize;
    while j0 + segment < samples.len() {
        let j1 = j0 + segment;
        let (Some(t0), Some(t1)) = (samples[j0].theta_rad, samples[j1].theta_rad) else {
            j0 += segment / 2;
            continue;
        };
        // cum[k] is the sum over samples[..k]: the samples (j0 − h, j1 − h].
        let (k0, k1) = (j0 as i64 - lag + 1, j1 as i64 - lag + 1);
        if k0 < 0 || k1 as usize >= cum.len() {
            j0 = j1;
            continue;
        }
        let (k0, k1) = (k0 as usize, k1 as usize);
        let turn = cum_turn[k1] - cum_turn[k0];
        let r = (t1 - t0) - (cum[k1] - cum[k0]);
        if turn.abs() > 0.05 {
            turning += 1;
        }
        x.push(vec![(k1 - k0) as f64, turn]);
        y.push(r);
        j0 = j1;
    }
    if turning < 8 {
        return None;
    }
    let fit = ols(&x, &y, &["rate", "gain"]).ok()?;
    let g = 1.0 + fit.coefficients[1].estimate;
    g.is_finite().then_some(g.clamp(0.8, 1.2))
}
