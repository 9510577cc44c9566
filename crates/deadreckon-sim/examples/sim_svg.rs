//! Writes the true path of a built-in scenario as an SVG polyline (a quick look).
//!
//! `cargo run -p deadreckon-sim --example sim_svg -- NAME > path.svg`

use deadreckon_sim::{simulate, Scenario, SimError};

fn main() -> Result<(), SimError> {
    let name = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "calibration".into());
    let out = simulate(&Scenario::builtin(&name)?, 1)?;
    let pts: Vec<(f64, f64)> = out
        .drive
        .truth
        .iter()
        .map(|p| (p.east_m, p.north_m))
        .collect();
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in &pts {
        x0 = x0.min(x);
        x1 = x1.max(x);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    let scale = 800.0 / (x1 - x0).max(y1 - y0);
    let poly: Vec<String> = pts
        .iter()
        .step_by(10)
        .map(|(x, y)| {
            format!(
                "{:.1},{:.1}",
                (x - x0) * scale + 10.0,
                (y1 - y) * scale + 10.0
            )
        })
        .collect();
    println!(
        "<svg xmlns='http://www.w3.org/2000/svg' width='820' height='820'><rect width='820' height='820' fill='white'/>\
         <polyline fill='none' stroke='black' stroke-width='1' points='{}'/>\
         <circle cx='{:.1}' cy='{:.1}' r='4' fill='red'/></svg>",
        poly.join(" "),
        (pts[0].0 - x0) * scale + 10.0,
        (y1 - pts[0].1) * scale + 10.0
    );
    Ok(())
}
