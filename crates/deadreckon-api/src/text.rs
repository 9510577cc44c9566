//! The commands' text tables and summary lines, built from library results
//! (the command line prints them line by line).

use deadreckon_core::compared::OutageResult;

use deadreckon_core::ParamsWithStd;

mod held_back;
pub use held_back::held_back_line;

/// The corrections as text lines (one per stream, and the tilt).
pub fn corrections_lines(c: &deadreckon_core::timing::Corrections) -> Vec<String> {
    use deadreckon_core::timing::{Stream, NOT_ASKED};
    let asked = |s: Stream| c.delays.get(s).status.reason() != Some(NOT_ASKED);
    if !Stream::ALL.into_iter().any(asked)
        && c.tilt.is_none()
        && c.gyro_scale.is_none()
        && c.traction.is_none()
    {
        // --corrections none: not "no three-axis IMU in the drive".
        return vec!["corrections: none estimated or applied".into()];
    }
    let mut out = vec![format!(
        "{:<10} {:>10} {:>9}  status",
        "delay of", "s", "std s"
    )];
    for s in Stream::ALL {
        let d = c.delays.get(s);
        out.push(match d.status.reason() {
            None => format!(
                "{:<10} {:>+10.4} {:>9.4}  estimated, applied{}",
                s.name(),
                d.delay_s,
                d.std_s,
                crate::corrections::step_offset_words(d)
            ),
            Some(r) if d.status.is_measured_not_applied() => format!(
                "{:<10} {:>+10.4} {:>9.4}  {r}",
                s.name(),
                d.delay_s,
                d.std_s
            ),
            Some(r) => format!(
                "{:<10} {:>10} {:>9}  not estimated: {r}",
                s.name(),
                "-",
                "-"
            ),
        });
    }
    if let Some(t) = &c.traction {
        out.push(match t.status.reason() {
            None => format!(
                "driven axle: {}, slip {:+.3}% ± {:.3}% per m/s² of forward specific force ({} one-second blocks), its wheel speeds corrected",
                t.axle.name(),
                100.0 * t.slip_per_mps2.abs(),
                100.0 * t.std,
                t.blocks
            ),
            Some(r) if t.status.is_measured_not_applied() => format!(
                "driven axle: {}, slip {:+.3}% ± {:.3}% per m/s² of forward specific force ({} one-second blocks), {r}",
                t.axle.name(),
                100.0 * t.slip_per_mps2.abs(),
                100.0 * t.std,
                t.blocks
            ),
            Some(r) => format!("driven axle slip: not estimated: {r}"),
        });
    }
    match &c.tilt {
        None => out.push("imu tilt: no three-axis IMU in the drive".into()),
        Some(t) => out.push(match t.status.reason() {
            None => format!(
                "imu tilt: {:.2}° ± {:.2}° (pitch {:+.2}° ± {:.2}°, roll {:+.2}° ± {:.2}°, from gravity while {}{}; |f| − g {:+.3} m/s²), yaw rate projected on the vertical",
                t.tilt_rad.to_degrees(),
                t.std_rad.to_degrees(),
                t.pitch_rad.to_degrees(),
                t.pitch_std_rad.to_degrees(),
                t.roll_rad.to_degrees(),
                t.roll_std_rad.to_degrees(),
                t.source.name(),
                t.gyro_bias.map_or(String::new(), |b| format!(
                    ", gyro bias {:+.4} ± {:.4} rad/s from the GNSS course",
                    b.bias_rps, b.std_rps
                )),
                t.accel_error_mps2
            ),
            Some(r) if t.status.is_measured_not_applied() => format!(
                "imu tilt: {:.2}° ± {:.2}° (pitch {:+.2}°, roll {:+.2}°), {r}",
                t.tilt_rad.to_degrees(),
                t.std_rad.to_degrees(),
                t.pitch_rad.to_degrees(),
                t.roll_rad.to_degrees(),
            ),
            Some(r) => format!("imu tilt: not estimated: {r}"),
        }),
    }
    if let Some(g) = &c.gyro_scale {
        out.push(match g.status.reason() {
            None => format!(
                "gyro scale error: {:+.3}% ± {:.3}% ({} turns), applied",
                100.0 * g.scale_error,
                100.0 * g.std,
                g.turns
            ),
            Some(r) if g.status.is_measured_not_applied() => format!(
                "gyro scale error: {:+.3}% ± {:.3}% ({} turns), {r}",
                100.0 * g.scale_error,
                100.0 * g.std,
                g.turns
            ),
            Some(r) => format!("gyro scale error: not estimated: {r}"),
        });
    }
    if let Some(h) = &c.held_back {
        out.push(held_back_line(h));
    }
    out
}

/// The header of a table-III-like parameter table.
pub fn params_header() -> String {
    format!(
        "{:<8} {:>22} {:>18} {:>20} {:>20} {:>20} {:>20}",
        "method", "b_gyro (rad/s)", "a_v", "rho_FL (m)", "rho_FR (m)", "rho_RL (m)", "rho_RR (m)"
    )
}

/// One row of a parameter table, with standard errors where they are non-zero.
pub fn params_row(name: &str, p: &ParamsWithStd) -> String {
    let a = p.params.to_array();
    let s = p.std.to_array();
    let cell = |v: f64, e: f64, prec: usize| -> String {
        if e > 0.0 {
            format!("{v:.prec$} ± {e:.prec$}")
        } else {
            format!("{v:.prec$}")
        }
    };
    format!(
        "{:<8} {:>22} {:>18} {:>20} {:>20} {:>20} {:>20}",
        name,
        cell(a[0], s[0], 6),
        cell(a[1], s[1], 5),
        cell(a[2], s[2], 5),
        cell(a[3], s[3], 5),
        cell(a[4], s[4], 5),
        cell(a[5], s[5], 5)
    )
}

/// A one-line account of what the filter used and gated.
pub fn stats_line(st: &deadreckon_core::ekf::FilterStats) -> String {
    format!(
        "filter: {} epochs, GNSS {} used / {} rejected by the gate ({} recoveries) / {} hidden, {} wheel gaps skipped; rejected by the χ² gates: {}",
        st.epochs,
        st.gnss_updates,
        st.gnss_rejected,
        st.gnss_recoveries,
        st.gnss_hidden,
        st.wheel_gaps,
        gated_text(&st.gates)
    )
}

/// The sensors the χ² gates rejected something of, as `name rejected/total`,
/// or `none`.
pub fn gated_text(g: &deadreckon_core::filter::GateCounts) -> String {
    let gated: Vec<String> = g
        .rows()
        .into_iter()
        .filter(|r| r.2 > 0)
        .map(|(name, a, r, _)| format!("{name} {r}/{}", a + r))
        .collect();
    if gated.is_empty() {
        "none".to_string()
    } else {
        gated.join(", ")
    }
}

/// The comparison table of `compare` and `demo`; `t0` is subtracted from the outage times.
pub fn comparison_lines(c: &deadreckon_eval::compare::Comparison, t0: f64) -> Vec<String> {
    // The point each estimator's errors were measured at (its rows say).
    let point = |r: Option<&OutageResult>| {
        r.map_or(String::new(), |r| format!(" at the {}", r.point.name()))
    };
    let mut out = vec![
        format!(
            "four-wheel EKF: {}; errors against the {}{}",
            c.params_source,
            c.four_wheel_reference,
            point(c.rows.iter().find_map(|r| r.1.as_ref()))
        ),
        format!(
            "TedriS: {}; errors against the {}{}",
            c.model_source,
            c.tedris_reference,
            point(c.rows.iter().find_map(|r| r.2.as_ref()))
        ),
    ];
    out.push(format!(
        "{:<20} {:<12} {:>10} {:>10} {:>10} {:>16}",
        "outage (s)", "method", "mean (m)", "max (m)", "final (m)", "time to 1 m (s)"
    ));
    let fmt = |r: &Option<deadreckon_core::compared::OutageResult>| match r {
        Some(r) => format!(
            "{:>10.2} {:>10.2} {:>10.2} {:>16}",
            r.mean_m(),
            r.max_m(),
            r.final_m(),
            r.time_to(1.0)
                .map(|t| format!("{t:.1}"))
                .unwrap_or_else(|| "never".into())
        ),
        None => format!("{:>10} {:>10} {:>10} {:>16}", "-", "-", "-", "-"),
    };
    for (o, f, t) in &c.rows {
        let w = format!("{:.1}:{:.1}", o.start_s - t0, o.end_s - t0);
        out.push(format!("{:<20} {:<12} {}", w, "four-wheel", fmt(f)));
        out.push(format!("{:<20} {:<12} {}", "", "TedriS", fmt(t)));
    }
    out.push(c.tedris_checks.line());
    out
}

/// `tedris run`'s table: the reference, one row per outage (the threshold
/// column only when it is not the 1 m one), and the machine's checks.
pub fn tedris_outage_lines(r: &deadreckon_tedris::OutageReport, threshold_m: f64) -> Vec<String> {
    let mut out = vec![format!(
        "reference heading: {}; errors of the rear axle against {}",
        r.source, r.reference
    )];
    let extra = (threshold_m != 1.0).then(|| format!("to_{threshold_m}m_s"));
    out.push(format!(
        "{:>9} {:>9} {:>10} {:>9} {:>10} {:>12}{}",
        "start_s",
        "end_s",
        "mean_m",
        "max_m",
        "final_m",
        "to_1m_s",
        extra
            .as_ref()
            .map_or(String::new(), |h| format!(" {h:>12}"))
    ));
    let opt = |v: Option<f64>| v.map_or("never".to_string(), |x| format!("{x:.1}"));
    for o in &r.outages {
        out.push(format!(
            "{:>9.1} {:>9.1} {:>10.2} {:>9.2} {:>10.2} {:>12}{}",
            o.result.start_s,
            o.result.end_s,
            o.mean_error_m(),
            o.max_error_m(),
            o.final_error_m(),
            opt(o.time_to_1m_s()),
            extra.as_ref().map_or(String::new(), |_| format!(
                " {:>12}",
                opt(o.time_to_threshold_s())
            ))
        ));
    }
    if let Some(m) = r.machine.model() {
        out.push(format!(
            "at the end of the run: {}",
            tedris_calibrated_line(m)
        ));
    }
    out.push(r.machine.checks().line());
    out
}

/// `evaluate --outage`'s text: the windows, the summary table, the gates
/// and the corrections estimated (when any).
pub fn outage_lines(
    ev: &deadreckon_core::outage::OutageEvaluation,
    source: &str,
    corrections: Option<&deadreckon_core::timing::Corrections>,
) -> Vec<String> {
    let mut out = vec![format!(
        "{} outage windows of {} s against the {} (parameters: {source})",
        ev.windows.len(),
        ev.outage_s,
        ev.reference.name()
    )];
    out.extend(summary_table(&[
        ("error at the start (m)", ev.start_error()),
        ("final error (m)", ev.final_error()),
        ("drift per 100 m (%)", ev.drift_pct()),
        ("distance before 1 m (m)", ev.distance_to_1m()),
    ]));
    out.extend(unsettled_line(ev));
    out.extend(ev.bias_switch.as_ref().map(ToString::to_string));
    out.push(format!(
        "rejected by the χ² gates: {}",
        gated_text(&ev.gates)
    ));
    if let Some(c) = corrections {
        out.extend(corrections_lines(c));
    }
    out
}

/// The windows left out of the summaries because the heading was not yet
/// known at their start, with their final errors (`None` when there are none).
pub fn unsettled_line(ev: &deadreckon_core::outage::OutageEvaluation) -> Option<String> {
    if ev.unsettled.is_empty() {
        return None;
    }
    let stds: Vec<f64> = ev
        .unsettled
        .iter()
        .filter_map(|w| w.start_yaw_std_rad.map(f64::to_degrees))
        .collect();
    let (lo, hi) = stds
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let finals: Vec<String> = ev
        .unsettled
        .iter()
        .map(|w| format!("{:.2}", w.final_m()))
        .collect();
    let range = if (hi - lo).abs() < 0.05 {
        format!("{lo:.1}°")
    } else {
        format!("{lo:.1}–{hi:.1}°")
    };
    Some(format!(
        "left out: {} window{} starting before the heading was known (the aided filter's yaw \
         standard deviation {range} at the start, above {:.1}°), final errors {} m",
        ev.unsettled.len(),
        if ev.unsettled.len() == 1 { "" } else { "s" },
        ev.heading_limit_rad.to_degrees(),
        finals.join(", ")
    ))
}

/// `evaluate --metric rpe|ape`'s two lines: what was measured, and the
/// statistics.
pub fn evo_lines(
    q: &crate::json::EvoQuery<'_>,
    r: &deadreckon_core::evo::TrajectoryError,
) -> Vec<String> {
    let what = if q.metric == "rpe" {
        format!(
            "RPE per {} m (translation, pairs from the {})",
            q.delta_m, q.pairs_from
        )
    } else {
        "APE (translation, no alignment)".to_string()
    };
    let s = &r.stats;
    vec![
        format!(
            "{what} of `{}` against `{}`: {} errors over {} associated poses (as evo {})",
            q.track,
            q.reference,
            r.errors_m.len(),
            r.matched,
            deadreckon_core::evo::EVO_VERSION
        ),
        format!(
            "rmse {:.4} m, mean {:.4} m, median {:.4} m, std {:.4} m, min {:.4} m, max {:.4} m",
            s.rmse, s.mean, s.median, s.std, s.min, s.max
        ),
    ]
}

/// The wheel-health lines of `run` and `calibrate`: a summary, a line per
/// wheel, and each stretch a wheel was out of the fusion.
pub fn wheel_health_lines(h: &deadreckon_core::wheel_health::WheelHealth) -> Vec<String> {
    let mut out = Vec::new();
    if h.all_good() {
        out.push("wheel health: no wheel slipped or read wrong".to_string());
    }
    out.extend(h.lines());
    if h.wheels.iter().any(|w| w.epochs_checked > 0) {
        let m = deadreckon_core::wheel_health::WheelMonitorConfig::default();
        out.push(format!(
            "  (|T|: a wheel's largest normalised residual against the other sensors, about standard normal on a healthy wheel; \
             short: over {} s, a wheel spinning or locking; long: over {} m of travel, a tyre reading wrong for good; \
             a wheel is dropped above {})",
            m.short_window_s, m.long_window_m, m.drop_sigma
        ));
    }
    for (name, w) in deadreckon_core::wheel_health::WHEEL_NAMES
        .iter()
        .zip(&h.wheels)
    {
        for i in &w.intervals {
            out.push(format!(
                "  wheel {name} out {:.2}..{:.2} s ({}, peak |T| {:.1})",
                i.start_s,
                i.end_s,
                i.reason.name(),
                i.peak_sigma
            ));
        }
    }
    out
}

/// ` ± s` after a calibrated value (`s` its standard error), or
/// ` (std not estimated)`: never a 0 standing in for unknown.
fn plus_minus(std: Option<f64>) -> String {
    std.map_or(" (std not estimated)".to_string(), |s| {
        format!(" ± {s:.2e}")
    })
}

/// The calibrated heading values of a TedriS model with their standard
/// errors (`tedris train`, and `tedris run` for the values at the end).
pub fn tedris_calibrated_line(m: &deadreckon_tedris::TedrisModel) -> String {
    if m.per_metre_straight {
        // Heading per metre as the rear radius mismatch it is.
        format!(
            "straight-line heading {:.3e}{} rad/m (per metre only: none at rest), turn gain = {:.4}{}",
            m.dcf_distance_rad_per_m,
            plus_minus(m.dcf_distance_std_rad_per_m),
            m.turn_gain,
            plus_minus(m.turn_gain_std)
        )
    } else if m.config.joint_calibration() {
        format!(
            "DCF0 = {:.3e} rad/sample, DCF = {:.3e}{} rad/sample + {:.3e}{} rad/m, turn gain = {:.4}{}",
            m.dcf0_rad,
            m.dcf_rad,
            plus_minus(m.dcf_std_rad),
            m.dcf_distance_rad_per_m,
            plus_minus(m.dcf_distance_std_rad_per_m),
            m.turn_gain,
            plus_minus(m.turn_gain_std)
        )
    } else {
        // The paper's method: eq. (6) only; no distance term, no turn gain.
        format!(
            "DCF0 = {:.3e} rad/sample, DCF = {:.3e} rad/sample (eq. 6, std not estimated; heading per metre and turn gain not estimated)",
            m.dcf0_rad, m.dcf_rad
        )
    }
}

/// The summary `tedris train` prints: the reference, τ and the lag, the
/// straight line, the drift corrections, the course convention, every
/// model kind with its coefficients and residual tests, the repositories.
pub fn tedris_train_lines(
    m: &deadreckon_tedris::TedrisModel,
    source: deadreckon_tedris::ReferenceSource,
) -> Vec<String> {
    use deadreckon_tedris::ReferenceSource;
    let mut out = Vec::new();
    let s = m.straight();
    out.push(format!("reference heading: {source}"));
    if let Some(c) = &m.corrections {
        out.push(format!(
            "trained on corrected streams (kept in the model, applied by tedris run): {}",
            known_corrections_text(c)
        ));
    }
    out.push(format!(
        "tau = {} samples, sample period {:.4} s, lag h = {} samples (peak corr {:.3})",
        m.tau(),
        m.sample_period_s,
        m.lag_samples,
        m.ccf
            .values
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max)
    ));
    out.push(match &m.blocks {
        Some(b) => format!("blocks: {}", b.describe(m.sample_period_s)),
        None => format!(
            "blocks: tau_samples = {} with block medians (wheel distances not quantised coarser than the turning)",
            m.config.tau_samples
        ),
    });
    if let Some(a) = &m.acceptance {
        out.push(format!(
            "physical acceptance: cross-correlation peak {:.3}{}",
            a.ccf_peak,
            a.expected_ccf_peak.map_or(
                " (expected from the turning: not estimated)".to_string(),
                |e| format!(" against {e:.3} expected from the turning")
            )
        ));
        if let Some(k) = a.fell_back_from {
            out.push(format!(
                "  the {} model was refused: the baseline model is used",
                k.name()
            ));
        }
    }
    let eps = s.epsilon_m.map_or("inf".to_string(), |e| format!("{e:.6}"));
    out.push(format!(
        "straight line ({} blocks{}): mu = {:.6} m, W_L = {:.6} m, W_H = {:.6} m, epsilon = {} m (per wheel sample)",
        s.blocks,
        if s.fallback { ", quietest blocks" } else { "" },
        s.mu_m,
        s.w_low_m,
        s.w_high_m,
        eps
    ));
    out.push(tedris_calibrated_line(m));
    if m.config.distance_scale() {
        out.push(match m.distance_scale.estimated() {
            Some(k) => format!(
                "rear wheels' distance scale = {k:.4} (from {} GNSS chords)",
                m.distance_scale.chords
            ),
            None => format!(
                "rear wheels' distance scale: not estimated (too few GNSS chords of {} s; 1 kept)",
                deadreckon_tedris::tuning::CHORD_S
            ),
        });
    }
    match &m.course_convention {
        Some(c) => out.push(format!(
            "course convention found on the data: the course is {} (residual as body yaw / as antenna course = {:.3})",
            c.convention, c.rss_ratio
        )),
        None if source == ReferenceSource::GnssCourse => {
            out.push("course convention: not decided on the data (taken as the antenna's velocity)".to_string())
        }
        None => {}
    }
    for f in &m.fits {
        let mark = if f.kind == m.chosen {
            "  <- chosen"
        } else {
            ""
        };
        out.push(String::new());
        out.push(format!(
            "model {} (n = {}, R² = {:.4}, sigma = {:.3e}, AIC = {:.1}, BIC = {:.1}){mark}",
            f.kind.name(),
            f.global.n,
            f.global.r_squared,
            f.global.sigma2.sqrt(),
            f.global.aic,
            f.global.bic
        ));
        out.extend(coefficient_lines(&f.global.coefficients));
        if let Some(k) = m.acceptance.as_ref().and_then(|a| a.kind(f.kind)) {
            out.push(format!(
                "  turn gain {} (heading per metre of right - left × track): {}",
                k.turn_gain
                    .map_or("not defined".to_string(), |g| format!("{g:.3}")),
                k.refused
                    .as_ref()
                    .map_or("accepted".to_string(), |r| format!("refused: {r}"))
            ));
        } else if let Some(r) = m.refused_kinds.iter().find(|r| r.kind == f.kind) {
            out.push(format!("  refused: {}", r.reason));
        }
        out.push(format!(
            "  Box-Pierce Q = {:.2} (L = {}, p = {:.4}); Ljung-Box Q* = {:.2} (p = {:.4})",
            f.box_pierce.statistic,
            f.box_pierce.lags,
            f.box_pierce.p_value,
            f.ljung_box.statistic,
            f.ljung_box.p_value
        ));
        match (&f.correction, &f.corrected) {
            (Some(c), Some(t)) => {
                out.push(format!(
                    "  residuals not white: {} correction (innovations Ljung-Box p = {:.4}); joint refit:",
                    c.correction.label(),
                    c.ljung_box.p_value
                ));
                out.extend(coefficient_lines(&t.coefficients));
            }
            (Some(c), None) => out.push(format!(
                "  residuals not white: {} correction",
                c.correction.label()
            )),
            _ => out.push("  residuals white: no correction".to_string()),
        }
    }
    out.push(String::new());
    out.push("repositories (omega interval per wheel sample, m):".to_string());
    for r in m.repositories.fill(m.config.required_bins) {
        out.push(format!(
            "  R{:<4} [{:>10.5}, {:>10.5}]  {:>6} tuples{}",
            r.index,
            r.low_m,
            r.high_m,
            r.tuples,
            if r.filled {
                ""
            } else {
                "  (below minimum fill)"
            }
        ));
    }
    out.push(format!("training complete: {}", m.complete));
    out
}

/// A coefficient table of a TedriS regression.
fn coefficient_lines(c: &[deadreckon_tedris::stats::Coefficient]) -> Vec<String> {
    let mut out = Vec::new();
    out.push(format!(
        "  {:<12} {:>14} {:>14} {:>10} {:>10}",
        "", "Estimate", "Std. Error", "t value", "p value"
    ));
    for r in c {
        out.push(format!(
            "  {:<12} {:>14.6e} {:>14.6e} {:>10.2} {:>10.4}",
            r.name, r.estimate, r.std_error, r.t_value, r.p_value
        ));
    }
    out
}

/// Summaries as a table: a header (mean, median, p95, max) and a row each.
pub fn summary_table(rows: &[(&str, deadreckon_core::metrics::Summary)]) -> Vec<String> {
    let mut out = vec![format!(
        "{:<28} {:>9} {:>9} {:>9} {:>9}",
        "", "mean", "median", "p95", "max"
    )];
    for (name, s) in rows {
        out.push(format!(
            "{:<28} {:>9.3} {:>9.3} {:>9.3} {:>9.3}",
            name, s.mean, s.median, s.p95, s.max
        ));
    }
    out
}

/// A kinematic calibration as a table: value, standard error and status
/// per parameter; the correlation of the estimated parameters; the fit.
pub fn kinematic_table(c: &deadreckon_core::kinematics::KinematicCalibration) -> Vec<String> {
    let mut out = vec![format!(
        "{:<18} {:>12} {:>12}  status",
        "parameter", "value", "std"
    )];
    for p in &c.params {
        let std = p.std.map_or("-".to_string(), |s| format!("{s:.6}"));
        let status = match &p.reason {
            None => "estimated".to_string(),
            Some(r) => format!("NOT ESTIMATED (nominal kept): {r}"),
        };
        out.push(format!(
            "{:<18} {:>12.6} {:>12}  {status}",
            p.name, p.value, std
        ));
    }
    if !c.correlated.is_empty() {
        out.push("correlation:".into());
        let mut header = format!("{:<18}", "");
        for n in &c.correlated {
            let short: String = n.chars().take(8).collect();
            header.push_str(&format!(" {short:>8}"));
        }
        out.push(header);
        for (n, row) in c.correlated.iter().zip(&c.correlation) {
            let mut line = format!("{n:<18}");
            for v in row {
                line.push_str(&format!(" {v:>8.3}"));
            }
            out.push(line);
        }
    }
    out.push(format!(
        "{} of {} windows above {} m/s, RMS at the window ends {:.3} m / {}; {} ({})",
        c.windows_used,
        c.windows_total,
        c.min_speed_mps,
        c.rms_position_m,
        c.rms_heading_rad.map_or_else(
            || "heading not computed (the reference has none)".to_string(),
            |h| format!("{h:.4} rad")
        ),
        if c.converged {
            "converged"
        } else {
            "NOT converged"
        },
        c.termination
    ));
    out
}

/// Known corrections in one line: the non-zero delays, the tilt of the
/// vertical, the gyro scale error.
pub fn known_corrections_text(c: &deadreckon_core::timing::KnownCorrections) -> String {
    use deadreckon_core::timing::Stream;
    let mut parts: Vec<String> = Stream::ALL
        .iter()
        .zip(c.delays_s)
        .filter(|(_, d)| *d != 0.0)
        .map(|(s, d)| format!("{} delay {d:+.4} s", s.name()))
        .collect();
    if let Some(u) = c.up {
        parts.push(format!(
            "IMU tilt {:.2}°",
            u[2].clamp(-1.0, 1.0).acos().to_degrees()
        ));
    }
    if c.gyro_scale_error != 0.0 {
        parts.push(format!(
            "gyro scale error {:+.3}%",
            100.0 * c.gyro_scale_error
        ));
    }
    if !c.model.is_empty() {
        parts.push(c.model.words());
    }
    parts.join(", ")
}

/// The RTS calibration's distance scale against GNSS chords, one line (or
/// that the drive was too short to check it).
pub fn chords_line(c: Option<&deadreckon_core::chords::ChordScale>) -> String {
    use deadreckon_core::chords::{BLOCK_S, MIN_BLOCKS, MIN_CHORD_M};
    match c {
        Some(c) => format!(
            "distance scale against GNSS chords: {:+.3}% ± {:.3}% ({} blocks of {BLOCK_S} s); \
             the speed scale's and circumferences' standard errors include it",
            100.0 * c.mean,
            100.0 * c.std,
            c.blocks,
        ),
        None => format!(
            "distance scale against GNSS chords: not checked (fewer than {MIN_BLOCKS} blocks \
             of {BLOCK_S} s with {MIN_CHORD_M} m of travel): the standard errors leave out \
             the receiver's slow error"
        ),
    }
}
