//! Process-wide counters of time spent inside renderers (a one-shot
//! process from start to exit, a worker from request to answer), for
//! benchmarks: with the wall time of a fit they give the share of time
//! spent outside the renderer.

use std::sync::Mutex;
use std::time::{Duration, Instant};

struct State {
    renders: u64,
    busy: Duration,
    in_flight: u64,
    /// When the last render in flight ended (or the counters were reset).
    idle_since: Instant,
    /// Wall time with no render in flight.
    idle: Duration,
}

static STATE: Mutex<Option<State>> = Mutex::new(None);

fn with<T>(f: impl FnOnce(&mut State) -> T) -> T {
    let mut g = STATE.lock().unwrap_or_else(|p| p.into_inner());
    let s = g.get_or_insert_with(|| State {
        renders: 0,
        busy: Duration::ZERO,
        in_flight: 0,
        idle_since: Instant::now(),
        idle: Duration::ZERO,
    });
    f(s)
}

/// A render attempt starts; pass the returned instant to `end`.
pub fn begin() -> Instant {
    let now = Instant::now();
    with(|s| {
        if s.in_flight == 0 {
            s.idle += now.saturating_duration_since(s.idle_since);
        }
        s.in_flight += 1;
    });
    now
}

/// The render attempt started at `started` is over.
pub fn end(started: Instant) {
    let now = Instant::now();
    with(|s| {
        s.renders += 1;
        s.busy += now.saturating_duration_since(started);
        s.in_flight = s.in_flight.saturating_sub(1);
        if s.in_flight == 0 {
            s.idle_since = now;
        }
    });
}

/// Since the last reset: render attempts, the renderer time they took
/// (summed over concurrent renders), and the wall time in which no render
/// was in flight (up to now).
pub fn snapshot() -> (u64, Duration, Duration) {
    let now = Instant::now();
    with(|s| {
        let idle = if s.in_flight == 0 {
            s.idle + now.saturating_duration_since(s.idle_since)
        } else {
            s.idle
        };
        (s.renders, s.busy, idle)
    })
}

pub fn reset() {
    with(|s| {
        s.renders = 0;
        s.busy = Duration::ZERO;
        s.idle = Duration::ZERO;
        s.idle_since = Instant::now();
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_idle_and_busy_time() {
        reset();
        std::thread::sleep(Duration::from_millis(20));
        let a = begin();
        let b = begin();
        std::thread::sleep(Duration::from_millis(20));
        end(a);
        end(b);
        let (n, busy, idle) = snapshot();
        assert_eq!(n, 2);
        assert!(busy >= Duration::from_millis(40), "{busy:?}");
        assert!(
            idle >= Duration::from_millis(20) && idle < Duration::from_millis(40),
            "{idle:?}"
        );
    }
}
