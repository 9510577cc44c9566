//! The ROS1 bag container, format 2.0, decoded from a byte slice.
//!
//! A bag is the 13-byte line `#ROSBAG V2.0\n` followed by records. Every record
//! is `header_len: u32`, a header of fields (`field_len: u32`, `name=value`),
//! `data_len: u32` and the data; all integers little-endian. The header field
//! `op` (one byte) gives the record type:
//!
//! | op | record | header fields | data |
//! |---|---|---|---|
//! | 0x03 | bag header | `index_pos` u64, `conn_count` u32, `chunk_count` u32 | padding |
//! | 0x05 | chunk | `compression` (`none`, `bz2`, `lz4`), `size` u32 (uncompressed) | compressed records (connections, messages) |
//! | 0x07 | connection | `conn` u32, `topic` | a connection header: `topic`, `type`, `md5sum`, `message_definition`, ... |
//! | 0x02 | message data | `conn` u32, `time` (sec u32, nsec u32) | the serialized message |
//! | 0x04 | index data | `ver` = 1, `conn` u32, `count` u32 | `count` × (time u64, offset u32) |
//! | 0x06 | chunk info | `ver` = 1, `chunk_pos` u64, `start_time`, `end_time`, `count` u32 | `count` × (conn u32, count u32) |
//!
//! [`Bag::parse`] walks every record of the file once, decompresses every chunk,
//! checks the index records against what the chunks hold, and returns the
//! connections and the messages. Every length is checked before it is used: a
//! malformed or truncated file is an error naming the byte offset, never a panic.

use std::collections::BTreeMap;

use crate::error::{Location, RosError};

/// The first line of every bag of format 2.0.
pub const MAGIC: &[u8] = b"#ROSBAG V2.0\n";

const OP_MSG_DATA: u8 = 0x02;
const OP_BAG_HEADER: u8 = 0x03;
const OP_INDEX_DATA: u8 = 0x04;
const OP_CHUNK: u8 = 0x05;
const OP_CHUNK_INFO: u8 = 0x06;
const OP_CONNECTION: u8 = 0x07;

/// One connection: a topic with its message type.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Connection {
    /// Connection id.
    pub id: u32,
    /// Topic name.
    pub topic: String,
    /// Message type, e.g. `nav_msgs/Odometry`.
    pub msg_type: String,
    /// MD5 sum of the message definition.
    pub md5sum: String,
    /// Full text of the message definition.
    pub message_definition: String,
}

/// One message record: where it is, its connection, its record time and its bytes.
#[derive(Debug, Clone, Copy)]
pub struct RawMessage<'a> {
    /// Connection id.
    pub conn: u32,
    /// Record (receive) time, s since the Unix epoch.
    pub time_s: f64,
    /// Serialized message.
    pub data: &'a [u8],
    /// Offset of the record in its chunk's uncompressed data (or in the file).
    pub offset: u64,
    /// Offset of the chunk record in the file, if the message is in a chunk.
    pub chunk_at: Option<u64>,
}

/// A decoded bag: connections by id, the uncompressed chunks, and where each message is.
#[derive(Debug, Default)]
pub struct Bag {
    /// Connections by id.
    pub connections: BTreeMap<u32, Connection>,
    /// Uncompressed chunk data (and, for unchunked messages, a copy of the message).
    chunks: Vec<Vec<u8>>,
    messages: Vec<MsgRef>,
    /// Number of chunk records.
    pub chunk_count: usize,
    /// Number of index-data records.
    pub index_count: usize,
}

#[derive(Debug, Clone, Copy)]
struct MsgRef {
    chunk: usize,
    conn: u32,
    time_s: f64,
    start: usize,
    end: usize,
    offset: u64,
    chunk_at: Option<u64>,
}

/// One header field: name and value.
type Field<'a> = (&'a [u8], &'a [u8]);

/// One record: its offset, its header fields and its data.
struct Record<'a> {
    offset: u64,
    fields: Vec<Field<'a>>,
    data: &'a [u8],
}

impl<'a> Record<'a> {
    fn field(&self, name: &str) -> Option<&'a [u8]> {
        self.fields
            .iter()
            .find(|(n, _)| *n == name.as_bytes())
            .map(|(_, v)| *v)
    }
    fn op(&self) -> Option<u8> {
        match self.field("op") {
            Some([op]) => Some(*op),
            _ => None,
        }
    }
}

/// Little-endian readers on slices, with a location for the error.
fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    b.get(at..at.checked_add(4)?)
        .map(|s| u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
}

fn parse_fields<'a>(mut h: &'a [u8], loc: &Location) -> Result<Vec<Field<'a>>, RosError> {
    let mut fields = Vec::new();
    while !h.is_empty() {
        let len = u32_at(h, 0)
            .ok_or_else(|| RosError::format(loc.clone(), "header field length cut short"))?
            as usize;
        let f = h.get(4..4usize.saturating_add(len)).ok_or_else(|| {
            RosError::format(
                loc.clone(),
                format!("header field of {len} bytes runs past the header"),
            )
        })?;
        let eq = f
            .iter()
            .position(|&c| c == b'=')
            .ok_or_else(|| RosError::format(loc.clone(), "header field without '='"))?;
        fields.push((&f[..eq], &f[eq + 1..]));
        h = &h[4 + len..];
    }
    Ok(fields)
}

/// Walks the records of `buf` (starting at `start`), calling `f` on each.
fn walk<'a>(
    buf: &'a [u8],
    start: usize,
    loc: &Location,
    mut f: impl FnMut(Record<'a>) -> Result<(), RosError>,
) -> Result<(), RosError> {
    let mut pos = start;
    while pos < buf.len() {
        let at = loc.at(pos as u64);
        let hlen = u32_at(buf, pos)
            .ok_or_else(|| RosError::format(at.clone(), "record header length cut short"))?
            as usize;
        let hstart = pos + 4;
        let hend = hstart
            .checked_add(hlen)
            .filter(|&e| e <= buf.len())
            .ok_or_else(|| {
                RosError::format(
                    at.clone(),
                    format!("record header of {hlen} bytes runs past the end"),
                )
            })?;
        let dlen = u32_at(buf, hend)
            .ok_or_else(|| RosError::format(at.clone(), "record data length cut short"))?
            as usize;
        let dstart = hend + 4;
        let dend = dstart
            .checked_add(dlen)
            .filter(|&e| e <= buf.len())
            .ok_or_else(|| {
                RosError::format(
                    at.clone(),
                    format!("record data of {dlen} bytes runs past the end"),
                )
            })?;
        let fields = parse_fields(&buf[hstart..hend], &at)?;
        f(Record {
            offset: pos as u64,
            fields,
            data: &buf[dstart..dend],
        })?;
        pos = dend;
    }
    Ok(())
}

fn field_u32(r: &Record<'_>, name: &str, loc: &Location) -> Result<u32, RosError> {
    match r.field(name) {
        Some(v) if v.len() == 4 => Ok(u32::from_le_bytes([v[0], v[1], v[2], v[3]])),
        Some(v) => Err(RosError::format(
            loc.clone(),
            format!("field '{name}' has {} bytes, expected 4", v.len()),
        )),
        None => Err(RosError::format(
            loc.clone(),
            format!("field '{name}' missing"),
        )),
    }
}

fn field_u64(r: &Record<'_>, name: &str, loc: &Location) -> Result<u64, RosError> {
    match r.field(name) {
        Some(v) if v.len() == 8 => {
            let mut b = [0u8; 8];
            b.copy_from_slice(v);
            Ok(u64::from_le_bytes(b))
        }
        Some(v) => Err(RosError::format(
            loc.clone(),
            format!("field '{name}' has {} bytes, expected 8", v.len()),
        )),
        None => Err(RosError::format(
            loc.clone(),
            format!("field '{name}' missing"),
        )),
    }
}

/// A ROS time field (sec u32, nsec u32) in seconds.
fn field_time(r: &Record<'_>, name: &str, loc: &Location) -> Result<f64, RosError> {
    let v = field_u64(r, name, loc)?;
    Ok(time_s(v))
}

fn time_s(v: u64) -> f64 {
    let sec = (v & 0xffff_ffff) as f64;
    let nsec = (v >> 32) as f64;
    sec + nsec * 1e-9
}

fn field_str(r: &Record<'_>, name: &str, loc: &Location) -> Result<String, RosError> {
    let v = r
        .field(name)
        .ok_or_else(|| RosError::format(loc.clone(), format!("field '{name}' missing")))?;
    Ok(String::from_utf8_lossy(v).into_owned())
}

fn parse_connection(r: &Record<'_>, loc: &Location) -> Result<Connection, RosError> {
    let id = field_u32(r, "conn", loc)?;
    let topic = field_str(r, "topic", loc)?;
    let inner = parse_fields(r.data, loc)?;
    let get = |name: &str| -> Result<String, RosError> {
        inner
            .iter()
            .find(|(n, _)| *n == name.as_bytes())
            .map(|(_, v)| String::from_utf8_lossy(v).into_owned())
            .ok_or_else(|| {
                RosError::format(loc.clone(), format!("connection header lacks '{name}'"))
            })
    };
    Ok(Connection {
        id,
        topic,
        msg_type: get("type")?,
        md5sum: get("md5sum")?,
        message_definition: get("message_definition").unwrap_or_default(),
    })
}

impl Bag {
    /// Decodes a whole bag held in memory. `file` names it in errors.
    pub fn parse(buf: &[u8], file: &str) -> Result<Bag, RosError> {
        let loc = Location::file(file);
        if !buf.starts_with(MAGIC) {
            let what = if buf.starts_with(b"#ROSBAG V") {
                "unsupported bag version (only 2.0 is read)"
            } else {
                "not a ROS bag (no '#ROSBAG V2.0' line)"
            };
            return Err(RosError::format(loc.at(0), what));
        }
        let mut bag = Bag::default();
        let mut seen_header = false;
        // (conn_count, chunk_count) of the bag header.
        let mut declared = (0u32, 0u32);
        // (conn, count) from the index records, checked against the chunks afterwards.
        let mut index_counts: BTreeMap<u32, u64> = BTreeMap::new();
        let mut chunk_info_counts: BTreeMap<u32, u64> = BTreeMap::new();
        walk(buf, MAGIC.len(), &loc, |r| {
            let at = loc.at(r.offset);
            match r.op() {
                Some(OP_BAG_HEADER) => {
                    let index_pos = field_u64(&r, "index_pos", &at)?;
                    if seen_header {
                        return Err(RosError::format(at, "a second bag header"));
                    }
                    declared = (
                        field_u32(&r, "conn_count", &at)?,
                        field_u32(&r, "chunk_count", &at)?,
                    );
                    if index_pos > buf.len() as u64 {
                        return Err(RosError::format(
                            at,
                            format!("index_pos {index_pos} is past the end of the file"),
                        ));
                    }
                    if index_pos == 0 {
                        return Err(RosError::format(
                            at,
                            "bag was not closed (index_pos is 0): reindex it with `rosbag reindex`",
                        ));
                    }
                    seen_header = true;
                }
                Some(OP_CHUNK) => {
                    if !seen_header {
                        return Err(RosError::format(at, "chunk before the bag header"));
                    }
                    let compression = field_str(&r, "compression", &at)?;
                    let size = field_u32(&r, "size", &at)?;
                    let data =
                        crate::compress::decompress(&compression, r.data, u64::from(size), &at)?;
                    let chunk_loc = Location {
                        in_chunk_at: Some(r.offset),
                        ..loc.clone()
                    };
                    let idx = bag.chunks.len();
                    let mut msgs = Vec::new();
                    let mut conns = Vec::new();
                    walk(&data, 0, &chunk_loc, |c| {
                        let cat = chunk_loc.at(c.offset);
                        match c.op() {
                            Some(OP_CONNECTION) => conns.push(parse_connection(&c, &cat)?),
                            Some(OP_MSG_DATA) => {
                                let conn = field_u32(&c, "conn", &cat)?;
                                let time_s = field_time(&c, "time", &cat)?;
                                let start = c.data.as_ptr() as usize - data.as_ptr() as usize;
                                msgs.push(MsgRef {
                                    chunk: idx,
                                    conn,
                                    time_s,
                                    start,
                                    end: start + c.data.len(),
                                    offset: c.offset,
                                    chunk_at: Some(r.offset),
                                });
                            }
                            Some(op) => {
                                return Err(RosError::format(
                                    cat,
                                    format!("record op {op:#04x} inside a chunk"),
                                ));
                            }
                            None => {
                                return Err(RosError::format(
                                    cat,
                                    "record without a one-byte 'op' field",
                                ))
                            }
                        }
                        Ok(())
                    })?;
                    for c in conns {
                        bag.add_connection(c, &at)?;
                    }
                    bag.messages.extend(msgs);
                    bag.chunks.push(data);
                    bag.chunk_count += 1;
                }
                Some(OP_CONNECTION) => {
                    let c = parse_connection(&r, &at)?;
                    bag.add_connection(c, &at)?;
                }
                Some(OP_MSG_DATA) => {
                    // Unchunked message (not written by rosbag 2.0, but readable).
                    let conn = field_u32(&r, "conn", &at)?;
                    let time_s = field_time(&r, "time", &at)?;
                    bag.messages.push(MsgRef {
                        chunk: bag.chunks.len(),
                        conn,
                        time_s,
                        start: 0,
                        end: r.data.len(),
                        offset: r.offset,
                        chunk_at: None,
                    });
                    bag.chunks.push(r.data.to_vec());
                }
                Some(OP_INDEX_DATA) => {
                    let ver = field_u32(&r, "ver", &at)?;
                    if ver != 1 {
                        return Err(RosError::format(
                            at,
                            format!("index data version {ver}, expected 1"),
                        ));
                    }
                    let conn = field_u32(&r, "conn", &at)?;
                    let count = field_u32(&r, "count", &at)?;
                    if r.data.len() as u64 != u64::from(count) * 12 {
                        return Err(RosError::format(
                            at,
                            format!(
                                "index data holds {} bytes for {count} entries of 12 bytes",
                                r.data.len()
                            ),
                        ));
                    }
                    *index_counts.entry(conn).or_default() += u64::from(count);
                    bag.index_count += 1;
                }
                Some(OP_CHUNK_INFO) => {
                    let ver = field_u32(&r, "ver", &at)?;
                    if ver != 1 {
                        return Err(RosError::format(
                            at,
                            format!("chunk info version {ver}, expected 1"),
                        ));
                    }
                    field_u64(&r, "chunk_pos", &at)?;
                    field_u64(&r, "start_time", &at)?;
                    field_u64(&r, "end_time", &at)?;
                    let count = field_u32(&r, "count", &at)?;
                    if r.data.len() as u64 != u64::from(count) * 8 {
                        return Err(RosError::format(
                            at,
                            format!(
                                "chunk info holds {} bytes for {count} entries of 8 bytes",
                                r.data.len()
                            ),
                        ));
                    }
                    for e in r.data.chunks_exact(8) {
                        let conn = u32::from_le_bytes([e[0], e[1], e[2], e[3]]);
                        let n = u32::from_le_bytes([e[4], e[5], e[6], e[7]]);
                        *chunk_info_counts.entry(conn).or_default() += u64::from(n);
                    }
                }
                Some(op) => {
                    return Err(RosError::format(at, format!("unknown record op {op:#04x}")))
                }
                None => return Err(RosError::format(at, "record without a one-byte 'op' field")),
            }
            Ok(())
        })?;
        if !seen_header {
            return Err(RosError::format(
                loc.at(MAGIC.len() as u64),
                "no bag header record",
            ));
        }
        if (bag.connections.len(), bag.chunk_count) != (declared.0 as usize, declared.1 as usize) {
            return Err(RosError::format(
                loc.at(MAGIC.len() as u64),
                format!(
                    "the bag header declares {} connections and {} chunks, the file holds {} and {}",
                    declared.0,
                    declared.1,
                    bag.connections.len(),
                    bag.chunk_count
                ),
            ));
        }
        // The index must describe exactly the messages the chunks hold.
        let mut counts: BTreeMap<u32, u64> = BTreeMap::new();
        for m in &bag.messages {
            *counts.entry(m.conn).or_default() += 1;
            if !bag.connections.contains_key(&m.conn) {
                let at = Location {
                    offset: Some(m.offset),
                    in_chunk_at: m.chunk_at,
                    ..loc.clone()
                };
                return Err(RosError::format(
                    at,
                    format!(
                        "message on connection {} that no connection record declares",
                        m.conn
                    ),
                ));
            }
        }
        if bag.index_count > 0 && index_counts != counts {
            return Err(RosError::format(
                loc.clone(),
                format!("index records count messages per connection {index_counts:?}, the chunks hold {counts:?}"),
            ));
        }
        if !chunk_info_counts.is_empty() && chunk_info_counts != counts {
            return Err(RosError::format(
                loc,
                format!("chunk info records count messages per connection {chunk_info_counts:?}, the chunks hold {counts:?}"),
            ));
        }
        Ok(bag)
    }

    fn add_connection(&mut self, c: Connection, at: &Location) -> Result<(), RosError> {
        match self.connections.get(&c.id) {
            Some(old) if old.topic != c.topic || old.msg_type != c.msg_type => {
                Err(RosError::format(
                    at.clone(),
                    format!(
                        "connection {} redeclared: {} ({}) then {} ({})",
                        c.id, old.topic, old.msg_type, c.topic, c.msg_type
                    ),
                ))
            }
            Some(_) => Ok(()),
            None => {
                self.connections.insert(c.id, c);
                Ok(())
            }
        }
    }

    /// The messages in the order rosbag plays them: by record time, then by position
    /// in the file (a stable sort).
    pub fn messages(&self) -> Vec<RawMessage<'_>> {
        let mut refs: Vec<&MsgRef> = self.messages.iter().collect();
        refs.sort_by(|a, b| a.time_s.total_cmp(&b.time_s));
        refs.into_iter()
            .filter_map(|m| {
                let data = self.chunks.get(m.chunk)?.get(m.start..m.end)?;
                Some(RawMessage {
                    conn: m.conn,
                    time_s: m.time_s,
                    data,
                    offset: m.offset,
                    chunk_at: m.chunk_at,
                })
            })
            .collect()
    }
}
