//! Unit tests of the plotting helpers.

use super::*;

#[test]
fn equal_aspect_gives_equal_metres_per_pixel() {
    let (w, h) = Frame::new(0.0..1.0, 0.0..1.0, "", "")
        .size(800, 600)
        .plot_area_px();
    let (x, y) = equal_aspect(0.0..1000.0, -50.0..50.0, (w, h));
    let (mx, my) = ((x.end - x.start) / w, (y.end - y.start) / h);
    assert!((mx - my).abs() < 1e-9 * mx);
    assert!(x.start <= 0.0 && x.end >= 1000.0 && y.start <= -50.0 && y.end >= 50.0);
}

#[test]
fn palette_is_consistent_and_aliases_share_colours() {
    let mut p = Palette::default();
    assert_eq!(p.color("GT"), p.color("truth"));
    assert_eq!(p.color("Ours"), p.color("RTS"));
    let a = p.color("my method");
    let b = p.color("other");
    assert_ne!(a, b);
    assert_eq!(p.color("My Method"), a);
}

/// Issue 34: TedriS and the four-wheel filter were drawn in two purples.
#[test]
fn tedris_and_the_four_wheel_filter_were_two_purples() {
    let mut p = Palette::default();
    for m in ["nominal", "RTS", "zupt", "truth", "filtered", "smoothed"] {
        p.register(m);
    }
    let t = p.color("TedriS");
    let f = p.color("four-wheel");
    assert_ne!(colour_name(t), colour_name(f), "{t:?} and {f:?}");
    // The extra colours a further method can get stay away from TedriS's
    // purple: the removed extra purple was 60.5 away in RGB, the nearest
    // extra now (brown 140, 86, 75) is 91.8.
    let d = |a: RGBColor, b: RGBColor| {
        let sq = |x: u8, y: u8| (f64::from(x) - f64::from(y)).powi(2);
        (sq(a.0, b.0) + sq(a.1, b.1) + sq(a.2, b.2)).sqrt()
    };
    for e in EXTRA {
        assert!(d(e, t) > 80.0, "{e:?} too close to TedriS {t:?}");
    }
}

#[test]
fn colour_names_follow_the_hue() {
    assert_eq!(colour_name(REFERENCE), "red");
    assert_eq!(colour_name(GATED), "orange");
    assert_eq!(colour_name(RGBColor(117, 60, 160)), "purple");
    assert_eq!(colour_name(RGBColor(0, 114, 178)), "blue");
    assert_eq!(colour_name(RGBColor(0, 158, 115)), "green");
    assert_eq!(colour_name(RGBColor(204, 121, 167)), "pink");
    assert_eq!(colour_name(RGBColor(120, 120, 120)), "grey");
    assert_eq!(colour_name(RGBColor(40, 40, 40)), "black");
    assert_eq!(colour_name(RGBColor(140, 86, 75)), "brown");
    for c in EXTRA {
        assert!(COLOUR_WORDS.contains(&colour_name(c)));
    }
}

#[test]
fn table_numbers_are_compact() {
    assert_eq!(fmt_sig(-0.00298, 3), "-0.00298");
    assert_eq!(fmt_sig(1.91664, 5), "1.9166");
    assert_eq!(fmt_sig(2.25148, 4), "2.251");
    assert_eq!(fmt_sig(1.2e-7, 3), "1.20e-7");
    assert_eq!(fmt_sig(f64::NAN, 3), "–");
    assert_eq!(fmt_trim(1.0, 3), "1");
    assert_eq!(fmt_trim(0.6333, 6), "0.6333");
    assert_eq!(fmt_trim(100.0, 3), "100");
}
