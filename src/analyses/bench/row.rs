//! One row of bench.csv: a run of one configuration at one grid and time point.

use crate::output::Field;

/// One row of bench.csv.
#[derive(Clone, Debug, Default)]
pub struct Row {
    pub configuration: String,
    pub overrides: String,
    /// explicit, newmark, quasi_static or staged.
    pub solver: String,
    pub dt: Option<f64>,
    pub load_steps: Option<usize>,
    pub cells: String,
    pub particles: Option<usize>,
    pub unknowns: Option<usize>,
    pub error: Option<f64>,
    pub wall_seconds: Option<f64>,
    pub run_seconds: Option<f64>,
    pub peak_mib: Option<f64>,
    pub steps: Option<u64>,
    pub newton_iterations: Option<u64>,
    pub krylov_iterations: Option<u64>,
    pub cutbacks: Option<u64>,
    pub status: String,
    pub note: String,
    /// The run's directory, relative to DIR.
    pub run_dir: String,
}

/// The columns of bench.csv.
pub const CSV_HEADER: [&str; 21] = [
    "configuration",
    "overrides",
    "solver",
    "dt",
    "load_steps",
    "cells",
    "particles",
    "unknowns",
    "error",
    "wall_seconds",
    "run_seconds",
    "peak_mib",
    "steps",
    "newton_iterations",
    "newton_per_step",
    "krylov_iterations",
    "krylov_per_newton",
    "cutbacks",
    "status",
    "note",
    "run_dir",
];

impl Row {
    pub fn newton_per_step(&self) -> Option<f64> {
        ratio(self.newton_iterations, self.steps)
    }

    pub fn krylov_per_newton(&self) -> Option<f64> {
        ratio(self.krylov_iterations, self.newton_iterations)
    }

    pub fn is_ok(&self) -> bool {
        self.status == "ok"
    }

    /// The fields of this row in the order of `CSV_HEADER`.
    pub fn fields(&self) -> [Field<'_>; 21] {
        [
            Field::from(&self.configuration),
            Field::from(&self.overrides),
            Field::from(&self.solver),
            self.dt.into(),
            self.load_steps.into(),
            Field::from(&self.cells),
            self.particles.into(),
            self.unknowns.into(),
            self.error.into(),
            self.wall_seconds.into(),
            self.run_seconds.into(),
            self.peak_mib.into(),
            self.steps.into(),
            self.newton_iterations.into(),
            self.newton_per_step().into(),
            self.krylov_iterations.into(),
            self.krylov_per_newton().into(),
            self.cutbacks.into(),
            Field::from(&self.status),
            Field::from(&self.note),
            Field::from(&self.run_dir),
        ]
    }
}

fn ratio(a: Option<u64>, b: Option<u64>) -> Option<f64> {
    match (a, b) {
        (Some(a), Some(b)) if b > 0 => Some(a as f64 / b as f64),
        _ => None,
    }
}
