//! The families, one module each; every one builds an [`crate::engine::Script`] from its seed
//! and renders it.

pub(crate) mod dispensing;
