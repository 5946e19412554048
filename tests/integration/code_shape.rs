//! The command line stays a thin shell over the library (issue 32): no function under
//! src/cli (or src/main.rs) is longer than 100 lines. Numerics, checks and orchestration
//! belong in `hbal::analysis`; a long function there is the sign of work that moved back.

use std::path::{Path, PathBuf};

/// Most lines of one function under src/cli.
const MAX_LINES: usize = 100;

/// The `.rs` files under `dir`, recursively.
pub(super) fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            out.extend(rust_files(&path));
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
    out
}

/// `line` with string and char literals and a trailing `//` comment blanked out, so that the
/// braces left are the code's (format strings' `{}` and `'{'` do not count). Raw strings
/// spanning lines are not handled: src/cli has none.
pub(super) fn code_of(line: &str) -> String {
    let chars: Vec<char> = line.chars().collect();
    let (mut out, mut i) = (String::new(), 0);
    while i < chars.len() {
        match chars[i] {
            '/' if chars.get(i + 1) == Some(&'/') => break,
            '"' => {
                i += 1;
                while i < chars.len() && chars[i] != '"' {
                    i += if chars[i] == '\\' { 2 } else { 1 };
                }
            }
            // A char literal (`'{'`, `'\n'`), not a lifetime (`'a`).
            '\'' if chars.get(i + 2) == Some(&'\'') => i += 2,
            '\'' if chars.get(i + 1) == Some(&'\\') => {
                while i + 1 < chars.len() && chars[i + 1] != '\'' {
                    i += 1;
                }
                i += 1;
            }
            c => out.push(c),
        }
        i += 1;
    }
    out
}

/// Every function of `text` longer than [`MAX_LINES`]: its name and length.
fn long_functions(text: &str) -> Vec<(String, usize)> {
    let lines: Vec<String> = text.lines().map(code_of).collect();
    let mut long = Vec::new();
    let mut i = 0;
    while i < lines.len() {
        let words: Vec<&str> = lines[i].split_whitespace().collect();
        let Some(at) = words.iter().position(|w| *w == "fn") else {
            i += 1;
            continue;
        };
        let name = words
            .get(at + 1)
            .map_or("?", |w| w.split(['(', '<']).next().unwrap_or("?"));
        let (mut depth, mut opened, mut end) = (0i64, false, i);
        for (j, line) in lines.iter().enumerate().skip(i) {
            for c in line.chars() {
                match c {
                    '{' => (depth, opened) = (depth + 1, true),
                    '}' => depth -= 1,
                    _ => {}
                }
            }
            end = j;
            if (opened && depth == 0) || (!opened && line.trim_end().ends_with(';')) {
                break;
            }
        }
        if end + 1 - i > MAX_LINES {
            long.push((name.to_string(), end + 1 - i));
        }
        i = if opened { end + 1 } else { i + 1 };
    }
    long
}

#[test]
fn no_function_of_the_command_line_is_longer_than_100_lines() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = rust_files(&root.join("src/cli"));
    files.push(root.join("src/main.rs"));
    assert!(files.len() >= 20, "{files:?}");
    let long: Vec<String> = files
        .iter()
        .flat_map(|f| {
            let text = std::fs::read_to_string(f).unwrap();
            long_functions(&text)
                .into_iter()
                .map(move |(name, n)| format!("{}: {name} ({n} lines)", f.display()))
        })
        .collect();
    assert!(
        long.is_empty(),
        "functions over {MAX_LINES} lines:\n{}",
        long.join("\n")
    );
}

#[test]
fn the_scanner_measures_functions() {
    let text = "fn short() {\n    let s = \"}}}\";\n}\nfn long() {\n".to_string()
        + &"    let c = '{';\n".repeat(101)
        + "}\n";
    assert_eq!(long_functions(&text), vec![("long".to_string(), 103)]);
}
