//! The candump log parser on arbitrary bytes.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = deadreckon_import::can::parse_candump(data, std::path::Path::new("fuzz.log"));
});
