//! `--corrections auto`'s held-back decision as text.

/// `--corrections auto`'s decision in one line: the held-back windows, the
/// error without corrections and with each candidate.
pub fn held_back_line(h: &deadreckon_core::held_back::HeldBack) -> String {
    if h.judged.is_empty() {
        return format!(
            "corrections: none applied (no correction at least {:.1} standard errors from none)",
            h.min_z
        );
    }
    if h.judged.iter().all(|j| j.by_significance) {
        let why = match &h.not_judged {
            Some(why) => why.clone(),
            None => format!(
                "no other correction at least {:.1} standard errors from none",
                h.min_z
            ),
        };
        return format!(
            "corrections: {} ({why})",
            h.judged
                .iter()
                .map(|j| format!(
                    "{} applied on its significance ({:+.1} standard errors)",
                    j.correction, j.z
                ))
                .collect::<Vec<_>>()
                .join("; "),
        );
    }
    let each: Vec<String> = h
        .judged
        .iter()
        .map(|j| {
            if j.by_significance {
                format!(
                    "{} applied on its significance ({:+.1} standard errors; the held-back fixes share its clock and cannot judge it)",
                    j.correction, j.z
                )
            } else if j.with_m.is_finite() && !j.t.is_finite() {
                // The same error in every window: nothing to test.
                format!(
                    "{} {:.3} m, the same in every window (not applied)",
                    j.correction, j.with_m
                )
            } else if j.with_m.is_finite() {
                let score = (j.score_t.is_finite())
                    .then(|| format!(", the hidden fixes' likelihood t {:+.1}", j.score_t));
                format!(
                    "{} {:.3} m against {:.3} m, t {:+.1}{} ({})",
                    j.correction,
                    j.with_m,
                    j.against_m,
                    j.t,
                    score.unwrap_or_default(),
                    if j.applied { "applied" } else { "not applied" }
                )
            } else {
                format!("{} not applied", j.correction)
            }
        })
        .collect();
    format!(
        "corrections chosen on held-back GNSS ({} windows of {:.0} s, the calibration blind to them): without them {:.3} m; {}{}",
        h.windows,
        h.window_s,
        h.without_m,
        each.join("; "),
        h.together_m
            .map_or(String::new(), |t| format!("; with the applied ones {t:.3} m"))
    )
}
