//! Material points, stored as a struct of arrays.
//!
//! History variables exist only for particles whose material has them: `History`
//! maps a particle to a slice of a flat buffer, and a scene of elastic bodies has an
//! empty buffer.

use crate::dim::{Mat3, Tensor, Vector};
use crate::model::tensors::{Layout, Tensors};

#[derive(Clone, Debug)]
pub struct Particles<const D: usize> {
    /// Current position x.
    pub x: Vec<Vector<D>>,
    /// Reference position X (for output and for reference-configuration solutions).
    pub x0: Vec<Vector<D>>,
    pub v: Vec<Vector<D>>,
    pub mass: Vec<f64>,
    pub volume: Vec<f64>,
    pub volume0: Vec<f64>,
    /// Deformation gradient (plane strain keeps F_zz = 1), packed by
    /// `Layout::gradient(D)`.
    pub f: Tensors,
    /// Cauchy stress (plane strain carries σ_zz), packed by `Layout::stress(D)`.
    pub stress: Tensors,
    /// Half-lengths of the particle domain in the reference configuration: the CPDI
    /// domain vectors at t = 0 are r_i⁰ = lp0_i e_i, and now r_i = F r_i⁰; GIMP uses
    /// them as the half-widths of the characteristic function.
    pub half_length0: Vec<Vector<D>>,
    pub body: Vec<u32>,
    pub material: Vec<u32>,
    /// Applied force on the particle (point loads and tractions), before load
    /// scaling; empty when no particle carries a load (`model::loads`).
    pub load: Vec<Vector<D>>,
    pub history: History,
    /// APIC's affine moment B_p = Σ_I S_Ip v_I (x_I − x_p)ᵀ (`solver::explicit::apic`):
    /// one per particle in a stage with `velocity_transfer = "apic"`, else empty.
    pub affine: Vec<Tensor<D>>,
    /// Pore pressure p (compression positive) of the prescribed water field at
    /// the start of the step (`model::water`): one per particle with `[water]`,
    /// else empty. `stress` holds the effective stress σ′.
    pub pore_pressure: Vec<f64>,
}

/// Per-particle history variables, only for materials that declare some.
#[derive(Clone, Debug, Default)]
pub struct History {
    /// Start of each particle's slice in `data`, or `NONE`.
    pub offset: Vec<u32>,
    pub len: Vec<u16>,
    pub data: Vec<f64>,
}

impl History {
    pub const NONE: u32 = u32::MAX;

    pub fn get(&self, p: usize) -> &[f64] {
        match self.offset[p] {
            Self::NONE => &[],
            o => &self.data[o as usize..o as usize + self.len[p] as usize],
        }
    }

    /// The per-particle mutable slices of another buffer laid out like `data`.
    pub fn slots_mut<'a>(&self, data: &'a mut [f64]) -> Vec<&'a mut [f64]> {
        split_slots(&self.len, data)
    }

    /// The per-particle slices of `data` itself, to update in place.
    pub fn own_slots_mut(&mut self) -> Vec<&mut [f64]> {
        split_slots(&self.len, &mut self.data)
    }

    /// The per-particle slices of another buffer laid out like `data`.
    pub fn slots<'a>(&self, data: &'a [f64]) -> Vec<&'a [f64]> {
        let mut rest = data;
        self.len
            .iter()
            .map(|&n| {
                let (head, tail) = rest.split_at(n as usize);
                rest = tail;
                head
            })
            .collect()
    }

    /// Append a slot of `n` values for a new particle (no slot when n = 0).
    pub fn push(&mut self, n: usize) {
        if n == 0 {
            self.offset.push(Self::NONE);
            self.len.push(0);
        } else {
            self.offset.push(self.data.len() as u32);
            self.len.push(n as u16);
            self.data.resize(self.data.len() + n, 0.0);
        }
    }
}

impl History {
    /// The slots of `rows`, in that order, packed anew.
    pub fn select(&self, rows: &[usize]) -> History {
        let mut h = History::default();
        rows.iter().for_each(|&q| h.push_values(self.get(q)));
        h
    }

    /// Append the slots of `other` after these.
    pub fn append(&mut self, other: &History) {
        (0..other.len.len()).for_each(|q| self.push_values(other.get(q)));
    }

    /// Append a slot holding `values`.
    fn push_values(&mut self, values: &[f64]) {
        self.push(values.len());
        let start = self.data.len() - values.len();
        self.data[start..].copy_from_slice(values);
    }
}

/// The values of `rows`, in that order (an empty array stays empty: no
/// particle has one).
pub fn pick<T: Clone>(v: &[T], rows: &[usize]) -> Vec<T> {
    match v.is_empty() {
        true => Vec::new(),
        false => rows.iter().map(|&q| v[q].clone()).collect(),
    }
}

/// Split `data` into consecutive slices of the given lengths.
fn split_slots<'a>(len: &[u16], data: &'a mut [f64]) -> Vec<&'a mut [f64]> {
    let mut rest = data;
    let mut out = Vec::with_capacity(len.len());
    for &n in len {
        let (head, tail) = std::mem::take(&mut rest).split_at_mut(n as usize);
        out.push(head);
        rest = tail;
    }
    out
}

impl<const D: usize> Default for Particles<D> {
    fn default() -> Self {
        Particles {
            x: Vec::new(),
            x0: Vec::new(),
            v: Vec::new(),
            mass: Vec::new(),
            volume: Vec::new(),
            volume0: Vec::new(),
            f: Tensors::new(Layout::gradient(D)),
            stress: Tensors::new(Layout::stress(D)),
            half_length0: Vec::new(),
            body: Vec::new(),
            material: Vec::new(),
            load: Vec::new(),
            history: History::default(),
            affine: Vec::new(),
            pore_pressure: Vec::new(),
        }
    }
}

impl<const D: usize> Particles<D> {
    pub fn len(&self) -> usize {
        self.x.len()
    }

    pub fn is_empty(&self) -> bool {
        self.x.is_empty()
    }

    /// The total stress σ = σ′ − p I (Terzaghi, tension positive) of particle
    /// q with effective stress `effective`: σ′ itself without `[water]`.
    #[inline(always)]
    pub fn total_stress(&self, q: usize, effective: &Mat3) -> Mat3 {
        match self.pore_pressure.get(q) {
            Some(&p) => effective - Mat3::identity() * p,
            None => *effective,
        }
    }

    /// The total stress of particle q from its stored (effective) stress.
    #[inline(always)]
    pub fn stored_total_stress(&self, q: usize) -> Mat3 {
        self.total_stress(q, &self.stress.get(q))
    }

    /// Room for `additional` more particles (a fill knows its count: no regrowth).
    pub fn reserve(&mut self, additional: usize) {
        let n = additional;
        self.x.reserve_exact(n);
        self.x0.reserve_exact(n);
        self.v.reserve_exact(n);
        self.mass.reserve_exact(n);
        self.volume.reserve_exact(n);
        self.volume0.reserve_exact(n);
        self.f.reserve(n);
        self.stress.reserve(n);
        self.half_length0.reserve_exact(n);
        self.body.reserve_exact(n);
        self.material.reserve_exact(n);
    }

    /// The particles of `rows`, in that order, with everything they carry
    /// (staged construction, `model::staging`).
    pub fn select(&self, rows: &[usize]) -> Particles<D> {
        Particles {
            x: pick(&self.x, rows),
            x0: pick(&self.x0, rows),
            v: pick(&self.v, rows),
            mass: pick(&self.mass, rows),
            volume: pick(&self.volume, rows),
            volume0: pick(&self.volume0, rows),
            f: self.f.select(rows),
            stress: self.stress.select(rows),
            half_length0: pick(&self.half_length0, rows),
            body: pick(&self.body, rows),
            material: pick(&self.material, rows),
            load: pick(&self.load, rows),
            history: self.history.select(rows),
            affine: pick(&self.affine, rows),
            pore_pressure: pick(&self.pore_pressure, rows),
        }
    }

    /// Append `other`'s particles after these. A per-particle array only one
    /// side keeps (loads, APIC's affine moments, pore pressures) is kept for
    /// all, zero for the particles that had none.
    pub fn append(&mut self, other: &Particles<D>) {
        let (n, m) = (self.len(), other.len());
        self.x.extend_from_slice(&other.x);
        self.x0.extend_from_slice(&other.x0);
        self.v.extend_from_slice(&other.v);
        self.mass.extend_from_slice(&other.mass);
        self.volume.extend_from_slice(&other.volume);
        self.volume0.extend_from_slice(&other.volume0);
        self.f.append(&other.f);
        self.stress.append(&other.stress);
        self.half_length0.extend_from_slice(&other.half_length0);
        self.body.extend_from_slice(&other.body);
        self.material.extend_from_slice(&other.material);
        append_optional(&mut self.load, n, &other.load, m, Vector::<D>::zeros());
        append_optional(&mut self.affine, n, &other.affine, m, Tensor::<D>::zeros());
        append_optional(&mut self.pore_pressure, n, &other.pore_pressure, m, 0.0);
        self.history.append(&other.history);
    }

    /// Add one particle at rest, undeformed and unstressed.
    #[allow(clippy::too_many_arguments)]
    pub fn push(
        &mut self,
        x: Vector<D>,
        v: Vector<D>,
        mass: f64,
        volume: f64,
        half_length0: Vector<D>,
        body: u32,
        material: u32,
        n_history: usize,
    ) {
        self.x.push(x);
        self.x0.push(x);
        self.v.push(v);
        self.mass.push(mass);
        self.volume.push(volume);
        self.volume0.push(volume);
        self.f.push(&Mat3::identity());
        self.stress.push(&Mat3::zeros());
        self.half_length0.push(half_length0);
        self.body.push(body);
        self.material.push(material);
        if !self.load.is_empty() {
            self.load.push(Vector::<D>::zeros());
        }
        self.history.push(n_history);
    }
}

/// `a` (of `n` particles, or empty) followed by `b` (of `m`, or empty): empty
/// when both are, else every particle's value, `zero` where a side had none.
fn append_optional<T: Clone>(a: &mut Vec<T>, n: usize, b: &[T], m: usize, zero: T) {
    if a.is_empty() && b.is_empty() {
        return;
    }
    if a.is_empty() {
        a.resize(n, zero.clone());
    }
    match b.is_empty() {
        true => a.resize(n + m, zero),
        false => a.extend_from_slice(b),
    }
}
