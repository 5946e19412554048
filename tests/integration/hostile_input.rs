//! The hostile inputs of issue 13, each with the message and exit code it must give now: memory
//! bombs refused before any allocation, meaningless fields refused with their field path (the
//! non-finite values are in `hostile_non_finite`).

use crate::common::hostile;

use hostile::{judge, run_limited, write, Run};
use std::path::{Path, PathBuf};

pub(crate) fn example(name: &str) -> String {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/scenes")
        .join(name);
    std::fs::read_to_string(p).expect("example scene")
}

/// A directory of this test's own (tests run in parallel threads named after them).
pub(crate) fn temp_dir() -> PathBuf {
    let test = std::thread::current()
        .name()
        .unwrap_or("main")
        .replace("::", "-");
    std::env::temp_dir().join(format!("hbal-hostile-input-{}-{test}", std::process::id()))
}

/// `example` with `from` replaced by `to` (which must change it).
pub(crate) fn edited(example_name: &str, from: &str, to: &str) -> String {
    let text = example(example_name);
    assert!(text.contains(from), "{example_name} lacks `{from}`");
    text.replace(from, to)
}

/// Runs `hbal args` (with `{}` replaced by the scene written as `name`) and checks the exit
/// code and that stderr names the file and says `message`.
pub(crate) fn expect(name: &str, scene: &str, args: &[&str], code: i32, message: &str) -> Run {
    let file = write(&temp_dir(), name, scene);
    let args: Vec<&str> = args
        .iter()
        .map(|a| if *a == "{}" { file.as_str() } else { a })
        .collect();
    let run = run_limited(&args);
    assert_eq!(run.code, Some(code), "{name}: {args:?}: {}", run.stderr);
    assert!(
        run.stderr.contains(message),
        "{name}: `{}` lacks `{message}`",
        run.stderr
    );
    if code == 2 && !args.iter().any(|a| a.starts_with("--")) {
        assert!(run.stderr.contains(name), "{name}: {}", run.stderr);
    }
    judge(&run, args.contains(&"--json")).unwrap_or_else(|(b, w)| panic!("{name}: {b:?}: {w}"));
    run
}

const TEETH: &str =
    "elements[0].teeth: gear stage `mesh`: parameter `teeth` must be an integer in 1..=65536";

#[test]
fn memory_bombs_are_refused_before_any_allocation() {
    let pair = "two_shaft_gear_pair.toml";
    let bomb = edited(pair, "teeth = 20", "teeth = 4000000000");
    for cmd in ["check", "solve"] {
        expect("teeth_4e9.toml", &bomb, &[cmd, "{}"], 2, TEETH);
    }
    // A static analysis (H = 0) skips the mesh-order check of the harmonics; its stability
    // once allocated 64 GB for the stiffness jumps.
    let static_bomb = bomb.replace("count = 64", "count = 0").replace(
        "  { dof = \"pinion\", order = 1, cos = 2.0, sin = 0.5 },\n",
        "",
    );
    expect(
        "teeth_static.toml",
        &static_bomb,
        &["solve", "--json", "{}"],
        2,
        TEETH,
    );
    let slow = edited(pair, "teeth = 20", "teeth = 1000000000");
    let run = expect("teeth_1e9.toml", &slow, &["check", "{}"], 2, TEETH);
    assert!(run.seconds < 10.0, "{} s", run.seconds);
    let backlash = edited(
        "gear_backlash.toml",
        "stiffness = { shape = \"cosine\", mean = 1.0, amplitude = 0.2 }",
        "teeth = 4000000000\nstiffness = { shape = \"rectangular\", one_tooth = 1.0, two_tooth = 2.0, contact_ratio = 1.5 }",
    );
    expect(
        "backlash_teeth.toml",
        &backlash,
        &["check", "{}"],
        2,
        "elements[0].teeth: element `contact`: parameter `teeth` must be an integer in 1..=65536",
    );
    let iterations = edited(
        "gear_backlash.toml",
        "[solver]",
        "[solver]\nmax_iterations = 1000000000000",
    );
    expect(
        "iterations.toml",
        &iterations,
        &["solve", "{}"],
        2,
        "solver.max_iterations: must be in 1..=1000000, got 1000000000000",
    );
    let dofs = "dofs = { count = 1000000000 }\nmass = { triplets = [[1, 1, 1.0]] }\n\
                fundamental = { rad_s = 1.0 }\nharmonics = { count = 1 }\n";
    expect(
        "dofs.toml",
        dofs,
        &["check", "{}"],
        2,
        "dofs.count: must be at most 1000000 (the largest model), got 1000000000",
    );
    let cylinders = "dofs = [\"crank\"]\nmass = [[1.0]]\nstiffness = [[1.0]]\n\
                     fundamental = { rpm = 3000 }\nharmonics = { count = 4 }\n[engine]\n\
                     dof = \"crank\"\ncylinders = 4000000000\norders = [{ order = 2.0, amplitude = 1.0 }]\n";
    expect(
        "cylinders.toml",
        cylinders,
        &["check", "{}"],
        2,
        "engine: `cylinders` must be at most 64, got 4000000000",
    );
    // 200 DOFs with H = 65536: 79 GiB of dynamic stiffness.
    let n = 200;
    let identity: Vec<String> = (0..n)
        .map(|i| {
            let row: Vec<&str> = (0..n).map(|j| if i == j { "1.0" } else { "0.0" }).collect();
            format!("[{}]", row.join(","))
        })
        .collect();
    let big = format!(
        "dofs = {{ count = {n} }}\nmass = [{0}]\nstiffness = [{0}]\nfundamental = {{ rad_s = 1.3 }}\n\
         harmonics = {{ count = 65536 }}\nloads = [{{ dof = \"dof.1\", order = 1, cos = 1.0 }}]\n",
        identity.join(",")
    );
    expect(
        "big.toml",
        &big,
        &["check", "{}"],
        2,
        "the harmonic-balance system (200 DOFs, H = 65536, N = 524288, full formulation) needs \
         about 79.3 GiB, more than the limit of 4 GiB: use fewer harmonics or samples",
    );
    let duffing = example("duffing.toml");
    expect(
        "points.toml",
        &duffing,
        &["sweep", "{}", "--to", "2", "--max-points", "10000000"],
        2,
        "10000000 is not in 1..=100000",
    );
    expect(
        "points.toml",
        &duffing,
        &[
            "sweep",
            "{}",
            "--parameter",
            "loads[0].cos",
            "--from",
            "0",
            "--to",
            "1",
            "--points",
            "10000000",
        ],
        2,
        "10000000 is not in 2..=100000",
    );
    let _ = std::fs::remove_dir_all(temp_dir());
}

#[test]
fn meaningless_fields_are_refused_with_their_path() {
    let backlash = "gear_backlash.toml";
    let range = "must be 0 or between 1e-100 and 1e100 in magnitude";
    let cases = [
        (
            "load_1e308.toml",
            edited(backlash, "cos = 0.05", "cos = 1e308"),
            format!("loads[1].cos: {range}, got 1e308"),
        ),
        (
            "speed_1e-320.toml",
            edited("two_shaft_gear_pair.toml", "rpm = 3000", "rpm = 1e-320"),
            format!("fundamental.rpm: {range}, got 1e-320"),
        ),
        (
            "mass_1e308.toml",
            edited(backlash, "mass = [[1.0]]", "mass = [[1e308]]"),
            format!("mass[0][0]: {range}, got 1e308"),
        ),
        (
            "mass_subnormal.toml",
            edited(backlash, "mass = [[1.0]]", "mass = [[1e-320]]"),
            format!("mass[0][0]: {range}, got 1e-320"),
        ),
        (
            "tolerance_0.toml",
            edited(backlash, "[solver]", "[solver]\ntolerance = 0.0"),
            "solver.tolerance: must be in [1e-15, 1) (the relative residual stops at rounding, \
             about 1e-16), got 0"
                .into(),
        ),
        (
            "iterations_0.toml",
            edited(backlash, "[solver]", "[solver]\nmax_iterations = 0"),
            "solver.max_iterations: must be in 1..=1000000, got 0".into(),
        ),
        (
            "static_sin.toml",
            edited(
                backlash,
                "order = 0, cos = 0.1 }",
                "order = 0, cos = 0.1, sin = 3.0 }",
            ),
            "loads[0].sin: must be 0 on a static load (order 0, where sin(0 Ωt) = 0), got 3: \
             give the static load in `cos`"
                .into(),
        ),
        (
            "negative_mesh.toml",
            edited(backlash, "amplitude = 0.2", "amplitude = 2.0"),
            "elements[0].stiffness.amplitude: element `contact`: parameter `amplitude` must be at \
             most the mean 1 in magnitude"
                .into(),
        ),
        (
            "fourier_dip.toml",
            edited(
                backlash,
                "{ shape = \"cosine\", mean = 1.0, amplitude = 0.2 }",
                "{ shape = \"fourier\", mean = 1.0, cos = [0.0, 1.2] }",
            ),
            "elements[0]: element `contact`: the Fourier stiffness profile falls to -2.000000e-1 at φ = 1.5708 rad".into(),
        ),
        (
            "duplicate_dofs.toml",
            edited(
                "two_shaft_gear_pair.toml",
                "dofs = [\"pinion\", \"gear\"]",
                "dofs = [\"pinion\", \"pinion\"]",
            ),
            "dofs[1]: DOF `pinion` appears twice (first at dofs[0]): names are unique".into(),
        ),
        (
            "zero_weights.toml",
            edited(
                "duffing.toml",
                "connects = { x = 1.0 }",
                "connects = { x = 0.0 }",
            ),
            "elements[0].connects: needs a DOF with a nonzero weight".into(),
        ),
    ];
    for (name, scene, message) in &cases {
        expect(name, scene, &["check", "{}"], 2, message);
    }
    let duffing = example("duffing.toml");
    expect(
        "duffing.toml",
        &duffing,
        &["solve", "{}", "--tolerance", "0"],
        2,
        "--tolerance must be in [1e-15, 1)",
    );
    // A negative value is a value, not an unknown option: the sweep's own check answers.
    expect(
        "duffing.toml",
        &duffing,
        &["sweep", "{}", "--to", "-1"],
        2,
        "--to must be a finite speed > 0 (rad_s) whose fundamental is within 1e-100 to 1e100 rad/s, got -1",
    );
    // A whole-number field takes whole values ...
    let count_sweep = |points| {
        [
            "sweep",
            "{}",
            "--parameter",
            "harmonics.count",
            "--from",
            "5",
            "--to",
            "9",
            "--points",
            points,
        ]
    };
    let run = expect("duffing.toml", &duffing, &count_sweep("5"), 0, "");
    assert!(
        run.stdout
            .contains("5 values of harmonics.count from 5 to 9"),
        "{}",
        run.stdout
    );
    // ... and the others are refused before the sweep starts.
    expect(
        "duffing.toml",
        &duffing,
        &count_sweep("4"),
        2,
        "--parameter harmonics.count takes whole numbers, and value 2 (6.333333333333333) is not \
         one: choose --from, --to and --points so that every value is whole",
    );
    let _ = std::fs::remove_dir_all(temp_dir());
}
