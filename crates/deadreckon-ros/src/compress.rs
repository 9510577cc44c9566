//! Chunk decompression for both containers, pure Rust: bz2 (`bzip2` on
//! `libbz2-rs-sys`), lz4 frames (`lz4_flex`, feature `lz4`), zstd frames
//! (`ruzstd`, feature `zstd`). Output is bounded by the size the chunk declares.
//! Also messages compressed one by one (rosbag2's per-message mode).

use std::io::Read;

use crate::error::{Location, RosError};

/// Largest uncompressed chunk accepted (bags and MCAP files are written with
/// chunks of a few MiB at most).
pub(crate) const MAX_CHUNK_BYTES: u64 = 1 << 30;

/// Decompresses `data` into exactly `size` bytes. `compression` is the chunk's
/// name for it: `none` or empty (stored), `bz2`, `lz4`, `zstd`.
pub(crate) fn decompress(
    compression: &str,
    data: &[u8],
    size: u64,
    loc: &Location,
) -> Result<Vec<u8>, RosError> {
    let err = |what: String| RosError::Compression {
        at: Box::new(loc.clone()),
        compression: if compression.is_empty() {
            "uncompressed".into()
        } else {
            compression.to_owned()
        },
        what,
    };
    if size > MAX_CHUNK_BYTES {
        return Err(err(format!(
            "uncompressed size {size} exceeds the limit of {MAX_CHUNK_BYTES} bytes"
        )));
    }
    let missing = |feature: &str| {
        err(format!(
            "this build cannot read it (enable the `{feature}` feature of deadreckon-ros)"
        ))
    };
    let mut out = Vec::with_capacity((size as usize).min(16 << 20));
    let read = match compression {
        "none" | "" => {
            out.extend_from_slice(data);
            Ok(out.len())
        }
        "bz2" => bzip2::read::BzDecoder::new(data)
            .take(size + 1)
            .read_to_end(&mut out),
        #[cfg(feature = "lz4")]
        "lz4" => lz4_flex::frame::FrameDecoder::new(data)
            .take(size + 1)
            .read_to_end(&mut out),
        #[cfg(not(feature = "lz4"))]
        "lz4" => return Err(missing("lz4")),
        #[cfg(feature = "zstd")]
        "zstd" => match ruzstd::decoding::StreamingDecoder::new(data) {
            Ok(d) => d.take(size + 1).read_to_end(&mut out),
            Err(e) => return Err(err(e.to_string())),
        },
        #[cfg(not(feature = "zstd"))]
        "zstd" => return Err(missing("zstd")),
        other => return Err(err(format!("unknown compression '{other}'"))),
    };
    let _ = missing;
    read.map_err(|e| err(e.to_string()))?;
    if out.len() as u64 != size {
        return Err(err(format!(
            "decompressed to {} bytes, the chunk header says {size}",
            out.len()
        )));
    }
    Ok(out)
}

/// Largest uncompressed message accepted from a per-message compressed file.
const MAX_MESSAGE_BYTES: u64 = 64 << 20;

/// zstd frame magic number (RFC 8878).
const ZSTD_MAGIC: [u8; 4] = [0x28, 0xb5, 0x2f, 0xfd];
/// lz4 frame magic number (lz4 frame format).
const LZ4_MAGIC: [u8; 4] = [0x04, 0x22, 0x4d, 0x18];

/// The payload of a message that rosbag2 compressed on its own
/// (`compression_mode: message`: each message's data is one zstd or lz4
/// frame, told apart from CDR, which starts with `00`, by its magic number),
/// or `None` when the data is not compressed.
pub(crate) fn message_payload(data: &[u8], loc: &Location) -> Result<Option<Vec<u8>>, RosError> {
    let compression = match data.get(..4) {
        Some(m) if m == ZSTD_MAGIC => "zstd",
        Some(m) if m == LZ4_MAGIC => "lz4",
        _ => return Ok(None),
    };
    let err = |what: String| RosError::Compression {
        at: Box::new(loc.clone()),
        compression: format!("per-message {compression}"),
        what,
    };
    let missing = |feature: &str| {
        err(format!(
            "this build cannot read it (enable the `{feature}` feature of deadreckon-ros)"
        ))
    };
    let mut out = Vec::new();
    let read = match compression {
        #[cfg(feature = "lz4")]
        "lz4" => lz4_flex::frame::FrameDecoder::new(data)
            .take(MAX_MESSAGE_BYTES + 1)
            .read_to_end(&mut out),
        #[cfg(feature = "zstd")]
        "zstd" => match ruzstd::decoding::StreamingDecoder::new(data) {
            Ok(d) => d.take(MAX_MESSAGE_BYTES + 1).read_to_end(&mut out),
            Err(e) => return Err(err(e.to_string())),
        },
        c => return Err(missing(c)),
    };
    read.map_err(|e| err(e.to_string()))?;
    if out.len() as u64 > MAX_MESSAGE_BYTES {
        return Err(err(format!(
            "a message decompresses to more than {MAX_MESSAGE_BYTES} bytes"
        )));
    }
    Ok(Some(out))
}
