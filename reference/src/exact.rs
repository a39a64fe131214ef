//! Exact sign predicates built from error-free floating-point transformations
//! (Knuth's two-sum, FMA-based two-product and Shewchuk's expansion growth).
//!
//! All results are exact for finite inputs whose products neither overflow nor
//! underflow into the subnormal range.

use glam::{DVec2, DVec3};

/// `a + b` as an unevaluated sum `s + e` with `s = fl(a + b)`, exactly.
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let b_virtual = s - a;
    let a_virtual = s - b_virtual;
    (s, (a - a_virtual) + (b - b_virtual))
}

/// `a * b` as an unevaluated sum `p + e` with `p = fl(a * b)`, exactly.
fn two_product(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, a.mul_add(b, -p))
}

/// Exact sign (-1, 0 or 1) of the sum of `terms`.
///
/// The terms are accumulated into a non-overlapping expansion whose components
/// grow in magnitude; the sign of the largest non-zero component is the sign of
/// the exact sum.
fn sign_of_sum<const N: usize>(terms: [f64; N]) -> f64 {
    let mut expansion = [0.0; N];
    for (len, term) in terms.into_iter().enumerate() {
        let mut q = term;
        for component in &mut expansion[..len] {
            let (sum, err) = two_sum(q, *component);
            *component = err;
            q = sum;
        }
        expansion[len] = q;
    }
    expansion
        .iter()
        .rev()
        .find(|c| **c != 0.0)
        .map_or(0.0, |c| c.signum())
}

/// Exact orientation of the 2D points `a`, `b`, `c`: the sign (-1, 0 or 1) of
/// `(b - a) x (c - a)`, positive when the points turn counter-clockwise
/// (in a y-up frame).
///
/// A floating-point evaluation decides whenever it is provably correct; otherwise
/// the determinant is expanded into products of the input coordinates and summed
/// exactly.
pub(crate) fn orient2d(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    let left = (b.x - a.x) * (c.y - a.y);
    let right = (b.y - a.y) * (c.x - a.x);
    let det = left - right;
    // Relative error bound of the evaluation above is (3 + 16 eps) eps ~ 3.3e-16.
    let bound = 1e-15 * (left.abs() + right.abs());
    if det > bound || -det > bound {
        return det.signum();
    }
    // (bx - ax)(cy - ay) - (by - ay)(cx - ax), expanded; the ax*ay terms cancel.
    let products = [
        two_product(b.x, c.y),
        two_product(-b.x, a.y),
        two_product(-a.x, c.y),
        two_product(-b.y, c.x),
        two_product(b.y, a.x),
        two_product(a.y, c.x),
    ];
    let mut terms = [0.0; 12];
    for (k, (p, e)) in products.into_iter().enumerate() {
        terms[2 * k] = p;
        terms[2 * k + 1] = e;
    }
    sign_of_sum(terms)
}

/// Whether the triangle has exactly zero area in 3D: the three components of the
/// cross product of its edges are the exact orientations of its projections onto
/// the coordinate planes.
pub(crate) fn has_zero_area(tri: &[DVec3; 3]) -> bool {
    [(1, 2), (2, 0), (0, 1)].iter().all(|&(i, j)| {
        let project = |p: DVec3| DVec2::new(p[i], p[j]);
        orient2d(project(tri[0]), project(tri[1]), project(tri[2])) == 0.0
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orient2d_is_exact_near_collinear() {
        // Points on the line y = x with tiny perturbations that a naive
        // evaluation misjudges.
        let a = DVec2::new(0.5, 0.5);
        let b = DVec2::new(12.0, 12.0);
        let c = DVec2::new(24.0, 24.0);
        assert_eq!(orient2d(a, b, c), 0.0);
        let above = DVec2::new(24.0, 24.0 + f64::EPSILON * 16.0);
        assert_eq!(orient2d(a, b, above), 1.0);
        let below = DVec2::new(24.0, 24.0 - f64::EPSILON * 16.0);
        assert_eq!(orient2d(a, b, below), -1.0);
        assert_eq!(orient2d(a, a, c), 0.0);
    }

    #[test]
    fn orient2d_resolves_ulp_perturbations() {
        // Shewchuk's example: a = (0.5 + i ulp, 0.5 + j ulp), b = (12, 12),
        // c = (24, 24); the exact determinant is 12 (j - i) ulp.
        let ulp = 0.5 * f64::EPSILON;
        let b = DVec2::new(12.0, 12.0);
        let c = DVec2::new(24.0, 24.0);
        for i in 0..64i32 {
            for j in 0..64 {
                let a = DVec2::new(0.5 + f64::from(i) * ulp, 0.5 + f64::from(j) * ulp);
                assert_eq!(orient2d(a, b, c), f64::from((j - i).signum()), "{i} {j}");
            }
        }
    }

    #[test]
    fn orient2d_matches_rational_evaluation_on_small_integers() {
        for ax in -3..=3i32 {
            for by in -3..=3 {
                for cx in -3..=3 {
                    let a = DVec2::new(f64::from(ax), 1.0);
                    let b = DVec2::new(2.0, f64::from(by));
                    let c = DVec2::new(f64::from(cx), -2.0);
                    let exact = (2 - ax) * (-2 - 1) - (by - 1) * (cx - ax);
                    assert_eq!(orient2d(a, b, c), f64::from(exact.signum()));
                }
            }
        }
    }
}
