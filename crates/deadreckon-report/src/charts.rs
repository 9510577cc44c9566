//! Chart kinds shared by several sections: grouped histograms, box plots and
//! time series, drawn with a consistent colour per method.

use plotters::prelude::*;

use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::plot::{
    data_begin, data_end, draw_line, padded_range, render_chart, segments, Frame, Legend, OrPlot,
    Swatch,
};
use crate::stats::{bin_edges, histogram, minmax_indices, quantile_sorted, sorted_finite};
use crate::{ReportError, MAX_POINTS};

/// One sample to draw: name, colour, values.
pub(crate) struct Sample<'a> {
    pub name: String,
    pub color: RGBColor,
    pub values: &'a [f64],
}

/// Quantile of the pooled values that ends the regular bins of a histogram:
/// values beyond it go to one overflow bin, so that one outlier (or one method
/// far worse than the others) does not set bins of 10 m for errors of 0.5 m.
pub(crate) const HISTOGRAM_QUANTILE: f64 = 0.95;
/// A method whose median is more than this many times the best method's
/// does not set the regular bins (its values land in the overflow bin): on
/// comma2k19 nominal's 250 m windows set bins of 10 m for the calibrated
/// methods' 0.6 m, which then shared one bar.
pub(crate) const HISTOGRAM_OUTLIER_RATIO: f64 = 10.0;
/// About this many regular bins.
const HISTOGRAM_BINS: usize = 20;

/// A histogram figure: the SVG and, when values lay beyond the regular bins,
/// the lower edge of the overflow bin.
pub(crate) struct Histogram {
    /// The chart.
    pub svg: String,
    /// Values above this were counted in the last (overflow) bin.
    pub overflow_above: Option<f64>,
}

impl Histogram {
    /// The sentence for the caption about the overflow bin (empty without one).
    pub fn overflow_note(&self, unit: &str) -> String {
        match self.overflow_above {
            Some(x) => format!(
                " Bins up to the {:.0}th percentile of the values of the methods whose median is within \
                 {:.0}\u{d7} the best method's; the last bar, marked \u{201c}>\u{201d}, \
                 counts every value above {} {unit}.",
                100.0 * HISTOGRAM_QUANTILE,
                HISTOGRAM_OUTLIER_RATIO,
                crate::plot::fmt_trim(x, 3)
            ),
            None => String::new(),
        }
    }
}

/// The sorted finite values of the methods whose median is within
/// [`HISTOGRAM_OUTLIER_RATIO`] of the best method's (every method's when the
/// best median is not positive).
fn bin_setting(samples: &[Sample<'_>]) -> Vec<f64> {
    let medians: Vec<Option<f64>> = samples
        .iter()
        .map(|s| {
            let v = sorted_finite(s.values);
            (!v.is_empty()).then(|| quantile_sorted(&v, 0.5))
        })
        .collect();
    let best = medians
        .iter()
        .flatten()
        .copied()
        .fold(f64::INFINITY, f64::min);
    // No positive best median (none, or 0): every method sets the bins.
    let ratio_applies = best > 0.0;
    let keep =
        |m: &Option<f64>| m.is_some_and(|m| !ratio_applies || m <= HISTOGRAM_OUTLIER_RATIO * best);
    sorted_finite(
        &samples
            .iter()
            .zip(&medians)
            .filter(|(_, m)| keep(m))
            .flat_map(|(s, _)| s.values.iter().copied())
            .collect::<Vec<_>>(),
    )
}

/// Grouped histograms: in each bin one bar per method side by side (fraction
/// of each sample per bin, so methods with different counts compare). The bins
/// run up to the [`HISTOGRAM_QUANTILE`] of the pooled values of the methods
/// within [`HISTOGRAM_OUTLIER_RATIO`] of the best median, and one overflow
/// bin holds the rest. `None` without finite values.
pub(crate) fn histogram_chart(
    figure: &str,
    samples: &[Sample<'_>],
    x_desc: &str,
    y_desc: &str,
    vline: Option<(f64, &str)>,
) -> Result<Option<Histogram>, ReportError> {
    let pooled = sorted_finite(
        &samples
            .iter()
            .flat_map(|s| s.values.iter().copied())
            .collect::<Vec<_>>(),
    );
    let (Some(&lo), Some(&hi)) = (pooled.first(), pooled.last()) else {
        return Ok(None);
    };
    let robust_hi = quantile_sorted(&bin_setting(samples), HISTOGRAM_QUANTILE);
    let overflow = hi > robust_hi && robust_hi > lo;
    let upper = if overflow { robust_hi } else { hi };
    let extra = vline.map(|v| [v.0]);
    let range = [lo, upper];
    let mut all: Vec<&[f64]> = vec![&range];
    if let Some(e) = &extra {
        all.push(e);
    }
    let mut edges = bin_edges(&all, HISTOGRAM_BINS);
    if edges.len() < 2 {
        return Ok(None);
    }
    let regular = edges[edges.len() - 1];
    let overflow_above = (overflow && hi > regular).then_some(regular);
    if overflow_above.is_some() {
        let w = edges[1] - edges[0];
        edges.push(regular + w);
    }
    let nb = edges.len() - 1;
    let fractions: Vec<Vec<f64>> = samples
        .iter()
        .map(|s| {
            let mut c = histogram(
                s.values,
                &edges[..if overflow_above.is_some() { nb } else { nb + 1 }],
            );
            if overflow_above.is_some() {
                c.push(
                    s.values
                        .iter()
                        .filter(|v| v.is_finite() && **v > regular)
                        .count(),
                );
            }
            let n = s.values.iter().filter(|v| v.is_finite()).count().max(1) as f64;
            c.into_iter().map(|k| k as f64 / n).collect()
        })
        .collect();
    let top = fractions.iter().flatten().fold(0.0f64, |a, b| a.max(*b));
    if top <= 0.0 {
        return Ok(None);
    }
    let x0 = edges[0];
    let x1 = edges[nb];
    let frame = Frame::new(x0..x1, 0.0..top * 1.12, x_desc, y_desc);
    let svg = render_chart(figure, &frame, |chart, keys| {
        data_begin(chart)?;
        // One bar per method in each bin, side by side: two methods in the same
        // bin (RTS and truth within 0.5 m) are two bars, not one.
        let k = samples.len().max(1) as f64;
        for (j, (s, f)) in samples.iter().zip(&fractions).enumerate() {
            let c = s.color;
            chart
                .draw_series(
                    f.iter()
                        .enumerate()
                        .filter(|(_, v)| **v > 0.0)
                        .map(|(i, v)| {
                            let w = edges[i + 1] - edges[i];
                            let a = edges[i] + w * (0.05 + 0.9 * j as f64 / k);
                            let b = edges[i] + w * (0.05 + 0.9 * (j + 1) as f64 / k);
                            Rectangle::new([(a, 0.0), (b, *v)], c.mix(0.85).filled())
                        }),
                )
                .or_plot()?;
            let n = s.values.iter().filter(|v| v.is_finite()).count();
            keys.add(format!("{} (n = {n})", s.name), Swatch::Bar(c));
        }
        data_end(chart)?;
        if let Some(at) = overflow_above {
            let mid = 0.5 * (edges[nb - 1] + edges[nb]);
            chart
                .draw_series(std::iter::once(Text::new(
                    format!(">{}", crate::plot::fmt_trim(at, 3)),
                    (mid, top * 1.1),
                    (crate::plot::FONT, 13)
                        .into_font()
                        .color(&BLACK)
                        .pos(Pos::new(HPos::Center, VPos::Top)),
                )))
                .or_plot()?;
        }
        if let Some((x, label)) = vline {
            crate::plot::draw_vline(chart, keys, x, crate::plot::REFERENCE, Some(label))?;
        }
        Ok(())
    })?;
    Ok(Some(Histogram {
        svg,
        overflow_above,
    }))
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Regression: on comma2k19 nominal's 250 m windows set the outage
    /// histogram's bins (10 m wide), and RTS, truth and params.toml's 0.6 m
    /// shared one bar. Nominal now lands in the overflow bin.
    #[test]
    fn nominal_ruled_the_comma2k19_outage_histogram() {
        let rts = [0.45, 0.52, 0.58, 0.61, 0.66, 0.79, 0.88];
        let truth = [0.41, 0.50, 0.55, 0.60, 0.70, 0.75, 0.84];
        let nominal = [231.0, 240.0, 247.0, 252.0, 255.0, 261.0, 270.0];
        let c = |name: &str, values: &'static [f64]| Sample {
            name: name.into(),
            color: RGBColor(0, 0, 0),
            values,
        };
        let rts: &'static [f64] = Box::leak(Box::new(rts));
        let truth: &'static [f64] = Box::leak(Box::new(truth));
        let nominal: &'static [f64] = Box::leak(Box::new(nominal));
        let h = histogram_chart(
            "t",
            &[c("rts", rts), c("truth", truth), c("nominal", nominal)],
            "m",
            "fraction",
            None,
        )
        .unwrap()
        .unwrap();
        let above = h.overflow_above.expect("an overflow bin");
        // The regular bins end near the calibrated methods' largest error
        // (0.88 m), not at nominal's.
        assert!((0.8..=1.0).contains(&above), "{above}");
        assert!(h.overflow_note("m").contains("10× the best method's"));
        // Methods of one size keep the pooled 95th percentile.
        let close: &'static [f64] = Box::leak(Box::new([0.9, 1.1, 1.3, 1.6, 2.0, 2.4, 3.1]));
        let h = histogram_chart(
            "t",
            &[c("rts", rts), c("other", close)],
            "m",
            "fraction",
            None,
        )
        .unwrap()
        .unwrap();
        assert!(
            h.overflow_above.is_none_or(|x| x > 2.0),
            "{:?}",
            h.overflow_above
        );
    }
}
