pub mod equations;
pub mod events;
pub mod integrators;
pub mod records;
pub mod run;
pub mod steppers;
