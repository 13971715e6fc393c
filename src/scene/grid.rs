//! The scene's background grid: its box, its cells, the shape-function family on
//! it, and the names of its faces (`xmin` … `zmax`), which boundary conditions
//! and tractions refer to.

use serde::Deserialize;
use strum::{EnumIter, IntoStaticStr};

#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridConfig {
    pub min: Vec<f64>,
    pub max: Vec<f64>,
    pub cells: Vec<usize>,
    #[serde(default = "default_shape")]
    pub shape_function: ShapeFunction,
    /// What a particle that leaves the grid box does to the run.
    #[serde(default)]
    pub particles_outside: ParticlesOutside,
    /// The stress within a particle domain in the internal force.
    #[serde(default)]
    pub domain_stress: DomainStress,
}

/// `domain_stress`: the stress within each particle domain is the particle's
/// (`"constant"`, the default, as in every MPM code) or linear about it with
/// a least-squares gradient from the neighbouring particles of the same body
/// (`"linear"`, `solver::implicit::stress_gradient`): for `cpgimp` and `cpbspline2` in
/// implicit stages; it removes the O(h) stress error of the particles at a
/// body's faces (docs/accuracy.md).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DomainStress {
    #[default]
    Constant,
    Linear,
}

/// `particles_outside`: a particle that leaves the grid stops the run
/// (`"stop"`, the default: it usually means the grid is too small), or it is
/// removed from the transfers where it left, its mass and energy counted as
/// lost in history.csv (`"remove"`: ejecta and spall in impact runs, as
/// impact codes delete them).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ParticlesOutside {
    #[default]
    Stop,
    Remove,
}

fn default_shape() -> ShapeFunction {
    ShapeFunction::Linear
}

#[derive(
    Clone, Copy, Debug, PartialEq, Eq, Deserialize, serde::Serialize, IntoStaticStr, EnumIter,
)]
#[serde(rename_all = "snake_case")]
#[strum(serialize_all = "snake_case")]
pub enum ShapeFunction {
    /// Standard MPM: piecewise-linear (bilinear, trilinear) hat functions.
    Linear,
    /// Uniform GIMP: fixed axis-aligned particle domain.
    Ugimp,
    /// Contiguous-particle GIMP: axis-aligned domain stretched by the diagonal of F.
    Cpgimp,
    /// Convected particle domain interpolation (CPDI1): parallelogram/parallelepiped
    /// spanned by r_i = F r_i⁰, weights from the corners.
    Cpdi,
    /// Quadratic B-spline on a clamped uniform knot vector.
    Bspline2,
    /// Cubic B-spline on a clamped uniform knot vector.
    Bspline3,
    /// Quadratic B-spline averaged over the contiguous particle domain (axis-aligned,
    /// stretched by the diagonal of F as in cpGIMP): no knot-crossing error.
    Cpbspline2,
}

impl ShapeFunction {
    pub fn name(&self) -> &'static str {
        self.into()
    }

    /// Whether the family follows the particle's deformation (reads F): cpGIMP,
    /// the domain-averaged B-spline and CPDI.
    pub fn reads_deformation(&self) -> bool {
        matches!(
            self,
            ShapeFunction::Cpgimp | ShapeFunction::Cpbspline2 | ShapeFunction::Cpdi
        )
    }

    /// Polynomial degree of the underlying grid basis (sets the node layout).
    pub fn degree(&self) -> usize {
        match self {
            ShapeFunction::Bspline2 | ShapeFunction::Cpbspline2 => 2,
            ShapeFunction::Bspline3 => 3,
            _ => 1,
        }
    }

    /// Largest number of nodes one particle can touch.
    /// Nodes per direction of a separable family (a product of 1D factors);
    /// `None` for CPDI.
    pub fn per_axis(&self) -> Option<usize> {
        match self {
            ShapeFunction::Cpdi => None,
            _ => Some(self.max_support(1)),
        }
    }

    pub fn max_support(&self, dim: usize) -> usize {
        let per_dir: usize = match self {
            ShapeFunction::Linear => 2,
            ShapeFunction::Ugimp | ShapeFunction::Cpgimp => 3,
            ShapeFunction::Cpdi => 4,
            ShapeFunction::Bspline2 => 3,
            ShapeFunction::Bspline3 | ShapeFunction::Cpbspline2 => 4,
        };
        per_dir.pow(dim as u32)
    }
}

/// The axis of a component name: "x" 0, "y" 1, "z" 2.
pub fn axis(name: &str) -> Option<usize> {
    ["x", "y", "z"].iter().position(|a| *a == name)
}

/// One face of the grid box: `axis` 0..D, `upper` false for the min face.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Face {
    pub axis: usize,
    pub upper: bool,
}

impl Face {
    /// Parse "xmin", "ymax", "zmin", ...
    pub fn parse(name: &str, dim: usize) -> Option<Face> {
        let axis = match name.as_bytes().first()? {
            b'x' => 0,
            b'y' => 1,
            b'z' => 2,
            _ => return None,
        };
        let upper = match &name[1..] {
            "min" => false,
            "max" => true,
            _ => return None,
        };
        (axis < dim).then_some(Face { axis, upper })
    }

    pub fn name(&self) -> String {
        format!(
            "{}{}",
            ["x", "y", "z"][self.axis],
            if self.upper { "max" } else { "min" }
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faces_parse() {
        assert_eq!(
            Face::parse("ymax", 2),
            Some(Face {
                axis: 1,
                upper: true
            })
        );
        assert_eq!(Face::parse("zmin", 2), None);
        assert_eq!(
            Face::parse("zmin", 3),
            Some(Face {
                axis: 2,
                upper: false
            })
        );
        assert_eq!(Face::parse("xmid", 3), None);
    }
}
