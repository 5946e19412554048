//! The fixed-point loop does not allocate: a solve of 40 iterations makes exactly as many heap
//! allocations as one of 2 (the returned Solution and its preallocated history are the only
//! ones). Counted with a global allocator, in a test binary of its own.

use hbal::catalog::TwoShaft;
use hbal::{FixedPoint, HarmonicBalance, HarmonicBasis};
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

struct Counting;
static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn fixed_point_iterations_do_not_allocate() {
    let case = TwoShaft::new(60000.0);
    let model = case.model().unwrap();
    let hb =
        HarmonicBalance::new(&model, HarmonicBasis::new(case.mesh_omega(), 32).unwrap()).unwrap();
    let mut ws = hb.workspace();
    let count = |iterations: usize, ws: &mut hbal::Workspace| {
        let solver = FixedPoint::new()
            .with_tolerance(0.0)
            .unwrap()
            .with_max_iterations(iterations);
        let before = ALLOCATIONS.load(Ordering::Relaxed);
        let sol = solver.solve(&hb, ws).unwrap();
        let after = ALLOCATIONS.load(Ordering::Relaxed);
        assert_eq!(sol.stats.iterations, iterations);
        assert_eq!(sol.stats.ffts, 3 * (iterations + 1));
        after - before
    };
    let few = count(2, &mut ws);
    let many = count(40, &mut ws);
    assert_eq!(few, many, "allocations grow with the iteration count");
    assert!(few <= 4, "{few} allocations per solve");
}
