//! How well conditioned a factored system is, and how many digits its answer can have lost.
//!
//! The 1-norm condition number `kappa_1(A) = ||A||_1 ||A^-1||_1` of a symmetric matrix is
//! estimated without forming `A^-1`: `||A||_1` is the largest column sum of `|a_ij|` (both
//! triangles of the stored upper one), and `||A^-1||_1` comes from Hager's estimator as refined
//! by Higham (W. W. Hager, "Condition estimates", SIAM J. Sci. Stat. Comput. 5 (1984) 311-316;
//! N. J. Higham, "FORTRAN codes for estimating the one-norm of a real or complex matrix, with
//! applications to condition estimation", ACM TOMS 14 (1988) 381-396, Algorithm 4.1; also
//! LAPACK's `xLACON`). It maximizes the convex function `||A^-1 x||_1` over the unit 1-ball by
//! a gradient ascent that visits its vertices `e_j`: `y = A^-1 x`, `xi = sign(y)`,
//! `z = A^-T xi`; stop when `||z||_inf <= z^T x` (a local maximum), else `x = e_j` with
//! `j = argmax |z_j|`. Higham's alternating vector `b_i = (-1)^i (1 + i / (n - 1))` gives a
//! second lower bound `2 ||A^-1 b||_1 / (3 n)` that catches the matrices where the ascent stops
//! early. The estimate is a lower bound, in practice within a factor of 3 of the true value,
//! and costs at most `2 * MAX_SWEEPS + 1` solves with the factorization already at hand (a
//! sweep whose sign vector `xi` repeats the sweep before's stops without its `z` solve, as
//! LAPACK's `xLACN2` does). For a
//! symmetric `A`, `A^-T = A^-1`, so only the solve is needed; for a general (unsymmetric) `A`
//! factored by LU, `z = A^-T xi` is the LU's transpose solve (`U^T L^T P z = xi`).
//!
//! The digits an answer can lose are `log10(kappa)`; a backward-stable solve with that
//! condition number leaves a relative residual of order `eps kappa` in the worst case (Higham,
//! *Accuracy and Stability of Numerical Algorithms*, 2nd ed., SIAM 2002, ch. 7), so an
//! equilibrium residual far above `eps kappa` is not round-off, and one far above `1e-12` has
//! lost digits whatever its cause.

use crate::solver::sparse::SymmetricPattern;

/// Most ascent sweeps of the estimator (Higham's `ITMAX = 5`).
pub const MAX_SWEEPS: usize = 5;

/// A relative equilibrium residual at or below this is at round-off in the tool's reports (the
/// tolerance the force-balance checks of the catalogue use); above it the run warns.
pub const EQUILIBRIUM_ROUND_OFF: f64 = 1e-12;

/// `||A||_1` (= `||A||_inf`) of the symmetric matrix whose upper triangle `values` is stored on
/// `pattern`; NaN when an entry is NaN.
pub fn symmetric_norm1(pattern: &SymmetricPattern, values: &[f64]) -> f64 {
    let mut column = vec![0.0f64; pattern.n];
    for j in 0..pattern.n {
        for k in pattern.col_ptr[j]..pattern.col_ptr[j + 1] {
            let i = pattern.row_idx[k];
            let a = values[k].abs();
            column[j] += a;
            if i != j {
                column[i] += a;
            }
        }
    }
    crate::solver::linear::max_abs(&column)
}

/// Hager-Higham estimate of `||A^-1||_1` for a symmetric `n x n` matrix `A`, given
/// `solve(b)`, which overwrites `b` with `A^-1 b`.
pub fn inverse_norm1_symmetric(n: usize, mut solve: impl FnMut(&mut [f64])) -> f64 {
    inverse_norm1(n, |b, _| solve(b))
}

/// Hager-Higham estimate of `||A^-1||_1` for a general `n x n` matrix `A`, given
/// `solve(b, transpose)`, which overwrites `b` with `A^-1 b` (`transpose`: `A^-T b`), e.g. by
/// an LU factorization and its transpose.
pub fn inverse_norm1(n: usize, mut solve: impl FnMut(&mut [f64], bool)) -> f64 {
    inverse_norm1_columns(n, |b, transpose| {
        for column in b.chunks_mut(n.max(1)) {
            solve(column, transpose)
        }
    })
}

/// [`inverse_norm1`] given `solve(b, transpose)` that solves every column of `b` (`n` values
/// each, one after the other) at once: the first sweep's solve and Higham's alternating vector
/// share one pass over the factor, which costs about one column's solve when the solve is
/// bound by reading the factor. The estimate is the same.
pub fn inverse_norm1_columns(n: usize, mut solve: impl FnMut(&mut [f64], bool)) -> f64 {
    if n == 0 {
        return 0.0;
    }
    let norm1 = |v: &[f64]| v.iter().map(|a| a.abs()).sum::<f64>();
    let mut x = vec![1.0 / n as f64; n];
    // Higham's alternating vector, solved beside the first sweep's `x`
    let mut alternating: Vec<f64> = (0..n)
        .map(|i| {
            let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
            let ramp = if n > 1 {
                i as f64 / (n - 1) as f64
            } else {
                0.0
            };
            sign * (1.0 + ramp)
        })
        .collect();
    let mut estimate = 0.0f64;
    let mut last_vertex = usize::MAX;
    let mut last_signs: Option<Vec<f64>> = None;
    for sweep in 0..MAX_SWEEPS {
        let mut y = x.clone();
        if sweep == 0 {
            y.extend_from_slice(&alternating);
            solve(&mut y, false);
            alternating.copy_from_slice(&y[n..]);
            y.truncate(n);
        } else {
            solve(&mut y, false);
        }
        let gamma = norm1(&y);
        if !gamma.is_finite() {
            return f64::INFINITY;
        }
        // a vertex that does not raise the estimate ends the ascent
        if sweep > 0 && gamma <= estimate {
            break;
        }
        estimate = gamma;
        let signs: Vec<f64> = y
            .iter()
            .map(|v| if *v >= 0.0 { 1.0 } else { -1.0 })
            .collect();
        // the sign vector of the sweep before again: its `z` is known, the ascent is at a
        // vertex it has visited (LAPACK's xLACN2 test), so the solve is saved
        if last_signs.as_ref() == Some(&signs) {
            break;
        }
        let mut z = signs.clone();
        last_signs = Some(signs);
        solve(&mut z, true);
        let (j, zj) = z.iter().enumerate().fold((0, -1.0f64), |(bj, bv), (i, v)| {
            if v.abs() > bv {
                (i, v.abs())
            } else {
                (bj, bv)
            }
        });
        let ztx: f64 = z.iter().zip(&x).map(|(a, b)| a * b).sum();
        if zj <= ztx || j == last_vertex {
            break;
        }
        last_vertex = j;
        x.iter_mut().for_each(|v| *v = 0.0);
        x[j] = 1.0;
    }
    let alternative = 2.0 * norm1(&alternating) / (3.0 * n as f64);
    if alternative.is_nan() {
        return f64::INFINITY;
    }
    estimate.max(alternative)
}

/// Estimated `kappa_1(A)` of a factored symmetric matrix (`values` on `pattern`, `solve` its
/// factorization's solve): infinite when the inverse's estimate is not finite.
pub fn condition_estimate_symmetric(
    pattern: &SymmetricPattern,
    values: &[f64],
    mut solve: impl FnMut(&mut [f64]),
) -> f64 {
    let n = pattern.n;
    condition_estimate_symmetric_columns(pattern, values, |b| {
        for column in b.chunks_mut(n.max(1)) {
            solve(column)
        }
    })
}

/// [`condition_estimate_symmetric`] given a `solve` of every column of `b` at once (see
/// [`inverse_norm1_columns`]).
pub fn condition_estimate_symmetric_columns(
    pattern: &SymmetricPattern,
    values: &[f64],
    mut solve: impl FnMut(&mut [f64]),
) -> f64 {
    let norm = symmetric_norm1(pattern, values);
    let inverse = inverse_norm1_columns(pattern.n, |b, _| solve(b));
    if norm.is_finite() && inverse.is_finite() {
        norm * inverse
    } else {
        f64::INFINITY
    }
}

/// `||A||_1` (largest column sum of `|a_ij|`) of a general matrix in compressed columns.
pub fn general_norm1(col_ptr: &[usize], values: &[f64]) -> f64 {
    let columns: Vec<f64> = col_ptr
        .windows(2)
        .map(|w| values[w[0]..w[1]].iter().map(|a| a.abs()).sum())
        .collect();
    crate::solver::linear::max_abs(&columns)
}

/// Estimated `kappa_1(A)` of a factored general matrix (compressed columns `col_ptr`,
/// `values`; `solve(b, transpose)` its factorization's solves with `A` and `A^T`): infinite
/// when the inverse's estimate is not finite.
pub fn condition_estimate_general(
    col_ptr: &[usize],
    values: &[f64],
    solve: impl FnMut(&mut [f64], bool),
) -> f64 {
    let norm = general_norm1(col_ptr, values);
    let inverse = inverse_norm1(col_ptr.len() - 1, solve);
    if norm.is_finite() && inverse.is_finite() {
        norm * inverse
    } else {
        f64::INFINITY
    }
}

/// The decimal digits a condition number `kappa` can cost an answer: `log10(kappa)`, at least 0.
pub fn lost_digits(kappa: f64) -> f64 {
    if kappa.is_finite() && kappa > 1.0 {
        kappa.log10()
    } else if kappa.is_finite() {
        0.0
    } else {
        f64::INFINITY
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::sparse::{Cholesky, PatternBuilder};

    /// Dense `||A^-1||_1` by Gauss-Jordan elimination with partial pivoting (the independent
    /// reference for the estimator).
    fn dense_inverse_norm1(a: &[f64], n: usize) -> f64 {
        let mut m = a.to_vec();
        let mut inv = vec![0.0; n * n];
        for i in 0..n {
            inv[i * n + i] = 1.0;
        }
        for c in 0..n {
            let p = (c..n)
                .max_by(|&r, &s| m[r * n + c].abs().total_cmp(&m[s * n + c].abs()))
                .unwrap();
            for k in 0..n {
                m.swap(c * n + k, p * n + k);
                inv.swap(c * n + k, p * n + k);
            }
            let d = m[c * n + c];
            for k in 0..n {
                m[c * n + k] /= d;
                inv[c * n + k] /= d;
            }
            for r in 0..n {
                if r != c {
                    let f = m[r * n + c];
                    for k in 0..n {
                        m[r * n + k] -= f * m[c * n + k];
                        inv[r * n + k] -= f * inv[c * n + k];
                    }
                }
            }
        }
        (0..n)
            .map(|j| (0..n).map(|i| inv[i * n + j].abs()).sum::<f64>())
            .fold(0.0, f64::max)
    }

    /// A symmetric positive definite tridiagonal matrix with diagonal `d` and off-diagonal `e`,
    /// as a pattern, its upper values and the dense matrix.
    fn tridiagonal(d: &[f64], e: &[f64]) -> (SymmetricPattern, Vec<f64>, Vec<f64>) {
        let n = d.len();
        let mut b = PatternBuilder::new(n);
        for i in 0..n - 1 {
            b.add_block(&[i, i + 1]);
        }
        let p = b.build();
        let mut values = vec![0.0; p.nnz()];
        let mut dense = vec![0.0; n * n];
        for i in 0..n {
            values[p.position(i, i).unwrap()] = d[i];
            dense[i * n + i] = d[i];
            if i + 1 < n {
                values[p.position(i, i + 1).unwrap()] = e[i];
                dense[i * n + i + 1] = e[i];
                dense[(i + 1) * n + i] = e[i];
            }
        }
        (p, values, dense)
    }

    fn estimate(p: &SymmetricPattern, values: &[f64]) -> f64 {
        let f = Cholesky::analyse(p, &crate::solver::sparse::UNLIMITED)
            .unwrap()
            .factor(p, values)
            .unwrap();
        condition_estimate_symmetric(p, values, |b| f.solve_in_place(b))
    }

    #[test]
    fn a_diagonal_matrix_has_the_ratio_of_its_extreme_entries() {
        // kappa_1(diag(d)) = max d / min d exactly, and the estimator finds the vertex
        let d = [3.0, 1e-6, 7.0, 2.0, 5e4];
        let (p, values, _) = tridiagonal(&d, &[0.0; 4]);
        let kappa = estimate(&p, &values);
        let exact = 5e4 / 1e-6;
        assert!((kappa - exact).abs() <= 1e-12 * exact, "{kappa} vs {exact}");
    }

    /// On `diag(1, 2, ..., n)` the ascent moves to the vertex `e_0` after its first sweep;
    /// there `sign(A^-1 e_0)` is the first sweep's sign vector, so the second sweep's `z`
    /// solve is saved: four solves in all (two, one, and the alternating vector), and the
    /// estimate is exact (`||A^-1||_1 = 1`).
    #[test]
    fn a_repeated_sign_vector_saves_its_solve() {
        let n = 6;
        let d: Vec<f64> = (1..=n).map(|i| i as f64).collect();
        let mut solves = 0;
        let inverse = inverse_norm1_symmetric(n, |b| {
            solves += 1;
            b.iter_mut().zip(&d).for_each(|(v, d)| *v /= d);
        });
        assert_eq!(inverse, 1.0);
        assert_eq!(solves, 4, "{solves} solves");
    }

    /// Solving every column at once, the first sweep and the alternating vector share a
    /// pass: three passes on `diag(1, .., n)` instead of four solves, the same estimate; and
    /// on a tridiagonal matrix the same value as the column-by-column estimator.
    #[test]
    fn the_alternating_vector_shares_the_first_pass() {
        let n = 6;
        let d: Vec<f64> = (1..=n).map(|i| i as f64).collect();
        let mut passes = 0;
        let inverse = inverse_norm1_columns(n, |b, _| {
            passes += 1;
            for column in b.chunks_mut(n) {
                column.iter_mut().zip(&d).for_each(|(v, d)| *v /= d);
            }
        });
        assert_eq!(inverse, 1.0);
        assert_eq!(passes, 3, "{passes} passes");
        let (p, values, _) = tridiagonal(&vec![2.0; 40], &vec![-1.0; 39]);
        let f = Cholesky::analyse(&p, &crate::solver::sparse::UNLIMITED)
            .unwrap()
            .factor(&p, &values)
            .unwrap();
        let one = condition_estimate_symmetric(&p, &values, |b| f.solve_in_place(b));
        let all = condition_estimate_symmetric_columns(&p, &values, |b| {
            f.solve_columns_with_trailing(b, b.len() / 40, |_| {})
        });
        assert!((one - all).abs() <= 1e-12 * one, "{one} vs {all}");
    }

    #[test]
    fn the_laplacian_estimate_matches_the_dense_inverse() {
        // 1D Laplacian tridiag(-1, 2, -1): ||A||_1 = 3 (n = 2) or 4, ||A^-1||_1 from the dense
        // inverse; the inverse is entrywise positive, where Hager's ascent is exact
        for n in [2, 5, 40, 200] {
            let (p, values, dense) = tridiagonal(&vec![2.0; n], &vec![-1.0; n - 1]);
            let norm = if n == 2 { 3.0 } else { 4.0 };
            let exact = norm * dense_inverse_norm1(&dense, n);
            let kappa = estimate(&p, &values);
            // a lower bound, and (for this matrix) the exact value up to round-off
            assert!(kappa <= exact * (1.0 + 1e-10), "n {n}: {kappa} > {exact}");
            assert!(kappa >= exact * (1.0 - 1e-10), "n {n}: {kappa} < {exact}");
        }
    }

    #[test]
    fn a_stiff_spring_raises_the_estimate_by_its_stiffness() {
        // a chain of unit springs with one spring kappa times stiffer: the estimate is a lower
        // bound within a factor 3 of the dense condition number, and grows like kappa
        let n = 30;
        // (at 1e12 the chain's pivots fall below the factorization's singularity threshold)
        for kappa in [1.0, 1e4, 1e8, 1e10] {
            let mut d = vec![2.0; n];
            let mut e = vec![-1.0; n - 1];
            d[10] += kappa - 1.0;
            d[11] += kappa - 1.0;
            e[10] = -kappa;
            let (p, values, dense) = tridiagonal(&d, &e);
            let exact = symmetric_norm1(&p, &values) * dense_inverse_norm1(&dense, n);
            let got = estimate(&p, &values);
            assert!(
                got <= exact * (1.0 + 1e-6),
                "kappa {kappa}: {got} > {exact}"
            );
            assert!(got >= exact / 3.0, "kappa {kappa}: {got} < {exact} / 3");
        }
    }

    /// An unsymmetric tridiagonal matrix (sub-diagonal 3x the super-diagonal, a convection
    /// operator) factored by sparse LU: the estimate from solves with the LU and its transpose
    /// matches the dense `||A||_1 ||A^-1||_1` to 1e-12 (the ascent finds the maximizing
    /// vertex on this matrix), and is a lower bound within a factor 3 on a random one.
    #[test]
    fn the_lu_estimate_matches_the_dense_inverse_of_an_unsymmetric_matrix() {
        use crate::solver::sparse::{GeneralPattern, Lu, UNLIMITED};
        for (n, seed) in [(30usize, 0u64), (12, 7)] {
            let mut b = PatternBuilder::new(n);
            for i in 0..n - 1 {
                b.add_block(&[i, i + 1]);
            }
            let general = GeneralPattern::from_symmetric(&b.build());
            let mut dense = vec![0.0; n * n];
            let mut state = seed;
            let mut random = || {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (state >> 11) as f64 / (1u64 << 53) as f64
            };
            for i in 0..n {
                dense[i * n + i] = 4.0 + if seed > 0 { random() } else { 0.0 };
                if i + 1 < n {
                    dense[i * n + i + 1] = -1.0 + if seed > 0 { random() } else { 0.0 };
                    dense[(i + 1) * n + i] = -3.0 + if seed > 0 { random() } else { 0.0 };
                }
            }
            let mut values = vec![0.0; general.nnz()];
            for j in 0..n {
                for k in general.col_ptr[j]..general.col_ptr[j + 1] {
                    values[k] = dense[general.row_idx[k] * n + j];
                }
            }
            let lu = Lu::analyse(&general, &UNLIMITED).unwrap();
            let f = lu.factor(&general, &values).unwrap();
            let estimate = condition_estimate_general(&general.col_ptr, &values, |b, t| {
                if t {
                    f.solve_transpose_in_place(b)
                } else {
                    f.solve_in_place(b)
                }
            });
            let norm = (0..n)
                .map(|j| (0..n).map(|i| dense[i * n + j].abs()).sum::<f64>())
                .fold(0.0, f64::max);
            let exact = norm * dense_inverse_norm1(&dense, n);
            if seed == 0 {
                assert!(
                    (estimate - exact).abs() <= 1e-12 * exact,
                    "{estimate} vs {exact}"
                );
            } else {
                assert!(
                    estimate <= exact * (1.0 + 1e-12) && estimate >= exact / 3.0,
                    "{estimate} vs {exact}"
                );
            }
        }
    }

    #[test]
    fn lost_digits_are_the_decimal_logarithm() {
        assert_eq!(lost_digits(1e8), 8.0);
        assert_eq!(lost_digits(0.5), 0.0);
        assert_eq!(lost_digits(f64::INFINITY), f64::INFINITY);
        assert_eq!(lost_digits(f64::NAN), f64::INFINITY);
    }
}
