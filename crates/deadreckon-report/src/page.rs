//! The page: view types the sections produce (facts, tables, figures), the header
//! and footer, and the HTML template (minijinja, auto-escaped; only the SVG from
//! plotters is inserted as is).

use serde::Serialize;

use crate::model::{Footer, Header};
use crate::plot::fmt_sig;
use crate::ReportError;

/// One rendered section.
#[derive(Debug, Clone, Serialize)]
pub(crate) struct SectionView {
    /// HTML id (anchor).
    pub id: &'static str,
    /// Heading.
    pub title: &'static str,
    /// Content, in order.
    pub blocks: Vec<Block>,
}

/// A piece of a section.
#[derive(Debug, Clone, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub(crate) enum Block {
    /// A line of text.
    Note { text: String },
    /// Tables side by side.
    Tables { tables: Vec<TableView> },
    /// Full-width figures.
    Figure(FigureView),
    /// Small multiples in a grid.
    Grid { figures: Vec<FigureView> },
}

/// A table.
#[derive(Debug, Clone, Serialize)]
pub(crate) struct TableView {
    pub caption: String,
    pub headers: Vec<String>,
    pub rows: Vec<RowView>,
    /// The column of words (a status, a verdict): it wraps and is left-aligned,
    /// so that the table stays within the page (the corrections' status ran
    /// past it, even at 1920 px; issue 34).
    pub text_column: Option<usize>,
}

/// A table row: the first cell may carry the method's colour swatch.
#[derive(Debug, Clone, Serialize)]
pub(crate) struct RowView {
    pub swatch: Option<String>,
    pub cells: Vec<String>,
}

/// A figure: plotters' SVG and a caption.
#[derive(Debug, Clone, Serialize)]
pub(crate) struct FigureView {
    /// Stable name, used by the self-check.
    pub name: String,
    pub caption: String,
    pub svg: String,
}

impl FigureView {
    /// True when the figure's data group holds at least one element (a figure
    /// whose series were all non-finite would otherwise be an empty frame).
    pub fn has_data(&self) -> bool {
        self.svg
            .split("<g class=\"data\">")
            .skip(1)
            .any(|g| g.trim_start().starts_with('<') && !g.trim_start().starts_with("</g>"))
    }
}

impl SectionView {
    /// Drops figures without data, then grids and table groups left empty.
    pub fn drop_empty_figures(&mut self) {
        self.blocks.retain_mut(|b| match b {
            Block::Figure(f) => f.has_data(),
            Block::Grid { figures } => {
                figures.retain(FigureView::has_data);
                !figures.is_empty()
            }
            Block::Tables { tables } => !tables.is_empty(),
            Block::Note { .. } => true,
        });
    }

    /// True when the section has no figure and no table.
    pub fn is_empty(&self) -> bool {
        !self.blocks.iter().any(|b| match b {
            Block::Note { .. } => false,
            Block::Tables { tables } => !tables.is_empty(),
            Block::Figure(_) => true,
            Block::Grid { figures } => !figures.is_empty(),
        })
    }
}

#[derive(Debug, Serialize)]
struct HeaderView {
    drive_name: String,
    facts: Vec<(String, String)>,
    streams: Vec<(String, String, String)>,
    inputs: Vec<(String, String)>,
}

#[derive(Debug, Serialize)]
struct Page<'a> {
    header: HeaderView,
    sections: &'a [SectionView],
    footer: &'a Footer,
}

fn header_view(h: &Header) -> HeaderView {
    let mut facts = Vec::new();
    if let Some(d) = h.duration_s.filter(|d| d.is_finite()) {
        // Minutes and seconds of the rounded whole seconds: 59.96 s is
        // "1 min 0 s", not "0 min 60 s".
        let whole = d.round();
        let (m, s) = ((whole / 60.0).floor(), whole % 60.0);
        facts.push(("duration".into(), format!("{d:.1} s ({m:.0} min {s:.0} s)")));
    }
    if let Some(d) = h.distance_m.filter(|d| d.is_finite()) {
        facts.push(("distance".into(), format!("{:.3} km", d / 1000.0)));
    }
    let streams = h
        .streams
        .iter()
        .map(|s| {
            (
                s.name.clone(),
                s.samples.to_string(),
                s.rate_hz
                    .filter(|r| r.is_finite())
                    .map(|r| fmt_sig(r, 3))
                    .unwrap_or_else(|| "–".into()),
            )
        })
        .collect();
    HeaderView {
        drive_name: if h.drive_name.is_empty() {
            "(unnamed drive)".into()
        } else {
            h.drive_name.clone()
        },
        facts,
        streams,
        inputs: h
            .inputs
            .iter()
            .map(|n| (n.name.clone(), n.value.clone()))
            .collect(),
    }
}

const TEMPLATE: &str = include_str!("report.html.j2");

/// Renders the page.
pub(crate) fn render_page(
    header: &Header,
    footer: &Footer,
    sections: &[SectionView],
) -> Result<String, ReportError> {
    let mut env = minijinja::Environment::new();
    env.set_auto_escape_callback(|_| minijinja::AutoEscape::Html);
    env.add_template("report.html", TEMPLATE)
        .map_err(|e| ReportError::Template(e.to_string()))?;
    let page = Page {
        header: header_view(header),
        sections,
        footer,
    };
    env.get_template("report.html")
        .and_then(|t| t.render(minijinja::value::Serde(&page)))
        .map_err(|e| ReportError::Template(e.to_string()))
}
