//! The report's colours: one per method across every figure ([`Palette`]),
//! the fixed ones, and the words captions use for them.

use std::collections::HashMap;

use plotters::prelude::*;

/// Consistent colours per method across all figures.
#[derive(Debug, Clone, Default)]
pub(crate) struct Palette {
    assigned: HashMap<String, RGBColor>,
    next: usize,
}

/// Colours for methods without a fixed colour, in order of first appearance
/// (no purple: that is TedriS's, and the four-wheel filter drew in a second
/// purple beside it; issue 34).
pub(crate) const EXTRA: [RGBColor; 7] = [
    RGBColor(23, 190, 207),
    RGBColor(188, 189, 34),
    RGBColor(214, 39, 40),
    RGBColor(140, 86, 75),
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
];

/// The colour of a gated (rejected) observation.
pub(crate) const GATED: RGBColor = RGBColor(213, 94, 0);
/// The colour of reference lines (thresholds, bounds).
pub(crate) const REFERENCE: RGBColor = RGBColor(200, 30, 30);

fn canonical(method: &str) -> String {
    // A label that says where the values came from (`RTS, calibrated on
    // this drive; streams corrected as params.toml stores`) keeps its
    // method's colour.
    let m = method
        .split([',', ';', '+'])
        .next()
        .unwrap_or(method)
        .trim()
        .to_lowercase();
    match m.as_str() {
        "gt" | "ground truth" | "reference" => "truth".to_string(),
        "ours" | "our method" | "rts calibration" | "rts-calibrated" => "rts".to_string(),
        "ekf" => "filtered".to_string(),
        // The comparison's four-wheel filter is the RTS-calibrated one.
        "four-wheel" | "four-wheel ekf" => "rts".to_string(),
        _ => m,
    }
}

fn fixed(canonical: &str) -> Option<RGBColor> {
    Some(match canonical {
        "truth" => RGBColor(40, 40, 40),
        "gnss" => RGBColor(120, 120, 120),
        "filtered" => RGBColor(0, 158, 115),
        "smoothed" => RGBColor(86, 180, 233),
        "rts" => RGBColor(0, 114, 178),
        "zupt" => RGBColor(230, 159, 0),
        "nominal" => RGBColor(204, 121, 167),
        "tedris" => RGBColor(117, 60, 160),
        _ => return None,
    })
}

/// The word a caption uses for a colour: the hue's name, `grey` or `black` for
/// the unsaturated ones, `brown` for a dark red or orange. Captions name colours
/// through this, so that the word matches what is drawn.
pub(crate) fn colour_name(c: RGBColor) -> &'static str {
    let (r, g, b) = (f64::from(c.0), f64::from(c.1), f64::from(c.2));
    let max = r.max(g).max(b);
    let min = r.min(g).min(b);
    if max - min < 30.0 {
        return if max < 70.0 { "black" } else { "grey" };
    }
    let d = max - min;
    let hue = if max == r {
        (60.0 * (g - b) / d).rem_euclid(360.0)
    } else if max == g {
        60.0 * (b - r) / d + 120.0
    } else {
        60.0 * (r - g) / d + 240.0
    };
    match hue {
        h if !(15.0..345.0).contains(&h) => {
            if max < 150.0 {
                "brown"
            } else {
                "red"
            }
        }
        h if h < 45.0 => {
            if max < 150.0 {
                "brown"
            } else {
                "orange"
            }
        }
        h if h < 70.0 => "yellow",
        h if h < 170.0 => "green",
        h if h < 200.0 => "cyan",
        h if h < 255.0 => "blue",
        h if h < 295.0 => "purple",
        _ => "pink",
    }
}

/// Every colour word [`colour_name`] can give.
#[cfg(test)]
pub(crate) const COLOUR_WORDS: [&str; 11] = [
    "black", "grey", "brown", "red", "orange", "yellow", "green", "cyan", "blue", "purple", "pink",
];

impl Palette {
    /// Registers a method so that it keeps its colour in every figure.
    pub fn register(&mut self, method: &str) {
        let key = canonical(method);
        if fixed(&key).is_some() || self.assigned.contains_key(&key) {
            return;
        }
        let c = EXTRA[self.next % EXTRA.len()];
        self.next += 1;
        self.assigned.insert(key, c);
    }

    /// The colour of a method (registering it if new).
    pub fn color(&mut self, method: &str) -> RGBColor {
        self.register(method);
        let key = canonical(method);
        fixed(&key)
            .or_else(|| self.assigned.get(&key).copied())
            .unwrap_or(BLACK)
    }

    /// The colour as CSS hex, for tables.
    pub fn css(&mut self, method: &str) -> String {
        let c = self.color(method);
        format!("#{:02x}{:02x}{:02x}", c.0, c.1, c.2)
    }
}
