//! Independent refits run side by side. A diagnosis's refits (every
//! effect's, warm and from scratch) do not depend on one another, and one
//! refit alone cannot keep the cores busy: between its batches of renders
//! the search, the metric and the scene edits run on one thread, and a
//! batch of a few dozen small renders ends on an idle core. So the `jobs`
//! renders at once are split into lanes, each running whole refits with
//! its share, as many lanes as jobs (and no more than there are refits).
//!
//! Each refit depends only on its own inputs and seed (a fit's result does
//! not depend on its `jobs`), and results come back in task order, so the
//! diagnosis is the same whatever the number of lanes.

use std::sync::atomic::{AtomicUsize, Ordering};

/// What runs refits and counts their renders, split into lanes.
pub trait Lanes: Sized + Send + Sync {
    /// Renders at once.
    fn jobs(&self) -> usize;
    /// Lanes at most (see [`lanes_for`]).
    fn lanes(&self) -> usize;
    /// The same refits with `jobs` renders at once and none counted yet.
    fn lane(&self, jobs: usize) -> Self;
    /// Renders counted so far.
    fn renders(&self) -> usize;
    fn add_renders(&mut self, n: usize);
}

/// `refit(lane, item)` for every item, side by side in lanes, their
/// renders counted in `fits`; results in item order.
pub fn side_by_side<R: Lanes, I: Sync, T: Send>(
    fits: &mut R,
    items: &[I],
    refit: impl Fn(&mut R, &I) -> T + Sync,
) -> Vec<T> {
    let this = &*fits;
    let done = run(fits.lanes(), fits.jobs(), items.len(), |i, jobs| {
        let mut lane = this.lane(jobs);
        let out = refit(&mut lane, &items[i]);
        (out, lane.renders())
    });
    done.into_iter()
        .map(|(out, renders)| {
            fits.add_renders(renders);
            out
        })
        .collect()
}

/// Lanes for a diagnosis with `jobs` renders at once: one per job, but
/// one only when the user fixed the renderer's workers (`--workers`), a
/// count per session that lanes, each with its session, would multiply.
pub fn lanes_for(config: &super::DiagnoseConfig, jobs: usize) -> usize {
    match config.render_options.workers {
        Some(_) => 1,
        None => jobs,
    }
}

/// Runs `task(i, jobs_of_its_lane)` for every `i < n` on up to `lanes`
/// lanes (and no more than `jobs`), and returns the results in the order
/// of `i`. Tasks are taken in order as lanes come free, so put the longest
/// first.
pub fn run<T: Send>(
    lanes: usize,
    jobs: usize,
    n: usize,
    task: impl Fn(usize, usize) -> T + Sync,
) -> Vec<T> {
    let lanes = lanes.min(jobs).min(n).max(1);
    if lanes == 1 {
        return (0..n).map(|i| task(i, jobs.max(1))).collect();
    }
    // Lanes share the jobs evenly; the remainder goes to the first lanes.
    let share = |lane: usize| jobs / lanes + usize::from(lane < jobs % lanes);
    let next = AtomicUsize::new(0);
    let mut done: Vec<(usize, T)> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..lanes)
            .map(|lane| {
                let (task, next) = (&task, &next);
                scope.spawn(move || {
                    let mut mine = Vec::new();
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        if i >= n {
                            return mine;
                        }
                        mine.push((i, task(i, share(lane))));
                    }
                })
            })
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().unwrap_or_else(|p| std::panic::resume_unwind(p)))
            .collect()
    });
    done.sort_by_key(|(i, _)| *i);
    done.into_iter().map(|(_, t)| t).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashSet;
    use std::sync::Mutex;

    #[test]
    fn results_come_back_in_task_order_whatever_the_lanes() {
        for jobs in [1, 2, 3, 8] {
            let out = run(jobs, jobs, 7, |i, _| i * i);
            assert_eq!(out, vec![0, 1, 4, 9, 16, 25, 36], "jobs {jobs}");
        }
    }

    #[test]
    fn lanes_split_the_jobs_and_run_at_once() {
        let threads = Mutex::new(HashSet::new());
        let started = AtomicUsize::new(0);
        let shares = run(5, 5, 2, |_, share| {
            threads.lock().unwrap().insert(std::thread::current().id());
            // Each task waits (a while at most) for the other to start:
            // both see it only if they run at once.
            started.fetch_add(1, Ordering::SeqCst);
            let deadline = std::time::Instant::now() + std::time::Duration::from_secs(20);
            while started.load(Ordering::SeqCst) < 2 && std::time::Instant::now() < deadline {
                std::thread::yield_now();
            }
            (share, started.load(Ordering::SeqCst))
        });
        assert_eq!(shares.iter().map(|s| s.0).sum::<usize>(), 5);
        assert!(shares.iter().all(|s| s.0 >= 2 && s.1 == 2), "{shares:?}");
        assert_eq!(threads.lock().unwrap().len(), 2);
        // One lane: every task on the calling thread, with all the jobs.
        assert_eq!(run(1, 1, 3, |_, share| share), vec![1, 1, 1]);
        assert_eq!(run(4, 4, 1, |_, share| share), vec![4]);
        // Lanes capped: one lane keeps all the jobs.
        assert_eq!(run(1, 4, 2, |_, share| share), vec![4, 4]);
    }
}
