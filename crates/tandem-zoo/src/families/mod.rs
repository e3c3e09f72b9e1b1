//! The families, one module each; every one builds an [`crate::engine::Script`] from its seed
//! and renders it.

pub(crate) mod cable_routing;
pub(crate) mod deburring;
pub(crate) mod dispensing;
pub(crate) mod painting;
pub(crate) mod peg_insertion;
pub(crate) mod pick_and_place;
pub(crate) mod polishing;
pub(crate) mod screw_driving;
