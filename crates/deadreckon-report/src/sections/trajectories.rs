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
    // The frame covers what is anchored to the ground (the reference, the
    // GNSS fixes, the filtered and smoothed tracks); a dead-reckoned track that
    // wanders far beyond it (nominal parameters: a spiral hundreds of metres
    // off) is clipped there and shown whole in a second, small figure.
    let anchored: Vec<&EnPath> = lines
        .iter()
        .filter(|(n, _, _)| !n.starts_with("DR ("))
        .map(|(_, p, _)| *p)
        .chain(reference)
        .chain(gnss)
        .collect();
    let everything: Vec<&EnPath> = lines
        .iter()
        .map(|(_, p, _)| *p)
        .chain(reference)
        .chain(gnss)
        .collect();
    let extent = |paths: &[&EnPath]| {
        let e = paths.iter().flat_map(|p| p.east_m.iter());
        let n = paths.iter().flat_map(|p| p.north_m.iter());
        padded_range(e, 0.04).zip(padded_range(n, 0.04))
    };
    let Some((all_x, all_y)) = extent(&everything) else {
        return Ok(None);
    };
    let (xr, yr) = match extent(&anchored) {
        Some((x, y)) => (x, y),
        None => (all_x.clone(), all_y.clone()),
    };
    let span = |r: &std::ops::Range<f64>| r.end - r.start;
    let outside: Vec<&str> = lines
        .iter()
        .filter(|(_, p, _)| {
            p.east_m.iter().zip(&p.north_m).any(|(e, n)| {
                let (dx, dy) = (0.5 * span(&xr), 0.5 * span(&yr));
                *e < xr.start - dx || *e > xr.end + dx || *n < yr.start - dy || *n > yr.end + dy
            })
        })
        .map(|(n, _, _)| n.as_str())
        .collect();
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
    let draw_all = |frame: &Frame, name: &str, counts: &mut Vec<String>| {
        render_chart(name, frame, |chart, keys| {
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
                // Points outside the frame break the line (plotters would draw
                // them along the frame's edge).
                let inside = |e: f64, n: f64| frame.x.contains(&e) && frame.y.contains(&n);
                let (east, north): (Vec<f64>, Vec<f64>) = p
                    .east_m
                    .iter()
                    .zip(&p.north_m)
                    .map(|(&e, &n)| {
                        if inside(e, n) {
                            (e, n)
                        } else {
                            (f64::NAN, f64::NAN)
                        }
                    })
                    .unzip();
                let idx = stride_indices(east.len(), MAX_POINTS);
                draw_line(
                    chart,
                    keys,
                    segments(&east, &north, &idx),
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
        })
    };
    // The height follows the shape of the drive, within limits; then one metre gets
    // the same number of pixels on both axes.
    let aspect = span(&yr) / span(&xr);
    // The most important figure gets a little more width than the others.
    let width = WIDTH + 100;
    let height = ((f64::from(width - LEGEND_WIDTH) * aspect) as u32).clamp(420, 760);
    let mut frame = Frame::new(xr.clone(), yr.clone(), "east (m)", "north (m)")
        .size(width, height)
        .legend(Legend::Right);
    (frame.x, frame.y) = equal_aspect(xr, yr, frame.plot_area_px());
    let svg = draw_all(&frame, "trajectories", &mut counts)?;
    let mut caption = "Trajectories in the local east-north frame, equal scales on both axes. DR: dead reckoning \
                       from the start with each calibration (figure 6 of the four-wheel paper)."
        .to_string();
    if !counts.is_empty() {
        caption.push(' ');
        caption.push_str(&counts.join(", "));
        caption.push('.');
    }
    let mut blocks = Vec::new();
    if outside.is_empty() {
        blocks.push(Block::Figure(FigureView {
            name: "trajectories".into(),
            caption,
            svg,
        }));
    } else {
        caption.push_str(&format!(
            " The frame covers the tracks anchored to the ground (reference, GNSS fixes, \
             filtered, smoothed); {} leave{} it by more than half its size (clipped \
             here, whole in the next figure).",
            outside.join(", "),
            if outside.len() == 1 { "s" } else { "" }
        ));
        blocks.push(Block::Figure(FigureView {
            name: "trajectories".into(),
            caption,
            svg,
        }));
        let aspect = span(&all_y) / span(&all_x);
        let w = WIDTH;
        let h = ((f64::from(w - LEGEND_WIDTH) * aspect) as u32).clamp(300, 520);
        let mut whole = Frame::new(all_x.clone(), all_y.clone(), "east (m)", "north (m)")
            .size(w, h)
            .legend(Legend::Right);
        (whole.x, whole.y) = equal_aspect(all_x, all_y, whole.plot_area_px());
        let svg = draw_all(&whole, "trajectories-whole", &mut Vec::new())?;
        blocks.push(Block::Figure(FigureView {
            name: "trajectories-whole".into(),
            caption: "Every track at its full extent (same colours).".into(),
            svg,
        }));
    }
    Ok(Some(SectionView {
        id: "trajectories",
        title: "Trajectories",
        blocks,
    }))
}
