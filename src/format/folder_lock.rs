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
    /// Waits for and takes the lock on `dir`, which must exist.
    pub fn acquire(dir: &Path) -> Result<Self> {
        let io = |action, source| Error::Io {
            path: dir.to_path_buf(),
            action,
            source,
        };
        #[cfg(unix)]
        let file = File::open(dir).map_err(|e| io("open the output directory to lock", e))?;
        #[cfg(not(unix))]
        let file = std::fs::OpenOptions::new()
            .create(true)
            .truncate(false)
            .write(true)
            .open(dir.join(".kiln.lock"))
            .map_err(|e| io("create the lock file in", e))?;
        file.lock()
            .map_err(|e| io("lock the output directory", e))?;
        Ok(Self { _file: file })
    }
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
