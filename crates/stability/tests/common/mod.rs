//! Shared helpers of the integration tests.
pub mod random_models;
