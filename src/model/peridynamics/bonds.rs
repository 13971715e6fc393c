//! The bonds of a peridynamic body, built once in the reference configuration:
//! every pair (i, j), i < j, with |ξ| = |x_j − x_i| ≤ δ (up to a relative 1e-10,
//! so lattice points at exactly δ are in: m = 3 gives 28 neighbours in 2D,
//! against πm² = 28.3 of the continuum; no partial-volume correction), found by
//! binning the points in cells of side δ. Bond k's state (|ξ|, intact) is
//! stored once for both ends. Bonds are numbered in increasing (i, j), so the
//! bonds whose lower end is i are the consecutive ids `first[i]..first[i + 1]`,
//! with their upper ends in `upper`; a particle's bonds to lower ends are
//! listed apart (`below_*`, in increasing lower end). A particle's family runs
//! through both in increasing order of the other end, the order in which every
//! per-particle sum runs, so the sums do not depend on the threads. That is
//! 21 bytes per bond (`model::memory::BYTES_PER_BOND`) and two offsets per
//! particle, against 33 for a list of both ends and a CSR of (bond, other end)
//! at each end; the sums read a particle's own bonds in sequence.

use crate::dim::Vector;
use crate::parallel::MIN_PARALLEL_LEN;
use rayon::prelude::*;
use std::collections::BTreeMap;

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Bonds {
    /// The bonds whose lower end is particle i are the ids `first[i]..first[i + 1]`.
    pub first: Vec<u32>,
    /// The upper end j of each bond.
    pub upper: Vec<u32>,
    /// Reference length |ξ| of each bond.
    pub length: Vec<f64>,
    /// Whether each bond is intact (a broken bond never heals).
    pub intact: Vec<bool>,
    /// Whether each particle is exposed: fewer bonds than the most any
    /// particle of the points has (near a face or a notch), or one broken. Only
    /// an exposed particle can come near a particle it is not bonded to
    /// (`physics::peridynamics::short_range`).
    pub exposed: Vec<bool>,
    /// Particle j's bonds to lower ends are entries `below_offset[j]..below_offset[j + 1]`
    /// of `below_bond` (their ids) and `below_end` (their lower ends, increasing).
    pub below_offset: Vec<u32>,
    pub below_bond: Vec<u32>,
    pub below_end: Vec<u32>,
}

impl Bonds {
    /// The bonds of points `x` (reference positions) within horizon `delta`.
    pub fn build<const D: usize>(x: &[Vector<D>], delta: f64) -> Bonds {
        Bonds::build_where(x, delta, |_, _| true)
    }

    /// The bonds of points `x` within horizon `delta` that `keep(i, j)` accepts
    /// (e.g. those whose segment stays inside the body, `Geometry::holds_segment`).
    pub fn build_where<const D: usize>(
        x: &[Vector<D>],
        delta: f64,
        keep: impl Fn(usize, usize) -> bool,
    ) -> Bonds {
        let reach = delta * (1.0 + 1e-10);
        let cell =
            |p: &Vector<D>| -> [i64; D] { std::array::from_fn(|d| (p[d] / delta).floor() as i64) };
        let mut cells: BTreeMap<[i64; D], Vec<u32>> = BTreeMap::new();
        for (i, p) in x.iter().enumerate() {
            cells.entry(cell(p)).or_default().push(i as u32);
        }
        let mut first = Vec::with_capacity(x.len() + 1);
        let mut upper = Vec::new();
        let mut length = Vec::new();
        for (i, p) in x.iter().enumerate() {
            first.push(upper.len() as u32);
            let mut near: Vec<u32> = Vec::new();
            let c = cell(p);
            for around in 0..3usize.pow(D as u32) {
                let key: [i64; D] =
                    std::array::from_fn(|d| c[d] + (around / 3usize.pow(d as u32) % 3) as i64 - 1);
                if let Some(list) = cells.get(&key) {
                    near.extend(list.iter().filter(|&&j| j as usize > i));
                }
            }
            near.sort_unstable();
            for j in near {
                let l = (x[j as usize] - p).norm();
                if l <= reach && keep(i, j as usize) {
                    upper.push(j);
                    length.push(l);
                }
            }
        }
        first.push(upper.len() as u32);
        let (below_offset, below_bond, below_end) = below(x.len(), &first, &upper);
        let count = |i: usize| {
            (first[i + 1] - first[i]) as usize + (below_offset[i + 1] - below_offset[i]) as usize
        };
        let most = (0..x.len()).map(count).max().unwrap_or(0);
        Bonds {
            exposed: (0..x.len()).map(|i| count(i) < most).collect(),
            intact: vec![true; upper.len()],
            first,
            upper,
            length,
            below_offset,
            below_bond,
            below_end,
        }
    }

    pub fn len(&self) -> usize {
        self.upper.len()
    }

    pub fn is_empty(&self) -> bool {
        self.upper.is_empty()
    }

    /// The ends (i, j), i < j, of bond k (a search over `first`: for checks and
    /// reports, not for the per-step sums).
    pub fn ends(&self, k: usize) -> [usize; 2] {
        let i = self.first.partition_point(|&f| f as usize <= k) - 1;
        [i, self.upper[k] as usize]
    }

    /// Particle i's bonds (bond id, other end), intact or not, in increasing
    /// order of the other end.
    pub fn family(&self, i: usize) -> impl Iterator<Item = (usize, usize)> + '_ {
        let below = self.below_offset[i] as usize..self.below_offset[i + 1] as usize;
        let own = self.first[i] as usize..self.first[i + 1] as usize;
        (below.map(|e| (self.below_bond[e] as usize, self.below_end[e] as usize)))
            .chain(own.map(|k| (k, self.upper[k] as usize)))
    }

    /// Σ over particle i's intact bonds k (other end j), in family order, of f(k, j).
    pub fn gather<const D: usize>(
        &self,
        i: usize,
        f: impl Fn(usize, usize) -> Vector<D>,
    ) -> Vector<D> {
        let mut sum = Vector::<D>::zeros();
        self.each_intact(i, |k, j| sum += f(k, j));
        sum
    }

    /// f(k, j) for each of particle i's intact bonds k (other end j), in family
    /// order (two loops, not `family`'s chain: this is the per-step sum).
    pub fn each_intact(&self, i: usize, mut f: impl FnMut(usize, usize)) {
        for e in self.below_offset[i] as usize..self.below_offset[i + 1] as usize {
            let k = self.below_bond[e] as usize;
            if self.intact[k] {
                f(k, self.below_end[e] as usize);
            }
        }
        for k in self.first[i] as usize..self.first[i + 1] as usize {
            if self.intact[k] {
                f(k, self.upper[k] as usize);
            }
        }
    }

    /// As `gather`, of a scalar.
    pub fn gather_scalar(&self, i: usize, f: impl Fn(usize, usize) -> f64) -> f64 {
        let mut sum = 0.0;
        self.each_intact(i, |k, j| sum += f(k, j));
        sum
    }

    /// The stretch s = (|y_j − y_i| − |ξ|)/|ξ| of bond k between i and j at positions y.
    pub fn stretch_between<const D: usize>(
        &self,
        k: usize,
        i: usize,
        j: usize,
        y: &[Vector<D>],
    ) -> f64 {
        ((y[j] - y[i]).norm() - self.length[k]) / self.length[k]
    }

    /// The stretch of bond k at positions y.
    pub fn stretch<const D: usize>(&self, k: usize, y: &[Vector<D>]) -> f64 {
        let [i, j] = self.ends(k);
        self.stretch_between(k, i, j, y)
    }

    /// Break, irreversibly, the intact bonds with s > s0 at positions y (no
    /// fracture when s0 is infinite). Returns how many broke.
    pub fn break_stretched<const D: usize>(&mut self, y: &[Vector<D>], s0: f64) -> usize {
        if s0.is_infinite() {
            return 0;
        }
        let this = &*self;
        let stretched: Vec<(usize, usize)> = (0..y.len())
            .into_par_iter()
            .with_min_len(MIN_PARALLEL_LEN)
            .flat_map_iter(|i| {
                (this.first[i] as usize..this.first[i + 1] as usize)
                    .filter(move |&k| {
                        this.intact[k] && this.stretch_between(k, i, this.upper[k] as usize, y) > s0
                    })
                    .map(move |k| (i, k))
            })
            .collect();
        for &(i, k) in &stretched {
            self.break_between(k, i);
        }
        stretched.len()
    }

    /// Break bond k for good (its ends exposed).
    pub fn break_bond(&mut self, k: usize) {
        let [i, _] = self.ends(k);
        self.break_between(k, i);
    }

    /// Break bond k, whose lower end is i.
    fn break_between(&mut self, k: usize, i: usize) {
        self.intact[k] = false;
        self.exposed[i] = true;
        self.exposed[self.upper[k] as usize] = true;
    }

    /// Does an intact bond join particles i and j? (A binary search among the
    /// lower one's own bonds, whose upper ends increase.)
    pub fn joined(&self, i: usize, j: usize) -> bool {
        let (lo, hi) = (i.min(j), i.max(j));
        let own = self.first[lo] as usize..self.first[lo + 1] as usize;
        match self.upper[own.clone()].binary_search(&(hi as u32)) {
            Ok(e) => self.intact[own.start + e],
            Err(_) => false,
        }
    }

    /// Damage φ_i = 1 − Σ_intact V_j / Σ_all V_j (digest Part 2 §2.2); 0 for a
    /// particle without bonds.
    pub fn damage(&self, i: usize, volume: &[f64]) -> f64 {
        let all: f64 = self.family(i).map(|(_, j)| volume[j]).sum();
        if all == 0.0 {
            return 0.0;
        }
        let intact = self.gather_scalar(i, |_, j| volume[j]);
        1.0 - intact / all
    }
}

/// Each of the `n` particles' bonds to lower ends, from the bonds' lower-end
/// ranges `first` and upper ends `upper`: offsets, bond ids and lower ends,
/// each particle's in increasing lower end (the bonds come in increasing
/// (i, j)).
fn below(n: usize, first: &[u32], upper: &[u32]) -> (Vec<u32>, Vec<u32>, Vec<u32>) {
    let mut count = vec![0u32; n + 1];
    for &j in upper {
        count[j as usize + 1] += 1;
    }
    for i in 0..n {
        count[i + 1] += count[i];
    }
    let offset = count.clone();
    let mut next = count;
    let mut bond = vec![0u32; upper.len()];
    let mut end = vec![0u32; upper.len()];
    for i in 0..n {
        for k in first[i] as usize..first[i + 1] as usize {
            let e = next[upper[k] as usize] as usize;
            (bond[e], end[e]) = (k as u32, i as u32);
            next[upper[k] as usize] += 1;
        }
    }
    (offset, bond, end)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lattice(n: usize, dx: f64) -> Vec<Vector<2>> {
        (0..n * n)
            .map(|q| Vector::<2>::new((q % n) as f64 * dx, (q / n) as f64 * dx))
            .collect()
    }

    #[test]
    fn an_interior_point_has_the_28_lattice_neighbours_of_m_3_each_bond_once() {
        let x = lattice(9, 0.1);
        let b = Bonds::build(&x, 0.3);
        let centre = 4 * 9 + 4;
        assert_eq!(b.family(centre).count(), 28);
        // Each bond once, i < j, in increasing (i, j); in the family of both
        // ends, each family in increasing other end.
        let ends: Vec<[usize; 2]> = (0..b.len()).map(|k| b.ends(k)).collect();
        assert!(ends.windows(2).all(|w| w[0] < w[1]));
        assert!(ends.iter().all(|[i, j]| i < j));
        let mut seen = vec![0; b.len()];
        for i in 0..x.len() {
            let family: Vec<(usize, usize)> = b.family(i).collect();
            assert!(family.windows(2).all(|w| w[0].1 < w[1].1));
            for (k, j) in family {
                let [p, q] = ends[k];
                assert!(p == i && q == j || q == i && p == j);
                seen[k] += 1;
            }
        }
        assert!(seen.iter().all(|&s| s == 2));
        // Against a brute-force count.
        let brute = (0..x.len())
            .flat_map(|i| (i + 1..x.len()).map(move |j| (i, j)))
            .filter(|&(i, j)| (x[j] - x[i]).norm() <= 0.3 * (1.0 + 1e-10))
            .count();
        assert_eq!(b.len(), brute);
    }

    /// A slit one lattice row wide, from the left edge to the middle: no bond
    /// joins the rows on either side of it (they are δ = 3 Δx apart at the
    /// lattice's x, so the plain horizon would bond them); beyond its tip the
    /// bonds are those of the plain lattice, and a convex body keeps them all.
    #[test]
    fn no_bond_crosses_a_notch_of_its_body() {
        use crate::model::geometry::Geometry;
        let dx = 0.1;
        // Points of a 9 × 9 lattice but for the slit's row y = 0.4, x < 0.45.
        let x: Vec<Vector<2>> = lattice(9, dx)
            .into_iter()
            .filter(|p| !((p.y - 0.4).abs() < 1e-9 && p.x < 0.45))
            .collect();
        let body = Geometry::Polygon(vec![
            vec![-0.05, -0.05],
            vec![0.85, -0.05],
            vec![0.85, 0.85],
            vec![-0.05, 0.85],
            vec![-0.05, 0.45],
            vec![0.45, 0.45],
            vec![0.45, 0.35],
            vec![-0.05, 0.35],
        ]);
        let keep =
            |i: usize, j: usize| body.holds_segment(x[i].as_slice(), x[j].as_slice(), dx / 2.0);
        let (seen, plain) = (Bonds::build_where(&x, 0.3, keep), Bonds::build(&x, 0.3));
        let crosses = |b: &Bonds| {
            (0..b.len())
                .map(|k| b.ends(k))
                .filter(|[i, j]| {
                    let (p, q) = (x[*i], x[*j]);
                    (p.y - 0.4) * (q.y - 0.4) < 0.0 && p.x.max(q.x) < 0.45 - 1e-9
                })
                .count()
        };
        assert!(
            crosses(&plain) > 0,
            "the plain horizon bonds across the slit"
        );
        assert_eq!(crosses(&seen), 0);
        // Away from the slit (both ends at x > 0.75: beyond δ from it) nothing changes.
        let far = |b: &Bonds| {
            (0..b.len())
                .map(|k| b.ends(k))
                .filter(|[i, j]| x[*i].x > 0.75 && x[*j].x > 0.75)
                .count()
        };
        assert_eq!(far(&seen), far(&plain));
        let square = Geometry::Box {
            min: vec![-0.05; 2],
            max: vec![0.85; 2],
        };
        let all = lattice(9, dx);
        let kept = Bonds::build_where(&all, 0.3, |i, j| {
            square.holds_segment(all[i].as_slice(), all[j].as_slice(), dx / 2.0)
        });
        assert_eq!(kept, Bonds::build(&all, 0.3));
    }

    /// A polygon's edges are tested exactly: a slit far thinner than any
    /// sampling step still cuts the segments across it, and only those.
    #[test]
    fn a_hair_thin_slit_cuts_the_segments_across_it() {
        use crate::model::geometry::Geometry;
        let slit = Geometry::Polygon(vec![
            vec![0.0, 0.0],
            vec![1.0, 0.0],
            vec![1.0, 1.0],
            vec![0.0, 1.0],
            vec![0.0, 0.5005],
            vec![0.5, 0.5005],
            vec![0.5, 0.4995],
            vec![0.0, 0.4995],
        ]);
        assert!(!slit.holds_segment(&[0.2, 0.3], &[0.2, 0.7], 0.5));
        assert!(!slit.holds_segment(&[0.1, 0.45], &[0.45, 0.55], 0.5));
        assert!(slit.holds_segment(&[0.8, 0.3], &[0.8, 0.7], 0.5));
        assert!(slit.holds_segment(&[0.2, 0.3], &[0.4, 0.45], 0.5));
    }

    /// The particles near a face are exposed, the interior ones not; a bond
    /// broken by stretch and the same bond broken by id (a restart) leave the
    /// same state, its ends exposed.
    #[test]
    fn faces_and_broken_bonds_expose_their_particles() {
        let x = lattice(9, 0.1);
        let mut b = Bonds::build(&x, 0.3);
        // Within δ = 3 Δx of a face: all but the 3 × 3 in the middle.
        let interior: Vec<usize> = (0..x.len()).filter(|&i| !b.exposed[i]).collect();
        assert_eq!(interior, vec![30, 31, 32, 39, 40, 41, 48, 49, 50]);
        let mut by_id = b.clone();
        // Stretch the bond between the centre 40 and 41 only.
        let k = (0..b.len()).find(|&k| b.ends(k) == [40, 41]).unwrap();
        let mut y = x.clone();
        y[41].x += 0.01;
        let s0 = 0.75 * b.stretch(k, &y);
        let others = (0..b.len())
            .filter(|&q| q != k)
            .all(|q| b.stretch(q, &y) < s0);
        assert!(others);
        assert_eq!(b.break_stretched(&y, s0), 1);
        by_id.break_bond(k);
        assert_eq!(b, by_id);
        assert!(b.exposed[40] && b.exposed[41] && !b.exposed[31]);
    }
}
