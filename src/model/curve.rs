//! The evaluator of a time history (`scene::curve`): a piecewise-linear
//! curve f(t) through (t_k, f_k), held at f_0 before t_0 and at f_n after
//! t_n, and its first and second integrals from t = 0,
//!
//!   F1(t) = ∫_0^t f ds,   F2(t) = ∫_0^t F1 ds,
//!
//! exact for the piecewise-linear f (on a segment starting at s_k with value
//! a and slope m: F1 = F1_k + a τ + m τ²/2, F2 = F2_k + F1_k τ + a τ²/2 +
//! m τ³/6, τ = t − s_k). They turn an acceleration or velocity history into
//! the displacement a face follows (`model::conditions::FaceMotion`).

/// A piecewise-linear curve and its integrals from t = 0.
#[derive(Clone, Debug, PartialEq)]
pub struct TimeCurve {
    times: Vec<f64>,
    values: Vec<f64>,
    /// Segment starts s_k ≥ 0 (0, then the table's times after 0), with the
    /// value, slope and integrals at each: the last segment runs on, flat.
    starts: Vec<Segment>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
struct Segment {
    start: f64,
    value: f64,
    slope: f64,
    first: f64,
    second: f64,
}

impl TimeCurve {
    /// From (time, value) rows with strictly increasing times (validated).
    pub fn new(points: &[[f64; 2]]) -> TimeCurve {
        assert!(!points.is_empty(), "a time history has at least one row");
        let times: Vec<f64> = points.iter().map(|p| p[0]).collect();
        let values: Vec<f64> = points.iter().map(|p| p[1]).collect();
        let mut curve = TimeCurve {
            times,
            values,
            starts: Vec::new(),
        };
        curve.starts = curve.segments();
        curve
    }

    /// f(t): linear between rows, held outside them.
    pub fn value(&self, t: f64) -> f64 {
        let (ts, fs) = (&self.times, &self.values);
        let n = ts.len();
        if t <= ts[0] {
            return fs[0];
        }
        if t >= ts[n - 1] {
            return fs[n - 1];
        }
        let k = ts.partition_point(|&tk| tk <= t);
        let w = (t - ts[k - 1]) / (ts[k] - ts[k - 1]);
        fs[k - 1] + w * (fs[k] - fs[k - 1])
    }

    /// The segments on [0, ∞) over which f is linear, with the integrals at
    /// their starts.
    fn segments(&self) -> Vec<Segment> {
        let mut knots = vec![0.0];
        knots.extend(self.times.iter().copied().filter(|&t| t > 0.0));
        let mut out: Vec<Segment> = Vec::with_capacity(knots.len());
        let (mut first, mut second) = (0.0, 0.0);
        for (k, &start) in knots.iter().enumerate() {
            if let Some(prev) = out.last() {
                let tau = start - prev.start;
                (first, second) = prev.integrals(tau);
            }
            let value = self.value(start);
            let slope = match knots.get(k + 1) {
                Some(&next) => (self.value(next) - value) / (next - start),
                None => 0.0,
            };
            out.push(Segment {
                start,
                value,
                slope,
                first,
                second,
            });
        }
        out
    }

    /// The integral of order `order` (0: f itself, 1: F1, 2: F2) at t ≥ 0.
    pub fn integral(&self, order: usize, t: f64) -> f64 {
        let t = t.max(0.0);
        let k = self.starts.partition_point(|s| s.start <= t) - 1;
        let s = &self.starts[k];
        let tau = t - s.start;
        match order {
            0 => s.value + s.slope * tau,
            1 => s.integrals(tau).0,
            _ => s.integrals(tau).1,
        }
    }
}

impl Segment {
    /// (F1, F2) at τ after the segment's start.
    fn integrals(&self, tau: f64) -> (f64, f64) {
        let (a, m) = (self.value, self.slope);
        let first = self.first + a * tau + m * tau * tau / 2.0;
        let second = self.second + self.first * tau + a * tau * tau / 2.0 + m * tau.powi(3) / 6.0;
        (first, second)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn triangle() -> TimeCurve {
        TimeCurve::new(&[[0.0, 0.0], [1.0, 2.0], [3.0, 0.0]])
    }

    #[test]
    fn linear_between_rows_and_held_outside() {
        let c = triangle();
        for (t, f) in [
            (-1.0, 0.0),
            (0.0, 0.0),
            (0.25, 0.5),
            (1.0, 2.0),
            (2.0, 1.0),
            (3.0, 0.0),
            (9.0, 0.0),
        ] {
            assert!(
                (c.value(t) - f).abs() < 1e-15,
                "f({t}) = {} ≠ {f}",
                c.value(t)
            );
            assert!((c.integral(0, t.max(0.0)) - f).abs() < 1e-15);
        }
        let late = TimeCurve::new(&[[0.5, 1.0], [1.5, 3.0]]);
        assert_eq!(
            (late.value(0.0), late.value(1.0), late.value(2.0)),
            (1.0, 2.0, 3.0)
        );
    }

    /// F1 and F2 of the triangle in closed form: on [0, 1] f = 2t, F1 = t²,
    /// F2 = t³/3; on [1, 3] f = 3 − t, F1 = 1 + 2τ − τ²/2 … (τ = t − 1);
    /// after 3: F1 = 3 (the triangle's area), F2 grows by 3 per unit time.
    #[test]
    fn integrals_are_exact() {
        let c = triangle();
        let f1 = |t: f64| match t {
            t if t <= 1.0 => t * t,
            t if t <= 3.0 => {
                let s = t - 1.0;
                1.0 + 2.0 * s - s * s / 2.0
            }
            _ => 3.0,
        };
        let f2 = |t: f64| match t {
            t if t <= 1.0 => t.powi(3) / 3.0,
            t if t <= 3.0 => {
                let s = t - 1.0;
                1.0 / 3.0 + s + s * s - s.powi(3) / 6.0
            }
            t => 1.0 / 3.0 + 2.0 + 4.0 - 8.0 / 6.0 + 3.0 * (t - 3.0),
        };
        for t in [0.0, 0.3, 1.0, 1.7, 3.0, 4.5] {
            assert!((c.integral(1, t) - f1(t)).abs() < 1e-13, "F1({t})");
            assert!(
                (c.integral(2, t) - f2(t)).abs() < 1e-13,
                "F2({t}) = {}",
                c.integral(2, t)
            );
        }
    }

    /// A table that starts before 0 is integrated from 0; one that starts
    /// after 0 holds its first value from 0 to its first time.
    #[test]
    fn integrals_start_at_zero() {
        let c = TimeCurve::new(&[[-1.0, 0.0], [1.0, 2.0]]);
        // f = 1 + t on [0, 1]: F1(1) = 1.5.
        assert!((c.integral(1, 1.0) - 1.5).abs() < 1e-15);
        let c = TimeCurve::new(&[[1.0, 2.0], [2.0, 2.0]]);
        assert!((c.integral(1, 1.5) - 3.0).abs() < 1e-15);
        assert!((c.integral(2, 1.0) - 1.0).abs() < 1e-15);
    }
}
