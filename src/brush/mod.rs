//! `flourish brush`: structured ornament along sketched paths, the DecoBrush
//! pipeline (Lu et al. 2014, decobrush.txt §5) with vector output.
//!
//! Stages, each in its own module and each tested against a reference:
//! - [`query`]: sketch paths → arc-length resampled spines with the
//!   per-sample features of the matching (turning angle, width, distance to
//!   the ends);
//! - [`matching`]: §5.1 piecewise matching, a dynamic programme over
//!   exemplar segments (oracle: exhaustive search on tiny inputs);
//! - [`ribs`]: the exemplars' ribs resampled at the query's pace with
//!   their matching features (stroke-width envelope, ink cross-sections);
//! - [`arap`]: §5.2 as-rigid-as-possible deformation of a segment's rib mesh
//!   onto the query spine (Igarashi et al. 2005), and the rasterized map back
//!   to exemplar coordinates;
//! - [`graphcut`]: §5.3 seams between overlapping warped segments, an exact
//!   s–t minimum cut of Eq. 1–2 (oracle: brute force on tiny grids), on
//!   the Boykov–Kolmogorov max-flow of [`maxflow`] (oracle: Dinic);
//! - [`synth`]: §5.4 hierarchical synthesis of exemplar coordinates
//!   (oriented-neighbourhood correction, coordinate upsampling);
//! - [`pipeline`]: the stages chained for one query, on its own canvas;
//! - [`output`]: per-layer SDFs through the coordinates, traced to one
//!   `<g>` per query;
//! - [`baseline`]: the "art brush" reference, one exemplar stretched along
//!   the whole query.

pub mod analysis;
pub mod arap;
pub mod baseline;
pub mod graphcut;
pub mod matching;
pub mod maxflow;
pub mod output;
pub mod pipeline;
pub mod query;
pub mod ribs;
pub mod synth;
