//! The large-deflection cantilever under a vertical dead end load P: the elastica
//! EI θ'' = −P cos θ, θ(0) = 0, θ'(L) = 0 (Mattiasson 1981), optionally with
//! extension and shear (Reissner's beam), solved by shooting on θ'(0) with RK4 and
//! bisection. Lengths are in units of the beam length; k = P L²/EI.
//! Checked against Mattiasson's table in tests/verification/cantilever.rs.

/// Integrate θ'' = −k x'(θ) over s ∈ [0, 1] from θ(0) = 0, θ'(0) = kappa0, with
/// x' = cos θ + (a_e − a_s) sin θ cos θ and v' = sin θ + a_e sin²θ + a_s cos²θ
/// (Reissner's beam under the section force (0, −P): N = P sin θ, Q = P cos θ,
/// a_e = P/EA, a_s = P/(κGA); the classical elastica has a_e = a_s = 0), in `n`
/// RK4 steps. Returns [θ, θ', v, x] at s = 1.
pub fn shoot(k: f64, kappa0: f64, a_e: f64, a_s: f64, n: usize) -> [f64; 4] {
    let c = a_e - a_s;
    let f = |y: [f64; 4]| -> [f64; 4] {
        let (s, co) = y[0].sin_cos();
        let xp = co + c * s * co;
        [y[1], -k * xp, s + a_e * s * s + a_s * co * co, xp]
    };
    let h = 1.0 / n as f64;
    let add = |y: [f64; 4], d: [f64; 4], t: f64| std::array::from_fn(|i| y[i] + t * d[i]);
    let mut y = [0.0, kappa0, 0.0, 0.0];
    for _ in 0..n {
        let k1 = f(y);
        let k2 = f(add(y, k1, 0.5 * h));
        let k3 = f(add(y, k2, 0.5 * h));
        let k4 = f(add(y, k3, h));
        y = std::array::from_fn(|i| y[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]));
    }
    y
}

/// Tip deflections over the length (v/L down, u/L towards the clamp) and the tip
/// rotation, for k = P L²/EI. θ'(1) < 0 at θ'(0) = 0 and > 0 at θ'(0) = k (1 + |a_e −
/// a_s|), so bisection on θ'(0) over that bracket finds the root.
pub fn elastica(k: f64, a_e: f64, a_s: f64) -> (f64, f64, f64) {
    let (mut lo, mut hi) = (0.0, k * (1.0 + (a_e - a_s).abs()));
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if shoot(k, mid, a_e, a_s, 2000)[1] > 0.0 {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    let y = shoot(k, 0.5 * (lo + hi), a_e, a_s, 2000);
    (y[2], 1.0 - y[3], y[0])
}
