//! Sparse symmetric matrices: a pattern computed once, scatter-assembly, sparse Cholesky.
//!
//! The global matrix is stored as its upper triangle (row <= column) in compressed sparse
//! columns, the layout faer's sparse Cholesky reads with `Side::Upper`. The pattern is the union
//! of the dense blocks that every element (and, later, every contact pair or mortar segment)
//! couples; it is fixed before any value is assembled, so the symbolic factorization (fill-
//! reducing ordering and elimination tree) is computed once and reused for every numeric
//! factorization with the same pattern (Newton iterations, penalty sweeps).
//!
//! Saddle-point systems `[[K, -B^T], [-B, 0]]` (Lagrange multipliers) are factored as
//! `P A P^T = L D L^T` with faer's supernodal/simplicial LDL^T and the expected pivot signs
//! (+ for displacements, - for multipliers) given to its dynamic regularization; the ordering is
//! plain AMD, so the solve is followed by a few steps of iterative refinement.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, LdltRef, SymbolicCholesky, SymmetricOrdering,
};
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, Mat, Par, Side};
use std::sync::Arc;

/// Upper-triangular CSC pattern of a symmetric `n x n` matrix.
#[derive(Clone, Debug)]
pub struct SymmetricPattern {
    pub n: usize,
    pub col_ptr: Vec<usize>,
    pub row_idx: Vec<usize>,
}

/// Collects the dense blocks that couple equations, then freezes them into a pattern.
#[derive(Debug)]
pub struct PatternBuilder {
    n: usize,
    columns: Vec<Vec<usize>>,
}

impl PatternBuilder {
    pub fn new(n: usize) -> Self {
        PatternBuilder {
            n,
            columns: vec![Vec::new(); n],
        }
    }

    /// Couple every pair of the equations in `eqs` (entries `>= n` are ignored, so callers can
    /// pass a sentinel for eliminated dofs).
    pub fn add_block(&mut self, eqs: &[usize]) {
        for &j in eqs {
            if j >= self.n {
                continue;
            }
            for &i in eqs {
                if i <= j {
                    self.columns[j].push(i);
                }
            }
        }
    }

    pub fn build(self) -> SymmetricPattern {
        let mut col_ptr = Vec::with_capacity(self.n + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for (j, mut col) in self.columns.into_iter().enumerate() {
            col.push(j); // the diagonal is always stored
            col.sort_unstable();
            col.dedup();
            row_idx.extend_from_slice(&col);
            col_ptr.push(row_idx.len());
        }
        SymmetricPattern {
            n: self.n,
            col_ptr,
            row_idx,
        }
    }
}

impl SymmetricPattern {
    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// Position of entry `(i, j)` (either order) in the value array.
    pub fn position(&self, i: usize, j: usize) -> Option<usize> {
        let (r, c) = if i <= j { (i, j) } else { (j, i) };
        let range = self.col_ptr[c]..self.col_ptr[c + 1];
        self.row_idx[range.clone()]
            .binary_search(&r)
            .ok()
            .map(|k| range.start + k)
    }

    /// Add the dense symmetric block `ke` (row-major, `eqs.len()` square) into `values`;
    /// entries whose equation is `>= n` (eliminated) are skipped. Panics if the block was not
    /// part of the pattern, which is a programming error.
    pub fn scatter(&self, eqs: &[usize], ke: &[f64], values: &mut [f64]) {
        let m = eqs.len();
        for (b, &j) in eqs.iter().enumerate() {
            if j >= self.n {
                continue;
            }
            let range = self.col_ptr[j]..self.col_ptr[j + 1];
            let rows = &self.row_idx[range.clone()];
            for (a, &i) in eqs.iter().enumerate() {
                if i > j {
                    continue;
                }
                let k = rows
                    .binary_search(&i)
                    .expect("entry outside the assembled pattern");
                values[range.start + k] += ke[a * m + b];
            }
        }
    }

    pub fn symbolic(&self) -> SymbolicSparseColMatRef<'_, usize> {
        SymbolicSparseColMatRef::new_checked(self.n, self.n, &self.col_ptr, None, &self.row_idx)
    }

    /// `y = A x` for the symmetric matrix whose upper triangle is `values`.
    pub fn mul(&self, values: &[f64], x: &[f64], y: &mut [f64]) {
        y.iter_mut().for_each(|v| *v = 0.0);
        for j in 0..self.n {
            for k in self.col_ptr[j]..self.col_ptr[j + 1] {
                let i = self.row_idx[k];
                y[i] += values[k] * x[j];
                if i != j {
                    y[j] += values[k] * x[i];
                }
            }
        }
    }
}

/// Why a factorization failed.
#[derive(Debug, Clone, PartialEq)]
pub enum FactorError {
    /// The matrix is not positive definite: pivot `equation` was not positive.
    NotPositiveDefinite { equation: usize },
    /// Out of memory or another non-numerical failure.
    Other(String),
}

/// Sparse Cholesky `A = L L^T` with the symbolic analysis done once per pattern.
pub struct Cholesky {
    symbolic: SymbolicLlt<usize>,
}

impl Cholesky {
    /// Analyse the pattern (ordering, elimination tree, supernodes).
    pub fn analyse(pattern: &SymmetricPattern) -> Result<Self, FactorError> {
        let symbolic = SymbolicLlt::try_new(pattern.symbolic(), Side::Upper)
            .map_err(|e| FactorError::Other(format!("{e:?}")))?;
        Ok(Cholesky { symbolic })
    }

    /// Numeric factorization of the matrix with this pattern and `values`.
    pub fn factor(
        &self,
        pattern: &SymmetricPattern,
        values: &[f64],
    ) -> Result<Factor, FactorError> {
        let mat = SparseColMatRef::new(pattern.symbolic(), values);
        Llt::try_new_with_symbolic(self.symbolic.clone(), mat, Side::Upper)
            .map(|llt| Factor { llt })
            .map_err(|e| match e {
                faer::sparse::linalg::LltError::Numeric(
                    faer::linalg::cholesky::llt::factor::LltError::NonPositivePivot { index },
                ) => FactorError::NotPositiveDefinite { equation: index },
                other => FactorError::Other(format!("{other:?}")),
            })
    }
}

/// A numeric factorization, ready to solve.
pub struct Factor {
    llt: Llt<usize, f64>,
}

impl Factor {
    /// Solve `A x = b` in place.
    pub fn solve_in_place(&self, b: &mut [f64]) {
        let mut rhs = Mat::<f64>::from_fn(b.len(), 1, |i, _| b[i]);
        self.llt.solve_in_place(rhs.as_mut());
        for (i, v) in b.iter_mut().enumerate() {
            *v = rhs[(i, 0)];
        }
    }
}

/// Sparse `L D L^T` of a symmetric indefinite matrix with known pivot signs.
pub struct Ldlt {
    symbolic: Arc<SymbolicCholesky<usize>>,
}

/// A numeric `L D L^T` factorization.
pub struct LdltFactor {
    symbolic: Arc<SymbolicCholesky<usize>>,
    values: Vec<f64>,
}

impl Ldlt {
    /// Symbolic analysis with the ordering "AMD of the leading `leading x leading` block, then
    /// the remaining equations in order", so that multipliers (numbered last) are eliminated
    /// after their displacements and every pivot has its expected sign exactly.
    pub fn analyse(pattern: &SymmetricPattern, leading: usize) -> Result<Self, FactorError> {
        let n = pattern.n;
        fn other(e: impl std::fmt::Debug) -> FactorError {
            FactorError::Other(format!("{e:?}"))
        }
        let nnz = pattern.col_ptr[leading];
        let block = SymbolicSparseColMatRef::new_checked(
            leading,
            leading,
            &pattern.col_ptr[..=leading],
            None,
            &pattern.row_idx[..nnz],
        );
        let mut fwd = vec![0usize; n];
        let mut inv = vec![0usize; n];
        let mut mem = MemBuffer::new(faer::sparse::linalg::amd::order_scratch::<usize>(
            leading, nnz,
        ));
        faer::sparse::linalg::amd::order(
            &mut fwd[..leading],
            &mut inv[..leading],
            block,
            Default::default(),
            MemStack::new(&mut mem),
        )
        .map_err(other)?;
        for k in leading..n {
            fwd[k] = k;
            inv[k] = k;
        }
        let perm = faer::perm::PermRef::new_checked(&fwd, &inv, n);
        let symbolic = factorize_symbolic_cholesky(
            pattern.symbolic(),
            Side::Upper,
            SymmetricOrdering::Custom(perm),
            Default::default(),
        )
        .map_err(other)?;
        Ok(Ldlt {
            symbolic: Arc::new(symbolic),
        })
    }

    /// Factor with expected pivot `signs` (+1 / -1 per equation); a pivot of the wrong sign or
    /// smaller than `epsilon` is replaced by `epsilon` with the expected sign.
    pub fn factor(
        &self,
        pattern: &SymmetricPattern,
        values: &[f64],
        signs: &[i8],
        epsilon: f64,
    ) -> Result<LdltFactor, FactorError> {
        let mut l = vec![0.0; self.symbolic.len_val()];
        let par = Par::Seq;
        let mut mem = MemBuffer::new(
            self.symbolic
                .factorize_numeric_ldlt_scratch::<f64>(par, Default::default()),
        );
        let mat = SparseColMatRef::new(pattern.symbolic(), values);
        let regularization = faer::linalg::cholesky::ldlt::factor::LdltRegularization {
            dynamic_regularization_signs: Some(signs),
            dynamic_regularization_delta: epsilon,
            dynamic_regularization_epsilon: epsilon,
        };
        self.symbolic
            .factorize_numeric_ldlt(
                &mut l,
                mat,
                Side::Upper,
                regularization,
                par,
                MemStack::new(&mut mem),
                Default::default(),
            )
            .map_err(|e| FactorError::Other(format!("{e:?}")))?;
        Ok(LdltFactor {
            symbolic: self.symbolic.clone(),
            values: l,
        })
    }
}

impl LdltFactor {
    /// Solve `A x = b` in place.
    pub fn solve_in_place(&self, b: &mut [f64]) {
        let par = Par::Seq;
        let mut rhs = Mat::<f64>::from_fn(b.len(), 1, |i, _| b[i]);
        let mut mem = MemBuffer::new(self.symbolic.solve_in_place_scratch::<f64>(1, par));
        LdltRef::new(&self.symbolic, &self.values).solve_in_place_with_conj(
            Conj::No,
            rhs.as_mut(),
            par,
            MemStack::new(&mut mem),
        );
        for (i, v) in b.iter_mut().enumerate() {
            *v = rhs[(i, 0)];
        }
    }
}

/// Solve `A x = b` for the symmetric matrix whose upper triangle is `values` by sparse LU with
/// partial pivoting (both triangles are expanded); `None` if LU fails or the result is not
/// finite.
pub fn lu_solve(pattern: &SymmetricPattern, values: &[f64], b: &[f64]) -> Option<Vec<f64>> {
    use faer::sparse::{SparseColMat, Triplet};
    let mut triplets = Vec::with_capacity(2 * pattern.nnz());
    for j in 0..pattern.n {
        for k in pattern.col_ptr[j]..pattern.col_ptr[j + 1] {
            let i = pattern.row_idx[k];
            triplets.push(Triplet::new(i, j, values[k]));
            if i != j {
                triplets.push(Triplet::new(j, i, values[k]));
            }
        }
    }
    let a =
        SparseColMat::<usize, f64>::try_new_from_triplets(pattern.n, pattern.n, &triplets).ok()?;
    let lu = a.sp_lu().ok()?;
    let mut rhs = Mat::<f64>::from_fn(b.len(), 1, |i, _| b[i]);
    lu.solve_in_place(rhs.as_mut());
    let x: Vec<f64> = (0..b.len()).map(|i| rhs[(i, 0)]).collect();
    x.iter().all(|v| v.is_finite()).then_some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn assembled_laplacian_solves() {
        // 1D chain of springs: blocks [i, i+1] with [[1, -1], [-1, 1]], plus 1 on the diagonal.
        let n = 50;
        let mut pb = PatternBuilder::new(n);
        for i in 0..n - 1 {
            pb.add_block(&[i, i + 1]);
        }
        let pattern = pb.build();
        assert_eq!(pattern.nnz(), 2 * n - 1);
        let mut values = vec![0.0; pattern.nnz()];
        for i in 0..n - 1 {
            pattern.scatter(&[i, i + 1], &[1.0, -1.0, -1.0, 1.0], &mut values);
        }
        for i in 0..n {
            values[pattern.position(i, i).unwrap()] += 1.0;
        }
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut b = vec![0.0; n];
        pattern.mul(&values, &x, &mut b);
        let chol = Cholesky::analyse(&pattern).unwrap();
        let f = chol.factor(&pattern, &values).unwrap();
        f.solve_in_place(&mut b);
        for i in 0..n {
            assert!((b[i] - x[i]).abs() < 1e-12, "{i}: {} vs {}", b[i], x[i]);
        }
        // the same symbolic analysis serves a second matrix with the same pattern
        let doubled: Vec<f64> = values.iter().map(|v| 2.0 * v).collect();
        let mut b2 = vec![0.0; n];
        pattern.mul(&doubled, &x, &mut b2);
        chol.factor(&pattern, &doubled)
            .unwrap()
            .solve_in_place(&mut b2);
        assert!(b2.iter().zip(&x).all(|(a, b)| (a - b).abs() < 1e-12));
    }

    #[test]
    fn singular_matrix_is_reported() {
        let mut pb = PatternBuilder::new(2);
        pb.add_block(&[0, 1]);
        let pattern = pb.build();
        let mut values = vec![0.0; pattern.nnz()];
        pattern.scatter(&[0, 1], &[1.0, -1.0, -1.0, 1.0], &mut values);
        let chol = Cholesky::analyse(&pattern).unwrap();
        assert!(matches!(
            chol.factor(&pattern, &values),
            Err(FactorError::NotPositiveDefinite { .. })
        ));
    }

    #[test]
    fn ldlt_solves_a_saddle_point_system() {
        // K = tridiagonal SPD (3 x 3), one constraint u0 - u2 = 0.5: [[K, -b], [-b^T, 0]]
        let mut pb = PatternBuilder::new(4);
        pb.add_block(&[0, 1]);
        pb.add_block(&[1, 2]);
        pb.add_block(&[0, 2, 3]);
        let p = pb.build();
        let mut v = vec![0.0; p.nnz()];
        let mut set = |i: usize, j: usize, x: f64| v[p.position(i, j).unwrap()] = x;
        set(0, 0, 2.0);
        set(1, 1, 2.0);
        set(2, 2, 2.0);
        set(0, 1, -1.0);
        set(1, 2, -1.0);
        set(0, 3, -1.0);
        set(2, 3, 1.0);
        let x = [0.3, -0.2, -0.2, 1.7];
        let mut b = vec![0.0; 4];
        p.mul(&v, &x, &mut b);
        let f = Ldlt::analyse(&p, 3)
            .unwrap()
            .factor(&p, &v, &[1, 1, 1, -1], 1e-14)
            .unwrap();
        f.solve_in_place(&mut b);
        for i in 0..4 {
            assert!((b[i] - x[i]).abs() < 1e-12, "{i}: {} vs {}", b[i], x[i]);
        }
    }

    #[test]
    fn eliminated_equations_are_skipped() {
        let mut pb = PatternBuilder::new(2);
        pb.add_block(&[0, usize::MAX, 1]);
        let pattern = pb.build();
        let mut values = vec![0.0; pattern.nnz()];
        let ke = [2.0, 9.0, -1.0, 9.0, 9.0, 9.0, -1.0, 9.0, 2.0];
        pattern.scatter(&[0, usize::MAX, 1], &ke, &mut values);
        assert_eq!(values[pattern.position(0, 1).unwrap()], -1.0);
        assert_eq!(values[pattern.position(1, 1).unwrap()], 2.0);
    }
}
