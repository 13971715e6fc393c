//! Loads on particles: a point force shared by the particles of a region, or a
//! traction on one face of each particle (axisymmetric: per radian, over the
//! face's area per radian, `model::axisymmetry`), with its time history (a ramp, a
//! pulse or a piecewise-linear curve). The force at full value is stored on the particles (`Particles::load`);
//! a solver scales it by the factor of the particle's history at time t
//! (`load_factor`).

use crate::dim::Vector;
use crate::model::axisymmetry::face_area_per_radian;
use crate::model::curve::TimeCurve;
use crate::model::particles::Particles;
use crate::scene::{Face, LoadConfig, LoadKind, SceneConfig};
use std::sync::Arc;

/// How a load varies in time.
#[derive(Clone, Debug, PartialEq)]
pub enum LoadTime {
    /// min(t / ramp_time, 1); at once when the ramp time is 0.
    Ramp(f64),
    /// A smooth pulse of duration T: sin²(π t / T) for t ≤ T, then 0.
    Pulse(f64),
    /// A piecewise-linear time history (`time_history`, `model::curve`).
    Curve(Arc<TimeCurve>),
}

impl LoadTime {
    pub fn of(l: &LoadConfig) -> LoadTime {
        match (&l.time_history, l.pulse_duration) {
            (Some(h), _) => LoadTime::Curve(Arc::new(TimeCurve::new(&h.points()))),
            (None, Some(t)) => LoadTime::Pulse(t),
            (None, None) => LoadTime::Ramp(l.ramp_time),
        }
    }

    /// Whether the factor follows a time history given in the scene (also in
    /// quasi-static stages, where ramps follow the stage's load factor).
    pub fn is_curve(&self) -> bool {
        matches!(self, LoadTime::Curve(_))
    }

    pub fn factor(&self, t: f64) -> f64 {
        match *self {
            LoadTime::Ramp(r) if r > 0.0 => (t / r).min(1.0),
            LoadTime::Ramp(_) => 1.0,
            LoadTime::Pulse(d) if t >= 0.0 && t <= d => {
                (std::f64::consts::PI * t / d).sin().powi(2)
            }
            LoadTime::Pulse(_) => 0.0,
            LoadTime::Curve(ref c) => c.value(t),
        }
    }
}

/// Load factor of particle q from its ramp (`Model::load_ramp_of`, empty when
/// the scene has no loads) and the factor of each ramp (0: the particle carries
/// no load).
pub fn load_factor(ramp_of: &[u32], q: usize, scales: &[f64]) -> f64 {
    match ramp_of.get(q) {
        None | Some(&u32::MAX) => 0.0,
        Some(&r) => scales[r as usize],
    }
}

/// The loads of a scene, put on the particles at full value.
#[derive(Default)]
pub struct Loads {
    /// The distinct time histories.
    pub ramps: Vec<LoadTime>,
    /// For each particle, the index into `ramps` of its load (u32::MAX: none);
    /// empty, as `Particles::load`, when the scene has no loads.
    pub ramp_of: Vec<u32>,
}

impl Loads {
    /// Add each `[[load]]` to the particles it selects. An error names the key: a
    /// region that selects no particle, or a particle given two time histories.
    pub fn apply<const D: usize>(
        c: &SceneConfig,
        particles: &mut Particles<D>,
    ) -> Result<Loads, (String, String)> {
        if c.loads.is_empty() {
            return Ok(Loads::default());
        }
        let vec = |v: &[f64]| Vector::<D>::from_fn(|d, _| v[d]);
        let mut ramp_of = vec![u32::MAX; particles.len()];
        particles.load = vec![Vector::<D>::zeros(); particles.len()];
        let mut ramps = Vec::new();
        for (i, l) in c.loads.iter().enumerate() {
            let body = l.body.as_ref().map(|n| {
                c.bodies
                    .iter()
                    .position(|b| b.name.as_deref() == Some(n))
                    .unwrap() as u32
            });
            let (lo, hi) = (vec(&l.region_min), vec(&l.region_max));
            let selected: Vec<usize> = (0..particles.len())
                .filter(|&p| body.is_none_or(|b| particles.body[p] == b))
                .filter(|&p| {
                    (0..D).all(|d| particles.x0[p][d] >= lo[d] && particles.x0[p][d] <= hi[d])
                })
                .collect();
            if selected.is_empty() {
                return Err((
                    format!("load.{i}.region_min"),
                    "the load region selects no particle".into(),
                ));
            }
            let time = LoadTime::of(l);
            let ramp = match ramps.iter().position(|r| *r == time) {
                Some(r) => r,
                None => {
                    ramps.push(time);
                    ramps.len() - 1
                }
            };
            for &p in &selected {
                if ramp_of[p] != u32::MAX && ramp_of[p] != ramp as u32 {
                    let key = match (&l.time_history, l.pulse_duration) {
                        (Some(_), _) => "time_history",
                        (None, Some(_)) => "pulse_duration",
                        (None, None) => "ramp_time",
                    };
                    return Err((
                        format!("load.{i}.{key}"),
                        format!("particle {p} already carries a load with another time history (ramp_time, pulse_duration or time_history)"),
                    ));
                }
                ramp_of[p] = ramp as u32;
                particles.load[p] += match l.kind {
                    LoadKind::Point => vec(l.force.as_ref().unwrap()) / selected.len() as f64,
                    LoadKind::Traction => {
                        let face = Face::parse(l.face.as_ref().unwrap(), D).unwrap();
                        let half = particles.half_length0[p];
                        let area: f64 = if c.dimension.is_axisymmetric() {
                            face_area_per_radian(&particles.x0[p], &half, face)
                        } else {
                            (0..D)
                                .filter(|&d| d != face.axis)
                                .map(|d| 2.0 * half[d])
                                .product()
                        };
                        vec(l.traction.as_ref().unwrap()) * area
                    }
                };
            }
        }
        Ok(Loads { ramps, ramp_of })
    }
}

#[cfg(test)]
mod tests {
    use crate::model::Model;
    use crate::scene::testing::BLOCK;
    use crate::scene::Scene;

    const LOAD: &str = r#"
[[load]]
kind = "point"
force = [0.0, -10.0]
region_min = [0.5, 0.5]
region_max = [1.0, 1.0]
"#;

    #[test]
    fn only_a_scene_with_loads_keeps_them_per_particle() {
        let model = |text: &str| {
            let scene = Scene::parse("block.toml", text, &[]).unwrap();
            Model::<2>::build(&scene).unwrap()
        };
        let bare = model(BLOCK);
        assert!(!bare.particles.is_empty());
        assert!(bare.particles.load.is_empty() && bare.load_ramp_of.is_empty());
        let loaded = model(&format!("{BLOCK}{LOAD}"));
        let n = loaded.particles.len();
        assert_eq!(
            (loaded.particles.load.len(), loaded.load_ramp_of.len()),
            (n, n)
        );
        let carrying = (0..n).filter(|&q| loaded.load_ramp_of[q] != u32::MAX);
        let total = carrying.fold(0.0, |t, q| t + loaded.particles.load[q][1]);
        assert!((total + 10.0).abs() < 1e-12, "{total}");
    }
}
