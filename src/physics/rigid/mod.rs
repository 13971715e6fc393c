//! Rigid bodies: their surfaces, which deformable particles may not enter
//! (`surface`), and the Newton–Euler motion of free ones (`newton_euler`).

pub(crate) mod newton_euler;
pub(crate) mod surface;
