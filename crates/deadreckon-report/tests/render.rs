//! End-to-end tests of the HTML report on synthetic input: every section draws
//! data, empty sections are left out, the page is self-contained, and it stays
//! small for an hour-long drive.

use deadreckon_report::sample::sample_input;
use deadreckon_report::*;

/// The figures of a page: (name, inner HTML).
fn figures(html: &str) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let mut rest = html;
    while let Some(p) = rest.find("<figure ") {
        rest = &rest[p..];
        let end = rest.find("</figure>").expect("figure closed");
        let body = &rest[..end];
        let name = body
            .split("data-figure=\"")
            .nth(1)
            .and_then(|s| s.split('"').next())
            .expect("figure has data-figure")
            .to_string();
        out.push((name, body.to_string()));
        rest = &rest[end..];
    }
    out
}

/// The value of attribute `a` in the tag `tag`.
fn attr<'a>(tag: &'a str, a: &str) -> Option<&'a str> {
    tag.split(&format!(" {a}=\""))
        .nth(1)
        .and_then(|s| s.split('"').next())
}

/// Counts the data elements inside the figure's `<g class="data">` that draw
/// something: polylines with two distinct points, circles with a radius, rectangles
/// with an area.
fn drawn_elements(figure: &str) -> usize {
    let mut n = 0;
    for group in figure.split("<g class=\"data\">").skip(1) {
        let group = group.split("</g>").next().unwrap_or("");
        for tag in group.split('<').skip(1) {
            let drawn = if tag.starts_with("polyline") || tag.starts_with("polygon") {
                let pts: Vec<&str> = attr(tag, "points")
                    .unwrap_or("")
                    .split_whitespace()
                    .collect();
                pts.iter().any(|p| *p != pts[0])
            } else if tag.starts_with("circle") {
                attr(tag, "r")
                    .and_then(|r| r.parse::<f64>().ok())
                    .is_some_and(|r| r > 0.0)
            } else if tag.starts_with("rect") {
                let w = attr(tag, "width")
                    .and_then(|r| r.parse::<f64>().ok())
                    .unwrap_or(0.0);
                let h = attr(tag, "height")
                    .and_then(|r| r.parse::<f64>().ok())
                    .unwrap_or(0.0);
                w > 0.0 && h > 0.0
            } else {
                tag.starts_with("line ")
            };
            n += usize::from(drawn);
        }
    }
    n
}

fn section_ids(html: &str) -> Vec<String> {
    html.split("<section id=\"")
        .skip(1)
        .map(|s| s.split('"').next().unwrap_or("").to_string())
        .collect()
}

#[test]
fn every_section_and_figure_of_a_full_report_draws_data() {
    let html = render_html(&sample_input(300.0)).unwrap();
    assert_eq!(
        section_ids(&html),
        [
            "not-computed",
            "trajectories",
            "errors",
            "calibration",
            "drift",
            "health",
            "tedris",
            "outages"
        ]
    );
    let figs = figures(&html);
    // 1 trajectory + 6 iteration plots + 2 drift + 3 innovations + 2 NIS
    // + cross-correlation, heading, repositories, 3 outages + 1 outage evaluation
    // + its 95 % bound (issue 31) + the error against time and distance
    // (issue 34).
    assert_eq!(
        figs.len(),
        24,
        "{:?}",
        figs.iter().map(|f| &f.0).collect::<Vec<_>>()
    );
    for (name, body) in &figs {
        assert!(body.contains("<svg"), "{name}: no svg");
        let n = drawn_elements(body);
        let want = match name.as_str() {
            "trajectories" => 50, // 8 lines + GNSS points + gated crosses
            n if n.starts_with("calibration-iterations") => 7,
            "tedris-repositories" => 17,
            "tedris-cross-correlation" => 61,
            _ => 2,
        };
        assert!(
            n >= want,
            "{name}: {n} drawn data elements, want at least {want}"
        );
        // Axis descriptions with units are drawn as SVG text.
        assert!(
            body.matches("<text").count() >= 4,
            "{name}: axis text missing"
        );
    }
    for table in [
        "Calibrated parameters",
        "Dead-reckoning drift",
        "Regression model",
        "simulated outage",
    ] {
        assert!(html.contains(table), "table {table} missing");
    }
}

#[test]
fn the_page_is_self_contained() {
    let html = render_html(&sample_input(120.0)).unwrap();
    assert!(
        !html.contains("http://") && !html.contains("https://"),
        "URL in the page"
    );
    assert!(!html.contains("src="), "external resource");
    for href in html.split("href=\"").skip(1) {
        assert!(
            href.starts_with('#'),
            "link outside the page: {}",
            &href[..20.min(href.len())]
        );
    }
    assert!(html.contains("id=\"selfcheck\""));
    assert!(html.contains("Content-Security-Policy"));
}

#[test]
fn an_hour_long_drive_gives_a_small_page_with_decimated_series() {
    let mut input = sample_input(3600.0);
    // As many health series as a drive with every sensor: 9 innovations, 5 NIS.
    let health = input.health.as_mut().unwrap();
    let (gyro, wheels) = (health.innovations[0].clone(), health.nis[1].clone());
    for k in 0..6 {
        health.innovations.push(InnovationSeries {
            sensor: format!("wheel {k}"),
            ..gyro.clone()
        });
    }
    for k in 0..3 {
        health.nis.push(NisSeries {
            sensor: format!("sensor {k}"),
            ..wheels.clone()
        });
    }
    let html = render_html(&input).unwrap();
    eprintln!("one-hour page with 14 health series: {} bytes", html.len());
    assert!(html.len() < 5_000_000, "{} bytes", html.len());
    for tag in html.split("<polyline").skip(1) {
        let n = attr(tag, "points").unwrap_or("").split_whitespace().count();
        assert!(n <= MAX_POINTS + MAX_POINTS / 2, "polyline with {n} points");
    }
    for (name, body) in figures(&html) {
        let circles = body.matches("<circle").count();
        assert!(circles <= 2 * MAX_POINTS + 100, "{name}: {circles} circles");
    }
}

#[test]
fn empty_sections_are_left_out() {
    let input = ReportInput {
        trajectories: Some(Trajectories::default()),
        calibration: Some(Calibration::default()),
        drift: Some(Drift::default()),
        health: Some(FilterHealth {
            innovations: vec![InnovationSeries::default()],
            nis: vec![NisSeries {
                dof: 2,
                ..Default::default()
            }],
            ..Default::default()
        }),
        tedris: Some(Tedris::default()),
        outages: Some(OutageEvaluation {
            window_s: Some(30.0),
            methods: vec![MethodSample {
                method: "RTS".into(),
                final_error_m: vec![f64::NAN],
            }],
            bound: Some(OutageBound::default()),
        }),
        ..Default::default()
    };
    let html = render_html(&input).unwrap();
    assert!(section_ids(&html).is_empty(), "{:?}", section_ids(&html));
    assert!(figures(&html).is_empty());
    assert!(!html.contains("<nav>"));

    let html = render_html(&ReportInput::default()).unwrap();
    assert!(html.contains("(unnamed drive)"));
    assert!(figures(&html).is_empty());
}

#[test]
fn each_section_renders_alone() {
    let full = sample_input(120.0);
    let cases: Vec<(&str, ReportInput)> = vec![
        (
            "trajectories",
            ReportInput {
                trajectories: full.trajectories.clone(),
                ..Default::default()
            },
        ),
        (
            "calibration",
            ReportInput {
                calibration: full.calibration.clone(),
                ..Default::default()
            },
        ),
        (
            "drift",
            ReportInput {
                drift: full.drift.clone(),
                ..Default::default()
            },
        ),
        (
            "health",
            ReportInput {
                health: full.health.clone(),
                ..Default::default()
            },
        ),
        (
            "tedris",
            ReportInput {
                tedris: full.tedris.clone(),
                ..Default::default()
            },
        ),
        (
            "outages",
            ReportInput {
                outages: full.outages.clone(),
                ..Default::default()
            },
        ),
    ];
    for (id, input) in cases {
        let html = render_html(&input).unwrap();
        // The trajectories bring the error against the reference (issue 34).
        let want: &[&str] = if id == "trajectories" {
            &["trajectories", "errors"]
        } else {
            &[id]
        };
        assert_eq!(section_ids(&html), want);
        assert!(
            figures(&html).iter().all(|(_, b)| drawn_elements(b) > 0),
            "{id}"
        );
    }
}

#[test]
fn a_section_with_only_some_data_shows_only_that() {
    let input = ReportInput {
        trajectories: Some(Trajectories {
            gnss: Some(EnPath {
                east_m: vec![0.0, 1.0, 2.0],
                north_m: vec![0.0, 1.0, f64::NAN],
                ..Default::default()
            }),
            ..Default::default()
        }),
        calibration: Some(Calibration {
            rows: vec![CalibrationRow {
                method: "ZUPT".into(),
                values: Params::from_array([-0.002, 1.0, 0.0, 0.0, 0.0, 0.0]),
                std: None,
            }],
            ..Default::default()
        }),
        ..Default::default()
    };
    let html = render_html(&input).unwrap();
    assert_eq!(section_ids(&html), ["trajectories", "calibration"]);
    let figs = figures(&html);
    assert_eq!(
        figs.len(),
        1,
        "the calibration has a table but no iteration plots"
    );
    assert_eq!(drawn_elements(&figs[0].1), 2, "two finite GNSS fixes");
}

#[test]
fn mismatched_lengths_are_an_error_naming_the_series() {
    let input = ReportInput {
        drift: None,
        tedris: Some(Tedris {
            repositories: Some(Repositories {
                index: vec![-1, 0, 1],
                fill: vec![3, 4],
                ..Default::default()
            }),
            ..Default::default()
        }),
        ..Default::default()
    };
    match render_html(&input) {
        Err(ReportError::LengthMismatch {
            section,
            series,
            left,
            right,
        }) => {
            assert_eq!(
                (section, series.as_str(), left, right),
                ("tedris", "repositories", 3, 2)
            );
        }
        other => panic!("expected a length mismatch, got {other:?}"),
    }
}

#[test]
fn a_method_has_the_same_colour_in_every_figure() {
    let html = render_html(&sample_input(120.0)).unwrap();
    // RTS has the fixed colour #0072B2: in the trajectories, the iterations, the
    // drift histogram and the outage evaluation.
    let figs = figures(&html);
    for name in [
        "trajectories",
        "calibration-iterations-0",
        "drift-error-histogram",
        "outage-final-error",
    ] {
        let body = &figs.iter().find(|f| f.0 == name).unwrap().1;
        assert!(body.to_uppercase().contains("#0072B2"), "{name}");
    }
    assert!(html.contains("background:#0072b2"), "table swatch");
}

#[test]
fn text_from_the_input_is_escaped() {
    let mut input = ReportInput::default();
    input.header.drive_name = "<script>alert(1)</script>".into();
    input.footer.command_line = "deadreckon report \"a&b\"".into();
    let html = render_html(&input).unwrap();
    assert!(!html.contains("<script>alert"));
    assert!(html.contains("&lt;script&gt;"));
}

#[test]
fn write_report_replaces_the_file_atomically() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("report.html");
    std::fs::write(&path, "old").unwrap();
    write_report(&path, &sample_input(60.0)).unwrap();
    let html = std::fs::read_to_string(&path).unwrap();
    assert!(html.starts_with("<!DOCTYPE html>") && html.trim_end().ends_with("</html>"));
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, ["report.html"], "no temporary file left");
    let missing = dir.path().join("no/such/dir/report.html");
    assert!(matches!(
        write_report(&missing, &ReportInput::default()),
        Err(ReportError::Write(_))
    ));
}

/// Issue 12: `report` replaced a 0600 file with a 0644 one.
#[cfg(unix)]
#[test]
fn report_replacing_a_private_file_made_it_world_readable() {
    use std::os::unix::fs::PermissionsExt;
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("report.html");
    std::fs::write(&path, "old").unwrap();
    std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o600)).unwrap();
    write_report(&path, &sample_input(60.0)).unwrap();
    let mode = std::fs::metadata(&path).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode, 0o600);
    let fresh = dir.path().join("new.html");
    write_report(&fresh, &sample_input(60.0)).unwrap();
    let mode = std::fs::metadata(&fresh).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode, 0o644, "a new report is an ordinary document");
}

#[test]
fn the_input_round_trips_through_json() {
    let input = sample_input(30.0);
    let json = serde_json::to_string(&input).unwrap();
    let back: ReportInput = serde_json::from_str(&json).unwrap();
    // serde_json (without `float_roundtrip`) parses floats to within an ulp:
    // compare the structure, and the numbers to a relative 1e-12.
    assert_eq!(back.header, input.header);
    let (a, b) = (back.drift.as_ref().unwrap(), input.drift.as_ref().unwrap());
    for (x, y) in a.methods[0]
        .error_after_segment_m
        .iter()
        .zip(&b.methods[0].error_after_segment_m)
    {
        assert!((x - y).abs() <= 1e-12 * y.abs());
    }
    assert_eq!(
        back.health.unwrap().nis[0].nis.len(),
        input.health.unwrap().nis[0].nis.len()
    );
    // Sections and fields may be left out.
    let partial: ReportInput =
        serde_json::from_str(r#"{"header": {"drive_name": "x"}, "drift": {"methods": []}}"#)
            .unwrap();
    assert_eq!(partial.drift.unwrap().segment_m, 100.0);
}

#[test]
fn series_without_finite_values_give_no_empty_frames() {
    let nan = f64::NAN;
    let input = ReportInput {
        trajectories: Some(Trajectories {
            truth: Some(EnPath {
                east_m: vec![nan; 3],
                north_m: vec![1.0; 3],
                ..Default::default()
            }),
            ..Default::default()
        }),
        calibration: Some(Calibration {
            iterated_method: "RTS".into(),
            iterations: vec![Params::from_array([nan, nan, 0.0, 0.0, 0.0, 0.0]); 3],
            ..Default::default()
        }),
        health: Some(FilterHealth {
            nis: vec![NisSeries {
                sensor: "GNSS".into(),
                dof: 2,
                t_s: vec![0.0, 1.0],
                nis: vec![nan, nan],
                gated: vec![false, false],
                gate_chi2: Some(13.8),
            }],
            ..Default::default()
        }),
        tedris: Some(Tedris {
            outages: vec![OutageRun {
                name: "o".into(),
                series: vec![MethodSeries {
                    method: "TedriS".into(),
                    t_s: vec![0.0, 1.0],
                    error_m: vec![nan, nan],
                }],
            }],
            ..Default::default()
        }),
        ..Default::default()
    };
    let html = render_html(&input).unwrap();
    for (name, body) in figures(&html) {
        assert!(drawn_elements(&body) > 0, "{name} is an empty frame");
    }
    // Circumferences are 0 (finite), so only those four iteration plots remain.
    assert_eq!(section_ids(&html), ["calibration"]);
    assert_eq!(figures(&html).len(), 4);
}

/// Issue 12, the report looked at: a 59.96 s drive read "60.0 s (0 min 60 s)".
#[test]
fn a_duration_just_under_a_minute_read_0_min_60_s() {
    let mut input = sample_input(60.0);
    input.header.duration_s = Some(59.96);
    let html = render_html(&input).unwrap();
    assert!(html.contains("60.0 s (1 min 0 s)"), "no rounded duration");
    assert!(!html.contains("0 min 60 s"));
}

/// Issue 12: the trajectories were framed by a nominal dead-reckoning spiral
/// hundreds of metres off; the frame follows the anchored tracks, and the
/// wandering one is shown whole in a second figure.
#[test]
fn a_dead_reckoned_spiral_set_the_trajectory_frame() {
    let mut input = sample_input(120.0);
    let far = {
        let t = input.trajectories.as_ref().unwrap().truth.as_ref().unwrap();
        EnPath {
            east_m: t
                .east_m
                .iter()
                .enumerate()
                .map(|(k, e)| e + 5.0 * k as f64)
                .collect(),
            north_m: t.north_m.clone(),
            t_s: t.t_s.clone(),
        }
    };
    input.trajectories.as_mut().unwrap().dead_reckoned[0].path = far;
    let html = render_html(&input).unwrap();
    assert!(html.contains("trajectories-whole"), "no full-extent figure");
    assert!(
        html.contains("DR (nominal) runs out of it"),
        "the caption does not name the track"
    );
    // Without a wandering track there is one figure.
    let html = render_html(&sample_input(120.0)).unwrap();
    assert!(!html.contains("trajectories-whole"));
}

/// Issue 12: the NIS frame reached the gate (1000), flattening every NIS at 0.
#[test]
fn the_gate_flattened_the_nis_figure() {
    let html = render_html(&sample_input(120.0)).unwrap();
    assert!(
        html.contains("(above the frame)"),
        "the gate outside the frame is not named in the caption"
    );
}

/// The SVG of the named figure of a page.
fn figure<'a>(html: &'a str, name: &str) -> &'a str {
    let at = html
        .find(&format!("data-figure=\"{name}\""))
        .unwrap_or_else(|| panic!("no figure {name}"));
    let body = &html[at..];
    &body[..body.find("</figure>").expect("figure closed")]
}

/// Issue 34: the GNSS fixes were drawn before the tracks, which hid them on the
/// comma2k19 straight. Every track line must come before the first fix; only the
/// gated crosses (drawn in the gated colour) may follow.
#[test]
fn gnss_fixes_were_hidden_under_the_tracks() {
    let html = render_html(&sample_input(120.0)).unwrap();
    let fig = figure(&html, "trajectories");
    let data = fig
        .split("<g class=\"data\">")
        .nth(1)
        .and_then(|g| g.split("</g>").next())
        .expect("data group");
    let first_fix = data.find("<circle").expect("GNSS fixes drawn");
    let before = data[..first_fix].matches("<polyline").count();
    assert!(
        before >= 4,
        "the tracks come before the fixes ({before} lines)"
    );
    let gated = "#D55E00";
    for line in data[first_fix..].split("<polyline").skip(1) {
        let tag = line.split('>').next().unwrap_or("");
        assert!(
            tag.contains(gated),
            "a line drawn above the GNSS fixes that is not a gated cross: {tag}"
        );
    }
}

/// Issue 34: a filtered track that ran away (and a dead-reckoned one) set the
/// axes of the trajectory figure; the axes follow the reference and the GNSS
/// fixes, the runaway tracks are clipped and the caption names them.
#[test]
fn a_runaway_filtered_track_set_the_trajectory_axes() {
    let mut input = sample_input(120.0);
    let t = input.trajectories.as_mut().unwrap();
    let runaway = |p: &EnPath| EnPath {
        east_m: p
            .east_m
            .iter()
            .enumerate()
            .map(|(k, e)| e + 3.0 * k as f64)
            .collect(),
        north_m: p.north_m.clone(),
        t_s: p.t_s.clone(),
    };
    t.filtered = t.filtered.as_ref().map(runaway);
    let html = render_html(&input).unwrap();
    let cap = figure(&html, "trajectories");
    assert!(
        cap.contains("The frame is set by the reference and the GNSS fixes"),
        "the caption does not say what sets the frame"
    );
    assert!(
        cap.contains("filtered runs out of it and is clipped"),
        "the caption does not name the clipped track"
    );
    assert!(html.contains("trajectories-whole"), "no full-extent figure");
    // The runaway track reaches 3 m × its samples east; the frame's x ticks
    // stay within the reference's extent plus the margin and the equal-aspect
    // widening.
    let ticks_max = largest_label;
    let plain = render_html(&sample_input(120.0)).unwrap();
    assert_eq!(
        ticks_max(figure(&html, "trajectories")),
        ticks_max(figure(&plain, "trajectories")),
        "the runaway track moved the axes"
    );
}

/// The largest number among the text labels of a figure (its axis ticks).
fn largest_label(fig: &str) -> f64 {
    fig.split("<text")
        .filter_map(|t| t.split('>').nth(1))
        .filter_map(|t| t.split('<').next())
        .filter_map(|t| t.trim().parse::<f64>().ok())
        .fold(f64::NEG_INFINITY, f64::max)
}

/// Issue 34: one outlier set bins of 10 m for errors of 0.5 m, and the methods
/// shared one bar. The bins end at the 95th percentile with a labelled overflow
/// bin, and each method has its own bars that never overlap another's.
#[test]
fn one_outlier_ruled_the_histogram_bins() {
    let mut input = sample_input(120.0);
    let o = input.outages.as_mut().unwrap();
    let regular_max = o
        .methods
        .iter()
        .flat_map(|m| m.final_error_m.iter().copied())
        .fold(0.0f64, f64::max);
    o.methods[0].final_error_m[0] = 1.0e4;
    let html = render_html(&input).unwrap();
    let fig = figure(&html, "outage-final-error");
    assert!(
        fig.contains("counts every value above"),
        "the overflow bin is not explained"
    );
    let top = largest_label(fig);
    assert!(
        top < 2.0 * regular_max.max(1.0),
        "axis reaches {top} for values up to {regular_max} and one outlier"
    );
    // Bars of different methods never share an x interval.
    let data = fig
        .split("<g class=\"data\">")
        .nth(1)
        .and_then(|g| g.split("</g>").next())
        .expect("data group");
    let mut bars: Vec<(f64, f64, String)> = Vec::new();
    for tag in data.split("<rect").skip(1) {
        let tag = tag.split('>').next().unwrap_or("");
        let num = |a: &str| {
            tag.split(&format!(" {a}=\""))
                .nth(1)
                .and_then(|s| s.split('"').next())
                .and_then(|s| s.parse::<f64>().ok())
                .unwrap_or(0.0)
        };
        let fill = tag
            .split(" fill=\"")
            .nth(1)
            .and_then(|s| s.split('"').next())
            .unwrap_or("")
            .to_string();
        bars.push((num("x"), num("x") + num("width"), fill));
    }
    let methods = input.outages.as_ref().unwrap().methods.len();
    let fills: std::collections::BTreeSet<&str> = bars.iter().map(|b| b.2.as_str()).collect();
    assert_eq!(fills.len(), methods, "one bar colour per method");
    for a in &bars {
        for b in &bars {
            if a.2 != b.2 {
                assert!(
                    a.1 <= b.0 + 0.5 || b.1 <= a.0 + 0.5,
                    "bars of {} and {} overlap",
                    a.2,
                    b.2
                );
            }
        }
    }
}

/// Issue 34: innovation plots whose ±2σ bands dwarfed the points read
/// "0 outside ±2σ, expected 4.6 %" and nothing else; steering innovations were
/// in m/s without a word.
#[test]
fn a_band_that_dwarfed_the_innovations_said_nothing() {
    let mut input = sample_input(120.0);
    let h = input.health.as_mut().unwrap();
    // The sample's gyro: σ 0.0031 rad/s. A band 50 times that.
    h.innovations[0].std.iter_mut().for_each(|s| *s *= 50.0);
    let mut steering = h.innovations[0].clone();
    steering.sensor = "steering".into();
    steering.unit = "m/s".into();
    h.innovations.push(steering);
    let html = render_html(&input).unwrap();
    let gyro = figure(&html, "health-innovation-0");
    assert!(
        gyro.contains("The ±2σ band dwarfs the points"),
        "no word on the band"
    );
    // "/" is escaped in the caption's HTML.
    assert!(
        gyro.contains("rad&#x2f;s,") || gyro.contains("rad/s,"),
        "the caption's numbers have no unit"
    );
    let last = h_len(&input) - 1;
    let steer = figure(&html, &format!("health-innovation-{last}"));
    assert!(steer.contains("not an angle"), "steering unit unexplained");
    // The sample as it is (band about 2σ of the innovations) says nothing.
    let plain = render_html(&sample_input(120.0)).unwrap();
    assert!(!plain.contains("dwarfs the points"));
}

fn h_len(input: &ReportInput) -> usize {
    input.health.as_ref().unwrap().innovations.len()
}

/// Issue 34: the corrections table ran past the page: its status column did
/// not wrap, cut even at 1920 px. The status cells wrap (class `text`), the
/// numbers do not.
#[test]
fn the_corrections_status_column_did_not_wrap() {
    let mut input = sample_input(120.0);
    let c = input
        .calibration
        .as_mut()
        .and_then(|c| c.corrections.as_mut())
        .expect("the sample has corrections");
    let long = "stored in params.toml, applied; estimated on this drive too and the two differ by more than their standard errors";
    c.rows[0].status = long.into();
    let html = render_html(&input).unwrap();
    assert!(
        html.contains(&format!("<td class=\"text\">{long}</td>")),
        "the status cell does not wrap"
    );
    assert!(html.contains("th.text, td.text { white-space: normal; text-align: left"));
    assert!(
        html.contains("<th class=\"text\">status</th>"),
        "the status heading is not aligned with its cells"
    );
    assert!(html.contains("table { max-width: 100%; }"));
    // One wrapping cell per corrections row and per NEES row, no more.
    let rows = input
        .calibration
        .as_ref()
        .unwrap()
        .corrections
        .as_ref()
        .unwrap()
        .rows
        .len()
        + input
            .health
            .as_ref()
            .and_then(|h| h.consistency.as_ref())
            .map_or(0, |c| c.rows.len());
    assert_eq!(html.matches("<td class=\"text\">").count(), rows);
}

/// Issue 34: stored corrections showed "–" as their standard error without a
/// word; the caption says what the dash means when a value has no error.
#[test]
fn a_stored_correction_showed_a_dash_for_its_std() {
    let mut input = sample_input(120.0);
    let c = input
        .calibration
        .as_mut()
        .and_then(|c| c.corrections.as_mut())
        .expect("the sample has corrections");
    c.rows[0].value = Some(0.1);
    c.rows[0].std = None;
    c.rows[0].status = "stored, applied".into();
    let html = render_html(&input).unwrap();
    assert!(html.contains("–: no standard error (params.toml keeps the values it applies"));
    // With every value's error known, no such note.
    let mut input = sample_input(120.0);
    let c = input
        .calibration
        .as_mut()
        .and_then(|c| c.corrections.as_mut())
        .unwrap();
    c.rows.retain(|r| r.value.is_none() || r.std.is_some());
    let html = render_html(&input).unwrap();
    assert!(!html.contains("–: no standard error"));
}

/// Issue 31: the outage section draws error and 95 % bound against time in
/// outage, in the method's colour and the reference red, and states the
/// coverage and sharpness in the caption.
#[test]
fn the_outage_section_draws_the_error_against_its_bound_with_the_coverage() {
    let input = sample_input(120.0);
    let b = input.outages.as_ref().unwrap().bound.clone().unwrap();
    let html = render_html(&input).unwrap();
    let fig = figure(&html, "outage-bound");
    assert!(fig.to_uppercase().contains("#0072B2"), "RTS's colour");
    let caption = format!(
        "within the bound in {} of {} windows ({:.0} %)",
        b.within,
        b.time_s.len(),
        100.0 * b.within as f64 / b.time_s.len() as f64
    );
    assert!(html.contains(&caption), "no `{caption}` in the page");
    // (The page escapes the slash of "median bound / median final error".)
    assert!(html.contains("median final error 2.10"), "sharpness");
    // The sample's windows: 30 s each, so the time axis ends near 30 s.
    let top = largest_label(fig);
    assert!(top >= 30.0, "largest axis label {top}");
}

/// Issue 34: on comma2k19 the trajectory figure collapsed to one line on a
/// 1 km straight and the methods could not be told apart; each track's error
/// against the reference is drawn through time and distance, the GNSS
/// outage shaded and named in the caption.
#[test]
fn the_comma2k19_trajectory_collapsed_to_one_line() {
    let input = sample_input(600.0);
    let html = render_html(&input).unwrap();
    for name in ["error-time", "error-distance"] {
        let cap = figure(&html, name);
        assert!(cap.contains("logarithmic"), "{name}: {cap}");
        // The sample's one outage: 239.9 to 270.0 s (5 % of 600 s at 40 %).
        assert!(cap.contains("(1 of them, 30.1 s in all)"), "{name}: {cap}");
    }
    let svg = &html[html.find("data-figure=\"error-time\"").unwrap()..];
    let svg = &svg[..svg.find("</figure>").unwrap()];
    for key in ["filtered", "DR (nominal)", "DR (RTS)", "GNSS outage"] {
        assert!(svg.contains(key), "no legend entry {key}");
    }
    // Paths without times (reports written before them) draw no such figure.
    let mut old = input.clone();
    let t = old.trajectories.as_mut().unwrap();
    for p in [&mut t.truth, &mut t.gnss, &mut t.filtered, &mut t.smoothed]
        .into_iter()
        .flatten()
    {
        p.t_s.clear();
    }
    let html = render_html(&old).unwrap();
    assert!(!html.contains("error-time"));
}

/// Issue 30: the report held every innovation of a long drive (72 MB of
/// series on the bench's hour) to draw a few thousand points of each.
/// Series reduced before the report is made ([`DrawnInnovations::of`],
/// [`DrawnNis::of`]: the counts and quantiles of every observation, the
/// samples drawn) must draw the same page, byte for byte, with gated
/// observations and series longer than the figures draw.
#[test]
fn series_reduced_before_the_report_draw_the_same_page() {
    let full = sample_input(1800.0);
    let h = full.health.as_ref().expect("the sample's filter health");
    assert!(h.innovations.iter().any(|s| s.t_s.len() > 2 * MAX_POINTS));
    assert!(h.innovations.iter().any(|s| s.gated.iter().any(|g| *g)));
    let mut reduced = full.clone();
    let h = reduced.health.as_mut().expect("the sample's filter health");
    let p = h.nis_probability();
    h.drawn_innovations = h
        .innovations
        .drain(..)
        .map(|s| DrawnInnovations::of(&s).expect("a whole series"))
        .collect();
    h.drawn_nis = h
        .nis
        .drain(..)
        .map(|s| DrawnNis::of(&s, p).expect("a whole series"))
        .collect();
    assert!(h
        .drawn_innovations
        .iter()
        .all(|d| d.points.len() <= MAX_SCATTER_POINTS && d.band_t_s.len() <= MAX_POINTS));
    let (a, b) = (render_html(&full).unwrap(), render_html(&reduced).unwrap());
    assert!(a.contains("health-innovation-2") && a.contains("health-nis-1"));
    assert!(a == b, "the reduced series drew another page");
}
