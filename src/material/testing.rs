//! Fixtures shared by the models' unit tests: increments, a general deformation
//! gradient, rotations about a skew axis and the relative difference of tensors.

use super::parameters::KeyError;
use super::{Increment, Material};
use crate::dim::Mat3;
use nalgebra::{Rotation3, Unit, Vector3};

/// An increment ΔF from (F_old, σ_old, history); the models here ignore dt.
pub fn increment<'a>(f_old: Mat3, df: Mat3, stress_old: Mat3, history: &'a [f64]) -> Increment<'a> {
    Increment::new(f_old, df, 0.0, stress_old, history)
}

/// A start stress with shear components (the hyperelastic models ignore it).
pub fn prestress() -> Mat3 {
    Mat3::new(1.0e5, 2.0e4, 0.0, 2.0e4, -3.0e4, 1.0e4, 0.0, 1.0e4, 5.0e4)
}

/// An increment ΔF from F_old with the stress `prestress` and no history.
pub fn prestressed<'a>(f_old: Mat3, df: Mat3) -> Increment<'a> {
    increment(f_old, df, prestress(), &[])
}

/// A general deformation gradient (stretch, shear and rotation; det F ≈ 1.03).
pub fn general_f() -> Mat3 {
    Mat3::new(1.2, 0.3, -0.1, 0.05, 0.9, 0.15, 0.02, -0.1, 1.1)
}

/// A rotation by `angle` about the skew axis (0.3, −0.5, 0.8).
pub fn rotation(angle: f64) -> Mat3 {
    let axis = Unit::new_normalize(Vector3::new(0.3, -0.5, 0.8));
    *Rotation3::from_axis_angle(&axis, angle).matrix()
}

/// diag(d) rotated by 0.3 about the skew axis: principal stretches in general axes.
pub fn rotated(d: [f64; 3]) -> Mat3 {
    rotation(0.3) * Mat3::from_diagonal(&Vector3::from(d))
}

/// |a − b| / |b|.
pub fn rel(a: &Mat3, b: &Mat3) -> f64 {
    (a - b).norm() / b.norm()
}

/// Each (extra keys, key path, message part): `build(extra)` fails at that key
/// with a message containing that part.
pub fn assert_refused_at_keys(
    build: impl Fn(&str) -> Result<Box<dyn Material>, KeyError>,
    cases: &[(&str, &str, &str)],
) {
    for &(extra, key, message) in cases {
        let err = build(extra).expect_err(extra);
        assert_eq!(err.0, key, "{extra}: {err:?}");
        assert!(err.1.contains(message), "{extra}: {}", err.1);
    }
}
