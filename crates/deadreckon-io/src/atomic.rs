//! Atomic file writes: write to a temporary file in the same directory, flush,
//! sync, then rename over the target, so a reader never sees a half-written file.

use std::fs;
use std::io::{BufWriter, Write};
use std::path::Path;

use crate::IoError;

/// Writes `path` atomically: `write` fills a temporary file created in the same
/// directory (named `.<file name>.<random>.tmp`), which is then flushed, synced
/// and renamed over `path`.
///
/// On any error (from `write`, from the file system, or a parent that is not a
/// directory) the temporary file is removed and `path` is left as it was: absent,
/// or with its previous content. The parent directory is not created.
///
/// The new file keeps the permissions of the file it replaces, or gets `0o644`
/// on Unix when it is new (temporary files are created `0o600`). While it
/// exists the temporary file is registered in [`crate::temporaries`], so an
/// interrupted program can remove it.
///
/// ```
/// # let dir = tempfile::tempdir().unwrap();
/// let path = dir.path().join("hello.txt");
/// deadreckon_io::atomic_write(&path, |w| w.write_all(b"hello\n")).unwrap();
/// assert_eq!(std::fs::read_to_string(&path).unwrap(), "hello\n");
/// ```
pub fn atomic_write<F>(path: &Path, write: F) -> Result<(), IoError>
where
    F: FnOnce(&mut dyn Write) -> std::io::Result<()>,
{
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let name = path
        .file_name()
        .ok_or_else(|| {
            IoError::io(
                path,
                std::io::Error::new(std::io::ErrorKind::InvalidInput, "not a file path"),
            )
        })?
        .to_string_lossy()
        .into_owned();
    let tmp = tempfile::Builder::new()
        .prefix(&format!(".{name}."))
        .suffix(".tmp")
        .tempfile_in(parent)
        .map_err(|e| IoError::io(path, in_dir(parent, e)))?;
    let _registered = crate::temporaries::register(tmp.path());
    let previous_permissions = fs::metadata(path).ok().map(|m| m.permissions());
    {
        let mut w = BufWriter::new(tmp.as_file());
        write(&mut w).map_err(|e| IoError::io(path, e))?;
        w.flush().map_err(|e| IoError::io(path, e))?;
    }
    tmp.as_file().sync_all().map_err(|e| IoError::io(path, e))?;
    let permissions = match previous_permissions {
        Some(p) => Some(p),
        None => default_permissions(),
    };
    if let Some(p) = permissions {
        fs::set_permissions(tmp.path(), p).map_err(|e| IoError::io(path, e))?;
    }
    tmp.persist(path).map_err(|e| IoError::io(path, e.error))?;
    // Make the rename durable; failure here does not undo the write.
    if let Ok(d) = fs::File::open(parent) {
        let _ = d.sync_all();
    }
    Ok(())
}

#[cfg(unix)]
fn default_permissions() -> Option<fs::Permissions> {
    use std::os::unix::fs::PermissionsExt;
    Some(fs::Permissions::from_mode(0o644))
}

#[cfg(not(unix))]
fn default_permissions() -> Option<fs::Permissions> {
    None
}

/// The error of creating the temporary file in `dir`, said of the directory:
/// `tempfile`'s own text names the temporary file, which the user never asked
/// for.
fn in_dir(dir: &Path, e: std::io::Error) -> std::io::Error {
    let text = e.to_string();
    let os = text.find(" at path ").map_or(text.as_str(), |i| &text[..i]);
    std::io::Error::new(
        e.kind(),
        format!("cannot create a file in {}: {os}", dir.display()),
    )
}
