//! Reading ROS1 bags into a drive, and listing their topics.

use crate::bag::Bag;
use crate::error::{Location, RosError};
use crate::ingest::{ImportReport, Ingest};
use crate::mapping::Mapping;
use crate::msgs::{decode_ros1, MsgType};
use crate::TopicInfo;

/// Reads a ROS1 bag held in memory. `file` names it in errors and in the report.
pub fn read_rosbag_bytes(
    bytes: &[u8],
    file: &str,
    mapping: &Mapping,
) -> Result<(deadreckon_core::Drive, ImportReport), RosError> {
    mapping.validate()?;
    let bag = Bag::parse(bytes, file)?;
    let loc = Location::file(file);
    let topics: Vec<(String, String)> = bag
        .connections
        .values()
        .map(|c| (c.topic.clone(), c.msg_type.clone()))
        .collect();
    let mut ingest = Ingest::new(mapping, file, "rosbag");
    ingest.bind(&topics, &loc)?;
    // Connection id -> mapped stream index.
    let streams: std::collections::BTreeMap<u32, (usize, &str, &str)> = bag
        .connections
        .values()
        .filter_map(|c| {
            ingest
                .stream_of(&c.topic)
                .map(|i| (c.id, (i, c.topic.as_str(), c.msg_type.as_str())))
        })
        .collect();
    for m in bag.messages() {
        let Some(&(i, topic, msg_type)) = streams.get(&m.conn) else {
            continue;
        };
        let t: MsgType = ingest.msg_type(i);
        let decoded = decode_ros1(t, m.data).map_err(|what| RosError::Message {
            at: Box::new(Location {
                offset: Some(m.offset),
                in_chunk_at: m.chunk_at,
                ..loc.on(topic)
            }),
            msg_type: msg_type.to_owned(),
            what,
        })?;
        ingest.push(i, m.time_s, decoded);
    }
    Ok(ingest.finish())
}

/// The topics of a ROS1 bag held in memory, sorted by name.
pub fn list_rosbag_topics_bytes(bytes: &[u8], file: &str) -> Result<Vec<TopicInfo>, RosError> {
    let bag = Bag::parse(bytes, file)?;
    let mut out: Vec<TopicInfo> = Vec::new();
    // Several connections may share a topic (one per publisher): merge them.
    let mut conn_topic = std::collections::BTreeMap::new();
    for c in bag.connections.values() {
        let idx = match out.iter().position(|t| t.topic == c.topic) {
            Some(i) => i,
            None => {
                out.push(TopicInfo {
                    topic: c.topic.clone(),
                    msg_type: c.msg_type.clone(),
                    encoding: "ros1".into(),
                    md5sum: Some(c.md5sum.clone()),
                    messages: 0,
                    first_t_s: None,
                    last_t_s: None,
                });
                out.len() - 1
            }
        };
        conn_topic.insert(c.id, idx);
    }
    for m in bag.messages() {
        if let Some(t) = conn_topic.get(&m.conn).and_then(|&i| out.get_mut(i)) {
            t.add(m.time_s);
        }
    }
    out.sort_by(|a, b| a.topic.cmp(&b.topic));
    Ok(out)
}
