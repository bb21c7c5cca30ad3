//! Process-wide counters of time spent inside renderers (a one-shot
//! process from start to exit, a worker from request to answer), for
//! benchmarks: with the wall time of a fit they give the share of time the
//! pool spends outside the renderer.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Duration;

static RENDERS: AtomicU64 = AtomicU64::new(0);
static BUSY_NANOS: AtomicU64 = AtomicU64::new(0);

/// Counts one render attempt that kept a renderer busy for `d`.
pub fn record(d: Duration) {
    RENDERS.fetch_add(1, Ordering::Relaxed);
    BUSY_NANOS.fetch_add(
        u64::try_from(d.as_nanos()).unwrap_or(u64::MAX),
        Ordering::Relaxed,
    );
}

/// Render attempts and the renderer time they took since the last reset.
pub fn snapshot() -> (u64, Duration) {
    (
        RENDERS.load(Ordering::Relaxed),
        Duration::from_nanos(BUSY_NANOS.load(Ordering::Relaxed)),
    )
}

pub fn reset() {
    RENDERS.store(0, Ordering::Relaxed);
    BUSY_NANOS.store(0, Ordering::Relaxed);
}
