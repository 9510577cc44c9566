//! Each track's horizontal error against the reference, through time and
//! through the distance travelled (issue 34): on a straight drive the
//! trajectories figure collapses to one line, and the methods differ only
//! here. The error axis is logarithmic (a nominal dead reckoning hundreds of
//! metres off beside a filtered track within a metre); the drive's own GNSS
//! outages (no fix for longer than [`GAP_MIN_S`]) are shaded.

use std::ops::Range;

use plotters::prelude::*;

use crate::model::{EnPath, Trajectories};
use crate::page::{Block, FigureView, SectionView};
use crate::plot::{
    data_begin, data_end, draw_line, fmt_trim, render_chart, segments, Frame, Legend, OrPlot,
    Palette, Swatch, WIDTH,
};
use crate::stats::minmax_indices;
use crate::{check_len, ReportError, MAX_POINTS};

/// The shortest time without a GNSS fix that is shaded as an outage, s (a
/// receiver at 1–10 Hz that drops a fix or two is not in an outage).
pub(crate) const GAP_MIN_S: f64 = 2.0;
/// The smallest error drawn, m: the axis is logarithmic, and an error of
/// zero (a track that is the reference) is drawn at this floor.
const ERROR_FLOOR_M: f64 = 1e-3;
/// The shading of the GNSS outages.
const OUTAGE_SHADE: RGBColor = RGBColor(255, 214, 153);

/// One track's error at the reference's times.
pub(crate) struct ErrorSeries {
    /// `filtered`, `smoothed` or `DR (method)`.
    pub name: String,
    /// The colour key (the method, or `filtered`/`smoothed`).
    pub key: String,
    /// Index into the reference's samples of each error.
    pub at: Vec<usize>,
    /// Horizontal error, m.
    pub error_m: Vec<f64>,
}

/// The track's position at `t` by linear interpolation between its two
/// neighbouring points (`None` outside its time span or next to a break).
fn position_at(p: &EnPath, t: f64) -> Option<(f64, f64)> {
    let ts = &p.t_s;
    let j = ts.partition_point(|&x| x < t);
    if j == ts.len() || (j == 0 && ts[0] != t) {
        return None;
    }
    if ts[j] == t {
        let (e, n) = (p.east_m[j], p.north_m[j]);
        return (e.is_finite() && n.is_finite()).then_some((e, n));
    }
    let (a, b) = (j - 1, j);
    let w = (t - ts[a]) / (ts[b] - ts[a]);
    let e = p.east_m[a] + w * (p.east_m[b] - p.east_m[a]);
    let n = p.north_m[a] + w * (p.north_m[b] - p.north_m[a]);
    (e.is_finite() && n.is_finite()).then_some((e, n))
}

/// The horizontal error of `track` at each finite reference sample inside
/// the track's time span.
pub(crate) fn errors_against(
    reference: &EnPath,
    name: &str,
    key: &str,
    track: &EnPath,
) -> ErrorSeries {
    let mut s = ErrorSeries {
        name: name.to_string(),
        key: key.to_string(),
        at: Vec::new(),
        error_m: Vec::new(),
    };
    for (i, &t) in reference.t_s.iter().enumerate() {
        let (re, rn) = (reference.east_m[i], reference.north_m[i]);
        if !(t.is_finite() && re.is_finite() && rn.is_finite()) {
            continue;
        }
        if let Some((e, n)) = position_at(track, t) {
            s.at.push(i);
            s.error_m.push((e - re).hypot(n - rn));
        }
    }
    s
}

/// The intervals without a GNSS fix longer than [`GAP_MIN_S`], s, from the
/// times of every fix (used and gated).
pub(crate) fn gnss_gaps(fix_times_s: &[f64]) -> Vec<(f64, f64)> {
    let mut t: Vec<f64> = fix_times_s
        .iter()
        .copied()
        .filter(|t| t.is_finite())
        .collect();
    t.sort_by(f64::total_cmp);
    t.windows(2)
        .filter(|w| w[1] - w[0] > GAP_MIN_S)
        .map(|w| (w[0], w[1]))
        .collect()
}

/// Cumulative distance along the finite points of a path, m (a break adds
/// nothing).
fn cumulative_distance(p: &EnPath) -> Vec<f64> {
    let mut d = Vec::with_capacity(p.east_m.len());
    let mut total = 0.0;
    let mut last: Option<(f64, f64)> = None;
    for (&e, &n) in p.east_m.iter().zip(&p.north_m) {
        if e.is_finite() && n.is_finite() {
            if let Some((le, ln)) = last {
                total += (e - le).hypot(n - ln);
            }
            last = Some((e, n));
        }
        d.push(total);
    }
    d
}

/// `y` at `x` on the increasing samples `(xs, ys)`, clamped at the ends.
fn interp(xs: &[f64], ys: &[f64], x: f64) -> f64 {
    let j = xs.partition_point(|&v| v < x);
    if j == 0 {
        return ys[0];
    }
    if j == xs.len() {
        return ys[ys.len() - 1];
    }
    let w = (x - xs[j - 1]) / (xs[j] - xs[j - 1]);
    ys[j - 1] + w * (ys[j] - ys[j - 1])
}

fn timed(p: &Option<EnPath>) -> Option<&EnPath> {
    p.as_ref()
        .filter(|p| !p.t_s.is_empty() && p.east_m.iter().any(|e| e.is_finite()))
}

/// Renders the section, or `None` without a timed reference and a timed track.
pub(crate) fn section(
    t: &Trajectories,
    start_t_s: Option<f64>,
    palette: &mut Palette,
) -> Result<Option<SectionView>, ReportError> {
    let truth = timed(&t.truth);
    let gnss = timed(&t.gnss);
    let Some((reference, ref_name)) = truth
        .map(|r| (r, "the reference (truth)"))
        .or_else(|| gnss.map(|g| (g, "the GNSS fixes")))
    else {
        return Ok(None);
    };
    let mut tracks: Vec<(String, String, &EnPath)> = Vec::new();
    for (name, p) in [("filtered", &t.filtered), ("smoothed", &t.smoothed)] {
        if let Some(p) = timed(p) {
            tracks.push((name.into(), name.into(), p));
        }
    }
    for m in &t.dead_reckoned {
        if !m.path.t_s.is_empty() {
            tracks.push((format!("DR ({})", m.method), m.method.clone(), &m.path));
        }
    }
    check_len(
        "errors",
        "reference times",
        reference.east_m.len(),
        reference.t_s.len(),
    )?;
    for (name, _, p) in &tracks {
        check_len("errors", name, p.east_m.len(), p.t_s.len())?;
    }
    let series: Vec<ErrorSeries> = tracks
        .iter()
        .map(|(name, key, p)| errors_against(reference, name, key, p))
        .filter(|s| !s.error_m.is_empty())
        .collect();
    if series.is_empty() {
        return Ok(None);
    }
    let fixes: Vec<f64> = [&t.gnss, &t.gnss_gated]
        .into_iter()
        .flatten()
        .flat_map(|g| g.t_s.iter().copied())
        .collect();
    let gaps = gnss_gaps(&fixes);
    let start = start_t_s.unwrap_or(0.0);
    let time: Vec<f64> = reference.t_s.iter().map(|t| t - start).collect();
    let colors: Vec<RGBColor> = series.iter().map(|s| palette.color(&s.key)).collect();
    let logs: Vec<Vec<f64>> = series
        .iter()
        .map(|s| {
            s.error_m
                .iter()
                .map(|e| e.max(ERROR_FLOOR_M).log10())
                .collect()
        })
        .collect();
    let (lo, hi) = logs
        .iter()
        .flatten()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    // Whole decades, at least two.
    let y = lo.floor()..hi.ceil().max(lo.floor() + 2.0);
    let gap_note = if gaps.is_empty() {
        format!("The GNSS fixes have no gap longer than {GAP_MIN_S} s, so nothing is shaded.")
    } else {
        let total: f64 = gaps.iter().map(|g| g.1 - g.0).sum();
        format!(
            "Shaded: the GNSS outages of the drive, where no fix came for more than {} s ({} of them, {} s in all); \
             the filtered and smoothed tracks dead-reckon through them.",
            GAP_MIN_S,
            gaps.len(),
            fmt_trim(total, 3)
        )
    };
    let what = format!(
        "Horizontal error against {ref_name} at its samples, in metres on a logarithmic axis \
         (each labelled line a factor of 10). filtered and smoothed: the GNSS-aided filter and \
         its RTS smoothing; DR: dead reckoning from the start without GNSS, with each calibration."
    );
    let mut blocks = Vec::new();
    let chart = |name: &str, x: &[f64], x_desc: &str, shade: &[(f64, f64)]| {
        let xr = x.iter().copied().filter(|v| v.is_finite());
        let (x0, x1) = xr.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
        let x_range: Range<f64> = if x1 > x0 { x0..x1 } else { x0 - 1.0..x0 + 1.0 };
        let frame = Frame::new(x_range, y.clone(), x_desc, "horizontal error (m)")
            .size(WIDTH + 100, 420)
            .legend(Legend::Right)
            .y_log10();
        render_chart(name, &frame, |chart, keys| {
            let yr = chart.y_range();
            for &(a, b) in shade {
                chart
                    .draw_series(std::iter::once(Rectangle::new(
                        [(a, yr.start), (b, yr.end)],
                        OUTAGE_SHADE.mix(0.6).filled(),
                    )))
                    .or_plot()?;
            }
            if !shade.is_empty() {
                keys.add(
                    format!("GNSS outage (> {GAP_MIN_S} s)"),
                    Swatch::Bar(OUTAGE_SHADE),
                );
            }
            data_begin(chart)?;
            for ((s, v), c) in series.iter().zip(&logs).zip(&colors) {
                let xs: Vec<f64> = s.at.iter().map(|&i| x[i]).collect();
                let idx = minmax_indices(v, MAX_POINTS);
                draw_line(chart, keys, segments(&xs, v, &idx), *c, 2, Some(&s.name))?;
            }
            data_end(chart)
        })
    };
    let shade_t: Vec<(f64, f64)> = gaps.iter().map(|g| (g.0 - start, g.1 - start)).collect();
    blocks.push(Block::Figure(FigureView {
        name: "error-time".into(),
        caption: format!(
            "{what} Against the {}. {gap_note}",
            crate::sections::time_desc(start_t_s)
        ),
        svg: chart(
            "error-time",
            &time,
            crate::sections::time_desc(start_t_s),
            &shade_t,
        )?,
    }));
    // Against the distance travelled along the reference: where the car
    // stood still the time figure stretches, this one does not.
    if truth.is_some() {
        let dist = cumulative_distance(reference);
        if dist.last().is_some_and(|d| *d > 0.0) {
            let shade_d: Vec<(f64, f64)> = gaps
                .iter()
                .map(|g| {
                    (
                        interp(&reference.t_s, &dist, g.0),
                        interp(&reference.t_s, &dist, g.1),
                    )
                })
                .collect();
            blocks.push(Block::Figure(FigureView {
                name: "error-distance".into(),
                caption: format!(
                    "The same errors (m, logarithmic axis) against the distance travelled along the reference (m): \
                     the drift of each dead reckoning per metre driven, standstills left out. {gap_note}"
                ),
                svg: chart(
                    "error-distance",
                    &dist,
                    "distance travelled (m)",
                    &shade_d,
                )?,
            }));
        }
    }
    Ok(Some(SectionView {
        id: "errors",
        title: "Error against the reference",
        blocks,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn path(t: &[f64], e: &[f64], n: &[f64]) -> EnPath {
        EnPath {
            east_m: e.to_vec(),
            north_m: n.to_vec(),
            t_s: t.to_vec(),
        }
    }

    #[test]
    fn the_error_is_the_distance_to_the_track_interpolated_at_the_reference_times() {
        let reference = path(&[0.0, 1.0, 2.0, 3.0], &[0.0, 10.0, 20.0, 30.0], &[0.0; 4]);
        // The track is 3 m north, sampled at other times, and ends at 2.5 s.
        let track = path(&[-0.5, 0.5, 1.5, 2.5], &[-5.0, 5.0, 15.0, 25.0], &[3.0; 4]);
        let s = errors_against(&reference, "DR (x)", "x", &track);
        assert_eq!(
            s.at,
            vec![0, 1, 2],
            "the 3 s sample is past the track's end"
        );
        for e in &s.error_m {
            assert!((e - 3.0).abs() < 1e-12, "{e}");
        }
    }

    #[test]
    fn gaps_longer_than_two_seconds_are_outages() {
        let g = gnss_gaps(&[0.0, 0.1, 0.2, 2.1, 2.2, 10.0, 10.1]);
        assert_eq!(g, vec![(2.2, 10.0)]);
    }
}
