//! Writing files so that a reader never sees half of one: every file the
//! tool writes goes through a temporary file in the same directory that is
//! flushed and synced before it is renamed into place. A failed write (a
//! full disk) leaves the previous file intact and the temporary file
//! removed. Files are created with the process's umask, like any other
//! program's output, so that a web server can read a report's figures.

use crate::error::{Error, Result};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

/// Writes `bytes` to `path` atomically.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_atomic_with(path, |w| w.write_all(bytes))
}

/// Writes `path` atomically through `fill`, which writes the contents into
/// a buffered writer; nothing is renamed into place unless every byte
/// reached the disk.
pub fn write_atomic_with(
    path: &Path,
    fill: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    let tmp = temp_path(path);
    let result = (|| -> std::io::Result<()> {
        let file = std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&tmp)?;
        let mut w = std::io::BufWriter::new(file);
        fill(&mut w)?;
        let file = w.into_inner().map_err(|e| e.into_error())?;
        file.sync_all()?;
        std::fs::rename(&tmp, path)?;
        // The rename itself is durable once the directory is synced.
        if let Ok(d) = std::fs::File::open(parent(path)) {
            let _ = d.sync_all();
        }
        Ok(())
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(write_error(path, e));
    }
    Ok(())
}

/// A write that failed for want of room (a full disk, a quota, a file-size
/// limit) or a device error is the run's failure, not the user's mistake;
/// one that failed for a missing or read-only directory is the user's.
fn write_error(path: &Path, e: std::io::Error) -> Error {
    let room = [libc::ENOSPC, libc::EFBIG, libc::EDQUOT, libc::EIO];
    match e.raw_os_error() {
        Some(code) if room.contains(&code) => Error::Run(format!(
            "{}: could not be written ({e}); the previous file, if any, is kept",
            path.display()
        )),
        _ => Error::io(path, e),
    }
}

/// True for the name of a temporary file `write_atomic` makes: one a
/// killed process may leave behind.
pub fn is_temp_name(name: &str) -> bool {
    name.starts_with('.') && name.contains(".tmp.")
}

// Reading lives in `input`, the one way to open an input; these names
// stay for the callers that read through `fsio`.
pub use crate::input::{read_capped, read_text_capped, CappedRead, MAX_JSON_BYTES};

fn parent(path: &Path) -> &Path {
    path.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// `.NAME.tmp.PID.N` beside `path`: hidden, and unique within and across
/// processes.
fn temp_path(path: &Path) -> PathBuf {
    static COUNTER: AtomicU64 = AtomicU64::new(0);
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().to_string())
        .unwrap_or_else(|| "out".into());
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    parent(path).join(format!(".{name}.tmp.{}.{n}", std::process::id()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_failed_write_keeps_the_previous_file() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.json");
        write_atomic(&p, b"first").unwrap();
        let err = write_atomic_with(&p, |w| {
            w.write_all(b"half")?;
            Err(std::io::Error::other("disk full"))
        });
        assert!(err.is_err());
        assert_eq!(std::fs::read(&p).unwrap(), b"first");
        let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(left.len(), 1, "the temporary file is removed");
    }

    #[test]
    fn files_follow_the_umask() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("b.txt");
        let old = unsafe { libc::umask(0o022) };
        write_atomic(&p, b"x").unwrap();
        unsafe { libc::umask(old) };
        let mode = std::fs::metadata(&p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode, 0o644);
    }
}
