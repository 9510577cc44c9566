//! One module per report section; each turns its part of the [`crate::ReportInput`]
//! into a [`SectionView`], or nothing when it has no data.

mod calibration;
#[cfg(test)]
mod caption_colours;
mod drift;
mod errors;
mod health;
mod kinematic;
mod outages;
mod tedris;
mod trajectories;

use crate::model::ReportInput;
use crate::page::SectionView;
use crate::plot::Palette;
use crate::ReportError;

/// Renders every section that has data, in report order.
pub(crate) fn render_all(input: &ReportInput) -> Result<Vec<SectionView>, ReportError> {
    let mut palette = Palette::default();
    register_methods(input, &mut palette);
    let mut out = Vec::new();
    if !input.not_computed.is_empty() {
        out.push(SectionView {
            id: "not-computed",
            title: "Not computed",
            blocks: input
                .not_computed
                .iter()
                .map(|n| crate::page::Block::Note {
                    text: format!("{}: {}", n.what, n.reason),
                })
                .collect(),
        });
    }
    let mut push = |s: Option<SectionView>| {
        if let Some(mut s) = s {
            s.drop_empty_figures();
            if !s.is_empty() {
                out.push(s);
            }
        }
    };
    if let Some(t) = &input.trajectories {
        push(trajectories::section(t, &mut palette)?);
        push(errors::section(t, input.header.start_t_s, &mut palette)?);
    }
    if let Some(k) = &input.kinematic {
        push(Some(kinematic::section(k)));
    }
    if let Some(c) = &input.calibration {
        push(calibration::section(c, &mut palette)?);
    }
    if let Some(d) = &input.drift {
        push(drift::section(d, &mut palette)?);
    }
    if let Some(h) = &input.health {
        push(health::section(h, input.header.start_t_s)?);
    }
    if let Some(t) = &input.tedris {
        push(tedris::section(t, input.header.start_t_s, &mut palette)?);
    }
    if let Some(o) = &input.outages {
        push(outages::section(o, &mut palette)?);
    }
    Ok(out)
}

/// Gives every method its colour in order of first appearance in the report, so
/// that a method has the same colour in every figure.
fn register_methods(input: &ReportInput, palette: &mut Palette) {
    if let Some(t) = &input.trajectories {
        t.dead_reckoned
            .iter()
            .for_each(|m| palette.register(&m.method));
    }
    if let Some(c) = &input.calibration {
        c.rows.iter().for_each(|r| palette.register(&r.method));
        palette.register(&c.iterated_method);
    }
    if let Some(d) = &input.drift {
        d.methods.iter().for_each(|m| palette.register(&m.method));
    }
    if let Some(t) = &input.tedris {
        t.outages
            .iter()
            .flat_map(|o| &o.series)
            .for_each(|s| palette.register(&s.method));
    }
    if let Some(o) = &input.outages {
        o.methods.iter().for_each(|m| palette.register(&m.method));
    }
}

/// Time axis values: `t − start`, or `t` without a start.
pub(crate) fn rel_time(t: &[f64], start: Option<f64>) -> Vec<f64> {
    let s = start.unwrap_or(0.0);
    t.iter().map(|t| t - s).collect()
}

/// The x-axis description of time axes.
pub(crate) fn time_desc(start: Option<f64>) -> &'static str {
    if start.is_some() {
        "time since start (s)"
    } else {
        "time (s)"
    }
}
