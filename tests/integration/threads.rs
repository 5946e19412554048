//! The harmonics of a speed on several threads (`HBAL_THREADS`) give the same bits as on one:
//! the 1000-DOF drivetrain scene (condensed, 33 harmonics per speed, enough work for the
//! threads) solved both ways, every harmonic of every DOF compared exactly.

use std::process::Command;

fn solve_json(threads: &str) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_hbal"))
        .args([
            "solve",
            concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/examples/scenes/large/drivetrain_1000.toml"
            ),
            "--no-stability",
            "--json",
        ])
        .env("HBAL_THREADS", threads)
        .output()
        .expect("hbal runs");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut doc: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    // Everything but the timings.
    if let Some(o) = doc.as_object_mut() {
        o.retain(|k, _| !k.contains("time") && !k.contains("_ms") && !k.contains("_us"));
    }
    assert!(doc["dofs"].as_array().is_some_and(|d| d.len() == 1000));
    doc["dofs"].to_string()
}

#[test]
fn two_threads_give_the_bits_of_one() {
    assert_eq!(solve_json("1"), solve_json("2"));
}
