//! Solving with a factored matrix after a low-rank change, by the Sherman-Morrison-Woodbury
//! identity, so that an active-set iteration that changes few contact rows needs no new
//! factorization.
//!
//! The base `A = L L^T` is factored ([`crate::solver::sparse::Factor`]). The matrix of a later
//! iteration is `M = A + U W U^T`: `U = [u_1 .. u_r]` are the gradients `b_i` of the `r` rows
//! whose weight changed (sparse, a few entries each) and `W = diag(dw_i)` the changes of weight,
//! of either sign (a row that closed adds `+w_i`, one that opened `-w_i`). Woodbury's identity
//! (W. W. Hager, "Updating the inverse of a matrix", SIAM Review 31 (1989) 221-239; Golub & Van
//! Loan, *Matrix Computations*, 4th ed., 2013, sec. 2.1.4):
//!
//! ```text
//! M^-1 = A^-1 - Z C^-1 Z^T,   Z = A^-1 U (n x r),   C = W^-1 + U^T Z (r x r, symmetric)
//! ```
//!
//! and `det M = det A det W det C`, so `C` is nonsingular exactly when `M` is. `C` is indefinite
//! when rows open, so it is factored by dense LU with partial pivoting (faer). A solve with `M`
//! costs one solve with `L`, `2 n r` multiply-adds and an `r x r` solve; building the update
//! costs one solve with `r` right-hand sides at once for the columns of `Z` not already known
//! (they depend on the base and the row alone, so [`LowRankBase`] keeps them across
//! iterations), and `n r` values of memory.
//!
//! Accuracy: the identity is exact; in floating point its error grows with `cond(C)` (Yip,
//! "A note on the stability of solving a rank-p modification of a linear system by the
//! Sherman-Morrison-Woodbury formula", SIAM J. Sci. Stat. Comput. 7 (1986) 507-513). The callers
//! therefore judge every answer by the residual of `M` itself and refine it (iterative
//! refinement with `M`'s own residual converges to round-off when `||I - M M~^-1|| < 1`), and
//! refactor `M` when the update's answer does not reach round-off (the fallback), when `C` is
//! singular to working precision, or when more rows changed than the update allows.

use crate::solver::sparse::{Factor, TINY_PIVOT};
use faer::linalg::matmul::triangular::{matmul, BlockStructure};
use faer::linalg::solvers::{Llt, PartialPivLu, Solve};
use faer::{Accum, Mat, MatRef, Side};
use std::collections::HashMap;
use std::rc::Rc;

/// The most trailing equations a trailing-block update factors densely (`8 c^2` bytes for the
/// Schur complement and as much for its factor: 128 MB each at this bound).
pub const MAX_TRAILING_EQUATIONS: usize = 4000;

/// A pivot of the capacitance `C` below this share of its largest entry counts as zero: the
/// update is refused and the caller refactors.
pub const CAPACITANCE_TINY_PIVOT: f64 = 1e-13;

/// Either a factorization of `M` itself or the base factorization with a Woodbury update or
/// a trailing-block update.
pub enum Operator {
    Factored(Rc<Factor>),
    Updated(LowRankUpdate),
    Trailing(TrailingUpdate),
}

impl Operator {
    /// `b <- M^-1 b`.
    pub fn solve_in_place(&self, b: &mut [f64]) {
        match self {
            Operator::Factored(f) => f.solve_in_place(b),
            Operator::Updated(u) => u.solve_in_place(b),
            Operator::Trailing(u) => u.solve_in_place(b),
        }
    }

    /// `B <- M^-1 B` for the `columns` columns of `b` (`b.len() / columns` values each, one
    /// after the other): one pass over the factor for a factorization or a trailing-block
    /// update, a solve per column for a Woodbury update.
    pub fn solve_columns_in_place(&self, b: &mut [f64], columns: usize) {
        let n = b.len() / columns.max(1);
        match self {
            Operator::Factored(f) => f.solve_columns_with_trailing(b, columns, |_| {}),
            Operator::Updated(u) => b.chunks_mut(n.max(1)).for_each(|c| u.solve_in_place(c)),
            Operator::Trailing(u) => u.solve_columns_in_place(b, columns),
        }
    }

    /// The rank of the update (0 for a factorization of `M` itself): the rows whose weight
    /// changed.
    pub fn rank(&self) -> usize {
        match self {
            Operator::Factored(_) => 0,
            Operator::Updated(u) => u.columns.len(),
            Operator::Trailing(u) => u.changes.len(),
        }
    }

    /// The name of the linear solver in the iteration history.
    pub fn solver_name(&self) -> &'static str {
        match self {
            Operator::Factored(_) => "cholesky",
            Operator::Updated(_) => "cholesky-low-rank-update",
            Operator::Trailing(_) => "cholesky-trailing-update",
        }
    }
}

/// A sparse vector: equations and values.
pub type SparseColumn = (Vec<usize>, Vec<f64>);

/// `M^-1` as the base factor's inverse minus `Z C^-1 Z^T`.
pub struct LowRankUpdate {
    base: Rc<Factor>,
    /// The columns `u_a` of `U`.
    columns: Vec<SparseColumn>,
    /// `z_a = A^-1 u_a`.
    z: Vec<Rc<Vec<f64>>>,
    capacitance: PartialPivLu<f64>,
}

fn sparse_dot((eqs, values): &SparseColumn, x: &[f64]) -> f64 {
    eqs.iter().zip(values).map(|(&e, v)| v * x[e]).sum()
}

impl LowRankUpdate {
    /// `b <- M^-1 b = A^-1 b - Z C^-1 (Z^T b)`; `Z^T b = U^T (A^-1 b)` by symmetry of `A`.
    pub fn solve_in_place(&self, b: &mut [f64]) {
        self.base.solve_in_place(b);
        let r = self.columns.len();
        let t = Mat::<f64>::from_fn(r, 1, |a, _| sparse_dot(&self.columns[a], b));
        let s = self.capacitance.solve(&t);
        for (a, z) in self.z.iter().enumerate() {
            let sa = s[(a, 0)];
            if sa != 0.0 {
                b.iter_mut().zip(z.iter()).for_each(|(x, zj)| *x -= sa * zj);
            }
        }
    }
}

/// The base factor's trailing block `L_CC` and the Schur complement on the trailing equations
/// `C` it gives, dense: `A_C = L_CC L_CC^T = A_CC - A_CL A_LL^-1 A_LC`
/// ([`Factor::trailing_block`]).
pub struct TrailingBase {
    /// Each equation's position in the block (`usize::MAX` for a leading equation).
    position: Vec<usize>,
    /// `L_CC`, lower triangular.
    factor: Mat<f64>,
    /// `A_C` (both triangles).
    schur: Mat<f64>,
}

impl TrailingBase {
    fn new(factor: &Factor, n: usize) -> Option<TrailingBase> {
        let equations = factor.trailing_equations()?.clone();
        let l = factor.trailing_block()?;
        let c = equations.len();
        let mut schur = Mat::<f64>::zeros(c, c);
        matmul(
            schur.as_mut(),
            BlockStructure::TriangularLower,
            Accum::Replace,
            l.as_ref(),
            BlockStructure::TriangularLower,
            l.transpose(),
            BlockStructure::TriangularUpper,
            1.0,
            faer::get_global_parallelism(),
        );
        for j in 0..c {
            for i in 0..j {
                schur[(i, j)] = schur[(j, i)];
            }
        }
        let mut position = vec![usize::MAX; n];
        for (k, &e) in equations.iter().enumerate() {
            position[e] = k;
        }
        Some(TrailingBase {
            position,
            factor: l,
            schur,
        })
    }
}

/// `M^-1` for `M = A + E dP E^T` whose change `dP = sum_i dw_i b_i b_i^T` from the factored
/// base `A = P^T L L^T P` lies in the block of the trailing equations `C` (`E` selects them,
/// eliminated last): `L^-1 E = [0; L_CC^-1]`, so
///
/// ```text
/// M = P^T L diag(I, L_CC^-1 (A_C + dP) L_CC^-T) L^T P,   A_C = L_CC L_CC^T,
/// M^-1 b = P^T L^-T diag(I, L_CC^T (A_C + dP)^-1 L_CC) L^-1 P b,
/// ```
///
/// where `A_C + dP` is the Schur complement of the new matrix on `C`, factored densely
/// (`c^3 / 3` multiply-adds) and positive definite exactly when `M` is. A solve costs one solve
/// with the base factor and `3 c^2` multiply-adds; any number of rows may change.
pub struct TrailingUpdate {
    base: Rc<Factor>,
    block: Rc<TrailingBase>,
    /// The changed rows: positions in the block, coefficients and the change of weight.
    changes: Vec<(Vec<usize>, Vec<f64>, f64)>,
    llt: Llt<f64>,
}

impl TrailingUpdate {
    /// `b <- M^-1 b`.
    pub fn solve_in_place(&self, b: &mut [f64]) {
        self.solve_columns_in_place(b, 1)
    }

    /// `B <- M^-1 B` for the `columns` columns of `b`, one pass over the base factor.
    pub fn solve_columns_in_place(&self, b: &mut [f64], columns: usize) {
        let l = &self.block.factor;
        self.base.solve_columns_with_trailing(b, columns, |y| {
            let c = y.len();
            let par = faer::get_global_parallelism();
            // `L_CC y` and `L_CC^T z` read only the stored triangle
            let mut t = Mat::<f64>::zeros(c, 1);
            matmul(
                t.as_mut(),
                BlockStructure::Rectangular,
                Accum::Replace,
                l.as_ref(),
                BlockStructure::TriangularLower,
                MatRef::from_column_major_slice(y, c, 1),
                BlockStructure::Rectangular,
                1.0,
                par,
            );
            let z = self.llt.solve(&t);
            matmul(
                faer::MatMut::from_column_major_slice_mut(y, c, 1),
                BlockStructure::Rectangular,
                Accum::Replace,
                l.transpose(),
                BlockStructure::TriangularUpper,
                z.as_ref(),
                BlockStructure::Rectangular,
                1.0,
                par,
            );
        });
    }
}

/// The factored base matrix `A = K + sum_i w_i b_i b_i^T` (the weights `w_i`, zero for an
/// inactive row, of the set it was factored for) and the columns `A^-1 b_i` computed so far.
pub struct LowRankBase {
    factor: Rc<Factor>,
    weights: Vec<f64>,
    known: HashMap<usize, Rc<Vec<f64>>>,
    /// The Schur complement on the trailing equations, once an update asked for it.
    trailing: Option<Rc<TrailingBase>>,
}

impl LowRankBase {
    pub fn new(factor: Rc<Factor>, weights: Vec<f64>) -> Self {
        LowRankBase {
            factor,
            weights,
            known: HashMap::new(),
            trailing: None,
        }
    }

    /// The update to `M = A + sum_i (weights_i - base_i) b_i b_i^T` through the base's trailing
    /// block ([`TrailingUpdate`]), whatever the number of changed rows; `None` when the base
    /// has no trailing equations, no row changed, a changed row has a nonzero coefficient on a
    /// leading equation, or the new Schur complement is not positive definite to working
    /// precision (the caller then updates by low rank or refactors).
    pub fn trailing_update<'a>(
        &mut self,
        weights: &[f64],
        row: impl Fn(usize) -> (&'a [usize], &'a [f64]),
        n: usize,
    ) -> Option<TrailingUpdate> {
        let changed = self.changed(weights);
        if changed.is_empty() || self.factor.trailing_equations().is_none() {
            return None;
        }
        if self.trailing.is_none() {
            self.trailing = Some(Rc::new(TrailingBase::new(&self.factor, n)?));
        }
        let block = self.trailing.clone()?;
        let mut changes = Vec::with_capacity(changed.len());
        for &i in &changed {
            let (eqs, coeffs) = row(i);
            let mut positions = Vec::with_capacity(eqs.len());
            let mut kept = Vec::with_capacity(eqs.len());
            for (&e, &a) in eqs.iter().zip(coeffs) {
                if a == 0.0 {
                    continue;
                }
                let p = block.position[e];
                if p == usize::MAX {
                    return None;
                }
                positions.push(p);
                kept.push(a);
            }
            changes.push((positions, kept, weights[i] - self.weights[i]));
        }
        let mut m = block.schur.clone();
        for (positions, coeffs, dw) in &changes {
            for (&p, &a) in positions.iter().zip(coeffs) {
                for (&q, &b) in positions.iter().zip(coeffs) {
                    m[(p, q)] += dw * a * b;
                }
            }
        }
        let llt = m.llt(Side::Lower).ok()?;
        let l = llt.L();
        if (0..m.nrows()).any(|k| {
            let d = l[(k, k)] * l[(k, k)];
            !d.is_finite() || d <= TINY_PIVOT * m[(k, k)].abs()
        }) {
            return None;
        }
        Some(TrailingUpdate {
            base: self.factor.clone(),
            block,
            changes,
            llt,
        })
    }

    /// The rows whose weight differs from the base's.
    pub fn changed(&self, weights: &[f64]) -> Vec<usize> {
        (0..weights.len())
            .filter(|&i| weights[i] != self.weights[i])
            .collect()
    }

    /// The update to `M = A + sum_i (weights_i - base_i) b_i b_i^T`, with `row(i)` the sparse
    /// gradient `b_i`; `None` when more than `max_rank` rows changed, more than `max_new` of
    /// them need a new column `A^-1 b_i`, or the capacitance is singular to working precision
    /// (the caller then refactors).
    pub fn update<'a>(
        &mut self,
        weights: &[f64],
        row: impl Fn(usize) -> (&'a [usize], &'a [f64]),
        n: usize,
        max_rank: usize,
        max_new: usize,
    ) -> Option<LowRankUpdate> {
        let changed = self.changed(weights);
        if changed.is_empty() || changed.len() > max_rank {
            return None;
        }
        let columns: Vec<SparseColumn> = changed
            .iter()
            .map(|&i| {
                let (e, c) = row(i);
                (e.to_vec(), c.to_vec())
            })
            .collect();
        // the columns of Z not known yet, in one solve with several right-hand sides
        let missing: Vec<usize> = (0..changed.len())
            .filter(|&a| !self.known.contains_key(&changed[a]))
            .collect();
        if missing.len() > max_new {
            return None;
        }
        // keep the memory of the known columns within twice the rank bound
        if self.known.len() + missing.len() > 2 * max_rank {
            self.known.retain(|i, _| changed.contains(i));
        }
        if !missing.is_empty() {
            let mut rhs = Mat::<f64>::zeros(n, missing.len());
            for (k, &a) in missing.iter().enumerate() {
                let (eqs, values) = &columns[a];
                for (&e, &v) in eqs.iter().zip(values) {
                    rhs[(e, k)] += v;
                }
            }
            self.factor.solve_columns_in_place(&mut rhs);
            for (k, &a) in missing.iter().enumerate() {
                let z: Vec<f64> = (0..n).map(|j| rhs[(j, k)]).collect();
                self.known.insert(changed[a], Rc::new(z));
            }
        }
        let z: Vec<Rc<Vec<f64>>> = changed.iter().map(|i| self.known[i].clone()).collect();
        let r = changed.len();
        let mut c = Mat::<f64>::zeros(r, r);
        for a in 0..r {
            for b in 0..r {
                c[(a, b)] = sparse_dot(&columns[a], &z[b]);
            }
        }
        for a in 0..r {
            for b in 0..a {
                let v = 0.5 * (c[(a, b)] + c[(b, a)]);
                c[(a, b)] = v;
                c[(b, a)] = v;
            }
        }
        // the scale of C's terms before they cancel: its entries U^T Z and the 1 / dw_i
        let mut scale = (0..r)
            .flat_map(|a| (0..r).map(move |b| (a, b)))
            .fold(0.0f64, |m, (a, b)| m.max(c[(a, b)].abs()));
        for a in 0..r {
            let inverse = 1.0 / (weights[changed[a]] - self.weights[changed[a]]);
            scale = scale.max(inverse.abs());
            c[(a, a)] += inverse;
        }
        let lu = c.partial_piv_lu();
        let u = lu.U();
        let singular = !scale.is_finite()
            || (0..r).any(|k| {
                let p = u[(k, k)];
                !p.is_finite() || p.abs() <= CAPACITANCE_TINY_PIVOT * scale
            });
        if singular {
            return None;
        }
        Some(LowRankUpdate {
            base: self.factor.clone(),
            columns,
            z,
            capacitance: lu,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::sparse::{Cholesky, PatternBuilder, SymmetricPattern, UNLIMITED};

    /// `max |x - exact| / max |exact|`.
    fn relative_difference(x: &[f64], exact: &[f64]) -> f64 {
        let scale = exact.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        x.iter()
            .zip(exact)
            .fold(0.0f64, |m, (a, e)| m.max((a - e).abs()))
            / scale
    }

    /// The 1D Laplacian with a spring at the left end, `n` equations, plus the pattern.
    fn laplacian(n: usize) -> (SymmetricPattern, Vec<f64>) {
        let mut builder = PatternBuilder::new(n);
        for j in 1..n {
            builder.add_block(&[j - 1, j]);
        }
        let pattern = builder.build();
        let mut values = vec![0.0; pattern.nnz()];
        for j in 0..n {
            values[pattern.position(j, j).unwrap()] = if j + 1 == n { 1.0 } else { 2.0 };
            if j > 0 {
                values[pattern.position(j - 1, j).unwrap()] = -1.0;
            }
        }
        (pattern, values)
    }

    fn rows(n: usize) -> Vec<SparseColumn> {
        // rows on one equation and on two (a row of a node-to-surface segment)
        (0..n)
            .map(|i| {
                if i % 3 == 0 && i + 1 < n {
                    (vec![i, i + 1], vec![0.6, -0.8])
                } else {
                    (vec![i], vec![1.0])
                }
            })
            .collect()
    }

    /// `A + sum_i w_i b_i b_i^T` factored from scratch.
    fn factored(pattern: &SymmetricPattern, k: &[f64], rows: &[SparseColumn], w: &[f64]) -> Factor {
        let mut values = k.to_vec();
        for ((eqs, c), &wi) in rows.iter().zip(w) {
            if wi == 0.0 {
                continue;
            }
            let m = eqs.len();
            let block: Vec<f64> = (0..m * m).map(|q| wi * c[q / m] * c[q % m]).collect();
            pattern.scatter(eqs, &block, &mut values);
        }
        Cholesky::analyse(pattern, &UNLIMITED)
            .unwrap()
            .factor(pattern, &values)
            .unwrap()
    }

    /// Rows that close and rows that open (weights up and down, many at once) give the
    /// solution of the refactored matrix to round-off; a known column is reused.
    #[test]
    fn a_woodbury_update_solves_like_a_new_factorization() {
        let n = 60;
        let (pattern, k) = laplacian(n);
        let rows = rows(n);
        let base_w: Vec<f64> = (0..n).map(|i| if i < 30 { 1e3 } else { 0.0 }).collect();
        let mut base = LowRankBase::new(Rc::new(factored(&pattern, &k, &rows, &base_w)), base_w);
        let b: Vec<f64> = (0..n).map(|i| ((i * 7) % 11) as f64 - 5.0).collect();
        // 25 to 35 open (weight 0 below 30) or close (above 30); then a second set over the
        // same base that shares rows with the first
        for (lo, hi) in [(25, 35), (20, 40)] {
            let w: Vec<f64> = (0..n)
                .map(|i| {
                    if (i < 30) != (lo <= i && i < hi) {
                        1e3
                    } else {
                        0.0
                    }
                })
                .collect();
            let update = base
                .update(&w, |i| (&rows[i].0, &rows[i].1), n, 64, 64)
                .expect("rank below the limit");
            assert_eq!(Operator::Updated(update).rank(), hi - lo);
            let update = base
                .update(&w, |i| (&rows[i].0, &rows[i].1), n, 64, 64)
                .unwrap();
            let mut x = b.clone();
            update.solve_in_place(&mut x);
            let mut exact = b.clone();
            factored(&pattern, &k, &rows, &w).solve_in_place(&mut exact);
            let err = relative_difference(&x, &exact);
            assert!(err < 1e-12, "({lo}, {hi}): relative difference {err:.2e}");
        }
    }

    /// Rows on the second half of a chain, whose equations the factor eliminates last: 90
    /// rows that close and open at once (beyond any Woodbury rank bound), and then a second set
    /// over the same base, are solved through the trailing block like a new factorization; a
    /// base without trailing equations, or a row reaching a leading equation, gives none.
    #[test]
    fn a_trailing_update_solves_like_a_new_factorization() {
        let n = 200;
        let (pattern, k) = laplacian(n);
        let all = rows(n);
        // rows on equations 200.. only (the others carry no row: weight 0 throughout)
        let rows: Vec<SparseColumn> = all
            .iter()
            .enumerate()
            .map(|(i, r)| {
                if i >= 100 {
                    r.clone()
                } else {
                    (vec![], vec![])
                }
            })
            .collect();
        let mut trailing: Vec<usize> = rows.iter().flat_map(|r| r.0.clone()).collect();
        trailing.sort_unstable();
        trailing.dedup();
        let chol = Cholesky::analyse_with_trailing(&pattern, &trailing, &UNLIMITED).unwrap();
        let base_w: Vec<f64> = (0..n)
            .map(|i| if (100..150).contains(&i) { 1e3 } else { 0.0 })
            .collect();
        let factor_of = |w: &[f64]| {
            let mut values = k.clone();
            for ((eqs, c), &wi) in rows.iter().zip(w) {
                let m = eqs.len();
                let block: Vec<f64> = (0..m * m).map(|q| wi * c[q / m] * c[q % m]).collect();
                pattern.scatter(eqs, &block, &mut values);
            }
            values
        };
        let base_factor = chol.factor(&pattern, &factor_of(&base_w)).unwrap();
        let mut base = LowRankBase::new(Rc::new(base_factor), base_w.clone());
        let row = |i: usize| (&rows[i].0[..], &rows[i].1[..]);
        let b: Vec<f64> = (0..n).map(|i| ((i * 7) % 11) as f64 - 5.0).collect();
        for (lo, hi) in [(105, 195), (110, 140)] {
            let w: Vec<f64> = (0..n)
                .map(|i| {
                    if i >= 100 && ((i < 150) != (lo <= i && i < hi)) {
                        1e3
                    } else {
                        0.0
                    }
                })
                .collect();
            let update = base.trailing_update(&w, row, n).expect("a trailing update");
            let operator = Operator::Trailing(update);
            assert_eq!(operator.rank(), hi - lo);
            assert_eq!(operator.solver_name(), "cholesky-trailing-update");
            let mut x = b.clone();
            operator.solve_in_place(&mut x);
            let mut exact = b.clone();
            factored(&pattern, &k, &rows, &w).solve_in_place(&mut exact);
            let err = relative_difference(&x, &exact);
            assert!(err < 1e-12, "({lo}, {hi}): relative difference {err:.2e}");
        }
        assert!(base.trailing_update(&base_w, row, n).is_none(), "no change");
        // a row that reaches equation 0, which the factor eliminates first
        let reaching: Vec<SparseColumn> = rows
            .iter()
            .enumerate()
            .map(|(i, r)| {
                if i == 120 {
                    (vec![0, 120], vec![1.0, 1.0])
                } else {
                    r.clone()
                }
            })
            .collect();
        let mut w = base_w.clone();
        w[120] = 0.0;
        let reach = |i: usize| (&reaching[i].0[..], &reaching[i].1[..]);
        assert!(
            base.trailing_update(&w, reach, n).is_none(),
            "leading equation"
        );
        let amd = Cholesky::analyse(&pattern, &UNLIMITED).unwrap();
        let plain = amd.factor(&pattern, &factor_of(&base_w)).unwrap();
        let mut plain = LowRankBase::new(Rc::new(plain), base_w.clone());
        assert!(
            plain.trailing_update(&w, row, n).is_none(),
            "no trailing block"
        );
    }

    /// More changed rows than allowed, no change, or an update that makes `M` singular: no
    /// update (the caller refactors).
    #[test]
    fn no_update_beyond_the_rank_limit_or_for_a_singular_matrix() {
        let n = 12;
        let (pattern, k) = laplacian(n);
        let rows = rows(n);
        let base_w = vec![0.0; n];
        let mut base = LowRankBase::new(
            Rc::new(factored(&pattern, &k, &rows, &base_w)),
            base_w.clone(),
        );
        let row = |i: usize| (&rows[i].0[..], &rows[i].1[..]);
        assert!(base.update(&base_w, row, n, 4, 4).is_none());
        let many: Vec<f64> = (0..n).map(|i| if i < 5 { 1.0 } else { 0.0 }).collect();
        assert!(base.update(&many, row, n, 4, 4).is_none());
        assert!(base.update(&many, row, n, 5, 5).is_some());
        // a negative spring -1 / (e^T A^-1 e) on the last equation makes M singular
        let mut e = vec![0.0; n];
        e[n - 1] = 1.0;
        base.factor.solve_in_place(&mut e);
        let mut singular = base_w.clone();
        singular[n - 1] = -1.0 / e[n - 1];
        assert!(base.update(&singular, row, n, 4, 4).is_none());
    }
}
