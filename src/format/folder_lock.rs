//! One writer at a time in an output folder: the replacement rule's check
//! ([`super::replace::check`]) and the renames that follow it are made under an exclusive lock
//! on the folder, so that of two bakes of different specs into one folder exactly one writes and
//! the other is refused by the rule, naming the first one's files (without it both checked an
//! empty folder, both renamed their files into place, and both said they wrote them).
//!
//! The lock is the operating system's advisory file lock (`flock` on Unix, `LockFileEx` on
//! Windows, through [`std::fs::File::lock`]), released when the process ends however it ends:
//! an interrupted bake leaves no lock behind. On Unix the folder itself is locked (nothing is
//! added to it); elsewhere a file `.kiln.lock` in the folder is. A bake holds the lock only for
//! the moments its files take to check and rename, never during the integration.

use crate::error::{Error, Result};
use std::fs::File;
use std::path::Path;

/// An exclusive lock on an output folder, held until dropped.
#[derive(Debug)]
pub struct FolderLock {
    _file: File,
}

impl FolderLock {
    /// Creates `dir` if need be, then waits for and takes the lock on it. Another kiln may
    /// remove a folder it created for its start-up check ([`super::check_output_dir`]) while
    /// this one takes the lock: the lock is taken again until it holds the folder that is at
    /// `dir` (on Unix, the same inode), so that two writers never lock two different folders.
    pub fn acquire(dir: &Path) -> Result<Self> {
        let io = |action, source| Error::Io {
            path: dir.to_path_buf(),
            action,
            source,
        };
        let mut attempts = 0;
        loop {
            attempts += 1;
            std::fs::create_dir_all(dir).map_err(|e| io("create the output directory", e))?;
            #[cfg(unix)]
            let opened = File::open(dir);
            #[cfg(not(unix))]
            let opened = std::fs::OpenOptions::new()
                .create(true)
                .truncate(false)
                .write(true)
                .open(dir.join(".kiln.lock"));
            let file = match opened {
                Ok(file) => file,
                Err(e) if e.kind() == std::io::ErrorKind::NotFound && attempts < 100 => continue,
                Err(e) => return Err(io("open the output directory to lock", e)),
            };
            file.lock()
                .map_err(|e| io("lock the output directory", e))?;
            if holds(&file, dir) || attempts >= 100 {
                return Ok(Self { _file: file });
            }
        }
    }
}

/// Removes the empty folder `dir` unless another kiln holds its lock (it is about to write
/// there): what a start-up check does with a folder it created ([`super::check_output_dir`]).
/// Failures are harmless: the folder stays.
pub fn remove_if_free(dir: &Path) {
    #[cfg(unix)]
    if let Ok(file) = File::open(dir) {
        if file.try_lock().is_ok() {
            let _ = std::fs::remove_dir(dir);
        }
        return;
    }
    let _ = std::fs::remove_dir(dir);
}

/// Whether the locked `file` is (on Unix) the folder now at `dir`.
#[cfg(unix)]
fn holds(file: &File, dir: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (file.metadata(), std::fs::metadata(dir)) {
        (Ok(locked), Ok(there)) => locked.ino() == there.ino() && locked.dev() == there.dev(),
        _ => false,
    }
}

/// Elsewhere the lock file in the folder keeps it from being removed.
#[cfg(not(unix))]
fn holds(_: &File, _: &Path) -> bool {
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    /// While one holder has the folder, another waits: checked with a non-blocking try from a
    /// second open of the folder (what a second process does), before and after the drop.
    #[test]
    fn a_second_holder_waits_for_the_first() {
        let dir = tempfile::tempdir().expect("temp dir");
        let held = FolderLock::acquire(dir.path()).expect("lock");
        #[cfg(unix)]
        let other = File::open(dir.path()).expect("open");
        #[cfg(not(unix))]
        let other = File::open(dir.path().join(".kiln.lock")).expect("open");
        assert!(matches!(
            other.try_lock(),
            Err(std::fs::TryLockError::WouldBlock)
        ));
        drop(held);
        other.try_lock().expect("free once dropped");
    }
}
