//! Particle deformation from a nodal displacement increment, shared by the explicit
//! and implicit solvers: ΔF_p = I + Σ_I u_I ⊗ ∇S_Ip (the explicit step uses
//! u_I = Δt v_I, i.e. ΔF = I + Δt L, thesis 2-31), F ← ΔF F, V = det F V0, and the
//! material's stress update from the start-of-increment state. The result is a
//! trial state, so an implicit solver can evaluate it at every Newton iterate
//! without drift and commit it once the step has converged. With F-bar (`fbar`)
//! the particles follow ΔF̄ instead of ΔF. In axisymmetric mode ΔF_θθ is the hoop
//! stretch of the increment (`physics::shape::hoop`) instead of 1.

use crate::dim::{compose, embed_deformation, Mat3, Tensor, Vector};
use crate::material::{Increment, Material};
use crate::model::grid::Grid;
use crate::model::particles::Particles;
use crate::model::tensors::{Layout, TensorMut, Tensors};
use crate::parallel::MIN_PARALLEL_LEN;
use crate::physics::kinematics::fbar::{scale_factor, scaled, Cells, FBarState};
use crate::physics::shape::hoop::hoop_stretch;
use crate::physics::shape::Stencils;
use crate::physics::transfer::{gradient, NodeMap};
use rayon::prelude::*;
use std::sync::atomic::{AtomicUsize, Ordering};

/// The state the particles would reach under a displacement increment.
///
/// ΔF_p is not stored: [`Trial::df`] forms it again from the increment's nodal
/// displacements (with F-bar, from the plain ΔF_p and the cells' mean
/// dilatation), with the arithmetic of `evaluate`, so every reader sees the
/// same bits (72 bytes per particle less in every implicit step).
#[derive(Clone, Debug)]
pub struct Trial<const D: usize> {
    /// The nodal displacements u of the increment (one per active node).
    u: Vec<Vector<D>>,
    /// Packed as the particles' stresses.
    pub stress: Tensors,
    pub volume: Vec<f64>,
    /// History variables, laid out like `Particles::history.data`.
    pub history: Vec<f64>,
    /// F-bar (None: off): the cells of this step, set by `use_fbar`.
    pub fbar: Option<FBarState>,
}

impl<const D: usize> Default for Trial<D> {
    fn default() -> Self {
        Trial {
            u: Vec::new(),
            stress: Tensors::new(Layout::stress(D)),
            volume: Vec::new(),
            history: Vec::new(),
            fbar: None,
        }
    }
}

impl<const D: usize> Trial<D> {
    /// Turn F-bar on for the coming evaluations, with the particles grouped by
    /// the cells of their step-start positions `x` (call once per step).
    pub fn use_fbar(&mut self, grid: &Grid<D>, x: &[Vector<D>]) {
        let state = self.fbar.get_or_insert_with(FBarState::default);
        state.cells = Cells::locate(grid, x);
    }

    /// Evaluate the trial state under nodal displacements `u` (one per active node).
    /// Returns the first particle whose deformation inverts (det F ≤ 0), if any.
    pub fn evaluate(
        &mut self,
        p: &Particles<D>,
        materials: &[Box<dyn Material>],
        st: &Stencils<D>,
        map: &NodeMap,
        u: &[Vector<D>],
        dt: f64,
    ) -> Option<usize> {
        let n = p.len();
        self.u.clear();
        self.u.extend_from_slice(u);
        self.stress.resize(n, &Mat3::zeros());
        self.volume.resize(n, 0.0);
        self.history.clone_from(&p.history.data);
        let axisymmetric = !st.hoop.is_empty();
        if let Some(fbar) = &mut self.fbar {
            let (df, dj) = (&mut fbar.df, &mut fbar.dj);
            match dilatations(st, map, u, axisymmetric, &fbar.cells, &p.volume, df, dj) {
                Ok(dj_bar) => fbar.dj_bar = dj_bar,
                Err(q) => return Some(q),
            }
        }
        let history_old = p.history.slots(&p.history.data);
        let mut history = p.history.slots_mut(&mut self.history);
        let (u, fbar) = (&self.u, self.fbar.as_ref().map(Dilatations::of));
        let inverted = (self.stress.par_iter_mut())
            .zip(self.volume.par_iter_mut())
            .zip(history.par_iter_mut())
            .enumerate()
            .with_min_len(MIN_PARALLEL_LEN)
            .map(|(q, ((mut stress, volume), hist))| {
                let material = materials[p.material[q] as usize].as_ref();
                let df = df_of(u, fbar, st, map, q);
                let inc = Increment::new(p.f.get(q), df, dt, p.stress.get(q), history_old[q]);
                let new = advance(material, &inc, p.volume0[q], hist);
                stress.set(&new.stress);
                *volume = new.volume;
                new.inverted_at(q)
            })
            .min()
            .unwrap_or(usize::MAX);
        (inverted != usize::MAX).then_some(inverted)
    }

    /// ΔF_p of the last evaluation (ΔF̄_p with F-bar), formed as `evaluate`
    /// formed it.
    pub fn df(&self, st: &Stencils<D>, map: &NodeMap, q: usize) -> Mat3 {
        df_of(&self.u, self.fbar.as_ref().map(Dilatations::of), st, map, q)
    }

    /// The nodal displacements u of the last evaluation.
    pub fn displacements(&self) -> &[Vector<D>] {
        &self.u
    }

    /// `measure(p, ΔF_p, σ_p)` of every particle under nodal displacements `u`,
    /// with the ΔF_p (ΔF̄_p with F-bar) and the stress that `evaluate` would
    /// leave (the same arithmetic; the stress packed and read back as `stress`
    /// holds it), keeping nothing: the trial state stays that of the last
    /// evaluation (an implicit solver's residual at a point that is not its
    /// iterate, a difference product). Err(q): particle q inverts (det F ≤ 0).
    #[allow(clippy::too_many_arguments)]
    pub fn probe<T: Send>(
        &self,
        p: &Particles<D>,
        materials: &[Box<dyn Material>],
        st: &Stencils<D>,
        map: &NodeMap,
        u: &[Vector<D>],
        dt: f64,
        measure: impl Fn(usize, &Mat3, &Mat3) -> T + Sync,
    ) -> Result<Vec<T>, usize> {
        let n = p.len();
        let axisymmetric = !st.hoop.is_empty();
        // F-bar: ΔF_p and ΔJ_p of every particle, then the cells' mean ΔJ̄_c.
        let mut plain: (Vec<Mat3>, Vec<f64>, Vec<f64>) = Default::default();
        if let Some(fbar) = &self.fbar {
            let (df, dj, dj_bar) = &mut plain;
            *dj_bar = dilatations(st, map, u, axisymmetric, &fbar.cells, &p.volume, df, dj)?;
        }
        let fbar = (self.fbar.as_ref()).map(|f| Dilatations {
            df: &plain.0,
            dj: &plain.1,
            dj_bar: &plain.2,
            cell_of: &f.cells.of,
        });
        let history_old = p.history.slots(&p.history.data);
        let inverted = AtomicUsize::new(usize::MAX);
        let scratch = || {
            (
                Vec::new(),
                Tensors::filled(Layout::stress(D), 1, &Mat3::zeros()),
            )
        };
        let out = (0..n)
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .map_init(scratch, |(hist, packed), q| {
                let material = materials[p.material[q] as usize].as_ref();
                hist.clear();
                hist.extend_from_slice(history_old[q]);
                let df = df_of(u, fbar, st, map, q);
                let inc = Increment::new(p.f.get(q), df, dt, p.stress.get(q), history_old[q]);
                let new = advance(material, &inc, p.volume0[q], hist);
                inverted.fetch_min(new.inverted_at(q), Ordering::Relaxed);
                packed.set(0, &new.stress);
                measure(q, &df, &packed.get(0))
            })
            .collect();
        match inverted.into_inner() {
            usize::MAX => Ok(out),
            q => Err(q),
        }
    }

    /// The explicit step's update: the particles take the state of the
    /// displacement increment `u` (`evaluate` and `commit` with F-bar, else
    /// `update_in_place`). On an inversion, the particle and its det F (the
    /// particles are then not, or only partly, updated, and the run stops).
    pub fn advance(
        &mut self,
        p: &mut Particles<D>,
        materials: &[Box<dyn Material>],
        st: &Stencils<D>,
        map: &NodeMap,
        u: &[Vector<D>],
        dt: f64,
    ) -> Result<(), (usize, f64)> {
        if self.fbar.is_none() {
            return match update_in_place(p, materials, st, map, u, dt) {
                Some(q) => Err((q, p.f.get(q).determinant())),
                None => Ok(()),
            };
        }
        if let Some(q) = self.evaluate(p, materials, st, map, u, dt) {
            return Err((q, self.f(p, st, map, q).determinant()));
        }
        self.commit(p, st, map);
        Ok(())
    }

    /// The trial deformation gradient of particle q, F = ΔF F_old (2-31); not
    /// stored: only a commit and an inversion's report need it.
    pub fn f(&self, p: &Particles<D>, st: &Stencils<D>, map: &NodeMap, q: usize) -> Mat3 {
        compose(&self.df(st, map, q), &p.f.get(q))
    }

    /// Make the trial state the particles' state: F = ΔF F_old formed in place,
    /// the other buffers swapped, not copied. (`update_in_place` is this and
    /// `evaluate` in one pass, without F-bar.)
    pub fn commit(&mut self, p: &mut Particles<D>, st: &Stencils<D>, map: &NodeMap) {
        (p.f.par_iter_mut())
            .enumerate()
            .with_min_len(MIN_PARALLEL_LEN)
            .for_each(|(q, mut f)| f.set(&compose(&self.df(st, map, q), &f.get())));
        std::mem::swap(&mut p.stress, &mut self.stress);
        std::mem::swap(&mut p.volume, &mut self.volume);
        std::mem::swap(&mut p.history.data, &mut self.history);
    }
}

/// The plain ΔF_p, ΔJ_p and the cells' ΔJ̄_c of one F-bar evaluation.
#[derive(Clone, Copy)]
struct Dilatations<'a> {
    df: &'a [Mat3],
    dj: &'a [f64],
    dj_bar: &'a [f64],
    /// The cell of each particle.
    cell_of: &'a [u32],
}

impl<'a> Dilatations<'a> {
    fn of(f: &'a FBarState) -> Self {
        Dilatations {
            df: &f.df,
            dj: &f.dj,
            dj_bar: &f.dj_bar,
            cell_of: &f.cells.of,
        }
    }
}

/// ΔF_p under the nodal displacements `u`; with F-bar, ΔF̄_p from the plain
/// ΔF_p and dilatations that `fbar` holds.
fn df_of<const D: usize>(
    u: &[Vector<D>],
    fbar: Option<Dilatations>,
    st: &Stencils<D>,
    map: &NodeMap,
    q: usize,
) -> Mat3 {
    let axisymmetric = !st.hoop.is_empty();
    let Some(fbar) = fbar else {
        return increment(st, map, q, u, axisymmetric);
    };
    let (dj_bar, dj) = (fbar.dj_bar[fbar.cell_of[q] as usize], fbar.dj[q]);
    // Axisymmetric: n = 3, the hoop stretch is scaled too.
    match axisymmetric {
        true => scaled::<3>(&fbar.df[q], scale_factor::<3>(dj_bar, dj)),
        false => scaled::<D>(&fbar.df[q], scale_factor::<D>(dj_bar, dj)),
    }
}

/// A particle's state after an increment: the material's stress, F = ΔF F_old
/// and V = det F V0 (2-31, 2-32).
struct Advanced {
    stress: Mat3,
    f: Mat3,
    volume: f64,
    det: f64,
}

impl Advanced {
    /// q if the deformation inverted (det F ≤ 0), else `usize::MAX` (for a
    /// `min` over the particles).
    fn inverted_at(&self, q: usize) -> usize {
        match self.det > 0.0 {
            true => usize::MAX,
            false => q,
        }
    }
}

/// The stress update of one particle under `inc` (writing its new history into
/// `history`), its new F and volume.
fn advance(
    material: &dyn Material,
    inc: &Increment,
    volume0: f64,
    history: &mut [f64],
) -> Advanced {
    let stress = material.update(inc, history);
    let f = inc.f;
    let det = f.determinant();
    Advanced {
        stress,
        f,
        volume: det * volume0,
        det,
    }
}

/// ΔF_p = I + Σ_I u_I ⊗ ∇S_Ip; axisymmetric: ΔF_θθ = 1 + Σ_I u_Ir S_Ip / r_p.
/// F-bar's measures under nodal displacements u: ΔF_p and ΔJ_p = det ΔF_p of
/// every particle (into `df`, `dj`), and the cells' mean dilatation ΔJ̄_c, from
/// which ΔF̄_p = (ΔJ̄_c / ΔJ_p)^{1/n} ΔF_p (Coombs et al. 2018). Err(q): ΔJ_q ≤ 0.
#[allow(clippy::too_many_arguments)]
fn dilatations<const D: usize>(
    st: &Stencils<D>,
    map: &NodeMap,
    u: &[Vector<D>],
    axisymmetric: bool,
    cells: &Cells,
    volume: &[f64],
    df: &mut Vec<Mat3>,
    dj: &mut Vec<f64>,
) -> Result<Vec<f64>, usize> {
    df.clear();
    (0..volume.len())
        .into_par_iter()
        .with_min_len(MIN_PARALLEL_LEN)
        .map(|q| increment(st, map, q, u, axisymmetric))
        .collect_into_vec(df);
    dj.clear();
    dj.extend(df.iter().map(|f| f.determinant()));
    if let Some(q) = dj.iter().position(|&j| j <= 0.0) {
        return Err(q);
    }
    Ok(cells.mean_dilatation(volume, dj))
}

fn increment<const D: usize>(
    st: &Stencils<D>,
    map: &NodeMap,
    q: usize,
    u: &[Vector<D>],
    axisymmetric: bool,
) -> Mat3 {
    let grad_u: Tensor<D> = gradient(map, st, q, u);
    let mut df = embed_deformation::<D>(&(Tensor::<D>::identity() + grad_u));
    if axisymmetric {
        let entries = st.range(q).map(|e| (u[map.local_of(st, e)][0], st.hoop[e]));
        df[(2, 2)] = hoop_stretch(entries);
    }
    df
}

/// The explicit step's deformation and stress update without F-bar, written
/// straight into the particles: `Trial::evaluate` and `Trial::commit` in one pass
/// with the same arithmetic (bit-identical), and no trial buffers (216 bytes per
/// particle less). Returns the first particle whose deformation inverts (det F ≤
/// 0), if any; the state is then part updated, and the run stops.
fn update_in_place<const D: usize>(
    p: &mut Particles<D>,
    materials: &[Box<dyn Material>],
    st: &Stencils<D>,
    map: &NodeMap,
    u: &[Vector<D>],
    dt: f64,
) -> Option<usize> {
    let axisymmetric = !st.hoop.is_empty();
    let Particles {
        f,
        stress,
        volume,
        volume0,
        material,
        history,
        ..
    } = p;
    let update = |q: usize, f: TensorMut, stress: TensorMut, volume: &mut f64, hist: &mut [f64]| {
        let material = materials[material[q] as usize].as_ref();
        let df = increment(st, map, q, u, axisymmetric);
        let mut state = ParticleState {
            f,
            stress,
            volume,
            history: hist,
        };
        // NaN counts as inverted, as in `Advanced::inverted_at`.
        match update_particle(material, &df, dt, volume0[q], &mut state) > 0.0 {
            true => usize::MAX,
            false => q,
        }
    };
    let states = f
        .par_iter_mut()
        .zip(stress.par_iter_mut())
        .zip(volume.par_iter_mut())
        .enumerate()
        .with_min_len(MIN_PARALLEL_LEN);
    let inverted = match history.data.is_empty() {
        true => states
            .map(|(q, ((f, s), v))| update(q, f, s, v, &mut []))
            .min(),
        false => states
            .zip(history.own_slots_mut())
            .map(|((q, ((f, s), v)), h)| update(q, f, s, v, h))
            .min(),
    }
    .unwrap_or(usize::MAX);
    (inverted != usize::MAX).then_some(inverted)
}

/// The mutable state of one particle that a stress update changes.
pub struct ParticleState<'a> {
    pub f: TensorMut<'a>,
    pub stress: TensorMut<'a>,
    pub volume: &'a mut f64,
    pub history: &'a mut [f64],
}

/// One particle's deformation and stress update under ΔF, in place: the
/// material's stress from the step-start state, F = ΔF F_old, V = det F V0
/// (2-31, 2-32). Returns det F (the deformation inverted unless det F > 0).
pub fn update_particle(
    material: &dyn Material,
    df: &Mat3,
    dt: f64,
    volume0: f64,
    state: &mut ParticleState,
) -> f64 {
    // The material reads the step-start history and writes the new one.
    let hist = &mut *state.history;
    let mut kept = [0.0; 8];
    let old: Vec<f64>;
    let history_old: &[f64] = match hist.len() <= kept.len() {
        _ if hist.is_empty() => &[],
        true => {
            kept[..hist.len()].copy_from_slice(hist);
            &kept[..hist.len()]
        }
        false => {
            old = hist.to_vec();
            &old
        }
    };
    let inc = Increment::new(state.f.get(), *df, dt, state.stress.get(), history_old);
    let new = advance(material, &inc, volume0, hist);
    state.stress.set(&new.stress);
    state.f.set(&new.f);
    *state.volume = new.volume;
    new.det
}
