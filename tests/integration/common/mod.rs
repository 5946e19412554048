//! Shared helpers: the independently computed reference solutions in tests/data (copied from
//! ../shared/reference).

#![allow(dead_code)]

pub mod cli;
pub mod floquet;
pub mod galerkin;
pub mod hostile;
pub mod time_domain;

use num_complex::Complex64;

/// A reference periodic solution: harmonics 0..=32 and its fundamental.
pub struct Reference {
    pub omega: f64,
    pub harmonics: Vec<Complex64>,
    pub json: serde_json::Value,
}

pub fn reference(file: &str) -> Reference {
    let path = format!("{}/tests/data/{file}", env!("CARGO_MANIFEST_DIR"));
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap();
    let a = json["a"].as_array().unwrap();
    let b = json["b"].as_array().unwrap();
    let harmonics = a
        .iter()
        .zip(b)
        .map(|(a, b)| hbal::harmonic::from_cos_sin(a.as_f64().unwrap(), b.as_f64().unwrap()))
        .collect();
    Reference {
        omega: json["fundamental_angular_frequency"].as_f64().unwrap(),
        harmonics,
        json,
    }
}

/// Runs the `hbal` binary of this build with `args`.
pub fn hbal(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_hbal"))
        .args(args)
        .output()
        .expect("run hbal")
}
