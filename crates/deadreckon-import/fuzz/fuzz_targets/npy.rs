//! The `.npy` reader (header guard, npyz, reordering, accessors) on arbitrary bytes.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let p = std::path::Path::new("fuzz.npy");
    if let Ok(a) = deadreckon_import::npy::parse_npy(data, p) {
        let _ = a.f64_vector(p);
        let _ = a.f64_rows::<3>(p);
        let _ = a.i64_vector(p);
        let _ = a.bytes_fixed::<8>(p);
    }
});
