//! The laws of the grid-face conditions: node constraints and rough rigid walls
//! (`conditions`), and the dashpots and springs of absorbing faces
//! (`absorbing`).

pub(crate) mod absorbing;
pub(crate) mod conditions;
