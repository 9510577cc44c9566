//! The drift evaluation: table IV (mean and standard deviation of the error per
//! segment, as % of the segment length), the error distribution after each segment
//! (figure 4) and the distance driven before the error reaches the threshold
//! (figure 5) of the four-wheel paper.

use crate::charts::{box_chart, histogram_chart, Sample};
use crate::model::Drift;
use crate::page::{Block, FigureView, RowView, SectionView, TableView};
use crate::plot::{fmt_sig, fmt_trim, Palette};
use crate::stats::summary;
use crate::ReportError;

/// Renders the section, or `None` without methods.
pub(crate) fn section(
    d: &Drift,
    palette: &mut Palette,
) -> Result<Option<SectionView>, ReportError> {
    if d.methods.is_empty() {
        return Ok(None);
    }
    let seg = d.segment_m;
    let pct = |v: f64| format!("{:.2}", 100.0 * v / seg);
    let rows = d
        .methods
        .iter()
        .map(|m| {
            let e = summary(&m.error_after_segment_m);
            let r = summary(&m.distance_to_threshold_m);
            RowView {
                swatch: Some(palette.css(&m.method)),
                cells: vec![
                    m.method.clone(),
                    e.map(|s| pct(s.mean)).unwrap_or_else(|| "–".into()),
                    e.map(|s| pct(s.std)).unwrap_or_else(|| "–".into()),
                    e.map(|s| s.n.to_string()).unwrap_or_else(|| "0".into()),
                    r.map(|s| fmt_sig(s.median, 3))
                        .unwrap_or_else(|| "–".into()),
                    r.map(|s| fmt_sig(s.min, 3)).unwrap_or_else(|| "–".into()),
                    r.map(|s| s.n.to_string()).unwrap_or_else(|| "0".into()),
                ],
            }
        })
        .collect();
    let mut blocks = vec![Block::Tables {
        tables: vec![TableView {
            caption: format!(
                "Dead-reckoning drift (table IV): error after {} m of dead reckoning, in % of the distance; \
                 distance driven before the error reaches {} m.",
                fmt_trim(seg, 3),
                fmt_trim(d.threshold_m, 3)
            ),
            headers: vec![
                "method".into(),
                "mean (%)".into(),
                "std (%)".into(),
                "n segments".into(),
                format!("median distance to {} m (m)", fmt_trim(d.threshold_m, 3)),
                "shortest (m)".into(),
                "n runs".into(),
            ],
            rows,
            text_column: None,
        }],
    }];
    let errors: Vec<Sample<'_>> = d
        .methods
        .iter()
        .filter(|m| !m.error_after_segment_m.is_empty())
        .map(|m| Sample {
            name: m.method.clone(),
            color: palette.color(&m.method),
            values: &m.error_after_segment_m,
        })
        .collect();
    if let Some(svg) = histogram_chart(
        "drift-error-histogram",
        &errors,
        "horizontal error (m)",
        "fraction of segments",
        None,
    )? {
        blocks.push(Block::Figure(FigureView {
            name: "drift-error-histogram".into(),
            caption: format!(
                "Horizontal error after {} m of dead reckoning (figure 4): fraction of segments per bin, \
                 one bar per method.{}",
                fmt_trim(seg, 3),
                svg.overflow_note("m")
            ),
            svg: svg.svg,
        }));
    }
    let distances: Vec<Sample<'_>> = d
        .methods
        .iter()
        .filter(|m| !m.distance_to_threshold_m.is_empty())
        .map(|m| Sample {
            name: m.method.clone(),
            color: palette.color(&m.method),
            values: &m.distance_to_threshold_m,
        })
        .collect();
    if let Some(svg) = box_chart(
        "drift-distance-to-threshold",
        &distances,
        &format!(
            "distance before {} m of error (m)",
            fmt_trim(d.threshold_m, 3)
        ),
    )? {
        blocks.push(Block::Figure(FigureView {
            name: "drift-distance-to-threshold".into(),
            caption: format!(
                "Distance dead-reckoned before the error reaches {} m (figure 5): box from the first to the third \
                 quartile, bar at the median, whiskers to the 5th and 95th percentiles, dots beyond, triangle at \
                 the mean.",
                fmt_trim(d.threshold_m, 3)
            ),
            svg,
        }));
    }
    Ok(Some(SectionView {
        id: "drift",
        title: "Dead-reckoning drift",
        blocks,
    }))
}
