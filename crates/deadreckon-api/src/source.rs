//! A drive from any source the tool reads, chosen by what the path holds.

use std::path::Path;

use deadreckon_core::Drive;

use crate::Error;

/// What a path holds, as the tool tells recordings apart: by what a
/// directory contains and a file's extension (the one place that decides;
/// the command line asks it).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SourceKind {
    /// A drive directory (`vehicle.toml` and the CSV streams; also a
    /// directory that is none of the others: reading it says what is missing).
    DriveDirectory,
    /// A comma2k19 segment directory (`processed_log/`, no `vehicle.toml`).
    Comma2k19,
    /// A rosbag2 directory (`metadata.yaml`) holding one `.mcap`.
    Rosbag2Directory,
    /// A ROS1 `.bag` or ROS2 `.mcap` file.
    RosFile,
    /// A tricycle log (`.txt`), read as a drive or through the tricycle's
    /// own kinematics.
    TricycleLog,
    /// A file of no format the tool reads.
    Unknown,
}

/// What `path` holds ([`SourceKind`]).
pub fn detect(path: &Path) -> SourceKind {
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
    if path.is_dir() {
        if !path.join("vehicle.toml").exists() && path.join("processed_log").is_dir() {
            SourceKind::Comma2k19
        } else if path.join("metadata.yaml").is_file() {
            SourceKind::Rosbag2Directory
        } else {
            SourceKind::DriveDirectory
        }
    } else if path.is_file() {
        match ext {
            "bag" | "mcap" => SourceKind::RosFile,
            "txt" => SourceKind::TricycleLog,
            _ => SourceKind::Unknown,
        }
    } else {
        // Missing: the drive reader names it.
        SourceKind::DriveDirectory
    }
}

/// Reads a drive from a drive directory or, directly, from a recording that a
/// reader understands: a comma2k19 segment directory, a ROS1 `.bag`, a ROS2
/// `.mcap` (with `mapping`, a topic-mapping TOML file, or the built-in Husky
/// or Jackal mapping) or a tricycle `dataset.txt`.
pub fn read_drive(path: &Path, mapping: Option<&Path>) -> Result<Drive, Error> {
    read_drive_with(path, &deadreckon_io::ReadOptions::default(), mapping)
}

/// [`read_drive`] with reading options for drive directories (recordings are
/// read whole).
pub fn read_drive_with(
    path: &Path,
    options: &deadreckon_io::ReadOptions,
    mapping: Option<&Path>,
) -> Result<Drive, Error> {
    match detect(path) {
        SourceKind::Comma2k19 => {
            deadreckon_import::read_comma2k19(path, None).map_err(|source| Error::Comma2k19 {
                path: path.to_path_buf(),
                source: Box::new(source),
            })
        }
        // A rosbag2 directory: read through its one .mcap file.
        SourceKind::Rosbag2Directory | SourceKind::RosFile => Ok(read_ros(path, mapping)?.0),
        SourceKind::TricycleLog => {
            let o = deadreckon_import::tricycle::TricycleOptions::default();
            Ok(deadreckon_import::tricycle::read_tricycle(path, &o)
                .map_err(|source| Error::Tricycle {
                    path: path.to_path_buf(),
                    source: Box::new(source),
                })?
                .drive)
        }
        SourceKind::Unknown => Err(Error::Unrecognised {
            path: path.to_path_buf(),
        }),
        SourceKind::DriveDirectory => {
            deadreckon_io::read_drive_with(path, options).map_err(|source| Error::Drive {
                path: path.to_path_buf(),
                source: Box::new(source),
            })
        }
    }
}

/// Reads a ROS1 bag or ROS2 MCAP recording with the `mapping` file, or the
/// built-in mapping whose wheel topic the recording has
/// ([`builtin_mapping`]), with the reader's report of what was used,
/// dropped and counted.
pub fn read_ros(
    path: &Path,
    mapping: Option<&Path>,
) -> Result<(Drive, deadreckon_ros::ImportReport), Error> {
    read_ros_saying(path, mapping).map(|(d, r, _)| (d, r))
}

/// [`read_ros`], and which mapping was used and why, in words (for the
/// import's report).
pub fn read_ros_saying(
    path: &Path,
    mapping: Option<&Path>,
) -> Result<(Drive, deadreckon_ros::ImportReport, String), Error> {
    let ros_err = |source| Error::Ros {
        path: path.to_path_buf(),
        source: Box::new(source),
    };
    // Read once: the topics choose the built-in mapping, then the same bytes
    // are read with it.
    let (bytes, file) = deadreckon_ros::log_bytes(path).map_err(ros_err)?;
    let (mapping, said) = match mapping {
        Some(m) => (mapping_file(m)?, format!("mapping: {}", m.display())),
        None => {
            let topics = deadreckon_ros::list_topics_bytes(&bytes, &file).map_err(ros_err)?;
            let names: Vec<&str> = topics.iter().map(|t| t.topic.as_str()).collect();
            builtin_mapping(&names)
        }
    };
    let (drive, report) =
        deadreckon_ros::read_log_bytes(&bytes, &file, &mapping).map_err(ros_err)?;
    Ok((drive, report, said))
}

/// The built-in mapping for a recording with these topics: the Jackal's when
/// it has the Jackal's wheel odometry topic, else the Husky's (whose
/// missing topics the reader then names); and the choice in words. It used
/// to be the Jackal's when the file's name contained "jackal", silently
/// (issue 33).
pub fn builtin_mapping(topics: &[&str]) -> (deadreckon_ros::Mapping, String) {
    let wheel_topic = |m: &deadreckon_ros::Mapping| {
        m.streams
            .iter()
            .find(|s| s.kind == deadreckon_ros::StreamKind::OdometryWheels)
            .map(|s| s.topic.clone())
            .unwrap_or_default()
    };
    let jackal = deadreckon_ros::Mapping::jackal();
    let jt = wheel_topic(&jackal);
    if topics.contains(&jt.as_str()) {
        return (
            jackal,
            format!("mapping: the built-in Jackal mapping (the recording has {jt}; --mapping FILE to choose another)"),
        );
    }
    let husky = deadreckon_ros::Mapping::husky();
    let ht = wheel_topic(&husky);
    let why = if topics.contains(&ht.as_str()) {
        format!("the recording has {ht}")
    } else {
        format!("the default: the recording has neither {ht} nor {jt}")
    };
    (
        husky,
        format!("mapping: the built-in Husky mapping ({why}; --mapping FILE to choose another)"),
    )
}

/// Reads and validates a mapping file.
pub fn mapping_file(m: &Path) -> Result<deadreckon_ros::Mapping, Error> {
    let text = std::fs::read_to_string(m).map_err(|source| Error::MappingFile {
        path: m.to_path_buf(),
        source,
    })?;
    deadreckon_ros::Mapping::from_toml_str(&text).map_err(|source| Error::Mapping {
        path: m.to_path_buf(),
        source: Box::new(source),
    })
}

/// The mapping of a live node: a mapping file, the name of a built-in one
/// (`husky`, `jackal`) when no such file exists, or by default the Husky's.
pub fn live_mapping(spec: Option<&Path>) -> Result<deadreckon_ros::Mapping, Error> {
    match spec {
        None => Ok(deadreckon_ros::Mapping::husky()),
        Some(p) if !p.exists() && p.as_os_str() == "husky" => Ok(deadreckon_ros::Mapping::husky()),
        Some(p) if !p.exists() && p.as_os_str() == "jackal" => {
            Ok(deadreckon_ros::Mapping::jackal())
        }
        Some(p) => mapping_file(p),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_live_node_takes_a_builtin_mapping_by_name_and_the_husky_by_default() {
        let husky = deadreckon_ros::Mapping::husky();
        assert_eq!(live_mapping(None).unwrap(), husky);
        assert_eq!(live_mapping(Some(Path::new("husky"))).unwrap(), husky);
        let jackal = live_mapping(Some(Path::new("jackal"))).unwrap();
        assert_eq!(jackal, deadreckon_ros::Mapping::jackal());
        assert!(matches!(
            live_mapping(Some(Path::new("no/such/mapping.toml"))),
            Err(Error::MappingFile { .. })
        ));
    }

    #[test]
    fn the_command_line_told_tricycle_logs_apart_by_itself() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let file = |name: &str| {
            let p = d.join(name);
            std::fs::write(&p, "x").unwrap();
            p
        };
        assert_eq!(detect(&file("dataset.txt")), SourceKind::TricycleLog);
        assert_eq!(detect(&file("h.bag")), SourceKind::RosFile);
        assert_eq!(detect(&file("h.mcap")), SourceKind::RosFile);
        assert_eq!(detect(&file("h.csv")), SourceKind::Unknown);
        let seg = d.join("seg");
        std::fs::create_dir_all(seg.join("processed_log")).unwrap();
        assert_eq!(detect(&seg), SourceKind::Comma2k19);
        // With a vehicle.toml it is a drive directory (an imported segment).
        std::fs::write(seg.join("vehicle.toml"), "").unwrap();
        assert_eq!(detect(&seg), SourceKind::DriveDirectory);
        let bag2 = d.join("bag2");
        std::fs::create_dir_all(&bag2).unwrap();
        std::fs::write(bag2.join("metadata.yaml"), "").unwrap();
        assert_eq!(detect(&bag2), SourceKind::Rosbag2Directory);
        assert_eq!(detect(&d.join("missing")), SourceKind::DriveDirectory);
    }

    #[test]
    fn an_unknown_file_is_refused_naming_it() {
        let dir = tempfile::tempdir().unwrap();
        let f = dir.path().join("x.csv");
        std::fs::write(&f, "t_s\n").unwrap();
        let e = read_drive(&f, None).unwrap_err();
        assert!(matches!(e, Error::Unrecognised { .. }));
        assert!(e
            .to_string()
            .starts_with(&format!("{}: not a drive", f.display())));
    }

    #[test]
    fn a_missing_vehicle_toml_names_the_file() {
        let dir = tempfile::tempdir().unwrap();
        let e = read_drive(dir.path(), None).unwrap_err();
        let text = crate::chain_text(&e);
        assert!(text.starts_with("reading drive "), "{text}");
        assert!(text.contains("vehicle.toml"), "{text}");
    }
}
