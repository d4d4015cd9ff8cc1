pub mod exact;
pub mod paper_newmark;
pub mod registry;
pub mod step_control;
pub mod steppers;
pub mod tableau;
pub mod trapezoid;
