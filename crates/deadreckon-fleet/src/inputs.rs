//! From command-line arguments to the list of drives of a batch, and the
//! check that an output file is none of them.

use std::path::{Path, PathBuf};

use crate::FleetError;

/// True when `path` is one drive: a drive directory (with `vehicle.toml`), a
/// comma2k19 segment directory (with `processed_log/`), or a file (a
/// recording; whether it reads is the loader's to say, as a failed row).
pub fn is_drive(path: &Path) -> bool {
    if path.is_dir() {
        path.join("vehicle.toml").is_file() || path.join("processed_log").is_dir()
    } else {
        path.is_file()
    }
}

fn has_glob_chars(s: &str) -> bool {
    s.contains(['*', '?', '['])
}

/// The drives of one path: itself when it is a drive, else the drives directly
/// inside it (sorted by name; recordings `.bag`/`.mcap` included, other files
/// not).
fn drives_of(path: &Path) -> Result<Vec<PathBuf>, FleetError> {
    if is_drive(path) {
        return Ok(vec![path.to_path_buf()]);
    }
    if !path.exists() {
        return Err(FleetError::NoDrives {
            path: path.to_path_buf(),
            note: "no such file or directory".into(),
        });
    }
    let entries = std::fs::read_dir(path).map_err(|e| FleetError::NoDrives {
        path: path.to_path_buf(),
        note: format!("cannot list the directory: {e}"),
    })?;
    let mut found = Vec::new();
    for entry in entries {
        let p = entry
            .map_err(|e| FleetError::NoDrives {
                path: path.to_path_buf(),
                note: format!("cannot list the directory: {e}"),
            })?
            .path();
        let recording = p.is_file() && p.extension().is_some_and(|e| e == "bag" || e == "mcap");
        if (p.is_dir() && is_drive(&p)) || recording {
            found.push(p);
        }
    }
    found.sort();
    if found.is_empty() {
        return Err(FleetError::NoDrives {
            path: path.to_path_buf(),
            note: "not a drive (no vehicle.toml) and no drive directories or .bag/.mcap recordings inside (name other recordings, e.g. a tricycle .txt, directly)".into(),
        });
    }
    Ok(found)
}

/// Expands the arguments of `batch` into drives, in argument order, each
/// drive once. An argument is a drive, a directory of drives, or a glob
/// pattern (`*`, `?`, `[...]`, for shells that did not expand it) whose every
/// match is taken as an argument. An argument that yields no drive is an
/// error: a typo must not shrink a fleet silently.
pub fn expand(args: &[String]) -> Result<Vec<PathBuf>, FleetError> {
    let mut out: Vec<PathBuf> = Vec::new();
    for arg in args {
        let paths: Vec<PathBuf> = if has_glob_chars(arg) && !Path::new(arg).exists() {
            let matches = glob::glob(arg).map_err(|e| FleetError::Pattern {
                pattern: arg.clone(),
                message: e.to_string(),
            })?;
            let mut v = Vec::new();
            for m in matches {
                v.push(m.map_err(|e| FleetError::Pattern {
                    pattern: arg.clone(),
                    message: e.to_string(),
                })?);
            }
            if v.is_empty() {
                return Err(FleetError::NoDrives {
                    path: arg.into(),
                    note: "the pattern matches nothing".into(),
                });
            }
            v
        } else {
            vec![PathBuf::from(arg)]
        };
        for p in paths {
            for d in drives_of(&p)? {
                if !out.contains(&d) {
                    out.push(d);
                }
            }
        }
    }
    Ok(out)
}

/// `path` made absolute with symbolic links resolved, as far as it exists
/// (the file itself may not exist yet).
fn resolved(path: &Path) -> PathBuf {
    if let Ok(p) = path.canonicalize() {
        return p;
    }
    match (path.parent(), path.file_name()) {
        (Some(parent), Some(name)) => {
            let parent = if parent.as_os_str().is_empty() {
                Path::new(".")
            } else {
                parent
            };
            parent
                .canonicalize()
                .map(|p| p.join(name))
                .unwrap_or_else(|_| path.to_path_buf())
        }
        _ => path.to_path_buf(),
    }
}

/// Refuses an output file that is one of the drives, lies inside a drive
/// directory (it would change the drive it is computed from), or is a
/// directory; `what` names the option in the message.
pub fn check_output(out: &Path, drives: &[PathBuf], what: &str) -> Result<(), FleetError> {
    if out.is_dir() {
        return Err(FleetError::Options(format!(
            "{what} {}: is a directory, give a file name",
            out.display()
        )));
    }
    // Found before the drives are run, not after.
    if let Some(parent) = out.parent().filter(|p| !p.as_os_str().is_empty()) {
        if !parent.is_dir() {
            return Err(FleetError::Options(format!(
                "{what} {}: directory {} does not exist",
                out.display(),
                parent.display()
            )));
        }
    }
    let o = resolved(out);
    for d in drives {
        let d_res = resolved(d);
        if o == d_res || (d.is_dir() && o.starts_with(&d_res)) {
            return Err(FleetError::OutputIsInput {
                out: out.to_path_buf(),
                input: d.clone(),
                what: what.to_string(),
            });
        }
    }
    Ok(())
}

/// Refuses two outputs that are the same file.
pub fn check_distinct(a: &Path, b: &Path) -> Result<(), FleetError> {
    if resolved(a) == resolved(b) {
        return Err(FleetError::Options(format!(
            "--out and --history are the same file {}",
            a.display()
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn drive_dir(root: &Path, name: &str) -> PathBuf {
        let d = root.join(name);
        std::fs::create_dir_all(&d).unwrap();
        std::fs::write(d.join("vehicle.toml"), "").unwrap();
        d
    }

    #[test]
    fn directories_globs_and_duplicates() {
        let t = tempfile::tempdir().unwrap();
        let b = drive_dir(t.path(), "b");
        let a = drive_dir(t.path(), "a");
        std::fs::create_dir(t.path().join("empty")).unwrap();
        std::fs::write(t.path().join("notes.txt"), "x").unwrap();
        let root = t.path().to_string_lossy().to_string();
        // A directory of drives: its drive directories, sorted; other entries skipped.
        assert_eq!(
            expand(std::slice::from_ref(&root)).unwrap(),
            vec![a.clone(), b.clone()]
        );
        // A drive given twice, once through a pattern, counts once.
        let pattern = format!("{root}/[ab]");
        let got = expand(&[b.to_string_lossy().to_string(), pattern]).unwrap();
        assert_eq!(got, vec![b.clone(), a.clone()]);
        // Nothing found is an error naming the argument.
        let e = expand(&[format!("{root}/empty")]).unwrap_err().to_string();
        assert!(e.contains("empty") && e.contains("no drive"), "{e}");
        let e = expand(&[format!("{root}/z*")]).unwrap_err().to_string();
        assert!(e.contains("matches nothing"), "{e}");
        let e = expand(&[format!("{root}/missing")])
            .unwrap_err()
            .to_string();
        assert!(e.contains("no such file"), "{e}");
    }

    #[test]
    fn outputs_that_are_inputs_are_refused() {
        let t = tempfile::tempdir().unwrap();
        let a = drive_dir(t.path(), "a");
        let rec = t.path().join("r.bag");
        std::fs::write(&rec, "x").unwrap();
        let drives = vec![a.clone(), rec.clone()];
        assert!(check_output(&t.path().join("results.csv"), &drives, "--out").is_ok());
        let e = check_output(&rec, &drives, "--out")
            .unwrap_err()
            .to_string();
        assert!(e.contains("would overwrite"), "{e}");
        let e = check_output(&a.join("x.csv"), &drives, "--out").unwrap_err();
        assert!(matches!(e, FleetError::OutputIsInput { .. }));
        // Through another spelling of the same path.
        let other = a.join("..").join("r.bag");
        assert!(check_output(&other, &drives, "--out").is_err());
        assert!(check_output(&a, &drives, "--out").is_err());
        let e = check_output(&t.path().join("no/r.csv"), &drives, "--history")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("--history") && e.contains("does not exist"),
            "{e}"
        );
        assert!(check_distinct(&t.path().join("x.csv"), &t.path().join("./x.csv")).is_err());
    }
}
