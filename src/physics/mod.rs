//! Physics shared by the explicit and the implicit solver: shape functions,
//! particle–grid transfers, the stress update, F-bar kinematics, and the laws of
//! the boundary conditions. Nothing here knows which solver calls it.

pub mod absorbing;
pub mod apic;
pub mod axisymmetry;
pub mod boundary;
pub mod bulk_viscosity;
pub mod contact;
pub mod deformation;
pub mod fbar;
pub mod field_split;
pub mod geostatic;
pub mod grid_update;
pub mod mirror;
pub mod rigid_body;
pub mod rigid_penalty;
pub mod rigid_surface;
pub mod scatter;
pub mod shape;
pub mod stress_gradient;
pub mod transfer;
