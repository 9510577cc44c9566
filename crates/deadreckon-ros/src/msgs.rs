//! The few message types read, in one decoded form, with the ROS1 decoder.
//!
//! ROS1 serialization is little-endian with no padding: `time` is (sec u32,
//! nsec u32), a string is (length u32, bytes), a fixed array is its elements, a
//! `std_msgs/Header` is (seq u32, stamp time, frame_id string). ROS2 messages
//! (CDR) are decoded by [`crate::ros2`] into the same [`Decoded`] form.

/// The message types a mapping can name, without the ROS2 `/msg/` part.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum MsgType {
    Odometry,
    Imu,
    NavSatFix,
    TwistStamped,
    PoseStamped,
}

impl MsgType {
    /// Parses `nav_msgs/Odometry` or `nav_msgs/msg/Odometry`.
    pub(crate) fn from_name(name: &str) -> Option<MsgType> {
        Some(match name.replace("/msg/", "/").as_str() {
            "nav_msgs/Odometry" => MsgType::Odometry,
            "sensor_msgs/Imu" => MsgType::Imu,
            "sensor_msgs/NavSatFix" => MsgType::NavSatFix,
            "geometry_msgs/TwistStamped" => MsgType::TwistStamped,
            "geometry_msgs/PoseStamped" => MsgType::PoseStamped,
            _ => return None,
        })
    }
}

/// A header stamp: seconds and nanoseconds since the epoch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Stamp {
    pub sec: i64,
    pub nsec: u32,
}

impl Stamp {
    /// The stamp in seconds, or `None` for the zero stamp (unset by the driver).
    pub(crate) fn seconds(self) -> Option<f64> {
        if self.sec == 0 && self.nsec == 0 {
            None
        } else {
            Some(self.sec as f64 + f64::from(self.nsec) * 1e-9)
        }
    }
}

/// A message decoded to the fields the importer uses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Decoded {
    /// `nav_msgs/Odometry`: twist.linear.x (m/s) and twist.angular.z (rad/s).
    Odometry {
        stamp: Stamp,
        v_mps: f64,
        w_rps: f64,
    },
    /// `sensor_msgs/Imu`: angular_velocity (rad/s) in the IMU frame.
    Imu { stamp: Stamp, gyro: [f64; 3] },
    /// `sensor_msgs/NavSatFix`.
    NavSatFix {
        stamp: Stamp,
        status: i8,
        lat_deg: f64,
        lon_deg: f64,
        alt_m: f64,
        cov: [f64; 9],
        cov_type: u8,
    },
    /// `geometry_msgs/TwistStamped`: linear.x and angular.z.
    Twist {
        stamp: Stamp,
        v_mps: f64,
        w_rps: f64,
    },
    /// `geometry_msgs/PoseStamped`: position and orientation (x, y, z, w).
    Pose {
        stamp: Stamp,
        position: [f64; 3],
        orientation: [f64; 4],
    },
}

/// A ROS1 little-endian cursor; every read is bounds-checked.
struct Ros1<'a> {
    b: &'a [u8],
    pos: usize,
}

impl<'a> Ros1<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8], String> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.b.len());
        match end {
            Some(e) => {
                let s = &self.b[self.pos..e];
                self.pos = e;
                Ok(s)
            }
            None => Err(format!(
                "message cut short: {n} bytes wanted at byte {} of {}",
                self.pos,
                self.b.len()
            )),
        }
    }
    fn u8(&mut self) -> Result<u8, String> {
        Ok(self.take(1)?[0])
    }
    fn u32(&mut self) -> Result<u32, String> {
        let s = self.take(4)?;
        Ok(u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
    }
    fn f64(&mut self) -> Result<f64, String> {
        let s = self.take(8)?;
        let mut a = [0u8; 8];
        a.copy_from_slice(s);
        Ok(f64::from_le_bytes(a))
    }
    fn f64s<const N: usize>(&mut self) -> Result<[f64; N], String> {
        let mut out = [0.0; N];
        for v in &mut out {
            *v = self.f64()?;
        }
        Ok(out)
    }
    fn skip_f64s(&mut self, n: usize) -> Result<(), String> {
        self.take(n * 8).map(|_| ())
    }
    fn string(&mut self) -> Result<(), String> {
        let n = self.u32()? as usize;
        self.take(n).map(|_| ())
    }
    /// `std_msgs/Header`: seq, stamp, frame_id.
    fn header(&mut self) -> Result<Stamp, String> {
        self.u32()?;
        let sec = self.u32()?;
        let nsec = self.u32()?;
        self.string()?;
        Ok(Stamp {
            sec: i64::from(sec),
            nsec,
        })
    }
    fn end(&self) -> Result<(), String> {
        if self.pos == self.b.len() {
            Ok(())
        } else {
            Err(format!(
                "{} bytes left over after the message (wrong type?)",
                self.b.len() - self.pos
            ))
        }
    }
}

/// Decodes a ROS1-serialized message of type `t`.
pub(crate) fn decode_ros1(t: MsgType, data: &[u8]) -> Result<Decoded, String> {
    let mut c = Ros1 { b: data, pos: 0 };
    let d = match t {
        MsgType::Odometry => {
            let stamp = c.header()?;
            c.string()?; // child_frame_id
            c.skip_f64s(7 + 36)?; // pose.pose, pose.covariance
            let lin: [f64; 3] = c.f64s()?;
            let ang: [f64; 3] = c.f64s()?;
            c.skip_f64s(36)?; // twist.covariance
            Decoded::Odometry {
                stamp,
                v_mps: lin[0],
                w_rps: ang[2],
            }
        }
        MsgType::Imu => {
            let stamp = c.header()?;
            c.skip_f64s(4 + 9)?; // orientation, orientation_covariance
            let gyro: [f64; 3] = c.f64s()?;
            c.skip_f64s(9 + 3 + 9)?; // angular_velocity_covariance, linear_acceleration(+cov)
            Decoded::Imu { stamp, gyro }
        }
        MsgType::NavSatFix => {
            let stamp = c.header()?;
            let status = c.u8()? as i8;
            c.take(2)?; // service
            let [lat_deg, lon_deg, alt_m]: [f64; 3] = c.f64s()?;
            let cov: [f64; 9] = c.f64s()?;
            let cov_type = c.u8()?;
            Decoded::NavSatFix {
                stamp,
                status,
                lat_deg,
                lon_deg,
                alt_m,
                cov,
                cov_type,
            }
        }
        MsgType::TwistStamped => {
            let stamp = c.header()?;
            let lin: [f64; 3] = c.f64s()?;
            let ang: [f64; 3] = c.f64s()?;
            Decoded::Twist {
                stamp,
                v_mps: lin[0],
                w_rps: ang[2],
            }
        }
        MsgType::PoseStamped => {
            let stamp = c.header()?;
            let position: [f64; 3] = c.f64s()?;
            let orientation: [f64; 4] = c.f64s()?;
            Decoded::Pose {
                stamp,
                position,
                orientation,
            }
        }
    };
    c.end()?;
    Ok(d)
}
