//! Physics shared by the explicit and the implicit solver, by concept: shape
//! functions (`shape`, with the hoop terms of axisymmetry), particle–grid
//! transfers (`transfer`), the kinematics of the stress update (`kinematics`:
//! ΔF, F-bar), the laws of the grid-face conditions (`boundary`: velocity
//! conditions, rough walls, absorbing faces), rigid bodies (`rigid`: their
//! surfaces and Newton–Euler motion), what contact between bodies shares
//! (`contact`: the split grid of velocity fields, the per-pair totals) the
//! geostatic initial stress, and the Darcy flow of coupled pore water
//! (`pore_flow`). Nothing here knows which solver calls it: what
//! only one solver uses lives under that solver (`solver::explicit`,
//! `solver::implicit`).

pub(crate) mod boundary;
pub(crate) mod contact;
pub mod geostatic;
pub(crate) mod kinematics;
pub mod peridynamics;
pub mod pore_flow;
pub(crate) mod rigid;
pub mod shape;
pub mod transfer;
