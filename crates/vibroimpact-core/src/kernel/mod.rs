pub(crate) mod balance;
pub(crate) mod compact;
pub(crate) mod contact_balance;
pub mod events;
pub(crate) mod impacts;
pub mod memory;
pub mod reductions;
pub(crate) mod sized;
