//! The calibration table (table III of the four-wheel paper) with standard errors,
//! and the path of each parameter over the smoothing–calibration iterations.

use plotters::prelude::*;

use crate::model::{Calibration, Params};
use crate::page::{Block, FigureView, RowView, SectionView, TableView};
use crate::plot::{
    data_begin, data_end, draw_hline, draw_line, fmt_sig, padded_range, render_chart, Frame,
    Legend, OrPlot, Palette, SMALL_WIDTH,
};
use crate::{check_optional_len, ReportError};

/// The figures' names of the six parameters, with units, in
/// [`Params::to_array`] order ([`Params::NAMES`] are the params.toml keys).
const PARAM_LABELS: [&str; 6] = [
    "gyro bias (rad/s)",
    "speed scale",
    "circumference FL (m)",
    "circumference FR (m)",
    "circumference RL (m)",
    "circumference RR (m)",
];

/// Column headings of the table (the paper's symbols).
const SHORT_LABELS: [&str; 6] = [
    "gyro bias (rad/s)",
    "speed scale",
    "ρ FL (m)",
    "ρ FR (m)",
    "ρ RL (m)",
    "ρ RR (m)",
];

/// Renders the section, or `None` without rows or iterations.
pub(crate) fn section(
    c: &Calibration,
    palette: &mut Palette,
) -> Result<Option<SectionView>, ReportError> {
    check_optional_len(
        "calibration",
        "iteration_std",
        c.iterations.len(),
        c.iteration_std.len(),
    )?;
    let mut blocks = Vec::new();
    if !c.rows.is_empty() {
        // One cell per parameter, "value ± std": with a column for each
        // standard error the table was wider than the page (its last
        // columns and caption were cut off at 1,120 px).
        let mut headers = vec!["method".to_string()];
        headers.extend(SHORT_LABELS.iter().map(|l| l.to_string()));
        let rows = c
            .rows
            .iter()
            .map(|r| {
                let mut cells = vec![r.method.clone()];
                let std = r.std.map(|s| s.to_array());
                for (i, v) in r.values.to_array().into_iter().enumerate() {
                    let value = fmt_sig(v, if i == 0 { 3 } else { 5 });
                    // A standard error of exactly 0 is a parameter the method
                    // held fixed (the data could not determine it): "± 0"
                    // read as perfectly known.
                    cells.push(match std.map(|s| s[i]) {
                        None => value,
                        Some(0.0) => format!("{value} n.e."),
                        Some(s) => format!("{value} ± {}", fmt_sig(s, 2)),
                    });
                }
                RowView {
                    swatch: Some(palette.css(&r.method)),
                    cells,
                }
            })
            .collect();
        blocks.push(Block::Tables {
            tables: vec![TableView {
                caption: "Calibrated parameters (table III); ± one standard error; \
                          n.e.: not estimated, held at its starting value (the drive \
                          cannot determine it). Each method says where its values \
                          come from (nominal, calibrated on this drive, a params.toml) \
                          and, after +, where the corrections every section applied \
                          to the streams come from."
                    .into(),
                headers,
                rows,
                text_column: None,
            }],
        });
    }
    if let Some(k) = &c.corrections {
        let rows = k
            .rows
            .iter()
            .map(|r| {
                let num = |v: Option<f64>| v.map_or("–".to_string(), |v| fmt_sig(v, 3));
                RowView {
                    swatch: None,
                    cells: vec![
                        format!("{} ({})", r.what, r.unit),
                        num(r.value),
                        num(r.std),
                        r.status.clone(),
                    ],
                }
            })
            .collect();
        blocks.push(Block::Tables {
            tables: vec![TableView {
                caption: format!(
                    "Timing and mounting corrections of the streams every section uses: {}.{}",
                    k.source,
                    if k.rows.iter().any(|r| r.std.is_none() && r.value.is_some()) {
                        " –: no standard error (params.toml keeps the values it applies, \
                         not their errors; a correction not estimated has neither)."
                    } else {
                        ""
                    }
                ),
                headers: ["correction", "value", "std", "status"]
                    .map(String::from)
                    .to_vec(),
                rows,
                text_column: Some(3),
            }],
        });
    }
    if c.iterations.len() >= 2 {
        let color = palette.color(&c.iterated_method);
        let refs: Vec<(String, RGBColor, [f64; 6])> = c
            .rows
            .iter()
            .filter(|r| !r.method.eq_ignore_ascii_case(&c.iterated_method))
            .map(|r| {
                (
                    r.method.clone(),
                    palette.color(&r.method),
                    r.values.to_array(),
                )
            })
            .collect();
        let values: Vec<[f64; 6]> = c.iterations.iter().map(Params::to_array).collect();
        let stds: Vec<[f64; 6]> = c.iteration_std.iter().map(Params::to_array).collect();
        let n = values.len();
        let mut figures = Vec::new();
        for (k, label) in PARAM_LABELS.iter().enumerate() {
            let col: Vec<f64> = values.iter().map(|v| v[k]).collect();
            if !col.iter().any(|v| v.is_finite()) {
                continue;
            }
            let mut span: Vec<f64> = col.clone();
            for (i, s) in stds.iter().enumerate() {
                span.push(col[i] - s[k]);
                span.push(col[i] + s[k]);
            }
            span.extend(refs.iter().map(|r| r.2[k]));
            let Some(yr) = padded_range(span.iter(), 0.08) else {
                continue;
            };
            let frame = Frame::new(-0.3..(n as f64 - 0.7), yr, "iteration", *label)
                .x_integer()
                .size(SMALL_WIDTH, 250)
                .legend(Legend::None);
            let name = format!("calibration-iterations-{}", k);
            let svg = render_chart(&name, &frame, |chart, keys| {
                for (m, rc, v) in &refs {
                    draw_hline(chart, keys, v[k], *rc, Some(m))?;
                }
                data_begin(chart)?;
                for (i, s) in stds.iter().enumerate() {
                    let x = i as f64;
                    if !(col[i] - s[k]).is_finite() || !(col[i] + s[k]).is_finite() {
                        continue;
                    }
                    chart
                        .draw_series(std::iter::once(PathElement::new(
                            vec![(x, col[i] - s[k]), (x, col[i] + s[k])],
                            color.mix(0.5).stroke_width(2),
                        )))
                        .or_plot()?;
                }
                let pts: Vec<(f64, f64)> = col
                    .iter()
                    .enumerate()
                    .filter(|(_, v)| v.is_finite())
                    .map(|(i, v)| (i as f64, *v))
                    .collect();
                draw_line(
                    chart,
                    keys,
                    vec![pts.clone()],
                    color,
                    2,
                    Some(&c.iterated_method),
                )?;
                chart
                    .draw_series(pts.into_iter().map(|p| Circle::new(p, 3, color.filled())))
                    .or_plot()?;
                data_end(chart)
            })?;
            figures.push(FigureView {
                name,
                caption: format!("{label} over the iterations"),
                svg,
            });
        }
        let mut note = format!(
            "Each parameter of the {} calibration over the smoothing–calibration iterations (iteration 0 is the start)",
            c.iterated_method
        );
        if !stds.is_empty() {
            note.push_str("; bars: ± one standard error");
        }
        if !refs.is_empty() {
            let names: Vec<&str> = refs.iter().map(|r| r.0.as_str()).collect();
            note.push_str(&format!(
                "; dashed lines: {} (colours as in the table)",
                names.join(", ")
            ));
        }
        note.push('.');
        blocks.push(Block::Note { text: note });
        blocks.push(Block::Grid { figures });
    }
    Ok(Some(SectionView {
        id: "calibration",
        title: "Calibration",
        blocks,
    }))
}
