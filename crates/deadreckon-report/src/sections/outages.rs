//! The outage evaluation: the distribution of the final error at the end of
//! sliding simulated GNSS outages, per method, with a summary table.

use crate::charts::{histogram_chart, Sample};
use crate::model::OutageEvaluation;
use crate::page::{Block, FigureView, RowView, SectionView, TableView};
use crate::plot::{fmt_sig, fmt_trim, Palette};
use crate::stats::summary;
use crate::ReportError;

/// Renders the section, or `None` without data.
pub(crate) fn section(
    o: &OutageEvaluation,
    palette: &mut Palette,
) -> Result<Option<SectionView>, ReportError> {
    let methods: Vec<_> = o
        .methods
        .iter()
        .filter(|m| summary(&m.final_error_m).is_some())
        .collect();
    if methods.is_empty() {
        return Ok(None);
    }
    let window = o
        .window_s
        .map(|w| format!(" of {} s", fmt_trim(w, 3)))
        .unwrap_or_default();
    let rows = methods
        .iter()
        .filter_map(|m| {
            let s = summary(&m.final_error_m)?;
            Some(RowView {
                swatch: Some(palette.css(&m.method)),
                cells: vec![
                    m.method.clone(),
                    s.n.to_string(),
                    fmt_sig(s.mean, 3),
                    fmt_sig(s.median, 3),
                    fmt_sig(s.p95, 3),
                    fmt_sig(s.max, 3),
                ],
            })
        })
        .collect();
    let mut blocks = vec![Block::Tables {
        tables: vec![TableView {
            caption: format!("Horizontal error at the end of each simulated outage{window} (m)."),
            headers: [
                "method",
                "n",
                "mean (m)",
                "median (m)",
                "p95 (m)",
                "max (m)",
            ]
            .map(String::from)
            .to_vec(),
            rows,
            text_column: None,
        }],
    }];
    let samples: Vec<Sample<'_>> = methods
        .iter()
        .map(|m| Sample {
            name: m.method.clone(),
            color: palette.color(&m.method),
            values: &m.final_error_m,
        })
        .collect();
    if let Some(svg) = histogram_chart(
        "outage-final-error",
        &samples,
        "final horizontal error (m)",
        "fraction of windows",
        None,
    )? {
        blocks.push(Block::Figure(FigureView {
            name: "outage-final-error".into(),
            caption: format!("Error at the end of each sliding outage window{window}: fraction of windows per bin, one bar per method.{}", svg.overflow_note("m")),
            svg: svg.svg,
        }));
    }
    Ok(Some(SectionView {
        id: "outages",
        title: "Outage evaluation",
        blocks,
    }))
}
