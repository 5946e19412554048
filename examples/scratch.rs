use hbal::force::{MeshDamping, MeshProfile, MeshStiffness};
use hbal::{FixedPoint, HarmonicBalance, HarmonicBasis, Model};
fn main() {
    for g in [0.0,0.3,0.5,0.7,0.8,0.9,0.95] { let rpm = 6000.0;
    let omega_mesh = 4.0 * rpm * std::f64::consts::TAU / 60.0;
    let model = Model::builder(&["gear"])
        .mass_diagonal(&[1e-3])
        .element("mesh", &[("gear", 1.0)], MeshStiffness::new(1,
            MeshProfile::Rectangular { one_tooth: 2.5e5, two_tooth: 5e5, contact_ratio: 1.5 },
            MeshDamping::Proportional(5.1639777949e-6)))
        .load("gear", 0, 10.0, 0.0)
        .load("gear", 1, 1e-3 * 5e-4 * omega_mesh * omega_mesh, 0.0)
        .build().unwrap();
    let hb = HarmonicBalance::new(&model, HarmonicBasis::new(omega_mesh, 32).unwrap()).unwrap();
    let s = FixedPoint::new().with_gamma(g).unwrap().with_max_iterations(2000).solve(&hb, &mut hb.workspace()).unwrap();
    println!("{g} {:?} {} {:?} {:?}", s.termination, s.history.len(), s.history.last(), s.wall_time);
    println!("{:?}", &s.harmonics()[..4]);
    }
}
