pub mod ensemble;
pub mod lanes;
pub mod settling;
pub mod shooting;
pub mod study;
pub mod tangent;
