//! `deadreckon stream`: the four-wheel filter on JSON-line events from
//! standard input, one JSON line per filter epoch on standard output
//! ([`deadreckon_api::stream`]).

use anyhow::Result;
use deadreckon_api::stream::{self, StreamOptions};

use super::common;
use crate::args::stream::{OnBadLine, StreamArgs};

/// Runs `stream`.
pub fn run(a: StreamArgs) -> Result<()> {
    // The learned parameters and the state file (read, then written) are
    // outputs: neither may be the vehicle or the parameters read.
    let inputs = a.start.inputs();
    for out in a.params_out.iter().chain(a.state.iter()) {
        common::check_output(out, &inputs)?;
    }
    let o = StreamOptions {
        filter: a.start.filter(),
        state: a.state.clone(),
        learn: a.learn,
        params_out: a.params_out.clone(),
        save_every_s: a.save_every_s,
        skip_bad_lines: a.on_bad_line == OnBadLine::Skip,
        last_part: a.last_part,
    };
    let (_, mut online, warning) = stream::start(&a.start.vehicle, &a.start.params, &o)?;
    if let Some(n) = stream::corrections_note(&a.start.params, &online) {
        note!("{n}");
    }
    if let Some(w) = warning {
        note!("warning: {w}");
    }
    let s = stream::run(
        &mut online,
        std::io::stdin().lock(),
        "stdin",
        std::io::stdout().lock(),
        &o,
        &mut |e| note!("skipped: {e}"),
    )?;
    if let Some(e) = s.write_error {
        return common::quiet_on_broken_pipe(Err(e));
    }
    if let Some(st) = s.stats {
        note!("{st}");
    }
    if s.hold_s > 0.0 {
        note!(
            "stored corrections: poses {:.3} s of stream time behind the events",
            s.hold_s
        );
    }
    if s.held_in_state > 0 {
        note!(
            "{} events held back by the corrections kept in the state for the next run",
            s.held_in_state
        );
    }
    if s.skipped > 0 {
        note!("{} bad lines skipped", s.skipped);
    }
    if let Some(l) = s.learned {
        note!(
            "learned: {:.0}% calibrated, {}",
            l.calibrated_pct,
            if l.valid { "valid" } else { "not yet valid" }
        );
        if let Some(path) = &a.params_out {
            note!("wrote {}", path.display());
        }
    }
    Ok(())
}
