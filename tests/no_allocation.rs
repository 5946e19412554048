//! The solver loops do not allocate: a solve of 40 iterations makes exactly as many heap
//! allocations as one of 2 (solver buffers, argmin's executor and the returned Solution are
//! allocated once per solve). Counted with a global allocator, in a test binary of its own.

use hbal::catalog::TwoShaft;
use hbal::{FixedPoint, HarmonicBalance, HarmonicBasis};
use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

struct Counting;

thread_local! {
    /// Allocations made by this thread (the test harness allocates on other threads).
    static ALLOCATIONS: Cell<usize> = const { Cell::new(0) };
}

fn allocations() -> usize {
    ALLOCATIONS.with(|c| c.get())
}

fn count_one() {
    // `try_with`: the thread-local may be gone while a thread shuts down.
    let _ = ALLOCATIONS.try_with(|c| c.set(c.get() + 1));
}

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        count_one();
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        count_one();
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn fixed_point_iterations_do_not_allocate() {
    let case = TwoShaft::new(60000.0);
    let model = case.model().unwrap();
    let basis = HarmonicBasis::new(case.mesh_omega(), 32)
        .unwrap()
        .with_tail_correction(true);
    let hb = HarmonicBalance::new(&model, basis).unwrap();
    let mut ws = hb.workspace();
    let count = |iterations: usize, ws: &mut hbal::Workspace| {
        let solver = FixedPoint::new()
            .with_tolerance(0.0)
            .unwrap()
            .with_max_iterations(iterations);
        let before = allocations();
        let sol = solver.solve(&hb, ws).unwrap();
        let after = allocations();
        assert_eq!(sol.stats.iterations, iterations);
        // Three FFTs per evaluation, four more for the tail correction of the mesh (its
        // damping is proportional to its stiffness: one synthesis and one analysis a stage).
        assert!(hb.tail_corrected());
        assert_eq!(sol.stats.ffts, 7 * (iterations + 1));
        after - before
    };
    let few = count(2, &mut ws);
    let many = count(40, &mut ws);
    assert_eq!(few, many, "allocations grow with the iteration count");
    assert!(few <= 16, "{few} allocations per solve");
}

/// Anderson and Newton: allocations per solve do not depend on the number of iterations
/// (Newton reuses one Jacobian buffer for the matrix and its LU factors).
#[test]
fn anderson_and_newton_iterations_do_not_allocate() {
    let model = hbal::catalog::GearBacklash::default().model().unwrap();
    let hb = HarmonicBalance::new(&model, HarmonicBasis::new(0.7, 16).unwrap()).unwrap();
    let mut ws = hb.workspace();
    let methods = |iterations: usize| {
        [
            hbal::Method::Anderson(
                hbal::Anderson::new()
                    .with_tolerance(0.0)
                    .unwrap()
                    .with_max_iterations(iterations),
            ),
            hbal::Method::Newton(
                hbal::Newton::new()
                    .with_tolerance(0.0)
                    .unwrap()
                    .with_max_iterations(iterations),
            ),
        ]
    };
    for (few, many) in methods(2).into_iter().zip(methods(8)) {
        let count = |m: hbal::Method, ws: &mut hbal::Workspace| {
            let before = allocations();
            let sol = m.solve(&hb, None, ws).unwrap();
            let after = allocations();
            (after - before, sol.stats.iterations)
        };
        // A first solve sets up the per-thread LU scratch (once per thread).
        let _ = few.solve(&hb, None, &mut ws);
        let (a_few, it_few) = count(few, &mut ws);
        let (a_many, it_many) = count(many, &mut ws);
        assert!(
            it_many > it_few,
            "{} ran {it_few} and {it_many} iterations",
            few.name()
        );
        assert_eq!(
            a_few,
            a_many,
            "{}: allocations grow with iterations",
            few.name()
        );
    }
}

/// The new laws and an element offset (whose batch calls shift the coordinate through a stack
/// buffer): Newton's allocations per solve do not depend on the number of iterations.
#[test]
fn new_laws_and_offsets_do_not_allocate_per_iteration() {
    use hbal::force::{
        Friction, GapContact, MeshProfile, Offset, PolynomialSpring, QuadraticDamper, Stage,
        StopSpring,
    };
    let contact = GapContact::with_profile(
        0.3,
        MeshProfile::Rectangular {
            one_tooth: 4.0,
            two_tooth: 6.0,
            contact_ratio: 1.4,
        },
    )
    .with_contact_damping(0.1);
    let model = hbal::Model::builder(&["a", "b"])
        .mass_diagonal(&[1.0, 2.0])
        .damping(hbal::nalgebra::DMatrix::from_diagonal_element(2, 2, 0.1))
        .stiffness(hbal::nalgebra::DMatrix::from_diagonal_element(2, 2, 1.0))
        .element("contact", &[("a", 1.0)], Offset::new(0.2, contact))
        .element(
            "stages",
            &[("a", 1.0), ("b", -1.0)],
            StopSpring::new(vec![
                Stage {
                    from: 0.1,
                    stiffness: 1.0,
                },
                Stage {
                    from: 0.4,
                    stiffness: 3.0,
                },
            ]),
        )
        .element("friction", &[("b", 1.0)], Friction::new(0.05, 0.2))
        .element("damper", &[("b", 1.0)], QuadraticDamper::new(0.1))
        .element(
            "poly",
            &[("b", 1.0)],
            Offset::new(-0.1, PolynomialSpring::new(vec![0.5, 0.2, 0.1])),
        )
        .load("a", 1, 0.8, 0.0)
        .build()
        .unwrap();
    let hb = HarmonicBalance::new(&model, HarmonicBasis::new(1.1, 16).unwrap()).unwrap();
    let mut ws = hb.workspace();
    let newton = |iterations: usize| {
        hbal::Method::Newton(
            hbal::Newton::new()
                .with_tolerance(0.0)
                .unwrap()
                .with_max_iterations(iterations),
        )
    };
    let _ = newton(2).solve(&hb, None, &mut ws);
    let mut count = |iterations: usize| {
        let before = allocations();
        let sol = newton(iterations).solve(&hb, None, &mut ws).unwrap();
        (allocations() - before, sol.stats.iterations)
    };
    let (few, it_few) = count(2);
    let (many, it_many) = count(8);
    assert!(it_many > it_few, "{it_few} and {it_many} iterations");
    assert_eq!(few, many, "allocations grow with iterations");
}

/// Laws with memory: the march over the period and its chained Jacobian use the workspace's
/// preallocated buffers; residual and Jacobian evaluations allocate nothing.
#[test]
fn memory_laws_do_not_allocate() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/scenes/nlvib_07_jenkins.toml"
    );
    let scene = hbal::scene::Scene::load(std::path::Path::new(path)).unwrap();
    let hb = HarmonicBalance::new(&scene.model, HarmonicBasis::new(1.2, 7).unwrap()).unwrap();
    let mut ws = hb.workspace();
    let m = hb.layout().len();
    let x: Vec<f64> = (0..m).map(|i| 0.3 / (1.0 + i as f64)).collect();
    let mut r = vec![0.0; m];
    let mut jac = hbal::nalgebra::DMatrix::zeros(m, m);
    hb.residual_real_into(&x, &mut r, Some(&mut jac), &mut ws)
        .unwrap();
    let before = allocations();
    for _ in 0..10 {
        hb.residual_real_into(&x, &mut r, Some(&mut jac), &mut ws)
            .unwrap();
        hb.residual_real_into(&x, &mut r, None, &mut ws).unwrap();
    }
    assert_eq!(allocations() - before, 0);
    // The march did run with slip (the Jacobian differs from the stuck linear part).
    assert!(r.iter().all(|v| v.is_finite()) && jac.amax() > 0.0);
}

/// The torus AFT loop does not allocate either: after one warm-up, the residual with the
/// Jacobian's samples and a Jacobian product of the two-stage drivetrain (three bases, a
/// 32 × 16 × 16 grid) make no heap allocation.
#[test]
fn torus_residual_and_jacobian_product_do_not_allocate() {
    use hbal::catalog::TwoStageTrain;
    use hbal::torus::{IndexSet, TorusBalance, Truncation};
    let model = TwoStageTrain::default().model().unwrap();
    let set = IndexSet::new(
        &TwoStageTrain::bases().unwrap(),
        &[8, 4, 4],
        Truncation::Box,
    )
    .unwrap();
    let tm = TwoStageTrain::bind(&model).unwrap();
    let hb = TorusBalance::new(tm, set, &[32, 16, 16], 300.0).unwrap();
    let mut ws = hb.workspace();
    let u = hb.linear_start();
    let mut r = vec![hbal::num_complex::Complex64::default(); hb.len()];
    let mut jv = r.clone();
    hb.residual_into(&u, &mut r, true, &mut ws).unwrap();
    hb.jacobian_apply(&u, &mut jv, &mut ws);
    let before = allocations();
    hb.residual_into(&u, &mut r, true, &mut ws).unwrap();
    hb.jacobian_apply(&u, &mut jv, &mut ws);
    assert_eq!(allocations() - before, 0);
}
