//! Sparse symmetric matrices: a pattern computed once, scatter-assembly, sparse Cholesky.
//!
//! The global matrix is stored as its upper triangle (row <= column) in compressed sparse
//! columns, the layout faer's sparse Cholesky reads with `Side::Upper`. The pattern is the union
//! of the dense blocks that every element (and, later, every contact pair or mortar segment)
//! couples; it is fixed before any value is assembled, so the symbolic factorization (fill-
//! reducing ordering and elimination tree) is computed once and reused for every numeric
//! factorization with the same pattern (Newton iterations, penalty sweeps).
//!
//! Cholesky: `P A P^T = L L^T` with `P` the AMD ordering, through faer's low-level API so that
//! the permutation is ours to read: elimination step `k` belongs to the original equation
//! `fwd[k]`. A failing pivot is an error naming that original equation; faer's failing index
//! is `k + 1` on its simplicial path and `k` on its supernodal path.
//!
//! Saddle-point systems `[[K, -B^T], [-B, 0]]` (Lagrange multipliers) are factored as
//! `P A P^T = L D L^T` with faer's supernodal/simplicial LDL^T and the expected pivot signs
//! (+ for displacements, - for multipliers) given to its dynamic regularization; the ordering is
//! plain AMD, so the solve is followed by a few steps of iterative refinement.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltError;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, LdltRef, LltRef, SymbolicCholesky, SymbolicCholeskyRaw,
    SymmetricOrdering,
};
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

/// Why a factorization failed. Every equation is in the caller's numbering (the fill-reducing
/// permutation is undone).
#[derive(Debug, Clone, PartialEq)]
pub enum FactorError {
    /// The matrix is not positive definite: the pivot of `equation` was not positive.
    NotPositiveDefinite { equation: usize },
    /// Out of memory or another non-numerical failure.
    Other(String),
}

impl FactorError {
    /// The same error with its equation renumbered by `map` (e.g. from a reduced system).
    pub fn map_equation(self, map: impl Fn(usize) -> usize) -> FactorError {
        match self {
            FactorError::NotPositiveDefinite { equation } => FactorError::NotPositiveDefinite {
                equation: map(equation),
            },
            other => other,
        }
    }
}

/// Original equation of elimination step `k`.
fn original(symbolic: &SymbolicCholesky<usize>, k: usize) -> usize {
    symbolic.perm().map_or(k, |p| p.arrays().0[k])
}

/// Sparse Cholesky `A = L L^T` with the symbolic analysis (AMD ordering, elimination tree,
/// supernodes) done once per pattern and shared by every numeric factorization.
pub struct Cholesky {
    symbolic: Arc<SymbolicCholesky<usize>>,
}

impl Cholesky {
    /// Analyse the pattern (ordering, elimination tree, supernodes).
    pub fn analyse(pattern: &SymmetricPattern) -> Result<Self, FactorError> {
        let symbolic = factorize_symbolic_cholesky(
            pattern.symbolic(),
            Side::Upper,
            SymmetricOrdering::Amd,
            Default::default(),
        )
        .map_err(|e| FactorError::Other(format!("{e:?}")))?;
        Ok(Cholesky {
            symbolic: Arc::new(symbolic),
        })
    }

    /// Whether the numeric factorization works on supernodes (dense blocks) rather than
    /// column by column; faer decides from the pattern.
    pub fn is_supernodal(&self) -> bool {
        matches!(self.symbolic.raw(), SymbolicCholeskyRaw::Supernodal(_))
    }

    /// Numeric factorization of the matrix with this pattern and `values`. A pivot that is not
    /// positive is an error naming its equation.
    pub fn factor(
        &self,
        pattern: &SymmetricPattern,
        values: &[f64],
    ) -> Result<Factor, FactorError> {
        let sym = &*self.symbolic;
        let mut l = Vec::new();
        l.try_reserve_exact(sym.len_val())
            .map_err(|e| FactorError::Other(format!("{e}")))?;
        l.resize(sym.len_val(), 0.0);
        let par = faer::get_global_parallelism();
        let mut mem =
            MemBuffer::try_new(sym.factorize_numeric_llt_scratch::<f64>(par, Default::default()))
                .map_err(|e| FactorError::Other(format!("{e:?}")))?;
        let mat = SparseColMatRef::new(pattern.symbolic(), values);
        let result = sym.factorize_numeric_llt(
            &mut l,
            mat,
            Side::Upper,
            Default::default(),
            par,
            MemStack::new(&mut mem),
            Default::default(),
        );
        if let Err(e) = result {
            return Err(match e {
                LltError::NonPositivePivot { index } => {
                    // faer's failing index is 1-based on the simplicial path and 0-based on
                    // the supernodal one, both in elimination order
                    let k = match sym.raw() {
                        SymbolicCholeskyRaw::Simplicial(_) => index - 1,
                        SymbolicCholeskyRaw::Supernodal(_) => index,
                    };
                    FactorError::NotPositiveDefinite {
                        equation: original(sym, k),
                    }
                }
            });
        }
        Ok(Factor {
            symbolic: self.symbolic.clone(),
            values: l,
        })
    }
}

/// A numeric factorization, ready to solve.
pub struct Factor {
    symbolic: Arc<SymbolicCholesky<usize>>,
    values: Vec<f64>,
}

impl Factor {
    /// Solve `A x = b` in place.
    pub fn solve_in_place(&self, b: &mut [f64]) {
        let par = faer::get_global_parallelism();
        let mut rhs = Mat::<f64>::from_fn(b.len(), 1, |i, _| b[i]);
        let mut mem = MemBuffer::new(self.symbolic.solve_in_place_scratch::<f64>(1, par));
        LltRef::new(&self.symbolic, &self.values).solve_in_place_with_conj(
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

    /// A `side x side` grid whose equations couple with their 8 neighbours (diagonally
    /// dominant, so positive definite), except `loose`, which couples with nothing and has the
    /// diagonal `value`.
    fn grid_with_loose_equation(
        side: usize,
        loose: usize,
        value: f64,
    ) -> (SymmetricPattern, Vec<f64>) {
        let n = side * side;
        let mut pb = PatternBuilder::new(n);
        let mut blocks = Vec::new();
        for j in 0..side {
            for i in 0..side {
                for (di, dj) in [(1, 0), (0, 1), (1, 1)] {
                    let (a, b) = (j * side + i, (j + dj) * side + i + di);
                    if i + di < side && j + dj < side && a != loose && b != loose {
                        pb.add_block(&[a, b]);
                        blocks.push([a, b]);
                    }
                }
            }
        }
        let p = pb.build();
        let mut v = vec![0.0; p.nnz()];
        for [a, b] in blocks {
            p.scatter(&[a, b], &[1.0, -1.0, -1.0, 1.0], &mut v);
        }
        for e in 0..n {
            v[p.position(e, e).unwrap()] += if e == loose { value } else { 0.5 };
        }
        (p, v)
    }

    #[test]
    fn a_failing_pivot_is_named_by_its_equation_on_both_paths() {
        // faer counts the failing pivot from 1 on its simplicial path and from 0 on its
        // supernodal path, both in the fill-reducing order
        for (side, supernodal) in [(5, false), (150, true)] {
            let loose = side * side / 2 + 3;
            for value in [-1.0, 0.0] {
                let (p, v) = grid_with_loose_equation(side, loose, value);
                let chol = Cholesky::analyse(&p).unwrap();
                assert_eq!(chol.is_supernodal(), supernodal);
                assert_eq!(
                    chol.factor(&p, &v).err(),
                    Some(FactorError::NotPositiveDefinite { equation: loose }),
                    "side {side}, value {value}"
                );
            }
            let (p, v) = grid_with_loose_equation(side, loose, 1.0);
            assert!(Cholesky::analyse(&p).unwrap().factor(&p, &v).is_ok());
        }
    }
}
