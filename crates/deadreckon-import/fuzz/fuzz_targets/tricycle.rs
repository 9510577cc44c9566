//! The tricycle log parser and drive builder on arbitrary bytes.
#![no_main]

use deadreckon_import::tricycle::{parse_record, parse_tricycle, tricycle_drive, TricycleOptions};
use deadreckon_import::TimeOrderPolicy;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let p = std::path::Path::new("fuzz.txt");
    if let Ok(text) = std::str::from_utf8(data) {
        for (i, line) in text.lines().enumerate() {
            let _ = parse_record(line, i + 1);
        }
    }
    if let Ok(log) = parse_tricycle(data, p) {
        for policy in [TimeOrderPolicy::Error, TimeOrderPolicy::Gate] {
            let _ = tricycle_drive(&log, p, &TricycleOptions { policy, ..Default::default() });
        }
    }
});
