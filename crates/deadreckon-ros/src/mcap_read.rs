//! Reading MCAP files (ROS2 `cdr` or ROS1 `ros1` message encoding) into a drive.
//!
//! The records are walked here, in the file and in each chunk, so that every
//! error names the byte offset of its record and no length is trusted before it
//! is checked; `mcap` parses each record's body. Chunks are decompressed by
//! [`crate::compress`] (zstd and lz4 behind features) and their CRC is checked.

use std::borrow::Cow;
use std::collections::BTreeMap;

use mcap::records::{op, Record};

use crate::error::{Location, RosError};
use crate::ingest::{ImportReport, Ingest};
use crate::mapping::Mapping;
use crate::msgs::{decode_ros1, MsgType};
use crate::TopicInfo;

/// The 8 bytes an MCAP file starts and ends with.
pub const MAGIC: &[u8] = b"\x89MCAP0\r\n";

struct Channel {
    topic: String,
    schema_name: String,
    message_encoding: String,
}

struct Msg<'a> {
    channel: u16,
    log_time_ns: u64,
    data: Cow<'a, [u8]>,
    /// Offset of the message record: in the file, or in the uncompressed chunk.
    offset: u64,
    /// Offset of the chunk record holding the message, if any.
    chunk_at: Option<u64>,
}

#[derive(Default)]
struct Mcap<'a> {
    schemas: BTreeMap<u16, (String, String)>,
    channels: BTreeMap<u16, Channel>,
    messages: Vec<Msg<'a>>,
}

/// Parses the records the reader uses (schema, channel, message, chunk) with
/// `mcap`; every other record is skipped unparsed: fuzzing found `mcap` 0.26's
/// attachment parser slicing past a short body.
fn parse<'b>(opcode: u8, body: &'b [u8], at: &Location) -> Result<Option<Record<'b>>, RosError> {
    match opcode {
        op::SCHEMA | op::CHANNEL | op::MESSAGE | op::CHUNK => mcap::parse_record(opcode, body)
            .map(Some)
            .map_err(|e| RosError::format(at.clone(), e.to_string())),
        _ => Ok(None),
    }
}

/// Walks the records (opcode u8, length u64, body) of `buf` from `pos`, calling
/// `f(offset, opcode, body)` on each until it returns `false` or `buf` ends.
/// Returns the offset after the last record read.
fn walk<'b>(
    buf: &'b [u8],
    mut pos: usize,
    loc: &Location,
    mut f: impl FnMut(usize, u8, &'b [u8]) -> Result<bool, RosError>,
) -> Result<usize, RosError> {
    while pos < buf.len() {
        let at = loc.at(pos as u64);
        let head = buf
            .get(pos..pos + 9)
            .ok_or_else(|| RosError::format(at.clone(), "record header cut short"))?;
        let opcode = head[0];
        let mut len = [0u8; 8];
        len.copy_from_slice(&head[1..9]);
        let len = u64::from_le_bytes(len);
        let start = pos + 9;
        let end = usize::try_from(len)
            .ok()
            .and_then(|l| start.checked_add(l))
            .filter(|&e| e <= buf.len())
            .ok_or_else(|| {
                RosError::format(at, format!("record of {len} bytes runs past the end"))
            })?;
        let more = f(pos, opcode, &buf[start..end])?;
        pos = end;
        if !more {
            break;
        }
    }
    Ok(pos)
}

impl<'a> Mcap<'a> {
    fn record(
        &mut self,
        rec: Record<'a>,
        at: &Location,
        chunk_at: Option<u64>,
    ) -> Result<(), RosError> {
        match rec {
            Record::Schema { header, .. } => {
                if header.id == 0 {
                    return Err(RosError::format(at.clone(), "schema with id 0"));
                }
                self.schemas
                    .insert(header.id, (header.name, header.encoding));
            }
            Record::Channel(c) => {
                let schema_name = match c.schema_id {
                    0 => String::new(),
                    id => match self.schemas.get(&id) {
                        Some((name, _)) => name.clone(),
                        None => {
                            return Err(RosError::format(
                                at.on(&c.topic),
                                format!(
                                    "channel {} names schema {id}, which is not declared before it",
                                    c.id
                                ),
                            ))
                        }
                    },
                };
                self.channels.insert(
                    c.id,
                    Channel {
                        topic: c.topic,
                        schema_name,
                        message_encoding: c.message_encoding,
                    },
                );
            }
            Record::Message { header, data } => self.messages.push(Msg {
                channel: header.channel_id,
                log_time_ns: header.log_time,
                data,
                offset: at.offset.unwrap_or(0),
                chunk_at,
            }),
            Record::Chunk { header, data } => {
                if chunk_at.is_some() {
                    return Err(RosError::format(at.clone(), "chunk inside a chunk"));
                }
                let offset = at.offset.unwrap_or(0);
                let chunk_loc = Location {
                    in_chunk_at: Some(offset),
                    offset: None,
                    ..at.clone()
                };
                let raw = crate::compress::decompress(
                    &header.compression,
                    &data,
                    header.uncompressed_size,
                    &chunk_loc,
                )?;
                if header.uncompressed_crc != 0 && crc32fast::hash(&raw) != header.uncompressed_crc
                {
                    return Err(RosError::Compression {
                        at: Box::new(chunk_loc),
                        compression: header.compression,
                        what: "CRC of the uncompressed records does not match".into(),
                    });
                }
                let mut inner = Vec::new();
                walk(&raw, 0, &chunk_loc, |pos, opcode, body| {
                    let at = chunk_loc.at(pos as u64);
                    if let Some(rec) = parse(opcode, body, &at)? {
                        inner.push((at, rec.into_owned()));
                    }
                    Ok(true)
                })?;
                for (at, rec) in inner {
                    self.record(rec, &at, Some(offset))?;
                }
            }
            _ => {}
        }
        Ok(())
    }

    fn parse(buf: &'a [u8], file: &str) -> Result<Self, RosError> {
        let loc = Location::file(file);
        if !buf.starts_with(MAGIC) {
            return Err(RosError::format(loc.at(0), "not an MCAP file (bad magic)"));
        }
        let mut m = Mcap::default();
        let mut footer = false;
        let end = walk(buf, MAGIC.len(), &loc, |pos, opcode, body| {
            let at = loc.at(pos as u64);
            if opcode == op::FOOTER {
                footer = true;
                return Ok(false);
            }
            if let Some(rec) = parse(opcode, body, &at)? {
                m.record(rec, &at, None)?;
            }
            Ok(true)
        })?;
        if !footer {
            return Err(RosError::format(
                loc.at(end as u64),
                "file ends before the footer record (truncated?)",
            ));
        }
        if buf.get(end..) != Some(MAGIC) {
            return Err(RosError::format(
                loc.at(end as u64),
                "footer not followed by the closing magic",
            ));
        }
        Ok(m)
    }

    /// Messages sorted by log time, stable (file order among equal times).
    fn sorted(&self) -> Vec<&Msg<'a>> {
        let mut v: Vec<&Msg<'a>> = self.messages.iter().collect();
        v.sort_by_key(|m| m.log_time_ns);
        v
    }
}

/// Reads an MCAP file held in memory. `file` names it in errors and in the report.
pub fn read_mcap_bytes(
    bytes: &[u8],
    file: &str,
    mapping: &Mapping,
) -> Result<(deadreckon_core::Drive, ImportReport), RosError> {
    mapping.validate()?;
    let m = Mcap::parse(bytes, file)?;
    let loc = Location::file(file);
    let topics: Vec<(String, String)> = m
        .channels
        .values()
        .map(|c| (c.topic.clone(), c.schema_name.clone()))
        .collect();
    let mut ingest = Ingest::new(mapping, file, "mcap");
    ingest.bind(&topics, &loc)?;
    for msg in m.sorted() {
        let Some(ch) = m.channels.get(&msg.channel) else {
            return Err(RosError::format(
                Location {
                    in_chunk_at: msg.chunk_at,
                    ..loc.at(msg.offset)
                },
                format!(
                    "message on channel {} that no channel record declares",
                    msg.channel
                ),
            ));
        };
        let Some(i) = ingest.stream_of(&ch.topic) else {
            continue;
        };
        let at = Location {
            in_chunk_at: msg.chunk_at,
            ..loc.on(&ch.topic).at(msg.offset)
        };
        let t: MsgType = ingest.msg_type(i);
        let payload = crate::compress::message_payload(&msg.data, &at)?;
        let data = payload.as_deref().unwrap_or(&msg.data);
        let decoded = match ch.message_encoding.as_str() {
            "cdr" => crate::ros2::decode(t, data),
            "ros1" => decode_ros1(t, data),
            other => Err(format!(
                "message encoding '{other}' is not read (only cdr and ros1)"
            )),
        }
        .map_err(|what| RosError::Message {
            at: Box::new(at),
            msg_type: ch.schema_name.clone(),
            what,
        })?;
        ingest.push(i, msg.log_time_ns as f64 * 1e-9, decoded);
    }
    Ok(ingest.finish())
}

/// The topics of an MCAP file held in memory, sorted by name.
pub fn list_mcap_topics_bytes(bytes: &[u8], file: &str) -> Result<Vec<TopicInfo>, RosError> {
    let m = Mcap::parse(bytes, file)?;
    let mut out: Vec<TopicInfo> = Vec::new();
    let mut index = BTreeMap::new();
    for (id, c) in &m.channels {
        let i = match out.iter().position(|t| t.topic == c.topic) {
            Some(i) => i,
            None => {
                out.push(TopicInfo {
                    topic: c.topic.clone(),
                    msg_type: c.schema_name.clone(),
                    encoding: c.message_encoding.clone(),
                    md5sum: None,
                    messages: 0,
                    first_t_s: None,
                    last_t_s: None,
                });
                out.len() - 1
            }
        };
        index.insert(*id, i);
    }
    for msg in m.sorted() {
        if let Some(t) = index.get(&msg.channel).and_then(|&i| out.get_mut(i)) {
            t.add(msg.log_time_ns as f64 * 1e-9);
        }
    }
    out.sort_by(|a, b| a.topic.cmp(&b.topic));
    Ok(out)
}
