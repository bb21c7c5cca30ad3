//! One way to open an input: every file the tool reads (scenes, shots
//! files, photographs, masks, maps, worker outputs, checkpoints and other
//! run-directory files, fonts) goes through [`read_capped`]. It opens
//! without blocking, so a FIFO cannot hang the run; it refuses what is not
//! a regular file (a FIFO, a device such as `/dev/zero`, a socket) with a
//! line saying what the file is; it knows the size (fstat) before reading,
//! so a 20 GB sparse file is refused without a byte read; and it never
//! reads more than the caller's cap, so a file that grows while read is
//! refused too. No input asks for a device today; one that does would need
//! its own, explicit, opener. Images read are decoded by [`decode`].

pub mod decode;

use crate::error::{Error, Result};
use std::fs::File;
use std::io::Read;
use std::os::unix::fs::{FileTypeExt, OpenOptionsExt};
use std::path::Path;

/// The most a JSON file the tool reads back (a result, a checkpoint) may
/// hold: far above any real one, far below what would exhaust memory.
pub const MAX_JSON_BYTES: u64 = 256 << 20;

/// The most a font file may hold: the largest CJK fonts are ~20 MiB.
pub const MAX_FONT_BYTES: u64 = 64 << 20;

/// The most a mesh file (PLY or OBJ) may hold: ~10 M triangles in
/// binary PLY, far below what would exhaust memory once parsed.
pub const MAX_MESH_BYTES: u64 = 256 << 20;

/// The most a texture file (PNG or OpenEXR) may hold: an 8192 x 8192
/// 16-bit RGBA PNG stored raw is 512 MiB; real ones are far smaller.
pub const MAX_TEXTURE_BYTES: u64 = 512 << 20;

/// The most a calibration file (COLMAP's cameras.txt or images.txt, an
/// OpenCV YAML) may hold: images.txt lists every 2-D point of every
/// photograph, some hundreds of MiB for the largest reconstructions.
pub const MAX_CALIBRATION_BYTES: u64 = 512 << 20;

/// The most another tool's scene file (a Mitsuba 3 XML) may hold: its
/// meshes live in files of their own, so real ones are far smaller.
pub const MAX_SCENE_XML_BYTES: u64 = 256 << 20;

/// The most a text file of a run directory (a trace, a ledger) may hold.
pub const MAX_TEXT_BYTES: u64 = 64 << 20;

/// Why a capped read gave no bytes; each caller words it for its file.
/// A file that is not regular (FIFO, device, socket) comes as `Io` with an
/// `InvalidInput` error that says what it is and that a regular file was
/// expected, so that every caller's message names it.
#[derive(Debug)]
pub enum CappedRead {
    Io(std::io::Error),
    Directory,
    /// Longer than the limit.
    TooLarge,
}

/// Opens `path` for reading without blocking (a FIFO with no writer would
/// block a plain open forever), checks it is a regular file, then makes it
/// blocking again for the read. Returns the file and its size.
fn open_regular(path: &Path) -> std::result::Result<(File, u64), CappedRead> {
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK | libc::O_NOCTTY)
        .open(path)
        .map_err(CappedRead::Io)?;
    let meta = file.metadata().map_err(CappedRead::Io)?;
    let kind = meta.file_type();
    if kind.is_dir() {
        return Err(CappedRead::Directory);
    }
    if !kind.is_file() {
        let what = if kind.is_fifo() {
            "a FIFO"
        } else if kind.is_char_device() || kind.is_block_device() {
            "a device"
        } else if kind.is_socket() {
            "a socket"
        } else {
            "not a file"
        };
        return Err(CappedRead::Io(std::io::Error::new(
            std::io::ErrorKind::InvalidInput,
            format!("{what}; expected a regular file"),
        )));
    }
    clear_nonblocking(&file).map_err(CappedRead::Io)?;
    Ok((file, meta.len()))
}

/// Clears O_NONBLOCK, which a regular file ignores today but a read of one
/// on a network file system may not.
fn clear_nonblocking(file: &File) -> std::io::Result<()> {
    use std::os::fd::AsRawFd;
    let fd = file.as_raw_fd();
    // SAFETY: fcntl on a descriptor this function's caller owns.
    let flags = unsafe { libc::fcntl(fd, libc::F_GETFL) };
    if flags < 0 || unsafe { libc::fcntl(fd, libc::F_SETFL, flags & !libc::O_NONBLOCK) } < 0 {
        return Err(std::io::Error::last_os_error());
    }
    Ok(())
}

/// Reads at most `limit` bytes of the regular file `path`: a longer file
/// is refused by its size before anything is read, and one that grows past
/// the limit while read is refused too.
pub fn read_capped(path: &Path, limit: u64) -> std::result::Result<Vec<u8>, CappedRead> {
    let (file, len) = open_regular(path)?;
    if len > limit {
        return Err(CappedRead::TooLarge);
    }
    let mut bytes = Vec::with_capacity(len as usize);
    file.take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(CappedRead::Io)?;
    if bytes.len() as u64 > limit {
        return Err(CappedRead::TooLarge);
    }
    Ok(bytes)
}

/// Reads the last `n` bytes (at most) of the regular file `path`,
/// whatever its size: the tail of a log another program writes.
pub fn read_tail(path: &Path, n: u64) -> std::result::Result<Vec<u8>, CappedRead> {
    use std::io::{Seek, SeekFrom};
    let (mut file, len) = open_regular(path)?;
    file.seek(SeekFrom::Start(len.saturating_sub(n)))
        .map_err(CappedRead::Io)?;
    let mut bytes = Vec::with_capacity(n.min(len) as usize);
    file.take(n)
        .read_to_end(&mut bytes)
        .map_err(CappedRead::Io)?;
    Ok(bytes)
}

/// Reads the first `n` bytes (at most) of the regular file `path`, and
/// gives its size: a file's signature, before another program reads it.
pub fn read_head(path: &Path, n: u64) -> std::result::Result<(Vec<u8>, u64), CappedRead> {
    let (file, len) = open_regular(path)?;
    let mut bytes = Vec::with_capacity(n.min(len) as usize);
    file.take(n)
        .read_to_end(&mut bytes)
        .map_err(CappedRead::Io)?;
    Ok((bytes, len))
}

/// Reads a text file the tool wrote, of at most `limit` bytes.
pub fn read_text_capped(path: &Path, limit: u64) -> Result<String> {
    let bytes =
        read_capped(path, limit).map_err(|e| capped_error(path, e, "a file scenefit wrote"))?;
    String::from_utf8(bytes)
        .map_err(|_| Error::Usage(format!("{}: not UTF-8 text", path.display())))
}

/// The error for a capped read of `path` that failed, `expected` naming
/// what the file should have been ("a file scenefit wrote").
pub fn capped_error(path: &Path, e: CappedRead, expected: &str) -> Error {
    match e {
        CappedRead::Io(e) => Error::io(path, e),
        CappedRead::Directory => Error::Usage(format!(
            "{}: a directory; expected {expected}",
            path.display()
        )),
        CappedRead::TooLarge => Error::Usage(format!(
            "{}: too large; expected {expected}",
            path.display()
        )),
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn a_tail_is_read_from_the_end_of_any_size_of_file() {
        let d = tempfile::tempdir().unwrap();
        let small = d.path().join("small.log");
        std::fs::write(&small, b"abcdef").unwrap();
        assert_eq!(read_tail(&small, 4).unwrap(), b"cdef");
        assert_eq!(read_tail(&small, 100).unwrap(), b"abcdef");
        // sparse: 20 GB declared, only the tail is read
        let huge = d.path().join("huge.log");
        let f = std::fs::File::create(&huge).unwrap();
        f.set_len(20 << 30).unwrap();
        assert_eq!(read_tail(&huge, 8).unwrap(), vec![0u8; 8]);
    }

    use super::*;
    use std::time::{Duration, Instant};

    fn refusal(path: &Path) -> String {
        match read_capped(path, 1 << 20) {
            Err(CappedRead::Io(e)) => e.to_string(),
            Err(CappedRead::TooLarge) => "too large".into(),
            Err(CappedRead::Directory) => "directory".into(),
            Ok(b) => panic!("{} read as {} bytes", path.display(), b.len()),
        }
    }

    #[test]
    fn a_fifo_is_refused_at_once() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("fifo");
        let c = std::ffi::CString::new(p.to_str().unwrap()).unwrap();
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let t = Instant::now();
        let e = refusal(&p);
        assert!(e.contains("a FIFO; expected a regular file"), "{e}");
        assert!(t.elapsed() < Duration::from_secs(2));
    }

    #[test]
    fn devices_and_links_to_them_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let link = dir.path().join("zero");
        std::os::unix::fs::symlink("/dev/zero", &link).unwrap();
        for p in [Path::new("/dev/zero"), &link] {
            let e = refusal(p);
            assert!(e.contains("a device; expected a regular file"), "{e}");
        }
    }

    #[test]
    fn a_huge_sparse_file_is_refused_by_its_size() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("sparse");
        File::create(&p).unwrap().set_len(20 << 30).unwrap();
        let t = Instant::now();
        assert_eq!(refusal(&p), "too large");
        assert!(t.elapsed() < Duration::from_secs(2));
        assert_eq!(refusal(dir.path()), "directory");
    }

    #[test]
    fn a_file_within_the_cap_is_read_whole() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a");
        std::fs::write(&p, b"12345").unwrap();
        assert_eq!(read_capped(&p, 5).unwrap(), b"12345");
        assert!(matches!(read_capped(&p, 4), Err(CappedRead::TooLarge)));
        assert_eq!(read_text_capped(&p, 5).unwrap(), "12345");
    }
}
