//! The trajectories figure (figure 6 of the four-wheel paper): truth, GNSS fixes,
//! filtered, smoothed and dead-reckoned tracks in the east-north plane, with equal
//! metres per pixel on both axes.

use plotters::prelude::*;

use crate::model::{EnPath, Trajectories};
use crate::page::{Block, FigureView, SectionView};
use crate::plot::{
    data_begin, data_end, draw_line, equal_aspect, padded_range, render_chart, segments, Frame,
    Legend, OrPlot, Palette, Swatch, GATED, LEGEND_WIDTH, WIDTH,
};
use crate::stats::stride_indices;
use crate::{check_len, ReportError, MAX_POINTS};

/// The reference trajectory: a wide light band.
const REFERENCE_BAND: RGBColor = RGBColor(200, 200, 200);

fn has_points(p: &EnPath) -> bool {
    p.east_m
        .iter()
        .zip(&p.north_m)
        .any(|(e, n)| e.is_finite() && n.is_finite())
}

fn usable(p: &Option<EnPath>) -> Option<&EnPath> {
    p.as_ref().filter(|p| has_points(p))
}

/// Renders the section, or `None` when no path has data.
pub(crate) fn section(
    t: &Trajectories,
    palette: &mut Palette,
) -> Result<Option<SectionView>, ReportError> {
    let reference = usable(&t.truth);
    let mut lines: Vec<(String, &EnPath, u32)> = Vec::new();
    for (name, p) in [("filtered", &t.filtered), ("smoothed", &t.smoothed)] {
        if let Some(p) = usable(p) {
            lines.push((name.to_string(), p, 2));
        }
    }
    for m in &t.dead_reckoned {
        if has_points(&m.path) {
            lines.push((format!("DR ({})", m.method), &m.path, 2));
        }
    }
    let gnss = usable(&t.gnss);
    let gated = usable(&t.gnss_gated);
    let named = lines
        .iter()
        .map(|(n, p, _)| (n.as_str(), *p))
        .chain(reference.map(|p| ("truth", p)))
        .chain(gnss.map(|p| ("GNSS", p)))
        .chain(gated.map(|p| ("gated GNSS", p)));
    for (name, p) in named {
        check_len("trajectories", name, p.east_m.len(), p.north_m.len())?;
    }
    if lines.is_empty() && reference.is_none() && gnss.is_none() && gated.is_none() {
        return Ok(None);
    }
    let shown = || {
        lines
            .iter()
            .map(|(_, p, _)| *p)
            .chain(reference)
            .chain(gnss)
    };
    let all_e = shown().flat_map(|p| p.east_m.iter());
    let all_n = shown().flat_map(|p| p.north_m.iter());
    let (Some(xr), Some(yr)) = (padded_range(all_e, 0.04), padded_range(all_n, 0.04)) else {
        return Ok(None);
    };
    // The height follows the shape of the drive, within limits; then one metre gets
    // the same number of pixels on both axes.
    let aspect = (yr.end - yr.start) / (xr.end - xr.start);
    // The most important figure gets a little more width than the others.
    let width = WIDTH + 100;
    let height = ((f64::from(width - LEGEND_WIDTH) * aspect) as u32).clamp(420, 760);
    let mut frame = Frame::new(xr.clone(), yr.clone(), "east (m)", "north (m)")
        .size(width, height)
        .legend(Legend::Right);
    (frame.x, frame.y) = equal_aspect(xr, yr, frame.plot_area_px());
    let mut colors: Vec<RGBColor> = Vec::new();
    for (name, _, _) in &lines {
        let key = name
            .strip_prefix("DR (")
            .and_then(|s| s.strip_suffix(')'))
            .unwrap_or(name);
        colors.push(palette.color(key));
    }
    let gnss_color = palette.color("GNSS");
    let mut counts = Vec::new();
    let svg = render_chart("trajectories", &frame, |chart, keys| {
        data_begin(chart)?;
        if let Some(r) = reference {
            // The reference as a wide light band under everything else.
            let idx = stride_indices(r.east_m.len(), MAX_POINTS);
            draw_line(
                chart,
                keys,
                segments(&r.east_m, &r.north_m, &idx),
                REFERENCE_BAND,
                7,
                Some("truth (reference)"),
            )?;
        }
        if let Some(g) = gnss {
            let idx = stride_indices(g.east_m.len(), MAX_POINTS);
            let pts: Vec<(f64, f64)> = segments(&g.east_m, &g.north_m, &idx).concat();
            counts.push(format!("{} GNSS fixes used", g.east_m.len()));
            chart
                .draw_series(
                    pts.into_iter()
                        .map(|p| Circle::new(p, 1, gnss_color.mix(0.7).filled())),
                )
                .or_plot()?;
            keys.add("GNSS fixes", Swatch::Dot(gnss_color));
        }
        for ((name, p, w), c) in lines.iter().zip(&colors) {
            let idx = stride_indices(p.east_m.len(), MAX_POINTS);
            draw_line(
                chart,
                keys,
                segments(&p.east_m, &p.north_m, &idx),
                *c,
                *w,
                Some(name),
            )?;
        }
        if let Some(g) = gated {
            let idx = stride_indices(g.east_m.len(), MAX_POINTS);
            let pts: Vec<(f64, f64)> = segments(&g.east_m, &g.north_m, &idx).concat();
            counts.push(format!(
                "{} GNSS fixes rejected by the gate",
                g.east_m.len()
            ));
            chart
                .draw_series(
                    pts.into_iter()
                        .map(|p| Cross::new(p, 4, GATED.stroke_width(2))),
                )
                .or_plot()?;
            keys.add("gated GNSS fixes", Swatch::Cross(GATED));
        }
        data_end(chart)
    })?;
    let mut caption = "Trajectories in the local east-north frame, equal scales on both axes. DR: dead reckoning \
                       from the start with each calibration (figure 6 of the four-wheel paper)."
        .to_string();
    if !counts.is_empty() {
        caption.push(' ');
        caption.push_str(&counts.join(", "));
        caption.push('.');
    }
    Ok(Some(SectionView {
        id: "trajectories",
        title: "Trajectories",
        blocks: vec![Block::Figure(FigureView {
            name: "trajectories".into(),
            caption,
            svg,
        })],
    }))
}
