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
//! the permutation and the pivots are ours to read. The pivot of elimination step `k` is
//! `d_k = L_kk^2`; it belongs to the original equation `fwd[k]` (`P` maps step `k` to `fwd[k]`).
//! A failing pivot (`d_k <= 0`) and a pivot that is zero relative to its diagonal
//! (`d_k <= TINY_PIVOT A_kk`: singular to working precision) are errors naming that original
//! equation; faer's failing index is `k + 1` on its simplicial path and `k` on its supernodal
//! path.
//!
//! Saddle-point systems `[[K, -B^T], [-B, 0]]` (Lagrange multipliers) are factored as
//! `P A P^T = L D L^T` with faer's supernodal/simplicial LDL^T and the expected pivot signs
//! (+ for displacements, - for multipliers) given to its dynamic regularization; the ordering is
//! AMD of the displacement block with the multipliers last, so the solve is followed by a few
//! steps of iterative refinement. A pivot that the regularization replaced (it then holds
//! exactly `+-epsilon`) or that is zero relative to its diagonal is an error, never a silently
//! perturbed matrix.
//!
//! General matrices on a structurally symmetric pattern (unsymmetric tangents, saddle systems
//! LDL^T refuses): [`GeneralPattern`] holds both triangles, [`Lu`] is faer's sparse LU with
//! partial pivoting whose symbolic analysis is made once per pattern and reused.
//!
//! Work bound: every symbolic analysis gives the factor's size before any value is allocated,
//! [`FactorWork`]: its entries (memory) and its multiply-adds `sum_j c_j^2` over the column
//! counts `c_j` of `L` (George & Liu 1981, sec. 2.2; a dense matrix: `n^3 / 3`). Above the
//! case's [`WorkLimit`] the analysis is refused ([`FactorError::TooLarge`]). An LU is
//! estimated as twice the Cholesky factor of its (structurally symmetric) pattern under AMD.
//! An `L D L^T` whose multipliers-last order is above the limit is analysed again with each
//! multiplier beside its own displacement (see `multipliers_after_their_displacements`): a long
//! interface against a coarse master couples every multiplier through the master's few
//! displacements, so multipliers last make their whole block dense; beside their slave
//! displacements they stay sparse. Below the limit the multipliers-last order is kept, so the
//! results of every system that fits are unchanged.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::llt::factor::LltError;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::cholesky::supernodal::SupernodalLltRef;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, LdltRef, LltRef, SymbolicCholesky, SymbolicCholeskyRaw,
    SymmetricOrdering,
};
use faer::sparse::linalg::triangular_solve;
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

/// `(s, e)` with `s = fl(a + b)` and `a + b = s + e` exactly (Knuth's TwoSum).
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let z = s - a;
    (s, (a - (s - z)) + (b - z))
}

impl SymmetricPattern {
    /// `r = b - A x` as if computed in twice the working precision, then rounded: every
    /// product `a x = p + e` is split exactly with a fused multiply-add, every sum by TwoSum,
    /// and the rounding errors are accumulated beside each row (Ogita, Rump and Oishi's
    /// `Dot2`). Iterative refinement with this residual converges to the solution of the
    /// stored matrix to about working precision whatever the elimination order, instead of
    /// stalling at `cond(A) eps`.
    pub fn residual_accurate(&self, values: &[f64], x: &[f64], b: &[f64], r: &mut [f64]) {
        let mut low = vec![0.0; self.n];
        r.copy_from_slice(b);
        let mut add = |i: usize, p: f64, e: f64, r: &mut [f64]| {
            let (s, t) = two_sum(r[i], -p);
            r[i] = s;
            low[i] += t - e;
        };
        for j in 0..self.n {
            for k in self.col_ptr[j]..self.col_ptr[j + 1] {
                let i = self.row_idx[k];
                let a = values[k];
                let p = a * x[j];
                add(i, p, a.mul_add(x[j], -p), r);
                if i != j {
                    let p = a * x[i];
                    add(j, p, a.mul_add(x[i], -p), r);
                }
            }
        }
        r.iter_mut().zip(&low).for_each(|(v, l)| *v += l);
    }
}

/// Why a factorization failed. Every equation is in the caller's numbering (the fill-reducing
/// permutation is undone).
#[derive(Debug, Clone, PartialEq)]
pub enum FactorError {
    /// The matrix is not positive definite: the pivot of `equation` was not positive.
    NotPositiveDefinite { equation: usize },
    /// A pivot that is zero relative to the matrix: `|d_k| <= TINY_PIVOT * scale_k` (the
    /// matrix is singular to working precision), or, for `L D L^T`, a pivot that the dynamic
    /// regularization had to replace. `ratio` is `|d_k| / scale_k` before any replacement is
    /// known, so for a replaced pivot it is the replacement's ratio.
    ZeroPivot {
        equation: usize,
        ratio: f64,
        regularized: usize,
    },
    /// The symbolic analysis shows a factor larger than the case allows (memory or
    /// operations); nothing was allocated for it.
    TooLarge { work: FactorWork, limit: WorkLimit },
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
            FactorError::ZeroPivot {
                equation,
                ratio,
                regularized,
            } => FactorError::ZeroPivot {
                equation: map(equation),
                ratio,
                regularized,
            },
            other => other,
        }
    }
}

/// A pivot `d_k` with `|d_k| <= TINY_PIVOT * scale_k` counts as zero: the matrix is singular
/// to working precision. `scale_k` is the diagonal entry `|A_kk|` the pivot started from (for
/// `L L^T` of a positive definite matrix `0 < d_k <= A_kk`), or the caller's scale for a zero
/// diagonal (multiplier rows of a saddle-point system). Measured: over every case, table and
/// the million-dof square the smallest ratio is 5e-5 (penalty methods), 4e-6 in a stabilized
/// contact solve with nu = 0.4999; a part of a body that floats free gives 7e-17 (or a
/// negative pivot); a penalty `kappa` above about `1e10 E / h` would come here too.
pub const TINY_PIVOT: f64 = 1e-11;

/// Diagonal entry of each column of the upper-triangular pattern (always stored, last).
fn diagonal(pattern: &SymmetricPattern, values: &[f64]) -> Vec<f64> {
    (0..pattern.n)
        .map(|j| values[pattern.col_ptr[j + 1] - 1])
        .collect()
}

/// The pivots `d_k` of a numeric factorization in elimination order `k` (the fill-reducing
/// order): the diagonal of `D` for `L D L^T`, the squared diagonal of `L` for `L L^T`.
fn pivots(symbolic: &SymbolicCholesky<usize>, values: &[f64], squared: bool) -> Vec<f64> {
    let mut d = Vec::with_capacity(symbolic.nrows());
    match symbolic.raw() {
        SymbolicCholeskyRaw::Simplicial(s) => {
            // the diagonal entry opens every column of the simplicial factor
            d.extend(s.col_ptr()[..s.nrows()].iter().map(|&p| values[p]));
        }
        SymbolicCholeskyRaw::Supernodal(s) => {
            // supernode: a column-major block of (pattern + width) rows, diagonal on top
            for sn in 0..s.n_supernodes() {
                let width = s.supernode_end()[sn] - s.supernode_begin()[sn];
                let rows = s.supernode(sn).pattern().len() + width;
                let base = s.col_ptr_for_val()[sn];
                d.extend((0..width).map(|j| values[base + j * rows + j]));
            }
        }
    }
    if squared {
        d.iter_mut().for_each(|v| *v *= *v);
    }
    d
}

/// The size of a factorization, known from its symbolic analysis before any value is
/// computed: `equations` (the order `n`), `entries` (the stored factor values, `len_val`:
/// supernodes store their dense `w x (w + r)` blocks) and `operations`, the multiply-adds of the
/// numeric factorization, `sum_j c_j^2` over the factor's columns with `c_j` the entries of
/// column `j` on and below the diagonal (George & Liu, *Computer Solution of Large Sparse
/// Positive Definite Systems*, 1981, sec. 2.2: a dense `n x n` matrix has `n (n + 1) / 2`
/// entries and about `n^3 / 3` operations).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FactorWork {
    pub equations: usize,
    pub entries: usize,
    pub operations: f64,
}

impl FactorWork {
    /// The work of the factorization `symbolic` describes.
    pub fn of(symbolic: &SymbolicCholesky<usize>) -> FactorWork {
        let operations = match symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(s) => s
                .col_ptr()
                .windows(2)
                .map(|w| ((w[1] - w[0]) as f64).powi(2))
                .sum(),
            SymbolicCholeskyRaw::Supernodal(s) => (0..s.n_supernodes())
                .map(|sn| {
                    let width = s.supernode_end()[sn] - s.supernode_begin()[sn];
                    let below = s.supernode(sn).pattern().len();
                    // column k of the supernode has width - k + below entries
                    (1..=width)
                        .map(|c| ((c + below) as f64).powi(2))
                        .sum::<f64>()
                })
                .sum(),
        };
        FactorWork {
            equations: symbolic.nrows(),
            entries: symbolic.len_val(),
            operations,
        }
    }

    /// The sentence that refuses this factorization under `limit`: the system's size, its
    /// factor's entries, memory and operations, and the limits.
    pub fn refusal(&self, limit: &WorkLimit) -> String {
        format!(
            "the sparse factorization of {} equations would hold {} factor entries ({:.2} GB) \
             and take {:.2e} multiply-adds, above the limits of {} GB \
             (limits.factor_gigabytes) and {:.1e} multiply-adds (limits.factor_operations)",
            self.equations,
            self.entries,
            self.gigabytes(),
            self.operations,
            limit.gigabytes,
            limit.operations
        )
    }

    /// Memory of the factor's values in gigabytes (8 bytes each).
    pub fn gigabytes(&self) -> f64 {
        self.entries as f64 * 8.0 / 1e9
    }

    /// `Err(FactorError::TooLarge)` when the factor's memory or operations exceed `limit`.
    pub fn check(self, limit: &WorkLimit) -> Result<FactorWork, FactorError> {
        if self.gigabytes() > limit.gigabytes || self.operations > limit.operations {
            return Err(FactorError::TooLarge {
                work: self,
                limit: *limit,
            });
        }
        Ok(self)
    }
}

/// No bound on the work of a factorization (for tests and internal tiny systems).
pub const UNLIMITED: WorkLimit = WorkLimit {
    gigabytes: f64::INFINITY,
    operations: f64::INFINITY,
};

/// How to get past [`FactorError::TooLarge`].
pub const TOO_LARGE_HINT: &str = "raise \"limits\": {\"factor_gigabytes\": G, \"factor_operations\": N} in the case if the machine has the memory and the time, or use a coarser mesh, or for a Lagrange-multiplier interface a penalty-type method (penalty, augmented Lagrangian) or elimination, which factor no multipliers";

/// The most memory (gigabytes of factor values) and multiply-adds one factorization may take
/// (the case's `limits.factor_gigabytes` and `limits.factor_operations`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorkLimit {
    pub gigabytes: f64,
    pub operations: f64,
}

/// Original equation of elimination step `k`.
fn original(symbolic: &SymbolicCholesky<usize>, k: usize) -> usize {
    symbolic.perm().map_or(k, |p| p.arrays().0[k])
}

/// Sparse Cholesky `A = L L^T` with the symbolic analysis (AMD or nested-dissection ordering,
/// elimination tree, supernodes) done once per pattern and shared by every numeric factorization.
pub struct Cholesky {
    symbolic: Arc<SymbolicCholesky<usize>>,
    /// With [`Cholesky::analyse_with_trailing`], the original equations of the last steps of
    /// the elimination, in step order.
    trailing: Option<Arc<[usize]>>,
}

impl Cholesky {
    /// Analyse the pattern (ordering, elimination tree, supernodes); a factor whose work
    /// exceeds `limit` is [`FactorError::TooLarge`].
    pub fn analyse(pattern: &SymmetricPattern, limit: &WorkLimit) -> Result<Self, FactorError> {
        Self::analyse_at(pattern, None, limit)
    }

    /// [`Cholesky::analyse`] with `points[e]` the point of equation `e` (its node), which lets
    /// large systems try the geometric dissection too ([`cheaper_order`]).
    pub fn analyse_at(
        pattern: &SymmetricPattern,
        points: Option<&[[f64; 3]]>,
        limit: &WorkLimit,
    ) -> Result<Self, FactorError> {
        let whole = crate::solver::ordering::Pattern {
            n: pattern.n,
            col_ptr: &pattern.col_ptr,
            row_idx: &pattern.row_idx,
        };
        let symbolic = cheaper_order(&whole, points, |order| symbolic_in_order(pattern, order))?;
        FactorWork::of(&symbolic).check(limit)?;
        Ok(Cholesky {
            symbolic: Arc::new(symbolic),
            trailing: None,
        })
    }

    /// Analyse the pattern with the equations `trailing` eliminated last (in the given order)
    /// and the others in the cheaper of AMD's and the nested-dissection order of their own
    /// block ([`cheaper_order`]), so that the factor's trailing block
    /// `L_CC` gives the Schur complement `S + P_C = L_CC L_CC^T` of the leading equations
    /// ([`Factor::trailing_block`]): a later matrix that differs from this one in the
    /// `trailing x trailing` block alone is then solved with this factor and a dense
    /// factorization of that block ([`crate::solver::low_rank::TrailingUpdate`]). An empty
    /// `trailing`, or one that is not a set of distinct equations of the pattern, is the
    /// analysis of [`Cholesky::analyse`].
    pub fn analyse_with_trailing(
        pattern: &SymmetricPattern,
        trailing: &[usize],
        limit: &WorkLimit,
    ) -> Result<Self, FactorError> {
        Self::analyse_with_trailing_at(pattern, trailing, None, limit)
    }

    /// [`Cholesky::analyse_with_trailing`] with `points[e]` the point of equation `e`, as in
    /// [`Cholesky::analyse_at`].
    pub fn analyse_with_trailing_at(
        pattern: &SymmetricPattern,
        trailing: &[usize],
        points: Option<&[[f64; 3]]>,
        limit: &WorkLimit,
    ) -> Result<Self, FactorError> {
        let n = pattern.n;
        let mut is_trailing = vec![false; n];
        for &e in trailing {
            if e >= n || is_trailing[e] {
                return Self::analyse_at(pattern, points, limit);
            }
            is_trailing[e] = true;
        }
        if trailing.is_empty() || trailing.len() == n {
            return Self::analyse_at(pattern, points, limit);
        }
        let (leading, col_ptr, row_idx) = leading_block(pattern, &is_trailing);
        let m = leading.len();
        let block = crate::solver::ordering::Pattern {
            n: m,
            col_ptr: &col_ptr,
            row_idx: &row_idx,
        };
        let leading_points: Option<Vec<[f64; 3]>> =
            points.map(|p| leading.iter().map(|&e| p[e]).collect());
        // the whole order: the leading block's, then the trailing equations as given
        let symbolic = cheaper_order(&block, leading_points.as_deref(), |order| {
            let fwd: Vec<usize> = order
                .iter()
                .map(|&k| leading[k])
                .chain(trailing.iter().copied())
                .collect();
            symbolic_in_order(pattern, &fwd)
        })?;
        FactorWork::of(&symbolic).check(limit)?;
        // the symbolic analysis may reorder (postorder) the elimination tree: the trailing
        // block is the one it ends with, which must still be the trailing equations
        let c = trailing.len();
        let last: Vec<usize> = (n - c..n).map(|k| original(&symbolic, k)).collect();
        let kept = last.iter().all(|&e| is_trailing[e]);
        Ok(Cholesky {
            symbolic: Arc::new(symbolic),
            trailing: kept.then(|| last.into()),
        })
    }

    /// The size of the factorization ([`FactorWork`]).
    pub fn work(&self) -> FactorWork {
        FactorWork::of(&self.symbolic)
    }

    /// Whether the numeric factorization works on supernodes (dense blocks) rather than
    /// column by column; faer decides from the pattern.
    pub fn is_supernodal(&self) -> bool {
        matches!(self.symbolic.raw(), SymbolicCholeskyRaw::Supernodal(_))
    }

    /// Numeric factorization of the matrix with this pattern and `values`. A pivot that is not
    /// positive, or positive but zero relative to its diagonal entry ([`TINY_PIVOT`]), is an
    /// error naming its equation.
    pub fn factor(
        &self,
        pattern: &SymmetricPattern,
        values: &[f64],
    ) -> Result<Factor, FactorError> {
        let sym = &*self.symbolic;
        let mut l = Vec::new();
        l.try_reserve_exact(sym.len_val())
            .map_err(|e| FactorError::Other(format!("{e}")))?;
        // the first write to each page of a large factor makes the kernel zero it; written
        // by rayon's threads, that cost is shared by the cores instead of paid by one
        {
            use rayon::iter::ParallelExtend;
            l.par_extend(rayon::iter::repeat_n(0.0, sym.len_val()));
        }
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
        let diag = diagonal(pattern, values);
        let d = pivots(sym, &l, true);
        if let Some(k) = (0..d.len()).find(|&k| {
            let a = diag[original(sym, k)].abs();
            d[k].is_nan() || d[k] <= TINY_PIVOT * a
        }) {
            let e = original(sym, k);
            return Err(FactorError::ZeroPivot {
                equation: e,
                ratio: d[k] / diag[e].abs(),
                regularized: 0,
            });
        }
        Ok(Factor {
            symbolic: self.symbolic.clone(),
            values: l,
            trailing: self.trailing.clone(),
        })
    }
}

/// A numeric factorization, ready to solve.
pub struct Factor {
    symbolic: Arc<SymbolicCholesky<usize>>,
    values: Vec<f64>,
    trailing: Option<Arc<[usize]>>,
}

impl Factor {
    /// The equations eliminated last ([`Cholesky::analyse_with_trailing`]), in step order.
    pub fn trailing_equations(&self) -> Option<&Arc<[usize]>> {
        self.trailing.as_ref()
    }

    /// The trailing block `L_CC` of the factor (dense, lower triangular, rows and columns in
    /// the order of [`Factor::trailing_equations`]): with `A = [[A_LL, A_LC], [A_CL, A_CC]]`
    /// and `C` eliminated last, `L_CC L_CC^T = A_CC - A_CL A_LL^-1 A_LC`, the Schur complement
    /// of the leading block. `None` without trailing equations.
    pub fn trailing_block(&self) -> Option<Mat<f64>> {
        let c = self.trailing.as_ref()?.len();
        let n = self.symbolic.nrows();
        let first = n - c;
        let mut block = Mat::<f64>::zeros(c, c);
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(s) => {
                let (col_ptr, row_idx) = (s.col_ptr(), s.row_idx());
                for j in first..n {
                    for k in col_ptr[j]..col_ptr[j + 1] {
                        let i = row_idx[k];
                        if i >= first {
                            block[(i - first, j - first)] = self.values[k];
                        }
                    }
                }
            }
            SymbolicCholeskyRaw::Supernodal(s) => {
                for sn in 0..s.n_supernodes() {
                    let (begin, end) = (s.supernode_begin()[sn], s.supernode_end()[sn]);
                    if end <= first {
                        continue;
                    }
                    // a column-major block: the supernode's own rows, then its pattern
                    let width = end - begin;
                    let pattern = s.supernode(sn).pattern();
                    let rows = width + pattern.len();
                    let base = s.col_ptr_for_val()[sn];
                    for j in begin.max(first)..end {
                        let col = base + (j - begin) * rows;
                        for i in j..end {
                            block[(i - first, j - first)] = self.values[col + i - begin];
                        }
                        for (q, &i) in pattern.iter().enumerate() {
                            if i >= first {
                                block[(i - first, j - first)] = self.values[col + width + q];
                            }
                        }
                    }
                }
            }
        }
        Some(block)
    }

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

    /// Solve `A x = b` in place as `P^T L^-T T L^-1 P b`, where `T` is `middle` applied to the
    /// trailing `c` entries of `L^-1 P b` (steps `n - c ..`, in the order of
    /// [`Factor::trailing_equations`]) and the identity on the others: with `middle` the
    /// identity this is [`Factor::solve_in_place`]; a trailing-block update puts its dense
    /// correction there ([`crate::solver::low_rank::TrailingUpdate`]). `c` is 0 without
    /// trailing equations.
    pub fn solve_in_place_with_trailing(&self, b: &mut [f64], middle: impl FnMut(&mut [f64])) {
        self.solve_columns_with_trailing(b, 1, middle)
    }

    /// [`Factor::solve_in_place_with_trailing`] for the `columns` columns of `b` (`b.len() /
    /// columns` values each, one after the other) in one pass over the factor; `middle` is
    /// applied to each column's trailing entries.
    pub fn solve_columns_with_trailing(
        &self,
        b: &mut [f64],
        columns: usize,
        mut middle: impl FnMut(&mut [f64]),
    ) {
        let columns = columns.max(1);
        let n = b.len() / columns;
        let c = self.trailing.as_ref().map_or(0, |t| t.len());
        let par = faer::get_global_parallelism();
        let fwd = self.symbolic.perm().map(|p| p.arrays().0);
        let step_of = |k: usize| fwd.map_or(k, |f| f[k]);
        let mut y = Mat::<f64>::from_fn(n, columns, |k, j| b[j * n + step_of(k)]);
        let mut mem = MemBuffer::new(self.symbolic.solve_in_place_scratch::<f64>(columns, par));
        let stack = MemStack::new(&mut mem);
        let mut apply_middle = |y: &mut Mat<f64>| {
            for j in 0..columns {
                middle(&mut y.col_as_slice_mut(j)[n - c..]);
            }
        };
        match self.symbolic.raw() {
            SymbolicCholeskyRaw::Simplicial(s) => {
                let l = SparseColMatRef::new(s.factor(), &self.values);
                triangular_solve::solve_lower_triangular_in_place(l, Conj::No, y.as_mut(), par);
                apply_middle(&mut y);
                triangular_solve::solve_lower_triangular_transpose_in_place(
                    l,
                    Conj::No,
                    y.as_mut(),
                    par,
                );
            }
            SymbolicCholeskyRaw::Supernodal(s) => {
                let l = SupernodalLltRef::new(s, &self.values);
                l.l_solve_with_conj(Conj::No, y.as_mut(), par, stack);
                apply_middle(&mut y);
                l.l_transpose_solve_with_conj(Conj::No, y.as_mut(), par, stack);
            }
        }
        for j in 0..columns {
            for k in 0..n {
                b[j * n + step_of(k)] = y[(k, j)];
            }
        }
    }

    /// Solve `A X = B` in place for every column of `b` at once (one pass over the factor).
    pub fn solve_columns_in_place(&self, b: &mut Mat<f64>) {
        let par = faer::get_global_parallelism();
        let mut mem = MemBuffer::new(
            self.symbolic
                .solve_in_place_scratch::<f64>(b.ncols().max(1), par),
        );
        LltRef::new(&self.symbolic, &self.values).solve_in_place_with_conj(
            Conj::No,
            b.as_mut(),
            par,
            MemStack::new(&mut mem),
        );
    }
}

/// The elimination order "every trailing equation (multiplier) right after a leading equation
/// (displacement) of its own": each multiplier is matched to one of its displacements that as
/// few other multipliers couple as possible (for dual mortar its slave displacement, coupled to
/// it alone), the pair is one node of the graph AMD orders (the displacement's adjacency plus
/// the multiplier's), and the multiplier follows its displacement; unmatched multipliers come
/// last. A multiplier eliminated after its own displacement has the expected (negative) pivot
/// as long as the rows eliminated so far are independent on the displacements eliminated so far
/// (with `K` positive definite, the leading principal blocks `[[K_SS, B_S^T], [B_S, D]]` then
/// have `B_S` of full row rank); a pivot that fails is reported by [`Ldlt::factor`] as for the
/// multipliers-last order. Returns `(fwd, inv)`: the original equation of each step and the
/// step of each equation.
fn multipliers_after_their_displacements(
    pattern: &SymmetricPattern,
    leading: usize,
) -> Result<(Vec<usize>, Vec<usize>), FactorError> {
    let n = pattern.n;
    let column = |j: usize| &pattern.row_idx[pattern.col_ptr[j]..pattern.col_ptr[j + 1]];
    let coupled: Vec<Vec<usize>> = (leading..n)
        .map(|j| column(j).iter().copied().filter(|&i| i < leading).collect())
        .collect();
    // how many multipliers couple each displacement
    let mut sharing = vec![0usize; leading];
    for displacements in &coupled {
        for &e in displacements {
            sharing[e] += 1;
        }
    }
    // match each multiplier to a free displacement shared by the fewest multipliers
    let mut matched: Vec<Option<usize>> = vec![None; n - leading];
    let mut owner: Vec<Option<usize>> = vec![None; leading];
    for (i, displacements) in coupled.iter().enumerate() {
        if let Some(&e) = displacements
            .iter()
            .filter(|&&e| owner[e].is_none())
            .min_by_key(|&&e| (sharing[e], e))
        {
            owner[e] = Some(i);
            matched[i] = Some(e);
        }
    }
    // the quotient graph: a matched pair is its displacement's node
    let mut builder = PatternBuilder::new(leading);
    for j in 0..leading {
        for &i in column(j) {
            builder.add_block(&[i, j]);
        }
    }
    for (i, displacements) in coupled.iter().enumerate() {
        let Some(own) = matched[i] else { continue };
        for &e in displacements {
            builder.add_block(&[own, e]);
        }
        // multiplier-multiplier couplings (a perturbation C)
        for &k in column(leading + i) {
            if k >= leading {
                if let Some(other) = matched[k - leading] {
                    builder.add_block(&[own, other]);
                }
            }
        }
    }
    let block = builder.build();
    let nnz = block.row_idx.len();
    let mut fwd_leading = vec![0usize; leading];
    let mut step = vec![0usize; leading];
    let mut mem = MemBuffer::try_new(faer::sparse::linalg::amd::order_scratch::<usize>(
        leading, nnz,
    ))
    .map_err(|e| FactorError::Other(format!("{e:?}")))?;
    faer::sparse::linalg::amd::order(
        &mut fwd_leading,
        &mut step,
        block.symbolic(),
        Default::default(),
        MemStack::new(&mut mem),
    )
    .map_err(|e| FactorError::Other(format!("{e:?}")))?;
    let mut fwd = Vec::with_capacity(n);
    for &e in &fwd_leading {
        fwd.push(e);
        if let Some(i) = owner[e] {
            fwd.push(leading + i);
        }
    }
    fwd.extend(
        (0..n - leading)
            .filter(|&i| matched[i].is_none())
            .map(|i| leading + i),
    );
    let mut inv = vec![0usize; n];
    for (k, &e) in fwd.iter().enumerate() {
        inv[e] = k;
    }
    Ok((fwd, inv))
}

/// Above this many multiply-adds of the AMD factor, and above
/// [`DISSECTION_WORK_PER_EQUATION`] per equation, the nested-dissection order
/// ([`crate::solver::ordering::dissection_order`]) is analysed too and the cheaper of the two
/// kept; below either the second analysis would cost more than it could save.
pub const NESTED_DISSECTION_ABOVE: f64 = 1e10;

/// The AMD factor's multiply-adds per equation above which METIS's dissection can repay its
/// own time. Measured on the 1M-dof contact block of `crosscheck/performance.py` (2026-11-25,
/// load average below 2): METIS took 2.65 s for its 501,415 vertices (about 2.6 microseconds per
/// equation) and cut the factor from 8.74e10 to 5.25e10 multiply-adds, while the numeric
/// factorization ran at about 6e-11 s per multiply-add, so it saved about 2 s of factorization
/// for 2.65 s of ordering plus a second symbolic analysis: AMD's 8.7e4 multiply-adds per
/// equation are below the break-even (about 1e5 for a 40 % cut) and AMD is kept there. On the
/// 3D slab `cases/large/slab-3d-1m.json` (9.4e6 per equation) the dissection cut 1.03e13 to
/// 3.07e12 and the whole run from 233 s to 107-118 s (two runs of
/// `crosscheck/performance.sh 1000000`). Twice the break-even, since the dissection
/// does not always cut 40 %.
pub const DISSECTION_WORK_PER_EQUATION: f64 = 2e5;

/// The equations not marked trailing (in increasing order) and the upper CSC pattern of their
/// block, renumbered `0..m` in that order.
fn leading_block(
    pattern: &SymmetricPattern,
    is_trailing: &[bool],
) -> (Vec<usize>, Vec<usize>, Vec<usize>) {
    let n = pattern.n;
    let leading: Vec<usize> = (0..n).filter(|&e| !is_trailing[e]).collect();
    let mut local = vec![usize::MAX; n];
    for (k, &e) in leading.iter().enumerate() {
        local[e] = k;
    }
    let mut col_ptr = Vec::with_capacity(leading.len() + 1);
    let mut row_idx = Vec::with_capacity(pattern.nnz());
    col_ptr.push(0);
    for &j in &leading {
        // rows of column j below it in the original numbering keep their order: the
        // renumbering is increasing
        row_idx.extend(
            pattern.row_idx[pattern.col_ptr[j]..pattern.col_ptr[j + 1]]
                .iter()
                .filter(|&&i| !is_trailing[i])
                .map(|&i| local[i]),
        );
        col_ptr.push(row_idx.len());
    }
    (leading, col_ptr, row_idx)
}

/// AMD's order of the symmetric pattern `block` (upper CSC): `order[k]` is the equation
/// eliminated `k`-th (Amestoy, Davis and Duff, "An approximate minimum degree ordering
/// algorithm", SIAM J. Matrix Anal. Appl. 17 (1996) 886-905; faer's implementation).
fn amd_order(block: &crate::solver::ordering::Pattern) -> Result<Vec<usize>, FactorError> {
    fn other(e: impl std::fmt::Debug) -> FactorError {
        FactorError::Other(format!("{e:?}"))
    }
    let n = block.n;
    let nnz = block.col_ptr[n];
    let pattern = SymbolicSparseColMatRef::new_checked(n, n, block.col_ptr, None, block.row_idx);
    let mut order = vec![0usize; n];
    let mut order_inv = vec![0usize; n];
    let mut mem = MemBuffer::try_new(faer::sparse::linalg::amd::order_scratch::<usize>(n, nnz))
        .map_err(other)?;
    faer::sparse::linalg::amd::order(
        &mut order,
        &mut order_inv,
        pattern,
        Default::default(),
        MemStack::new(&mut mem),
    )
    .map_err(other)?;
    Ok(order)
}

/// The symbolic factor of `pattern` eliminated in the order `fwd` (`fwd[k]` the equation
/// eliminated `k`-th).
fn symbolic_in_order(
    pattern: &SymmetricPattern,
    fwd: &[usize],
) -> Result<SymbolicCholesky<usize>, FactorError> {
    let mut inv = vec![0usize; fwd.len()];
    for (k, &e) in fwd.iter().enumerate() {
        inv[e] = k;
    }
    let perm = faer::perm::PermRef::new_checked(fwd, &inv, pattern.n);
    factorize_symbolic_cholesky(
        pattern.symbolic(),
        Side::Upper,
        SymmetricOrdering::Custom(perm),
        Default::default(),
    )
    .map_err(|e| FactorError::Other(format!("{e:?}")))
}

/// The symbolic factor, `whole(order)` for an order of the equations of `block`:
///
/// - on systems of at least [`COORDINATE_DISSECTION_FROM`] equations with `points` (each
///   equation's point), the geometric dissection
///   ([`crate::solver::ordering::coordinate_dissection`]) first; where its factor is cheap
///   ([`NESTED_DISSECTION_ABOVE`] multiply-adds, or [`DISSECTION_WORK_PER_EQUATION`] per
///   equation), it is kept without analysing another order, since AMD's analysis would then cost
///   about as much as the factorization it might shorten (on the 1M-dof contact block of the
///   performance report AMD alone took about as long as the dissection and its symbolic
///   analysis together, 0.9 s against 1.0 s, for a factor 1.7 times as expensive);
/// - otherwise AMD's order, and where the cheapest so far is expensive by both bounds, METIS's
///   dissection too: the order of fewest multiply-adds is kept (the first of equals in the
///   order geometric, AMD, METIS). A dissection whose analysis fails is passed over.
fn cheaper_order(
    block: &crate::solver::ordering::Pattern,
    points: Option<&[[f64; 3]]>,
    whole: impl Fn(&[usize]) -> Result<SymbolicCholesky<usize>, FactorError>,
) -> Result<SymbolicCholesky<usize>, FactorError> {
    let cheap = |work: f64| {
        work <= NESTED_DISSECTION_ABOVE || work <= DISSECTION_WORK_PER_EQUATION * block.n as f64
    };
    let geometric = points
        .filter(|_| block.n >= COORDINATE_DISSECTION_FROM)
        .and_then(|p| crate::solver::ordering::coordinate_dissection(block, p))
        .and_then(|order| whole(&order).ok());
    let geometric = match geometric {
        Some(g) if cheap(FactorWork::of(&g).operations) => return Ok(g),
        other => other,
    };
    let amd = whole(&amd_order(block)?)?;
    let mut best = match geometric {
        Some(g) if FactorWork::of(&g).operations <= FactorWork::of(&amd).operations => g,
        _ => amd,
    };
    let work = FactorWork::of(&best).operations;
    if cheap(work) {
        return Ok(best);
    }
    if let Ok(nd) = whole(&crate::solver::ordering::dissection_order(block)) {
        if FactorWork::of(&nd).operations < work {
            best = nd;
        }
    }
    Ok(best)
}

/// Systems of at least this many equations with points also try the geometric dissection
/// ([`cheaper_order`]); below, AMD's analysis takes a few milliseconds and the orders of the
/// small scenes of the tables stay AMD's.
pub const COORDINATE_DISSECTION_FROM: usize = 50_000;

/// The symbolic factor for the order "AMD of the leading `leading x leading` block, then the
/// remaining equations (the multipliers) in order".
fn multipliers_last(
    pattern: &SymmetricPattern,
    leading: usize,
) -> Result<SymbolicCholesky<usize>, FactorError> {
    fn other(e: impl std::fmt::Debug) -> FactorError {
        FactorError::Other(format!("{e:?}"))
    }
    let n = pattern.n;
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
    factorize_symbolic_cholesky(
        pattern.symbolic(),
        Side::Upper,
        SymmetricOrdering::Custom(perm),
        Default::default(),
    )
    .map_err(other)
}

/// Sparse `L D L^T` of a symmetric indefinite matrix with known pivot signs.
pub struct Ldlt {
    symbolic: Arc<SymbolicCholesky<usize>>,
    /// With the interleaved order chosen, the multipliers-last order to fall back on.
    fallback: Option<Fallback>,
}

/// The interleaved order matches each multiplier to one displacement of its pattern, which
/// may carry a zero coefficient in the values (a tangential row on a node's normal dof): its
/// pivot can then vanish although the matrix is regular. A pivot failure of that order is
/// retried with multipliers last (whose pivots have their expected signs whenever the rows
/// are independent), analysed then, and that order is kept from then on.
struct Fallback {
    leading: usize,
    limit: WorkLimit,
    last: std::sync::OnceLock<Result<Arc<SymbolicCholesky<usize>>, FactorError>>,
}

/// A numeric `L D L^T` factorization.
pub struct LdltFactor {
    symbolic: Arc<SymbolicCholesky<usize>>,
    values: Vec<f64>,
}

impl Ldlt {
    /// Symbolic analysis with the cheaper of two orders for the multipliers (numbered from
    /// `leading` on): "AMD of the leading `leading x leading` block, then the multipliers in
    /// order", whose pivots have their expected signs exactly when the rows are independent,
    /// or each multiplier right after one of its displacements
    /// (`multipliers_after_their_displacements`), with multipliers last as the fallback of a
    /// pivot failure (`Fallback`). A factor whose work exceeds `limit` is
    /// [`FactorError::TooLarge`].
    pub fn analyse(
        pattern: &SymmetricPattern,
        leading: usize,
        limit: &WorkLimit,
    ) -> Result<Self, FactorError> {
        let n = pattern.n;
        fn other(e: impl std::fmt::Debug) -> FactorError {
            FactorError::Other(format!("{e:?}"))
        }
        // Two orders: each multiplier right after its displacements, and all multipliers last.
        // Multipliers last fill their whole block in when the multipliers couple displacements
        // far apart (a long interface: the Schur complement of the displacements on the
        // multipliers is dense, m(m+1)/2 entries for m multipliers), where the interleaved
        // order costs far less; with few multipliers, or multipliers of separate small
        // interfaces, multipliers last costs less. The cheaper of the two is kept. The
        // multipliers-last analysis itself takes time in proportion to its entries, so it is
        // skipped when a dense multiplier block alone would outnumber the interleaved factor's
        // entries (it could not be the cheaper one then unless its block stayed sparse).
        let (fwd, inv) = multipliers_after_their_displacements(pattern, leading)?;
        let perm = faer::perm::PermRef::new_checked(&fwd, &inv, n);
        let interleaved = factorize_symbolic_cholesky(
            pattern.symbolic(),
            Side::Upper,
            SymmetricOrdering::Custom(perm),
            Default::default(),
        )
        .map_err(other)?;
        let work = FactorWork::of(&interleaved);
        let m = (n - leading) as f64;
        let (symbolic, smaller, is_interleaved) = if m * (m + 1.0) / 2.0 > work.entries as f64 {
            (interleaved, work, true)
        } else {
            let last = multipliers_last(pattern, leading)?;
            let last_work = FactorWork::of(&last);
            if work.operations < last_work.operations {
                (interleaved, work, true)
            } else {
                (last, last_work, false)
            }
        };
        if smaller.check(limit).is_ok() {
            return Ok(Ldlt {
                symbolic: Arc::new(symbolic),
                fallback: is_interleaved.then(|| Fallback {
                    leading,
                    limit: *limit,
                    last: std::sync::OnceLock::new(),
                }),
            });
        }
        Err(FactorError::TooLarge {
            work: smaller,
            limit: *limit,
        })
    }

    /// Factor with expected pivot `signs` (+1 / -1 per equation). faer's dynamic regularization
    /// replaces a pivot of the wrong sign or smaller than `epsilon` by `epsilon` with the
    /// expected sign; such a replacement means the matrix is singular (or its pivots have the
    /// wrong inertia), so it is an error ([`FactorError::ZeroPivot`] with the count), as is a
    /// pivot that is zero relative to its diagonal ([`TINY_PIVOT`]; `zero_diagonal_scale` for
    /// equations whose diagonal is zero).
    pub fn factor(
        &self,
        pattern: &SymmetricPattern,
        values: &[f64],
        signs: &[i8],
        epsilon: f64,
        zero_diagonal_scale: f64,
    ) -> Result<LdltFactor, FactorError> {
        // once the interleaved order failed, multipliers last
        let fell_back = self
            .fallback
            .as_ref()
            .and_then(|f| f.last.get())
            .and_then(|last| last.as_ref().ok());
        let symbolic = fell_back.unwrap_or(&self.symbolic);
        let first = ldlt_numeric(
            symbolic,
            pattern,
            values,
            signs,
            epsilon,
            zero_diagonal_scale,
        );
        let Some(fallback) = &self.fallback else {
            return first;
        };
        if fell_back.is_some() || !matches!(first, Err(FactorError::ZeroPivot { .. })) {
            return first;
        }
        let last = fallback.last.get_or_init(|| {
            let symbolic = multipliers_last(pattern, fallback.leading)?;
            FactorWork::of(&symbolic).check(&fallback.limit)?;
            Ok(Arc::new(symbolic))
        });
        match last {
            Ok(last) => ldlt_numeric(last, pattern, values, signs, epsilon, zero_diagonal_scale),
            // multipliers last would exceed the limit: the interleaved order's failure stands
            Err(_) => first,
        }
    }
}

/// The numeric `L D L^T` of `values` with the analysis `symbolic` (see [`Ldlt::factor`]).
fn ldlt_numeric(
    symbolic: &Arc<SymbolicCholesky<usize>>,
    pattern: &SymmetricPattern,
    values: &[f64],
    signs: &[i8],
    epsilon: f64,
    zero_diagonal_scale: f64,
) -> Result<LdltFactor, FactorError> {
    let mut l = vec![0.0; symbolic.len_val()];
    let par = Par::Seq;
    let mut mem =
        MemBuffer::new(symbolic.factorize_numeric_ldlt_scratch::<f64>(par, Default::default()));
    let mat = SparseColMatRef::new(pattern.symbolic(), values);
    let regularization = faer::linalg::cholesky::ldlt::factor::LdltRegularization {
        dynamic_regularization_signs: Some(signs),
        dynamic_regularization_delta: epsilon,
        dynamic_regularization_epsilon: epsilon,
    };
    let sym = &**symbolic;
    sym.factorize_numeric_ldlt(
        &mut l,
        mat,
        Side::Upper,
        regularization,
        par,
        MemStack::new(&mut mem),
        Default::default(),
    )
    .map_err(|e| match e {
        faer::linalg::cholesky::ldlt::factor::LdltError::ZeroPivot { index } => {
            let k = match sym.raw() {
                SymbolicCholeskyRaw::Simplicial(_) => index - 1,
                SymbolicCholeskyRaw::Supernodal(_) => index,
            };
            FactorError::ZeroPivot {
                equation: original(sym, k),
                ratio: 0.0,
                regularized: 0,
            }
        }
    })?;
    // a replaced pivot holds exactly +-epsilon with its expected sign
    let diag = diagonal(pattern, values);
    let d = pivots(sym, &l, false);
    let scale = |e: usize| {
        if diag[e] != 0.0 {
            diag[e].abs()
        } else {
            zero_diagonal_scale
        }
    };
    let regularized: Vec<usize> = (0..d.len())
        .filter(|&k| f64::from(signs[original(sym, k)]) * d[k] <= epsilon)
        .collect();
    let tiny = (0..d.len()).find(|&k| {
        let e = original(sym, k);
        d[k].is_nan() || d[k].abs() <= TINY_PIVOT * scale(e)
    });
    if let Some(k) = regularized.first().copied().or(tiny) {
        let e = original(sym, k);
        return Err(FactorError::ZeroPivot {
            equation: e,
            ratio: d[k].abs() / scale(e),
            regularized: regularized.len(),
        });
    }
    Ok(LdltFactor {
        symbolic: symbolic.clone(),
        values: l,
    })
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

/// The full (both triangles) compressed-column pattern of a matrix whose structure is
/// symmetric while its values need not be: unsymmetric tangents (Coulomb slip, slave normals
/// without the `delta xi` term) and saddle-point systems that LDL^T refuses, solved by LU.
/// Built once from a [`SymmetricPattern`]; `upper[k]` is the position in the symmetric storage
/// of the entry `k` (or of its transpose), so a symmetric matrix's values expand without search.
#[derive(Clone, Debug)]
pub struct GeneralPattern {
    pub n: usize,
    pub col_ptr: Vec<usize>,
    pub row_idx: Vec<usize>,
    upper: Vec<usize>,
}

impl GeneralPattern {
    /// Both triangles of `p`.
    pub fn from_symmetric(p: &SymmetricPattern) -> GeneralPattern {
        let n = p.n;
        let mut count = vec![0usize; n];
        for j in 0..n {
            for k in p.col_ptr[j]..p.col_ptr[j + 1] {
                let i = p.row_idx[k];
                count[j] += 1;
                if i != j {
                    count[i] += 1;
                }
            }
        }
        let mut col_ptr = vec![0usize; n + 1];
        for j in 0..n {
            col_ptr[j + 1] = col_ptr[j] + count[j];
        }
        let mut next = col_ptr.clone();
        let nnz = col_ptr[n];
        let (mut row_idx, mut upper) = (vec![0usize; nnz], vec![0usize; nnz]);
        // columns are filled in increasing row order: the lower part of column j (entries (i, j)
        // with i > j, stored as (j, i) in column i) comes after its upper part, and both arrive
        // sorted because the loop runs over columns in order
        for j in 0..n {
            for k in p.col_ptr[j]..p.col_ptr[j + 1] {
                let i = p.row_idx[k];
                row_idx[next[j]] = i;
                upper[next[j]] = k;
                next[j] += 1;
                if i != j {
                    row_idx[next[i]] = j;
                    upper[next[i]] = k;
                    next[i] += 1;
                }
            }
        }
        GeneralPattern {
            n,
            col_ptr,
            row_idx,
            upper,
        }
    }

    pub fn nnz(&self) -> usize {
        self.row_idx.len()
    }

    /// Position of entry `(i, j)` in the value array, if it is in the pattern.
    pub fn position(&self, i: usize, j: usize) -> Option<usize> {
        let (a, b) = (self.col_ptr[j], self.col_ptr[j + 1]);
        self.row_idx[a..b].binary_search(&i).ok().map(|k| a + k)
    }

    /// The values of the symmetric matrix whose upper triangle is `upper_values`.
    pub fn symmetric_values(&self, upper_values: &[f64]) -> Vec<f64> {
        self.upper.iter().map(|&k| upper_values[k]).collect()
    }

    /// The upper triangle (the storage of the [`SymmetricPattern`] this pattern was built from,
    /// `nnz_upper` entries) of the matrix with `values` on both triangles.
    pub fn upper_values(&self, values: &[f64], nnz_upper: usize) -> Vec<f64> {
        let mut out = vec![0.0; nnz_upper];
        for j in 0..self.n {
            for k in self.col_ptr[j]..self.col_ptr[j + 1] {
                if self.row_idx[k] <= j {
                    out[self.upper[k]] = values[k];
                }
            }
        }
        out
    }

    fn symbolic(&self) -> SymbolicSparseColMatRef<'_, usize> {
        SymbolicSparseColMatRef::new_checked(self.n, self.n, &self.col_ptr, None, &self.row_idx)
    }
}

/// Sparse LU with partial pivoting (faer) whose symbolic analysis (column ordering and
/// structure) is done once per pattern and reused for every numeric factorization.
pub struct Lu {
    symbolic: faer::sparse::linalg::solvers::SymbolicLu<usize>,
}

/// A numeric LU factorization.
pub struct LuFactor {
    lu: faer::sparse::linalg::solvers::Lu<usize, f64>,
}

impl Lu {
    /// Analyse the pattern. The work is estimated before, as `L` and `U` each the size of the
    /// Cholesky factor of the (structurally symmetric) pattern under AMD: partial pivoting can
    /// add fill, so this is an estimate from below; above `limit` it is
    /// [`FactorError::TooLarge`].
    pub fn analyse(pattern: &GeneralPattern, limit: &WorkLimit) -> Result<Lu, FactorError> {
        // the upper triangle of the full pattern: its entries with row <= column
        let mut col_ptr = vec![0usize; pattern.n + 1];
        let mut row_idx = Vec::with_capacity(pattern.nnz() / 2 + pattern.n);
        for j in 0..pattern.n {
            let rows = &pattern.row_idx[pattern.col_ptr[j]..pattern.col_ptr[j + 1]];
            row_idx.extend(rows.iter().copied().filter(|&i| i <= j));
            col_ptr[j + 1] = row_idx.len();
        }
        let upper =
            SymbolicSparseColMatRef::new_checked(pattern.n, pattern.n, &col_ptr, None, &row_idx);
        let cholesky = factorize_symbolic_cholesky(
            upper,
            Side::Upper,
            SymmetricOrdering::Amd,
            Default::default(),
        )
        .map_err(|e| FactorError::Other(format!("symbolic LU: {e:?}")))?;
        let one = FactorWork::of(&cholesky);
        FactorWork {
            equations: one.equations,
            entries: 2 * one.entries,
            operations: 2.0 * one.operations,
        }
        .check(limit)?;
        faer::sparse::linalg::solvers::SymbolicLu::try_new(pattern.symbolic())
            .map(|symbolic| Lu { symbolic })
            .map_err(|e| FactorError::Other(format!("symbolic LU: {e:?}")))
    }

    /// Factor the matrix with `values` on `pattern` (the pattern of the analysis).
    pub fn factor(
        &self,
        pattern: &GeneralPattern,
        values: &[f64],
    ) -> Result<LuFactor, FactorError> {
        let mat = SparseColMatRef::new(pattern.symbolic(), values);
        faer::sparse::linalg::solvers::Lu::try_new_with_symbolic(self.symbolic.clone(), mat)
            .map(|lu| LuFactor { lu })
            .map_err(|e| FactorError::Other(format!("numeric LU: {e:?}")))
    }
}

impl LuFactor {
    /// Overwrite `b` with `A^-1 b`.
    pub fn solve_in_place(&self, b: &mut [f64]) {
        let mut rhs = Mat::<f64>::from_fn(b.len(), 1, |i, _| b[i]);
        self.lu.solve_in_place(rhs.as_mut());
        for (i, v) in b.iter_mut().enumerate() {
            *v = rhs[(i, 0)];
        }
    }

    /// Overwrite `b` with `A^-T b`.
    pub fn solve_transpose_in_place(&self, b: &mut [f64]) {
        let mut rhs = Mat::<f64>::from_fn(b.len(), 1, |i, _| b[i]);
        self.lu.solve_transpose_in_place(rhs.as_mut());
        for (i, v) in b.iter_mut().enumerate() {
            *v = rhs[(i, 0)];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The 5-point Laplacian of an `m x m` grid plus a unit mass (positive definite): its
    /// pattern and values, equation `i + m j` at node `(i, j)`.
    fn grid_laplacian(m: usize) -> (SymmetricPattern, Vec<f64>) {
        let mut b = PatternBuilder::new(m * m);
        for j in 0..m {
            for i in 0..m {
                if i + 1 < m {
                    b.add_block(&[i + m * j, i + 1 + m * j]);
                }
                if j + 1 < m {
                    b.add_block(&[i + m * j, i + m * (j + 1)]);
                }
            }
        }
        let p = b.build();
        let mut v = vec![0.0; p.nnz()];
        for j in 0..p.n {
            for k in p.col_ptr[j]..p.col_ptr[j + 1] {
                v[k] = if p.row_idx[k] == j { 5.0 } else { -1.0 };
            }
        }
        (p, v)
    }

    /// With the bottom and left edges of a grid eliminated last, the factor's trailing block
    /// gives the Schur complement `S = A_CC - A_CL A_LL^-1 A_LC`, checked against `(A^-1)_CC =
    /// S^-1` from an independent factorization (AMD order); on a small grid (faer's simplicial
    /// factor) and a larger one (supernodal).
    #[test]
    fn the_trailing_block_gives_the_schur_complement() {
        for m in [6usize, 100] {
            let (p, v) = grid_laplacian(m);
            let mut trailing: Vec<usize> = (0..m).collect();
            trailing.extend((1..m).map(|j| m * j));
            let chol = Cholesky::analyse_with_trailing(&p, &trailing, &UNLIMITED).unwrap();
            let factor = chol.factor(&p, &v).unwrap();
            let order = factor
                .trailing_equations()
                .expect("trailing equations kept")
                .clone();
            let mut sorted = order.to_vec();
            sorted.sort_unstable();
            assert_eq!(sorted, {
                let mut t = trailing.clone();
                t.sort_unstable();
                t
            });
            let l = factor.trailing_block().unwrap();
            let c = order.len();
            // (A^-1)_CC = S^-1: the trailing columns of A^-1 from the AMD factorization
            let amd = Cholesky::analyse(&p, &UNLIMITED).unwrap();
            let mut e = Mat::<f64>::zeros(p.n, c);
            for (k, &i) in order.iter().enumerate() {
                e[(i, k)] = 1.0;
            }
            amd.factor(&p, &v).unwrap().solve_columns_in_place(&mut e);
            let inverse = Mat::<f64>::from_fn(c, c, |i, j| e[(order[i], j)]);
            let product = &l * (l.transpose() * &inverse);
            let err = (0..c)
                .flat_map(|i| (0..c).map(move |j| (i, j)))
                .fold(0.0f64, |m, (i, j)| {
                    let identity = if i == j { 1.0 } else { 0.0 };
                    m.max((product[(i, j)] - identity).abs())
                });
            assert!(
                err < 1e-12,
                "m = {m}: |L_CC L_CC^T (A^-1)_CC - I| = {err:.2e}"
            );
            assert_eq!(chol.is_supernodal(), m == 100, "m = {m}: the path tested");
            // the split solve with the identity in the middle is the solve
            let b: Vec<f64> = (0..p.n).map(|i| ((i * 13) % 7) as f64 - 3.0).collect();
            let (mut x1, mut x2) = (b.clone(), b.clone());
            factor.solve_in_place(&mut x1);
            factor.solve_in_place_with_trailing(&mut x2, |y| assert_eq!(y.len(), c));
            let d = x1
                .iter()
                .zip(&x2)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(d < 1e-14, "m = {m}: split solve differs by {d:.2e}");
            let mut r = vec![0.0; p.n];
            p.mul(&v, &x2, &mut r);
            let res = r
                .iter()
                .zip(&b)
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(res < 1e-12, "m = {m}: residual {res:.2e}");
        }
    }

    /// Repeated or out-of-range trailing equations fall back to the AMD analysis.
    /// The pattern of plane Q4 elasticity on an `m x m` grid of nodes (2 dofs per node, every
    /// node coupled to its 8 neighbours).
    fn q4_grid_pattern(m: usize) -> SymmetricPattern {
        let mut b = PatternBuilder::new(2 * m * m);
        for j in 0..m - 1 {
            for i in 0..m - 1 {
                let nodes = [
                    i + m * j,
                    i + 1 + m * j,
                    i + m * (j + 1),
                    i + 1 + m * (j + 1),
                ];
                let eqs: Vec<usize> = nodes.iter().flat_map(|&v| [2 * v, 2 * v + 1]).collect();
                b.add_block(&eqs);
            }
        }
        b.build()
    }

    /// The factor work of `p` in each candidate order of its leading block (the equations
    /// not in `trailing`), the trailing equations last: AMD's, METIS's nested dissection and,
    /// given the equations' points, the coordinate bisection.
    struct CandidateWork {
        amd: f64,
        metis: f64,
        geometric: Option<f64>,
    }

    fn candidate_work(
        p: &SymmetricPattern,
        trailing: &[usize],
        points: Option<&[[f64; 3]]>,
    ) -> CandidateWork {
        let mut is_trailing = vec![false; p.n];
        trailing.iter().for_each(|&e| is_trailing[e] = true);
        let (leading, col_ptr, row_idx) = leading_block(p, &is_trailing);
        let block = crate::solver::ordering::Pattern {
            n: leading.len(),
            col_ptr: &col_ptr,
            row_idx: &row_idx,
        };
        let work = |order: Vec<usize>| {
            let fwd: Vec<usize> = order
                .iter()
                .map(|&k| leading[k])
                .chain(trailing.iter().copied())
                .collect();
            FactorWork::of(&symbolic_in_order(p, &fwd).unwrap()).operations
        };
        let geometric = points.map(|points| {
            let leading_points: Vec<[f64; 3]> = leading.iter().map(|&e| points[e]).collect();
            work(crate::solver::ordering::coordinate_dissection(&block, &leading_points).unwrap())
        });
        CandidateWork {
            amd: work(amd_order(&block).unwrap()),
            metis: work(crate::solver::ordering::dissection_order(&block)),
            geometric,
        }
    }

    /// The pattern of 3D Hex8 elasticity on an `m x m x m` grid of nodes (3 dofs per node,
    /// every node coupled to the nodes of its cells).
    fn hex8_grid_pattern(m: usize) -> SymmetricPattern {
        let node = |i: usize, j: usize, k: usize| i + m * (j + m * k);
        let mut b = PatternBuilder::new(3 * m * m * m);
        for k in 0..m - 1 {
            for j in 0..m - 1 {
                for i in 0..m - 1 {
                    let eqs: Vec<usize> = (0..8)
                        .map(|c| node(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2)))
                        .flat_map(|v| [3 * v, 3 * v + 1, 3 * v + 2])
                        .collect();
                    b.add_block(&eqs);
                }
            }
        }
        b.build()
    }

    /// The pattern of plane Q4 elasticity on an `nx x ny` grid of unit-spaced nodes (2 dofs
    /// per node, numbered along x first) and the point of each equation.
    fn q4_rectangle(nx: usize, ny: usize) -> (SymmetricPattern, Vec<[f64; 3]>) {
        let mut b = PatternBuilder::new(2 * nx * ny);
        let mut points = vec![[0.0; 3]; 2 * nx * ny];
        for j in 0..ny {
            for i in 0..nx {
                let v = i + nx * j;
                points[2 * v] = [i as f64, j as f64, 0.0];
                points[2 * v + 1] = points[2 * v];
                if i + 1 < nx && j + 1 < ny {
                    let nodes = [v, v + 1, v + nx, v + nx + 1];
                    let eqs: Vec<usize> = nodes.iter().flat_map(|&w| [2 * w, 2 * w + 1]).collect();
                    b.add_block(&eqs);
                }
            }
        }
        (b.build(), points)
    }

    /// Values on `p`: -1 off the diagonal and one more than the row's count of them on it
    /// (symmetric, strictly diagonally dominant, so positive definite).
    fn diagonally_dominant(p: &SymmetricPattern) -> Vec<f64> {
        let mut off = vec![0.0; p.n];
        for j in 0..p.n {
            for &i in &p.row_idx[p.col_ptr[j]..p.col_ptr[j + 1]] {
                if i != j {
                    off[i] += 1.0;
                    off[j] += 1.0;
                }
            }
        }
        let mut values = vec![0.0; p.nnz()];
        for j in 0..p.n {
            for k in p.col_ptr[j]..p.col_ptr[j + 1] {
                values[k] = if p.row_idx[k] == j {
                    off[j] + 1.0
                } else {
                    -1.0
                };
            }
        }
        values
    }

    #[test]
    fn a_large_system_with_points_keeps_a_cheap_geometric_dissection() {
        // 400 x 80 nodes, 64,000 equations (above COORDINATE_DISSECTION_FROM): the factor of
        // the coordinate bisection's order is cheap by both bounds and kept without another
        // analysis (its grid-line separators beat AMD's order here too); without points, or
        // below the size, the order is AMD's
        let (p, points) = q4_rectangle(400, 80);
        assert!(p.n >= COORDINATE_DISSECTION_FROM);
        let candidates = candidate_work(&p, &[], Some(&points));
        let (amd, geometric) = (candidates.amd, candidates.geometric.unwrap());
        assert!(geometric < amd, "AMD {amd:e}, geometric {geometric:e}");
        let kept = Cholesky::analyse_at(&p, Some(&points), &UNLIMITED).unwrap();
        assert_eq!(kept.work().operations, geometric);
        assert_eq!(
            Cholesky::analyse(&p, &UNLIMITED).unwrap().work().operations,
            amd
        );
        // the kept order factors and solves an SPD matrix on the pattern
        let values = diagonally_dominant(&p);
        let factor = kept.factor(&p, &values).unwrap();
        let x_true: Vec<f64> = (0..p.n).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut b = vec![0.0; p.n];
        p.mul(&values, &x_true, &mut b);
        factor.solve_in_place(&mut b);
        let err = b
            .iter()
            .zip(&x_true)
            .fold(0.0f64, |m, (a, t)| m.max((a - t).abs()));
        assert!(err < 1e-10, "solution error {err:e}");
        // a small system keeps AMD's order even with points
        let (small, small_points) = q4_rectangle(40, 20);
        assert_eq!(
            Cholesky::analyse_at(&small, Some(&small_points), &UNLIMITED)
                .unwrap()
                .work()
                .operations,
            Cholesky::analyse(&small, &UNLIMITED)
                .unwrap()
                .work()
                .operations
        );
    }

    #[test]
    fn an_expensive_geometric_factor_is_compared_with_amd_and_metis() {
        // a 26^3 Hex8 grid (52,728 equations): the geometric dissection's factor is above both
        // bounds, so AMD and METIS are analysed too and the cheapest of the three kept
        let m = 26;
        let p = hex8_grid_pattern(m);
        assert!(p.n >= COORDINATE_DISSECTION_FROM);
        let points: Vec<[f64; 3]> = (0..p.n)
            .map(|e| {
                let v = e / 3;
                [(v % m) as f64, ((v / m) % m) as f64, (v / (m * m)) as f64]
            })
            .collect();
        let CandidateWork {
            amd,
            metis,
            geometric,
        } = candidate_work(&p, &[], Some(&points));
        let geometric = geometric.unwrap();
        assert!(
            geometric > NESTED_DISSECTION_ABOVE
                && geometric > DISSECTION_WORK_PER_EQUATION * p.n as f64,
            "geometric {geometric:e}"
        );
        let kept = Cholesky::analyse_at(&p, Some(&points), &UNLIMITED)
            .unwrap()
            .work()
            .operations;
        assert_eq!(
            kept,
            geometric.min(amd).min(metis),
            "geometric {geometric:e}, AMD {amd:e}, METIS {metis:e}"
        );
    }

    #[test]
    fn the_trailing_analysis_with_points_keeps_the_trailing_equations_last() {
        // the bottom row's y dofs (contact rows on a boundary) last, the rest by the cheaper
        // of AMD and the geometric dissection
        let (p, points) = q4_rectangle(400, 80);
        let trailing: Vec<usize> = (0..400).map(|i| 2 * i + 1).collect();
        let chol =
            Cholesky::analyse_with_trailing_at(&p, &trailing, Some(&points), &UNLIMITED).unwrap();
        assert_eq!(chol.trailing.as_deref(), Some(&trailing[..]));
        let amd = candidate_work(&p, &trailing, None).amd;
        assert!(
            chol.work().operations < amd,
            "kept {:e}, AMD {amd:e}",
            chol.work().operations
        );
    }

    #[test]
    fn the_analysis_keeps_the_cheaper_of_amd_and_the_dissection() {
        // a 2D grid whose AMD factor is cheap per equation (AMD kept without a second
        // analysis) and a 3D grid whose AMD factor is far above both thresholds (the cheaper
        // of the two kept)
        for (p, tried) in [(q4_grid_pattern(230), false), (hex8_grid_pattern(24), true)] {
            let CandidateWork { amd, metis: nd, .. } = candidate_work(&p, &[], None);
            let expensive =
                amd > NESTED_DISSECTION_ABOVE && amd > DISSECTION_WORK_PER_EQUATION * p.n as f64;
            assert_eq!(expensive, tried, "n {}: amd {amd:e}", p.n);
            let expected = if tried { amd.min(nd) } else { amd };
            let kept = Cholesky::analyse(&p, &UNLIMITED).unwrap().work().operations;
            assert_eq!(kept, expected, "n {}: amd {amd:e}, nd {nd:e}", p.n);
            if tried {
                // in 3D the dissection is the one kept, well below AMD
                assert!(nd < 0.8 * amd, "amd {amd:e}, nd {nd:e}");
            }
        }
    }

    #[test]
    fn a_dissected_trailing_analysis_ends_with_the_trailing_block() {
        // the trailing equations (the z dofs of the bottom layer, as contact rows on a
        // boundary) are eliminated last in their order, after the cheaper order of the
        // leading block
        let m = 24;
        let p = hex8_grid_pattern(m);
        let trailing: Vec<usize> = (0..m * m).rev().map(|v| 3 * v + 2).collect();
        let chol = Cholesky::analyse_with_trailing(&p, &trailing, &UNLIMITED).unwrap();
        assert_eq!(chol.trailing.as_deref(), Some(&trailing[..]));
        let CandidateWork { amd, metis: nd, .. } = candidate_work(&p, &trailing, None);
        assert!(nd < amd, "amd {amd:e}, nd {nd:e}");
        assert_eq!(chol.work().operations, nd, "amd {amd:e}, nd {nd:e}");
    }

    #[test]
    fn an_invalid_trailing_set_is_the_amd_analysis() {
        let (p, _) = grid_laplacian(5);
        for bad in [vec![0, 0], vec![3, 25], vec![]] {
            let chol = Cholesky::analyse_with_trailing(&p, &bad, &UNLIMITED).unwrap();
            assert!(chol.trailing.is_none(), "{bad:?}");
            assert_eq!(
                chol.work(),
                Cholesky::analyse(&p, &UNLIMITED).unwrap().work()
            );
        }
    }

    /// Upper pattern of a dense `n x n` matrix.
    fn dense_pattern(n: usize) -> SymmetricPattern {
        let mut b = PatternBuilder::new(n);
        b.add_block(&(0..n).collect::<Vec<_>>());
        b.build()
    }

    #[test]
    fn the_work_of_a_dense_factor_is_n_cubed_over_three() {
        for n in [1usize, 7, 40, 200] {
            let p = dense_pattern(n);
            let chol = Cholesky::analyse(&p, &UNLIMITED).unwrap();
            let work = FactorWork::of(&chol.symbolic);
            // sum_{c=1}^{n} c^2 = n (n + 1) (2n + 1) / 6, n^3/3 to leading order
            let exact = (n * (n + 1) * (2 * n + 1) / 6) as f64;
            assert_eq!(work.operations, exact, "n = {n}");
            let third = (n as f64).powi(3) / 3.0;
            assert!((work.operations - third).abs() <= (n * n) as f64, "n = {n}");
            assert_eq!(work.equations, n);
            // n (n + 1) / 2 entries column by column, n^2 in one dense supernode block
            let expected = if chol.is_supernodal() {
                n * n
            } else {
                n * (n + 1) / 2
            };
            assert_eq!(work.entries, expected, "n = {n}");
            assert_eq!(work.gigabytes(), expected as f64 * 8.0 / 1e9);
        }
    }

    #[test]
    fn the_work_of_a_chain_has_no_fill() {
        // tridiagonal: every column of L holds its diagonal and one entry below, the last
        // only its diagonal, whatever the AMD ordering (a path stays a path)
        let n = 500;
        let mut b = PatternBuilder::new(n);
        for i in 0..n - 1 {
            b.add_block(&[i, i + 1]);
        }
        let p = b.build();
        let work = FactorWork::of(&Cholesky::analyse(&p, &UNLIMITED).unwrap().symbolic);
        assert_eq!(work.operations, (4 * (n - 1) + 1) as f64);
    }

    #[test]
    fn a_factor_above_either_limit_is_refused_with_its_size() {
        let n = 40;
        let p = dense_pattern(n);
        let operations = (n * (n + 1) * (2 * n + 1) / 6) as f64;
        let at = |gigabytes: f64, operations: f64| WorkLimit {
            gigabytes,
            operations,
        };
        // exactly at the limit passes, just below refuses
        assert!(Cholesky::analyse(&p, &at(1.0, operations)).is_ok());
        match Cholesky::analyse(&p, &at(1.0, operations - 1.0)) {
            Err(FactorError::TooLarge { work, limit }) => {
                assert_eq!(work.operations, operations);
                assert_eq!(limit.operations, operations - 1.0);
                let text = work.refusal(&limit);
                assert!(text.contains("40 equations"), "{text}");
                assert!(text.contains("limits.factor_operations"), "{text}");
            }
            other => panic!("not refused: {:?}", other.map(|_| ())),
        }
        let entries = FactorWork::of(&Cholesky::analyse(&p, &UNLIMITED).unwrap().symbolic).entries;
        let gigabytes = entries as f64 * 8.0 / 1e9;
        assert!(Cholesky::analyse(&p, &at(gigabytes, f64::INFINITY)).is_ok());
        assert!(matches!(
            Cholesky::analyse(&p, &at(gigabytes * 0.999, f64::INFINITY)),
            Err(FactorError::TooLarge { .. })
        ));
        // LDL^T of the same pattern with its last 10 equations ordered last: still dense
        assert!(matches!(
            Ldlt::analyse(&p, n - 10, &at(1.0, operations - 1.0)),
            Err(FactorError::TooLarge { .. })
        ));
        assert!(Ldlt::analyse(&p, n - 10, &at(1.0, operations)).is_ok());
        // LU: L and U each the size of the Cholesky factor
        let g = GeneralPattern::from_symmetric(&p);
        assert!(Lu::analyse(&g, &at(1.0, 2.0 * operations)).is_ok());
        match Lu::analyse(&g, &at(1.0, 2.0 * operations - 1.0)) {
            Err(FactorError::TooLarge { work, .. }) => {
                assert_eq!(work.operations, 2.0 * operations);
                assert_eq!(work.entries, 2 * entries);
            }
            other => panic!("not refused: {:?}", other.map(|_| ())),
        }
    }

    /// A chain of `n` displacements (K tridiagonal, SPD) and `n - 1` multipliers, each tying
    /// its own displacement `i + 1` to the shared displacement 0 (a long interface against a
    /// coarse master): `u_{i+1} - u_0 = g_i`.
    fn hub_saddle(n: usize) -> (SymmetricPattern, Vec<f64>) {
        let m = n - 1;
        let mut pb = PatternBuilder::new(n + m);
        for i in 0..n - 1 {
            pb.add_block(&[i, i + 1]);
        }
        for i in 0..m {
            pb.add_block(&[0, i + 1, n + i]);
        }
        let p = pb.build();
        let mut v = vec![0.0; p.nnz()];
        let mut set = |i: usize, j: usize, x: f64| v[p.position(i, j).unwrap()] = x;
        for i in 0..n {
            set(i, i, 2.0);
        }
        for i in 0..n - 1 {
            set(i, i + 1, -1.0);
        }
        for i in 0..m {
            set(0, n + i, 1.0);
            set(i + 1, n + i, -1.0);
        }
        (p, v)
    }

    #[test]
    fn multipliers_beside_their_own_displacements_keep_the_factor_sparse_and_solve() {
        let n = 300;
        let (p, v) = hub_saddle(n);
        let last = FactorWork::of(&multipliers_last(&p, n).unwrap());
        // multipliers last: the hub couples them all, their block is dense, m^3/3 and more
        let m = (n - 1) as f64;
        assert!(last.operations >= m * m * m / 3.0, "{last:?}");
        let (fwd, inv) = multipliers_after_their_displacements(&p, n).unwrap();
        // every multiplier right after its own displacement i + 1
        for i in 0..n - 1 {
            assert_eq!(inv[n + i], inv[i + 1] + 1, "multiplier {i}");
        }
        assert!((0..p.n).all(|k| inv[fwd[k]] == k));
        let perm = faer::perm::PermRef::new_checked(&fwd, &inv, p.n);
        let symbolic = factorize_symbolic_cholesky(
            p.symbolic(),
            Side::Upper,
            SymmetricOrdering::Custom(perm),
            Default::default(),
        )
        .unwrap();
        let interleaved = FactorWork::of(&symbolic);
        // a chain with one hub: a bounded number of entries per column
        assert!(
            interleaved.operations <= 100.0 * p.n as f64,
            "{interleaved:?}"
        );
        // without a limit the analysis keeps the cheaper order
        assert_eq!(
            FactorWork::of(&Ldlt::analyse(&p, n, &UNLIMITED).unwrap().symbolic),
            interleaved
        );
        // under a limit only the interleaved order meets, the analysis takes it and solves
        let limit = WorkLimit {
            gigabytes: 1.0,
            operations: interleaved.operations,
        };
        let ldlt = Ldlt::analyse(&p, n, &limit).unwrap();
        assert_eq!(FactorWork::of(&ldlt.symbolic), interleaved);
        let x: Vec<f64> = (0..p.n)
            .map(|i| ((i * 7919) % 101) as f64 / 50.0 - 1.0)
            .collect();
        let mut b = vec![0.0; p.n];
        p.mul(&v, &x, &mut b);
        let signs: Vec<i8> = (0..p.n).map(|i| if i < n { 1 } else { -1 }).collect();
        let f = ldlt.factor(&p, &v, &signs, 1e-14, 1.0).unwrap();
        f.solve_in_place(&mut b);
        for i in 0..p.n {
            assert!((b[i] - x[i]).abs() < 1e-9, "{i}: {} vs {}", b[i], x[i]);
        }
        // under a limit neither order meets: refused with the smaller work
        let below = WorkLimit {
            gigabytes: 1.0,
            operations: interleaved.operations - 1.0,
        };
        match Ldlt::analyse(&p, n, &below) {
            Err(FactorError::TooLarge { work, .. }) => assert_eq!(work, interleaved),
            other => panic!("not refused: {:?}", other.map(|_| ())),
        }
    }

    #[test]
    fn with_few_multipliers_the_analysis_keeps_the_cheaper_of_the_two_orders() {
        // a chain of 60 displacements and 2 multipliers tying far-apart pairs of them: both
        // orders are analysed, and the one kept costs the fewer operations of the two
        let n = 60;
        let mut pb = PatternBuilder::new(n + 2);
        for i in 0..n - 1 {
            pb.add_block(&[i, i + 1]);
        }
        pb.add_block(&[0, n - 1, n]);
        pb.add_block(&[10, 40, n + 1]);
        let p = pb.build();
        let last = FactorWork::of(&multipliers_last(&p, n).unwrap());
        let (fwd, inv) = multipliers_after_their_displacements(&p, n).unwrap();
        let perm = faer::perm::PermRef::new_checked(&fwd, &inv, p.n);
        let interleaved = FactorWork::of(
            &factorize_symbolic_cholesky(
                p.symbolic(),
                Side::Upper,
                SymmetricOrdering::Custom(perm),
                Default::default(),
            )
            .unwrap(),
        );
        let kept = FactorWork::of(&Ldlt::analyse(&p, n, &UNLIMITED).unwrap().symbolic);
        let cheaper = if interleaved.operations < last.operations {
            interleaved
        } else {
            last
        };
        assert_eq!(kept, cheaper, "last {last:?}, interleaved {interleaved:?}");
    }

    #[test]
    fn lu_solves_unsymmetric_values_and_reuses_its_analysis() {
        // a symmetric structure (blocks of a chain) with unsymmetric values
        let n = 40;
        let mut pb = PatternBuilder::new(n);
        for i in 0..n - 2 {
            pb.add_block(&[i, i + 1, i + 2]);
        }
        let general = GeneralPattern::from_symmetric(&pb.build());
        let lu = Lu::analyse(&general, &UNLIMITED).unwrap();
        for trial in 0..2 {
            let mut a = vec![0.0; general.nnz()];
            for j in 0..n {
                for k in general.col_ptr[j]..general.col_ptr[j + 1] {
                    let i = general.row_idx[k];
                    a[k] = if i == j {
                        4.0 + trial as f64
                    } else {
                        0.3 * (i as f64 + 2.0 * j as f64 + trial as f64).sin()
                    };
                }
            }
            let x: Vec<f64> = (0..n).map(|i| (0.7 * i as f64).cos()).collect();
            let mut b = vec![0.0; n];
            for j in 0..n {
                for k in general.col_ptr[j]..general.col_ptr[j + 1] {
                    b[general.row_idx[k]] += a[k] * x[j];
                }
            }
            lu.factor(&general, &a).unwrap().solve_in_place(&mut b);
            for i in 0..n {
                assert!(
                    (b[i] - x[i]).abs() < 1e-12,
                    "trial {trial}, {i}: {} vs {}",
                    b[i],
                    x[i]
                );
            }
        }
        // symmetric values expand from the upper triangle
        let mut pb = PatternBuilder::new(3);
        pb.add_block(&[0, 1, 2]);
        let p = pb.build();
        let upper: Vec<f64> = (0..p.nnz()).map(|k| k as f64 + 1.0).collect();
        let g = GeneralPattern::from_symmetric(&p);
        let full = g.symmetric_values(&upper);
        for i in 0..3 {
            for j in 0..3 {
                let (r, c) = (i.min(j), i.max(j));
                assert_eq!(
                    full[g.position(i, j).unwrap()],
                    upper[p.position(r, c).unwrap()]
                );
            }
        }
    }

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
        let chol = Cholesky::analyse(&pattern, &UNLIMITED).unwrap();
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
        let chol = Cholesky::analyse(&pattern, &UNLIMITED).unwrap();
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
        let f = Ldlt::analyse(&p, 3, &UNLIMITED)
            .unwrap()
            .factor(&p, &v, &[1, 1, 1, -1], 1e-14, 1.0)
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
                let chol = Cholesky::analyse(&p, &UNLIMITED).unwrap();
                assert_eq!(chol.is_supernodal(), supernodal);
                assert_eq!(
                    chol.factor(&p, &v).err(),
                    Some(FactorError::NotPositiveDefinite { equation: loose }),
                    "side {side}, value {value}"
                );
            }
            let (p, v) = grid_with_loose_equation(side, loose, 1.0);
            assert!(Cholesky::analyse(&p, &UNLIMITED)
                .unwrap()
                .factor(&p, &v)
                .is_ok());
        }
    }

    #[test]
    fn a_pivot_that_is_zero_relative_to_its_diagonal_is_reported() {
        // [[1, 1], [1, 1 + 1e-14]]: the second pivot is 1e-14 of its diagonal
        let mut pb = PatternBuilder::new(3);
        pb.add_block(&[0, 2]);
        let p = pb.build();
        let mut v = vec![0.0; p.nnz()];
        p.scatter(&[0, 2], &[1.0, 1.0, 1.0, 1.0 + 1e-14], &mut v);
        v[p.position(1, 1).unwrap()] = 1.0;
        match Cholesky::analyse(&p, &UNLIMITED).unwrap().factor(&p, &v) {
            Err(FactorError::ZeroPivot {
                equation, ratio, ..
            }) => {
                assert!(equation == 0 || equation == 2, "{equation}");
                assert!(ratio < 1e-13 && ratio > 0.0, "{ratio}");
            }
            other => panic!("{:?}", other.err()),
        }
    }

    #[test]
    fn a_regularized_ldlt_pivot_is_reported() {
        // K = [[1, -1], [-1, 1]] (free in u0 = u1) with the constraint u0 - u1 = 0, which does
        // not hold that motion: the saddle-point matrix is singular
        let mut pb = PatternBuilder::new(3);
        pb.add_block(&[0, 1, 2]);
        let p = pb.build();
        let mut v = vec![0.0; p.nnz()];
        let mut set = |i: usize, j: usize, x: f64| v[p.position(i, j).unwrap()] = x;
        set(0, 0, 1.0);
        set(1, 1, 1.0);
        set(0, 1, -1.0);
        set(0, 2, -1.0);
        set(1, 2, 1.0);
        let err = Ldlt::analyse(&p, 2, &UNLIMITED)
            .unwrap()
            .factor(&p, &v, &[1, 1, -1], 1e-13, 1.0)
            .err();
        assert!(
            matches!(err, Some(FactorError::ZeroPivot { regularized, .. }) if regularized >= 1),
            "{err:?}"
        );
    }

    #[test]
    fn the_accurate_residual_keeps_what_plain_arithmetic_rounds_away() {
        // A = [[1, 1], [1, 3]], x = [1, 1e-16], b = [1, 1]: b - A x = [-1e-16, -3e-16], which
        // plain arithmetic rounds to zero (1 + 1e-16 = 1)
        let mut pb = PatternBuilder::new(2);
        pb.add_block(&[0, 1]);
        let p = pb.build();
        let mut v = vec![0.0; p.nnz()];
        p.scatter(&[0, 1], &[1.0, 1.0, 1.0, 3.0], &mut v);
        let (x, b) = ([1.0, 1e-16], [1.0, 1.0]);
        let mut plain = [0.0; 2];
        p.mul(&v, &x, &mut plain);
        assert_eq!(b[0] - plain[0], 0.0);
        let mut r = [0.0; 2];
        p.residual_accurate(&v, &x, &b, &mut r);
        assert_eq!(r, [-1e-16, -3.0 * 1e-16]);
    }
}
