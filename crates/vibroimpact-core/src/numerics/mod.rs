pub(crate) mod hermite;
pub mod linalg;
pub(crate) mod series;
