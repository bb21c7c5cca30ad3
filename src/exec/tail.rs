//! The last few KB a renderer printed: its stderr (and a one-shot's stdout,
//! and a worker's stray stdout lines), drained on its own task so that a
//! full pipe never blocks the renderer, kept for error messages.

use std::collections::VecDeque;
use std::sync::{Arc, Mutex};
use tokio::io::{AsyncRead, AsyncReadExt};
use tokio::task::JoinHandle;

/// Bytes kept per process: enough for a Python traceback.
pub const TAIL_BYTES: usize = 4096;

/// A bounded buffer of the most recent output.
#[derive(Debug, Default)]
pub struct Tail {
    buf: Mutex<Buf>,
}

#[derive(Debug, Default)]
struct Buf {
    bytes: VecDeque<u8>,
    /// Bytes ever pushed: marks say where a request's output starts.
    total: u64,
}

impl Tail {
    pub fn new() -> Arc<Tail> {
        Arc::new(Tail::default())
    }

    /// Appends bytes, dropping the oldest beyond `TAIL_BYTES`.
    pub fn push(&self, bytes: &[u8]) {
        let mut b = self.buf.lock().unwrap_or_else(|p| p.into_inner());
        b.total += bytes.len() as u64;
        let bytes = &bytes[bytes.len().saturating_sub(TAIL_BYTES)..];
        let excess = (b.bytes.len() + bytes.len()).saturating_sub(TAIL_BYTES);
        b.bytes.drain(..excess);
        b.bytes.extend(bytes);
    }

    /// Where the output printed from now on starts (see `text_since`).
    pub fn mark(&self) -> u64 {
        self.buf.lock().unwrap_or_else(|p| p.into_inner()).total
    }

    /// Appends one line with a prefix that says where it came from.
    pub fn push_line(&self, prefix: &str, line: &str) {
        self.push(format!("{prefix}{line}\n").as_bytes());
    }

    /// The kept text (lossy UTF-8; a cut-off first line is dropped).
    pub fn text(&self) -> String {
        self.text_since(0)
    }

    /// What was printed after `mark` (as much of it as is kept).
    pub fn text_since(&self, mark: u64) -> String {
        let b = self.buf.lock().unwrap_or_else(|p| p.into_inner());
        let new = usize::try_from(b.total.saturating_sub(mark)).unwrap_or(usize::MAX);
        let skip = b.bytes.len().saturating_sub(new);
        let v: Vec<u8> = b.bytes.iter().skip(skip).copied().collect();
        let s = String::from_utf8_lossy(&v).into_owned();
        // part of the range was dropped: its first line is cut off
        if new > b.bytes.len() {
            if let Some(i) = s.find('\n') {
                return s[i + 1..].to_string();
            }
        }
        s
    }
}

/// Reads `r` to its end into `tail`, on a task of its own.
pub fn drain<R>(r: Option<R>, tail: Arc<Tail>) -> Option<JoinHandle<()>>
where
    R: AsyncRead + Unpin + Send + 'static,
{
    let mut r = r?;
    Some(tokio::spawn(async move {
        let mut buf = [0u8; 4096];
        loop {
            match r.read(&mut buf).await {
                Ok(0) | Err(_) => break,
                Ok(n) => tail.push(&buf[..n]),
            }
        }
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_the_end() {
        let t = Tail::new();
        for i in 0..2000 {
            t.push_line("", &format!("line {i}"));
        }
        let s = t.text();
        assert!(s.len() <= TAIL_BYTES);
        assert!(s.starts_with("line "), "{s:?}");
        assert!(s.ends_with("line 1999\n"));
        let t = Tail::new();
        t.push(b"short");
        assert_eq!(t.text(), "short");
        let m = t.mark();
        t.push(b" and more");
        assert_eq!(t.text_since(m), " and more");
        assert_eq!(t.text_since(t.mark()), "");
    }
}
