//! Filter health: the innovations of each sensor over time with their predicted
//! ±2σ, and the normalised innovation squared (NIS) with its two-sided chi-square
//! bounds and the gate, observations rejected by the gate marked and counted.

use plotters::prelude::*;

use super::{rel_time, time_desc};
use crate::model::{
    DrawnInnovations, DrawnNis, FilterHealth, InnovationSeries, NisSeries, WideBand,
};
use crate::page::{Block, FigureView, RowView, SectionView, TableView};
use crate::plot::{
    data_begin, data_end, draw_hline, fmt_sig, padded_range, render_chart, segments, Frame, Legend,
    OrPlot, Swatch, GATED, REFERENCE, WIDTH,
};
use crate::stats::{chi2_quantile, minmax_indices, quantile_sorted, sorted_finite, stride_indices};
use crate::{check_len, check_optional_len, ReportError, MAX_POINTS, MAX_SCATTER_POINTS};

const LINE: RGBColor = RGBColor(0, 114, 178);
const BAND: RGBColor = RGBColor(60, 60, 60);

/// Renders the section, or `None` without series.
pub(crate) fn section(
    h: &FilterHealth,
    start: Option<f64>,
) -> Result<Option<SectionView>, ReportError> {
    let mut blocks = Vec::new();
    if let Some(c) = &h.consistency {
        blocks.push(Block::Note {
            text: format!(
                "Consistency through {} s dead-reckoning windows (NEES against the truth, 95 % bounds of the average over the windows): {}.",
                fmt_sig(c.outage_s, 3),
                c.summary
            ),
        });
        blocks.push(Block::Tables {
            tables: vec![TableView {
                caption: "NEES: pose (x, y, yaw; 3 dof) and motion (speed, yaw rate; 2 dof), averaged over the windows at a fraction of each.".into(),
                headers: ["block", "at", "windows", "NEES", "95 % bounds", "verdict"]
                    .map(String::from)
                    .to_vec(),
                rows: c
                    .rows
                    .iter()
                    .map(|r| RowView {
                        swatch: None,
                        cells: vec![
                            format!("{} ({} dof)", r.block, r.dof),
                            format!("{:.0} %", 100.0 * r.fraction),
                            r.windows.to_string(),
                            format!("{:.2}", r.nees),
                            format!("{:.2} – {:.2}", r.lower, r.upper),
                            r.verdict.clone(),
                        ],
                    })
                    .collect(),
                text_column: Some(5),
            }],
        });
    }
    if !h.wheel_health.is_empty() {
        blocks.push(Block::Note {
            text: format!("Wheel health: {}", h.wheel_health.join("; ")),
        });
    }
    // The full series reduced here, then those reduced by whoever made
    // them (the same figures either way).
    let innovations = h
        .innovations
        .iter()
        .map(DrawnInnovations::of)
        .collect::<Result<Vec<_>, _>>()?;
    for (i, d) in innovations.iter().chain(&h.drawn_innovations).enumerate() {
        if let Some(f) = innovation_figure(i, d, start)? {
            blocks.push(Block::Figure(f));
        }
    }
    let p = h.nis_probability();
    let nis = h
        .nis
        .iter()
        .map(|s| DrawnNis::of(s, p))
        .collect::<Result<Vec<_>, _>>()?;
    for (i, d) in nis.iter().chain(&h.drawn_nis).enumerate() {
        if let Some(f) = nis_figure(i, d, start)? {
            blocks.push(Block::Figure(f));
        }
    }
    if blocks.is_empty() {
        return Ok(None);
    }
    Ok(Some(SectionView {
        id: "health",
        title: "Filter health",
        blocks,
    }))
}

impl FilterHealth {
    /// The two-sided probability of the NIS bounds drawn
    /// (`nis_bound_probability`, 0.95 without it, within 0.5–0.999999).
    pub fn nis_probability(&self) -> f64 {
        self.nis_bound_probability
            .unwrap_or(0.95)
            .clamp(0.5, 0.999_999)
    }
}

/// The first and last finite value of `t`, by value.
fn finite_span(t: &[f64]) -> Option<(f64, f64)> {
    t.iter()
        .filter(|v| v.is_finite())
        .fold(None, |s, &v| match s {
            None => Some((v, v)),
            Some((a, b)) => Some((f64::min(a, v), f64::max(b, v))),
        })
}

/// The x range of a figure whose times span `span` (as `padded_range` of
/// every time less `start`: subtracting a constant keeps the extremes).
fn time_range(span: Option<(f64, f64)>, start: Option<f64>) -> Option<std::ops::Range<f64>> {
    let s = start.unwrap_or(0.0);
    let (a, b) = span?;
    padded_range([a - s, b - s].iter(), 0.0)
}

/// The gated observations drawn: at most [`MAX_POINTS`] of them, evenly,
/// those with a finite time and value.
fn gated_points(t: &[f64], v: &[f64], gated: &[bool]) -> (Vec<f64>, Vec<f64>) {
    let idx: Vec<usize> = (0..t.len())
        .filter(|&i| gated.get(i).copied().unwrap_or(false))
        .collect();
    let keep = stride_indices(idx.len(), MAX_POINTS);
    keep.into_iter()
        .map(|k| idx[k])
        .filter(|&i| t[i].is_finite() && v[i].is_finite())
        .map(|i| (t[i], v[i]))
        .unzip()
}

/// `v` at `idx`.
fn at(v: &[f64], idx: &[usize]) -> Vec<f64> {
    idx.iter().map(|&i| v[i]).collect()
}

impl DrawnInnovations {
    /// What the figure of `s` draws and its caption says, from every
    /// observation (an error when its columns and times differ in length).
    pub fn of(s: &InnovationSeries) -> Result<DrawnInnovations, ReportError> {
        let n = s.t_s.len();
        check_len("health", &s.sensor, n, s.innovation.len())?;
        check_optional_len("health", &format!("{} std", s.sensor), n, s.std.len())?;
        check_optional_len("health", &format!("{} gated", s.sensor), n, s.gated.len())?;
        let accepted: Vec<f64> = s
            .innovation
            .iter()
            .enumerate()
            .map(|(k, v)| {
                if s.gated.get(k).copied().unwrap_or(false) {
                    f64::NAN
                } else {
                    *v
                }
            })
            .collect();
        let upper: Vec<f64> = s.std.iter().map(|x| 2.0 * x).collect();
        // The y range covers the accepted innovations and the band; gated outliers are
        // drawn clamped to the edge so they do not squash the rest.
        let sorted = sorted_finite(&accepted);
        let lim = if sorted.is_empty() {
            sorted_finite(&s.innovation)
                .iter()
                .fold(0.0f64, |a, b| a.max(b.abs()))
        } else {
            quantile_sorted(&sorted, 0.999)
                .abs()
                .max(quantile_sorted(&sorted, 0.001).abs())
        };
        drop(sorted);
        let band = sorted_finite(&upper);
        let lim = lim.max(if band.is_empty() {
            0.0
        } else {
            quantile_sorted(&band, 0.99)
        });
        drop(band);
        let half_range = if lim > 0.0 { 1.15 * lim } else { 1.0 };
        // The band's minimum and maximum in each of MAX_POINTS / 2 buckets;
        // the points thinned evenly so the cloud keeps its shape (a min–max
        // envelope would paint noise as a solid block).
        let iu = minmax_indices(&upper, MAX_POINTS);
        let idx = stride_indices(accepted.len(), MAX_SCATTER_POINTS);
        let (gated_t_s, gated_values) = gated_points(&s.t_s, &s.innovation, &s.gated);
        let outside = (0..n)
            .filter(|&k| !s.gated.get(k).copied().unwrap_or(false))
            .filter(|&k| {
                s.std
                    .get(k)
                    .is_some_and(|sd| s.innovation[k].abs() > 2.0 * sd)
            })
            .count();
        Ok(DrawnInnovations {
            sensor: s.sensor.clone(),
            unit: s.unit.clone(),
            observations: n,
            gated: s.gated.iter().filter(|g| **g).count(),
            outside_two_sigma: outside,
            has_std: !s.std.is_empty(),
            has_gated: !s.gated.is_empty(),
            span_s: finite_span(&s.t_s),
            half_range,
            band_t_s: if upper.is_empty() {
                Vec::new()
            } else {
                at(&s.t_s, &iu)
            },
            band_two_sigma: at(&upper, &iu),
            points_t_s: at(&s.t_s, &idx),
            points: at(&accepted, &idx),
            gated_t_s,
            gated_values,
            wide_band: wide_band(&accepted, &s.std),
        })
    }
}

fn innovation_figure(
    i: usize,
    d: &DrawnInnovations,
    start: Option<f64>,
) -> Result<Option<FigureView>, ReportError> {
    let n = d.observations;
    let Some(xr) = time_range(d.span_s, start) else {
        return Ok(None);
    };
    let lim = d.half_range;
    let yr = -lim..lim;
    let gated: Vec<(f64, f64)> = rel_time(&d.gated_t_s, start)
        .into_iter()
        .zip(d.gated_values.iter().copied())
        .collect();
    let n_gated = d.gated;
    let unit = if d.unit.is_empty() {
        String::new()
    } else {
        format!(" ({})", d.unit)
    };
    let frame = Frame::new(
        xr,
        yr.clone(),
        time_desc(start),
        format!("innovation{unit}"),
    )
    .size(WIDTH, 250)
    .legend(Legend::Right);
    let name = format!("health-innovation-{i}");
    let svg = render_chart(&name, &frame, |chart, keys| {
        if d.has_std {
            // The ±2σ band as a light area under the points: a predicted σ that
            // changes from one sample to the next (front wheels at large
            // steering angles) drawn as two lines painted a solid black block.
            let t = rel_time(&d.band_t_s, start);
            let lower: Vec<f64> = d.band_two_sigma.iter().map(|x| -x).collect();
            let all: Vec<usize> = (0..t.len()).collect();
            let ups = segments(&t, &d.band_two_sigma, &all);
            let lows = segments(&t, &lower, &all);
            let fill = BAND.mix(0.16).filled();
            chart
                .draw_series(ups.iter().zip(&lows).map(|(u, l)| {
                    let ring: Vec<(f64, f64)> = u.iter().chain(l.iter().rev()).copied().collect();
                    Polygon::new(ring, fill)
                }))
                .or_plot()?;
            keys.add("±2σ predicted", Swatch::Bar(RGBColor(205, 205, 205)));
        }
        data_begin(chart)?;
        let t = rel_time(&d.points_t_s, start);
        let all: Vec<usize> = (0..t.len()).collect();
        let pts: Vec<(f64, f64)> = segments(&t, &d.points, &all).concat();
        chart
            .draw_series(
                pts.into_iter()
                    .map(|q| Circle::new(q, 1, LINE.mix(0.8).filled())),
            )
            .or_plot()?;
        keys.add(d.sensor.clone(), Swatch::Dot(LINE));
        if !gated.is_empty() {
            let clamp = |v: f64| v.clamp(yr.start, yr.end);
            chart
                .draw_series(
                    gated
                        .iter()
                        .map(|&(x, v)| Cross::new((x, clamp(v)), 4, GATED.stroke_width(2))),
                )
                .or_plot()?;
            keys.add("gated", Swatch::Cross(GATED));
        }
        data_end(chart)
    })?;
    let outside = d.outside_two_sigma;
    let mut caption = format!("Innovations of {}{unit}: {n} observations", d.sensor);
    if d.has_std {
        caption.push_str(&format!(
            ", {outside} ({:.1}%) of the accepted outside ±2σ (expected about 4.6%)",
            100.0 * outside as f64 / (n - n_gated).max(1) as f64
        ));
    }
    if d.has_gated {
        caption.push_str(&format!(
            ", {n_gated} rejected by the gate (crosses, clamped to the frame)"
        ));
    }
    caption.push('.');
    if d.sensor == "steering" && d.unit == "m/s" {
        caption.push_str(
            " The steering innovation is in m/s, not an angle: eq. (7)'s pseudo-measurement \
             v·tan δ against the model l·ψ̇ (a lateral speed at the front axle).",
        );
    }
    if let Some(w) = &d.wide_band {
        let u = if d.unit.is_empty() {
            String::new()
        } else {
            format!(" {}", d.unit)
        };
        caption.push_str(&format!(
            " The ±2σ band dwarfs the points: its median half-width is {}{u}, {:.0} times the \
             95th percentile of |innovation| ({}{u}). The predicted spread (state uncertainty \
             plus this sensor's noise setting) is far wider than what is observed, so the \
             count outside ±2σ says little here; the consistency of the state itself is the \
             NEES table's.",
            fmt_sig(w.band_half_width, 3),
            w.ratio,
            fmt_sig(w.p95_abs, 3),
        ));
    }
    Ok(Some(FigureView { name, caption, svg }))
}

/// Ratio of the band's median half-width 2σ to the 95th percentile of the
/// accepted |innovation| above which the caption says the band dwarfs the points.
const WIDE_BAND_RATIO: f64 = 4.0;

/// `Some` when the median 2σ is more than [`WIDE_BAND_RATIO`] times the 95th
/// percentile of the accepted |innovation|.
fn wide_band(accepted: &[f64], std: &[f64]) -> Option<WideBand> {
    let abs: Vec<f64> = accepted.iter().map(|v| v.abs()).collect();
    let abs = sorted_finite(&abs);
    let two_sigma = sorted_finite(&std.iter().map(|s| 2.0 * s).collect::<Vec<_>>());
    if abs.is_empty() || two_sigma.is_empty() {
        return None;
    }
    let p95_abs = quantile_sorted(&abs, 0.95);
    let band_half_width = quantile_sorted(&two_sigma, 0.5);
    let ratio = band_half_width / p95_abs;
    (p95_abs > 0.0 && ratio > WIDE_BAND_RATIO).then_some(WideBand {
        band_half_width,
        p95_abs,
        ratio,
    })
}

/// The two-sided `p` chi-square bounds of `dof` degrees of freedom.
fn nis_bounds(p: f64, dof: u32) -> (f64, f64) {
    (
        chi2_quantile(0.5 * (1.0 - p), dof),
        chi2_quantile(0.5 * (1.0 + p), dof),
    )
}

impl DrawnNis {
    /// What the figure of `s` draws and its caption says, from every
    /// observation, against the two-sided bounds of probability `p`
    /// ([`FilterHealth::nis_probability`]; an error when its columns and
    /// times differ in length).
    pub fn of(s: &NisSeries, p: f64) -> Result<DrawnNis, ReportError> {
        let n = s.t_s.len();
        check_len("health", &format!("{} NIS", s.sensor), n, s.nis.len())?;
        check_optional_len(
            "health",
            &format!("{} NIS gated", s.sensor),
            n,
            s.gated.len(),
        )?;
        let dof = s.dof.max(1);
        let (lo, hi) = nis_bounds(p, dof);
        let is_gated = |k: usize| s.gated.get(k).copied().unwrap_or(false);
        let accepted: Vec<f64> = s
            .nis
            .iter()
            .enumerate()
            .map(|(k, v)| if is_gated(k) { f64::NAN } else { *v })
            .collect();
        let acc_sorted = sorted_finite(&accepted);
        let drawable = !acc_sorted.is_empty() || s.nis.iter().any(|v| v.is_finite());
        let inside = acc_sorted.iter().filter(|v| **v >= lo && **v <= hi).count();
        let mean = if acc_sorted.is_empty() {
            f64::NAN
        } else {
            acc_sorted.iter().sum::<f64>() / acc_sorted.len() as f64
        };
        let p99 = if acc_sorted.is_empty() {
            0.0
        } else {
            quantile_sorted(&acc_sorted, 0.99)
        };
        let idx = stride_indices(accepted.len(), MAX_SCATTER_POINTS);
        let (gated_t_s, gated_values) = gated_points(&s.t_s, &s.nis, &s.gated);
        Ok(DrawnNis {
            sensor: s.sensor.clone(),
            dof: s.dof,
            gate_chi2: s.gate_chi2,
            probability: p,
            observations: n,
            gated: (0..n).filter(|&k| is_gated(k)).count(),
            has_gated: !s.gated.is_empty(),
            accepted: acc_sorted.len(),
            inside,
            mean,
            p99,
            span_s: finite_span(&s.t_s).filter(|_| drawable),
            points_t_s: at(&s.t_s, &idx),
            points: at(&accepted, &idx),
            gated_t_s,
            gated_values,
        })
    }
}

fn nis_figure(
    i: usize,
    d: &DrawnNis,
    start: Option<f64>,
) -> Result<Option<FigureView>, ReportError> {
    let n = d.observations;
    let Some(xr) = time_range(d.span_s, start) else {
        return Ok(None);
    };
    let p = d.probability;
    let dof = d.dof.max(1);
    let (lo, hi) = nis_bounds(p, dof);
    let inside = d.inside;
    let mean = d.mean;
    let n_gated = d.gated;
    // y from 0 to above the upper bound and gate, and most accepted values; larger
    // values are clamped to the top edge.
    let p99 = d.p99;
    // The gate (often 1000) is not in the range: it squashed every NIS to a
    // flat line at 0. It is drawn when it falls inside, and named otherwise.
    let top = hi.max(p99) * 1.15;
    let yr = 0.0..top;
    let clamped: Vec<f64> = d.points.iter().map(|v| v.min(top)).collect();
    let gated: Vec<(f64, f64)> = rel_time(&d.gated_t_s, start)
        .into_iter()
        .zip(d.gated_values.iter().copied())
        .collect();
    let frame = Frame::new(xr, yr, time_desc(start), format!("NIS ({dof} dof)"))
        .size(WIDTH, 260)
        .legend(Legend::Right);
    let name = format!("health-nis-{i}");
    let pc = format!("{:.0}", 100.0 * p);
    let svg = render_chart(&name, &frame, |chart, keys| {
        draw_hline(
            chart,
            keys,
            hi,
            BAND,
            Some(&format!("{pc}% bounds χ²({dof})")),
        )?;
        draw_hline(chart, keys, lo, BAND, None)?;
        if let Some(g) = d.gate_chi2.filter(|g| *g <= top) {
            draw_hline(chart, keys, g, REFERENCE, Some("gate"))?;
        }
        data_begin(chart)?;
        let t = rel_time(&d.points_t_s, start);
        let all: Vec<usize> = (0..t.len()).collect();
        let pts: Vec<(f64, f64)> = segments(&t, &clamped, &all).concat();
        chart
            .draw_series(
                pts.into_iter()
                    .map(|q| Circle::new(q, 1, LINE.mix(0.8).filled())),
            )
            .or_plot()?;
        keys.add(format!("NIS {}", d.sensor), Swatch::Dot(LINE));
        if !gated.is_empty() {
            chart
                .draw_series(
                    gated
                        .iter()
                        .map(|&(x, v)| Cross::new((x, v.min(top)), 4, GATED.stroke_width(2))),
                )
                .or_plot()?;
            keys.add("gated", Swatch::Cross(GATED));
        }
        data_end(chart)
    })?;
    let mut caption = format!(
        "NIS of {} ({dof} {}): {n} observations; of the {} accepted, {inside} ({:.1}%) inside the \
         two-sided {pc}% chi-square bounds [{}, {}]; mean {} (expected {dof})",
        d.sensor,
        if dof == 1 {
            "degree of freedom"
        } else {
            "degrees of freedom"
        },
        d.accepted,
        100.0 * inside as f64 / d.accepted.max(1) as f64,
        fmt_sig(lo, 3),
        fmt_sig(hi, 3),
        fmt_sig(mean, 3)
    );
    if d.has_gated {
        caption.push_str(&format!("; {n_gated} rejected by the gate (crosses)"));
    }
    if let Some(g) = d.gate_chi2.filter(|g| *g > top) {
        caption.push_str(&format!(
            "; the gate is at {} (above the frame)",
            fmt_sig(g, 3)
        ));
    }
    caption.push_str(". Values above the frame are drawn at its top edge.");
    Ok(Some(FigureView { name, caption, svg }))
}
