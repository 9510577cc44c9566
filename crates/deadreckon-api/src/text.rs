//! The commands' text tables and summary lines, built from library results
//! (the command line prints them line by line).

use deadreckon_core::ParamsWithStd;

/// The corrections as text lines (one per stream, and the tilt).
pub fn corrections_lines(c: &deadreckon_core::timing::Corrections) -> Vec<String> {
    use deadreckon_core::timing::Stream;
    let mut out = vec![format!(
        "{:<10} {:>10} {:>9}  status",
        "delay of", "s", "std s"
    )];
    for s in Stream::ALL {
        let d = c.delays.get(s);
        out.push(match d.status.reason() {
            None => format!(
                "{:<10} {:>+10.4} {:>9.4}  estimated, applied",
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
    match &c.tilt {
        None => out.push("imu tilt: no three-axis IMU in the drive".into()),
        Some(t) => out.push(match t.status.reason() {
            None => format!(
                "imu tilt: {:.2}° ± {:.2}° (pitch {:+.2}°, roll {:+.2}°, from gravity while {}), yaw rate projected on the vertical",
                t.tilt_rad.to_degrees(),
                t.std_rad.to_degrees(),
                t.pitch_rad.to_degrees(),
                t.roll_rad.to_degrees(),
                t.source.name()
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
            Some(r) => format!("gyro scale error: not estimated: {r}"),
        });
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
    let mut out = vec![
        format!(
            "four-wheel EKF: {}; errors against the {}",
            c.params_source, c.four_wheel_reference
        ),
        format!(
            "TedriS: {}; errors against the {}",
            c.model_source, c.tedris_reference
        ),
    ];
    out.push(format!(
        "{:<20} {:<12} {:>10} {:>10} {:>10} {:>16}",
        "outage (s)", "method", "mean (m)", "max (m)", "final (m)", "time to 1 m (s)"
    ));
    let fmt = |r: &Option<deadreckon_eval::compare::Row>| match r {
        Some(r) => format!(
            "{:>10.2} {:>10.2} {:>10.2} {:>16}",
            r.mean,
            r.max,
            r.fin,
            r.to_1m
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
    out
}

/// The wheel-health lines of `run` and `calibrate`: a summary, a line per
/// wheel, and each stretch a wheel was out of the fusion.
pub fn wheel_health_lines(h: &deadreckon_core::wheel_health::WheelHealth) -> Vec<String> {
    let mut out = Vec::new();
    if h.all_good() {
        out.push("wheel health: no wheel slipped or read wrong".to_string());
    }
    out.extend(h.lines());
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
