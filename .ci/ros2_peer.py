"""An independent ROS 2 peer for `deadreckon ros2` (tests/ros2.rs, .ci/ros2).

Eclipse Cyclone DDS (PyPI `cyclonedds`, a ROS 2 default middleware) replays a
ROS1 bag, read with `rosbags`, as ROS 2 messages of the bag's types
(nav_msgs/Odometry, sensor_msgs/Imu, sensor_msgs/NavSatFix: every field, the
bag's header stamps) in record order at `--rate` times real time, and writes
every nav_msgs/Odometry it receives on /deadreckon/odom as one JSON line.

It starts the node (the command after `--`) itself, waits until every topic is
matched both ways, replays, waits for the node to exit (it stops after its
`--until-idle`, or `--signal-after` sends it SIGTERM), and exits with the node's
status. Run it in a private network
namespace: `unshare -n` with `ip link set lo up multicast on`.
"""

import argparse
import json
import signal
import subprocess
import sys
import threading
import time
from dataclasses import dataclass
from pathlib import Path

import cyclonedds.idl.types as t
from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore


# ROS 2 message types as Cyclone IDL structs, with the DDS type names ROS 2
# gives them (package::msg::dds_::Type_).
@dataclass
class Time(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: t.int32
    nanosec: t.uint32


@dataclass
class Header(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
    stamp: Time
    frame_id: str


@dataclass
class Vector3(IdlStruct, typename="geometry_msgs::msg::dds_::Vector3_"):
    x: t.float64
    y: t.float64
    z: t.float64


@dataclass
class Point(IdlStruct, typename="geometry_msgs::msg::dds_::Point_"):
    x: t.float64
    y: t.float64
    z: t.float64


@dataclass
class Quaternion(IdlStruct, typename="geometry_msgs::msg::dds_::Quaternion_"):
    x: t.float64
    y: t.float64
    z: t.float64
    w: t.float64


@dataclass
class Pose(IdlStruct, typename="geometry_msgs::msg::dds_::Pose_"):
    position: Point
    orientation: Quaternion


@dataclass
class PoseWithCovariance(IdlStruct, typename="geometry_msgs::msg::dds_::PoseWithCovariance_"):
    pose: Pose
    covariance: t.array[t.float64, 36]


@dataclass
class Twist(IdlStruct, typename="geometry_msgs::msg::dds_::Twist_"):
    linear: Vector3
    angular: Vector3


@dataclass
class TwistWithCovariance(IdlStruct, typename="geometry_msgs::msg::dds_::TwistWithCovariance_"):
    twist: Twist
    covariance: t.array[t.float64, 36]


@dataclass
class Odometry(IdlStruct, typename="nav_msgs::msg::dds_::Odometry_"):
    header: Header
    child_frame_id: str
    pose: PoseWithCovariance
    twist: TwistWithCovariance


@dataclass
class Imu(IdlStruct, typename="sensor_msgs::msg::dds_::Imu_"):
    header: Header
    orientation: Quaternion
    orientation_covariance: t.array[t.float64, 9]
    angular_velocity: Vector3
    angular_velocity_covariance: t.array[t.float64, 9]
    linear_acceleration: Vector3
    linear_acceleration_covariance: t.array[t.float64, 9]


@dataclass
class NavSatStatus(IdlStruct, typename="sensor_msgs::msg::dds_::NavSatStatus_"):
    status: t.int8
    service: t.uint16


@dataclass
class NavSatFix(IdlStruct, typename="sensor_msgs::msg::dds_::NavSatFix_"):
    header: Header
    status: NavSatStatus
    latitude: t.float64
    longitude: t.float64
    altitude: t.float64
    position_covariance: t.array[t.float64, 9]
    position_covariance_type: t.uint8


def header(h):
    return Header(Time(int(h.stamp.sec), int(h.stamp.nanosec)), h.frame_id)


def vec(v, cls=Vector3):
    return cls(float(v.x), float(v.y), float(v.z))


def quat(q):
    return Quaternion(float(q.x), float(q.y), float(q.z), float(q.w))


def floats(a):
    return [float(x) for x in a]


def odometry(m):
    return Odometry(
        header(m.header),
        m.child_frame_id,
        PoseWithCovariance(
            Pose(vec(m.pose.pose.position, Point), quat(m.pose.pose.orientation)),
            floats(m.pose.covariance),
        ),
        TwistWithCovariance(
            Twist(vec(m.twist.twist.linear), vec(m.twist.twist.angular)),
            floats(m.twist.covariance),
        ),
    )


def imu(m):
    return Imu(
        header(m.header),
        quat(m.orientation),
        floats(m.orientation_covariance),
        vec(m.angular_velocity),
        floats(m.angular_velocity_covariance),
        vec(m.linear_acceleration),
        floats(m.linear_acceleration_covariance),
    )


def navsatfix(m):
    return NavSatFix(
        header(m.header),
        NavSatStatus(int(m.status.status), int(m.status.service)),
        float(m.latitude),
        float(m.longitude),
        float(m.altitude),
        floats(m.position_covariance),
        int(m.position_covariance_type),
    )


@dataclass
class KeyValue(IdlStruct, typename="diagnostic_msgs::msg::dds_::KeyValue_"):
    key: str
    value: str


@dataclass
class DiagnosticStatus(IdlStruct, typename="diagnostic_msgs::msg::dds_::DiagnosticStatus_"):
    level: t.uint8
    name: str
    message: str
    hardware_id: str
    values: t.sequence[KeyValue]


@dataclass
class DiagnosticArray(IdlStruct, typename="diagnostic_msgs::msg::dds_::DiagnosticArray_"):
    header: Header
    status: t.sequence[DiagnosticStatus]


# The bag's message types, as ROS 2 types and converters.
CONVERT = {
    "nav_msgs/msg/Odometry": (Odometry, odometry),
    "sensor_msgs/msg/Imu": (Imu, imu),
    "sensor_msgs/msg/NavSatFix": (NavSatFix, navsatfix),
}


def wait(what, done, timeout_s):
    end = time.monotonic() + timeout_s
    while not done():
        if time.monotonic() > end:
            sys.exit(f"ros2_peer: {what} not matched within {timeout_s} s")
        time.sleep(0.05)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bag", required=True, type=Path)
    ap.add_argument("--topics", required=True, help="comma-separated topics to replay")
    ap.add_argument("--rate", type=float, default=5.0)
    ap.add_argument("--domain-id", type=int, default=0)
    ap.add_argument("--signal-after", type=float, help="send the node SIGTERM after this many seconds of bag")
    ap.add_argument("--out", required=True, type=Path, help="JSON lines of what was received")
    ap.add_argument("--node-log", required=True, type=Path)
    ap.add_argument("--diagnostics-out", type=Path, help="JSON lines of the /diagnostics received")
    ap.add_argument("node", nargs=argparse.REMAINDER, help="-- the node's command")
    a = ap.parse_args()
    node_cmd = a.node[1:] if a.node[:1] == ["--"] else a.node
    topics = a.topics.split(",")

    # Reliable, keep the last 1000 (the node's QoS).
    qos = Qos(
        Policy.Reliability.Reliable(max_blocking_time=duration(seconds=1)),
        Policy.Durability.Volatile,
        Policy.History.KeepLast(1000),
    )
    dp = DomainParticipant(a.domain_id)
    received = []
    odom_topic = Topic(dp, "rt/deadreckon/odom", Odometry)
    # The node's publishers are transient local: this reader asks for that, so
    # that it gets every sample from the first (a volatile one lost a run of
    # about 33 just after the filter's start in about one run in three).
    durable = Qos(
        Policy.Reliability.Reliable(max_blocking_time=duration(seconds=1)),
        Policy.Durability.TransientLocal,
        Policy.History.KeepLast(1000),
    )
    reader = DataReader(dp, odom_topic, qos=durable)
    diagnostics = []
    diag_reader = None
    if a.diagnostics_out:
        diag_reader = DataReader(dp, Topic(dp, "rt/diagnostics", DiagnosticArray), qos=durable)

    with AnyReader([a.bag], default_typestore=get_typestore(Stores.ROS1_NOETIC)) as bag:
        conns = [c for c in bag.connections if c.topic in topics]
        missing = set(topics) - {c.topic for c in conns}
        if missing:
            sys.exit(f"ros2_peer: {a.bag} has no {sorted(missing)}")
        writers = {}
        for c in conns:
            cls, _ = CONVERT[c.msgtype]
            if c.topic not in writers:
                writers[c.topic] = DataWriter(dp, Topic(dp, "rt" + c.topic, cls), qos=qos)

        with open(a.node_log, "w") as log:
            node = subprocess.Popen(node_cmd, stderr=log, stdout=log)
        stop = threading.Event()

        def receive():
            while True:
                last = stop.is_set()
                for m in reader.take(N=1000):
                    if not isinstance(m, Odometry):
                        continue  # the writer's disposal when the node exits
                    received.append(
                        {
                            "sec": m.header.stamp.sec,
                            "nanosec": m.header.stamp.nanosec,
                            "frame_id": m.header.frame_id,
                            "child_frame_id": m.child_frame_id,
                            "x": m.pose.pose.position.x,
                            "y": m.pose.pose.position.y,
                            "z": m.pose.pose.position.z,
                            "qz": m.pose.pose.orientation.z,
                            "qw": m.pose.pose.orientation.w,
                            "cov": list(m.pose.covariance),
                            "vx": m.twist.twist.linear.x,
                            "wz": m.twist.twist.angular.z,
                        }
                    )
                for m in diag_reader.take(N=100) if diag_reader else []:
                    if isinstance(m, DiagnosticArray):
                        diagnostics.append(
                            {
                                "sec": m.header.stamp.sec,
                                "status": [
                                    {
                                        "level": st.level,
                                        "name": st.name,
                                        "message": st.message,
                                        "values": {kv.key: kv.value for kv in st.values},
                                    }
                                    for st in m.status
                                ],
                            }
                        )
                if last:
                    return
                time.sleep(0.01)

        rx = threading.Thread(target=receive)
        rx.start()
        try:
            for topic, w in writers.items():
                wait(topic, lambda: w.get_publication_matched_status().current_count > 0, 60)
            wait("/deadreckon/odom", lambda: reader.get_subscription_matched_status().current_count > 0, 60)
            start = time.monotonic()
            sent = 0
            t0 = None
            for c, t_ns, raw in bag.messages(connections=conns):
                if t0 is None:
                    t0 = t_ns
                if a.signal_after is not None and (t_ns - t0) * 1e-9 >= a.signal_after:
                    node.send_signal(signal.SIGTERM)
                    print(f"ros2_peer: sent the node SIGTERM after {a.signal_after} s of bag", flush=True)
                    break
                due = start + (t_ns - t0) * 1e-9 / a.rate
                pause = due - time.monotonic()
                if pause > 0:
                    time.sleep(pause)
                writers[c.topic].write(CONVERT[c.msgtype][1](bag.deserialize(raw, c.msgtype)))
                sent += 1
            took = time.monotonic() - start
            print(f"ros2_peer: replayed {sent} messages over {took:.1f} s ({(t_ns - t0) * 1e-9:.1f} s of bag)", flush=True)
            status = node.wait(timeout=600)
            # The node lingers after its last publication; what is still on its way arrives now.
            time.sleep(0.5)
        finally:
            if node.poll() is None:
                node.kill()
            stop.set()
            rx.join(timeout=10)
    with open(a.out, "w") as f:
        for r in received:
            f.write(json.dumps(r) + "\n")
    if a.diagnostics_out:
        with open(a.diagnostics_out, "w") as f:
            for r in diagnostics:
                f.write(json.dumps(r) + "\n")
    print(f"ros2_peer: received {len(received)} odometry messages, {len(diagnostics)} diagnostics; the node exited with {status}", flush=True)
    sys.exit(status)


if __name__ == "__main__":
    main()
