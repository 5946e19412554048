//! Property-based test of hostile input (issue 13): the example scenes, mutated at random, never
//! make `hbal check`, `hbal solve --json`, `hbal solve --out` or one more subcommand chosen at
//! random (`sweep`, `sweep --parameter`, `modes`, `compare`, `report`; issue 32) panic, abort,
//! exceed the time and memory limits, print
//! a non-finite number (`null`), or give an exit code that contradicts its JSON (see
//! `common/hostile.rs` for the judgement).
//!
//! Each case takes one scene of `examples/scenes/` (TOML or JSON) and applies one to four
//! mutations: a number set to an extreme (0, negated, ±1e308, 1e-320, 1e±100, infinity, the
//! string "NaN", 4e9, `i64::MAX`, 0.5, scaled by 1e±6, or mildly by 10, 2, 0.5, 0.1), a field or
//! list entry dropped, a list
//! entry duplicated, or a string replaced. The default is a short run (8 cases, a few seconds);
//! `PROPTEST_CASES=N` sets the number of cases, and
//! `HOSTILE_SECONDS=600 PROPTEST_CASES=1000000 cargo test --release --test integration --
//! hostile_property --nocapture` is the long run: ten minutes (cases after the time budget are skipped), and the
//! summary line reports the cases, runs, exit codes and breaches.

use crate::common::hostile;

use hostile::{judge_document, run_limited, write, Breach, Document};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestCaseError, TestRunner};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// One step into a TOML document.
#[derive(Debug, Clone)]
enum Key {
    Field(String),
    Index(usize),
}

/// An extreme for a number.
#[derive(Debug, Clone, Copy)]
enum Extreme {
    Float(f64),
    Int(i64),
    Negate,
    Scale(f64),
    NanString,
}

const EXTREMES: [Extreme; 19] = [
    Extreme::Float(0.0),
    Extreme::Negate,
    Extreme::Float(1e308),
    Extreme::Float(-1e308),
    Extreme::Float(1e-320),
    Extreme::Float(1e100),
    Extreme::Float(1e-100),
    Extreme::Float(f64::INFINITY),
    Extreme::NanString,
    Extreme::Int(4_000_000_000),
    Extreme::Int(i64::MAX),
    Extreme::Int(-1),
    Extreme::Float(0.5),
    Extreme::Scale(1e6),
    Extreme::Scale(1e-6),
    // Mild changes, so that many cases solve: a wrong but sane scene.
    Extreme::Scale(10.0),
    Extreme::Scale(0.1),
    Extreme::Scale(2.0),
    Extreme::Scale(0.5),
];

/// A mutation; the selector picks its target among the candidates modulo their number.
#[derive(Debug, Clone)]
enum Mutation {
    Number(usize, Extreme),
    Drop(usize),
    Duplicate(usize),
    Text(usize, &'static str),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        6 => (any::<usize>(), 0..EXTREMES.len()).prop_map(|(s, e)| Mutation::Number(s, EXTREMES[e])),
        2 => any::<usize>().prop_map(Mutation::Drop),
        1 => any::<usize>().prop_map(Mutation::Duplicate),
        1 => (any::<usize>(), prop::sample::select(vec!["", "x", "gear", "NaN", "newton", "../up"]))
            .prop_map(|(s, t)| Mutation::Text(s, t)),
    ]
}

/// Every node below the root with its path, and whether its parent is a list.
fn nodes(v: &toml::Value, path: &mut Vec<Key>, out: &mut Vec<(Vec<Key>, toml::Value)>) {
    let children: Vec<(Key, &toml::Value)> = match v {
        toml::Value::Table(t) => t.iter().map(|(k, x)| (Key::Field(k.clone()), x)).collect(),
        toml::Value::Array(a) => a
            .iter()
            .enumerate()
            .map(|(i, x)| (Key::Index(i), x))
            .collect(),
        _ => return,
    };
    for (k, x) in children {
        path.push(k);
        out.push((path.clone(), x.clone()));
        nodes(x, path, out);
        path.pop();
    }
}

fn at<'a>(v: &'a mut toml::Value, path: &[Key]) -> Option<&'a mut toml::Value> {
    path.iter().try_fold(v, |cur, k| match (k, cur) {
        (Key::Field(f), toml::Value::Table(t)) => t.get_mut(f),
        (Key::Index(i), toml::Value::Array(a)) => a.get_mut(*i),
        _ => None,
    })
}

/// Applies `m` to `doc` (nothing if it has no target).
fn apply(doc: &mut toml::Value, m: &Mutation) {
    let mut all = Vec::new();
    nodes(doc, &mut Vec::new(), &mut all);
    let pick = |s: usize, keep: &dyn Fn(&Vec<Key>, &toml::Value) -> bool| {
        let c: Vec<&Vec<Key>> = all
            .iter()
            .filter(|(p, v)| keep(p, v))
            .map(|(p, _)| p)
            .collect();
        (!c.is_empty()).then(|| c[s % c.len()].clone())
    };
    let is_number = |_: &Vec<Key>, v: &toml::Value| v.is_float() || v.is_integer();
    match *m {
        Mutation::Number(s, e) => {
            let Some(p) = pick(s, &is_number) else { return };
            let Some(v) = at(doc, &p) else { return };
            let x = v
                .as_float()
                .or(v.as_integer().map(|i| i as f64))
                .unwrap_or(1.0);
            *v = match e {
                Extreme::Float(f) => toml::Value::Float(f),
                Extreme::Int(i) => toml::Value::Integer(i),
                Extreme::Negate => match v {
                    toml::Value::Integer(i) => toml::Value::Integer(i.saturating_neg()),
                    _ => toml::Value::Float(-x),
                },
                Extreme::Scale(f) => toml::Value::Float(x * f),
                Extreme::NanString => toml::Value::String("NaN".into()),
            };
        }
        Mutation::Drop(s) => {
            let Some(p) = pick(s, &|_, _| true) else {
                return;
            };
            let (last, parent) = p.split_last().expect("not the root");
            match (at(doc, parent), last) {
                (Some(toml::Value::Table(t)), Key::Field(f)) => {
                    t.remove(f);
                }
                (Some(toml::Value::Array(a)), Key::Index(i)) => {
                    a.remove(*i);
                }
                _ => {}
            }
        }
        Mutation::Duplicate(s) => {
            let in_list = |p: &Vec<Key>, _: &toml::Value| matches!(p.last(), Some(Key::Index(_)));
            let Some(p) = pick(s, &in_list) else { return };
            let (_, parent) = p.split_last().expect("not the root");
            let copy = at(doc, &p).cloned();
            if let (Some(toml::Value::Array(a)), Some(c)) = (at(doc, parent), copy) {
                a.push(c);
            }
        }
        Mutation::Text(s, t) => {
            let Some(p) = pick(s, &|_, v| v.is_str()) else {
                return;
            };
            if let Some(v) = at(doc, &p) {
                *v = toml::Value::String(t.into());
            }
        }
    }
}

/// The example scenes (not the large ones) with their documents.
fn scenes() -> Vec<(PathBuf, toml::Value)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes");
    let mut out: Vec<(PathBuf, toml::Value)> = std::fs::read_dir(&dir)
        .expect("examples/scenes")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter_map(|p| {
            let text = std::fs::read_to_string(&p).ok()?;
            let doc = match p.extension()?.to_str()? {
                "toml" => toml::from_str(&text).ok()?,
                "json" => {
                    toml::Value::try_from(serde_json::from_str::<serde_json::Value>(&text).ok()?)
                        .ok()?
                }
                _ => return None,
            };
            Some((p, doc))
        })
        .collect();
    out.sort_by(|a, b| a.0.cmp(&b.0));
    out
}

/// Counts over the whole run.
#[derive(Debug, Default)]
struct Tally {
    cases: usize,
    runs: usize,
    codes: BTreeMap<i32, usize>,
    breaches: BTreeMap<String, usize>,
    slowest: f64,
    slowest_case: String,
}

/// The speed of a scene in its unit (1 where it has none).
fn speed_of(doc: &toml::Value) -> f64 {
    let fundamental = doc.get("fundamental");
    ["rpm", "hz", "rad_s"]
        .iter()
        .find_map(|u| {
            fundamental
                .and_then(|f| f.get(*u))
                .and_then(|v| v.as_float().or(v.as_integer().map(|i| i as f64)))
        })
        .filter(|v| v.is_finite() && *v > 0.0)
        .unwrap_or(1.0)
}

/// The arguments of subcommand `which` on `file` (a short sweep to `to`, a parameter sweep of
/// the first load's cosine, the modes, the comparison, a report) and the document it prints.
fn other_command<'a>(
    which: &str,
    file: &'a str,
    to: &'a str,
    out: &'a str,
) -> (Vec<&'a str>, Document) {
    // Short: a mutated scene may make each point's stability take seconds (a law with memory
    // is shot on its time-domain model, up to 1e6 steps).
    let short = ["--max-points", "3"];
    match which {
        "sweep" => (
            [&["sweep", "--json", file, "--to", to][..], &short].concat(),
            Document::Sweep,
        ),
        "parameter" => (
            vec![
                "sweep",
                "--json",
                file,
                "--parameter",
                "loads[0].cos",
                "--from",
                "0",
                "--to",
                "1",
                "--points",
                "3",
            ],
            Document::Sweep,
        ),
        "modes" => (vec!["modes", "--json", file], Document::Modes),
        "compare" => (
            vec!["compare", "--json", file, "--method", "newton"],
            Document::Compare,
        ),
        _ => (
            // The run-up's stability is the sweep's (above): here the report's own parts.
            vec!["report", file, "--to", to, "--out", out, "--no-stability"],
            Document::None,
        ),
    }
}

#[test]
fn mutated_scenes_keep_the_exit_code_contract() {
    let scenes = scenes();
    assert!(scenes.len() >= 10, "{} example scenes", scenes.len());
    let dir = std::env::temp_dir().join(format!("hbal-hostile-{}", std::process::id()));
    // chain_mtx.toml reads its matrices relative to itself.
    let mtx = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/scenes/chain_mtx");
    for f in ["dofs.txt", "mass.mtx", "damping.mtx", "stiffness.mtx"] {
        std::fs::create_dir_all(dir.join("chain_mtx")).expect("temp dir");
        std::fs::copy(mtx.join(f), dir.join("chain_mtx").join(f)).expect("copy chain_mtx");
    }
    let cases = std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|c| c.parse().ok())
        .unwrap_or(8);
    let mut runner = TestRunner::new(Config {
        cases,
        failure_persistence: None,
        ..Config::default()
    });
    let methods = prop::sample::select(vec!["", "fixed_point", "newton", "broyden", "anderson"]);
    // One more subcommand per case, so that every one meets mutated scenes.
    let others = prop::sample::select(vec!["sweep", "parameter", "modes", "compare", "report"]);
    let strategy = (
        0..scenes.len(),
        prop::collection::vec(mutation(), 1..=4),
        methods,
        others,
    );
    // A time budget for the long run: later cases are skipped.
    let budget = std::env::var("HOSTILE_SECONDS")
        .ok()
        .and_then(|s| s.parse().ok())
        .map(std::time::Duration::from_secs_f64);
    let started = std::time::Instant::now();
    let tally = Mutex::new(Tally::default());
    let result = runner.run(&strategy, |(index, mutations, method, other)| {
        if budget.is_some_and(|b| started.elapsed() > b) {
            return Ok(());
        }
        let (path, doc) = &scenes[index];
        let mut doc = doc.clone();
        for m in &mutations {
            apply(&mut doc, m);
        }
        let json = path.extension().is_some_and(|e| e == "json");
        let text = if json {
            serde_json::to_string(&doc).ok()
        } else {
            toml::to_string(&doc).ok()
        };
        let Some(text) = text else {
            return Ok(()); // not writable as a scene (TOML's own rules)
        };
        let name = path
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or("scene.toml");
        let file = write(&dir, name, &text);
        let mut commands = vec![(vec!["check", file.as_str()], Document::None)];
        let mut solve = vec!["solve", "--json", file.as_str()];
        if !method.is_empty() {
            solve.extend(["--method", method]);
        }
        commands.push((solve, Document::Solve));
        // With --out: the CSV files and plots of whatever solved (a static or odd solution
        // must not turn into a plot error).
        let out_dir = dir.join("out");
        let out_dir = out_dir.to_str().unwrap_or("out");
        commands.push((
            vec!["solve", file.as_str(), "--out", out_dir],
            Document::None,
        ));
        let to = format!("{}", 1.05 * speed_of(&doc));
        commands.push(other_command(other, file.as_str(), &to, out_dir));
        let mut t = tally.lock().expect("tally");
        t.cases += 1;
        for (args, document) in commands {
            let run = run_limited(&args);
            t.runs += 1;
            *t.codes.entry(run.code.unwrap_or(-1)).or_default() += 1;
            if run.seconds > t.slowest {
                t.slowest = run.seconds;
                t.slowest_case = format!(
                    "hbal {} ({} with {mutations:?})",
                    args.join(" "),
                    path.display()
                );
            }
            if let Err((breach, what)) = judge_document(&run, document) {
                *t.breaches.entry(format!("{breach:?}")).or_default() += 1;
                return Err(TestCaseError::fail(format!(
                    "{breach:?}: hbal {} ({} with {mutations:?}): {what}\nscene:\n{text}",
                    args.join(" "),
                    path.display()
                )));
            }
        }
        Ok(())
    });
    let t = tally.into_inner().expect("tally");
    let count = |b: Breach| t.breaches.get(&format!("{b:?}")).copied().unwrap_or(0);
    eprintln!(
        "hostile_property: {} cases in {:.0} s, {} runs of hbal, exit codes {:?}, panics {}, aborts {}, \
         timeouts {}, non-finite outputs {}, inconsistent exit codes {}, slowest run {:.2} s \
         ({})",
        t.cases,
        started.elapsed().as_secs_f64(),
        t.runs,
        t.codes,
        count(Breach::Panic),
        count(Breach::Abort),
        count(Breach::Timeout),
        count(Breach::NonFinite),
        count(Breach::Inconsistent) + count(Breach::ExitCode),
        t.slowest,
        t.slowest_case
    );
    let _ = std::fs::remove_dir_all(&dir);
    if let Err(e) = result {
        panic!("{e}");
    }
}
