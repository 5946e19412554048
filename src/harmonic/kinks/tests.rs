//! Tests of the kink-aware quadrature against fine trapezoid sums and closed forms.
use super::*;

/// `f(θ) = |cos θ - 0.3|` has kinks at `θ = ±acos 0.3`: the corrected 64-sample AFT of
/// harmonics 0..=8 matches the exact coefficients (from 2^16 samples plus the same
/// correction) to 1.3e-7 (jumps of the third and higher derivatives are left out), the
/// plain one is off by 4.4e-4.
#[test]
fn corrected_trapezoid_of_a_kinked_function() {
    let f = |t: f64| (t.cos() - 0.3).abs();
    let t0 = 0.3f64.acos();
    // f' = -sin θ sgn(cos θ - 0.3) jumps up by 2 sin t0 at both kinks (a V); f'' = -cos θ
    // sgn(...) jumps by +2 cos t0 at t0 and by -2 cos t0 at 2π - t0.
    let crossings = [
        Crossing {
            theta: t0,
            alpha: 0.0,
            slope: -t0.sin(),
            jumps: [0.0, 2.0 * t0.sin(), 2.0 * t0.cos()],
            du_jumps: [0.0; 2],
            ddu_jumps: [0.0; 2],
        },
        Crossing {
            theta: TAU - t0,
            alpha: 0.0,
            slope: t0.sin(),
            jumps: [0.0, 2.0 * t0.sin(), -2.0 * t0.cos()],
            du_jumps: [0.0; 2],
            ddu_jumps: [0.0; 2],
        },
    ];
    let aft = |n: usize, correct: bool| {
        let h = TAU / n as f64;
        let crossings: Vec<Crossing> = crossings
            .iter()
            .map(|c| Crossing {
                alpha: (c.theta / h).fract(),
                ..*c
            })
            .collect();
        let mut x = vec![Complex64::default(); 9];
        for (k, xk) in x.iter_mut().enumerate() {
            let mut s = Complex64::default();
            for j in 0..n {
                let t = TAU * j as f64 / n as f64;
                s += f(t) * Complex64::from_polar(1.0, -(k as f64) * t);
            }
            *xk = s * if k == 0 { 1.0 } else { 2.0 } / n as f64;
        }
        if correct {
            correct_harmonics(&mut x, n, &crossings);
        }
        x
    };
    let exact = aft(1 << 16, true);
    let (plain, fixed) = (aft(64, false), aft(64, true));
    let err = |x: &[Complex64]| {
        x.iter()
            .zip(&exact)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max)
    };
    assert!(err(&plain) > 1e-5, "plain {}", err(&plain));
    assert!(err(&fixed) < 1e-6, "corrected {}", err(&fixed));
}

/// A sample exactly on the contact edge: `u = 1 + sin θ` against a backlash edge at 1
/// (sample 0 sits on it). Both crossings are found, and the corrected 256-sample harmonics
/// of the contact force (with contact damping: a force jump) match 2^14 samples to 1e-8
/// (measured 9.7e-10; the jumps of the third and higher derivatives are left out).
#[test]
fn crossing_on_a_sample_is_corrected() {
    use crate::force::{Backlash, MeshProfile};
    let law =
        Backlash::new(1.0, MeshProfile::Constant { stiffness: 3.0 }).with_contact_damping(0.2);
    let uk = [Complex64::new(1.0, 0.0), Complex64::new(0.0, -1.0)];
    let harmonics = |n: usize| {
        let thetas: Vec<f64> = (0..n).map(|j| TAU * j as f64 / n as f64).collect();
        let u: Vec<f64> = thetas.iter().map(|t| 1.0 + t.sin()).collect();
        let mut crossings = Vec::new();
        let du: Vec<f64> = thetas.iter().map(|t| t.cos()).collect();
        find_crossings(&law, &law.kinks(), &u, &du, &uk, 1.0, 1, &mut crossings);
        let mut x = vec![Complex64::default(); 9];
        for (k, xk) in x.iter_mut().enumerate() {
            let mut s = Complex64::default();
            for (j, t) in thetas.iter().enumerate() {
                s += law.force(*t, u[j], t.cos()) * Complex64::from_polar(1.0, -(k as f64) * t);
            }
            *xk = s * if k == 0 { 1.0 } else { 2.0 } / n as f64;
        }
        correct_harmonics(&mut x, n, &crossings);
        (x, crossings.len())
    };
    let (coarse, found) = harmonics(256);
    let (fine, _) = harmonics(1 << 14);
    assert_eq!(found, 2);
    let err = coarse
        .iter()
        .zip(&fine)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    assert!(err < 1e-8, "{err}");
}

/// Grazing: `u = 1e-5 + sin(θ - h/2)` touches the edge at 1 between two samples (its
/// peak is mid-interval, both crossings inside it, no sample beyond the edge). The two
/// crossings are found from the extremum, and the 256-sample harmonics of the tiny contact
/// force (about 6e-8, all of it missed without them) match 2^14 samples to 1e-11
/// (measured 1.3e-12).
#[test]
fn grazing_between_samples_is_corrected() {
    use crate::force::{Backlash, MeshProfile};
    let law = Backlash::new(1.0, MeshProfile::Constant { stiffness: 3.0 });
    let n0 = 256;
    let shift = 0.5 * TAU / n0 as f64;
    let excess = 1e-5;
    let uk = [
        Complex64::new(excess, 0.0),
        Complex64::new(0.0, -1.0) * Complex64::from_polar(1.0, -shift),
    ];
    let harmonics = |n: usize| {
        let thetas: Vec<f64> = (0..n).map(|j| TAU * j as f64 / n as f64).collect();
        let u: Vec<f64> = thetas.iter().map(|t| excess + (t - shift).sin()).collect();
        let du: Vec<f64> = thetas.iter().map(|t| (t - shift).cos()).collect();
        let mut crossings = Vec::new();
        find_crossings(&law, &law.kinks(), &u, &du, &uk, 1.0, 1, &mut crossings);
        let mut x = vec![Complex64::default(); 9];
        for (k, xk) in x.iter_mut().enumerate() {
            let mut s = Complex64::default();
            for (j, t) in thetas.iter().enumerate() {
                s += law.force(*t, u[j], du[j]) * Complex64::from_polar(1.0, -(k as f64) * t);
            }
            *xk = s * if k == 0 { 1.0 } else { 2.0 } / n as f64;
        }
        correct_harmonics(&mut x, n, &crossings);
        (x, crossings.len())
    };
    let (coarse, found) = harmonics(n0);
    let (fine, _) = harmonics(1 << 14);
    assert_eq!(found, 2, "both crossings inside one interval");
    assert!(fine[1].norm() > 1e-8, "{}", fine[1]);
    let err = coarse
        .iter()
        .zip(&fine)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    assert!(err < 1e-11, "{err}");
}

/// The range check that skips a kink, where the bound `h Σ k |u_k|` matters: on 18 samples,
/// `u = sin(6θ + π/6)` peaks at 1 midway between samples (which reach only 0.5) and bottoms
/// out on samples. Edges at ±0.999 are crossed 24 times (a scan of 2^16 samples agrees): the
/// peaks are 0.5 above every sample, more than `h Σ |u_k|` (0.35) but less than
/// `h Σ k |u_k|` (2.1), so a bound without the factor k would skip the upper edge and lose 12.
/// Edges at ±8 are beyond the bound and skipped (none). Ω = 2.5, so that `du` in time and
/// `u_θ` differ.
#[test]
fn kinks_out_of_reach_are_skipped_and_grazed_ones_are_not() {
    use crate::force::{Backlash, MeshProfile};
    let (n, order, omega) = (18, 6, 2.5);
    let h = TAU / n as f64;
    let phase = std::f64::consts::FRAC_PI_6;
    let mut uk = vec![Complex64::default(); order + 1];
    uk[order] = Complex64::from_polar(1.0, phase - std::f64::consts::FRAC_PI_2);
    let at = |t: f64| (order as f64 * t + phase).sin();
    let thetas: Vec<f64> = (0..n).map(|j| h * j as f64).collect();
    let u: Vec<f64> = thetas.iter().map(|&t| at(t)).collect();
    let du: Vec<f64> = thetas
        .iter()
        .map(|t| omega * order as f64 * (order as f64 * t + phase).cos())
        .collect();
    assert!(u.iter().all(|&x| x < 0.5 + 1e-12));
    let count = |edge: f64| {
        let law = Backlash::new(edge, MeshProfile::Constant { stiffness: 3.0 });
        let mut crossings = Vec::new();
        find_crossings(&law, &law.kinks(), &u, &du, &uk, omega, 1, &mut crossings);
        for c in &crossings {
            assert!(
                (at(c.theta).abs() - edge).abs() < 1e-12,
                "{edge}: at {}",
                c.theta
            );
        }
        crossings.len()
    };
    let fine = 1 << 16;
    let dense = (0..fine)
        .filter(|&j| {
            let (a, b) = (
                at(TAU * j as f64 / fine as f64),
                at(TAU * (j + 1) as f64 / fine as f64),
            );
            ((a - 0.999) > 0.0) != ((b - 0.999) > 0.0) || ((a + 0.999) > 0.0) != ((b + 0.999) > 0.0)
        })
        .count();
    assert_eq!(dense, 24);
    assert_eq!(count(0.999), 24);
    assert_eq!(count(8.0), 0);
}
