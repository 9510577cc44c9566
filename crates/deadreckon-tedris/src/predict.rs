//! The per-sample evaluation of eq. (4): the FIFO of the last τ values of ω whose
//! median picks the repository, the regression of that repository, the DCF, and
//! during an outage the forecast of the AR/MA error correction.

use std::collections::VecDeque;

use serde::{Deserialize, Serialize};

use crate::config::ModelKind;
use crate::model::TedrisModel;
use crate::stats::median;

/// The heading increment of one wheel sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rate {
    /// The regression alone, rad per sample.
    pub base_rad: f64,
    /// Regression + DCF + error correction, rad per sample: the γ̂ of eq. (4).
    pub total_rad: f64,
    /// The repository used.
    pub repository: i32,
    /// The turning part of the regression, γ̂(ω) − γ̂(straight line), before the turn gain.
    pub turn_rad: f64,
}

/// The evaluation state: FIFO, previous block (ARX) and the correction forecast.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Predictor {
    fifo: VecDeque<f64>,
    block_count: usize,
    block_sum_rad: f64,
    prev_block: Option<(f64, f64)>,
    correcting: bool,
    e_hist: Vec<f64>,
    u_hist: Vec<f64>,
    correction_rad: f64,
}

impl Predictor {
    /// The increment for a sample with rear wheel difference `omega_m` and distance
    /// `dist_m` (m per sample). `dcf_rad` is added; the error correction only while predicting.
    pub fn step(&mut self, model: &TedrisModel, omega_m: f64, dist_m: f64, dcf_rad: f64) -> Rate {
        let tau = model.tau();
        self.fifo.push_back(omega_m);
        while self.fifo.len() > tau {
            self.fifo.pop_front();
        }
        // Quantised ticks: the mean of the FIFO, as their blocks are formed.
        let med = if model.block_means() {
            crate::stats::mean(self.fifo.make_contiguous())
        } else {
            median(self.fifo.make_contiguous())
        };
        let fit = model.chosen_fit();
        let repository = model.straight().bin(med).unwrap_or(0);
        let beta = fit.beta(repository);
        let centre = model.straight_centre(dist_m);
        let prev = self.prev_block;
        let eval = |w: f64| match fit.kind {
            ModelKind::Paper => beta[0] + beta[1] * w,
            ModelKind::Distance => beta[0] + beta[1] * w + beta[2] * dist_m,
            ModelKind::Arx => {
                let lin = beta[0] + beta[1] * w + beta[2] * dist_m;
                let (wp, gp) = prev.unwrap_or_else(|| {
                    // Start from the steady state of the ARX recursion.
                    let g = if beta[4].abs() < 0.99 {
                        (lin + beta[3] * w) / (1.0 - beta[4])
                    } else {
                        lin
                    };
                    (w, g)
                });
                lin + beta[3] * wp + beta[4] * gp
            }
            ModelKind::Baseline => beta[0] * w + beta[1] * dist_m,
            ModelKind::Speed => {
                beta[0] + beta[1] * w + beta[2] * dist_m + beta[3] * w * dist_m * dist_m
            }
        };
        // γ̂ = γ̂(straight) + g·(γ̂(ω) − γ̂(straight)): the turn gain g scales the part
        // of the increment that comes from turning.
        // In the per-metre form the turn is measured from ω = 0 and the
        // straight-line rate is the calibration's `dcf_distance_rad_per_m · d`
        // alone (added by the caller as DCF): no rate per sample.
        let straight = if model.per_metre_straight {
            eval(0.0)
        } else {
            eval(centre)
        };
        let turn = eval(omega_m) - straight;
        let straight_part = if model.per_metre_straight {
            0.0
        } else {
            straight
        };
        let base = straight_part + model.turn_gain * turn;
        let base = if base.is_finite() { base } else { 0.0 };
        let corr = if self.correcting {
            self.correction_rad
        } else {
            0.0
        };
        self.block_count += 1;
        self.block_sum_rad += base + corr;
        if self.block_count >= tau {
            self.prev_block = Some((med, self.block_sum_rad / self.block_count as f64));
            self.block_count = 0;
            self.block_sum_rad = 0.0;
            if self.correcting {
                // One block ahead: the forecast becomes the past error, its innovation is zero.
                self.e_hist.push(self.correction_rad);
                self.u_hist.push(0.0);
                self.correction_rad = fit.correction().forecast(&self.e_hist, &self.u_hist);
            }
        }
        Rate {
            turn_rad: if turn.is_finite() { turn } else { 0.0 },
            base_rad: base,
            total_rad: base + corr + dcf_rad,
            repository,
        }
    }

    /// Starts the error-correction forecast from the last block errors `e` and
    /// innovations `u` (most recent last), `skipped` blocks after them.
    pub fn begin_correction(
        &mut self,
        model: &TedrisModel,
        e: Vec<f64>,
        u: Vec<f64>,
        skipped: usize,
    ) {
        let c = model.chosen_fit().correction();
        self.e_hist = e;
        self.u_hist = u;
        let mut f = c.forecast(&self.e_hist, &self.u_hist);
        for _ in 0..skipped.min(64) {
            self.e_hist.push(f);
            self.u_hist.push(0.0);
            f = c.forecast(&self.e_hist, &self.u_hist);
        }
        self.correction_rad = if f.is_finite() { f } else { 0.0 };
        self.correcting = true;
    }

    /// Stops the error-correction forecast (reference heading back).
    pub fn end_correction(&mut self) {
        self.correcting = false;
        self.e_hist.clear();
        self.u_hist.clear();
        self.correction_rad = 0.0;
    }
}
