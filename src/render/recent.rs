//! The last few results of a costly computation, kept by key and shared
//! across threads: a renderer asks the same question of the same input
//! on every render of a fit, and a bounded list keeps the memory known
//! whatever the scene. First in, first out; a miss computes outside the
//! lock, so two threads may both compute a value once.

use std::sync::Mutex;

/// Up to `kept` values by key, the oldest dropped first.
pub struct Recent<K, V> {
    kept: usize,
    items: Mutex<Vec<(K, V)>>,
}

impl<K: PartialEq, V: Clone> Recent<K, V> {
    /// An empty list keeping up to `kept` values (at least one).
    pub const fn new(kept: usize) -> Self {
        Self {
            kept,
            items: Mutex::new(Vec::new()),
        }
    }

    /// The value kept for `key`, or `make`'s, which is then kept (an
    /// error is returned and not kept).
    pub fn get_or<E>(&self, key: K, make: impl FnOnce() -> Result<V, E>) -> Result<V, E> {
        if let Some((_, v)) = self.lock().iter().find(|(k, _)| *k == key) {
            return Ok(v.clone());
        }
        let v = make()?;
        let mut items = self.lock();
        if !items.iter().any(|(k, _)| *k == key) {
            if items.len() >= self.kept.max(1) {
                items.remove(0);
            }
            items.push((key, v.clone()));
        }
        Ok(v)
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Vec<(K, V)>> {
        // A panic elsewhere while holding it leaves a list still whole.
        self.items.lock().unwrap_or_else(|e| e.into_inner())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::Cell;

    #[test]
    fn a_kept_value_is_not_made_again_and_the_oldest_goes_first() {
        let made = Cell::new(0);
        let memo: Recent<u32, u32> = Recent::new(2);
        let get = |k: u32| {
            memo.get_or(k, || {
                made.set(made.get() + 1);
                Ok::<_, ()>(k * 10)
            })
            .unwrap()
        };
        assert_eq!(get(1), 10);
        assert_eq!(get(1), 10);
        assert_eq!(made.get(), 1);
        get(2);
        get(3); // drops 1
        assert_eq!(made.get(), 3);
        get(2);
        assert_eq!(made.get(), 3, "2 is still kept");
        get(1);
        assert_eq!(made.get(), 4, "1 was dropped as the oldest");
    }

    #[test]
    fn an_error_is_returned_and_not_kept() {
        let memo: Recent<u32, u32> = Recent::new(2);
        assert_eq!(memo.get_or(1, || Err("no")), Err("no"));
        assert_eq!(memo.get_or(1, || Ok::<_, &str>(5)), Ok(5));
    }
}
