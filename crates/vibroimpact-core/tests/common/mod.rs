//! Shared by the integration tests: a per-test time limit (see
//! `vibroimpact_core::testing`). `mod common;` in a test file, then wrap each
//! test's body: `common::timeout(30, || { ... })`.

pub use vibroimpact_core::testing::timeout;
