//! fretsim (crate docs to be completed).
#![warn(missing_docs)]
#![deny(clippy::float_cmp)]

pub mod error;
pub mod halfplane;
pub mod material;
pub mod quadrature;
