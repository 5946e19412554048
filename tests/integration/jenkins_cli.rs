//! The `jenkins` law from the command line: bad parameters exit 2 naming the element and the
//! field; `solve` and `sweep` report stability as not available (laws with memory), exit 0.

use crate::common;

use common::hbal;

const SCENE: &str = r#"
dofs = ["x"]
mass = [[1.0]]
stiffness = [[1.0]]
damping = [[0.05]]
fundamental = { rad_s = 1.5 }
harmonics = { count = 16 }
loads = [{ dof = "x", order = 1, cos = 1.0 }]

[[elements]]
name = "washer"
type = "jenkins"
connects = { x = 1.0 }
stiffness = 5.0
limit = LIMIT
"#;

fn write(name: &str, limit: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("hbal-jenkins-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, SCENE.replace("LIMIT", limit)).unwrap();
    path
}

#[test]
fn negative_or_non_finite_limit_exits_2_naming_element_and_field() {
    for (name, limit) in [
        ("negative.toml", "-1.0"),
        ("infinite.toml", "inf"),
        ("nan.toml", "nan"),
    ] {
        let path = write(name, limit);
        for cmd in ["check", "solve"] {
            let out = hbal(&[cmd, path.to_str().unwrap()]);
            let err = String::from_utf8_lossy(&out.stderr);
            assert_eq!(out.status.code(), Some(2), "{cmd} {name}: {err}");
            assert!(
                // A negative limit: the law's check (element name and field); a non-finite
                // number is refused while reading the file (element index and field).
                (err.contains("washer") && err.contains("`limit`"))
                    || err.contains("elements[0].limit: must be a finite number"),
                "{cmd} {name}: {err}"
            );
        }
    }
}

#[test]
fn solve_and_sweep_give_the_stability_of_laws_with_memory() {
    let path = write("good.toml", "0.5");
    let p = path.to_str().unwrap();
    let out = hbal(&["solve", p]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{text}");
    assert!(text.contains("stability: stable"), "{text}");
    let out = hbal(&["solve", p, "--json"]);
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(doc["converged"], true);
    assert_eq!(doc["stability"]["stable"], true, "{}", doc["stability"]);
    let out = hbal(&["sweep", p, "--from", "1.0", "--to", "2.0", "--json"]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let doc: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let points = doc["points"].as_array().unwrap();
    assert!(points.len() > 5);
    assert!(points
        .iter()
        .all(|p| p["stable"].is_boolean() && p["multipliers"].is_array()));
    let out = hbal(&["sweep", p, "--from", "1.0", "--to", "2.0", "--all-branches"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("laws with memory"));
}
