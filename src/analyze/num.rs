//! Small numeric helpers of the analysis: fractions for display,
//! polynomial division, spectral radii.

use nalgebra::DMatrix;

/// `x` as `p/q` when a fraction with `q` ≤ 1024 is within 1e-12 of it
/// (the smallest such `q`, so the fraction is reduced), else as a decimal.
pub fn fraction(x: f64) -> String {
    if !x.is_finite() {
        return format!("{x}");
    }
    if x.abs() < 1e-14 {
        return "0".into();
    }
    for q in 1..=1024i64 {
        let p = (x * q as f64).round();
        if p.abs() < 1e15 && (x - p / q as f64).abs() <= 1e-12 {
            let p = p as i64;
            return if q == 1 {
                format!("{p}")
            } else {
                format!("{p}/{q}")
            };
        }
    }
    format!("{x:.9}")
}

/// `a` (coefficients from the lowest power up) divided by `d`, when the
/// remainder is within `tol` of zero: the quotient.
pub fn divide(a: &[f64], d: &[f64], tol: f64) -> Option<Vec<f64>> {
    let (n, k) = (a.len(), d.len());
    if k == 0 || n < k || d[k - 1] == 0.0 {
        return None;
    }
    let mut r = a.to_vec();
    let mut q = vec![0.0; n - k + 1];
    for i in (0..q.len()).rev() {
        let c = r[i + k - 1] / d[k - 1];
        q[i] = c;
        for (j, dj) in d.iter().enumerate() {
            r[i + j] -= c * dj;
        }
    }
    r[..k - 1].iter().all(|x| x.abs() <= tol).then_some(q)
}

/// The product of two polynomials.
pub fn multiply(a: &[f64], b: &[f64]) -> Vec<f64> {
    if a.is_empty() || b.is_empty() {
        return Vec::new();
    }
    let mut out = vec![0.0; a.len() + b.len() - 1];
    for (i, x) in a.iter().enumerate() {
        for (j, y) in b.iter().enumerate() {
            out[i + j] += x * y;
        }
    }
    out
}

/// Iterations of the Schur decomposition before it gives up (nalgebra's
/// default has no bound, and some defective matrices never converge).
pub const MAX_SCHUR_ITERATIONS: usize = 20_000;

/// The eigenvalues of a square matrix, or `None` where the Schur
/// decomposition does not converge within [`MAX_SCHUR_ITERATIONS`].
pub fn eigenvalues(m: &DMatrix<f64>) -> Option<Vec<nalgebra::Complex<f64>>> {
    if m.is_empty() {
        return Some(Vec::new());
    }
    // A looser tolerance (1e-13 of the neighbouring diagonal) lets the
    // deflation of a defective matrix's nearly equal eigenvalues happen.
    let try_one = |a: DMatrix<f64>, eps: f64| {
        nalgebra::linalg::Schur::try_new(a, eps, MAX_SCHUR_ITERATIONS)
            .map(|s| s.complex_eigenvalues().iter().cloned().collect::<Vec<_>>())
    };
    // Where the iteration stalls (matrices with many equal eigenvalues),
    // the transpose or a similar matrix Q^T m Q, Q orthogonal from a
    // fixed pseudo-random matrix, has the same eigenvalues.
    try_one(m.clone(), f64::EPSILON)
        .or_else(|| try_one(m.clone(), 1e-13))
        .or_else(|| try_one(m.transpose(), 1e-13))
        .or_else(|| {
            let n = m.nrows();
            let mut seed = 0x9e37_79b9_7f4a_7c15u64;
            let r = DMatrix::from_fn(n, n, |_, _| {
                seed ^= seed << 13;
                seed ^= seed >> 7;
                seed ^= seed << 17;
                (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            });
            let q = r.qr().q();
            try_one(q.transpose() * m * &q, 1e-13)
        })
        .or_else(|| {
            // Eigenvalues of equal modulus on a circle (a rotation) stall
            // the shifts; m + c I moves them off it, and c comes back off.
            let n = m.nrows();
            let c = 0.375;
            let e = try_one(m + DMatrix::identity(n, n) * c, 1e-13)?;
            Some(e.iter().map(|z| z - c).collect())
        })
}

/// The spectral radius of a square matrix (0 for an empty one), or
/// `None` where its eigenvalues cannot be computed.
pub fn spectral_radius(m: &DMatrix<f64>) -> Option<f64> {
    Some(eigenvalues(m)?.iter().map(|c| c.norm()).fold(0.0, f64::max))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fractions_and_decimals() {
        assert_eq!(fraction(0.75), "3/4");
        assert_eq!(fraction(-0.0625), "-1/16");
        assert_eq!(fraction(1.0), "1");
        assert_eq!(fraction(1.0 / 3.0), "1/3");
        assert_eq!(fraction(std::f64::consts::PI), "3.141592654");
    }

    #[test]
    fn division_by_one_plus_z() {
        // (1 + z)^2 = 1 + 2z + z^2
        let q = divide(&[1.0, 2.0, 1.0], &[1.0, 1.0], 1e-12).unwrap();
        assert_eq!(q, vec![1.0, 1.0]);
        assert!(divide(&[1.0, 0.0, 1.0], &[1.0, 1.0], 1e-12).is_none());
        assert_eq!(multiply(&[1.0, 1.0], &[1.0, 1.0]), vec![1.0, 2.0, 1.0]);
    }
}
