//! `src/stability/` is arranged by method (issue 32): each file or folder directly under it is
//! a room (`integrated/`, `exponential/`, `shooting/`, `large/`, `choice/`, the shared files),
//! and the rooms' imports form no circle, so each can be read knowing only the ones it uses.
//!
//! A reference from a room counts as an edge to another when it names it by
//! `crate::stability::X` (or `super::X` from a file directly under `stability/`), `X` a room
//! or an item the module root re-exports from one (`pub use room::…::Item`). Comments and
//! strings do not count.

use super::code_shape::{code_of, rust_files};
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Room → the rooms it uses.
type Graph = BTreeMap<String, BTreeSet<String>>;

/// The first names after each `prefix` in `code`: `a` of `prefix a::b`, and `a`, `c` of
/// `prefix {a::b, c as d}` (a use group, nested groups skipped).
fn first_names(code: &str, prefix: &str) -> Vec<String> {
    let ident = |s: &str| -> String {
        s.trim_start()
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    let mut names = Vec::new();
    let mut rest = code;
    while let Some(at) = rest.find(prefix) {
        let before = rest[..at].chars().last();
        rest = &rest[at + prefix.len()..];
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
            continue;
        }
        let Some(group) = rest.trim_start().strip_prefix('{') else {
            names.push(ident(rest));
            continue;
        };
        let (mut depth, mut part) = (0, String::new());
        for c in group.chars() {
            match c {
                '{' => depth += 1,
                '}' if depth == 0 => break,
                '}' => depth -= 1,
                ',' if depth == 0 => names.push(ident(&std::mem::take(&mut part))),
                _ if depth == 0 => part.push(c),
                _ => {}
            }
        }
        names.push(ident(&part));
    }
    names.retain(|n| !n.is_empty());
    names
}

/// Item name → room, from the root's `pub use room::…` and `pub(crate) use room::…` lines.
fn reexports(root_code: &str, rooms: &BTreeSet<String>) -> BTreeMap<String, String> {
    let mut out = BTreeMap::new();
    for statement in root_code.split(';') {
        let s = statement.trim();
        let Some(path) = s
            .strip_prefix("pub use ")
            .or(s.strip_prefix("pub(crate) use "))
        else {
            continue;
        };
        let room: String = path.chars().take_while(|c| *c != ':').collect();
        if !rooms.contains(&room) {
            continue;
        }
        let items = path.rsplit_once("::").map_or(path, |(_, tail)| tail);
        for item in items.trim_matches(|c| c == '{' || c == '}').split(',') {
            let name = item.split(" as ").last().unwrap_or("").trim();
            out.insert(name.to_string(), room.clone());
        }
    }
    out
}

/// The room graph of the module at `dir`.
fn room_graph(dir: &Path) -> Graph {
    let code = |f: &Path| -> String {
        let text = std::fs::read_to_string(f).unwrap();
        text.lines().map(code_of).collect::<Vec<_>>().join("\n")
    };
    let room_of = |f: &Path| -> String {
        let rel = f.strip_prefix(dir).unwrap();
        let first = rel
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_string_lossy();
        first.trim_end_matches(".rs").to_string()
    };
    let files: Vec<_> = rust_files(dir)
        .into_iter()
        .filter(|f| f != &dir.join("mod.rs"))
        .collect();
    let rooms: BTreeSet<String> = files.iter().map(|f| room_of(f)).collect();
    let exported = reexports(&code(&dir.join("mod.rs")), &rooms);
    let mut graph: Graph = rooms.iter().map(|r| (r.clone(), BTreeSet::new())).collect();
    for f in &files {
        let (room, text) = (room_of(f), code(f));
        let mut names = first_names(&text, "crate::stability::");
        if f.parent() == Some(dir) {
            names.extend(first_names(&text, "super::"));
        }
        for name in names {
            let target = if rooms.contains(&name) {
                Some(name)
            } else {
                exported.get(&name).cloned()
            };
            if let Some(t) = target.filter(|t| *t != room) {
                graph.get_mut(&room).unwrap().insert(t);
            }
        }
    }
    graph
}

/// A circle of `graph` (its rooms in order), if it has one.
fn circle(graph: &Graph) -> Option<Vec<String>> {
    fn visit(g: &Graph, n: &str, path: &mut Vec<String>, done: &mut BTreeSet<String>) -> bool {
        if let Some(at) = path.iter().position(|p| p == n) {
            path.drain(..at);
            return true;
        }
        if done.contains(n) {
            return false;
        }
        path.push(n.to_string());
        for next in &g[n] {
            if visit(g, next, path, done) {
                return true;
            }
        }
        path.pop();
        done.insert(n.to_string());
        false
    }
    let mut done = BTreeSet::new();
    for n in graph.keys() {
        let mut path = Vec::new();
        if visit(graph, n, &mut path, &mut done) {
            return Some(path);
        }
    }
    None
}

#[test]
fn the_rooms_of_stability_use_each_other_without_a_circle() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/stability");
    let graph = room_graph(&dir);
    let uses = |a: &str, b: &str| graph[a].contains(b);
    // The scanner sees the real edges (direct, grouped, and through the root's re-exports).
    assert!(
        uses("choice", "shooting") && uses("choice", "large"),
        "{graph:?}"
    );
    assert!(uses("shooting", "exponential") && uses("exponential", "integrated"));
    assert!(uses("shooting", "multipliers") && uses("large", "hb_state"));
    // The shared ground uses no room with a method in it.
    for shared in [
        "multipliers",
        "options",
        "system",
        "neutral",
        "scales",
        "hb_state",
    ] {
        let methods = ["integrated", "exponential", "shooting", "large", "choice"];
        assert!(
            methods.iter().all(|m| !uses(shared, m)),
            "{shared}: {:?}",
            graph[shared]
        );
    }
    assert_eq!(circle(&graph), None, "{graph:#?}");
}

#[test]
fn the_scanner_finds_groups_reexports_and_circles() {
    let code = "use crate::stability::{a::B, c as d, e::{F, G}};\nlet x = super::h::i();";
    assert_eq!(first_names(code, "crate::stability::"), ["a", "c", "e"]);
    assert_eq!(first_names(code, "super::"), ["h"]);
    let rooms: BTreeSet<String> = ["r".to_string()].into();
    let root = "pub use r::x::{Y, Z as W};\npub(crate) use q::V;";
    let exported = reexports(root, &rooms);
    assert_eq!(exported.get("W").map(String::as_str), Some("r"));
    assert_eq!(exported.get("Y").map(String::as_str), Some("r"));
    assert!(!exported.contains_key("V"));
    let mut g: Graph = BTreeMap::new();
    g.insert("a".into(), ["b".to_string()].into());
    g.insert("b".into(), ["c".to_string()].into());
    g.insert("c".into(), BTreeSet::new());
    assert_eq!(circle(&g), None);
    g.get_mut("c").unwrap().insert("a".into());
    assert_eq!(circle(&g).unwrap().len(), 3);
}
