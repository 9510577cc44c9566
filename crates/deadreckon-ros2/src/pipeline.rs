//! What the node does with a message, without the network: the reorder
//! window, the bag reader's conversion ([`Converter`]) and the online filter,
//! so that it is tested on its own (`deadreckon-ros2`'s unit tests) and the
//! node's loop ([`crate::node`]) only moves messages.

use std::time::Instant;

use deadreckon_core::online::Online;
use deadreckon_core::TrackPoint;
use deadreckon_ros::{Converter, Mapping, Message, StreamKind, StreamReport};

use crate::reorder::Reorder;
use crate::Error;

/// Where the pipeline's results go.
pub trait Sink {
    /// A message received at `received` was given to the filter.
    fn fed(&mut self, received: Instant);
    /// The filter completed an epoch.
    fn epoch(&mut self, p: TrackPoint);
}

/// A message waiting in the reorder window.
struct Pending {
    stream: usize,
    record_t_s: f64,
    msg: Message,
    received: Instant,
}

/// The rank of a kind's events among equal times (as `Event`'s ties:
/// wheels, gyro, speed, steering, GNSS).
fn rank(kind: StreamKind) -> u8 {
    match kind {
        StreamKind::OdometryWheels => 0,
        StreamKind::ImuYawRate => 1,
        StreamKind::TwistSpeed => 2,
        StreamKind::NavsatfixGnss => 4,
        StreamKind::PoseTruth => 5,
    }
}

/// Messages of the mapped streams → events in stamp order → the filter.
pub struct Pipeline {
    conv: Converter,
    kinds: Vec<StreamKind>,
    window: Reorder<Pending>,
    late: Vec<u64>,
}

impl Pipeline {
    /// The pipeline of `mapping`'s streams with a reorder window of
    /// `window_s` seconds of stamp time.
    pub fn new(mapping: &Mapping, window_s: f64) -> Self {
        Pipeline {
            conv: Converter::new(mapping),
            kinds: mapping.streams.iter().map(|s| s.kind).collect(),
            window: Reorder::new(window_s),
            late: vec![0; mapping.streams.len()],
        }
    }

    /// Takes message `msg` of stream `stream`, received at `received`
    /// (`record_t_s`: the same instant on the system clock, s since the
    /// epoch); a late one is counted and dropped.
    pub fn receive(&mut self, stream: usize, record_t_s: f64, msg: Message, received: Instant) {
        let t = self.conv.time_s(stream, record_t_s, &msg);
        let p = Pending {
            stream,
            record_t_s,
            msg,
            received,
        };
        if self.window.push(t, rank(self.kinds[stream]), p).is_err() {
            self.late[stream] += 1;
        }
    }

    /// Gives the filter every message whose window has passed.
    pub fn release(&mut self, online: &mut Online, sink: &mut dyn Sink) -> Result<(), Error> {
        while let Some((_, p)) = self.window.pop_ready() {
            self.feed(online, sink, p)?;
        }
        Ok(())
    }

    /// The end of the input: every waiting message to the filter, then the
    /// filter finished. Returns why the filter never started, if it did not.
    pub fn finish(
        &mut self,
        online: &mut Online,
        sink: &mut dyn Sink,
    ) -> Result<Option<String>, Error> {
        while let Some((_, p)) = self.window.drain() {
            self.feed(online, sink, p)?;
        }
        // A filter that never started has nothing to finish: say why instead.
        match online.finish(&mut |p| sink.epoch(p)) {
            Err(e) if !online.is_started() => Ok(Some(e.to_string())),
            r => r.map(|()| None).map_err(Error::from),
        }
    }

    /// Converts one message and gives it to the filter.
    fn feed(&mut self, online: &mut Online, sink: &mut dyn Sink, p: Pending) -> Result<(), Error> {
        let Some(ev) = self
            .conv
            .push(p.stream, p.record_t_s, &p.msg)
            .and_then(|s| s.event())
        else {
            return Ok(());
        };
        sink.fed(p.received);
        online.push(ev, &mut |tp| sink.epoch(tp))?;
        Ok(())
    }

    /// Per mapped stream: what the conversion used and dropped.
    pub fn reports(&self) -> &[StreamReport] {
        self.conv.reports()
    }

    /// Per mapped stream: messages refused as late.
    pub fn late(&self) -> &[u64] {
        &self.late
    }
}
