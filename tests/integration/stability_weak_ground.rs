//! A soft ground spring far below the shafts' stiffness still restrains: the stability keeps
//! its multipliers (none is set aside as neutral) exactly where the harmonic balance treated
//! the motion as restrained, so a slowly diverging motion is labelled unstable.

use hbal::force::CubicSpring;
use hbal::{HarmonicBalance, HarmonicBasis, Model, Newton};

/// 12 unit inertias on shafts of 1e6 N m/rad (dampers `c`), a ground spring `kg` at the
/// first, a damper to ground of 0.5 at the last, a cubic shaft in the middle.
fn chain(kg: f64, c: f64) -> Model {
    let n = 12;
    let names: Vec<String> = (0..n).map(|i| format!("d{i}")).collect();
    let refs: Vec<&str> = names.iter().map(String::as_str).collect();
    let (mut k, mut d) = (Vec::new(), Vec::new());
    for i in 0..n - 1 {
        for (t, v) in [(&mut k, 1e6), (&mut d, c)] {
            t.extend([(i, i, v), (i + 1, i + 1, v), (i, i + 1, -v), (i + 1, i, -v)]);
        }
    }
    k.push((0, 0, kg));
    d.push((n - 1, n - 1, 0.5));
    Model::builder(&refs)
        .mass_diagonal(&vec![1.0; n])
        .stiffness_triplets(&k)
        .damping_triplets(&d)
        .element(
            "cubic",
            &[("d6", 1.0), ("d7", -1.0)],
            CubicSpring::new(0.0, 1e9),
        )
        .load("d11", 1, 10.0, 0.0)
        .build()
        .unwrap()
}

fn floquet(model: &Model, omega: f64) -> (hbal::stability::Floquet, bool) {
    let hb = HarmonicBalance::new(model, HarmonicBasis::new(omega, 5).unwrap()).unwrap();
    let sol = Newton::new().solve(&hb, &mut hb.workspace()).unwrap();
    let f = hbal::stability::FloquetOptions::default()
        .compute(model, &sol)
        .unwrap();
    (f, hb.rigid_modes().is_some())
}

#[test]
fn a_soft_negative_ground_spring_is_unstable_not_neutral() {
    let omega = 30.0;
    let period = std::f64::consts::TAU / omega;
    for kg in [-1e-2, -1e-3] {
        let (f, rigid) = floquet(&chain(kg, 10.0), omega);
        assert!(!rigid);
        assert_eq!(f.neutral, 0, "kg {kg}");
        // The whole line creeps away: m λ² + c λ + kg = 0 with m = 12, c = 0.5.
        let (m, c) = (12.0, 0.5);
        let lambda = (-c + (c * c - 4.0 * m * kg).sqrt()) / (2.0 * m);
        let want = (lambda * period).exp();
        assert!(!f.is_stable(), "kg {kg}: max |μ| {}", f.max_abs());
        assert!(
            (f.max_abs() - want).abs() < 1e-6,
            "kg {kg}: {} vs {want}",
            f.max_abs()
        );
    }
    // Restraining, it is the slowest decay; where the solve took the line as free (K0
    // singular to rounding), its multiplier 1 is neutral.
    let (f, rigid) = floquet(&chain(1e-3, 10.0), omega);
    assert!(!rigid && f.neutral == 0 && f.is_stable());
    let (f, rigid) = floquet(&chain(1e-6, 10.0), omega);
    assert!(rigid && f.neutral == 1 && f.is_stable());
}
