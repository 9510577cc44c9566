//! The outage evaluation: the distribution of the final error at the end of
//! sliding simulated GNSS outages, per method, with a summary table; and the
//! error against the 95 % bound through the windows, with its coverage.

use crate::charts::{histogram_chart, Sample};
use crate::charts::{lines_chart, Line};
use crate::model::{OutageBound, OutageEvaluation};
use crate::page::{Block, FigureView, RowView, SectionView, TableView};
use crate::plot::{fmt_sig, fmt_trim, Legend, Palette, REFERENCE, WIDTH};
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
    if let Some(b) = &o.bound {
        blocks.extend(bound_figure(b, &window, palette)?);
    }
    Ok(Some(SectionView {
        id: "outages",
        title: "Outage evaluation",
        blocks,
    }))
}

/// The error and the 95 % bound against time in outage, every window's
/// curves in one colour each (`None` without points).
fn bound_figure(
    b: &OutageBound,
    window: &str,
    palette: &mut Palette,
) -> Result<Option<Block>, ReportError> {
    let n = b.time_s.len();
    if n == 0 || b.error_m.len() != n || b.bound_m.len() != n {
        return Ok(None);
    }
    // The windows joined, a NaN between two (a break in the line).
    let joined = |v: &[Vec<f64>]| -> Vec<f64> {
        v.iter()
            .flat_map(|w| w.iter().copied().chain(std::iter::once(f64::NAN)))
            .collect()
    };
    let t = joined(&b.time_s);
    let (e, bound) = (joined(&b.error_m), joined(&b.bound_m));
    if t.len() != e.len() || t.len() != bound.len() {
        return Ok(None);
    }
    let lines = [
        Line {
            name: format!("error ({})", b.method),
            color: palette.color(&b.method),
            width: 1,
            t: &t,
            v: &e,
        },
        Line {
            name: "95 % bound".into(),
            color: REFERENCE,
            width: 1,
            t: &t,
            v: &bound,
        },
    ];
    let Some(svg) = lines_chart(
        "outage-bound",
        &lines,
        "time since outage start (s)",
        "horizontal error (m)",
        &[],
        (WIDTH, 320),
        Legend::Right,
    )?
    else {
        return Ok(None);
    };
    Ok(Some(Block::Figure(FigureView {
        name: "outage-bound".into(),
        caption: format!(
            "Horizontal error and its 95 % bound against time in each sliding outage{window} \
             with {}: the final error is within the bound in {} of {n} windows ({:.0} %); \
             median bound / median final error {}. The bound: {}.",
            b.method,
            b.within,
            100.0 * b.within as f64 / n as f64,
            fmt_sig(b.sharpness, 3),
            b.factor
        ),
        svg,
    })))
}
