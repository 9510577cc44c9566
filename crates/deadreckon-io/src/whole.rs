//! Whole drive directories: written beside the target under a temporary name
//! and renamed into place, so a reader sees the old drive or the new one,
//! never a mixture (a full disk, an error or a signal half-way leaves the
//! target as it was). The temporary directories are registered in
//! [`crate::temporaries`] and the final renames run in
//! [`crate::temporaries::critical`], so an interrupted program removes them
//! without ever removing the previous drive while it is moved aside.

use std::fs;
use std::path::Path;

use deadreckon_core::Drive;

use crate::{files, write_drive, IoError};

/// Writes `drive` (and whatever `extra` writes into the same directory, e.g.
/// `truth_params.toml`) as the directory `dir`, whole. An existing drive
/// directory is replaced; an existing directory that is not empty and holds no
/// `vehicle.toml` is refused (it is not ours to delete), as is a file.
pub fn write_drive_whole(
    dir: &Path,
    drive: &Drive,
    extra: impl FnOnce(&Path) -> Result<(), IoError>,
) -> Result<(), IoError> {
    let parent = match dir.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let name = dir
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .ok_or_else(|| refuse(dir, "not a directory name"))?;
    let exists = match fs::symlink_metadata(dir) {
        Ok(m) if m.is_dir() => true,
        Ok(_) => return Err(refuse(dir, "exists and is not a directory")),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => false,
        Err(e) => return Err(IoError::io(dir, e)),
    };
    if exists && !dir.join(files::VEHICLE).is_file() {
        let empty = fs::read_dir(dir)
            .map_err(|e| IoError::io(dir, e))?
            .next()
            .is_none();
        if !empty {
            return Err(refuse(
                dir,
                "exists, is not empty and holds no vehicle.toml: not replacing it \
                 (choose a new directory)",
            ));
        }
    }
    fs::create_dir_all(parent).map_err(|e| IoError::io(parent, e))?;
    let tmp = temp_dir(parent, &name)?;
    let _registered = crate::temporaries::register(tmp.path());
    write_drive(tmp.path(), drive)?;
    extra(tmp.path())?;
    crate::temporaries::critical(|| swap_in(dir, tmp, exists, parent, &name))
}

/// Moves the finished temporary directory `tmp` to `dir`, the previous drive
/// (if `exists`) aside and then away.
fn swap_in(
    dir: &Path,
    tmp: tempfile::TempDir,
    exists: bool,
    parent: &Path,
    name: &str,
) -> Result<(), IoError> {
    if exists {
        // Move the old directory aside (into a temporary directory removed
        // when it drops), the new one in; put the old one back on failure.
        let aside = temp_dir(parent, name)?;
        let _registered = crate::temporaries::register(aside.path());
        let old = aside.path().join("previous");
        fs::rename(dir, &old).map_err(|e| IoError::io(dir, e))?;
        if let Err(e) = fs::rename(tmp.path(), dir) {
            let _ = fs::rename(&old, dir);
            return Err(IoError::io(dir, e));
        }
        // The new directory is in place under `dir`; `tmp` no longer exists.
        let _ = tmp.keep();
        drop(aside);
    } else {
        fs::rename(tmp.path(), dir).map_err(|e| IoError::io(dir, e))?;
        let _ = tmp.keep();
    }
    Ok(())
}

fn temp_dir(parent: &Path, name: &str) -> Result<tempfile::TempDir, IoError> {
    tempfile::Builder::new()
        .prefix(&format!(".{name}."))
        .suffix(".tmp")
        .tempdir_in(parent)
        .map_err(|e| IoError::io(parent, e))
}

fn refuse(dir: &Path, what: &str) -> IoError {
    IoError::io(
        dir,
        std::io::Error::new(std::io::ErrorKind::AlreadyExists, what),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use deadreckon_core::drive::{Scalar, WheelTicks, Wheels};
    use deadreckon_core::Vehicle;

    fn drive(n: usize) -> Drive {
        Drive {
            vehicle: Vehicle::paper_car(),
            wheels: Wheels::Ticks(
                (0..n)
                    .map(|k| WheelTicks {
                        t_s: k as f64 * 0.02,
                        fl: 1,
                        fr: 1,
                        rl: 1,
                        rr: 1,
                    })
                    .collect(),
            ),
            yaw_rate: (0..n)
                .map(|k| Scalar {
                    t_s: k as f64 * 0.02,
                    value: 0.0,
                })
                .collect(),
            speed: Vec::new(),
            steering: Vec::new(),
            gnss: Vec::new(),
            truth: Vec::new(),
            imu: Default::default(),
        }
    }

    fn names(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn a_failure_half_way_left_a_partial_drive() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("d");
        // A new directory: a failing extra step leaves nothing at all.
        let e = write_drive_whole(&dir, &drive(10), |_| {
            Err(IoError::io("x", std::io::Error::other("disk full")))
        });
        assert!(e.is_err());
        assert_eq!(names(tmp.path()), Vec::<String>::new());
        // Written whole.
        write_drive_whole(&dir, &drive(10), |_| Ok(())).unwrap();
        assert_eq!(
            names(&dir),
            ["vehicle.toml", "wheel_ticks.csv", "yaw_rate.csv"]
        );
        // A failing rewrite keeps the old drive, byte for byte, and no temporary.
        let before = fs::read(dir.join("wheel_ticks.csv")).unwrap();
        let e = write_drive_whole(&dir, &drive(20), |_| {
            Err(IoError::io("x", std::io::Error::other("disk full")))
        });
        assert!(e.is_err());
        assert_eq!(fs::read(dir.join("wheel_ticks.csv")).unwrap(), before);
        assert_eq!(names(tmp.path()), ["d"]);
        // A successful rewrite replaces it whole.
        write_drive_whole(&dir, &drive(20), |p| {
            fs::write(p.join("truth_params.toml"), "x = 1\n").map_err(|e| IoError::io(p, e))
        })
        .unwrap();
        assert_ne!(fs::read(dir.join("wheel_ticks.csv")).unwrap(), before);
        assert!(dir.join("truth_params.toml").is_file());
        assert_eq!(names(tmp.path()), ["d"]);
    }

    #[test]
    fn a_directory_that_is_not_a_drive_is_not_replaced() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = tmp.path().join("photos");
        fs::create_dir(&dir).unwrap();
        fs::write(dir.join("a.jpg"), "x").unwrap();
        let e = write_drive_whole(&dir, &drive(10), |_| Ok(())).unwrap_err();
        assert!(e.to_string().contains("not replacing"), "{e}");
        assert_eq!(names(&dir), ["a.jpg"]);
        // An empty directory is fine.
        let empty = tmp.path().join("empty");
        fs::create_dir(&empty).unwrap();
        write_drive_whole(&empty, &drive(10), |_| Ok(())).unwrap();
        assert!(empty.join("vehicle.toml").is_file());
    }
}
