use hbal::catalog::TwoShaft;
use hbal::{FixedPoint, HarmonicBalance, HarmonicBasis};
fn main() {
    let ts = TwoShaft::new(60000.0);
    let model = ts.model().unwrap();
    let hb = HarmonicBalance::new(&model, HarmonicBasis::new(ts.mesh_omega(), 32).unwrap()).unwrap();
    let mut ws = hb.workspace();
    let s = FixedPoint::new().with_tolerance(0.0).unwrap().with_max_iterations(3);
    let t = std::time::Instant::now();
    let mut acc = 0.0;
    for _ in 0..200000 { acc += s.solve(&hb, &mut ws).unwrap().history[0]; }
    println!("{:?} {acc}", t.elapsed() / 200000);
}
