//! No heap allocation inside the time loop: a counting global allocator around 200 steps of
//! the c = 1, β = 45° pendulum (assembly, structured factorisation, solves, CRV rescaling,
//! projection) after the set-up.

use gebf::{Model, Options, samples};
use genalpha::{GenAlpha, IntegratorParams};
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
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn time_steps_do_not_allocate() {
    let (b, j, g) = samples::double_pendulum(1.0, 45.0, 5);
    let mut m = Model::new(&b, &j, g, Options { stabilization: true, ..Options::default() }).unwrap();
    let mut ga = GenAlpha::new(IntegratorParams::new(0.8, 0.002), &m).unwrap();
    let mut s = m.initial_state();
    ga.initialize(&m, &mut s).unwrap();
    ga.step(&mut m, &mut s).unwrap(); // first step: lazy set-up, if any
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    for _ in 0..200 {
        ga.step(&mut m, &mut s).unwrap();
        std::hint::black_box(m.tip_position(&s.q));
        std::hint::black_box(m.constraint_residual(&s.q));
    }
    let after = ALLOCATIONS.load(Ordering::Relaxed);
    assert_eq!(after - before, 0, "{} allocations in 200 steps", after - before);
}
