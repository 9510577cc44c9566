//! The node's DDS side over `ros2-client`: one subscription per mapped
//! stream (typed by its kind, deserialised into [`deadreckon_ros::ros2`]'s
//! message structs), the Odometry and diagnostics publishers, and the
//! quality of service.

use std::time::Duration;

use ros2_client::dds::rustdds::mio1 as mio;
use ros2_client::qos::{Durability, History, WhenFull};
use ros2_client::{
    Context, ContextOptions, MessageTypeName, Name, Node, NodeName, NodeOptions, Publisher,
    QosProfile, Subscription,
};
use serde::de::DeserializeOwned;
use serde::Serialize;

use deadreckon_ros::ros2;
use deadreckon_ros::{Mapping, Message, StreamKind};

use crate::diagnostics::DiagnosticArray;
use crate::Error;

/// Samples kept per topic, each way: a 400 Hz IMU's 2.5 s.
pub const HISTORY_DEPTH: usize = 1000;

/// How long a reliable `publish` waits for room in a full send window.
pub const WHEN_FULL_WAIT: Duration = Duration::from_millis(200);

/// The quality of service of every subscription: reliable, volatile, keep
/// the last [`HISTORY_DEPTH`] samples.
pub fn qos() -> QosProfile {
    QosProfile::publisher_default()
        .reliability_reliable(WhenFull::Wait(WHEN_FULL_WAIT))
        .durability(Durability::Volatile)
        .history(History::KeepLast {
            depth: HISTORY_DEPTH,
        })
}

/// The quality of service of the publishers: [`qos`], but transient local,
/// so that a subscriber asking for it gets the last [`HISTORY_DEPTH`]
/// samples from their start. A volatile subscriber (ROS 2's default) is
/// unaffected. Against Cyclone DDS with a volatile reader, a run of about 33
/// epochs just after the filter's start was lost in about one run in three
/// (docs/ros2.md); with a transient-local reader, in none of 11.
pub fn publisher_qos() -> QosProfile {
    qos().durability(Durability::TransientLocal)
}

/// One mapped stream's subscription, typed by its kind.
pub(crate) enum Sub {
    Odometry(Subscription<ros2::Odometry>),
    Imu(Subscription<ros2::Imu>),
    NavSatFix(Subscription<ros2::NavSatFix>),
    Twist(Subscription<ros2::TwistStamped>),
    Pose(Subscription<ros2::PoseStamped>),
}

fn take<M: 'static + DeserializeOwned>(s: &Subscription<M>) -> Result<Option<M>, String>
where
    for<'a> Message: From<&'a M>,
{
    s.take()
        .map(|o| o.map(|(m, _info)| m))
        .map_err(|e| e.to_string())
}

impl Sub {
    /// The next message received, if any.
    pub(crate) fn take(&self) -> Result<Option<Message>, String> {
        Ok(match self {
            Sub::Odometry(s) => take(s)?.map(|m| Message::from(&m)),
            Sub::Imu(s) => take(s)?.map(|m| Message::from(&m)),
            Sub::NavSatFix(s) => take(s)?.map(|m| Message::from(&m)),
            Sub::Twist(s) => take(s)?.map(|m| Message::from(&m)),
            Sub::Pose(s) => take(s)?.map(|m| Message::from(&m)),
        })
    }

    /// Registers the subscription with a poll, so that a message wakes it.
    pub(crate) fn register(
        &mut self,
        registry: &mio::Registry,
        token: mio::Token,
    ) -> std::io::Result<()> {
        let i = mio::Interest::READABLE;
        match self {
            Sub::Odometry(s) => registry.register(s, token, i),
            Sub::Imu(s) => registry.register(s, token, i),
            Sub::NavSatFix(s) => registry.register(s, token, i),
            Sub::Twist(s) => registry.register(s, token, i),
            Sub::Pose(s) => registry.register(s, token, i),
        }
    }
}

/// The ROS 2 message type of a stream kind (`nav_msgs/msg/Odometry` ...).
pub fn message_type(kind: StreamKind) -> MessageTypeName {
    let (package, name) = kind
        .msg_type_name()
        .split_once('/')
        .unwrap_or(("", kind.msg_type_name()));
    MessageTypeName::new(package, name)
}

/// A topic name as ROS 2 takes it (absolute: a leading `/` added).
fn name(topic: &str) -> Result<Name, Error> {
    let full = if topic.starts_with('/') {
        topic.to_owned()
    } else {
        format!("/{topic}")
    };
    Name::parse(&full).map_err(|e| Error::Dds {
        doing: format!("the topic name {topic}"),
        detail: format!("{e:?}"),
    })
}

fn dds<E: std::fmt::Display>(doing: impl Into<String>) -> impl FnOnce(E) -> Error {
    let doing = doing.into();
    move |e| Error::Dds {
        doing,
        detail: e.to_string(),
    }
}

/// The node and its endpoints.
pub(crate) struct Endpoints {
    pub(crate) subs: Vec<Sub>,
    pub(crate) odom: Publisher<ros2::Odometry>,
    pub(crate) diagnostics: Publisher<DiagnosticArray>,
    // Dropped last: the endpoints above belong to it.
    _node: Node,
}

/// Names of the node and its output.
#[derive(Debug, Clone)]
pub struct Names {
    /// The node's name (in namespace `/`).
    pub node: String,
    /// The Odometry topic.
    pub odom_topic: String,
}

impl Default for Names {
    fn default() -> Self {
        Names {
            node: "deadreckon".into(),
            odom_topic: "/deadreckon/odom".into(),
        }
    }
}

fn publisher<M: Serialize>(
    node: &mut Node,
    topic: &str,
    ty: MessageTypeName,
) -> Result<Publisher<M>, Error> {
    let t = node
        .create_topic(&name(topic)?, ty, &qos())
        .map_err(dds(format!("creating topic {topic}")))?;
    node.create_publisher::<M>(&t, Some(publisher_qos()))
        .map_err(dds(format!("publishing on {topic}")))
}

impl Endpoints {
    /// Joins DDS domain `domain_id` as node `names.node`: subscribes to
    /// every stream of `mapping`, publishes Odometry and diagnostics.
    pub(crate) fn open(mapping: &Mapping, domain_id: u16, names: &Names) -> Result<Self, Error> {
        let context = Context::with_options(ContextOptions::new().domain_id(domain_id))
            .map_err(dds(format!("joining DDS domain {domain_id}")))?;
        let node_name = NodeName::new("/", &names.node).map_err(|e| Error::Dds {
            doing: format!("the node name {}", names.node),
            detail: format!("{e:?}"),
        })?;
        let mut node = context
            .new_node(node_name, NodeOptions::new().enable_rosout(false))
            .map_err(dds("creating the node"))?;
        let mut subs = Vec::new();
        for s in &mapping.streams {
            let t = node
                .create_topic(&name(&s.topic)?, message_type(s.kind), &qos())
                .map_err(dds(format!("creating topic {}", s.topic)))?;
            let what = format!("subscribing to {}", s.topic);
            subs.push(match s.kind {
                StreamKind::OdometryWheels => {
                    Sub::Odometry(node.create_subscription(&t, None).map_err(dds(what))?)
                }
                StreamKind::ImuYawRate => {
                    Sub::Imu(node.create_subscription(&t, None).map_err(dds(what))?)
                }
                StreamKind::NavsatfixGnss => {
                    Sub::NavSatFix(node.create_subscription(&t, None).map_err(dds(what))?)
                }
                StreamKind::TwistSpeed => {
                    Sub::Twist(node.create_subscription(&t, None).map_err(dds(what))?)
                }
                StreamKind::PoseTruth => {
                    Sub::Pose(node.create_subscription(&t, None).map_err(dds(what))?)
                }
            });
        }
        let odom = publisher(
            &mut node,
            &names.odom_topic,
            MessageTypeName::new("nav_msgs", "Odometry"),
        )?;
        let diagnostics = publisher(
            &mut node,
            crate::diagnostics::TOPIC,
            MessageTypeName::new("diagnostic_msgs", "DiagnosticArray"),
        )?;
        Ok(Endpoints {
            subs,
            odom,
            diagnostics,
            _node: node,
        })
    }
}
