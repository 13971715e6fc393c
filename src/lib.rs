//! Material point method (MPM) research code.
//!
//! One code path serves 2D plane strain (`D = 2`) and 3D (`D = 3`) through const
//! generics. Tensors that exist in 3D even in plane strain (deformation gradient,
//! Cauchy stress) are always stored as 3×3; vectors on the grid and particles have
//! `D` components.

pub mod absorbing;
pub mod bench;
pub mod boundary;
pub mod deformation;
pub mod dim;
pub mod explicit;
pub mod fbar;
pub mod footing;
pub mod geostatic;
pub mod grid;
pub mod implicit;
pub mod limit_analysis;
pub mod linear;
pub mod material;
pub mod output;
pub mod particles;
pub mod reference;
pub mod run;
pub mod scene;
pub mod setup;
pub mod shape;
pub mod strength_reduction;
pub mod transfer;
