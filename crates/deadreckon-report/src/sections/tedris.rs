//! The TedriS section (Bonfim et al.): cross-correlation by lag with its peak
//! (figure 8), regression models side by side (table 1), GNSS and training heading
//! over time (figure 5), repository fill, and the dead-reckoning error through each
//! outage with the threshold line (figures 6–7).

use plotters::prelude::*;

use super::{rel_time, time_desc};
use crate::charts::{lines_chart, Line};
use crate::model::{CrossCorrelation, OutageRun, Repositories, Tedris, TimeSeries};
use crate::page::{Block, FigureView, RowView, SectionView, TableView};
use crate::plot::{
    colour_name, data_begin, data_end, draw_hline, draw_vline, fmt_sig, fmt_trim, padded_range,
    render_chart, Frame, Legend, OrPlot, Palette, Swatch, GATED, REFERENCE, SMALL_WIDTH, WIDTH,
};
use crate::{check_len, ReportError};

/// Renders the section, or `None` without data.
pub(crate) fn section(
    t: &Tedris,
    start: Option<f64>,
    palette: &mut Palette,
) -> Result<Option<SectionView>, ReportError> {
    let mut blocks = Vec::new();
    if let Some(cc) = &t.cross_correlation {
        if let Some(f) = cross_correlation(cc)? {
            blocks.push(Block::Figure(f));
        }
    }
    if !t.models.is_empty() {
        blocks.push(Block::Tables {
            tables: t.models.iter().map(model_table).collect(),
        });
    }
    if let Some(f) = heading(
        t.gnss_heading_rad.as_ref(),
        t.training_heading_rad.as_ref(),
        start,
        palette,
    )? {
        blocks.push(Block::Figure(f));
    }
    if let Some(r) = &t.repositories {
        if let Some(f) = repositories(r, palette)? {
            blocks.push(Block::Figure(f));
        }
    }
    let mut figures = Vec::new();
    for (i, o) in t.outages.iter().enumerate() {
        if let Some(f) = outage(i, o, t.threshold_m, palette)? {
            figures.push(f);
        }
    }
    if !figures.is_empty() {
        blocks.push(Block::Note {
            text: format!(
                "Dead-reckoning error through each outage (figures 6–7 of the TedriS paper); {} dashed line: {} m.",
                colour_name(REFERENCE),
                fmt_trim(t.threshold_m, 3)
            ),
        });
        blocks.push(Block::Grid { figures });
    }
    if blocks.is_empty() {
        return Ok(None);
    }
    Ok(Some(SectionView {
        id: "tedris",
        title: "TedriS",
        blocks,
    }))
}

fn cross_correlation(cc: &CrossCorrelation) -> Result<Option<FigureView>, ReportError> {
    check_len(
        "tedris",
        "cross-correlation",
        cc.lag.len(),
        cc.correlation.len(),
    )?;
    let pts: Vec<(f64, f64)> = cc
        .lag
        .iter()
        .zip(&cc.correlation)
        .filter(|(_, c)| c.is_finite())
        .map(|(l, c)| (*l as f64, *c))
        .collect();
    if pts.is_empty() {
        return Ok(None);
    }
    let peak = pts
        .iter()
        .copied()
        .fold(pts[0], |a, b| if b.1.abs() > a.1.abs() { b } else { a });
    let marked = cc
        .chosen_lag
        .and_then(|l| pts.iter().copied().find(|p| p.0 == l as f64))
        .unwrap_or(peak);
    let Some(xr) = padded_range(pts.iter().map(|p| &p.0), 0.04) else {
        return Ok(None);
    };
    let lo = pts.iter().map(|p| p.1).fold(0.0f64, f64::min);
    let hi = pts.iter().map(|p| p.1).fold(0.0f64, f64::max);
    let pad = 0.08 * (hi - lo).max(0.1);
    let frame = Frame::new(
        xr,
        (lo - pad)..(hi + pad),
        "lag (samples)",
        "correlation coefficient",
    );
    let color = RGBColor(0, 114, 178);
    let label = format!("lag {}: {}", marked.0, fmt_sig(marked.1, 3));
    let what = if cc.chosen_lag.is_some() {
        "the lag the model uses"
    } else {
        "the peak"
    };
    let svg = render_chart("tedris-cross-correlation", &frame, |chart, keys| {
        draw_hline(chart, keys, 0.0, RGBColor(160, 160, 160), None)?;
        data_begin(chart)?;
        chart
            .draw_series(
                pts.iter()
                    .map(|&(l, c)| PathElement::new(vec![(l, 0.0), (l, c)], color.stroke_width(2))),
            )
            .or_plot()?;
        chart
            .draw_series(pts.iter().map(|&p| Circle::new(p, 3, color.filled())))
            .or_plot()?;
        keys.add("cross-correlation", Swatch::Dot(color));
        data_end(chart)?;
        draw_vline(chart, keys, marked.0, REFERENCE, Some(&label))?;
        chart
            .draw_series(std::iter::once(Circle::new(
                marked,
                7,
                REFERENCE.stroke_width(2),
            )))
            .or_plot()?;
        Ok(())
    })?;
    Ok(Some(FigureView {
        name: "tedris-cross-correlation".into(),
        caption: format!(
            "Cross-correlation between the GNSS yaw rate and the wheel yaw rate by lag (figure 8 of the TedriS paper); marked: {what}, {label}."
        ),
        svg,
    }))
}

/// A p value, with everything below 1e-4 as "< 0.0001".
fn p_value(p: f64) -> String {
    if p < 1e-4 {
        "< 0.0001".into()
    } else {
        format!("{p:.4}")
    }
}

fn model_table(m: &crate::model::RegressionModel) -> TableView {
    let mut rows: Vec<RowView> = m
        .coefficients
        .iter()
        .map(|c| RowView {
            swatch: None,
            cells: vec![
                c.name.clone(),
                fmt_trim(c.estimate, 6),
                fmt_trim(c.std_error, 4),
                format!("{:.2}", c.t_value),
                p_value(c.p_value),
            ],
        })
        .collect();
    rows.extend(m.statistics.iter().map(|s| RowView {
        swatch: None,
        cells: vec![
            s.name.clone(),
            // The tests' p values as the coefficients' ("0" read as exact).
            if s.name.ends_with(" p") {
                p_value(s.value)
            } else {
                fmt_trim(s.value, 4)
            },
            String::new(),
            String::new(),
            String::new(),
        ],
    }));
    TableView {
        caption: format!("Regression model: {}", m.name),
        headers: ["coefficient", "estimate", "std error", "t value", "p value"]
            .map(String::from)
            .to_vec(),
        rows,
        text_column: None,
    }
}

/// Removes the 2π jumps of a heading sequence, in degrees.
fn unwrap_deg(rad: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(rad.len());
    let mut offset = 0.0;
    let mut prev: Option<f64> = None;
    for &a in rad {
        if !a.is_finite() {
            out.push(f64::NAN);
            continue;
        }
        if let Some(p) = prev {
            let tau = std::f64::consts::TAU;
            offset -= tau * ((a - p) / tau).round();
        }
        prev = Some(a);
        out.push((a + offset).to_degrees());
    }
    out
}

fn heading(
    gnss: Option<&TimeSeries>,
    training: Option<&TimeSeries>,
    start: Option<f64>,
    palette: &mut Palette,
) -> Result<Option<FigureView>, ReportError> {
    let mut series = Vec::new();
    // As in the paper: the GNSS heading wide and dark, the training heading thin on top.
    for (name, s, color, width) in [
        ("GNSS heading", gnss, RGBColor(0, 0, 0), 4),
        ("training heading", training, palette.color("TedriS"), 2),
    ] {
        if let Some(s) = s.filter(|s| !s.t_s.is_empty()) {
            check_len("tedris", name, s.t_s.len(), s.value.len())?;
            series.push((
                name,
                rel_time(&s.t_s, start),
                unwrap_deg(&s.value),
                color,
                width,
            ));
        }
    }
    if series.is_empty() {
        return Ok(None);
    }
    // Start both at the same turn: shift the training heading by whole turns onto the GNSS heading.
    if series.len() == 2 {
        let a = series[0].2.iter().find(|v| v.is_finite()).copied();
        let b = series[1].2.iter().find(|v| v.is_finite()).copied();
        if let (Some(a), Some(b)) = (a, b) {
            let k = ((a - b) / 360.0).round() * 360.0;
            series[1].2.iter_mut().for_each(|v| *v += k);
        }
    }
    let lines: Vec<Line<'_>> = series
        .iter()
        .map(|(name, t, v, c, w)| Line {
            name: name.to_string(),
            color: *c,
            width: *w,
            t,
            v,
        })
        .collect();
    let Some(svg) = lines_chart(
        "tedris-heading",
        &lines,
        time_desc(start),
        "heading, unwrapped (deg)",
        &[],
        (WIDTH, 320),
        Legend::Right,
    )?
    else {
        return Ok(None);
    };
    Ok(Some(FigureView {
        name: "tedris-heading".into(),
        caption: "GNSS heading and the heading reconstructed by the TedriS training phase (figure 5 of the TedriS paper), unwrapped.".into(),
        svg,
    }))
}

fn repositories(
    r: &Repositories,
    palette: &mut Palette,
) -> Result<Option<FigureView>, ReportError> {
    check_len("tedris", "repositories", r.index.len(), r.fill.len())?;
    if r.index.is_empty() {
        return Ok(None);
    }
    let xs = r.index.iter().map(|i| *i as f64).collect::<Vec<_>>();
    let lo = xs.iter().copied().fold(f64::INFINITY, f64::min) - 0.7;
    let hi = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max) + 0.7;
    let top = r
        .fill
        .iter()
        .copied()
        .chain(r.min_fill)
        .chain(r.max_fill)
        .max()
        .unwrap_or(1)
        .max(1) as f64
        * 1.15;
    let frame = Frame::new(
        lo..hi,
        0.0..top,
        "repository index n (R_n)",
        "stored tuples",
    )
    .x_integer();
    let color = palette.color("TedriS");
    let below = |f: u64| r.min_fill.is_some_and(|m| f < m);
    let n_below = r.fill.iter().filter(|f| below(**f)).count();
    let svg = render_chart("tedris-repositories", &frame, |chart, keys| {
        data_begin(chart)?;
        chart
            .draw_series(xs.iter().zip(&r.fill).map(|(&x, &f)| {
                let c = if below(f) { GATED } else { color };
                Rectangle::new([(x - 0.38, 0.0), (x + 0.38, f as f64)], c.mix(0.8).filled())
            }))
            .or_plot()?;
        keys.add("fill", Swatch::Bar(color));
        data_end(chart)?;
        if let Some(m) = r.min_fill {
            draw_hline(
                chart,
                keys,
                m as f64,
                REFERENCE,
                Some(&format!("min fill {m}")),
            )?;
        }
        if let Some(m) = r.max_fill {
            draw_hline(
                chart,
                keys,
                m as f64,
                RGBColor(90, 90, 90),
                Some(&format!("max fill {m}")),
            )?;
        }
        Ok(())
    })?;
    let mut caption = format!(
        "Fill of the {} TedriS repositories: {} tuples stored",
        r.index.len(),
        r.fill.iter().sum::<u64>()
    );
    if r.min_fill.is_some() {
        caption.push_str(&format!(
            "; {n_below} below the minimum fill ({})",
            colour_name(GATED)
        ));
    }
    caption.push('.');
    Ok(Some(FigureView {
        name: "tedris-repositories".into(),
        caption,
        svg,
    }))
}

fn outage(
    i: usize,
    o: &OutageRun,
    threshold_m: f64,
    palette: &mut Palette,
) -> Result<Option<FigureView>, ReportError> {
    let mut rel = Vec::new();
    for s in &o.series {
        check_len(
            "tedris",
            &format!("{} {}", o.name, s.method),
            s.t_s.len(),
            s.error_m.len(),
        )?;
        rel.push((s, palette.color(&s.method)));
    }
    let t0 = o
        .series
        .iter()
        .flat_map(|s| s.t_s.iter())
        .copied()
        .filter(|t| t.is_finite())
        .fold(f64::INFINITY, f64::min);
    if !t0.is_finite() {
        return Ok(None);
    }
    let times: Vec<Vec<f64>> = o
        .series
        .iter()
        .map(|s| rel_time(&s.t_s, Some(t0)))
        .collect();
    let lines: Vec<Line<'_>> = rel
        .iter()
        .zip(&times)
        .map(|((s, c), t)| Line {
            name: s.method.clone(),
            color: *c,
            width: 2,
            t,
            v: &s.error_m,
        })
        .collect();
    let name = format!("tedris-outage-{i}");
    let Some(svg) = lines_chart(
        &name,
        &lines,
        "time since outage start (s)",
        "horizontal error (m)",
        &[(
            threshold_m,
            REFERENCE,
            format!("{} m", fmt_trim(threshold_m, 3)),
        )],
        (SMALL_WIDTH, 260),
        Legend::Inside(SeriesLabelPosition::UpperLeft),
    )?
    else {
        return Ok(None);
    };
    let finals: Vec<String> = o
        .series
        .iter()
        .filter_map(|s| {
            let last = s.error_m.iter().rev().find(|v| v.is_finite())?;
            Some(format!("{} {} m", s.method, fmt_sig(*last, 3)))
        })
        .collect();
    Ok(Some(FigureView {
        name,
        caption: format!("{}: final error {}.", o.name, finals.join(", ")),
        svg,
    }))
}
