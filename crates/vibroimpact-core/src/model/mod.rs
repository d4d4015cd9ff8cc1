pub mod assembly;
pub mod beam;
pub mod closed_forms;
pub mod contact;
pub mod impact_damper;
pub mod materials;
pub mod signals;
pub mod structure;
