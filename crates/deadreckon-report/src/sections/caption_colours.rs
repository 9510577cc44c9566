//! Issue 34: a caption said orange for a red line. Every colour word in a
//! section's text must name a colour that is drawn in one of its figures.

use plotters::style::RGBColor;

use crate::plot::{colour_name, COLOUR_WORDS};
use crate::render_html;
use crate::sample::sample_input;

/// The names of the `#rrggbb` colours in `svg`.
fn drawn_colour_names(svg: &str) -> Vec<&'static str> {
    let mut names = Vec::new();
    for piece in svg.split('#').skip(1) {
        let hex: String = piece.chars().take(6).collect();
        if hex.len() == 6 && hex.chars().all(|c| c.is_ascii_hexdigit()) {
            let v = |i: usize| u8::from_str_radix(&hex[i..i + 2], 16).unwrap_or(0);
            let name = colour_name(RGBColor(v(0), v(2), v(4)));
            if !names.contains(&name) {
                names.push(name);
            }
        }
    }
    names
}

/// The text of `html` outside its `<svg>` elements and tags.
fn text_outside_svg(html: &str) -> String {
    let mut out = String::new();
    for (k, part) in html.split("<svg").enumerate() {
        let part = if k == 0 {
            part
        } else {
            part.split_once("</svg>").map_or("", |p| p.1)
        };
        for chunk in part.split('<') {
            if let Some((_, text)) = chunk.split_once('>') {
                out.push_str(text);
                out.push(' ');
            }
        }
    }
    out
}

#[test]
fn a_caption_said_orange_for_a_red_line() {
    let html = render_html(&sample_input(120.0)).unwrap();
    let mut checked = 0;
    for section in html.split("<section").skip(1) {
        let section = section.split("</section>").next().unwrap_or("");
        let drawn: Vec<&str> = section
            .split("<svg")
            .skip(1)
            .flat_map(|s| drawn_colour_names(s.split("</svg>").next().unwrap_or("")))
            .collect();
        let text = text_outside_svg(section).to_lowercase();
        for word in text.split(|c: char| !c.is_alphabetic()) {
            if COLOUR_WORDS.contains(&word) {
                checked += 1;
                assert!(
                    drawn.contains(&word),
                    "the text says {word:?}, the figures draw {drawn:?}"
                );
            }
        }
    }
    // The sample's TedriS section names the threshold line and the
    // repositories below the minimum fill.
    assert!(checked >= 2, "only {checked} colour words checked");
}
