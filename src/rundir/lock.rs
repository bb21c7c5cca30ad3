//! An advisory lock on a run directory (flock on a lock file), released
//! when the process ends however it ends, so a killed run never leaves a
//! stale lock behind. The lock file is opened without following a link
//! and must be a regular file: a planted symlink would otherwise have a
//! run write its PID into whatever file the link names.

use crate::error::{Error, Result};
use std::io::{Read, Seek, Write};
use std::os::unix::fs::OpenOptionsExt;
use std::os::unix::io::AsRawFd;
use std::path::Path;

/// Bytes of the holder's PID read back at most (the file is ours; a
/// planted huge one is not read whole).
const HOLDER_BYTES: u64 = 32;

#[derive(Debug)]
pub struct Lock {
    _file: std::fs::File,
}

impl Lock {
    /// Takes the lock, or says which process holds it.
    pub fn take(path: &Path) -> Result<Lock> {
        let not_a_lock = |what: &str| {
            Error::Usage(format!(
                "{}: {what}, not a scenefit lock file; remove it (scenefit never follows or writes through it)",
                path.display()
            ))
        };
        let mut file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            // O_NONBLOCK: a planted FIFO must not block the open.
            .custom_flags(libc::O_NOFOLLOW | libc::O_NONBLOCK)
            .open(path)
            .map_err(|e| match e.raw_os_error() {
                Some(libc::ELOOP) => not_a_lock("a symbolic link"),
                _ => Error::io(path, e),
            })?;
        let meta = file.metadata().map_err(|e| Error::io(path, e))?;
        if !meta.is_file() {
            return Err(not_a_lock("not a regular file"));
        }
        // SAFETY: flock on a descriptor this function owns.
        let r = unsafe { libc::flock(file.as_raw_fd(), libc::LOCK_EX | libc::LOCK_NB) };
        if r != 0 {
            let mut holder = String::new();
            let _ = (&mut file).take(HOLDER_BYTES).read_to_string(&mut holder);
            let dir = path.parent().unwrap_or(path);
            return Err(Error::Usage(format!(
                "{}: the directory is in use by another scenefit run{}; wait for it or choose another directory",
                dir.display(),
                match holder.trim() {
                    pid if !pid.is_empty() && pid.bytes().all(|b| b.is_ascii_digit()) =>
                        format!(" (pid {pid})"),
                    _ => String::new(),
                }
            )));
        }
        let _ = file.set_len(0);
        let _ = file.rewind();
        let _ = write!(file, "{}", std::process::id());
        Ok(Lock { _file: file })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_planted_symlink_is_refused_and_its_target_untouched() {
        let d = tempfile::tempdir().unwrap();
        let victim = d.path().join("victim.txt");
        std::fs::write(&victim, "precious").unwrap();
        let lock = d.path().join(".scenefit.lock");
        std::os::unix::fs::symlink(&victim, &lock).unwrap();
        let e = Lock::take(&lock).unwrap_err().to_string();
        assert!(e.contains("symbolic link"), "{e}");
        assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
    }

    #[test]
    fn a_planted_fifo_is_refused_without_blocking() {
        let d = tempfile::tempdir().unwrap();
        let lock = d.path().join(".scenefit.lock");
        let c = std::ffi::CString::new(lock.to_str().unwrap()).unwrap();
        // SAFETY: mkfifo on a path this test owns.
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let e = Lock::take(&lock).unwrap_err().to_string();
        assert!(e.contains("not a regular file"), "{e}");
    }
}
