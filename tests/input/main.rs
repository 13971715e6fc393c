//! Input handling: bad scene files and command lines give an error naming the
//! file, the key and the line and column, never a panic; `mpm bench` on good and
//! bad settings.

#[path = "../common/mod.rs"]
mod common;

mod axisymmetric;
mod bench;
mod body_kinds;
mod contact;
mod documented;
mod domain_stress;
mod fuzz;
mod geometry;
mod gmsh;
mod impact;
mod key_paths;
mod obj;
mod raster;
mod robustness;
mod scene_errors;
mod shipped;
mod staging;
mod time_histories;
mod water;
