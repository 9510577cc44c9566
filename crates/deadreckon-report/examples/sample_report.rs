//! Writes a full synthetic report: `cargo run -p deadreckon-report --example sample_report -- OUT.html [DURATION_S]`.

use std::process::ExitCode;

fn main() -> ExitCode {
    let mut args = std::env::args().skip(1);
    let Some(out) = args.next() else {
        eprintln!("usage: sample_report OUT.html [DURATION_S (default 3600)]");
        return ExitCode::from(2);
    };
    let duration_s = match args.next().map(|d| d.parse::<f64>()) {
        None => 3600.0,
        Some(Ok(d)) if d > 1.0 => d,
        Some(_) => {
            eprintln!("DURATION_S must be a number of seconds above 1");
            return ExitCode::from(2);
        }
    };
    let input = deadreckon_report::sample::sample_input(duration_s);
    match deadreckon_report::write_report(&out, &input) {
        Ok(()) => {
            let size = std::fs::metadata(&out).map(|m| m.len()).unwrap_or(0);
            println!("wrote {out} ({size} bytes)");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
