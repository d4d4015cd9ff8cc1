//! What a run shows an observer at its start, at each event and at its end:
//! the states either side of the event's jump and the modes either side of
//! its switches, with the rigid pairs the event's impulses acted on. The
//! tangent flow ([`crate::analysis::tangent`]) is made of these: the flow
//! between two events is smooth in one set of modes, and each event is a
//! reset map with its saltation. A run without an observer pays nothing.

use crate::error::Result;
use crate::model::assembly::Mode;

/// A rigid pair the event's impulses acted on (or held): its interaction
/// and the restitution the event gave it, the relative rate after being
/// `-restitution` times the one before (0: it stuck, or touched at rest).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Jump {
    pub interaction: usize,
    pub restitution: f64,
    /// Whether it struck: it arrived at a speed of its own and its impulse
    /// acted (the run records an impact), not a landing at rest, a pair
    /// held or one that starts to stick without an approach.
    pub struck: bool,
}

/// One event of a run.
#[derive(Debug, Clone, Copy)]
pub struct EventView<'a> {
    /// s.
    pub time: f64,
    /// The interaction whose event value was located (the others switched
    /// at the same instant).
    pub located: usize,
    /// The state (`x` then `v`, `2 dim` values) and modes before the event
    /// and after it.
    pub before: &'a [f64],
    pub after: &'a [f64],
    pub modes_before: &'a [Mode],
    pub modes_after: &'a [Mode],
    /// The rigid pairs the impulses acted on, in the order the event's
    /// complementarity problem took them; empty where no rigid pair did.
    pub jumps: &'a [Jump],
}

/// Told of a run's start, events and end.
pub trait EventObserver {
    /// The run starts at `time` (s) from state `y` (`x` then `v`) in `modes`.
    fn start(&mut self, time: f64, y: &[f64], modes: &[Mode]) -> Result<()>;
    /// An event: see [`EventView`].
    fn event(&mut self, view: &EventView<'_>) -> Result<()>;
    /// The run ends at `time` in state `y` and `modes`.
    fn finish(&mut self, time: f64, y: &[f64], modes: &[Mode]) -> Result<()>;
    /// Whether the observer is told of every step ([`Self::step`]); asked
    /// once, at the run's start. An observer that is not costs nothing per
    /// step.
    fn wants_steps(&self) -> bool {
        false
    }
    /// A step kept from `(t0, y0)` to `(t1, y1)` (`x` then `v`) in `modes`,
    /// the method's own (cut at an event it ends on, before the event's
    /// switches and jumps, which [`Self::event`] then shows).
    fn step(
        &mut self,
        _t0: f64,
        _y0: &[f64],
        _t1: f64,
        _y1: &[f64],
        _modes: &[Mode],
    ) -> Result<()> {
        Ok(())
    }
}

/// What a run keeps for its observer: the state and modes before the event
/// being handled, and the jumps of its impulses.
pub(crate) struct Watch<'o> {
    pub(crate) observer: &'o mut dyn EventObserver,
    /// The time and state at the start of the step being taken (where the
    /// observer wants steps).
    pub(crate) step_time: f64,
    pub(crate) step_start: Vec<f64>,
    pub(crate) before: Vec<f64>,
    pub(crate) modes_before: Vec<Mode>,
    pub(crate) jumps: Vec<Jump>,
}

impl<'o> Watch<'o> {
    pub(crate) fn new(observer: &'o mut dyn EventObserver, dim: usize, count: usize) -> Self {
        Self {
            observer,
            step_time: 0.0,
            step_start: vec![0.0; 2 * dim],
            before: vec![0.0; 2 * dim],
            modes_before: vec![Mode::Open; count],
            jumps: Vec::with_capacity(count),
        }
    }
}
