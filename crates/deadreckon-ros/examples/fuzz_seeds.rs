//! Writes the small seed inputs of the fuzz targets (`fuzz/`): two ROS 2 MCAP
//! files (chunked and not) and a tiny ROS1 bag, from the test fixtures.
//!
//! ```text
//! cargo run -p deadreckon-ros --example fuzz_seeds -- crates/deadreckon-ros/fuzz/seeds
//! ```

#[path = "../tests/common/mod.rs"]
mod common;

use std::path::PathBuf;
use std::process::ExitCode;

use common::{ros2_mcap_for, tiny_bag, Quirks};

fn write(dir: &std::path::Path) -> std::io::Result<()> {
    let q = Quirks {
        duplicate_odom: true,
        zero_stamp_imu: false,
        no_fix: false,
        message_compression: None,
    };
    std::fs::create_dir_all(dir.join("mcap"))?;
    std::fs::create_dir_all(dir.join("rosbag"))?;
    std::fs::write(dir.join("mcap/chunked.mcap"), ros2_mcap_for(true, &q, 0.2))?;
    std::fs::write(
        dir.join("mcap/unchunked.mcap"),
        ros2_mcap_for(false, &q, 0.2),
    )?;
    std::fs::write(dir.join("rosbag/tiny.bag"), tiny_bag(&[0u8; 40]))?;
    Ok(())
}

fn main() -> ExitCode {
    let mut args = std::env::args_os().skip(1);
    let (Some(dir), None) = (args.next(), args.next()) else {
        eprintln!("usage: fuzz_seeds SEEDS_DIR (e.g. crates/deadreckon-ros/fuzz/seeds)");
        return ExitCode::from(2);
    };
    let dir = PathBuf::from(dir);
    match write(&dir) {
        Ok(()) => {
            println!("seeds written to {}", dir.display());
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("error: writing seeds to {}: {e}", dir.display());
            ExitCode::FAILURE
        }
    }
}
