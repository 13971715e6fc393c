//! The kinematics of the stress update that both solvers share: the
//! incremental deformation gradient from nodal displacements and the material
//! update (`deformation`), and F-bar against volumetric locking (`fbar`).

pub(crate) mod deformation;
pub(crate) mod fbar;
