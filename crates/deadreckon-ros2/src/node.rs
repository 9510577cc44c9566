//! The node's loop: messages taken from the subscriptions into the
//! [`Pipeline`] (stamp order through the reorder window, the bag reader's
//! conversion, the online filter as `deadreckon stream` feeds it), one
//! Odometry published per epoch.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use ros2_client::dds::rustdds::mio1 as mio;

use deadreckon_core::online::{LearnTargets, Learned, Online};
use deadreckon_core::TrackPoint;
use deadreckon_ros::{ros2_out, Mapping, StreamReport};

use crate::dds::{Endpoints, Names};
use crate::latency::{seconds, Latency, LatencySummary};
use crate::pipeline::{Pipeline, Sink};
use crate::Error;

/// The frame of the published pose (REP 105's `odom`: east/north/up about
/// the vehicle's origin).
pub const FRAME_ID: &str = "odom";

/// How long the node stays after its last publication so that reliable
/// subscribers get the last samples (RustDDS's publisher is dropped then).
pub const LINGER: Duration = Duration::from_millis(1000);

/// How the node runs.
#[derive(Debug, Clone)]
pub struct NodeOptions {
    /// The DDS domain (`ROS_DOMAIN_ID`).
    pub domain_id: u16,
    /// Stop after this long without a message (wall time, s).
    pub until_idle_s: Option<f64>,
    /// The reorder window, s of stamp time.
    pub reorder_window_s: f64,
    /// Publish the learned parameters every this many seconds of stream time.
    pub learned_every_s: f64,
    /// The node's and the output topic's names.
    pub names: Names,
}

/// The default reorder window, s: three times the largest lateness measured
/// on `husky_gps.bag` replayed in record order (a message's stamp at most
/// 33.3 ms behind the newest stamp before it, on `/imu/data`).
pub const DEFAULT_REORDER_WINDOW_S: f64 = 0.1;

impl Default for NodeOptions {
    fn default() -> Self {
        NodeOptions {
            domain_id: 0,
            until_idle_s: None,
            reorder_window_s: DEFAULT_REORDER_WINDOW_S,
            learned_every_s: 1.0,
            names: Names::default(),
        }
    }
}

/// Why the node stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stop {
    /// SIGINT or SIGTERM (the stop flag).
    Signal,
    /// No message for `until_idle_s`.
    Idle,
}

impl std::fmt::Display for Stop {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Stop::Signal => "stopped by a signal",
            Stop::Idle => "stopped after the idle time without input",
        })
    }
}

/// What the node did.
#[derive(Debug, Clone)]
pub struct Summary {
    /// Why it stopped.
    pub stop: Stop,
    /// Why the filter never started (no GNSS start), when it did not.
    pub not_started: Option<String>,
    /// Per mapped stream: what the conversion used and dropped.
    pub streams: Vec<StreamReport>,
    /// Per mapped stream: messages refused as late (older than one already
    /// given to the filter), never applied.
    pub late: Vec<u64>,
    /// Odometry messages published.
    pub published: u64,
    /// Epochs not published: their time has no ROS 2 stamp.
    pub unstamped: u64,
    /// Publications that failed, and the first failure.
    pub publish_errors: (u64, Option<String>),
    /// Latency from receipt to publication.
    pub latency: Option<LatencySummary>,
    /// The learned parameters at the end (with learning).
    pub learned: Option<Learned>,
}

impl Summary {
    /// The lines the command prints on standard error.
    pub fn lines(&self) -> Vec<String> {
        let mut out = vec![format!("{}", self.stop)];
        for (s, late) in self.streams.iter().zip(&self.late) {
            out.push(format!(
                "{} ({}): {} received, {} used, {} late, {} out of order or repeated, {} invalid, {} without a fix",
                s.topic,
                s.kind.name(),
                s.messages + late,
                s.accepted,
                late,
                s.non_increasing_time,
                s.invalid_value,
                s.no_fix
            ));
        }
        out.push(format!("{} odometry messages published", self.published));
        if self.unstamped > 0 {
            out.push(format!(
                "{} epochs not published: their time has no ROS 2 stamp",
                self.unstamped
            ));
        }
        if let (n @ 1.., Some(e)) = (self.publish_errors.0, &self.publish_errors.1) {
            out.push(format!("{n} publications failed, the first: {e}"));
        }
        match &self.latency {
            Some(l) => out.push(l.to_string()),
            None => out.push("latency: nothing published".into()),
        }
        out
    }
}

fn wall_s() -> f64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64())
}

/// What publishes the epochs: the Odometry publisher with its counters.
struct Output<'a> {
    ep: &'a Endpoints,
    published: u64,
    unstamped: u64,
    errors: u64,
    first_error: Option<String>,
    latency: Latency,
}

impl Sink for Output<'_> {
    fn fed(&mut self, received: Instant) {
        self.latency.fed(received);
    }

    fn epoch(&mut self, p: TrackPoint) {
        let Some(m) = ros2_out::odometry_in(&p, FRAME_ID) else {
            self.unstamped += 1;
            return;
        };
        match self.ep.odom.publish(m) {
            Ok(()) => {
                self.published += 1;
                self.latency.published(Instant::now());
            }
            Err(e) => {
                self.errors += 1;
                self.first_error.get_or_insert_with(|| e.to_string());
            }
        }
    }
}

/// Runs the node until `stop` is set or the idle time passes: every
/// message of the mapped topics converted as the bag reader converts it
/// (`mapping`: its topics, kinds and vehicle), in stamp order, into
/// `online`; each epoch published as Odometry on the output topic; with
/// learning, the learned parameters on `/diagnostics` every
/// `learned_every_s` of stream time. At the end the reorder window is
/// emptied and the filter finished (as `stream` does at the end of its input).
pub fn run(
    online: &mut Online,
    mapping: &Mapping,
    o: &NodeOptions,
    stop: &AtomicBool,
) -> Result<Summary, Error> {
    let mut ep = Endpoints::open(mapping, o.domain_id, &o.names)?;
    let mut poll = mio::Poll::new().map_err(|e| Error::Io("creating a poll", e))?;
    for (i, s) in ep.subs.iter_mut().enumerate() {
        s.register(poll.registry(), mio::Token(i))
            .map_err(|e| Error::Io("registering a subscription", e))?;
    }
    let mut events = mio::Events::with_capacity(64);
    let mut pipe = Pipeline::new(mapping, o.reorder_window_s);
    let mut out = Output {
        ep: &ep,
        published: 0,
        unstamped: 0,
        errors: 0,
        first_error: None,
        latency: Latency::default(),
    };
    let targets = LearnTargets::default();
    let mut last_learned: Option<f64> = None;
    let mut last_input = Instant::now();
    let idle = o.until_idle_s.map(seconds);
    let stopped = loop {
        if stop.load(Ordering::SeqCst) {
            break Stop::Signal;
        }
        if idle.is_some_and(|d| last_input.elapsed() >= d) {
            break Stop::Idle;
        }
        // Woken by a message, or every 50 ms to look at the stop flag and the idle time.
        if let Err(e) = poll.poll(&mut events, Some(Duration::from_millis(50))) {
            if e.kind() != std::io::ErrorKind::Interrupted {
                return Err(Error::Io("polling the subscriptions", e));
            }
        }
        for (i, sub) in out.ep.subs.iter().enumerate() {
            while let Some(msg) = sub.take().map_err(|detail| Error::Dds {
                doing: format!("reading {}", mapping.streams[i].topic),
                detail,
            })? {
                last_input = Instant::now();
                pipe.receive(i, wall_s(), msg, last_input);
            }
        }
        pipe.release(online, &mut out)?;
        learned(online, &out, o, &targets, &mut last_learned, false);
    };
    let not_started = pipe.finish(online, &mut out)?;
    learned(online, &out, o, &targets, &mut last_learned, true);
    std::thread::sleep(LINGER);
    let summary = Summary {
        stop: stopped,
        not_started,
        streams: pipe.reports().to_vec(),
        late: pipe.late().to_vec(),
        published: out.published,
        unstamped: out.unstamped,
        publish_errors: (out.errors, out.first_error.clone()),
        latency: out.latency.summary(),
        learned: online.learned(&targets),
    };
    drop(out);
    drop(ep);
    Ok(summary)
}

/// Publishes the learned parameters when learning, every `learned_every_s`
/// of stream time (and at the end with `at_end`).
fn learned(
    online: &Online,
    out: &Output,
    o: &NodeOptions,
    targets: &LearnTargets,
    last: &mut Option<f64>,
    at_end: bool,
) {
    let Some(l) = online.learned(targets) else {
        return;
    };
    let Some(t) = online.time_s() else {
        return;
    };
    if !at_end && last.is_some_and(|t0| t - t0 < o.learned_every_s) {
        return;
    }
    *last = Some(t);
    if let Some(stamp) = ros2_out::stamp(t) {
        let msg = crate::diagnostics::learned(&l, stamp, &o.names.node);
        // A failed diagnostics publication is not worth stopping for.
        let _ = out.ep.diagnostics.publish(msg);
    }
}
