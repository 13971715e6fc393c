//! Verification against analytical and published solutions: each module runs
//! a scene (or a single material point) and compares with its reference, with
//! the tolerance stated at the assertion.

#[path = "../common/mod.rs"]
mod common;

mod absorbing;
mod apic;
mod axisymmetric;
mod cam_clay;
mod cantilever;
mod collapse;
mod column_explicit;
mod consolidation;
mod contact;
mod disks;
mod footing;
mod friction;
mod geomaterial_driver;
mod geomaterial_mpm;
mod gmsh;
mod impact;
mod implicit_bar;
mod implicit_column;
mod limit_analysis;
mod loads_and_conditions;
mod peridynamics;
mod site_response;
mod slope_3d;
mod slope_runout;
mod stages;
mod staging;
mod strength_reduction;
mod three_d;
mod time_histories;
mod vibrating_bar;
mod water;
