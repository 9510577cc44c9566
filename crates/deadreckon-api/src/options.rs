//! The commands' option words parsed into the library's enums.

use deadreckon_core::calibrate::{Iteration, PassState};
use deadreckon_core::ekf::Timing;
use deadreckon_core::timing::Which;

use crate::Error;

/// `--timing`: `wheel` (the paper's, one epoch per wheel row) or `each`.
pub fn parse_timing(s: &str) -> Result<Timing, Error> {
    match s {
        "wheel" => Ok(Timing::WheelEpochs),
        "each" => Ok(Timing::EachMeasurement),
        _ => Err(unknown("timing", s, "wheel, each")),
    }
}

/// `calibrate --iteration`: `anderson` or `plain`.
pub fn parse_iteration(s: &str) -> Result<Iteration, Error> {
    match s {
        "anderson" => Ok(Iteration::Anderson),
        "plain" => Ok(Iteration::Plain),
        _ => Err(unknown("iteration", s, "anderson, plain")),
    }
}

/// `calibrate --state`: `augmented` or `paper`.
pub fn parse_pass_state(s: &str) -> Result<PassState, Error> {
    match s {
        "augmented" => Ok(PassState::Augmented),
        "paper" => Ok(PassState::Paper),
        _ => Err(unknown("pass state", s, "augmented, paper")),
    }
}

/// `--corrections`: `auto`, `gnss`, `all` or `none`.
pub fn parse_corrections(s: &str) -> Result<Which, Error> {
    match s {
        "auto" => Ok(Which::Auto),
        "gnss" => Ok(Which::Gnss),
        "all" => Ok(Which::All),
        "none" => Ok(Which::None),
        _ => Err(unknown("corrections", s, "auto, gnss, all, none")),
    }
}

fn unknown(what: &'static str, value: &str, allowed: &'static str) -> Error {
    Error::UnknownOption {
        what,
        value: value.to_string(),
        allowed,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_parse_and_unknown_words_say_what_is_allowed() {
        assert_eq!(parse_timing("each").unwrap(), Timing::EachMeasurement);
        assert_eq!(parse_iteration("plain").unwrap(), Iteration::Plain);
        assert_eq!(parse_pass_state("paper").unwrap(), PassState::Paper);
        assert_eq!(parse_corrections("gnss").unwrap(), Which::Gnss);
        assert!(parse_corrections("some").is_err());
        assert_eq!(
            parse_timing("every").unwrap_err().to_string(),
            "unknown timing `every` (wheel, each)"
        );
    }
}
