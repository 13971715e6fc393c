//! The smoother of the V-cycle: a Chebyshev polynomial (Adams, Brezina, Hu &
//! Tuminaro 2003; Saad 2003, Algorithm 12.1) in the nodal block-Jacobi
//! preconditioned operator D⁻¹A, on an interval below the largest eigenvalue
//! of D⁻¹A that a few Lanczos steps estimate. The blocks are the unknowns of
//! each node (all its components together).

use super::operator::Operator;
use crate::solver::linear::iterative::Preconditioner;
use crate::solver::linear::preconditioner::BlockJacobi;

/// Degree of the Chebyshev polynomial of each pre- and post-smoothing.
pub const SMOOTHING_STEPS: usize = 2;
/// The smoother damps the eigenvalues of D⁻¹A in [λ_max / EIGEN_RATIO, λ_max].
pub const EIGEN_RATIO: f64 = 10.0;
/// Lanczos (CG) steps for λ_max(D⁻¹A).
pub const ESTIMATE_STEPS: usize = 10;

/// The smoother of one level above the coarsest: nodal block Jacobi D and the
/// estimated largest eigenvalue of D⁻¹A, times 1.1.
pub(super) struct Smoother {
    blocks: BlockJacobi,
    lambda: f64,
}

impl Smoother {
    /// The smoother of operator `a` with the blocks of unknowns `blocks`
    /// (one per node, `Transfer::fine_blocks`).
    pub(super) fn new(a: &Operator, blocks: &[Vec<usize>]) -> Smoother {
        let values: Vec<Vec<f64>> = blocks.iter().map(|b| a.block_values(b)).collect();
        let blocks = BlockJacobi::new(
            blocks
                .iter()
                .zip(&values)
                .map(|(u, v)| (u.as_slice(), v.as_slice())),
        );
        let lambda = 1.1 * largest_eigenvalue(a, &blocks);
        Smoother { blocks, lambda }
    }
}

/// λ_max(D⁻¹A) from ESTIMATE_STEPS steps of conjugate gradients preconditioned
/// by D on A x = b with a fixed b: the largest eigenvalue of the Lanczos
/// tridiagonal matrix that CG's coefficients define (Saad 2003, §6.7.3), a lower
/// bound that converges fast to the top of the spectrum.
fn largest_eigenvalue(a: &Operator, d: &BlockJacobi) -> f64 {
    let n = a.rows();
    if n == 0 {
        return 1.0;
    }
    let mut r: Vec<f64> = (0..n).map(|i| 1.0 + 0.5 * (i as f64).sin()).collect();
    let (mut z, mut q) = (vec![0.0; n], vec![0.0; n]);
    d.apply(&r, &mut z);
    let mut p = z.clone();
    let mut rz: f64 = r.iter().zip(&z).map(|(a, b)| a * b).sum();
    let (mut diagonal, mut off) = (Vec::new(), Vec::new());
    let (mut alpha_prev, mut beta_prev) = (0.0, 0.0);
    for k in 0..ESTIMATE_STEPS {
        a.apply(&p, &mut q);
        let pq: f64 = p.iter().zip(&q).map(|(a, b)| a * b).sum();
        if !(pq > 0.0 && rz > 0.0) {
            break;
        }
        let alpha = rz / pq;
        // T_kk = 1/α_k + β_{k−1}/α_{k−1}, T_{k−1,k} = √β_{k−1}/α_{k−1}.
        diagonal.push(1.0 / alpha + if k > 0 { beta_prev / alpha_prev } else { 0.0 });
        if k > 0 {
            off.push(beta_prev.sqrt() / alpha_prev);
        }
        r.iter_mut().zip(&q).for_each(|(ri, qi)| *ri -= alpha * qi);
        d.apply(&r, &mut z);
        let rz_next: f64 = r.iter().zip(&z).map(|(a, b)| a * b).sum();
        let beta = rz_next / rz;
        p.iter_mut()
            .zip(&z)
            .for_each(|(pi, zi)| *pi = zi + beta * *pi);
        (alpha_prev, beta_prev, rz) = (alpha, beta, rz_next);
    }
    let m = diagonal.len();
    if m == 0 {
        return 1.0;
    }
    let t = nalgebra::DMatrix::<f64>::from_fn(m, m, |i, j| {
        if i == j {
            diagonal[i]
        } else if i + 1 == j {
            off[i]
        } else if j + 1 == i {
            off[j]
        } else {
            0.0
        }
    });
    t.symmetric_eigenvalues().max()
}

/// SMOOTHING_STEPS Chebyshev iterations for A x = b preconditioned by the
/// level's block Jacobi D, on [λ/EIGEN_RATIO, λ] (Saad 2003, Algorithm 12.1).
pub(super) fn chebyshev(a: &Operator, smoother: &Smoother, b: &[f64], x: &mut [f64]) {
    let n = b.len();
    let upper = smoother.lambda;
    let lower = upper / EIGEN_RATIO;
    let theta = 0.5 * (upper + lower);
    let delta = 0.5 * (upper - lower);
    let sigma = theta / delta;
    let mut rho = 1.0 / sigma;
    let (mut r, mut z, mut d) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    a.apply(x, &mut r);
    r.iter_mut().zip(b).for_each(|(ri, bi)| *ri = bi - *ri);
    smoother.blocks.apply(&r, &mut z);
    d.iter_mut().zip(&z).for_each(|(di, zi)| *di = zi / theta);
    for k in 0..SMOOTHING_STEPS {
        x.iter_mut().zip(&d).for_each(|(xi, di)| *xi += di);
        if k + 1 == SMOOTHING_STEPS {
            break;
        }
        a.apply(&d, &mut z);
        r.iter_mut().zip(&z).for_each(|(ri, adi)| *ri -= adi);
        smoother.blocks.apply(&r, &mut z);
        let rho_next = 1.0 / (2.0 * sigma - rho);
        d.iter_mut()
            .zip(&z)
            .for_each(|(di, zi)| *di = rho_next * rho * *di + 2.0 * rho_next / delta * zi);
        rho = rho_next;
    }
}
