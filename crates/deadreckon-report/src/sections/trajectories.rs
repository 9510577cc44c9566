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
/// Margin around the extent of the reference and GNSS fixes that sets the frame,
/// as a fraction of that extent.
const FRAME_MARGIN: f64 = 0.1;
/// Radius of a GNSS fix, px (drawn above the tracks).
const GNSS_DOT_PX: i32 = 2;

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
    // The frame is set by what is tied to the ground: the reference and the
    // GNSS fixes (the filtered and smoothed tracks only when neither exists),
    // plus a margin. A track that runs away from it (nominal parameters: a
    // half-circle hundreds of metres off) is clipped at the frame and shown
    // whole in a second, small figure; the caption says which.
    let ground: Vec<&EnPath> = reference.into_iter().chain(gnss).collect();
    let anchored: Vec<&EnPath> = if ground.is_empty() {
        lines.iter().map(|(_, p, _)| *p).collect()
    } else {
        ground
    };
    let everything: Vec<&EnPath> = lines
        .iter()
        .map(|(_, p, _)| *p)
        .chain(reference)
        .chain(gnss)
        .collect();
    let extent = |paths: &[&EnPath], pad: f64| {
        let e = paths.iter().flat_map(|p| p.east_m.iter());
        let n = paths.iter().flat_map(|p| p.north_m.iter());
        padded_range(e, pad).zip(padded_range(n, pad))
    };
    let Some((all_x, all_y)) = extent(&everything, 0.04) else {
        return Ok(None);
    };
    let (xr, yr) = match extent(&anchored, FRAME_MARGIN) {
        Some((x, y)) => (x, y),
        None => (all_x.clone(), all_y.clone()),
    };
    let span = |r: &std::ops::Range<f64>| r.end - r.start;
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
            // The fixes above the tracks: under them they were hidden (issue 34).
            if let Some(g) = gnss {
                let idx = stride_indices(g.east_m.len(), MAX_POINTS);
                let pts: Vec<(f64, f64)> = segments(&g.east_m, &g.north_m, &idx).concat();
                counts.push(format!("{} GNSS fixes used", g.east_m.len()));
                chart
                    .draw_series(
                        pts.into_iter()
                            .map(|p| Circle::new(p, GNSS_DOT_PX, gnss_color.filled())),
                    )
                    .or_plot()?;
                keys.add("GNSS fixes", Swatch::Dot(gnss_color));
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
    // The tracks with a point outside the frame: clipped there.
    let outside: Vec<&str> = lines
        .iter()
        .filter(|(_, p, _)| {
            p.east_m.iter().zip(&p.north_m).any(|(e, n)| {
                e.is_finite() && n.is_finite() && !(frame.x.contains(e) && frame.y.contains(n))
            })
        })
        .map(|(n, _, _)| n.as_str())
        .collect();
    let svg = draw_all(&frame, "trajectories", &mut counts)?;
    let mut caption = "Trajectories in the local east-north frame, equal scales on both axes. DR: dead reckoning \
                       from the start with each calibration (figure 6 of the four-wheel paper)."
        .to_string();
    if let (Some(m), true) = (
        &t.aided_with,
        usable(&t.filtered).or(usable(&t.smoothed)).is_some(),
    ) {
        caption.push_str(&format!(
            " filtered and smoothed: the GNSS-aided filter and its RTS smoothing with the \
             parameters of the calibration table's row “{m}”, the tracks `deadreckon run` writes \
             with them."
        ));
    }
    if !counts.is_empty() {
        caption.push(' ');
        caption.push_str(&counts.join(", "));
        caption.push('.');
    }
    let frame_basis = match (reference.is_some(), gnss.is_some()) {
        (true, true) => "the reference and the GNSS fixes",
        (true, false) => "the reference",
        (false, true) => "the GNSS fixes",
        (false, false) => "the tracks",
    };
    let mut blocks = Vec::new();
    if outside.is_empty() {
        blocks.push(Block::Figure(FigureView {
            name: "trajectories".into(),
            caption,
            svg,
        }));
    } else {
        caption.push_str(&format!(
            " The frame is set by {} plus a margin of {:.0} % of their extent; {} run{} \
             out of it and {} clipped at its edge (whole in the next figure).",
            frame_basis,
            100.0 * FRAME_MARGIN,
            outside.join(", "),
            if outside.len() == 1 { "s" } else { "" },
            if outside.len() == 1 { "is" } else { "are" },
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
