//! One persistent worker process speaking the JSON-lines protocol of
//! docs/plugins.md: it prints `{"ready": true, "renderer": "..."}`, then answers
//! each request line `{"id": N, ...}` with `{"id": N, "ok": true}` or
//! `{"id": N, "ok": false, "error": "..."}`. Lines on its stdout that are
//! not protocol (Blender's banner, a stray print) are kept with its stderr,
//! not treated as errors. What breaks the protocol fails the request at
//! once and the worker is replaced: a line longer than `MAX_LINE`, an
//! answer to another id, a line that would be an answer but is not JSON.
//! An answer `"pixels": "raw"` says the output file holds raw pixels
//! rather than an image file (the protocol's optional extension).

use super::launcher::{Launched, Launcher};
use super::process::{CommandSpec, Group};
use super::slurm::Task;
use super::tail::{drain, Tail};
use super::RenderFailure;
use serde_json::Value;
use std::sync::Arc;
use std::time::Duration;
use tokio::io::{AsyncBufRead, AsyncBufReadExt, AsyncWriteExt, BufReader};
use tokio::process::{Child, ChildStdin, ChildStdout};
use tokio::time::Instant;

/// A running worker, idle between requests.
pub struct Worker {
    child: Child,
    group: Group,
    stdin: ChildStdin,
    stdout: BufReader<ChildStdout>,
    pub tail: Arc<Tail>,
    /// What the ready line said, e.g. "blender 3.4.1".
    pub renderer: String,
    /// Requests answered so far.
    pub renders: usize,
    /// Where the current request's output starts in `tail`.
    mark: u64,
    launcher: Launcher,
    /// The Slurm task it runs as, if it does.
    task: Option<Task>,
}

/// Why a request did not succeed.
#[derive(Debug)]
pub enum RequestError {
    /// The worker answered `ok: false`; it is still usable.
    Answered(String),
    /// The worker died, hung or broke the protocol; it must be replaced.
    Dead(String),
}

/// What a worker that answered ok wrote at the request's output path.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Written {
    /// An image file (PNG, BMP, ...): every worker may answer this way.
    Image,
    /// Raw 8-bit sRGB RGB pixels, no header (answer `"pixels": "raw"`).
    Raw,
}

/// What a line on the worker's stdout is.
enum Line {
    Json(serde_json::Map<String, Value>),
    Other,
}

fn classify(line: &str) -> Line {
    match serde_json::from_str::<Value>(line) {
        Ok(Value::Object(m)) => Line::Json(m),
        _ => Line::Other,
    }
}

/// The longest line a worker may print on stdout (1 MiB): protocol lines
/// are short, and an unbounded line would take unbounded memory.
pub const MAX_LINE: usize = 1 << 20;

/// Bytes of a bad line quoted in messages.
const QUOTE: usize = 100;

/// The first `QUOTE` bytes of a line, for a message.
fn quote(line: &[u8]) -> String {
    let cut = &line[..line.len().min(QUOTE)];
    let more = if line.len() > QUOTE { "..." } else { "" };
    format!("\"{}{more}\"", String::from_utf8_lossy(cut).trim())
}

/// Reads one line of at most `MAX_LINE` bytes; None at end of file. A
/// longer line is an error (InvalidData) quoting its start.
async fn read_line<R: AsyncBufRead + Unpin>(r: &mut R) -> std::io::Result<Option<String>> {
    let mut buf = Vec::new();
    loop {
        let avail = r.fill_buf().await?;
        if avail.is_empty() {
            if buf.is_empty() {
                return Ok(None);
            }
            break;
        }
        let (take, done) = match avail.iter().position(|b| *b == b'\n') {
            Some(i) => (i, true),
            None => (avail.len(), false),
        };
        // buf holds at most MAX_LINE bytes here: keep one more to tell
        let room = MAX_LINE + 1 - buf.len();
        buf.extend_from_slice(&avail[..take.min(room)]);
        r.consume(if done { take + 1 } else { take });
        if buf.len() > MAX_LINE {
            return Err(std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!(
                    "a line longer than {MAX_LINE} bytes on stdout, starting {}",
                    quote(&buf)
                ),
            ));
        }
        if done {
            break;
        }
    }
    Ok(Some(String::from_utf8_lossy(&buf).trim().to_string()))
}

impl Worker {
    /// Starts `spec` where `launcher` runs processes and waits for its
    /// ready line.
    pub async fn start(
        spec: &CommandSpec,
        launcher: &Launcher,
        timeout: Duration,
    ) -> Result<Worker, RenderFailure> {
        let fail = |message: String, stderr: String| RenderFailure { message, stderr };
        let launched = launcher.launch(spec);
        let spec = &launched.spec.clone();
        let mut w = Worker::spawn(launched, launcher)?;
        let deadline = Instant::now() + timeout;
        loop {
            match tokio::time::timeout_at(deadline, read_line(&mut w.stdout)).await {
                Err(_) => {
                    let msg = format!(
                        "worker {} did not print its ready line within {} s",
                        spec.display(),
                        timeout.as_secs_f64()
                    );
                    return Err(fail(msg, w.stop().await));
                }
                Ok(Err(e)) => {
                    return Err(fail(
                        format!("cannot read from worker {}: {e}", spec.display()),
                        w.stop().await,
                    ))
                }
                Ok(Ok(None)) => {
                    let status = w.exit_status().await;
                    return Err(fail(
                        format!(
                            "worker {} exited before it was ready ({status})",
                            spec.display()
                        ),
                        w.stop().await,
                    ));
                }
                Ok(Ok(Some(line))) => match classify(&line) {
                    Line::Json(m) if m.contains_key("ready") => {
                        if m.get("ready") == Some(&Value::Bool(true)) {
                            w.renderer = m
                                .get("renderer")
                                .and_then(Value::as_str)
                                .unwrap_or("")
                                .to_string();
                            return Ok(w);
                        }
                        let why = m
                            .get("error")
                            .and_then(Value::as_str)
                            .unwrap_or("no reason given")
                            .to_string();
                        return Err(fail(
                            format!("worker {} is not ready: {why}", spec.display()),
                            w.stop().await,
                        ));
                    }
                    _ if line.is_empty() => {}
                    _ => w.tail.push_line("[stdout] ", &line),
                },
            }
        }
    }

    /// Starts the process (not yet ready).
    fn spawn(launched: Launched, launcher: &Launcher) -> Result<Worker, RenderFailure> {
        let spec = &launched.spec;
        let (mut child, group) = spec.spawn(true).map_err(|e| {
            RenderFailure::new(format!("cannot start worker {}: {e}", spec.display()))
        })?;
        let tail = Tail::new();
        drain(child.stderr.take(), tail.clone());
        let (Some(stdin), Some(stdout)) = (child.stdin.take(), child.stdout.take()) else {
            return Err(RenderFailure::new("worker started without pipes"));
        };
        Ok(Worker {
            child,
            group,
            stdin,
            stdout: BufReader::new(stdout),
            tail,
            renderer: String::new(),
            renders: 0,
            mark: 0,
            launcher: launcher.clone(),
            task: launched.task,
        })
    }

    /// Sends one request line (which carries `"id": id`) and waits for its answer.
    pub async fn request(
        &mut self,
        line: &str,
        id: u64,
        timeout: Duration,
    ) -> Result<Written, RequestError> {
        self.mark = self.tail.mark();
        let started = super::stats::begin();
        let result = self.exchange(line, id, timeout).await;
        super::stats::end(started);
        result
    }

    async fn exchange(
        &mut self,
        line: &str,
        id: u64,
        timeout: Duration,
    ) -> Result<Written, RequestError> {
        let deadline = Instant::now() + timeout;
        self.send(line, deadline, timeout).await?;
        loop {
            let line = self.next_line(deadline, timeout).await?;
            if let Some(answer) = self.answer(&line, id) {
                return answer;
            }
        }
    }

    /// Writes the request line, within the request's time.
    async fn send(
        &mut self,
        line: &str,
        deadline: Instant,
        timeout: Duration,
    ) -> Result<(), RequestError> {
        let sent = tokio::time::timeout_at(deadline, async {
            // one write: through srun a second small one (the newline)
            // waited ~40 ms for the first to be acknowledged (measured)
            let mut bytes = Vec::with_capacity(line.len() + 1);
            bytes.extend_from_slice(line.as_bytes());
            bytes.push(b'\n');
            self.stdin.write_all(&bytes).await?;
            self.stdin.flush().await
        })
        .await;
        match sent {
            Err(_) => Err(RequestError::Dead(format!(
                "timed out after {} s (the worker does not read its input)",
                timeout.as_secs_f64()
            ))),
            Ok(Err(e)) => {
                let status = self.exit_status().await;
                Err(RequestError::Dead(format!(
                    "cannot send the request ({e}); the worker {status}"
                )))
            }
            Ok(Ok(())) => Ok(()),
        }
    }

    /// The worker's next stdout line, within the request's time.
    async fn next_line(
        &mut self,
        deadline: Instant,
        timeout: Duration,
    ) -> Result<String, RequestError> {
        match tokio::time::timeout_at(deadline, read_line(&mut self.stdout)).await {
            Err(_) => Err(RequestError::Dead(format!(
                "timed out after {} s and was killed",
                timeout.as_secs_f64()
            ))),
            Ok(Err(e)) => Err(RequestError::Dead(format!(
                "cannot read the worker's answer: {e}"
            ))),
            Ok(Ok(None)) => {
                let status = self.exit_status().await;
                Err(RequestError::Dead(format!(
                    "the worker {status} while rendering"
                )))
            }
            Ok(Ok(Some(line))) => Ok(line),
        }
    }

    /// What one stdout line means for request `id`: None when it is not
    /// the answer (kept in the log tail), else the request's outcome.
    fn answer(&mut self, line: &str, id: u64) -> Option<Result<Written, RequestError>> {
        let Line::Json(m) = classify(line) else {
            if line.starts_with('{') && line.contains("\"id\"") {
                // meant as an answer, but unreadable: waiting on would
                // only wait for the timeout
                return Some(Err(RequestError::Dead(format!(
                    "protocol violation: the answer is not valid JSON: {}",
                    quote(line.as_bytes())
                ))));
            }
            if !line.is_empty() {
                self.tail.push_line("[stdout] ", line);
            }
            return None;
        };
        let answer_id = m.get("id");
        let ours = answer_id.and_then(Value::as_u64) == Some(id);
        // id null: the worker could not read our request line
        let unread = matches!(answer_id, None | Some(Value::Null)) && m.contains_key("ok");
        if !ours && !unread {
            if m.contains_key("ok") {
                // one request at a time: an answer to another id means
                // the worker lost track of what it was asked
                return Some(Err(RequestError::Dead(format!(
                    "protocol violation: answer to id {}, expected id {id}: {}",
                    answer_id.map(Value::to_string).unwrap_or_default(),
                    quote(line.as_bytes())
                ))));
            }
            self.tail
                .push_line("[stdout, not an answer to this request] ", line);
            return None;
        }
        self.renders += 1;
        if m.get("ok") == Some(&Value::Bool(true)) && ours {
            let raw = m.get("pixels").and_then(Value::as_str) == Some("raw");
            return Some(Ok(if raw { Written::Raw } else { Written::Image }));
        }
        let why = m
            .get("error")
            .and_then(Value::as_str)
            .unwrap_or("answered ok: false without an error message");
        Some(Err(RequestError::Answered(why.to_string())))
    }

    /// "exited with status N" or "is still running", waiting a moment for it to end.
    async fn exit_status(&mut self) -> String {
        match tokio::time::timeout(Duration::from_secs(2), self.child.wait()).await {
            Ok(Ok(s)) => match s.code() {
                Some(c) => format!("exited with status {c}"),
                None => format!("ended ({s})"),
            },
            _ => "stopped answering".into(),
        }
    }

    /// What the worker printed since the current request was sent (all of
    /// it before the first request), once its last lines are in.
    pub async fn output(&self) -> String {
        // the stderr drain runs on its own task: give it a moment
        tokio::time::sleep(Duration::from_millis(20)).await;
        let text = self.tail.text_since(self.mark);
        match self.task.as_ref().map(Task::stderr_tail) {
            Some(err) if !err.trim().is_empty() => format!("{text}{err}"),
            _ => text,
        }
    }

    /// Kills the worker (and its process group) and returns `output()`.
    pub async fn stop(mut self) -> String {
        self.group.kill();
        self.launcher.cancel(self.task.as_ref());
        let _ = self.child.start_kill();
        let _ = tokio::time::timeout(Duration::from_secs(5), self.child.wait()).await;
        self.output().await
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[tokio::test]
    async fn lines_are_capped() {
        let mut long = vec![b'x'; MAX_LINE + 10];
        long.push(b'\n');
        let mut r = BufReader::new(&long[..]);
        let e = read_line(&mut r).await.unwrap_err();
        assert!(e.to_string().contains("\"xxxx"), "{e}");
        let mut r = BufReader::new(&b"{\"id\": 1}\nrest"[..]);
        assert_eq!(
            read_line(&mut r).await.unwrap().as_deref(),
            Some("{\"id\": 1}")
        );
        assert_eq!(read_line(&mut r).await.unwrap().as_deref(), Some("rest"));
        assert_eq!(read_line(&mut r).await.unwrap(), None);
    }
}
