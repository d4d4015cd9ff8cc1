//! The founding paper's Newmark allocates nothing in a step: its buffers and
//! inverses are made with it. Counted by a global allocator, on the test's
//! own thread only (its own binary, so that no other test's allocations
//! count).

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicUsize, Ordering};
use vibroimpact_core::methods::paper_newmark::PaperNewmark;
use vibroimpact_core::methods::steppers::SystemStepper;
use vibroimpact_core::model::assembly::{Mode, Scratch};
use vibroimpact_core::{Contact, ImpactDamper, LawKind, State};

struct Counting;

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

thread_local! {
    static COUNTING: Cell<bool> = const { Cell::new(false) };
}

// SAFETY: every call is passed on to the system allocator unchanged; the
// count is a side effect.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if COUNTING.with(Cell::get) {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        }
        System.alloc(layout)
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        System.dealloc(ptr, layout)
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, size: usize) -> *mut u8 {
        if COUNTING.with(Cell::get) {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        }
        System.realloc(ptr, layout, size)
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

#[test]
fn a_step_allocates_nothing() {
    common::timeout(30, || {
        // Steps apart and in contact with either wall, the contacts changing
        // (the inverse made again), restarts and steps of another length.
        let damper = ImpactDamper::new(1.0, 1.0, 0.01, 0.25, 0.005).unwrap();
        let contact = Contact::new(LawKind::HysterHertz, 3000.0, Some(0.9), 0.01).unwrap();
        let system = damper.assembly(&contact).unwrap();
        let mut stepper = PaperNewmark::new(&system, 0.25, 0.5).unwrap();
        let mut scratch = Scratch::new(&system);
        let y = State::new(1e-3, 0.02, 6e-3, 0.1)
            .unwrap()
            .vector(&system)
            .unwrap();
        let mut end = y.clone();
        let touching = Mode::Compliant {
            approach_rate: 0.1,
            indented_only: false,
        };
        let sets = [
            [Mode::Open, Mode::Open],
            [touching, Mode::Open],
            [Mode::Open, touching],
        ];
        COUNTING.with(|c| c.set(true));
        for step in 0..300 {
            let modes = &sets[step % 3];
            if step % 7 == 0 {
                stepper.reset();
            }
            if step % 5 == 0 {
                stepper.switched_within_step();
            }
            let h = if step % 11 == 0 { 5e-5 } else { 1e-4 };
            stepper
                .attempt(&system, 0.0, &y, h, modes, &mut scratch, &mut end)
                .unwrap();
            stepper.accept();
        }
        COUNTING.with(|c| c.set(false));
        assert_eq!(ALLOCATIONS.load(Ordering::Relaxed), 0);
        assert!(end.iter().all(|v| v.is_finite()));
    });
}
