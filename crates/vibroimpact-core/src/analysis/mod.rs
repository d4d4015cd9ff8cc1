pub mod ensemble;
pub mod settling;
pub mod shooting;
pub mod study;
