//! Running the `hbal` binary on hostile input and judging the outcome by the exit-code
//! contract: no panic (101), no abort (a signal), an exit code in {0, 1, 2}, at most one JSON
//! object on stdout with no `null` where a number belongs, and an exit code that matches the
//! JSON (`converged`, a failed stability computation, capped automatic harmonics).

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

/// Address space of one run (6 GiB): above the 4 GiB a harmonic-balance system may take, so
/// that an allocation the limits missed aborts the run instead of the machine.
pub const ADDRESS_SPACE_KB: u64 = 6 << 20;

/// Wall-time limit of one run.
pub const TIME_LIMIT: Duration = Duration::from_secs(60);

/// What one run of `hbal` did.
#[derive(Debug)]
pub struct Run {
    /// The exit code, `None` if a signal ended it (an abort) or the time limit did.
    pub code: Option<i32>,
    pub stdout: String,
    pub stderr: String,
    pub seconds: f64,
    pub timed_out: bool,
}

/// Runs `hbal args` under [`ADDRESS_SPACE_KB`] and [`TIME_LIMIT`] (killed on time out).
pub fn run_limited(args: &[&str]) -> Run {
    let script = format!("ulimit -v {ADDRESS_SPACE_KB} && exec \"$0\" \"$@\"");
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(script)
        .arg(env!("CARGO_BIN_EXE_hbal"))
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run hbal");
    // Drain the pipes on threads so that a chatty run cannot block on a full pipe.
    let mut out = child.stdout.take().expect("stdout");
    let mut err = child.stderr.take().expect("stderr");
    let out = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = std::io::Read::read_to_string(&mut out, &mut s);
        s
    });
    let err = std::thread::spawn(move || {
        let mut s = String::new();
        let _ = std::io::Read::read_to_string(&mut err, &mut s);
        s
    });
    let start = Instant::now();
    let mut timed_out = false;
    let status = loop {
        if let Some(status) = child.try_wait().expect("wait for hbal") {
            break status;
        }
        if start.elapsed() > TIME_LIMIT {
            timed_out = true;
            let _ = child.kill();
            break child.wait().expect("wait for hbal");
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    Run {
        code: status.code(),
        stdout: out.join().unwrap_or_default(),
        stderr: err.join().unwrap_or_default(),
        seconds: start.elapsed().as_secs_f64(),
        timed_out,
    }
}

/// How a run broke the contract.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Breach {
    /// Exit code 101 or a panic message.
    Panic,
    /// Ended by a signal (an abort, a failed allocation, a crash).
    Abort,
    /// Killed at the time limit.
    Timeout,
    /// An exit code outside {0, 1, 2}.
    ExitCode,
    /// `null` where a number belongs (NaN or infinity on the way), or not one JSON object.
    NonFinite,
    /// The exit code contradicts the JSON (`converged`, stability, automatic harmonics).
    Inconsistent,
}

/// Keys whose value may be `null` by the documented schema (docs/scenes.md).
const NULLABLE: [&str; 35] = [
    "auto_harmonics",
    "error_estimate",
    "found_by",
    "gear_stage",
    "other_orbit",
    "quadrature",
    "reduction",
    "stability",
    "start",
    "stopped",
    "worst_force",
    "worst_quantity",
    // A sweep's points and branches: what a point has only with its stability or estimate.
    "stable",
    "fold_speed",
    "bifurcation",
    "bifurcation_speed",
    "error_estimate_harmonics",
    "multipliers",
    "multipliers_abs",
    "neutral",
    "orbit_correction",
    "polished",
    "stability_orbit",
    "orbit_difference",
    "orbit_distance",
    "turn_evidence",
    "from_speed",
    "from_omega_rad_s",
    "side",
    "parent_point",
    // The modes' bounds where a mode has none; compare's quantity where it was not measured.
    "lower_hz",
    "upper_hz",
    "worst_quantity_vs_time_domain",
    // Several base frequencies: why the automatic caps stopped (none: null); a base's Hz in a
    // sweep, where the speed varies (docs/torus.md).
    "caps_stopped",
    "hz",
];

/// Judges a run of `hbal check` (`json = false`) or `hbal solve --json` (`json = true`).
/// What a run prints on stdout, and so how its exit code is judged.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Document {
    /// Nothing to judge (text, files).
    None,
    /// `hbal solve --json`: converged, stability, automatic harmonics.
    Solve,
    /// `hbal sweep --json` (speed or parameter): `reached`.
    Sweep,
    /// `hbal modes --json`: `converged`.
    Modes,
    /// `hbal compare --json`: some method converged.
    Compare,
}

/// [`judge_document`] of `hbal solve --json` (`json`) or of a run without a document.
pub fn judge(run: &Run, json: bool) -> Result<(), (Breach, String)> {
    judge_document(
        run,
        if json {
            Document::Solve
        } else {
            Document::None
        },
    )
}

/// Judges `run`, which printed `document`: no panic, abort, timeout, exit code outside 0..=2,
/// non-finite number, or exit code its document contradicts.
pub fn judge_document(run: &Run, document: Document) -> Result<(), (Breach, String)> {
    let json = document != Document::None;
    let fail = |b: Breach, what: String| Err((b, format!("{what}\nstderr: {}", run.stderr)));
    if run.timed_out {
        return fail(
            Breach::Timeout,
            format!("killed after {:.0} s", run.seconds),
        );
    }
    let Some(code) = run.code else {
        return fail(Breach::Abort, "ended by a signal".into());
    };
    if code == 101 || run.stderr.contains("panicked") || run.stderr.contains("internal error") {
        return fail(Breach::Panic, format!("exit code {code}"));
    }
    if !(0..=2).contains(&code) {
        return fail(Breach::ExitCode, format!("exit code {code}"));
    }
    if !json || run.stdout.trim().is_empty() {
        // No result: a failure must say why.
        if code != 0 && !run.stderr.contains("error") {
            return fail(
                Breach::Inconsistent,
                format!("exit code {code} without an error message"),
            );
        }
        return Ok(());
    }
    let doc: serde_json::Value = match serde_json::from_str(&run.stdout) {
        Ok(d) => d,
        Err(e) => {
            return fail(
                Breach::NonFinite,
                format!("stdout is not one JSON object: {e}"),
            )
        }
    };
    if let Some(path) = null_number(&doc, "") {
        return fail(Breach::NonFinite, format!("`null` at {path}"));
    }
    if document != Document::Solve {
        let expected = match document {
            Document::Sweep => doc["reached"]
                .as_bool()
                .map(|r| if r { 0 } else { 1 })
                .or_else(|| torus_sweep_verdict(&doc)),
            Document::Modes => doc["converged"].as_bool().map(|c| if c { 0 } else { 1 }),
            _ => doc["methods"].as_array().map(|m| {
                let any = m.iter().any(|m| m["converged"] == true);
                if any {
                    0
                } else {
                    1
                }
            }),
        };
        return match expected {
            Some(e) if e == code => Ok(()),
            Some(e) => fail(
                Breach::Inconsistent,
                format!("exit code {code}, but the JSON says {e}"),
            ),
            None => fail(
                Breach::Inconsistent,
                "the JSON lacks its verdict field".into(),
            ),
        };
    }
    let converged = doc["converged"].as_bool();
    let stability_failed = doc["stability"].get("error").is_some();
    let capped = doc["auto_harmonics"]["reached"].as_bool() == Some(false);
    let expected = match converged {
        Some(true) if !stability_failed && !capped => 0,
        Some(_) => 1,
        None => return fail(Breach::Inconsistent, "no `converged` in the JSON".into()),
    };
    if code != expected {
        return fail(
            Breach::Inconsistent,
            format!("exit code {code}, but the JSON says {expected} (converged {converged:?}, stability failed {stability_failed}, capped {capped})"),
        );
    }
    Ok(())
}

/// The exit code a sweep on several base frequencies says it has (it has no `reached`): 1
/// where a point did not converge, a speed was skipped or the caps stopped short.
fn torus_sweep_verdict(doc: &serde_json::Value) -> Option<i32> {
    let points = doc["points"].as_array()?;
    let failed = points.iter().any(|p| p["converged"] != true)
        || doc["skipped"].as_array().is_some_and(|s| !s.is_empty())
        || !doc["caps_stopped"].is_null();
    Some(i32::from(failed))
}

/// The path of the first `null` outside the nullable keys.
fn null_number(v: &serde_json::Value, path: &str) -> Option<String> {
    match v {
        serde_json::Value::Null => Some(path.to_string()),
        serde_json::Value::Array(a) => a
            .iter()
            .enumerate()
            .find_map(|(i, x)| null_number(x, &format!("{path}[{i}]"))),
        serde_json::Value::Object(m) => m.iter().find_map(|(k, x)| {
            if x.is_null() && NULLABLE.contains(&k.as_str()) {
                None
            } else {
                null_number(x, &format!("{path}.{k}"))
            }
        }),
        _ => None,
    }
}

/// Writes `text` to `dir/name` and returns the path as a string.
pub fn write(dir: &Path, name: &str, text: &str) -> String {
    std::fs::create_dir_all(dir).expect("temp dir");
    let p = dir.join(name);
    std::fs::write(&p, text).expect("write scene");
    p.to_str().expect("utf-8 path").to_string()
}
