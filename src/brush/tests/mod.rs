//! Tests of the brush pipeline as a whole: the stages chained on a real
//! sketch, every shipped style on every sample, and sketches of many
//! strokes.

mod end_to_end;
mod many;
mod stages;
