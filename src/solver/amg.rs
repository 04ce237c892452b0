//! Smoothed-aggregation algebraic multigrid (SA-AMG) as a preconditioner of the conjugate
//! gradient method, for the symmetric positive definite systems of small-strain elasticity
//! and of penalty-type contact (`K + sum_i w_i b_i b_i^T`, `w_i > 0`).
//!
//! Reference: P. Vanek, J. Mandel and M. Brezina, "Algebraic multigrid by smoothed aggregation
//! for second and fourth order elliptic problems", Computing 56 (1996) 179-196 (sec. 3:
//! strength of connection and aggregation; sec. 4: the tentative prolongator from the
//! near-null space, smoothed by damped Jacobi); the preconditioner and its smoother follow
//! Y. Saad, *Iterative Methods for Sparse Linear Systems*, 2nd ed., SIAM 2003 (alg. 9.1,
//! preconditioned CG; alg. 12.1, Chebyshev acceleration) and M. Adams, M. Brezina, J. Hu and
//! R. Tuminaro, "Parallel multigrid smoothing: polynomial versus Gauss-Seidel", J. Comput.
//! Phys. 188 (2003) 593-610 (Chebyshev smoothers); the l1 diagonal is that of A. Baker,
//! R. Falgout, T. Kolev and U. Yang, "Multigrid smoothers for ultraparallel computing", SIAM
//! J. Sci. Comput. 33 (2011) 2864-2887, sec. 6.2.
//!
//! Levels `l = 0 .. L` with matrices `A_0 = A` and `A_{l+1} = P_l^T A_l P_l` (Galerkin).
//!
//! * Near-null space `B_0` (`n x m`): the rigid-body modes of the nodes' coordinates, three
//!   in 2D (`(1, 0)`, `(0, 1)`, `(-y, x)`) and six in 3D (three translations, the rotations
//!   `e_k x (x - x_c)`), restricted to the free equations.
//! * Strength of connection on nodal blocks (the dofs of one node, or of one coarse
//!   aggregate): blocks `I != J` are strongly connected when
//!   `||A_IJ||_F >= theta_l (||A_II||_F ||A_JJ||_F)^(1/2)`, `theta_l = 0.08 (1/2)^l`
//!   (Vanek et al., eq. 3.1 with their `epsilon`, halved per level).
//! * Aggregation (Vanek et al., alg. 5.1): (1) every block whose strong neighbourhood is
//!   non-empty and still free forms an aggregate with it; (2) every left-over block joins the
//!   aggregate of a strong neighbour aggregated in (1); (3) what is still left with strong
//!   neighbours forms aggregates of its free strong neighbourhoods; (4) the blocks without
//!   strong neighbours, which Vanek et al. leave out of the coarse space (right for a
//!   Dirichlet row), are aggregated among themselves by (1) and (2) on the graph of their
//!   couplings `||A_IJ||_F >= theta_l (m_I m_J)^(1/2)`, `m_I = max_{K != I} ||A_IK||_F`
//!   (strength relative to the largest coupling instead of the diagonal), and what is left
//!   joins the aggregate of its most strongly coupled aggregated neighbour. A contact node
//!   under a large penalty has a dominant diagonal block through its normal dof alone, its
//!   tangential dofs need the coarse correction: as a one-node aggregate it would stay a
//!   block of its own on every level and stall the coarsening (the 3D slab: 1,090,824 ->
//!   202,404 -> 127,812 equations); the contact layer aggregates as a layer.
//! * Tentative prolongator: on each aggregate `a` with rows `E_a`, the thin QR factorization
//!   `B_0[E_a, :] = Q_a R_a` (modified Gram-Schmidt, twice, dropping columns whose remainder
//!   is below `1e-10` of their norm: a one-node aggregate holds fewer dofs than modes);
//!   `P_tent[E_a, cols_a] = Q_a` and the coarse near-null space is `B_1[cols_a, :] = R_a`, so
//!   `P_tent B_1 = B_0` and `P_tent^T P_tent = I`. Each aggregate is one nodal block of the
//!   next level.
//! * Prolongator smoothing: `P = (I - omega D^-1 A) P_tent`, `omega = 4 / (3 rho)`,
//!   `rho` the spectral radius of `D^-1 A` estimated by power iteration (`D = diag A`).
//! * Smoother: Chebyshev acceleration of degree `k` on `D_l1^-1 A` with
//!   `D_l1 = diag(sum_j |a_ij|)`, whose spectrum lies in `(0, 1]` (Gershgorin: the infinity
//!   norm of `D_l1^-1 A` is 1); the interval is `[u / 10, u]` with `u = min(1, 1.1 lambda)`,
//!   `lambda` a power-iteration estimate of its largest eigenvalue. A polynomial in
//!   `D_l1^-1 A` is self-adjoint in the `A` inner product, so the same polynomial before and
//!   after the coarse correction makes the V-cycle symmetric, and it is positive definite
//!   while the smoother contracts in the energy norm (`|1 - lambda p(lambda)| < 1` on the
//!   spectrum, which holds on `(0, u]` and up to about 10 % beyond it for degree 2).
//! * Coarsest level (at most [`AmgOptions::coarsest_size`] equations, or when coarsening
//!   stalls): the sparse Cholesky factorization of [`crate::solver::sparse`], within the
//!   case's `limits.factor_*` ([`AmgOptions::factor_limit`]; above them the setup is refused
//!   with the levels' sizes, [`AmgError::CoarsestTooLarge`]).
//! * Preconditioned CG ([`conjugate_gradient`]) with the V-cycle `M`: stops when
//!   `||b - A x||_2 <= tol ||b||_2`; the final relative residual is recomputed from `x`.
//!
//! Matrix-vector products, the smoother's vector updates and the sparse products of the
//! setup run on all cores (rayon, row blocks).

use crate::solver::sparse::{
    Cholesky, Factor, FactorError, SymmetricPattern, WorkLimit, UNLIMITED,
};
use rayon::prelude::*;

/// Power iterations of the spectral-radius estimates (Rayleigh quotients, whose error is the
/// square of the eigenvector's).
const POWER_STEPS: usize = 12;

/// Rows per parallel task of a sparse product or vector update.
const ROWS_PER_TASK: usize = 4096;

/// A sparse matrix in compressed sparse rows (both triangles of a symmetric matrix).
#[derive(Clone, Debug)]
pub struct CsrMatrix {
    pub rows: usize,
    pub cols: usize,
    pub row_ptr: Vec<usize>,
    pub col_idx: Vec<usize>,
    pub values: Vec<f64>,
}

impl CsrMatrix {
    /// The full symmetric matrix whose upper triangle is `values` on `pattern`.
    pub fn from_symmetric_upper(pattern: &SymmetricPattern, values: &[f64]) -> CsrMatrix {
        let n = pattern.n;
        let mut count = vec![0usize; n + 1];
        for j in 0..n {
            for k in pattern.col_ptr[j]..pattern.col_ptr[j + 1] {
                let i = pattern.row_idx[k];
                count[i + 1] += 1;
                if i != j {
                    count[j + 1] += 1;
                }
            }
        }
        for i in 0..n {
            count[i + 1] += count[i];
        }
        let row_ptr = count.clone();
        let mut next = count;
        let nnz = row_ptr[n];
        let mut col_idx = vec![0usize; nnz];
        let mut vals = vec![0.0; nnz];
        // column j of the upper triangle holds entries (i, j), i <= j, rows increasing: it
        // gives row j its entries left of the diagonal (columns i < j, increasing), then every
        // row i <= j its entry in column j; columns are visited in increasing order, so every
        // row is filled left to right
        for j in 0..n {
            for k in pattern.col_ptr[j]..pattern.col_ptr[j + 1] {
                let i = pattern.row_idx[k];
                if i != j {
                    col_idx[next[j]] = i;
                    vals[next[j]] = values[k];
                    next[j] += 1;
                }
            }
            for k in pattern.col_ptr[j]..pattern.col_ptr[j + 1] {
                let i = pattern.row_idx[k];
                col_idx[next[i]] = j;
                vals[next[i]] = values[k];
                next[i] += 1;
            }
        }
        let mut m = CsrMatrix {
            rows: n,
            cols: n,
            row_ptr,
            col_idx,
            values: vals,
        };
        m.sort_rows();
        m
    }

    fn sort_rows(&mut self) {
        let CsrMatrix {
            row_ptr,
            col_idx,
            values,
            ..
        } = self;
        let mut pairs: Vec<(usize, f64)> = Vec::new();
        for i in 0..row_ptr.len() - 1 {
            let range = row_ptr[i]..row_ptr[i + 1];
            if col_idx[range.clone()].windows(2).all(|w| w[0] < w[1]) {
                continue;
            }
            pairs.clear();
            pairs.extend(
                col_idx[range.clone()]
                    .iter()
                    .copied()
                    .zip(values[range.clone()].iter().copied()),
            );
            pairs.sort_unstable_by_key(|p| p.0);
            for (k, (c, v)) in range.zip(pairs.iter()) {
                col_idx[k] = *c;
                values[k] = *v;
            }
        }
    }

    pub fn nnz(&self) -> usize {
        self.col_idx.len()
    }

    /// `y = A x`, row blocks in parallel.
    pub fn mul(&self, x: &[f64], y: &mut [f64]) {
        y.par_chunks_mut(ROWS_PER_TASK)
            .enumerate()
            .for_each(|(t, chunk)| {
                let first = t * ROWS_PER_TASK;
                for (o, yi) in chunk.iter_mut().enumerate() {
                    let i = first + o;
                    let mut s = 0.0;
                    for k in self.row_ptr[i]..self.row_ptr[i + 1] {
                        s += self.values[k] * x[self.col_idx[k]];
                    }
                    *yi = s;
                }
            });
    }

    /// `y += A x`.
    fn mul_add(&self, x: &[f64], y: &mut [f64]) {
        y.par_chunks_mut(ROWS_PER_TASK)
            .enumerate()
            .for_each(|(t, chunk)| {
                let first = t * ROWS_PER_TASK;
                for (o, yi) in chunk.iter_mut().enumerate() {
                    let i = first + o;
                    let mut s = 0.0;
                    for k in self.row_ptr[i]..self.row_ptr[i + 1] {
                        s += self.values[k] * x[self.col_idx[k]];
                    }
                    *yi += s;
                }
            });
    }

    /// `r = b - A x`.
    fn residual(&self, b: &[f64], x: &[f64], r: &mut [f64]) {
        r.par_chunks_mut(ROWS_PER_TASK)
            .enumerate()
            .for_each(|(t, chunk)| {
                let first = t * ROWS_PER_TASK;
                for (o, ri) in chunk.iter_mut().enumerate() {
                    let i = first + o;
                    let mut s = b[i];
                    for k in self.row_ptr[i]..self.row_ptr[i + 1] {
                        s -= self.values[k] * x[self.col_idx[k]];
                    }
                    *ri = s;
                }
            });
    }

    /// The diagonal (0 where none is stored).
    pub fn diagonal(&self) -> Vec<f64> {
        (0..self.rows)
            .map(|i| {
                let range = self.row_ptr[i]..self.row_ptr[i + 1];
                self.col_idx[range.clone()]
                    .binary_search(&i)
                    .map_or(0.0, |k| self.values[range.start + k])
            })
            .collect()
    }

    /// `A^T`.
    pub fn transpose(&self) -> CsrMatrix {
        let mut count = vec![0usize; self.cols + 1];
        for &c in &self.col_idx {
            count[c + 1] += 1;
        }
        for c in 0..self.cols {
            count[c + 1] += count[c];
        }
        let row_ptr = count.clone();
        let mut next = count;
        let mut col_idx = vec![0usize; self.nnz()];
        let mut values = vec![0.0; self.nnz()];
        for i in 0..self.rows {
            for k in self.row_ptr[i]..self.row_ptr[i + 1] {
                let c = self.col_idx[k];
                col_idx[next[c]] = i;
                values[next[c]] = self.values[k];
                next[c] += 1;
            }
        }
        CsrMatrix {
            rows: self.cols,
            cols: self.rows,
            row_ptr,
            col_idx,
            values,
        }
    }

    /// `A B` (Gustavson's row-by-row product with a dense accumulator; row blocks in parallel).
    pub fn product(&self, other: &CsrMatrix) -> CsrMatrix {
        assert_eq!(self.cols, other.rows, "product of incompatible matrices");
        let tasks = self.rows.div_ceil(ROWS_PER_TASK).max(1);
        let blocks: Vec<(Vec<usize>, Vec<usize>, Vec<f64>)> = (0..tasks)
            .into_par_iter()
            .map(|t| {
                let rows = t * ROWS_PER_TASK..((t + 1) * ROWS_PER_TASK).min(self.rows);
                let mut marker = vec![usize::MAX; other.cols];
                let mut accumulator = vec![0.0; other.cols];
                let mut lengths = Vec::with_capacity(rows.len());
                let mut cols = Vec::new();
                let mut vals = Vec::new();
                for i in rows {
                    let start = cols.len();
                    for k in self.row_ptr[i]..self.row_ptr[i + 1] {
                        let (j, a) = (self.col_idx[k], self.values[k]);
                        for kk in other.row_ptr[j]..other.row_ptr[j + 1] {
                            let c = other.col_idx[kk];
                            if marker[c] != i {
                                marker[c] = i;
                                accumulator[c] = 0.0;
                                cols.push(c);
                            }
                            accumulator[c] += a * other.values[kk];
                        }
                    }
                    cols[start..].sort_unstable();
                    vals.extend(cols[start..].iter().map(|&c| accumulator[c]));
                    lengths.push(cols.len() - start);
                }
                (lengths, cols, vals)
            })
            .collect();
        let mut row_ptr = Vec::with_capacity(self.rows + 1);
        row_ptr.push(0);
        let nnz = blocks.iter().map(|b| b.1.len()).sum();
        let mut col_idx = Vec::with_capacity(nnz);
        let mut values = Vec::with_capacity(nnz);
        for (lengths, cols, vals) in blocks {
            for l in lengths {
                row_ptr.push(row_ptr.last().copied().unwrap_or(0) + l);
            }
            col_idx.extend(cols);
            values.extend(vals);
        }
        CsrMatrix {
            rows: self.rows,
            cols: other.cols,
            row_ptr,
            col_idx,
            values,
        }
    }

    /// The upper triangle as a [`SymmetricPattern`] and its values (for the Cholesky of the
    /// coarsest level); the matrix is symmetrized as `(A + A^T) / 2` on the way.
    fn symmetric_upper(&self) -> (SymmetricPattern, Vec<f64>) {
        let t = self.transpose();
        let mut col_ptr = vec![0usize];
        let mut row_idx = Vec::new();
        let mut values = Vec::new();
        // column j of the upper triangle is row j of the lower one: entries (j, i), i <= j
        for j in 0..self.rows {
            let mut entries: Vec<(usize, f64)> = Vec::new();
            for k in self.row_ptr[j]..self.row_ptr[j + 1] {
                if self.col_idx[k] <= j {
                    entries.push((self.col_idx[k], 0.5 * self.values[k]));
                }
            }
            for k in t.row_ptr[j]..t.row_ptr[j + 1] {
                if t.col_idx[k] <= j {
                    entries.push((t.col_idx[k], 0.5 * t.values[k]));
                }
            }
            entries.push((j, 0.0));
            entries.sort_unstable_by_key(|e| e.0);
            let mut last = usize::MAX;
            for (i, v) in entries {
                if i == last {
                    *values.last_mut().expect("an entry was pushed") += v;
                } else {
                    row_idx.push(i);
                    values.push(v);
                    last = i;
                }
            }
            col_ptr.push(row_idx.len());
        }
        (
            SymmetricPattern {
                n: self.rows,
                col_ptr,
                row_idx,
            },
            values,
        )
    }
}

/// The equations of each nodal block (a node's free dofs, or a coarse aggregate's columns).
#[derive(Clone, Debug)]
pub struct NodalBlocks {
    pub ptr: Vec<usize>,
    pub equations: Vec<usize>,
}

impl NodalBlocks {
    pub fn count(&self) -> usize {
        self.ptr.len() - 1
    }

    fn block(&self, b: usize) -> &[usize] {
        &self.equations[self.ptr[b]..self.ptr[b + 1]]
    }

    /// Blocks from the block of each equation (`block_of[e]`, any numbering of blocks).
    pub fn from_block_of(block_of: &[usize]) -> NodalBlocks {
        let count = block_of.iter().map(|&b| b + 1).max().unwrap_or(0);
        let mut ptr = vec![0usize; count + 1];
        for &b in block_of {
            ptr[b + 1] += 1;
        }
        for b in 0..count {
            ptr[b + 1] += ptr[b];
        }
        let mut next = ptr.clone();
        let mut equations = vec![0usize; block_of.len()];
        for (e, &b) in block_of.iter().enumerate() {
            equations[next[b]] = e;
            next[b] += 1;
        }
        // drop empty blocks
        let mut compact = vec![0usize];
        for b in 0..count {
            if ptr[b + 1] > ptr[b] {
                compact.push(ptr[b + 1]);
            }
        }
        NodalBlocks {
            ptr: compact,
            equations,
        }
    }
}

/// The near-null space: `rows x modes`, row-major.
#[derive(Clone, Debug)]
pub struct NearNullSpace {
    pub modes: usize,
    pub values: Vec<f64>,
}

/// The rigid-body modes at equations with node coordinates `points` (the unused coordinates
/// zero in 2D) and displacement components `components`, in `dimension` 2 (3 modes) or 3 (6
/// modes); the rotations are about the centroid of the points.
pub fn rigid_body_modes(
    points: &[[f64; 3]],
    components: &[usize],
    dimension: usize,
) -> NearNullSpace {
    let modes = if dimension == 2 { 3 } else { 6 };
    let n = points.len().max(1) as f64;
    let mut centre = [0.0; 3];
    for p in points {
        for k in 0..3 {
            centre[k] += p[k] / n;
        }
    }
    let mut values = vec![0.0; points.len() * modes];
    for (e, (p, &c)) in points.iter().zip(components).enumerate() {
        let x = [p[0] - centre[0], p[1] - centre[1], p[2] - centre[2]];
        let row = &mut values[e * modes..(e + 1) * modes];
        row[c] = 1.0;
        if dimension == 2 {
            // rotation (-y, x)
            row[2] = if c == 0 { -x[1] } else { x[0] };
        } else {
            // rotation about axis k: e_k x x
            let rotation = |k: usize| -> f64 {
                let mut axis = [0.0; 3];
                axis[k] = 1.0;
                let cross = [
                    axis[1] * x[2] - axis[2] * x[1],
                    axis[2] * x[0] - axis[0] * x[2],
                    axis[0] * x[1] - axis[1] * x[0],
                ];
                cross[c]
            };
            for k in 0..3 {
                row[3 + k] = rotation(k);
            }
        }
    }
    NearNullSpace { modes, values }
}

/// Tuning of the hierarchy.
#[derive(Copy, Clone, Debug)]
pub struct AmgOptions {
    /// Strength threshold of the finest level (halved per level).
    pub strength_threshold: f64,
    /// Degree of the Chebyshev smoother (matrix-vector products per sweep).
    pub smoother_degree: usize,
    /// A level with at most this many equations is solved by Cholesky.
    pub coarsest_size: usize,
    pub max_levels: usize,
    /// The most the Cholesky factorization of the coarsest level may cost (the case's
    /// `limits.factor_*`): a coarsening that stalls leaves a large coarsest level, which is
    /// refused ([`AmgError::CoarsestTooLarge`]) rather than factored at any cost.
    pub factor_limit: WorkLimit,
}

impl Default for AmgOptions {
    fn default() -> Self {
        AmgOptions {
            strength_threshold: 0.08,
            smoother_degree: 2,
            coarsest_size: 2000,
            max_levels: 20,
            factor_limit: UNLIMITED,
        }
    }
}

/// The Chebyshev smoother of one level.
#[derive(Clone, Debug)]
struct Chebyshev {
    /// `1 / sum_j |a_ij|`.
    inverse_l1: Vec<f64>,
    lower: f64,
    upper: f64,
    degree: usize,
}

impl Chebyshev {
    fn new(a: &CsrMatrix, degree: usize) -> Result<Chebyshev, AmgError> {
        let mut inverse_l1 = Vec::with_capacity(a.rows);
        for i in 0..a.rows {
            let s: f64 = a.values[a.row_ptr[i]..a.row_ptr[i + 1]]
                .iter()
                .map(|v| v.abs())
                .sum();
            if s <= 0.0 || !s.is_finite() {
                return Err(AmgError::EmptyRow(i));
            }
            inverse_l1.push(1.0 / s);
        }
        let estimate = largest_eigenvalue(a, &inverse_l1, POWER_STEPS);
        let upper = (1.1 * estimate).min(1.0);
        Ok(Chebyshev {
            inverse_l1,
            lower: upper / 10.0,
            upper,
            degree,
        })
    }

    /// `degree` Chebyshev steps on `A x = b` (Saad, alg. 12.1, preconditioned by `D_l1`);
    /// `x` is zero on entry when `zero_start`.
    fn smooth(&self, a: &CsrMatrix, b: &[f64], x: &mut [f64], zero_start: bool) {
        let n = b.len();
        let theta = 0.5 * (self.upper + self.lower);
        let delta = 0.5 * (self.upper - self.lower);
        let sigma = theta / delta;
        let mut rho = 1.0 / sigma;
        let mut r = vec![0.0; n];
        if zero_start {
            r.copy_from_slice(b);
        } else {
            a.residual(b, x, &mut r);
        }
        let mut d: Vec<f64> = r
            .par_iter()
            .zip(&self.inverse_l1)
            .with_min_len(ROWS_PER_TASK)
            .map(|(r, m)| r * m / theta)
            .collect();
        let mut ad = vec![0.0; n];
        for k in 0..self.degree {
            x.par_iter_mut()
                .zip(&d)
                .with_min_len(ROWS_PER_TASK)
                .for_each(|(x, d)| *x += d);
            if k + 1 == self.degree {
                break;
            }
            a.mul(&d, &mut ad);
            let rho_next = 1.0 / (2.0 * sigma - rho);
            let (c_d, c_r) = (rho_next * rho, 2.0 * rho_next / delta);
            r.par_iter_mut()
                .zip(&ad)
                .zip(d.par_iter_mut())
                .zip(&self.inverse_l1)
                .with_min_len(ROWS_PER_TASK)
                .for_each(|(((r, ad), d), m)| {
                    *r -= ad;
                    *d = c_d * *d + c_r * m * *r;
                });
            rho = rho_next;
        }
    }
}

/// The largest eigenvalue of `D^-1 A` (`D^-1 = inverse_diagonal`, positive), by `steps` power
/// iterations from a fixed pseudo-random start, as the Rayleigh quotient in the `D` inner
/// product (a lower bound that converges from below).
fn largest_eigenvalue(a: &CsrMatrix, inverse_diagonal: &[f64], steps: usize) -> f64 {
    let n = a.rows;
    if n == 0 {
        return 1.0;
    }
    // a fixed sequence (Weyl, golden ratio), so the setup is reproducible
    let mut v: Vec<f64> = (0..n)
        .map(|i| ((i as f64 * 0.618_033_988_749_895).fract() - 0.5) + 0.1)
        .collect();
    let mut av = vec![0.0; n];
    let mut estimate = 0.0;
    for _ in 0..steps {
        // D-norm of v
        let norm = dot_weighted(&v, &v, inverse_diagonal, true).sqrt();
        if norm == 0.0 || !norm.is_finite() {
            break;
        }
        v.par_iter_mut().for_each(|x| *x /= norm);
        a.mul(&v, &mut av);
        // Rayleigh quotient v^T A v / v^T D v with v^T D v = 1
        estimate = dot(&v, &av);
        v.par_iter_mut()
            .zip(&av)
            .zip(inverse_diagonal)
            .for_each(|((v, av), m)| *v = av * m);
    }
    estimate
}

/// `sum x_i y_i / w_i` when `divide`, else `sum x_i y_i w_i`.
fn dot_weighted(x: &[f64], y: &[f64], w: &[f64], divide: bool) -> f64 {
    x.par_iter()
        .zip(y)
        .zip(w)
        .with_min_len(ROWS_PER_TASK)
        .map(|((a, b), w)| if divide { a * b / w } else { a * b * w })
        .sum()
}

/// `x . y`.
pub fn dot(x: &[f64], y: &[f64]) -> f64 {
    x.par_iter()
        .zip(y)
        .with_min_len(ROWS_PER_TASK)
        .map(|(a, b)| a * b)
        .sum()
}

/// Why a hierarchy could not be built.
#[derive(Debug, Clone, PartialEq)]
pub enum AmgError {
    /// Row `equation` of a level's matrix has no nonzero entry (a dof nothing holds).
    EmptyRow(usize),
    /// The Cholesky factorization of the coarsest level failed (the matrix is not positive
    /// definite: a mechanism).
    Coarsest(String),
    /// The coarsest level's factor would exceed the case's limits: the coarsening stalled.
    CoarsestTooLarge {
        /// Equations of each level, finest first (the coarsest last).
        levels: Vec<usize>,
        /// The factor's size and the limits ([`crate::solver::sparse::FactorWork::refusal`]).
        refusal: String,
    },
}

impl std::fmt::Display for AmgError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            AmgError::EmptyRow(e) => write!(f, "equation {e} has an empty row (nothing holds it)"),
            AmgError::Coarsest(why) => write!(
                f,
                "the coarsest level of the multigrid hierarchy cannot be factored ({why})"
            ),
            AmgError::CoarsestTooLarge { levels, refusal } => write!(
                f,
                "the coarsest level of the multigrid hierarchy (levels of {levels:?} equations) is too large to factor: {refusal}; a coarsening that stalls leaves a large coarsest level; raise limits.factor_gigabytes and limits.factor_operations if the machine has the memory, or use \"linear_solver\": \"direct\""
            ),
        }
    }
}

/// One level above the coarsest: its matrix, smoother and transfer to the next level.
#[derive(Clone, Debug)]
struct Level {
    a: CsrMatrix,
    smoother: Chebyshev,
    /// `P` (this level's rows, the next level's columns) and `R = P^T`.
    p: CsrMatrix,
    r: CsrMatrix,
}

/// The SA-AMG hierarchy and its V-cycle.
pub struct Hierarchy {
    levels: Vec<Level>,
    /// The matrix when it is the coarsest level itself (no level above it).
    single: Option<CsrMatrix>,
    coarsest_size: usize,
    coarsest: Factor,
    /// `sum_l nnz(A_l) / nnz(A_0)`, the coarsest included.
    operator_complexity: f64,
}

/// The block graph of one level: the strong neighbours of each block and, for a block with
/// none (its diagonal block dominates every coupling, e.g. a contact node under a large
/// penalty), its neighbours from the strongest relative coupling down.
#[derive(Clone, Debug, PartialEq)]
struct BlockStrength {
    strong: Vec<Vec<usize>>,
    /// Empty unless `strong[i]` is empty.
    weak_by_strength: Vec<Vec<usize>>,
    /// For a block without strong neighbours, those of its neighbours without strong
    /// neighbours whose coupling is strong relative to the largest off-diagonal blocks:
    /// `||A_IJ||_F >= theta (m_I m_J)^(1/2)`, `m_I = max_{K != I} ||A_IK||_F`.
    layer: Vec<Vec<usize>>,
}

/// Blocks `I != J` strongly connected to each block (see the module doc), and the neighbours
/// of the blocks that have no strong one, by decreasing `||A_IJ||_F / (||A_II||_F
/// ||A_JJ||_F)^(1/2)`.
fn strong_neighbours(a: &CsrMatrix, blocks: &NodalBlocks, theta: f64) -> BlockStrength {
    let nb = blocks.count();
    let mut block_of = vec![0usize; a.rows];
    for b in 0..nb {
        for &e in blocks.block(b) {
            block_of[e] = b;
        }
    }
    // squared Frobenius norms of the blocks of row block I
    let tasks = nb.div_ceil(1024).max(1);
    let per_block: Vec<Vec<Vec<(usize, f64)>>> = (0..tasks)
        .into_par_iter()
        .map(|t| {
            let mut marker = vec![usize::MAX; nb];
            let mut sum = vec![0.0; nb];
            let mut out = Vec::new();
            for bi in t * 1024..((t + 1) * 1024).min(nb) {
                let mut touched = Vec::new();
                for &e in blocks.block(bi) {
                    for k in a.row_ptr[e]..a.row_ptr[e + 1] {
                        let bj = block_of[a.col_idx[k]];
                        if marker[bj] != bi {
                            marker[bj] = bi;
                            sum[bj] = 0.0;
                            touched.push(bj);
                        }
                        sum[bj] += a.values[k] * a.values[k];
                    }
                }
                out.push(touched.iter().map(|&bj| (bj, sum[bj])).collect());
            }
            out
        })
        .collect();
    let norms: Vec<Vec<(usize, f64)>> = per_block.into_iter().flatten().collect();
    let diagonal: Vec<f64> = norms
        .iter()
        .enumerate()
        .map(|(bi, row)| {
            row.iter()
                .find(|(bj, _)| *bj == bi)
                .map_or(0.0, |(_, s)| s.sqrt())
        })
        .collect();
    // relative coupling of each off-diagonal block with a nonzero norm
    let relative: Vec<Vec<(usize, f64)>> = norms
        .par_iter()
        .enumerate()
        .map(|(bi, row)| {
            row.iter()
                .filter(|&&(bj, s)| bj != bi && s > 0.0)
                .map(|&(bj, s)| {
                    let scale = (diagonal[bi] * diagonal[bj]).sqrt();
                    let r = if scale > 0.0 {
                        s.sqrt() / scale
                    } else {
                        f64::INFINITY
                    };
                    (bj, r)
                })
                .collect()
        })
        .collect();
    let strong: Vec<Vec<usize>> = relative
        .iter()
        .map(|row| {
            row.iter()
                .filter(|&&(_, r)| r >= theta)
                .map(|&(bj, _)| bj)
                .collect()
        })
        .collect();
    let weak_by_strength = relative
        .into_iter()
        .zip(&strong)
        .map(|(mut row, strong)| {
            if !strong.is_empty() {
                return Vec::new();
            }
            row.sort_by(|x, y| y.1.total_cmp(&x.1).then(x.0.cmp(&y.0)));
            row.into_iter().map(|(bj, _)| bj).collect()
        })
        .collect();
    // the largest off-diagonal block norm of each block, and among the blocks without strong
    // neighbours those coupled strongly relative to it
    let off_diagonal: Vec<f64> = norms
        .iter()
        .enumerate()
        .map(|(bi, row)| {
            row.iter()
                .filter(|(bj, _)| *bj != bi)
                .fold(0.0, |m: f64, &(_, s)| m.max(s.sqrt()))
        })
        .collect();
    let isolated: Vec<bool> = strong.iter().map(|s| s.is_empty()).collect();
    let layer = norms
        .iter()
        .enumerate()
        .map(|(bi, row)| {
            if !isolated[bi] {
                return Vec::new();
            }
            row.iter()
                .filter(|&&(bj, s)| {
                    bj != bi
                        && isolated[bj]
                        && s > 0.0
                        && s.sqrt() >= theta * (off_diagonal[bi] * off_diagonal[bj]).sqrt()
                })
                .map(|&(bj, _)| bj)
                .collect()
        })
        .collect();
    BlockStrength {
        strong,
        weak_by_strength,
        layer,
    }
}

/// A block not yet in an aggregate (in [`aggregate`]'s `of`).
const FREE: usize = usize::MAX;

/// Phase 1 of [`aggregate`] on `graph`: every block with neighbours, all of them still free,
/// forms a new aggregate with them (numbered from `count`); returns the new count.
fn whole_free_neighbourhoods(graph: &[Vec<usize>], of: &mut [usize], mut count: usize) -> usize {
    for i in 0..graph.len() {
        if of[i] == FREE && !graph[i].is_empty() && graph[i].iter().all(|&j| of[j] == FREE) {
            of[i] = count;
            for &j in &graph[i] {
                of[j] = count;
            }
            count += 1;
        }
    }
    count
}

/// Phase 2 of [`aggregate`] on `graph`: every free block with a neighbour aggregated before
/// this phase joins that neighbour's aggregate (the first such neighbour's: the aggregate
/// stays connected).
fn join_an_aggregated_neighbour(graph: &[Vec<usize>], of: &mut [usize]) {
    let before = of.to_vec();
    for i in 0..graph.len() {
        if of[i] == FREE {
            if let Some(&j) = graph[i].iter().find(|&&j| before[j] != FREE) {
                of[i] = before[j];
            }
        }
    }
}

/// Vanek et al.'s aggregation (alg. 5.1), with the blocks that have no strong neighbour set
/// aside as they set them aside; returns the aggregate of each block and their count.
///
/// 1. Every block with strong neighbours, all still free, forms an aggregate with them.
/// 2. Every free block with a strong neighbour aggregated in phase 1 joins its aggregate.
/// 3. Every block still free with strong neighbours forms an aggregate with those of them
///    still free.
/// 4. The blocks without strong neighbours: phases 1 and 2 on their layer graph
///    ([`BlockStrength::layer`]); then each one still free joins the aggregate of its most
///    strongly coupled aggregated neighbour (swept until nothing changes: a chain of such
///    blocks reaches an aggregate); one without any neighbour is an aggregate of its own.
///    Vanek et al. leave these blocks out of the coarse space, which is right for a Dirichlet
///    row but not for a contact node under a large penalty: only its normal dof is dominated,
///    its tangential dofs need the coarse correction; as a singleton aggregate it would stay
///    a block of its own on every level (the coarsening stalls).
fn aggregate(strength: &BlockStrength) -> (Vec<usize>, usize) {
    let strong = &strength.strong;
    let n = strong.len();
    let mut of = vec![FREE; n];
    // phase 1: whole free neighbourhoods
    let mut count = whole_free_neighbourhoods(strong, &mut of, 0);
    // phase 2: join an aggregate of phase 1 (any strong neighbour's: the aggregate stays
    // connected)
    join_an_aggregated_neighbour(strong, &mut of);
    // phase 3: the free neighbourhoods of what is left
    for i in 0..n {
        if of[i] == FREE && !strong[i].is_empty() {
            of[i] = count;
            for &j in &strong[i] {
                if of[j] == FREE {
                    of[j] = count;
                }
            }
            count += 1;
        }
    }
    // phase 4: blocks without strong neighbours aggregate among themselves (phases 1 and 2
    // on the layer graph) ...
    count = whole_free_neighbourhoods(&strength.layer, &mut of, count);
    join_an_aggregated_neighbour(&strength.layer, &mut of);
    // ... and what is left joins the aggregate of its most strongly coupled aggregated
    // neighbour
    loop {
        let mut changed = false;
        for i in 0..n {
            if of[i] == FREE {
                if let Some(&j) = strength.weak_by_strength[i]
                    .iter()
                    .find(|&&j| of[j] != FREE)
                {
                    of[i] = of[j];
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
    for o in of.iter_mut() {
        if *o == FREE {
            *o = count;
            count += 1;
        }
    }
    (of, count)
}

/// Tentative prolongator and coarse near-null space (see the module doc), with the coarse
/// nodal blocks (one per aggregate).
fn tentative_prolongator(
    blocks: &NodalBlocks,
    null: &NearNullSpace,
    aggregate_of: &[usize],
    aggregates: usize,
    rows: usize,
) -> (CsrMatrix, NearNullSpace, NodalBlocks) {
    let m = null.modes;
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); aggregates];
    for (b, &a) in aggregate_of.iter().enumerate() {
        members[a].extend_from_slice(blocks.block(b));
    }
    // per aggregate: Q (|E| x k, column-major) and R (k x m)
    let factors: Vec<(Vec<f64>, Vec<f64>, usize)> = members
        .par_iter()
        .map(|eqs| {
            let len = eqs.len();
            let mut q: Vec<f64> = Vec::with_capacity(len * m);
            let mut r: Vec<f64> = Vec::new();
            let mut kept = 0;
            let mut columns_r: Vec<Vec<f64>> = Vec::new();
            for j in 0..m {
                let mut v: Vec<f64> = eqs.iter().map(|&e| null.values[e * m + j]).collect();
                let original = v.iter().map(|x| x * x).sum::<f64>().sqrt();
                let mut coefficients = vec![0.0; kept];
                for _pass in 0..2 {
                    for k in 0..kept {
                        let qk = &q[k * len..(k + 1) * len];
                        let c: f64 = qk.iter().zip(&v).map(|(a, b)| a * b).sum();
                        coefficients[k] += c;
                        v.iter_mut().zip(qk).for_each(|(x, q)| *x -= c * q);
                    }
                }
                let norm = v.iter().map(|x| x * x).sum::<f64>().sqrt();
                if original > 0.0 && norm > 1e-10 * original {
                    q.extend(v.iter().map(|x| x / norm));
                    coefficients.push(norm);
                    kept += 1;
                }
                columns_r.push(coefficients);
            }
            // R as k x m row-major
            r.resize(kept * m, 0.0);
            for (j, col) in columns_r.iter().enumerate() {
                for (k, &c) in col.iter().enumerate() {
                    r[k * m + j] = c;
                }
            }
            (q, r, kept)
        })
        .collect();
    let mut first_column = vec![0usize; aggregates + 1];
    for a in 0..aggregates {
        first_column[a + 1] = first_column[a] + factors[a].2;
    }
    let coarse = first_column[aggregates];
    // P_tent rows: each fine equation lies in one aggregate
    let mut row_entries: Vec<(usize, usize)> = vec![(usize::MAX, 0); rows]; // (aggregate, position)
    for (a, eqs) in members.iter().enumerate() {
        for (p, &e) in eqs.iter().enumerate() {
            row_entries[e] = (a, p);
        }
    }
    let mut row_ptr = vec![0usize];
    let mut col_idx = Vec::new();
    let mut values = Vec::new();
    for &(a, p) in &row_entries {
        if a != usize::MAX {
            let (q, _, k) = &factors[a];
            let len = members[a].len();
            for c in 0..*k {
                col_idx.push(first_column[a] + c);
                values.push(q[c * len + p]);
            }
        }
        row_ptr.push(col_idx.len());
    }
    let mut coarse_null = vec![0.0; coarse * m];
    for a in 0..aggregates {
        let (_, r, k) = &factors[a];
        coarse_null[first_column[a] * m..(first_column[a] + k) * m].copy_from_slice(r);
    }
    let coarse_blocks = NodalBlocks {
        ptr: first_column.clone(),
        equations: (0..coarse).collect(),
    };
    (
        CsrMatrix {
            rows,
            cols: coarse,
            row_ptr,
            col_idx,
            values,
        },
        NearNullSpace {
            modes: m,
            values: coarse_null,
        },
        coarse_blocks,
    )
}

/// `P = P_tent - omega D^-1 (A P_tent)`.
fn smooth_prolongator(a: &CsrMatrix, tentative: &CsrMatrix) -> Result<CsrMatrix, AmgError> {
    let diagonal = a.diagonal();
    if let Some(i) = diagonal.iter().position(|&d| d <= 0.0 || !d.is_finite()) {
        return Err(AmgError::EmptyRow(i));
    }
    let inverse: Vec<f64> = diagonal.iter().map(|d| 1.0 / d).collect();
    let rho = largest_eigenvalue(a, &inverse, POWER_STEPS).max(f64::MIN_POSITIVE);
    let omega = 4.0 / (3.0 * rho);
    Ok(damped_jacobi_product(a, &inverse, omega, tentative))
}

/// `(I - omega D^-1 A) P_tent`, `D^-1 = inverse_diagonal`.
fn damped_jacobi_product(
    a: &CsrMatrix,
    inverse: &[f64],
    omega: f64,
    tentative: &CsrMatrix,
) -> CsrMatrix {
    let ap = a.product(tentative);
    let mut row_ptr = vec![0usize];
    let mut col_idx = Vec::with_capacity(ap.nnz());
    let mut values = Vec::with_capacity(ap.nnz());
    for i in 0..a.rows {
        let (mut s, se) = (tentative.row_ptr[i], tentative.row_ptr[i + 1]);
        let (mut t, te) = (ap.row_ptr[i], ap.row_ptr[i + 1]);
        let scale = omega * inverse[i];
        while s < se || t < te {
            let cs = if s < se {
                tentative.col_idx[s]
            } else {
                usize::MAX
            };
            let ct = if t < te { ap.col_idx[t] } else { usize::MAX };
            if cs == ct {
                col_idx.push(cs);
                values.push(tentative.values[s] - scale * ap.values[t]);
                s += 1;
                t += 1;
            } else if cs < ct {
                col_idx.push(cs);
                values.push(tentative.values[s]);
                s += 1;
            } else {
                col_idx.push(ct);
                values.push(-scale * ap.values[t]);
                t += 1;
            }
        }
        row_ptr.push(col_idx.len());
    }
    CsrMatrix {
        rows: a.rows,
        cols: tentative.cols,
        row_ptr,
        col_idx,
        values,
    }
}

impl Hierarchy {
    /// Build the hierarchy of the SPD matrix `a` with its nodal blocks and near-null space.
    pub fn build(
        a: CsrMatrix,
        blocks: NodalBlocks,
        null: NearNullSpace,
        options: &AmgOptions,
    ) -> Result<Hierarchy, AmgError> {
        let fine_nnz = a.nnz().max(1) as f64;
        let mut total_nnz = 0.0;
        let mut levels = Vec::new();
        let (mut a, mut blocks, mut null) = (a, blocks, null);
        let mut theta = options.strength_threshold;
        while a.rows > options.coarsest_size && levels.len() + 1 < options.max_levels {
            let strong = strong_neighbours(&a, &blocks, theta);
            let (aggregate_of, count) = aggregate(&strong);
            let (tentative, coarse_null, coarse_blocks) =
                tentative_prolongator(&blocks, &null, &aggregate_of, count, a.rows);
            // a level that barely coarsens is not worth its cost: solve it directly
            if tentative.cols as f64 > 0.8 * a.rows as f64 {
                break;
            }
            let p = smooth_prolongator(&a, &tentative)?;
            let r = p.transpose();
            let coarse = r.product(&a.product(&p));
            let smoother = Chebyshev::new(&a, options.smoother_degree)?;
            total_nnz += a.nnz() as f64;
            levels.push(Level { a, smoother, p, r });
            a = coarse;
            blocks = coarse_blocks;
            null = coarse_null;
            theta *= 0.5;
        }
        total_nnz += a.nnz() as f64;
        let (pattern, values) = a.symmetric_upper();
        let coarsest_size = a.rows;
        let single = levels.is_empty().then_some(a);
        let coarsest = Cholesky::analyse(&pattern, &options.factor_limit)
            .and_then(|c| c.factor(&pattern, &values))
            .map_err(|e| match e {
                FactorError::TooLarge { work, limit } => AmgError::CoarsestTooLarge {
                    levels: levels
                        .iter()
                        .map(|l: &Level| l.a.rows)
                        .chain([coarsest_size])
                        .collect(),
                    refusal: work.refusal(&limit),
                },
                other => AmgError::Coarsest(format!("{other:?}")),
            })?;
        Ok(Hierarchy {
            levels,
            single,
            coarsest_size,
            coarsest,
            operator_complexity: total_nnz / fine_nnz,
        })
    }

    /// Number of levels, the coarsest included.
    pub fn level_count(&self) -> usize {
        self.levels.len() + 1
    }

    /// Equations of each level, finest first.
    pub fn level_sizes(&self) -> Vec<usize> {
        self.levels
            .iter()
            .map(|l| l.a.rows)
            .chain([self.coarsest_size])
            .collect()
    }

    pub fn operator_complexity(&self) -> f64 {
        self.operator_complexity
    }

    /// The finest matrix (the one the V-cycle preconditions).
    pub fn matrix(&self) -> &CsrMatrix {
        match self.levels.first() {
            Some(l) => &l.a,
            None => self
                .single
                .as_ref()
                .expect("a one-level hierarchy keeps its matrix"),
        }
    }

    /// Replace the finest matrix by `a` (same size; e.g. the next active set's), keeping the
    /// coarse levels: the V-cycle stays symmetric and positive definite (its smoother is
    /// rebuilt for `a`, the coarse operators are those of the old matrix, which only changes
    /// how well it preconditions). Returns `false` (nothing changed) when the hierarchy has
    /// one level or the size differs.
    pub fn replace_finest(&mut self, a: CsrMatrix) -> Result<bool, AmgError> {
        let Some(level) = self.levels.first_mut() else {
            return Ok(false);
        };
        if level.a.rows != a.rows {
            return Ok(false);
        }
        level.smoother = Chebyshev::new(&a, level.smoother.degree)?;
        level.a = a;
        Ok(true)
    }

    /// `z = M r`: one V-cycle from zero.
    pub fn apply(&self, r: &[f64], z: &mut [f64]) {
        z.iter_mut().for_each(|v| *v = 0.0);
        self.cycle(0, r, z);
    }

    fn cycle(&self, l: usize, b: &[f64], x: &mut [f64]) {
        let Some(level) = self.levels.get(l) else {
            x.copy_from_slice(b);
            self.coarsest.solve_in_place(x);
            return;
        };
        level.smoother.smooth(&level.a, b, x, true);
        let mut r = vec![0.0; b.len()];
        level.a.residual(b, x, &mut r);
        let mut bc = vec![0.0; level.p.cols];
        level.r.mul(&r, &mut bc);
        let mut xc = vec![0.0; level.p.cols];
        self.cycle(l + 1, &bc, &mut xc);
        level.p.mul_add(&xc, x);
        level.smoother.smooth(&level.a, b, x, false);
    }
}

/// What a CG solve did.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CgOutcome {
    pub iterations: usize,
    /// `||b - A x||_2 / ||b||_2` of the returned `x` (recomputed, not the recursive residual).
    pub relative_residual: f64,
    pub converged: bool,
}

/// Preconditioned conjugate gradients (Saad, alg. 9.1) on `A x = b` from the `x` given (a
/// warm start), preconditioner `precondition(r, z)` (`z = M r`); stops when
/// `||b - A x||_2 <= tolerance ||b||_2` or after `max_iterations`. The test is made on the
/// recursive residual and confirmed on the true one; when round-off has separated them, CG
/// restarts from the current `x` (the iterations count against the same limit).
pub fn conjugate_gradient(
    a: &CsrMatrix,
    precondition: impl Fn(&[f64], &mut [f64]),
    b: &[f64],
    x: &mut [f64],
    tolerance: f64,
    max_iterations: usize,
) -> CgOutcome {
    let n = b.len();
    let b_norm = dot(b, b).sqrt();
    if b_norm == 0.0 {
        x.iter_mut().for_each(|v| *v = 0.0);
        return CgOutcome {
            iterations: 0,
            relative_residual: 0.0,
            converged: true,
        };
    }
    let target = tolerance * b_norm;
    let mut r = vec![0.0; n];
    let mut z = vec![0.0; n];
    let mut q = vec![0.0; n];
    let mut iterations = 0;
    loop {
        a.residual(b, x, &mut r);
        let true_norm = dot(&r, &r).sqrt();
        if true_norm <= target || iterations >= max_iterations || !true_norm.is_finite() {
            return CgOutcome {
                iterations,
                relative_residual: true_norm / b_norm,
                converged: true_norm <= target,
            };
        }
        precondition(&r, &mut z);
        let mut p = z.clone();
        let mut rz = dot(&r, &z);
        let start = iterations;
        while iterations < max_iterations {
            iterations += 1;
            a.mul(&p, &mut q);
            let pq = dot(&p, &q);
            if pq <= 0.0 || !pq.is_finite() {
                break;
            }
            let alpha = rz / pq;
            x.par_iter_mut()
                .zip(&p)
                .with_min_len(ROWS_PER_TASK)
                .for_each(|(x, p)| *x += alpha * p);
            r.par_iter_mut()
                .zip(&q)
                .with_min_len(ROWS_PER_TASK)
                .for_each(|(r, q)| *r -= alpha * q);
            if dot(&r, &r).sqrt() <= target {
                break;
            }
            precondition(&r, &mut z);
            let rz_next = dot(&r, &z);
            let beta = rz_next / rz;
            rz = rz_next;
            p.par_iter_mut()
                .zip(&z)
                .with_min_len(ROWS_PER_TASK)
                .for_each(|(p, z)| *p = z + beta * *p);
        }
        if iterations == start {
            // a breakdown before any step (p^T A p <= 0: M or A is not definite)
            a.residual(b, x, &mut r);
            return CgOutcome {
                iterations,
                relative_residual: dot(&r, &r).sqrt() / b_norm,
                converged: false,
            };
        }
    }
}

#[cfg(test)]
mod tests {
    //! The kernels of the hierarchy against dense linear algebra (nalgebra) on small matrices:
    //! strength of connection, aggregation, tentative and smoothed prolongators, the Galerkin
    //! operator, the Chebyshev smoother and the V-cycle's error propagation `I - M A`.
    use super::*;
    use nalgebra::DMatrix;

    fn csr_from_dense(d: &DMatrix<f64>) -> CsrMatrix {
        let mut row_ptr = vec![0];
        let (mut col_idx, mut values) = (Vec::new(), Vec::new());
        for i in 0..d.nrows() {
            for j in 0..d.ncols() {
                if d[(i, j)] != 0.0 {
                    col_idx.push(j);
                    values.push(d[(i, j)]);
                }
            }
            row_ptr.push(col_idx.len());
        }
        CsrMatrix {
            rows: d.nrows(),
            cols: d.ncols(),
            row_ptr,
            col_idx,
            values,
        }
    }

    fn dense(m: &CsrMatrix) -> DMatrix<f64> {
        let mut d = DMatrix::zeros(m.rows, m.cols);
        for i in 0..m.rows {
            for k in m.row_ptr[i]..m.row_ptr[i + 1] {
                d[(i, m.col_idx[k])] += m.values[k];
            }
        }
        d
    }

    fn null_dense(null: &NearNullSpace) -> DMatrix<f64> {
        DMatrix::from_row_slice(null.values.len() / null.modes, null.modes, &null.values)
    }

    fn max_abs(d: &DMatrix<f64>) -> f64 {
        d.iter().fold(0.0, |m, v| m.max(v.abs()))
    }

    /// Plane-strain bilinear quadrilaterals (E = 1, nu = 0.3, 2 x 2 Gauss points) on an
    /// `nx x ny` grid of `2 x 1`, the left edge clamped, and `penalty` added to the vertical
    /// dof of every bottom node (a node-to-rigid-line contact layer under a penalty); equations
    /// numbered node by node. Returns the matrix, nodal blocks and rigid-body modes.
    fn plane_strain(nx: usize, ny: usize, penalty: f64) -> (CsrMatrix, NodalBlocks, NearNullSpace) {
        let (hx, hy) = (2.0 / nx as f64, 1.0 / ny as f64);
        let (e, nu) = (1.0, 0.3);
        let c = e / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let d = [
            [c * (1.0 - nu), c * nu, 0.0],
            [c * nu, c * (1.0 - nu), 0.0],
            [0.0, 0.0, c * (1.0 - 2.0 * nu) / 2.0],
        ];
        let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
        let g = 1.0 / 3f64.sqrt();
        let mut ke = [[0.0; 8]; 8];
        for (xi, eta) in [(-g, -g), (g, -g), (g, g), (-g, g)] {
            let mut b = [[0.0; 8]; 3];
            for (a, &(xa, ya)) in corners.iter().enumerate() {
                let dx = 0.25 * xa * (1.0 + eta * ya) * 2.0 / hx;
                let dy = 0.25 * ya * (1.0 + xi * xa) * 2.0 / hy;
                b[0][2 * a] = dx;
                b[1][2 * a + 1] = dy;
                b[2][2 * a] = dy;
                b[2][2 * a + 1] = dx;
            }
            let det = hx * hy / 4.0;
            for p in 0..8 {
                for q in 0..8 {
                    let mut s = 0.0;
                    for i in 0..3 {
                        for j in 0..3 {
                            s += b[i][p] * d[i][j] * b[j][q];
                        }
                    }
                    ke[p][q] += s * det;
                }
            }
        }
        // free nodes: i >= 1
        let node = |i: usize, j: usize| (i >= 1).then(|| j * nx + (i - 1));
        let n = 2 * nx * (ny + 1);
        let mut k = DMatrix::zeros(n, n);
        for j in 0..ny {
            for i in 0..nx {
                let nodes = [
                    node(i, j),
                    node(i + 1, j),
                    node(i + 1, j + 1),
                    node(i, j + 1),
                ];
                for (a, na) in nodes.iter().enumerate() {
                    for (b, nb) in nodes.iter().enumerate() {
                        if let (Some(na), Some(nb)) = (na, nb) {
                            for ca in 0..2 {
                                for cb in 0..2 {
                                    k[(2 * na + ca, 2 * nb + cb)] += ke[2 * a + ca][2 * b + cb];
                                }
                            }
                        }
                    }
                }
            }
        }
        let mut points = Vec::new();
        let mut components = Vec::new();
        let mut block_of = Vec::new();
        for j in 0..=ny {
            for i in 1..=nx {
                let p = node(i, j).expect("free");
                for c in 0..2 {
                    points.push([i as f64 * hx, j as f64 * hy, 0.0]);
                    components.push(c);
                    block_of.push(p);
                }
                if j == 0 {
                    k[(2 * p + 1, 2 * p + 1)] += penalty;
                }
            }
        }
        (
            csr_from_dense(&k),
            NodalBlocks::from_block_of(&block_of),
            rigid_body_modes(&points, &components, 2),
        )
    }

    fn options(coarsest_size: usize) -> AmgOptions {
        AmgOptions {
            coarsest_size,
            ..AmgOptions::default()
        }
    }

    /// Four blocks of two equations, block `b` holding equations `b` and `b + 4`; block 3's
    /// diagonal is 100 times the others' (a penalized contact node). Relative couplings
    /// `||A_IJ|| / (||A_II|| ||A_JJ||)^(1/2)`: (0, 1) 0.25, (1, 2) 0.05, (1, 3) 0.05,
    /// (2, 3) 0.025.
    fn four_blocks() -> (CsrMatrix, NodalBlocks) {
        let identity = DMatrix::<f64>::identity(2, 2);
        let mut blocks = vec![vec![DMatrix::<f64>::zeros(2, 2); 4]; 4];
        for b in 0..3 {
            blocks[b][b] = &identity * 4.0;
        }
        blocks[3][3] = &identity * 400.0;
        for (i, j, v) in [(0, 1, 1.0), (1, 2, 0.2), (1, 3, 2.0), (2, 3, 1.0)] {
            blocks[i][j] = &identity * v;
            blocks[j][i] = &identity * v;
        }
        let mut a = DMatrix::zeros(8, 8);
        for bi in 0..4 {
            for bj in 0..4 {
                for c in 0..2 {
                    for d in 0..2 {
                        a[(bi + 4 * c, bj + 4 * d)] = blocks[bi][bj][(c, d)];
                    }
                }
            }
        }
        let block_of: Vec<usize> = (0..8).map(|e| e % 4).collect();
        (csr_from_dense(&a), NodalBlocks::from_block_of(&block_of))
    }

    fn sorted(mut v: Vec<usize>) -> Vec<usize> {
        v.sort_unstable();
        v
    }

    #[test]
    fn strength_of_connection_compares_block_norms() {
        let (a, blocks) = four_blocks();
        let s = strong_neighbours(&a, &blocks, 0.08);
        let strong: Vec<Vec<usize>> = s.strong.iter().cloned().map(sorted).collect();
        assert_eq!(strong, vec![vec![1], vec![0], vec![], vec![]]);
        // the blocks without strong neighbours list theirs, strongest first
        assert_eq!(
            s.weak_by_strength,
            vec![vec![], vec![], vec![1, 3], vec![1, 2]]
        );
        let s = strong_neighbours(&a, &blocks, 0.04);
        let strong: Vec<Vec<usize>> = s.strong.iter().cloned().map(sorted).collect();
        assert_eq!(strong, vec![vec![1], vec![0, 2, 3], vec![1], vec![1]]);
        assert!(s.weak_by_strength.iter().all(|w| w.is_empty()));
    }

    #[test]
    fn blocks_without_strong_neighbours_aggregate_as_a_layer_or_join_a_neighbour() {
        let (a, blocks) = four_blocks();
        let strength = strong_neighbours(&a, &blocks, 0.08);
        // relative to the largest couplings (block 2: ||A_23||, block 3: ||A_31||), the
        // coupling (2, 3) is 2^(-1/2)
        assert_eq!(strength.layer, vec![vec![], vec![], vec![3], vec![2]]);
        assert_eq!(aggregate(&strength), (vec![0, 0, 1, 1], 2));
        // without a layer: the most strongly coupled aggregated neighbour's aggregate, through
        // a chain (block 2 reaches it through block 3) ; a block without any neighbour is an
        // aggregate of its own
        let chain = BlockStrength {
            strong: vec![vec![1], vec![0], vec![], vec![], vec![]],
            weak_by_strength: vec![vec![], vec![], vec![3], vec![1, 2], vec![]],
            layer: vec![vec![]; 5],
        };
        assert_eq!(aggregate(&chain), (vec![0, 0, 0, 0, 1], 2));
    }

    /// Each block in exactly one aggregate, no aggregate empty, each connected in the graph of
    /// the nonzero block couplings; under a penalty on the bottom layer no bottom node is left
    /// as an aggregate of its own (that stalled the coarsening of the 3D slab).
    #[test]
    fn aggregation_covers_every_block_once_with_connected_aggregates() {
        for penalty in [0.0, 1e6] {
            let (a, blocks, _) = plane_strain(24, 12, penalty);
            let strength = strong_neighbours(&a, &blocks, 0.08);
            let (of, count) = aggregate(&strength);
            assert_eq!(of.len(), blocks.count());
            let mut members = vec![Vec::new(); count];
            for (b, &g) in of.iter().enumerate() {
                assert!(g < count, "block {b} has no aggregate");
                members[g].push(b);
            }
            let coupled = strong_neighbours(&a, &blocks, 0.0).strong;
            for (g, m) in members.iter().enumerate() {
                assert!(m.len() >= 2, "penalty {penalty}: aggregate {g} is {m:?}");
                // breadth-first search inside the aggregate
                let mut seen = vec![m[0]];
                let mut next = 0;
                while next < seen.len() {
                    let b = seen[next];
                    next += 1;
                    for &c in &coupled[b] {
                        if of[c] == g && !seen.contains(&c) {
                            seen.push(c);
                        }
                    }
                }
                assert_eq!(seen.len(), m.len(), "aggregate {g} is not connected");
            }
            // a 2D aggregate is about a 3 x 3 patch of nodes
            assert!(
                count * 5 <= blocks.count(),
                "penalty {penalty}: {count} aggregates of {} blocks",
                blocks.count()
            );
        }
    }

    #[test]
    fn tentative_prolongator_reproduces_the_near_null_space_with_orthonormal_columns() {
        let (a, blocks, null) = plane_strain(12, 6, 1e3);
        let (mut of, mut count) = aggregate(&strong_neighbours(&a, &blocks, 0.08));
        // and one aggregate of a single node: two dofs for three modes, one column dropped
        let lone = of[5];
        of[5] = count;
        count += 1;
        assert!(
            of.contains(&lone),
            "the aggregate block 5 left is not empty"
        );
        let (p, coarse_null, coarse_blocks) =
            tentative_prolongator(&blocks, &null, &of, count, a.rows);
        let (p, b, bc) = (dense(&p), null_dense(&null), null_dense(&coarse_null));
        assert!(max_abs(&(&p * &bc - &b)) <= 1e-13 * max_abs(&b));
        let gram = p.transpose() * &p;
        assert!(max_abs(&(gram - DMatrix::identity(p.ncols(), p.ncols()))) <= 1e-13);
        // three columns per aggregate, two for the single node; the coarse blocks are the
        // aggregates' columns
        assert_eq!(coarse_blocks.count(), count);
        for g in 0..count {
            let expected = if g == count - 1 { 2 } else { 3 };
            assert_eq!(coarse_blocks.block(g).len(), expected, "aggregate {g}");
        }
        // each row lies in the columns of its own aggregate only
        let mut block_of = vec![0; a.rows];
        for bl in 0..blocks.count() {
            for &e in blocks.block(bl) {
                block_of[e] = bl;
            }
        }
        for i in 0..a.rows {
            let own = coarse_blocks.block(of[block_of[i]]);
            for j in 0..p.ncols() {
                assert!(own.contains(&j) || p[(i, j)] == 0.0, "P_tent({i}, {j})");
            }
        }
    }

    #[test]
    fn smoothed_prolongator_is_damped_jacobi_on_the_tentative_one_and_lowers_its_energy() {
        let (a, blocks, null) = plane_strain(12, 6, 1e3);
        let (of, count) = aggregate(&strong_neighbours(&a, &blocks, 0.08));
        let (tentative, _, _) = tentative_prolongator(&blocks, &null, &of, count, a.rows);
        let (ad, pt) = (dense(&a), dense(&tentative));
        let inverse: Vec<f64> = a.diagonal().iter().map(|d| 1.0 / d).collect();
        let d_inv = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(inverse.clone()));
        let omega = 0.7;
        let expected = &pt - (&d_inv * &ad * &pt) * omega;
        let p = dense(&damped_jacobi_product(&a, &inverse, omega, &tentative));
        assert!(max_abs(&(&p - &expected)) <= 1e-13 * max_abs(&expected));
        // the power estimate of rho(D^-1 A) is a lower bound within 10 %
        let d_half = d_inv.map(f64::sqrt);
        let rho = (&d_half * &ad * &d_half)
            .symmetric_eigen()
            .eigenvalues
            .max();
        let estimate = largest_eigenvalue(&a, &inverse, POWER_STEPS);
        assert!(
            estimate <= rho * (1.0 + 1e-12) && estimate >= 0.9 * rho,
            "estimate {estimate}, rho {rho}"
        );
        // omega = 4 / (3 rho): every column's energy p^T A p decreases
        let p = dense(&smooth_prolongator(&a, &tentative).unwrap());
        for j in 0..p.ncols() {
            let energy = |m: &DMatrix<f64>| (m.column(j).transpose() * &ad * m.column(j))[(0, 0)];
            assert!(
                energy(&p) < energy(&pt),
                "column {j}: {} >= {}",
                energy(&p),
                energy(&pt)
            );
        }
    }

    #[test]
    fn coarse_operators_are_the_galerkin_products() {
        let (a, blocks, null) = plane_strain(24, 12, 1e3);
        let h = Hierarchy::build(a, blocks, null, &options(20)).unwrap();
        assert!(h.levels.len() >= 2, "levels {:?}", h.level_sizes());
        for l in 0..h.levels.len() {
            let level = &h.levels[l];
            let (p, fine) = (dense(&level.p), dense(&level.a));
            let galerkin = p.transpose() * fine * &p;
            let coarse = match h.levels.get(l + 1) {
                Some(next) => dense(&next.a),
                None => {
                    // the coarsest level: its factor solves with P^T A P
                    let n = galerkin.nrows();
                    let mut x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
                    let b = &galerkin * nalgebra::DVector::from_vec(x.clone());
                    let solution = x.clone();
                    x.copy_from_slice(b.as_slice());
                    h.coarsest.solve_in_place(&mut x);
                    let err = x
                        .iter()
                        .zip(&solution)
                        .map(|(p, q)| (p - q).abs())
                        .fold(0.0, f64::max);
                    assert!(err <= 1e-8, "coarsest solve error {err}");
                    continue;
                }
            };
            assert!(
                max_abs(&(&coarse - &galerkin)) <= 1e-12 * max_abs(&galerkin),
                "level {}",
                l + 1
            );
            assert_eq!(dense(&level.r), p.transpose());
        }
    }

    /// On the eigenvectors of `D_l1^-1 A` with eigenvalues in the smoother's interval
    /// `[lower, upper]`, degree-2 Chebyshev multiplies the error by at most
    /// `1 / T_2(theta / delta)` (Saad, sec. 12.3.2) in the energy norm; the smoothest
    /// eigenvector is barely touched.
    #[test]
    fn chebyshev_damps_the_high_frequency_error() {
        let (a, _, _) = plane_strain(16, 8, 1e3);
        let smoother = Chebyshev::new(&a, 2).unwrap();
        let ad = dense(&a);
        let scale =
            nalgebra::DVector::from_iterator(a.rows, smoother.inverse_l1.iter().map(|m| m.sqrt()));
        let s = DMatrix::from_diagonal(&scale);
        let eigen = (&s * &ad * &s).symmetric_eigen();
        let energy = |e: &[f64]| {
            let v = nalgebra::DVector::from_column_slice(e);
            (v.transpose() * &ad * &v)[(0, 0)].sqrt()
        };
        let smooth_error = |e: &[f64]| {
            // A x = 0 from x = e: the new x is the new error
            let mut x = e.to_vec();
            smoother.smooth(&a, &vec![0.0; e.len()], &mut x, false);
            energy(&x) / energy(e)
        };
        let (theta, delta) = (
            0.5 * (smoother.upper + smoother.lower),
            0.5 * (smoother.upper - smoother.lower),
        );
        let sigma = theta / delta;
        let bound = 1.0 / (2.0 * sigma * sigma - 1.0);
        let mut high = nalgebra::DVector::zeros(a.rows);
        let mut smoothest = (f64::INFINITY, 0);
        for (k, &lambda) in eigen.eigenvalues.iter().enumerate() {
            if lambda < smoothest.0 {
                smoothest = (lambda, k);
            }
            if lambda >= smoother.lower && lambda <= smoother.upper {
                // D_l1^-1 A w = lambda w with w = D_l1^-1/2 v
                high += (&s * eigen.eigenvectors.column(k)) * (1.0 + (k as f64).sin());
            }
        }
        let ratio = smooth_error(high.as_slice());
        assert!(
            ratio <= bound * (1.0 + 1e-10),
            "high frequencies: {ratio} > {bound}"
        );
        assert!(bound < 0.51);
        let low = &s * eigen.eigenvectors.column(smoothest.1);
        let ratio = smooth_error(low.as_slice());
        assert!(ratio > 0.9, "the smoothest error shrank to {ratio}");
    }

    /// The V-cycle's error propagation `E = I - M A` is self-adjoint in the energy inner
    /// product, so `||E||_A = max |1 - lambda(M A)|` over the eigenvalues of the symmetric
    /// `L^T M L` (`A = L L^T`): at most 0.5 on the clamped plane-strain strip with and without
    /// a stiff contact layer, on two meshes.
    #[test]
    fn the_v_cycle_contracts_the_error_in_the_energy_norm() {
        for (nx, ny) in [(16, 8), (32, 16)] {
            for penalty in [0.0, 1e4] {
                let (a, blocks, null) = plane_strain(nx, ny, penalty);
                let n = a.rows;
                let ad = dense(&a);
                let h = Hierarchy::build(a, blocks, null, &options(30)).unwrap();
                let sizes = h.level_sizes();
                assert!(sizes.len() >= 3, "levels {sizes:?}");
                assert!(
                    sizes.windows(2).all(|w| 2 * w[1] <= w[0]),
                    "the coarsening stalls: levels {sizes:?}"
                );
                let mut m = DMatrix::zeros(n, n);
                let mut unit = vec![0.0; n];
                let mut column = vec![0.0; n];
                for j in 0..n {
                    unit[j] = 1.0;
                    h.apply(&unit, &mut column);
                    m.column_mut(j).copy_from_slice(&column);
                    unit[j] = 0.0;
                }
                let asymmetry = max_abs(&(&m - m.transpose()));
                assert!(
                    asymmetry <= 1e-12 * max_abs(&m),
                    "M is not symmetric: {asymmetry}"
                );
                let l = ad.clone().cholesky().expect("SPD").l();
                let eigenvalues = (l.transpose() * &m * &l).symmetric_eigen().eigenvalues;
                let (least, most) = (eigenvalues.min(), eigenvalues.max());
                let contraction = (1.0 - least).abs().max((1.0 - most).abs());
                eprintln!(
                    "{nx} x {ny}, penalty {penalty}: levels {:?}, lambda(MA) in [{least:.3}, {most:.3}], ||I - MA||_A = {contraction:.3}",
                    h.level_sizes()
                );
                assert!(least > 0.0, "M A is not positive definite: {least}");
                assert!(contraction <= 0.5, "||I - M A||_A = {contraction}");
            }
        }
    }

    #[test]
    fn a_coarsest_level_above_the_factor_limit_is_refused_with_the_levels() {
        let (a, blocks, null) = plane_strain(24, 12, 0.0);
        let tight = AmgOptions {
            coarsest_size: 100_000,
            factor_limit: WorkLimit {
                gigabytes: 1e-6,
                operations: 1e12,
            },
            ..AmgOptions::default()
        };
        let rows = a.rows;
        let e = Hierarchy::build(a, blocks, null, &tight)
            .err()
            .expect("refused");
        let AmgError::CoarsestTooLarge { levels, .. } = &e else {
            panic!("{e}");
        };
        assert_eq!(levels, &vec![rows]);
        let message = e.to_string();
        for part in [
            "too large to factor",
            "limits.factor_gigabytes",
            "\"direct\"",
        ] {
            assert!(message.contains(part), "{message}");
        }
    }
}
