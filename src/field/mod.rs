//! Direction fields: the orientation a synthesis follows at every pixel.
//!
//! [`etf`] estimates a signed, smooth tangent field from an image (exemplars,
//! fill tiles); [`diffusion`] builds target fields for fills from a region's
//! boundary and combing strokes (Brushables §3.2).

pub mod diffusion;
pub mod etf;

pub use etf::{edge_tangent_flow, DirectionGrid, EtfOptions};
