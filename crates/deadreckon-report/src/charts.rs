//! Chart kinds shared by several sections: overlaid histograms, box plots and
//! time series, drawn with a consistent colour per method.

use plotters::prelude::*;

use crate::plot::{
    data_begin, data_end, draw_line, padded_range, render_chart, segments, Frame, Legend, OrPlot,
};
use crate::stats::{bin_edges, histogram, minmax_indices, quantile_sorted, sorted_finite};
use crate::{ReportError, MAX_POINTS};

/// One sample to draw: name, colour, values.
pub(crate) struct Sample<'a> {
    pub name: String,
    pub color: RGBColor,
    pub values: &'a [f64],
}

/// Overlaid histograms (fraction of each sample per bin, so methods with different
/// counts compare), each a light fill under a step outline. `None` without finite values.
pub(crate) fn histogram_chart(
    figure: &str,
    samples: &[Sample<'_>],
    x_desc: &str,
    y_desc: &str,
    vline: Option<(f64, &str)>,
) -> Result<Option<String>, ReportError> {
    let mut all: Vec<&[f64]> = samples.iter().map(|s| s.values).collect();
    let extra = vline.map(|v| [v.0]);
    if let Some(e) = &extra {
        all.push(e);
    }
    let edges = bin_edges(&all, 30);
    if edges.len() < 2 {
        return Ok(None);
    }
    let fractions: Vec<Vec<f64>> = samples
        .iter()
        .map(|s| {
            let c = histogram(s.values, &edges);
            let n = c.iter().sum::<usize>().max(1) as f64;
            c.into_iter().map(|k| k as f64 / n).collect()
        })
        .collect();
    let top = fractions.iter().flatten().fold(0.0f64, |a, b| a.max(*b));
    if top <= 0.0 {
        return Ok(None);
    }
    let x0 = edges[0];
    let x1 = edges[edges.len() - 1];
    let frame = Frame::new(x0..x1, 0.0..top * 1.1, x_desc, y_desc);
    let svg = render_chart(figure, &frame, |chart, keys| {
        data_begin(chart)?;
        // Outlines drawn from the thickest to the thinnest: two methods with the
        // same bins (RTS and truth within the first bin) both stay visible, the
        // later one inside the earlier.
        let k = samples.len() as u32;
        for (j, (s, f)) in samples.iter().zip(&fractions).enumerate() {
            let c = s.color;
            let width = 2 + 2 * (k - 1 - j as u32);
            chart
                .draw_series(
                    f.iter()
                        .enumerate()
                        .filter(|(_, v)| **v > 0.0)
                        .map(|(i, v)| {
                            Rectangle::new(
                                [(edges[i], 0.0), (edges[i + 1], *v)],
                                c.mix(0.07).filled(),
                            )
                        }),
                )
                .or_plot()?;
            let mut step = vec![(edges[0], 0.0)];
            for (i, v) in f.iter().enumerate() {
                step.push((edges[i], *v));
                step.push((edges[i + 1], *v));
            }
            step.push((edges[edges.len() - 1], 0.0));
            let n = s.values.iter().filter(|v| v.is_finite()).count();
            draw_line(
                chart,
                keys,
                vec![step],
                c,
                width,
                Some(&format!("{} (n = {n})", s.name)),
            )?;
        }
        data_end(chart)?;
        if let Some((x, label)) = vline {
            crate::plot::draw_vline(chart, keys, x, crate::plot::REFERENCE, Some(label))?;
        }
        Ok(())
    })?;
    Ok(Some(svg))
}

/// Horizontal box plots, one row per sample: box from the first to the third
/// quartile, median bar, whiskers to the 5th and 95th percentiles, every value
/// beyond them as a dot, and the mean as a diamond.
pub(crate) fn box_chart(
    figure: &str,
    samples: &[Sample<'_>],
    x_desc: &str,
) -> Result<Option<String>, ReportError> {
    let sorted: Vec<Vec<f64>> = samples.iter().map(|s| sorted_finite(s.values)).collect();
    let Some(xr) = padded_range(sorted.iter().flatten(), 0.05) else {
        return Ok(None);
    };
    let k = samples.len();
    let names: Vec<String> = samples.iter().map(|s| s.name.clone()).collect();
    let height = (90 + 70 * k as u32).clamp(200, 480);
    let frame = Frame::new(xr, -0.6..(k as f64 - 0.4), x_desc, "")
        .size(crate::plot::WIDTH, height)
        .legend(Legend::None)
        .y_categories(names);
    let svg = render_chart(figure, &frame, |chart, _keys| {
        data_begin(chart)?;
        for (i, (s, v)) in samples.iter().zip(&sorted).enumerate() {
            if v.is_empty() {
                continue;
            }
            let y = i as f64;
            let c = s.color;
            let q = |p| quantile_sorted(v, p);
            let (p05, q1, med, q3, p95) = (q(0.05), q(0.25), q(0.5), q(0.75), q(0.95));
            let mean = v.iter().sum::<f64>() / v.len() as f64;
            let h = 0.28;
            let area = chart.plotting_area();
            area.draw(&Rectangle::new(
                [(q1, y - h), (q3, y + h)],
                c.mix(0.25).filled(),
            ))
            .or_plot()?;
            area.draw(&Rectangle::new(
                [(q1, y - h), (q3, y + h)],
                c.stroke_width(2),
            ))
            .or_plot()?;
            area.draw(&PathElement::new(
                vec![(med, y - h), (med, y + h)],
                c.stroke_width(3),
            ))
            .or_plot()?;
            for (a, b) in [(p05, q1), (q3, p95)] {
                area.draw(&PathElement::new(vec![(a, y), (b, y)], c.stroke_width(2)))
                    .or_plot()?;
            }
            for x in [p05, p95] {
                area.draw(&PathElement::new(
                    vec![(x, y - h / 2.0), (x, y + h / 2.0)],
                    c.stroke_width(2),
                ))
                .or_plot()?;
            }
            for &x in v.iter().filter(|x| **x < p05 || **x > p95) {
                area.draw(&Circle::new((x, y), 2, c.mix(0.7).filled()))
                    .or_plot()?;
            }
            area.draw(&TriangleMarker::new((mean, y), 5, BLACK.filled()))
                .or_plot()?;
        }
        data_end(chart)
    })?;
    Ok(Some(svg))
}

/// One time series line.
pub(crate) struct Line<'a> {
    pub name: String,
    pub color: RGBColor,
    /// Line width, px.
    pub width: u32,
    pub t: &'a [f64],
    pub v: &'a [f64],
}

/// Time series lines (decimated keeping the minimum and maximum of each bucket),
/// with optional horizontal reference lines drawn under them.
pub(crate) fn lines_chart(
    figure: &str,
    lines: &[Line<'_>],
    x_desc: &str,
    y_desc: &str,
    hlines: &[(f64, RGBColor, String)],
    size: (u32, u32),
    legend: Legend,
) -> Result<Option<String>, ReportError> {
    let Some(xr) = padded_range(lines.iter().flat_map(|l| l.t.iter()), 0.0) else {
        return Ok(None);
    };
    let ys = lines
        .iter()
        .flat_map(|l| l.v.iter())
        .chain(hlines.iter().map(|h| &h.0));
    let Some(mut yr) = padded_range(ys, 0.05) else {
        return Ok(None);
    };
    if yr.start > 0.0 && yr.start < 0.3 * yr.end {
        yr.start = 0.0;
    }
    if matches!(legend, Legend::Inside(_)) {
        // Headroom for a legend inside the frame, above the data (it covered
        // the curves of the small outage figures).
        let rows = lines.len() + hlines.len();
        yr.end += (0.12 * rows as f64 + 0.1) * (yr.end - yr.start);
    }
    let frame = Frame::new(xr, yr, x_desc, y_desc)
        .size(size.0, size.1)
        .legend(legend);
    let svg = render_chart(figure, &frame, |chart, keys| {
        for (y, c, label) in hlines {
            crate::plot::draw_hline(chart, keys, *y, *c, Some(label))?;
        }
        data_begin(chart)?;
        for l in lines {
            let idx = minmax_indices(l.v, MAX_POINTS);
            draw_line(
                chart,
                keys,
                segments(l.t, l.v, &idx),
                l.color,
                l.width,
                Some(&l.name),
            )?;
        }
        data_end(chart)
    })?;
    Ok(Some(svg))
}
