//! Small dense symmetric eigen-decompositions (Gram matrices of rigid modes, Schur complements of
//! a few contact rows): `S = V diag(e) V^T` for a symmetric `m x m` matrix.

/// Eigenvalues and eigenvectors (columns of `v`, row-major) of a symmetric `m x m` matrix
/// (row-major): faer's self-adjoint eigensolver, with cyclic Jacobi rotations as the fallback
/// should it report a failure.
pub fn symmetric_eigen(s: &[f64], m: usize) -> (Vec<f64>, Vec<f64>) {
    let a = faer::Mat::<f64>::from_fn(m, m, |i, j| s[i * m + j]);
    match a.self_adjoint_eigen(faer::Side::Lower) {
        Ok(evd) => {
            let (u, d) = (evd.U(), evd.S().column_vector());
            let eig = (0..m).map(|k| d[k]).collect();
            let mut v = vec![0.0; m * m];
            for i in 0..m {
                for k in 0..m {
                    v[i * m + k] = u[(i, k)];
                }
            }
            (eig, v)
        }
        Err(_) => jacobi_eigen(s, m),
    }
}

/// Eigenvalues and eigenvectors (columns of `v`, row-major) of a symmetric matrix by cyclic
/// Jacobi rotations.
pub fn jacobi_eigen(s: &[f64], m: usize) -> (Vec<f64>, Vec<f64>) {
    let mut a = s.to_vec();
    let mut v = vec![0.0; m * m];
    for i in 0..m {
        v[i * m + i] = 1.0;
    }
    for _sweep in 0..100 {
        let off: f64 = (0..m)
            .flat_map(|i| (0..m).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| a[i * m + j].powi(2))
            .sum();
        let diag: f64 = (0..m).map(|i| a[i * m + i].powi(2)).sum();
        if off <= 1e-30 * diag || off == 0.0 {
            break;
        }
        for p in 0..m {
            for q in (p + 1)..m {
                let apq = a[p * m + q];
                if apq.abs() < 1e-300 {
                    continue;
                }
                let theta = (a[q * m + q] - a[p * m + p]) / (2.0 * apq);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let sn = t * c;
                for k in 0..m {
                    let akp = a[k * m + p];
                    let akq = a[k * m + q];
                    a[k * m + p] = c * akp - sn * akq;
                    a[k * m + q] = sn * akp + c * akq;
                }
                for k in 0..m {
                    let apk = a[p * m + k];
                    let aqk = a[q * m + k];
                    a[p * m + k] = c * apk - sn * aqk;
                    a[q * m + k] = sn * apk + c * aqk;
                }
                for k in 0..m {
                    let vkp = v[k * m + p];
                    let vkq = v[k * m + q];
                    v[k * m + p] = c * vkp - sn * vkq;
                    v[k * m + q] = sn * vkp + c * vkq;
                }
            }
        }
    }
    ((0..m).map(|i| a[i * m + i]).collect(), v)
}
