//! The temporary files and directories a write has in flight, so that an
//! interrupted command (SIGINT, SIGTERM) can remove them before it exits.
//!
//! Every atomic write of this crate ([`crate::atomic_write`],
//! [`crate::write_drive_whole`]) and of the crates built on it registers its
//! temporary path here for as long as it exists. A program that installs a
//! signal handler calls [`remove_all`] from it and then exits; the command-line
//! tool does (`src/main.rs`). Without a handler nothing changes: temporary
//! files are removed on the normal paths as before.
//!
//! A rename that moves a finished result into place runs inside [`critical`],
//! and [`remove_all`] waits for it to end, so an interruption never removes a
//! directory that holds the user's previous drive while it is moved aside.
//!
//! ```
//! # let dir = tempfile::tempdir().unwrap();
//! let tmp = dir.path().join(".out.tmp");
//! std::fs::write(&tmp, b"half").unwrap();
//! let guard = deadreckon_io::temporaries::register(&tmp);
//! assert_eq!(deadreckon_io::temporaries::remove_all(), 1);
//! assert!(!tmp.exists());
//! drop(guard);
//! ```

use std::path::{Path, PathBuf};
use std::sync::Mutex;

struct Registry {
    next: u64,
    live: Vec<(u64, PathBuf)>,
}

static REGISTRY: Mutex<Registry> = Mutex::new(Registry {
    next: 0,
    live: Vec::new(),
});

/// Held by a rename that must not be interrupted half-way.
static CRITICAL: Mutex<()> = Mutex::new(());

/// A registered temporary path; dropping it unregisters the path (it does not
/// remove it: the owner removes or renames it).
#[derive(Debug)]
#[must_use = "the path is unregistered when the guard drops"]
pub struct Registered {
    id: u64,
}

/// Registers `path` (a file or a directory) as a temporary to remove if the
/// program is interrupted.
pub fn register(path: &Path) -> Registered {
    let mut r = REGISTRY.lock().unwrap_or_else(|e| e.into_inner());
    let id = r.next;
    r.next += 1;
    r.live.push((id, path.to_path_buf()));
    Registered { id }
}

impl Drop for Registered {
    fn drop(&mut self) {
        let mut r = REGISTRY.lock().unwrap_or_else(|e| e.into_inner());
        r.live.retain(|(id, _)| *id != self.id);
    }
}

/// Runs `f` (renames that move results into place) so that [`remove_all`]
/// waits until it has finished.
pub fn critical<T>(f: impl FnOnce() -> T) -> T {
    let _held = CRITICAL.lock().unwrap_or_else(|e| e.into_inner());
    f()
}

/// Removes every registered temporary that still exists (files, and
/// directories with their contents) and returns how many it removed. Meant for
/// a signal handler, just before the program exits: it waits for a rename in
/// [`critical`] to finish and then keeps later ones from starting.
pub fn remove_all() -> usize {
    let _held = CRITICAL.lock().unwrap_or_else(|e| e.into_inner());
    // Leak the guard so no critical section starts before the program exits.
    std::mem::forget(_held);
    let r = REGISTRY.lock().unwrap_or_else(|e| e.into_inner());
    let mut removed = 0;
    for (_, p) in &r.live {
        let gone = match std::fs::symlink_metadata(p) {
            Ok(m) if m.is_dir() => std::fs::remove_dir_all(p).is_ok(),
            Ok(_) => std::fs::remove_file(p).is_ok(),
            Err(_) => false,
        };
        removed += usize::from(gone);
    }
    removed
}
