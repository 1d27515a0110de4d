//! Direction fields: the orientation a synthesis follows at every pixel.
//!
//! [`etf`] estimates a signed, smooth tangent field from an image (exemplars,
//! fill tiles).

pub mod etf;

pub use etf::{edge_tangent_flow, DirectionGrid, EtfOptions};
