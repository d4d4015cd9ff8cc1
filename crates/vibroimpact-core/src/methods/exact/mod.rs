//! The exact flow of a linear system with rigid pairs (`method = "exact"`):
//! between impacts each normal mode is an oscillator under constant and
//! harmonic forcing, integrated in closed form, so a step of any length
//! lands on the solution to round-off and the event kernel's location of an
//! impact is limited by round-off alone.
//!
//! It is a [`SystemStepper`] for [`crate::kernel::events::integrate_system`]:
//! the kernel watches the gaps, locates impacts on this flow, applies the
//! impact map, sums chattering sequences and holds sticking pairs, whose
//! constrained system has its own modes (computed when first needed). Steps
//! are an eighth of the fastest period present, so that the kernel's cubic
//! check between step ends sees a gap dipping through zero and back within
//! one step (grazing). The energy accumulators (viscous loss, input work) are
//! integrated by 5-point Gauss-Legendre over each step, on the exact flow.
//!
//! Laid out by concern: `oscillator` (one mode in closed form),
//! `configurations` (the modes of each set of sticking and touching pairs,
//! made when first met), `flow` (the flow from a start: states and
//! accelerations), `energies` (the accumulators over a step), `stepper`
//! (the flow as a [`SystemStepper`]); [`modal`] and [`matrix_flow`] hold the
//! modes of classically and non-classically damped configurations,
//! `from_rest` the response from rest near a resonance.
//!
//! [`SystemStepper`]: crate::methods::steppers::SystemStepper

mod configurations;
mod energies;
mod flow;
mod from_rest;
pub mod matrix_flow;
pub mod modal;
mod oscillator;
mod stepper;
#[cfg(test)]
mod tests;

pub use flow::ExactFlow;
