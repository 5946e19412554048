//! Wall-clock medians for example tables (benchmarks use criterion).

use std::time::{Duration, Instant};

/// Runs `f` repeatedly (at least 3 times, until `budget` is spent or 10 000 runs) and returns
/// the median wall time of one run together with the last result.
pub fn median_time<T>(budget: Duration, mut f: impl FnMut() -> T) -> (Duration, T) {
    let start = Instant::now();
    let mut times = Vec::new();
    let mut last;
    loop {
        let t = Instant::now();
        last = f();
        times.push(t.elapsed());
        if (times.len() >= 3 && start.elapsed() >= budget) || times.len() >= 10_000 {
            break;
        }
    }
    times.sort();
    (times[times.len() / 2], last)
}
