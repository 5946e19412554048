//! The AFT transforms: round trip, Parseval, and exact harmonics of a cubic force.

use hbal::force::CubicSpring;
use hbal::harmonic::{from_cos_sin, AftPlan};
use hbal::{HarmonicBalance, HarmonicBasis, Model};
use num_complex::Complex64;

fn pseudo_random(n: usize, seed: u64) -> Vec<f64> {
    let mut s = seed;
    (0..n)
        .map(|_| {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        })
        .collect()
}

#[test]
fn round_trip_and_parseval() {
    for (h, n) in [(5, 11), (8, 17), (16, 64), (31, 100), (32, 256)] {
        let basis = HarmonicBasis::new(1.0, h).unwrap().with_samples(n).unwrap();
        let plan = AftPlan::new(basis);
        let mut s = plan.make_scratch();
        let r = pseudo_random(2 * h + 2, h as u64);
        let mut q: Vec<Complex64> = (0..=h)
            .map(|k| Complex64::new(r[2 * k], r[2 * k + 1]))
            .collect();
        q[0].im = 0.0;
        let mut x = vec![0.0; n];
        plan.synthesize_into(&q, |_| Complex64::new(1.0, 0.0), &mut x, &mut s);
        // Synthesis against the definition q(θ) = Re Σ Q_k e^{ikθ}.
        for (j, xj) in x.iter().enumerate() {
            let th = basis.theta(j);
            let direct: f64 = (0..=h)
                .map(|k| (q[k] * Complex64::from_polar(1.0, k as f64 * th)).re)
                .sum();
            assert!((xj - direct).abs() < 1e-13, "H {h} N {n} sample {j}");
        }
        // Parseval: mean of x² = |Q_0|² + ½ Σ |Q_k|².
        let mean_sq = x.iter().map(|v| v * v).sum::<f64>() / n as f64;
        let parseval = q[0].norm_sqr() + 0.5 * q[1..].iter().map(|v| v.norm_sqr()).sum::<f64>();
        assert!((mean_sq - parseval).abs() < 1e-14, "Parseval H {h} N {n}");
        let mut back = vec![Complex64::default(); h + 1];
        plan.analyze_into(&mut x, &mut back, &mut s);
        for k in 0..=h {
            assert!(
                (back[k] - q[k]).norm() < 1e-14,
                "round trip H {h} N {n} k {k}"
            );
        }
    }
}

/// Derivative synthesis: q̇ of a cos(kθ) + b sin(kθ) at Ω.
#[test]
fn derivative_synthesis() {
    let omega = 3.0;
    let basis = HarmonicBasis::new(omega, 4).unwrap();
    let plan = AftPlan::new(basis);
    let mut s = plan.make_scratch();
    let mut q = vec![Complex64::default(); 5];
    q[3] = from_cos_sin(0.4, -1.1);
    let mut x = vec![0.0; basis.samples()];
    plan.synthesize_into(
        &q,
        |k| Complex64::new(0.0, k as f64 * omega),
        &mut x,
        &mut s,
    );
    for (j, xj) in x.iter().enumerate() {
        let th = basis.theta(j);
        let exact = 3.0 * omega * (-0.4 * (3.0 * th).sin() - 1.1 * (3.0 * th).cos());
        assert!((xj - exact).abs() < 1e-13);
    }
}

/// For u = A cos θ, u³ = A³ (3 cos θ + cos 3θ) / 4 exactly; with the default N (>= 4H+1) the
/// AFT of the cubic rest α u³ has no aliasing.
#[test]
fn cubic_force_of_a_cosine_is_exact() {
    let (a, alpha) = (0.8, 2.5);
    let model = Model::builder(&["x"])
        .mass_diagonal(&[1.0])
        .element("duffing", &[("x", 1.0)], CubicSpring::new(1.0, alpha))
        .build()
        .unwrap();
    for h in [3usize, 4, 7] {
        let hb = HarmonicBalance::new(&model, HarmonicBasis::new(1.3, h).unwrap()).unwrap();
        let mut ws = hb.workspace();
        let mut q = vec![Complex64::default(); h + 1];
        q[1] = from_cos_sin(a, 0.0);
        let mut rest = vec![Complex64::default(); h + 1];
        hb.rest_into(&q, &mut rest, ws.aft_buffers()).unwrap();
        for (k, r) in rest.iter().enumerate() {
            let exact = match k {
                1 => 0.75 * alpha * a.powi(3),
                3 => 0.25 * alpha * a.powi(3),
                _ => 0.0,
            };
            assert!(
                (r.re - exact).abs() < 1e-14 && r.im.abs() < 1e-14,
                "H {h} k {k}: {r}"
            );
        }
    }
}
