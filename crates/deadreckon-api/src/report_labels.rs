//! The report's method labels say what was applied and where it came from
//! (issue 34): a report made with `--params params.toml` reads every section
//! on streams corrected as the file stores, so its "nominal" row was not
//! `evaluate --params nominal` (13.9 m against 15.3 m) and said nothing of
//! it. Each parameter set is named by where its values come from (nominal,
//! calibrated on this drive, read from the file), and, when the streams were
//! corrected, by where the corrections come from.

use deadreckon_report as rp;

/// How the corrections' source begins when a params.toml gave them.
pub const READ_FROM: &str = "read from";
/// The parameters calibrated on the drive the report is about (`RTS, this
/// drive`).
pub const CALIBRATED_HERE: &str = "this drive";

/// The label of a method (`nominal`, `ZUPT`, `RTS`, `truth`, `given`) with
/// the parameters' source and the corrections' source (`None`: the streams
/// as logged).
pub fn label(method: &str, params: Option<&str>, corrected: Option<&str>) -> String {
    let base = match method {
        "nominal" => "nominal".to_string(),
        "given" => params.unwrap_or("given").to_string(),
        m => format!("{m}, {CALIBRATED_HERE}"),
    };
    match corrected {
        Some(c) => format!("{base} + corrections {c}"),
        None => base,
    }
}

/// `evaluate`'s line for parameters given with `--params` (`nominal` or a
/// params.toml), in the report's words: where the values come from and,
/// when the file stores corrections (`stored`: applied to the streams,
/// [`crate::evaluate::Parameters::file_corrected`]), that too.
pub fn given_line(spec: &str, stored: bool) -> String {
    if spec == "nominal" {
        return label("nominal", None, None);
    }
    let corrected = stored.then(|| format!("from {spec}"));
    label("given", Some(spec), corrected.as_deref())
}

/// Where the corrections come from, in the label's words: `from
/// params.toml`, `estimated here`; `None` without corrections.
fn corrected_words(params: Option<&str>, c: Option<&rp::Corrections>) -> Option<String> {
    let c = c.filter(|c| !c.rows.is_empty())?;
    Some(match (params, c.source.starts_with(READ_FROM)) {
        (Some(p), true) => format!("from {p}"),
        _ => "estimated here".to_string(),
    })
}

/// Renames every method of `input` (tables, figures, the bound) by
/// [`label`].
pub fn say_what_was_applied(
    input: &mut rp::ReportInput,
    params: Option<&str>,
    corrections: Option<&rp::Corrections>,
) {
    let corrected = corrected_words(params, corrections);
    let rename = |m: &mut String| {
        if !m.is_empty() {
            *m = label(m, params, corrected.as_deref());
        }
    };
    if let Some(t) = &mut input.trajectories {
        t.dead_reckoned
            .iter_mut()
            .for_each(|m| rename(&mut m.method));
        if let Some(m) = &mut t.aided_with {
            rename(m);
        }
    }
    if let Some(c) = &mut input.calibration {
        c.rows.iter_mut().for_each(|r| rename(&mut r.method));
        rename(&mut c.iterated_method);
    }
    if let Some(d) = &mut input.drift {
        d.methods.iter_mut().for_each(|m| rename(&mut m.method));
    }
    if let Some(o) = &mut input.outages {
        o.methods.iter_mut().for_each(|m| rename(&mut m.method));
        if let Some(b) = &mut o.bound {
            rename(&mut b.method);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 34: "nominal" 13.9 m in the report against 15.3 m from
    /// `evaluate --params nominal`: the report's streams were corrected as
    /// the params.toml stores and the label hid it.
    #[test]
    fn nominal_in_the_report_hid_the_corrections_params_toml_applied() {
        let stored = rp::Corrections {
            source: format!("{READ_FROM} params.toml"),
            rows: vec![rp::CorrectionRow {
                what: "gnss delay".into(),
                ..Default::default()
            }],
        };
        let mut input = rp::ReportInput {
            drift: Some(rp::Drift {
                methods: ["nominal", "RTS", "given"]
                    .map(|m| rp::DriftMethod {
                        method: m.into(),
                        ..Default::default()
                    })
                    .to_vec(),
                ..Default::default()
            }),
            ..Default::default()
        };
        say_what_was_applied(&mut input, Some("params.toml"), Some(&stored));
        let names: Vec<&str> = input
            .drift
            .as_ref()
            .unwrap()
            .methods
            .iter()
            .map(|m| m.method.as_str())
            .collect();
        assert_eq!(
            names,
            [
                "nominal + corrections from params.toml",
                "RTS, this drive + corrections from params.toml",
                "params.toml + corrections from params.toml",
            ]
        );
        // Without corrections the nominal row is `evaluate --params nominal`'s.
        assert_eq!(label("nominal", None, None), "nominal");
        let estimated = rp::Corrections {
            source: "estimated on this drive (--corrections auto)".into(),
            rows: stored.rows.clone(),
        };
        assert_eq!(
            corrected_words(None, Some(&estimated)).as_deref(),
            Some("estimated here")
        );
    }
}
