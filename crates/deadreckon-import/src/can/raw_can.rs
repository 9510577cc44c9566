//! The comma2k19 `raw_can` arrays: `t` (s), `src` (bus), `address` (id) and
//! `data` (`|S8` byte strings, trailing zero bytes stripped by NumPy and padded
//! back here to 8 bytes: the RAV4's frames are all 8 bytes long).

use std::path::Path;

use super::CanFrame;
use crate::npy::read_npy;
use crate::ImportError;

/// Reads a `raw_can` directory (holding `t`, `src`, `address`, `data`).
pub fn read_raw_can(dir: &Path) -> Result<Vec<CanFrame>, ImportError> {
    if !dir.join("t").exists() {
        // A comma2k19 segment (or its processed_log) given where its raw_can
        // folder belongs: say where that folder is.
        for inner in ["processed_log/CAN/raw_can", "CAN/raw_can"] {
            if dir.join(inner).join("t").exists() {
                return Err(ImportError::WrongSource {
                    path: dir.to_path_buf(),
                    message: format!(
                        "a comma2k19 segment directory, not a raw_can folder: give `import can` \
                         {} (or import the whole segment with `import comma2k19`)",
                        dir.join(inner).display()
                    ),
                });
            }
        }
    }
    let load = |name: &str| {
        let p = dir.join(name);
        read_npy(&p).map(|a| (a, p))
    };
    let (t, tp) = load("t")?;
    let t = t.f64_vector(&tp)?;
    let (src, sp) = load("src")?;
    let src = src.i64_vector(&sp)?;
    let (address, ap) = load("address")?;
    let address = address.i64_vector(&ap)?;
    let (data, dp) = load("data")?;
    let data = data.bytes_fixed::<8>(&dp)?;
    let n = t.len();
    for (name, len) in [
        ("src", src.len()),
        ("address", address.len()),
        ("data", data.len()),
    ] {
        if len != n {
            return Err(ImportError::Stream {
                path: dir.to_path_buf(),
                stream: "raw_can".into(),
                index: len.min(n),
                t_s: f64::NAN,
                message: format!("`{name}` has {len} items, `t` has {n}"),
            });
        }
    }
    let mut frames = Vec::with_capacity(n);
    for (i, (((t, s), a), d)) in t.into_iter().zip(src).zip(address).zip(data).enumerate() {
        let id = u32::try_from(a)
            .ok()
            .filter(|&a| a <= 0x1FFF_FFFF)
            .ok_or_else(|| ImportError::Stream {
                path: dir.join("address"),
                stream: "raw_can".into(),
                index: i,
                t_s: t,
                message: format!("address {a} is not a CAN identifier"),
            })?;
        frames.push(CanFrame {
            t_s: t,
            bus: s.to_string(),
            id,
            extended: id > 0x7FF,
            rtr: false,
            data: d.to_vec(),
        });
    }
    Ok(frames)
}
