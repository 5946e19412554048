//! The harmonics of one speed are independent: `Z_k` is factored and solved for every `k`
//! on its own. [`map_owned`] spreads such per-harmonic work over the machine's cores (scoped
//! threads, harmonic `k` on thread `k mod T`), with the results in harmonic order and each
//! result computed exactly as on one thread, so the answers do not depend on the thread count.
//!
//! One thread unless `HBAL_THREADS` asks for more: on the shared two-core machine the
//! 1000-DOF run-up (84 points, condensed, H = 32) took 1.70 s wall on one thread and 1.8 to
//! 2.0 s on two while the other core was busy (the factorisation of a harmonic, 10 to 30 µs, is
//! too short to hide a contended core). On an idle multi-core machine `HBAL_THREADS=2` or more
//! may pay; the answers are the same.

/// Smallest problem (DOFs × harmonics) worth the threads (a spawn costs some 10 µs).
const MIN_WORK: usize = 20_000;

/// Threads to use for `work` (DOFs × harmonics): `HBAL_THREADS` (default 1), at most the
/// available cores, 1 for small problems.
pub(crate) fn threads(work: usize) -> usize {
    let asked = asked().unwrap_or(1);
    if work < MIN_WORK || asked == 1 {
        return 1;
    }
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    cores.min(asked).max(1)
}

/// Threads for a few long, independent tasks (tens of milliseconds each, where a busy core
/// costs little against the spawn): `HBAL_THREADS` if set, otherwise every available core.
pub(crate) fn threads_for_long_tasks() -> usize {
    asked().unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()))
}

std::thread_local! {
    /// The limit of [`limit_threads_here`] on this thread.
    static LIMIT: std::cell::Cell<Option<usize>> = const { std::cell::Cell::new(None) };
}

/// Limits the threads of the analyses started on the calling thread to `limit` (`None`: no
/// limit of its own, `HBAL_THREADS` and the cores decide) and returns the limit before. A
/// study that runs one analysis per core sets 1 in each task: every analysis keeps to its core
/// (no second thread for the stability's products), with the same answers to the bit. Only
/// this thread is affected, so analyses on other threads keep theirs.
///
/// ```
/// let before = hbal::limit_threads_here(Some(1));
/// assert_eq!(before, None);
/// assert_eq!(hbal::limit_threads_here(before), Some(1));
/// ```
pub fn limit_threads_here(limit: Option<usize>) -> Option<usize> {
    LIMIT.with(|l| l.replace(limit))
}

/// `HBAL_THREADS`, within the calling thread's limit ([`limit_threads_here`]).
fn asked() -> Option<usize> {
    let env = std::env::var("HBAL_THREADS")
        .ok()
        .and_then(|v| v.parse::<usize>().ok())
        .filter(|&t| t >= 1);
    match (LIMIT.with(|l| l.get()), env) {
        (Some(limit), Some(t)) => Some(t.min(limit.max(1))),
        (Some(limit), None) => Some(limit.max(1)),
        (None, env) => env,
    }
}

/// Whether an analysis may keep a second thread busy beside its own (the stability's
/// assembler, a sweep's stability worker): `HBAL_THREADS` (within the thread's limit) of 2 or
/// more, or, where neither is set, at least two available cores.
pub(crate) fn second_thread() -> bool {
    match asked() {
        Some(t) => t >= 2,
        None => std::thread::available_parallelism().is_ok_and(|n| n.get() >= 2),
    }
}

/// `[f(0, items[0]), f(1, items[1]), …]` on up to `threads` threads: each call owns its item
/// (a buffer of the last speed's, to be filled again instead of allocated).
pub(crate) fn map_owned<B: Send, T: Send>(
    items: Vec<B>,
    threads: usize,
    f: impl Fn(usize, B) -> T + Sync,
) -> Vec<T> {
    let count = items.len();
    let threads = threads.min(count);
    if threads <= 1 {
        return items
            .into_iter()
            .enumerate()
            .map(|(k, b)| f(k, b))
            .collect();
    }
    let mut shares: Vec<Vec<(usize, B)>> = (0..threads).map(|_| Vec::new()).collect();
    for (k, b) in items.into_iter().enumerate() {
        shares[k % threads].push((k, b));
    }
    let f = &f;
    let mut parts: Vec<Vec<T>> = std::thread::scope(|s| {
        let handles: Vec<_> = shares
            .into_iter()
            .map(|share| s.spawn(move || share.into_iter().map(|(k, b)| f(k, b)).collect()))
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    });
    let mut iters: Vec<_> = parts.iter_mut().map(|p| p.drain(..)).collect();
    (0..count)
        .map(|k| iters[k % threads].next().expect("one result per index"))
        .collect()
}

#[cfg(test)]
mod tests {
    #[test]
    fn owned_items_come_back_in_index_order() {
        let items = |_: ()| (0..37).map(|k| vec![k; 3]).collect::<Vec<_>>();
        let f = |k: usize, mut b: Vec<usize>| {
            b.push(k * k);
            b
        };
        let serial = super::map_owned(items(()), 1, f);
        let spread = super::map_owned(items(()), 3, f);
        assert_eq!(serial, spread);
        assert_eq!(spread[36], vec![36, 36, 36, 1296]);
    }
}
