//! Plot helpers around plotters' SVG backend: the chart frame (size, axes, tick
//! format, legend), the method colours, equal-aspect ranges, and the data markers
//! that wrap every figure's data elements in `<g class="data">` so that tests and
//! the in-page self-check can tell drawn data from an empty frame.

use std::ops::Range;

use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use crate::stats::nice_step;
use crate::ReportError;

/// The chart type every figure draws on: f64 × f64 Cartesian coordinates.
pub(crate) type Chart<'a, 'b> =
    ChartContext<'a, SVGBackend<'b>, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Result of a drawing closure: plotters' errors as text.
pub(crate) type DrawResult = Result<(), String>;

/// Width of a full-width figure, px (readable at ~800 px).
pub(crate) const WIDTH: u32 = 800;
/// Width of a small-multiple figure, px.
pub(crate) const SMALL_WIDTH: u32 = 390;
/// Outer margin, px.
const MARGIN: u32 = 12;
/// Height of the x label area (ticks + axis description), px.
const X_LABEL_AREA: u32 = 48;
/// Width of the y label area, px.
const Y_LABEL_AREA: u32 = 78;
/// Font family of every text.
pub(crate) const FONT: &str = "sans-serif";

const BEGIN_DATA: &str = "@@DATA_BEGIN@@";
const END_DATA: &str = "@@DATA_END@@";

/// Maps plotters' errors to text inside drawing closures.
pub(crate) trait OrPlot<T> {
    /// The error as text.
    fn or_plot(self) -> Result<T, String>;
}

impl<T, E: std::fmt::Display> OrPlot<T> for Result<T, E> {
    fn or_plot(self) -> Result<T, String> {
        self.map_err(|e| e.to_string())
    }
}

/// Where the legend goes.
#[derive(Debug, Clone)]
pub(crate) enum Legend {
    /// No legend.
    None,
    /// Inside the plotting area.
    Inside(SeriesLabelPosition),
    /// In a column of [`LEGEND_WIDTH`] right of the plotting area (inside the chart width).
    Right,
}

/// Width of the legend column of [`Legend::Right`], px.
pub(crate) const LEGEND_WIDTH: u32 = 190;

/// The symbol of a legend entry.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Swatch {
    /// A solid line of the given width.
    Line(RGBColor, u32),
    /// A dashed line (reference lines).
    Dashed(RGBColor),
    /// A dot (scatter points).
    Dot(RGBColor),
    /// A cross (rejected observations).
    Cross(RGBColor),
    /// A filled bar.
    Bar(RGBColor),
}

/// The legend entries of one chart, in drawing order.
#[derive(Debug, Default)]
pub(crate) struct Keys(Vec<(String, Swatch)>);

impl Keys {
    /// Adds an entry.
    pub fn add(&mut self, label: impl Into<String>, swatch: Swatch) {
        self.0.push((label.into(), swatch));
    }
}

/// Height of one legend entry, px.
const KEY_ROW: i32 = 20;
/// Font size of the legend (plotters divides by 1.24: about 12.9 px).
const KEY_FONT: f64 = 16.0;

/// Draws the legend on the whole chart area at pixel `(x, y)` (top-left), or
/// right-aligned to `x` when `align_right`.
fn draw_keys(
    root: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>,
    keys: &Keys,
    (x, y): (i32, i32),
    align_right: bool,
) -> DrawResult {
    if keys.0.is_empty() {
        return Ok(());
    }
    // plotters' own estimate of the text width for the SVG backend.
    let font = (FONT, KEY_FONT).into_font();
    // Long labels (a method that says where its values and corrections
    // come from, issue 34) wrap onto more lines instead of running out of
    // the chart.
    let wrapped: Vec<Vec<String>> = keys.0.iter().map(|(l, _)| wrap(l, KEY_CHARS)).collect();
    let text_w = wrapped
        .iter()
        .flatten()
        .map(|l| {
            font.box_size(l)
                .map(|b| b.0 as i32)
                .unwrap_or(8 * l.chars().count() as i32)
        })
        .max()
        .unwrap_or(0);
    let w = 40 + text_w + 8;
    let lines: i32 = wrapped.iter().map(|l| l.len() as i32).sum();
    let h = KEY_ROW * lines + 8;
    let x = if align_right { x - w } else { x };
    root.draw(&Rectangle::new(
        [(x, y), (x + w, y + h)],
        WHITE.mix(0.85).filled(),
    ))
    .or_plot()?;
    root.draw(&Rectangle::new(
        [(x, y), (x + w, y + h)],
        RGBColor(170, 170, 170),
    ))
    .or_plot()?;
    let mut row = 0;
    for ((_, swatch), label) in keys.0.iter().zip(&wrapped) {
        let cy = y + 4 + KEY_ROW * row + KEY_ROW / 2;
        row += label.len() as i32;
        let (sx, ex) = (x + 8, x + 32);
        match *swatch {
            Swatch::Line(c, w) => root.draw(&PathElement::new(
                vec![(sx, cy), (ex, cy)],
                c.stroke_width(w.clamp(2, 6)),
            )),
            Swatch::Dashed(c) => {
                for k in 0..3 {
                    let a = sx + 9 * k;
                    root.draw(&PathElement::new(
                        vec![(a, cy), (a + 6, cy)],
                        c.stroke_width(2),
                    ))
                    .or_plot()?;
                }
                Ok(())
            }
            Swatch::Dot(c) => root.draw(&Circle::new(((sx + ex) / 2, cy), 4, c.filled())),
            Swatch::Cross(c) => root.draw(&Cross::new(((sx + ex) / 2, cy), 5, c.stroke_width(2))),
            Swatch::Bar(c) => root.draw(&Rectangle::new(
                [(sx + 2, cy - 6), (ex - 2, cy + 6)],
                c.mix(0.8).filled(),
            )),
        }
        .or_plot()?;
        for (k, line) in label.iter().enumerate() {
            root.draw(&Text::new(
                line.clone(),
                (ex + 8, cy + KEY_ROW * k as i32),
                font.clone()
                    .color(&BLACK)
                    .pos(Pos::new(HPos::Left, VPos::Center)),
            ))
            .or_plot()?;
        }
    }
    Ok(())
}

/// The most characters on one line of a legend entry (the legend column
/// holds about 24 at its font).
const KEY_CHARS: usize = 24;

/// `text` in lines of at most `max` characters, broken at spaces (a longer
/// word keeps its own line).
fn wrap(text: &str, max: usize) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    for word in text.split(' ') {
        match lines.last_mut() {
            Some(l) if l.chars().count() + 1 + word.chars().count() <= max => {
                l.push(' ');
                l.push_str(word);
            }
            _ => lines.push(word.to_string()),
        }
    }
    if lines.is_empty() {
        lines.push(String::new());
    }
    lines
}

/// The frame of one chart.
pub(crate) struct Frame {
    pub x: Range<f64>,
    pub y: Range<f64>,
    pub x_desc: String,
    pub y_desc: String,
    /// Whole width of the chart (legend column included), px.
    pub width: u32,
    pub height: u32,
    pub legend: Legend,
    /// Names of the integer y values (box plots by category).
    pub y_categories: Option<Vec<String>>,
    /// The x values are counts (iterations): labelled at integers only, without decimals.
    pub x_integer: bool,
    /// The y values are decimal logarithms: labelled at whole decades as the
    /// value they stand for (`0.1`, `1`, `10`).
    pub y_log10: bool,
}

impl Frame {
    /// A frame over the given ranges, full width.
    pub fn new(
        x: Range<f64>,
        y: Range<f64>,
        x_desc: impl Into<String>,
        y_desc: impl Into<String>,
    ) -> Self {
        Frame {
            x,
            y,
            x_desc: x_desc.into(),
            y_desc: y_desc.into(),
            width: WIDTH,
            height: 340,
            legend: Legend::Right,
            y_categories: None,
            x_integer: false,
            y_log10: false,
        }
    }

    /// Labels y as a logarithmic axis: the y values are log10 of the
    /// quantity, labelled at whole decades with the quantity.
    pub fn y_log10(mut self) -> Self {
        self.y_log10 = true;
        self
    }

    /// Labels x at whole numbers only, without decimals (an iteration axis).
    pub fn x_integer(mut self) -> Self {
        self.x_integer = true;
        self
    }

    /// Labels the integer y values 0, 1, … with names.
    pub fn y_categories(mut self, names: Vec<String>) -> Self {
        self.y_categories = Some(names);
        self
    }

    /// Sets the size, px.
    pub fn size(mut self, width: u32, height: u32) -> Self {
        self.width = width;
        self.height = height;
        self
    }

    /// Sets the legend.
    pub fn legend(mut self, legend: Legend) -> Self {
        self.legend = legend;
        self
    }

    /// Extra width on the right for the legend, px.
    fn legend_px(&self) -> u32 {
        match self.legend {
            Legend::Right => LEGEND_WIDTH,
            _ => 0,
        }
    }

    /// The size of the plotting area, px.
    pub fn plot_area_px(&self) -> (f64, f64) {
        (
            f64::from(
                self.width
                    .saturating_sub(2 * MARGIN + Y_LABEL_AREA + self.legend_px()),
            ),
            f64::from(self.height.saturating_sub(2 * MARGIN + X_LABEL_AREA)),
        )
    }
}

/// Renders one chart into an SVG string. `draw` draws everything inside the
/// plotting area; it must wrap the data (not reference lines) between
/// [`data_begin`] and [`data_end`].
pub(crate) fn render_chart(
    figure: &str,
    frame: &Frame,
    draw: impl FnOnce(&mut Chart<'_, '_>, &mut Keys) -> DrawResult,
) -> Result<String, ReportError> {
    let err = |message: String| ReportError::Plot {
        figure: figure.to_string(),
        message,
    };
    let mut buf = String::new();
    {
        let root =
            SVGBackend::with_string(&mut buf, (frame.width, frame.height)).into_drawing_area();
        root.fill(&WHITE).or_plot().map_err(err)?;
        let mut chart = ChartBuilder::on(&root)
            .margin(MARGIN)
            .margin_right(MARGIN + frame.legend_px())
            .x_label_area_size(X_LABEL_AREA)
            .y_label_area_size(Y_LABEL_AREA)
            .build_cartesian_2d(frame.x.clone(), frame.y.clone())
            .or_plot()
            .map_err(err)?;
        let x_num = tick_formatter(&frame.x);
        let x_fmt = |v: &f64| {
            if frame.x_integer {
                let r = v.round();
                if (v - r).abs() < 1e-6 {
                    format!("{:.0}", r + 0.0)
                } else {
                    String::new()
                }
            } else {
                x_num(v)
            }
        };
        let y_num = tick_formatter(&frame.y);
        let y_fmt = |v: &f64| match &frame.y_categories {
            Some(names) => {
                let r = v.round();
                if (v - r).abs() < 1e-6 && r >= 0.0 {
                    names.get(r as usize).cloned().unwrap_or_default()
                } else {
                    String::new()
                }
            }
            None if frame.y_log10 => {
                let r = v.round();
                if (v - r).abs() < 1e-6 {
                    fmt_trim(10f64.powf(r), 3)
                } else {
                    String::new()
                }
            }
            None => y_num(v),
        };
        let n_x = if frame.width < 500 { 5 } else { 10 };
        let n_y = match &frame.y_categories {
            Some(names) => names.len() + 1,
            // One label per decade.
            None if frame.y_log10 => (frame.y.end - frame.y.start).round() as usize + 1,
            None if frame.height < 300 => 5,
            None => 8,
        };
        chart
            .configure_mesh()
            .x_desc(frame.x_desc.as_str())
            .y_desc(frame.y_desc.as_str())
            .x_labels(n_x)
            .y_labels(n_y)
            .x_label_formatter(&x_fmt)
            .y_label_formatter(&y_fmt)
            .label_style((FONT, 15))
            .axis_desc_style((FONT, 17))
            .bold_line_style(RGBColor(225, 225, 225))
            .light_line_style(RGBColor(245, 245, 245))
            .draw()
            .or_plot()
            .map_err(err)?;
        let mut keys = Keys::default();
        draw(&mut chart, &mut keys).map_err(err)?;
        // The legend is drawn on the whole chart area (not clipped to the plot).
        let (pw, _) = frame.plot_area_px();
        let left = (MARGIN + Y_LABEL_AREA) as i32;
        let top = MARGIN as i32;
        let placed = match &frame.legend {
            Legend::None => None,
            Legend::Right => Some(((left + pw as i32 + 12, top), false)),
            Legend::Inside(SeriesLabelPosition::UpperLeft) => Some(((left + 8, top + 6), false)),
            Legend::Inside(_) => Some(((left + pw as i32 - 8, top + 6), true)),
        };
        if let Some((at, right)) = placed {
            draw_keys(&root, &keys, at, right).map_err(err)?;
        }
        root.present().or_plot().map_err(err)?;
    }
    Ok(finish_svg(&buf))
}

/// Replaces the data markers by the data group, drops the XML namespace (not needed
/// inline in HTML, and it keeps the page free of URLs) and makes the SVG scale.
fn finish_svg(svg: &str) -> String {
    let mut out = replace_marker(svg, BEGIN_DATA, "<g class=\"data\">");
    out = replace_marker(&out, END_DATA, "</g>");
    // `stroke="none"` is the SVG default: dropping it shortens each scatter dot by a third.
    out = out.replace(" stroke=\"none\" stroke-width=\"1\"/>", "/>");
    out.replacen(
        " xmlns=\"http://www.w3.org/2000/svg\"",
        " class=\"plot\" role=\"img\"",
        1,
    )
}

/// Replaces every `<text …>marker</text>` element by `with`.
fn replace_marker(svg: &str, marker: &str, with: &str) -> String {
    let mut out = String::with_capacity(svg.len());
    let mut rest = svg;
    while let Some(pos) = rest.find(marker) {
        let start = rest[..pos].rfind("<text").unwrap_or(pos);
        let end = rest[pos..]
            .find("</text>")
            .map(|e| pos + e + "</text>".len())
            .unwrap_or(pos + marker.len());
        out.push_str(&rest[..start]);
        out.push_str(with);
        rest = &rest[end..];
    }
    out.push_str(rest);
    out
}

fn marker(chart: &mut Chart<'_, '_>, tag: &str) -> DrawResult {
    let x = chart.x_range().start;
    let y = chart.y_range().start;
    chart
        .plotting_area()
        .draw(&Text::new(
            tag.to_string(),
            (x, y),
            (FONT, 8).into_font().color(&BLACK),
        ))
        .or_plot()
}

/// Starts the data group: everything drawn until [`data_end`] is data.
pub(crate) fn data_begin(chart: &mut Chart<'_, '_>) -> DrawResult {
    marker(chart, BEGIN_DATA)
}

/// Ends the data group.
pub(crate) fn data_end(chart: &mut Chart<'_, '_>) -> DrawResult {
    marker(chart, END_DATA)
}

/// A tick formatter with as many decimals as the tick step needs.
fn tick_formatter(r: &Range<f64>) -> impl Fn(&f64) -> String {
    let step = nice_step((r.end - r.start).abs() / 8.0);
    let decimals = (-step.log10().floor()).max(0.0) as usize;
    let big = r.start.abs().max(r.end.abs()) >= 1e6;
    move |v: &f64| {
        let v = if v.abs() < step * 1e-6 { 0.0 } else { *v };
        if big {
            format!("{v:.3e}")
        } else {
            format!("{v:.decimals$}")
        }
    }
}

/// Formats a value for a table with `sig` significant digits (fixed notation for
/// moderate magnitudes, exponent otherwise).
pub(crate) fn fmt_sig(v: f64, sig: usize) -> String {
    if !v.is_finite() {
        return "–".to_string();
    }
    if v == 0.0 {
        return "0".to_string();
    }
    let mag = v.abs().log10().floor() as i32;
    if !(-4..6).contains(&mag) {
        return format!("{:.*e}", sig.saturating_sub(1), v);
    }
    let decimals = (sig as i32 - 1 - mag).max(0) as usize;
    format!("{v:.decimals$}")
}

/// Like [`fmt_sig`], without trailing zeros after the decimal point.
pub(crate) fn fmt_trim(v: f64, sig: usize) -> String {
    let s = fmt_sig(v, sig);
    if s.contains('e') || !s.contains('.') {
        return s;
    }
    s.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// The range of the finite values in `vs`, padded by `pad` of its span (a unit
/// span around a constant); `None` without finite values.
pub(crate) fn padded_range<'a>(
    vs: impl IntoIterator<Item = &'a f64>,
    pad: f64,
) -> Option<Range<f64>> {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for &v in vs {
        if v.is_finite() {
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    if !lo.is_finite() {
        return None;
    }
    let span = hi - lo;
    if span <= 1e-12 * lo.abs().max(1e-300) {
        let h = if lo == 0.0 { 1.0 } else { 0.05 * lo.abs() };
        return Some(lo - h..hi + h);
    }
    Some(lo - pad * span..hi + pad * span)
}

/// Widens one of the ranges so that one metre has the same length in pixels on
/// both axes of a `width` × `height` chart.
pub(crate) fn equal_aspect(
    x: Range<f64>,
    y: Range<f64>,
    plot_area_px: (f64, f64),
) -> (Range<f64>, Range<f64>) {
    let (w, h) = plot_area_px;
    let (sx, sy) = (x.end - x.start, y.end - y.start);
    // metres per pixel on each axis; widen the axis with fewer metres per pixel.
    let (mx, my) = (sx / w, sy / h);
    if mx > my {
        let c = 0.5 * (y.start + y.end);
        let half = 0.5 * mx * h;
        (x, c - half..c + half)
    } else {
        let c = 0.5 * (x.start + x.end);
        let half = 0.5 * my * w;
        (c - half..c + half, y)
    }
}

/// Points of a series as (x, y) pairs split at non-finite values, for line drawing.
pub(crate) fn segments(x: &[f64], y: &[f64], idx: &[usize]) -> Vec<Vec<(f64, f64)>> {
    let mut out = Vec::new();
    let mut cur = Vec::new();
    for &i in idx {
        let (a, b) = (x[i], y[i]);
        if a.is_finite() && b.is_finite() {
            cur.push((a, b));
        } else if !cur.is_empty() {
            out.push(std::mem::take(&mut cur));
        }
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

/// Draws a line series (split at non-finite values) with a legend entry.
pub(crate) fn draw_line(
    chart: &mut Chart<'_, '_>,
    keys: &mut Keys,
    pieces: Vec<Vec<(f64, f64)>>,
    color: RGBColor,
    width: u32,
    label: Option<&str>,
) -> DrawResult {
    if let Some(l) = label {
        keys.add(l, Swatch::Line(color, width));
    }
    for piece in pieces {
        chart
            .draw_series(LineSeries::new(piece, color.stroke_width(width)))
            .or_plot()?;
    }
    Ok(())
}

/// Draws a horizontal reference line across the chart, dashed, with a legend entry.
pub(crate) fn draw_hline(
    chart: &mut Chart<'_, '_>,
    keys: &mut Keys,
    y: f64,
    color: RGBColor,
    label: Option<&str>,
) -> DrawResult {
    if !y.is_finite() {
        return Ok(());
    }
    let xr = chart.x_range();
    chart
        .draw_series(DashedLineSeries::new(
            vec![(xr.start, y), (xr.end, y)],
            8,
            5,
            color.stroke_width(2),
        ))
        .or_plot()?;
    if let Some(l) = label {
        keys.add(l, Swatch::Dashed(color));
    }
    Ok(())
}

/// Draws a vertical reference line across the chart, dashed.
pub(crate) fn draw_vline(
    chart: &mut Chart<'_, '_>,
    keys: &mut Keys,
    x: f64,
    color: RGBColor,
    label: Option<&str>,
) -> DrawResult {
    if !x.is_finite() {
        return Ok(());
    }
    let yr = chart.y_range();
    chart
        .draw_series(DashedLineSeries::new(
            vec![(x, yr.start), (x, yr.end)],
            8,
            5,
            color.stroke_width(2),
        ))
        .or_plot()?;
    if let Some(l) = label {
        keys.add(l, Swatch::Dashed(color));
    }
    Ok(())
}

mod palette;
#[cfg(test)]
mod tests;

pub(crate) use palette::{colour_name, Palette, GATED, REFERENCE};
#[cfg(test)]
pub(crate) use palette::{COLOUR_WORDS, EXTRA};
