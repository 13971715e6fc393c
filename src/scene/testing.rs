//! Scene texts the unit tests of several layers build models from.

/// One elastic 1 m × 1 m body on a 2 × 1 grid of 1 m cells, explicit.
pub const BLOCK: &str = r#"dimension = 2
[grid]
min = [0.0, 0.0]
max = [2.0, 1.0]
cells = [2, 1]
[[material]]
name = "m"
model = "linear_elastic"
density = 1.0
youngs_modulus = 100.0
poisson_ratio = 0.3
[[body]]
material = "m"
shape = "rectangle"
min = [0.0, 0.0]
max = [1.0, 1.0]
[solver]
kind = "explicit"
end_time = 1.0
"#;
