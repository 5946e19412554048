//! The exact solution of linear scenes with piecewise-constant coefficients
//! (`method = "piecewise_exact"`) against independent references: the shared exact piecewise
//! solution at 6000 rpm, the time domain at tight tolerance at 60 and 600 rpm and with contact
//! ratio 1.6, and harmonic balance where it converges.

use crate::common::reference;
use hbal::catalog::TwoShaft;
use hbal::compare::relative_error;
use hbal::solve::PiecewiseExact;
use hbal::timesim::TimeSimulation;
use hbal::HarmonicBasis;

/// The time-domain reference at rtol 1e-12, run until periodic to 1e-11, its harmonics from
/// 16384 samples a period: at 60 rpm the jumps ring at harmonic 771, and 4096 samples put an
/// error of 6.6e-7 into the harmonics 0..32 (2.4e-9 with 16384).
fn time_domain(model: &hbal::Model, omega: f64) -> Vec<num_complex::Complex64> {
    TimeSimulation {
        rtol: 1e-12,
        steady_tolerance: 1e-11,
        samples: 16384,
        ..TimeSimulation::default()
    }
    .run(model, omega)
    .unwrap()
    .harmonics
}

#[test]
fn the_two_shaft_model_at_6000_rpm_against_the_shared_reference() {
    let r = reference("seed_rect_6000rpm.json");
    let shaft = TwoShaft::new(6000.0);
    let basis = HarmonicBasis::new(shaft.mesh_omega(), 32).unwrap();
    let exact = PiecewiseExact::new()
        .solve_exact(&shaft.model().unwrap(), &basis)
        .unwrap();
    let err = relative_error(exact.solution.harmonics(), &r.harmonics, 1, 32);
    eprintln!("6000 rpm: {err:.2e}, estimate {:?}", exact.estimate);
    // The reference is good to about 1e-11.
    assert!(err < 1e-10, "{err:.2e}");
    // The rounding estimate (the periodicity solve's pivots in the scaled state) says the
    // harmonics are exact to rounding; the reference's own error (~1e-12) is above it.
    let kept = exact.estimate.kept_harmonics;
    assert!(kept < 1e-12, "{kept:.2e} against {err:.2e}");
    assert!(!exact.estimate.lower_bound);
    // What H = 32 lacks: the rectangular stiffness's spectrum decays like l^-3.
    assert!(
        exact.estimate.relative > 1e-5 && exact.estimate.relative < 1e-2,
        "{:?}",
        exact.estimate
    );
}

#[test]
fn low_speeds_and_jumps_between_samples_against_the_time_domain() {
    for (rpm, ratio) in [(60.0, 1.5), (600.0, 1.5), (6000.0, 1.6)] {
        let shaft = TwoShaft::new(rpm);
        let model = shaft.model_with_contact_ratio(ratio).unwrap();
        let td = time_domain(&model, shaft.mesh_omega());
        let basis = HarmonicBasis::new(shaft.mesh_omega(), 32).unwrap();
        let exact = PiecewiseExact::new().solve_exact(&model, &basis).unwrap();
        let err = relative_error(exact.solution.harmonics(), &td, 1, 32);
        eprintln!("{rpm} rpm, contact ratio {ratio}: {err:.2e}");
        assert!(err < 1e-8, "{rpm} rpm, contact ratio {ratio}: {err:.2e}");
        // What H = 32 lacks is reported, not hidden: at 60 rpm the ringing near harmonic 771
        // (the harmonics 33..64 alone hold 2.5 % of the RMS).
        let lacks = exact.estimate.relative;
        assert!(
            lacks > if rpm < 100.0 { 1e-2 } else { 1e-4 },
            "{rpm}: {lacks:.2e}"
        );
    }
}

/// `hbal` run on `args`, its exit code and its standard output and error.
pub(super) fn run(args: &[&str]) -> (Option<i32>, String, String) {
    let out = crate::common::hbal(args);
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

pub(super) fn scene(name: &str) -> String {
    format!("{}/examples/scenes/{name}", env!("CARGO_MANIFEST_DIR"))
}

#[test]
fn hbal_solve_and_compare_with_the_exact_method() {
    let low = scene("two_shaft_60rpm.toml");
    let (code, out, err) = run(&[
        "solve",
        &low,
        "--method",
        "piecewise_exact",
        "--json",
        "--no-stability",
    ]);
    assert_eq!(code, Some(0), "{err}");
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(json["method"], "piecewise_exact");
    let estimate = &json["error_estimate"];
    // Exact harmonics; what H = 32 lacks (the ringing near harmonic 771) is not hidden.
    assert!(
        estimate["kept_harmonics"].as_f64().unwrap() < 1e-12,
        "{estimate}"
    );
    assert!(estimate["relative"].as_f64().unwrap() > 1e-2, "{estimate}");
    assert!(
        estimate["reference_harmonics"].as_u64().unwrap() > 771,
        "{estimate}"
    );
    // Extremes from the closed form: max |q| 5.7589e-5 (the time domain's samples reach
    // 5.7588e-5; the harmonics 0..32 alone say 4.18e-5), the mesh carries L0 = 10 N m.
    assert!(
        json["extremes_from"]["closed_form"]["intervals"]
            .as_u64()
            .unwrap()
            > 10_000
    );
    let max = json["dofs"][0]["max_abs"].as_f64().unwrap();
    assert!((max - 5.7589e-5).abs() < 1e-9, "{max:e}");
    let mean = json["elements"][0]["force"]["mean"].as_f64().unwrap();
    assert!((mean - 10.0).abs() < 1e-9, "{}", json["elements"]);
    // --start is not used by the exact method, and says so.
    let start = std::env::temp_dir().join(format!("hbal-exact-start-{}.json", std::process::id()));
    std::fs::write(&start, &out).unwrap();
    let (code, _, err) = run(&[
        "solve",
        &low,
        "--method",
        "piecewise_exact",
        "--start",
        start.to_str().unwrap(),
        "--no-stability",
    ]);
    let _ = std::fs::remove_file(&start);
    assert_eq!(code, Some(0), "{err}");
    assert!(err.contains("is not used"), "{err}");
    // Harmonic balance at 60 rpm leaves the harmonics 0..32 6.6e-3 off: a note points to the
    // exact method; at 6000 rpm (8.3e-7) none.
    let (code, _, err) = run(&["solve", &low, "--no-stability"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(err.contains("`--method piecewise_exact`"), "{err}");
    let (code, _, err) = run(&["solve", &scene("two_shaft_6000rpm.toml"), "--no-stability"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(!err.contains("piecewise_exact"), "{err}");
    // compare: the exact method is one of the methods on a linear scene, and agrees with the
    // time domain far below harmonic balance at H = 32.
    let (code, out, err) = run(&["compare", &scene("two_shaft_600rpm.toml"), "--json"]);
    assert_eq!(code, Some(0), "{err}");
    let json: serde_json::Value = serde_json::from_str(&out).unwrap();
    let methods = json["methods"].as_array().unwrap();
    let error_of = |name: &str| {
        methods
            .iter()
            .find(|m| m["method"] == name)
            .and_then(|m| m["error_vs_time_domain"].as_f64())
            .unwrap_or_else(|| panic!("{name} missing: {out}"))
    };
    assert!(error_of("piecewise_exact") < 1e-8, "{out}");
    assert!(error_of("newton") > 1e-3, "{out}");
    // ... and left out on a nonlinear one, which still compares the others.
    let (code, out, err) = run(&["compare", &scene("duffing.toml"), "--json"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(
        !out.contains("piecewise_exact") && out.contains("newton"),
        "{out}"
    );
}

#[test]
fn the_exact_method_refuses_what_it_cannot_solve() {
    // A nonlinear law, by element.
    let (code, _, err) = run(&[
        "solve",
        &scene("duffing.toml"),
        "--method",
        "piecewise_exact",
    ]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("element `spring`") && err.contains("piecewise_exact"),
        "{err}"
    );
    // A scene that names the method with an iterative method's option, by field.
    let dir = std::env::temp_dir().join(format!("hbal-exact-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let text = std::fs::read_to_string(scene("two_shaft_60rpm.toml"))
        .unwrap()
        .replace("method = \"newton\"", "method = \"piecewise_exact\"");
    assert!(text.contains("piecewise_exact") && text.contains("tolerance = 1e-10"));
    let path = dir.join("two_shaft.toml");
    std::fs::write(&path, &text).unwrap();
    let (code, _, err) = run(&["solve", path.to_str().unwrap()]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("solver.tolerance") && err.contains("not used"),
        "{err}"
    );
    // Without it the scene runs.
    std::fs::write(&path, text.replace("tolerance = 1e-10\n", "")).unwrap();
    let (code, out, err) = run(&["solve", path.to_str().unwrap(), "--no-stability"]);
    assert_eq!(code, Some(0), "{err}");
    assert!(out.contains("piecewise_exact"), "{out}");
    // The same option on the command line, by option.
    let (code, _, err) = run(&["solve", path.to_str().unwrap(), "--tolerance", "1e-8"]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("--tolerance") && err.contains("piecewise_exact"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn automatic_harmonics_with_the_exact_method() {
    use hbal::solve::{solve_auto, AutoHarmonics, Control, Method};
    let r = reference("seed_rect_6000rpm.json");
    let shaft = TwoShaft::new(6000.0);
    let model = shaft.model().unwrap();
    let start = HarmonicBasis::new(shaft.mesh_omega(), 8).unwrap();
    let method = Method::PiecewiseExact(PiecewiseExact::new());
    // The harmonics 0..H are exact: the first level is enough.
    let auto = AutoHarmonics {
        control: Control::Harmonics,
        ..AutoHarmonics::default()
    };
    let a = solve_auto(&model, start, &method, auto).unwrap();
    assert_eq!(a.levels.len(), 1);
    assert!(a.estimate.kept_harmonics < 1e-9);
    // The periodic solution: H doubles until what it lacks is below 1e-6 (the rectangular
    // stiffness's harmonics decay like l^-3: H = 512, as harmonic balance needs).
    let a = solve_auto(&model, start, &method, AutoHarmonics::default()).unwrap();
    let hs: Vec<usize> = a.levels.iter().map(|l| l.harmonics).collect();
    assert_eq!(hs, [8, 16, 32, 64, 128, 256, 512], "{:?}", a.levels);
    assert!(!a.capped && a.estimate.relative <= 1e-6, "{:?}", a.estimate);
    let err = relative_error(a.solution.harmonics(), &r.harmonics, 1, 32);
    assert!(err < 1e-10, "{err:.2e}");
    // The exact solution of the chosen level comes along (its closed form, its multipliers):
    // nobody solves it again. Harmonic balance has none.
    let exact = a
        .exact
        .as_ref()
        .expect("the exact solution of the last level");
    assert_eq!(exact.solution.harmonics(), a.solution.harmonics());
    assert_eq!(exact.solution.basis().harmonics(), 512);
    let newton = Method::Newton(hbal::Newton::new());
    let hb = solve_auto(&model, start, &newton, AutoHarmonics::default()).unwrap();
    assert!(hb.exact.is_none());
}

/// The exact monodromy matrix's multipliers against the shared reference's moduli and the
/// Floquet analysis of the HB orbit (shooting on the exponential flow): two independent
/// computations of the same stability.
#[test]
fn floquet_multipliers_of_the_exact_monodromy_matrix() {
    use hbal::stability::floquet;
    use hbal::{HarmonicBalance, Newton};
    let r = reference("seed_rect_6000rpm.json");
    let expected: Vec<f64> = r.json["floquet_multipliers_abs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    for rpm in [600.0, 6000.0, 60000.0] {
        let shaft = TwoShaft::new(rpm);
        let model = shaft.model().unwrap();
        let basis = HarmonicBasis::new(shaft.mesh_omega(), 32).unwrap();
        let exact = PiecewiseExact::new().solve_exact(&model, &basis).unwrap();
        assert_eq!(exact.multipliers.len(), 2);
        if rpm == 6000.0 {
            for (got, want) in exact.multipliers.iter().zip(&expected) {
                assert!(
                    (got.norm() - want).abs() < 1e-9,
                    "|μ| {} vs {want}",
                    got.norm()
                );
            }
        }
        let hb = HarmonicBalance::new(&model, basis).unwrap();
        let sol = Newton::new().solve(&hb, &mut hb.workspace()).unwrap();
        let f = floquet(&model, &sol).unwrap();
        let d = crate::common::floquet::hausdorff(&f.multipliers, &exact.multipliers);
        let scale = exact.multipliers[0].norm();
        eprintln!("{rpm} rpm: |μ| {scale:.3e}, Floquet analysis {d:.1e} away");
        assert!(
            d <= 1e-10 * scale.max(1e-3),
            "{rpm} rpm: {d:.2e} of {scale:.2e}"
        );
    }
}

/// The extremes of the closed form against the time domain's samples (65536 a period, about
/// 85 per ringing period at 60 rpm): where the ringing of every jump lies above H = 32, the
/// harmonics' own extremes are far off (max |q| 27 % low at 60 rpm).
#[test]
fn exact_extremes_against_the_time_domain_where_the_harmonics_lack_the_ringing() {
    for rpm in [60.0, 600.0] {
        let shaft = TwoShaft::new(rpm);
        let model = shaft.model().unwrap();
        let basis = HarmonicBasis::new(shaft.mesh_omega(), 32).unwrap();
        let exact = PiecewiseExact::new().solve_exact(&model, &basis).unwrap();
        let x = exact.extremes();
        let td = TimeSimulation {
            rtol: 1e-12,
            steady_tolerance: 1e-11,
            samples: 65536,
            ..TimeSimulation::default()
        }
        .run(&model, shaft.mesh_omega())
        .unwrap();
        let q = &td.samples[0];
        let (lo, hi) = q
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
                (a.min(v), b.max(v))
            });
        let series = exact.solution.max_abs_all()[0];
        let (xlo, xhi) = x.dofs[0];
        eprintln!(
            "{rpm} rpm: exact [{xlo:.6e}, {xhi:.6e}], time domain [{lo:.6e}, {hi:.6e}], H = 32 series max {series:.6e}"
        );
        // Samples lie inside the exact range, and reach it to the sampling's resolution.
        assert!(hi <= xhi * (1.0 + 1e-9) && lo >= xlo * (1.0 - 1e-9));
        assert!((xhi - hi) < 5e-4 * xhi && (lo - xlo) < 5e-3 * xlo, "{rpm}");
        assert!(series < 0.9 * xhi, "{rpm}: {series:e}");
        let mean = x.elements[0].force_mean;
        assert!((mean - TwoShaft::L0).abs() < 1e-9 * TwoShaft::L0, "{mean}");
    }
}
