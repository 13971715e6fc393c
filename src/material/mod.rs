//! Constitutive models.
//!
//! A model maps the state at the start of an increment (deformation gradient, Cauchy
//! stress, history) and the incremental deformation gradient ΔF to the Cauchy stress
//! and history at its end. The update is a pure function of the start state, so an
//! implicit solver can call it at every Newton iterate without drift, and it can ask
//! for the derivative of the updated stress with respect to ΔF (the consistent
//! tangent of the update).
//!
//! Each model is one file that also says how a scene builds it
//! (`parameters::FromParameters`: its name, its keys, their checks and its
//! constructor); the `models!` list below declares each model's module and
//! registers it, so a new model is a new file, one line in that list and its keys
//! in docs/scene.md.

pub mod bond;
pub(crate) mod deviatoric;
pub mod driver;
pub(crate) mod eos;
pub(crate) mod erosion;
pub(crate) mod parameters;
pub mod registry;
pub mod return_mapping;
pub(crate) mod spectral;
#[cfg(test)]
mod testing;
pub mod undrained;

mod law;

pub(crate) use law::debug_check_elastic;
pub use law::{
    lame, reduced_angle, set_derivative_column, shear_modulus, CloneMaterial, Increment, Material,
    PoreFluid, Strength, StressDerivative,
};

/// Declares each model's module and lists it in `MODELS` (its file, then its type).
macro_rules! models {
    ($($file:ident :: $model:ident),* $(,)?) => {
        $(pub mod $file;)*
        /// Every model a scene may name, in the order docs/scene.md lists them.
        pub const MODELS: &[parameters::Entry] = &[$(parameters::Entry::of::<$file::$model>()),*];
    };
}

// One line per model.
models! {
    linear_elastic::LinearElastic,
    neo_hookean::NeoHookean,
    hencky::Hencky,
    mooney_rivlin::MooneyRivlin,
    drucker_prager::DruckerPrager,
    mohr_coulomb::MohrCoulomb,
    modified_cam_clay::ModifiedCamClay,
    ogden::Ogden,
    johnson_cook::JohnsonCook,
    jh2::Jh2,
    hjc::Hjc,
    rht::Rht,
    rigid::Rigid,
}
