//! Per-particle 3×3 tensors stored by the components that can be non-zero.
//!
//! The solvers work with full 3×3 matrices (`Mat3`), but a particle keeps only
//! what its dimension allows: in plane strain and axisymmetry the deformation
//! gradient has no out-of-plane shear (F_xz = F_zx = F_yz = F_zy = 0), so five
//! components; the Cauchy stress is symmetric, with four components in 2D
//! (σ_xx, σ_yy, σ_xy, σ_zz) and six in 3D. A 2D particle stores 72 bytes for F
//! and σ instead of 144; a 3D one 120 instead of 144. Reading unpacks into a
//! `Mat3`, writing packs (an out-of-plane shear of F, or the skew part of σ, is
//! dropped: the materials produce none beyond round-off).

use crate::dim::{voigt, Mat3};
use rayon::prelude::*;

/// Which components a [`Tensors`] keeps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Layout {
    /// All nine (a 3D deformation gradient).
    Full,
    /// xx, xy, yx, yy, zz (a 2D deformation gradient).
    Plane,
    /// The Voigt components of a symmetric tensor (`dim::voigt`; a 3D stress).
    Symmetric,
    /// xx, yy, xy, zz of a symmetric tensor without out-of-plane shear (a 2D stress).
    PlaneSymmetric,
}

impl Layout {
    /// Components stored per tensor.
    pub const fn components(self) -> usize {
        match self {
            Layout::Full => 9,
            Layout::Plane => 5,
            Layout::Symmetric => 6,
            Layout::PlaneSymmetric => 4,
        }
    }

    /// The layout of a deformation gradient in `dim` dimensions.
    pub const fn gradient(dim: usize) -> Layout {
        match dim {
            2 => Layout::Plane,
            _ => Layout::Full,
        }
    }

    /// The layout of a stress in `dim` dimensions.
    pub const fn stress(dim: usize) -> Layout {
        match dim {
            2 => Layout::PlaneSymmetric,
            _ => Layout::Symmetric,
        }
    }

    #[inline(always)]
    fn unpack(self, c: &[f64]) -> Mat3 {
        match self {
            Layout::Full => Mat3::from_row_slice(&c[..9]),
            Layout::Plane => Mat3::new(c[0], c[1], 0.0, c[2], c[3], 0.0, 0.0, 0.0, c[4]),
            Layout::Symmetric => Mat3::new(c[0], c[3], c[5], c[3], c[1], c[4], c[5], c[4], c[2]),
            Layout::PlaneSymmetric => Mat3::new(c[0], c[2], 0.0, c[2], c[1], 0.0, 0.0, 0.0, c[3]),
        }
    }

    #[inline(always)]
    fn pack(self, m: &Mat3, c: &mut [f64]) {
        match self {
            Layout::Full => {
                for (k, out) in c[..9].iter_mut().enumerate() {
                    *out = m[(k / 3, k % 3)];
                }
            }
            Layout::Plane => {
                c[..5].copy_from_slice(&[m[(0, 0)], m[(0, 1)], m[(1, 0)], m[(1, 1)], m[(2, 2)]])
            }
            Layout::Symmetric => c[..6].copy_from_slice(&voigt(m)),
            Layout::PlaneSymmetric => {
                c[..4].copy_from_slice(&[m[(0, 0)], m[(1, 1)], m[(0, 1)], m[(2, 2)]])
            }
        }
    }
}

/// One tensor per particle, packed by a [`Layout`].
#[derive(Clone, Debug, PartialEq)]
pub struct Tensors {
    layout: Layout,
    data: Vec<f64>,
}

impl Tensors {
    pub fn new(layout: Layout) -> Self {
        Tensors {
            layout,
            data: Vec::new(),
        }
    }

    /// `n` copies of `value`.
    pub fn filled(layout: Layout, n: usize, value: &Mat3) -> Self {
        let mut t = Tensors::new(layout);
        t.resize(n, value);
        t
    }

    /// The tensors of `items`, packed.
    pub fn from_matrices(layout: Layout, items: impl IntoIterator<Item = Mat3>) -> Self {
        let mut t = Tensors::new(layout);
        items.into_iter().for_each(|m| t.push(&m));
        t
    }

    pub fn len(&self) -> usize {
        self.data.len() / self.layout.components()
    }

    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    /// Tensor q, unpacked.
    #[inline(always)]
    pub fn get(&self, q: usize) -> Mat3 {
        let n = self.layout.components();
        self.layout.unpack(&self.data[q * n..(q + 1) * n])
    }

    #[inline(always)]
    pub fn set(&mut self, q: usize, value: &Mat3) {
        let n = self.layout.components();
        self.layout.pack(value, &mut self.data[q * n..(q + 1) * n]);
    }

    pub fn push(&mut self, value: &Mat3) {
        let n = self.data.len();
        self.data.resize(n + self.layout.components(), 0.0);
        self.layout.pack(value, &mut self.data[n..]);
    }

    /// Shorten, or lengthen with copies of `value`.
    pub fn resize(&mut self, n: usize, value: &Mat3) {
        let old = self.len();
        self.data.resize(n * self.layout.components(), 0.0);
        for q in old..n {
            self.set(q, value);
        }
    }

    /// The tensors of `rows`, in that order (`Particles::select`).
    pub fn select(&self, rows: &[usize]) -> Tensors {
        let n = self.layout.components();
        let data = (rows.iter())
            .flat_map(|&q| self.data[q * n..(q + 1) * n].iter().copied())
            .collect();
        Tensors {
            layout: self.layout,
            data,
        }
    }

    /// Append the tensors of `other` (of the same layout).
    pub fn append(&mut self, other: &Tensors) {
        assert_eq!(self.layout, other.layout, "tensors of one layout");
        self.data.extend_from_slice(&other.data);
    }

    pub fn reserve(&mut self, additional: usize) {
        self.data
            .reserve_exact(additional * self.layout.components());
    }

    pub fn iter(&self) -> impl ExactSizeIterator<Item = Mat3> + '_ {
        let layout = self.layout;
        self.data
            .chunks_exact(layout.components())
            .map(move |c| layout.unpack(c))
    }

    pub fn iter_mut(&mut self) -> impl ExactSizeIterator<Item = TensorMut<'_>> {
        let layout = self.layout;
        (self.data.chunks_exact_mut(layout.components()))
            .map(move |data| TensorMut { layout, data })
    }

    pub fn par_iter_mut(&mut self) -> impl IndexedParallelIterator<Item = TensorMut<'_>> {
        let layout = self.layout;
        (self.data.par_chunks_exact_mut(layout.components()))
            .map(move |data| TensorMut { layout, data })
    }

    /// Runs of `size` tensors (the last may be shorter), for passes in fixed chunks.
    pub fn par_chunks_mut(
        &mut self,
        size: usize,
    ) -> impl IndexedParallelIterator<Item = TensorsMut<'_>> {
        let layout = self.layout;
        (self.data.par_chunks_mut(size * layout.components()))
            .map(move |data| TensorsMut { layout, data })
    }
}

/// One packed tensor, writable.
pub struct TensorMut<'a> {
    layout: Layout,
    data: &'a mut [f64],
}

impl TensorMut<'_> {
    #[inline(always)]
    pub fn get(&self) -> Mat3 {
        self.layout.unpack(self.data)
    }

    #[inline(always)]
    pub fn set(&mut self, value: &Mat3) {
        self.layout.pack(value, self.data);
    }
}

/// A run of packed tensors, writable.
pub struct TensorsMut<'a> {
    layout: Layout,
    data: &'a mut [f64],
}

impl TensorsMut<'_> {
    /// Tensor i of the run.
    #[inline(always)]
    pub fn at(&mut self, i: usize) -> TensorMut<'_> {
        let n = self.layout.components();
        TensorMut {
            layout: self.layout,
            data: &mut self.data[i * n..(i + 1) * n],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn packing_keeps_what_the_layout_allows() {
        let plane = Mat3::new(1.1, 0.2, 0.0, -0.3, 0.9, 0.0, 0.0, 0.0, 1.05);
        let sym_plane = Mat3::new(-5.0, 2.0, 0.0, 2.0, -7.0, 0.0, 0.0, 0.0, -3.0);
        let sym = Mat3::new(-5.0, 2.0, 1.5, 2.0, -7.0, 0.25, 1.5, 0.25, -3.0);
        let full = Mat3::from_fn(|i, j| (3 * i + j) as f64 + 0.5);
        let cases = [
            (Layout::Full, full),
            (Layout::Plane, plane),
            (Layout::Symmetric, sym),
            (Layout::PlaneSymmetric, sym_plane),
        ];
        for (layout, m) in cases {
            let mut t = Tensors::filled(layout, 3, &Mat3::identity());
            t.set(1, &m);
            t.push(&m);
            assert_eq!(t.len(), 4);
            assert_eq!(t.data.len(), 4 * layout.components());
            assert_eq!(t.get(0), Mat3::identity(), "{layout:?}");
            assert_eq!(t.get(1), m, "{layout:?}: round trip");
            assert_eq!(t.get(3), m, "{layout:?}: push");
            assert_eq!(
                t.iter().collect::<Vec<_>>(),
                [Mat3::identity(), m, Mat3::identity(), m]
            );
        }
        // What a layout cannot hold is dropped.
        let mut t = Tensors::filled(Layout::Plane, 1, &Mat3::identity());
        t.set(0, &Mat3::from_element(2.0));
        assert_eq!(
            t.get(0),
            Mat3::new(2.0, 2.0, 0.0, 2.0, 2.0, 0.0, 0.0, 0.0, 2.0)
        );
    }

    #[test]
    fn chunks_and_slots_write_their_own_tensors() {
        let mut t = Tensors::filled(Layout::Symmetric, 10, &Mat3::zeros());
        t.par_chunks_mut(3).enumerate().for_each(|(c, mut run)| {
            run.at(0).set(&Mat3::from_element(c as f64));
        });
        t.par_iter_mut().enumerate().for_each(|(q, mut s)| {
            if q % 3 != 0 {
                s.set(&Mat3::from_element(-(q as f64)));
            }
        });
        for q in 0..10 {
            let want = if q % 3 == 0 {
                (q / 3) as f64
            } else {
                -(q as f64)
            };
            assert_eq!(t.get(q), Mat3::from_element(want));
        }
    }
}
