//! Shared by the examples: the output directory from `--out DIR` (default `out/`), created;
//! the value of a flag; and the CPU-time measurements of the stability examples.

// Each example compiles all of this and uses only some of it.
#![allow(dead_code)]

use std::path::PathBuf;
use std::str::FromStr;
use std::time::Instant;

/// The directory given with `--out` (default `out`), created if needed.
pub fn out_dir() -> std::io::Result<PathBuf> {
    let args: Vec<String> = std::env::args().collect();
    let out = flag(&args, "--out", PathBuf::from("out"));
    std::fs::create_dir_all(&out)?;
    Ok(out)
}

/// The value after `name` in `args`, or `default` if it is missing or does not parse.
pub fn flag<T: FromStr>(args: &[String], name: &str, default: T) -> T {
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// CPU time of this thread in ms (wall clock where `/proc` is not there).
pub fn cpu_ms(start: Instant) -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .map_or_else(|| start.elapsed().as_secs_f64() * 1e3, |ns| ns * 1e-6)
}

/// CPU time of the whole process (every thread, also those that have ended) in ms, from
/// `/proc/self/stat` (ticks of 10 ms); 0 where it is not there.
pub fn process_cpu_ms() -> f64 {
    std::fs::read_to_string("/proc/self/stat")
        .ok()
        .and_then(|s| {
            // After the command name in parentheses: state is field 3, utime 14, stime 15.
            let rest = &s[s.rfind(')')? + 2..];
            let f: Vec<&str> = rest.split_whitespace().collect();
            Some((f.get(11)?.parse::<f64>().ok()? + f.get(12)?.parse::<f64>().ok()?) * 10.0)
        })
        .unwrap_or(0.0)
}

/// The median (the upper one of an even count).
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}
