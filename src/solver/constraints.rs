//! Affine constraints on dofs: the one owner of "which dofs are unknowns" for Dirichlet data and
//! for constraint elimination alike.
//!
//! ## The maths
//! A constraint (a *line*) ties one dof `u_o` to others, its *masters*:
//!
//! ```text
//! u_o = sum_j c_j u_j + b_o
//! ```
//!
//! A Dirichlet value is the line without masters (`u_o = b_o`); an active contact row
//! `g0 + sum_k a_k u_k = 0` solved for its owned dof `o` is the line with `c_k = -a_k / a_o` and
//! `b_o = -g0 / a_o`. Once every master is itself unconstrained (see *chains* below), the dofs
//! split into the free ones, numbered `0..m` in increasing dof order (the *reduced numbering*,
//! [`AffineConstraints::equations`]), and the constrained ones, and every dof is affine in the
//! free unknowns `y`:
//!
//! ```text
//! u = T y + t
//! ```
//!
//! with `T[d, e] = 1` when `d` is the free dof of unknown `e`, `T[o, e] = c_j` for the masters
//! `j` of line `o` (`e` the unknown of `j`), and `t` the constants `b` (zero at free dofs).
//! Minimizing `1/2 u^T K u - f^T u` over such `u` gives the reduced system
//!
//! ```text
//! T^T K T y = T^T (f - K t)
//! ```
//!
//! symmetric positive definite whenever `K` is on the constrained space; its pattern is
//! `T^T P T` for the pattern `P` of `K` and depends only on the constraint set, so it is built
//! (and a symbolic factorization of it analysed) once per set and reused for every matrix on it.
//! [`AffineConstraints::expand`] returns `u = T y + t`.
//!
//! **Forces of the constraints.** The same minimum with Lagrange multipliers reads
//! `K u - f = G^T mu`, `G u = b`, with row `o` of `G` equal to `e_o - sum_j c_j e_j`. A
//! constrained dof is never a master (chains are resolved), so column `o` of `G` holds the one
//! entry of line `o`, and the multiplier of line `o` is the residual at its eliminated dof:
//! `mu_o = (K u - f)_o` ([`AffineConstraints::forces`]). For a Dirichlet line it is the support
//! reaction; for a contact row `g0 + a . u = 0` it is `a_o lambda` (`lambda` the row's force).
//!
//! **Chains** (a master that is itself constrained) are *resolved* when the set is closed
//! ([`ConstraintBuilder::close`]): the master's own line is substituted, recursively, so a
//! line on a Dirichlet dof picks up its value (`u_1 = u_2 + b_1`, `u_2 = g` gives
//! `u_1 = g + b_1`) and repeated masters are merged (coefficients summed at the first
//! occurrence, so a set without chains or repeats keeps its lines as given). A **cycle**
//! (`u_1 = u_2`, `u_2 = 2 u_1`; or a line that names its own dof as master) has no such
//! resolution and is refused with [`ConstraintError::Cycle`]; a dof constrained twice with
//! [`ConstraintError::Repeated`]. A constrained master whose coefficient is exactly zero
//! contributes nothing and is dropped instead of followed (a contact row keeps the zero
//! component of a slave node's normal; two such rows at a corner would otherwise close a
//! cycle that does not exist); unconstrained masters are kept as given, zeros included. The multipliers [`AffineConstraints::forces`] returns are
//! those of the resolved lines (the resolution is a row operation `G' = L G`, `mu = L^T mu'`).
//!
//! **Dirichlet-only sets** ([`AffineConstraints::dirichlet`], no line has a master) cost no
//! product: `T` is a selection, so the element-level assembly ([`LocalAssembler`]) scatters
//! each element's free block and moves `K_fp u_p` to the right-hand side, and
//! [`AffineConstraints::expand`] only copies. Lines with masters go through the same entry
//! points with their `T^T K T` products.
//!
//! Two places to apply a set: element by element while assembling ([`LocalAssembler`]: the
//! Dirichlet data in [`crate::solver::linear`]), or on an assembled symmetric matrix
//! ([`Reduction`]: the active contact rows in constraint elimination, layered on the
//! Dirichlet-reduced system, see [`crate::solver::active_set`]).
//!
//! References: the affine-constraints design of deal.II (`AffineConstraints`: lines
//! `x_i = sum_j a_ij x_j + b_i`, closed once with chains resolved, applied while assembling by
//! `distribute_local_to_global`), and C. A. Felippa, *Introduction to Finite Element Methods*
//! (University of Colorado lecture notes), the chapters on multifreedom constraints
//! (master-slave elimination; Lagrange multipliers and the forces they carry).

use crate::solver::sparse::{PatternBuilder, SymmetricPattern};

/// Marks a dof that has no equation in the reduced numbering (it is constrained).
pub const NO_EQUATION: usize = usize::MAX;

/// Marks a dof without a line.
const NO_LINE: usize = usize::MAX;

/// Why a set of constraints cannot be built. Dofs are in the numbering the set was built in.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ConstraintError {
    /// A constrained dof or a master outside `0..size`.
    #[error("dof {dof} is outside the {size} dofs of the constraint set")]
    OutOfRange { dof: usize, size: usize },
    /// A dof constrained by two lines.
    #[error("dof {dof} is constrained twice")]
    Repeated { dof: usize },
    /// A coefficient or constant of the line of `dof` is not finite.
    #[error("the constraint on dof {dof} has a coefficient or constant that is not finite")]
    NotFinite { dof: usize },
    /// Lines that depend on each other in a cycle: each dof's line names the next dof as a
    /// master, the last one's names the first (a single dof: its line names itself).
    #[error("the constraints on dofs {dofs:?} depend on each other in a cycle")]
    Cycle { dofs: Vec<usize> },
}

/// Constraints as they are given, before chains are resolved: add lines, then
/// [`ConstraintBuilder::close`].
#[derive(Clone, Debug)]
pub struct ConstraintBuilder {
    size: usize,
    /// Line of each dof (`NO_LINE` when unconstrained).
    line_of: Vec<usize>,
    /// Constrained dof of each line, in the order given.
    dofs: Vec<usize>,
    constants: Vec<f64>,
    /// Masters of line `l`: `masters[ptr[l]..ptr[l + 1]]`, `(dof, coefficient)`.
    ptr: Vec<usize>,
    masters: Vec<(usize, f64)>,
}

impl ConstraintBuilder {
    /// No constraint on `size` dofs.
    pub fn new(size: usize) -> Self {
        ConstraintBuilder {
            size,
            line_of: vec![NO_LINE; size],
            dofs: Vec::new(),
            constants: Vec::new(),
            ptr: vec![0],
            masters: Vec::new(),
        }
    }

    /// `u_dof = value`.
    pub fn dirichlet(&mut self, dof: usize, value: f64) -> Result<(), ConstraintError> {
        self.constrain(dof, &[], value)
    }

    /// `u_dof = sum_j c_j u_j + constant` for `masters = [(j, c_j), ...]` (masters may be
    /// constrained themselves: chains are resolved by [`ConstraintBuilder::close`]).
    pub fn constrain(
        &mut self,
        dof: usize,
        masters: &[(usize, f64)],
        constant: f64,
    ) -> Result<(), ConstraintError> {
        let size = self.size;
        if let Some(&d) = std::iter::once(&dof)
            .chain(masters.iter().map(|(j, _)| j))
            .find(|&&d| d >= size)
        {
            return Err(ConstraintError::OutOfRange { dof: d, size });
        }
        if !constant.is_finite() || masters.iter().any(|(_, c)| !c.is_finite()) {
            return Err(ConstraintError::NotFinite { dof });
        }
        if self.line_of[dof] != NO_LINE {
            return Err(ConstraintError::Repeated { dof });
        }
        self.line_of[dof] = self.dofs.len();
        self.dofs.push(dof);
        self.constants.push(constant);
        self.masters.extend_from_slice(masters);
        self.ptr.push(self.masters.len());
        Ok(())
    }

    /// Resolve chains (substitute every constrained master by its own line, recursively; merge
    /// repeated masters) and number the free dofs. A cycle is refused.
    pub fn close(self) -> Result<AffineConstraints, ConstraintError> {
        let ConstraintBuilder {
            size,
            line_of,
            dofs,
            constants,
            ptr,
            masters,
        } = self;
        let lines = dofs.len();
        let chained = masters.iter().any(|&(j, _)| line_of[j] != NO_LINE);
        let (ptr, masters, constants) = if chained {
            resolve_chains(&line_of, &dofs, &constants, &ptr, &masters)?
        } else {
            let mut out_ptr = Vec::with_capacity(lines + 1);
            let mut out = Vec::with_capacity(masters.len());
            out_ptr.push(0);
            for l in 0..lines {
                merge_into(&mut out, out_ptr[l], &masters[ptr[l]..ptr[l + 1]], 1.0);
                out_ptr.push(out.len());
            }
            (out_ptr, out, constants)
        };
        let mut equation = vec![NO_EQUATION; size];
        let mut free = Vec::with_capacity(size - lines);
        for (d, e) in equation.iter_mut().enumerate() {
            if line_of[d] == NO_LINE {
                *e = free.len();
                free.push(d);
            }
        }
        let mut constant = vec![0.0; size];
        for (&d, &b) in dofs.iter().zip(&constants) {
            constant[d] = b;
        }
        let terms = masters
            .iter()
            .map(|&(j, c)| (equation[j], c))
            .collect::<Vec<_>>();
        Ok(AffineConstraints {
            equation,
            free,
            constant,
            dofs,
            line_of,
            ptr,
            master_dofs: masters.iter().map(|m| m.0).collect(),
            terms,
        })
    }
}

/// Append `scale * masters` to the line that starts at `out[start..]`, adding a repeated
/// master to its first occurrence.
fn merge_into(out: &mut Vec<(usize, f64)>, start: usize, masters: &[(usize, f64)], scale: f64) {
    for &(j, c) in masters {
        match out[start..].iter_mut().find(|m| m.0 == j) {
            Some(m) => m.1 += scale * c,
            None => out.push((j, scale * c)),
        }
    }
}

type Resolved = (Vec<usize>, Vec<(usize, f64)>, Vec<f64>);

/// Every line with its constrained masters substituted (depth first, so that a line is
/// resolved after the lines it names); a line met again while it is being resolved closes a
/// cycle.
fn resolve_chains(
    line_of: &[usize],
    dofs: &[usize],
    constants: &[f64],
    ptr: &[usize],
    masters: &[(usize, f64)],
) -> Result<Resolved, ConstraintError> {
    const NEW: u8 = 0;
    const OPEN: u8 = 1;
    const DONE: u8 = 2;
    let lines = dofs.len();
    let mut state = vec![NEW; lines];
    let mut resolved: Vec<(Vec<(usize, f64)>, f64)> = vec![(Vec::new(), 0.0); lines];
    let mut stack: Vec<(usize, usize)> = Vec::new();
    for root in 0..lines {
        if state[root] != NEW {
            continue;
        }
        state[root] = OPEN;
        stack.push((root, ptr[root]));
        while let Some(top) = stack.last_mut() {
            let (l, next) = *top;
            if next < ptr[l + 1] {
                top.1 += 1;
                let (j, c) = masters[next];
                let m = line_of[j];
                if m == NO_LINE || c == 0.0 {
                    continue;
                }
                match state[m] {
                    NEW => {
                        state[m] = OPEN;
                        stack.push((m, ptr[m]));
                    }
                    OPEN => {
                        let from = stack.iter().position(|s| s.0 == m).expect("open lines");
                        return Err(ConstraintError::Cycle {
                            dofs: stack[from..].iter().map(|s| dofs[s.0]).collect(),
                        });
                    }
                    _ => {}
                }
                continue;
            }
            // every constrained master of l is resolved: substitute them
            let mut out: Vec<(usize, f64)> = Vec::new();
            let mut b = constants[l];
            for &(j, c) in &masters[ptr[l]..ptr[l + 1]] {
                match line_of[j] {
                    NO_LINE => merge_into(&mut out, 0, &[(j, c)], 1.0),
                    _ if c == 0.0 => {}
                    m => {
                        merge_into(&mut out, 0, &resolved[m].0, c);
                        b += c * resolved[m].1;
                    }
                }
            }
            resolved[l] = (out, b);
            state[l] = DONE;
            stack.pop();
        }
    }
    let mut out_ptr = Vec::with_capacity(lines + 1);
    let mut out = Vec::new();
    let mut out_constants = Vec::with_capacity(lines);
    out_ptr.push(0);
    for (masters, b) in resolved {
        out.extend(masters);
        out_ptr.push(out.len());
        out_constants.push(b);
    }
    Ok((out_ptr, out, out_constants))
}

/// A closed set of affine constraints `u = T y + t` (see the module documentation): the
/// reduced numbering of the free dofs, the lines with their (free) masters and constants.
#[derive(Clone, Debug)]
pub struct AffineConstraints {
    /// Unknown of each dof in the reduced numbering (`NO_EQUATION` when constrained).
    equation: Vec<usize>,
    /// Dof of each unknown (increasing).
    free: Vec<usize>,
    /// `t`: the constant of each constrained dof, zero at free dofs.
    constant: Vec<f64>,
    /// Constrained dof of each line, in the order given.
    dofs: Vec<usize>,
    /// Line of each dof (`NO_LINE` when free).
    line_of: Vec<usize>,
    /// The masters of line `l` are `ptr[l]..ptr[l + 1]` of `master_dofs` and `terms`.
    ptr: Vec<usize>,
    master_dofs: Vec<usize>,
    /// `(unknown, coefficient)` of each master.
    terms: Vec<(usize, f64)>,
}

/// One line of a closed set: `u_dof = sum_k coefficients[k] u_{masters[k]} + constant`.
#[derive(Clone, Copy, Debug)]
pub struct Line<'a> {
    pub dof: usize,
    pub masters: &'a [usize],
    /// `(unknown, coefficient)` of each master, in the reduced numbering.
    pub terms: &'a [(usize, f64)],
    pub constant: f64,
}

impl AffineConstraints {
    /// The Dirichlet data `prescribed` (one entry per dof, `Some(value)` when prescribed): lines
    /// without masters, built in one pass (nothing to resolve).
    pub fn dirichlet(prescribed: &[Option<f64>]) -> Self {
        let size = prescribed.len();
        let lines = prescribed.iter().filter(|p| p.is_some()).count();
        let mut equation = Vec::with_capacity(size);
        let mut free = Vec::with_capacity(size - lines);
        let mut line_of = Vec::with_capacity(size);
        let mut dofs = Vec::with_capacity(lines);
        let mut constant = Vec::with_capacity(size);
        for (d, p) in prescribed.iter().enumerate() {
            match *p {
                Some(value) => {
                    equation.push(NO_EQUATION);
                    line_of.push(dofs.len());
                    dofs.push(d);
                    constant.push(value);
                }
                None => {
                    equation.push(free.len());
                    line_of.push(NO_LINE);
                    free.push(d);
                    constant.push(0.0);
                }
            }
        }
        AffineConstraints {
            equation,
            free,
            constant,
            dofs,
            line_of,
            ptr: vec![0; lines + 1],
            master_dofs: Vec::new(),
            terms: Vec::new(),
        }
    }

    /// Dofs of the space (free and constrained).
    pub fn size(&self) -> usize {
        self.equation.len()
    }

    /// Unknowns of the reduced system: the free dofs.
    pub fn free_count(&self) -> usize {
        self.free.len()
    }

    /// Number of lines (constrained dofs).
    pub fn len(&self) -> usize {
        self.dofs.len()
    }

    pub fn is_empty(&self) -> bool {
        self.dofs.is_empty()
    }

    /// No line has a master (Dirichlet data only): `T` is a selection.
    pub fn is_dirichlet_only(&self) -> bool {
        self.terms.is_empty()
    }

    /// The reduced numbering: the unknown of each dof, `NO_EQUATION` when it is constrained.
    pub fn equations(&self) -> &[usize] {
        &self.equation
    }

    /// The dof of each unknown (the inverse of [`AffineConstraints::equations`]).
    pub fn free_dofs(&self) -> &[usize] {
        &self.free
    }

    pub fn is_constrained(&self, dof: usize) -> bool {
        self.equation[dof] == NO_EQUATION
    }

    /// `t`: the constant of every constrained dof, zero at the free ones (for Dirichlet data,
    /// the prescribed values).
    pub fn constants(&self) -> &[f64] {
        &self.constant
    }

    /// The line of constraint `l` (in the order the lines were given).
    pub fn line(&self, l: usize) -> Line<'_> {
        let range = self.ptr[l]..self.ptr[l + 1];
        Line {
            dof: self.dofs[l],
            masters: &self.master_dofs[range.clone()],
            terms: &self.terms[range],
            constant: self.constant[self.dofs[l]],
        }
    }

    /// The lines in the order they were given.
    pub fn lines(&self) -> impl Iterator<Item = Line<'_>> + '_ {
        (0..self.len()).map(|l| self.line(l))
    }

    /// Row `dof` of `T`: `(unknown, coefficient)` pairs (`[(e, 1)]` for a free dof, the masters
    /// for a constrained one). `one` is storage for the free case.
    fn terms<'s>(&'s self, dof: usize, one: &'s mut [(usize, f64); 1]) -> &'s [(usize, f64)] {
        match self.equation[dof] {
            NO_EQUATION => {
                let l = self.line_of[dof];
                &self.terms[self.ptr[l]..self.ptr[l + 1]]
            }
            e => {
                one[0] = (e, 1.0);
                &one[..]
            }
        }
    }

    /// `u = T y + t`: every dof from the unknowns `y`.
    pub fn expand(&self, y: &[f64]) -> Vec<f64> {
        let mut u = self.constant.clone();
        for (&d, &v) in self.free.iter().zip(y) {
            u[d] = v;
        }
        for (l, &o) in self.dofs.iter().enumerate() {
            for &(e, c) in &self.terms[self.ptr[l]..self.ptr[l + 1]] {
                u[o] += c * y[e];
            }
        }
        u
    }

    /// The unknowns of `u` (its values at the free dofs): `expand(restrict(u)) = u` for every
    /// `u` that satisfies the constraints, `restrict(expand(y)) = y` for every `y`.
    pub fn restrict(&self, u: &[f64]) -> Vec<f64> {
        self.free.iter().map(|&d| u[d]).collect()
    }

    /// `T^T f`: a force on every dof as a right-hand side of the reduced system.
    pub fn reduce_vector(&self, f: &[f64]) -> Vec<f64> {
        let mut r = self.restrict(f);
        for (l, &o) in self.dofs.iter().enumerate() {
            for &(e, c) in &self.terms[self.ptr[l]..self.ptr[l + 1]] {
                r[e] += c * f[o];
            }
        }
        r
    }

    /// The largest `|u_o - sum_j c_j u_j - b_o|` over the lines (zero for `u = T y + t`).
    pub fn violation(&self, u: &[f64]) -> f64 {
        self.lines()
            .map(|line| {
                let sum: f64 = line
                    .masters
                    .iter()
                    .zip(line.terms)
                    .map(|(&j, &(_, c))| c * u[j])
                    .sum();
                (u[line.dof] - sum - line.constant).abs()
            })
            .fold(0.0, f64::max)
    }

    /// The multiplier (force) of every line, in the order given, from the residual
    /// `r = K u - f` of the unreduced system at the solution: `mu_o = r_o` (see the module
    /// documentation). For Dirichlet lines, the support reactions.
    pub fn forces(&self, residual: &[f64]) -> Vec<f64> {
        self.dofs.iter().map(|&o| residual[o]).collect()
    }

    /// Add the coupling of the dofs `dofs` (an element's, or any block's) to the reduced
    /// pattern: the unknowns their rows of `T` touch. `scratch` is reused storage.
    fn add_block(&self, dofs: &[usize], builder: &mut PatternBuilder, scratch: &mut Vec<usize>) {
        scratch.clear();
        if self.is_dirichlet_only() {
            // entries NO_EQUATION are skipped by the builder
            scratch.extend(dofs.iter().map(|&d| self.equation[d]));
        } else {
            let mut one = [(0, 0.0)];
            for &d in dofs {
                scratch.extend(self.terms(d, &mut one).iter().map(|t| t.0));
            }
            scratch.sort_unstable();
            scratch.dedup();
        }
        builder.add_block(scratch);
    }

    /// Element-level application (assembly): see [`LocalAssembler`].
    pub fn local(&self) -> LocalAssembler<'_> {
        LocalAssembler {
            constraints: self,
            eqs: Vec::new(),
        }
    }

    /// Matrix-level application: the reduced pattern `T^T P T` of the assembled matrices on
    /// `pattern` (see [`Reduction`]).
    pub fn reduction<'a>(&'a self, pattern: &'a SymmetricPattern) -> Reduction<'a> {
        assert_eq!(pattern.n, self.size(), "a pattern of the constrained space");
        let mut builder = PatternBuilder::new(self.free_count());
        let mut block = Vec::new();
        for j in 0..pattern.n {
            for &i in &pattern.row_idx[pattern.col_ptr[j]..pattern.col_ptr[j + 1]] {
                self.add_block(&[i, j], &mut builder, &mut block);
            }
        }
        Reduction {
            constraints: self,
            full: pattern,
            pattern: builder.build(),
        }
    }
}

/// The constraints applied element by element while assembling (deal.II's
/// `distribute_local_to_global`): each element's `T_e^T K_e T_e` goes into the reduced matrix
/// and `-T_e^T K_e t_e` into the reduced right-hand side. For a Dirichlet-only set this is a
/// scatter of the element's free block and the `K_fp u_p` term, with no product.
pub struct LocalAssembler<'a> {
    constraints: &'a AffineConstraints,
    eqs: Vec<usize>,
}

impl LocalAssembler<'_> {
    /// Couple the unknowns of the block `dofs` in the reduced pattern.
    pub fn add_pattern(&mut self, dofs: &[usize], builder: &mut PatternBuilder) {
        self.constraints.add_block(dofs, builder, &mut self.eqs);
    }

    /// Add the symmetric block `ke` (row-major, `dofs.len()` square) on `dofs` to the reduced
    /// matrix `values` (on `pattern`, built by [`LocalAssembler::add_pattern`]) and its
    /// constant part `-T^T ke t` to the reduced right-hand side `rhs`.
    pub fn distribute(
        &mut self,
        dofs: &[usize],
        ke: &[f64],
        pattern: &SymmetricPattern,
        values: &mut [f64],
        rhs: &mut [f64],
    ) {
        let c = self.constraints;
        let m = dofs.len();
        if c.is_dirichlet_only() {
            let eqs = &mut self.eqs;
            eqs.clear();
            eqs.extend(dofs.iter().map(|&d| c.equation[d]));
            pattern.scatter(eqs, ke, values);
            // move K_fp u_p to the right-hand side
            for (b, &db) in dofs.iter().enumerate() {
                if eqs[b] != NO_EQUATION || c.constant[db] == 0.0 {
                    continue;
                }
                for a in 0..m {
                    if eqs[a] != NO_EQUATION {
                        rhs[eqs[a]] -= ke[a * m + b] * c.constant[db];
                    }
                }
            }
            return;
        }
        let (mut one_a, mut one_b) = ([(0, 0.0)], [(0, 0.0)]);
        for (a, &da) in dofs.iter().enumerate() {
            let ta = c.terms(da, &mut one_a);
            for (b, &db) in dofs.iter().enumerate() {
                let k = ke[a * m + b];
                for &(pa, ca) in ta {
                    for &(pb, cb) in c.terms(db, &mut one_b) {
                        if pa <= pb {
                            let p = pattern.position(pa, pb).expect("in the reduced pattern");
                            values[p] += ca * cb * k;
                        }
                    }
                }
                let tb = c.constant[db];
                if c.equation[db] == NO_EQUATION && tb != 0.0 {
                    for &(pa, ca) in ta {
                        rhs[pa] -= ca * k * tb;
                    }
                }
            }
        }
    }
}

/// A constraint set applied to assembled symmetric matrices on one pattern `P` (upper
/// triangle): the reduced pattern `T^T P T` is built once (so is any symbolic factorization
/// of it), then [`Reduction::matrix`] and [`Reduction::rhs`] reduce every matrix and
/// right-hand side on `P`.
pub struct Reduction<'a> {
    constraints: &'a AffineConstraints,
    full: &'a SymmetricPattern,
    /// The pattern of `T^T K T` over the free unknowns.
    pub pattern: SymmetricPattern,
}

impl Reduction<'_> {
    /// `T^T K T` on [`Reduction::pattern`], for the values `k` of `K` on the full pattern.
    pub fn matrix(&self, k: &[f64]) -> Vec<f64> {
        let (c, p, rp) = (self.constraints, self.full, &self.pattern);
        let mut values = vec![0.0; rp.nnz()];
        let (mut one_r, mut one_c) = ([(0, 0.0)], [(0, 0.0)]);
        for j in 0..p.n {
            for idx in p.col_ptr[j]..p.col_ptr[j + 1] {
                let i = p.row_idx[idx];
                let kij = k[idx];
                // the stored entry (i, j) stands for K_ij and K_ji
                let pairs: &[(usize, usize)] = if i == j { &[(i, j)] } else { &[(i, j), (j, i)] };
                for &(r, s) in pairs {
                    let tr = c.terms(r, &mut one_r);
                    for &(pr, a) in tr {
                        for &(ps, b) in c.terms(s, &mut one_c) {
                            if pr <= ps {
                                values[rp.position(pr, ps).expect("in the reduced pattern")] +=
                                    a * b * kij;
                            }
                        }
                    }
                }
            }
        }
        values
    }

    /// `T^T (f - K t)` for the values `k` of `K` on the full pattern and `f` on every dof.
    pub fn rhs(&self, k: &[f64], f: &[f64]) -> Vec<f64> {
        let c = self.constraints;
        let n = self.full.n;
        let mut kt = vec![0.0; n];
        self.full.mul(k, &c.constant, &mut kt);
        let mut rb = vec![0.0; c.free_count()];
        let mut one = [(0, 0.0)];
        for d in 0..n {
            let v = f[d] - kt[d];
            for &(q, a) in c.terms(d, &mut one) {
                rb[q] += a * v;
            }
        }
        rb
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solver::sparse::Cholesky;

    /// A line as the tests give it: constrained dof, `(master, coefficient)` pairs, constant.
    type LineSpec = (usize, Vec<(usize, f64)>, f64);

    /// A small SPD matrix with a sparse pattern: a chain of springs `d - d+1` and `d - d+2`
    /// with stiffnesses from a fixed sequence, grounded at both ends (upper triangle, full
    /// pattern, and the same matrix dense).
    fn springs(n: usize) -> (SymmetricPattern, Vec<f64>, Vec<f64>) {
        let mut dense = vec![0.0; n * n];
        let mut s = 0.37f64;
        let mut next = || {
            s = (s * 7.13 + 0.29).fract();
            1.0 + 3.0 * s
        };
        for d in 0..n {
            for step in [1, 2] {
                if d + step < n {
                    let k = next();
                    let (a, b) = (d, d + step);
                    dense[a * n + a] += k;
                    dense[b * n + b] += k;
                    dense[a * n + b] -= k;
                    dense[b * n + a] -= k;
                }
            }
        }
        dense[0] += 2.0;
        dense[n * n - 1] += 1.5;
        let mut builder = PatternBuilder::new(n);
        for d in 0..n {
            builder.add_block(&(d..(d + 3).min(n)).collect::<Vec<_>>());
        }
        let pattern = builder.build();
        let mut values = vec![0.0; pattern.nnz()];
        for j in 0..n {
            for k in pattern.col_ptr[j]..pattern.col_ptr[j + 1] {
                values[k] = dense[pattern.row_idx[k] * n + j];
            }
        }
        (pattern, values, dense)
    }

    /// Solve the dense `n x n` system `a x = b` by Gaussian elimination with partial pivoting.
    fn dense_solve(mut a: Vec<f64>, mut b: Vec<f64>) -> Vec<f64> {
        let n = b.len();
        for k in 0..n {
            let p = (k..n)
                .max_by(|&i, &j| a[i * n + k].abs().total_cmp(&a[j * n + k].abs()))
                .unwrap();
            for j in 0..n {
                a.swap(k * n + j, p * n + j);
            }
            b.swap(k, p);
            for i in k + 1..n {
                let l = a[i * n + k] / a[k * n + k];
                for j in k..n {
                    a[i * n + j] -= l * a[k * n + j];
                }
                b[i] -= l * b[k];
            }
        }
        let mut x = vec![0.0; n];
        for k in (0..n).rev() {
            let s: f64 = (k + 1..n).map(|j| a[k * n + j] * x[j]).sum();
            x[k] = (b[k] - s) / a[k * n + k];
        }
        x
    }

    /// Solve the constrained problem by reduction: `T^T K T y = T^T (f - K t)`.
    fn solve_reduced(
        c: &AffineConstraints,
        pattern: &SymmetricPattern,
        k: &[f64],
        f: &[f64],
    ) -> Vec<f64> {
        let reduction = c.reduction(pattern);
        let values = reduction.matrix(k);
        let mut y = reduction.rhs(k, f);
        let chol =
            Cholesky::analyse(&reduction.pattern, &crate::solver::sparse::UNLIMITED).unwrap();
        chol.factor(&reduction.pattern, &values)
            .unwrap()
            .solve_in_place(&mut y);
        c.expand(&y)
    }

    /// The same problem by Lagrange multipliers, dense: `[[K, G^T], [G, 0]] [u; -mu] = [f; b]`
    /// with one row `e_o - sum_j c_j e_j` per line (as given, unresolved). Returns `(u, mu)`.
    fn solve_lagrange(dense: &[f64], f: &[f64], lines: &[LineSpec]) -> (Vec<f64>, Vec<f64>) {
        let n = f.len();
        let m = lines.len();
        let s = n + m;
        let mut a = vec![0.0; s * s];
        for i in 0..n {
            for j in 0..n {
                a[i * s + j] = dense[i * n + j];
            }
        }
        let mut b = f.to_vec();
        for (l, (o, masters, constant)) in lines.iter().enumerate() {
            let row = n + l;
            let mut g = vec![0.0; n];
            g[*o] += 1.0;
            for &(j, c) in masters {
                g[j] -= c;
            }
            for (d, &v) in g.iter().enumerate() {
                a[row * s + d] = v;
                a[d * s + row] = v;
            }
            b.push(*constant);
        }
        let x = dense_solve(a, b);
        (x[..n].to_vec(), x[n..].iter().map(|v| -v).collect())
    }

    fn residual(dense: &[f64], u: &[f64], f: &[f64]) -> Vec<f64> {
        let n = f.len();
        (0..n)
            .map(|i| (0..n).map(|j| dense[i * n + j] * u[j]).sum::<f64>() - f[i])
            .collect()
    }

    fn build(n: usize, lines: &[LineSpec]) -> AffineConstraints {
        let mut b = ConstraintBuilder::new(n);
        for (o, masters, constant) in lines {
            b.constrain(*o, masters, *constant).unwrap();
        }
        b.close().unwrap()
    }

    fn max_diff(a: &[f64], b: &[f64]) -> f64 {
        a.iter().zip(b).fold(0.0, |m, (x, y)| m.max((x - y).abs()))
    }

    fn max_abs(a: &[f64]) -> f64 {
        a.iter().fold(0.0, |m, x| m.max(x.abs()))
    }

    /// Dirichlet values at both ends and the two-master constraint `u_4 = 0.6 u_2 - 1.3 u_7
    /// + 0.05` (its masters far apart, so `T^T K T` couples unknowns `K` does not).
    fn example() -> (usize, Vec<f64>, Vec<LineSpec>) {
        let n = 10;
        let f: Vec<f64> = (0..n).map(|d| ((d * 5 % 7) as f64 - 3.0) * 0.4).collect();
        let lines = vec![
            (0, vec![], 0.02),
            (9, vec![], -0.01),
            (4, vec![(2, 0.6), (7, -1.3)], 0.05),
        ];
        (n, f, lines)
    }

    #[test]
    fn reduction_matches_lagrange_multipliers() {
        let (n, f, lines) = example();
        let (pattern, k, dense) = springs(n);
        let c = build(n, &lines);
        assert_eq!(c.free_count(), n - 3);
        assert!(!c.is_dirichlet_only());
        let u = solve_reduced(&c, &pattern, &k, &f);
        let (u_lagrange, mu) = solve_lagrange(&dense, &f, &lines);
        let scale = max_abs(&u_lagrange);
        assert!(scale > 1e-2, "a non-trivial solution ({scale})");
        let diff = max_diff(&u, &u_lagrange);
        assert!(diff <= 1e-12 * scale, "u differs by {diff:e}");
        assert!(c.violation(&u) <= 1e-14, "{}", c.violation(&u));
        assert!((u[4] - (0.6 * u[2] - 1.3 * u[7] + 0.05)).abs() < 1e-14);
        assert_eq!((u[0], u[9]), (0.02, -0.01));
        // the forces recovered at the eliminated dofs are the multipliers
        let forces = c.forces(&residual(&dense, &u, &f));
        let fscale = max_abs(&mu);
        assert!(
            mu[2].abs() > 1e-2 * fscale,
            "the constraint carries a force"
        );
        let diff = max_diff(&forces, &mu);
        assert!(diff <= 1e-11 * fscale, "forces {forces:?} vs {mu:?}");
        // and the unconstrained equilibrium would differ: the constraint does something
        let free = solve_reduced(&build(n, &lines[..2]), &pattern, &k, &f);
        assert!(max_diff(&free, &u) > 1e-3 * scale);
    }

    #[test]
    fn element_assembly_matches_the_reduction_of_the_assembled_matrix() {
        // assemble the springs element by element through the constraints and compare with
        // T^T K T and T^T (f - K t) of the assembled matrix
        let (n, f, lines) = example();
        let (pattern, k, dense) = springs(n);
        let c = build(n, &lines);
        let reduction = c.reduction(&pattern);
        let mut local = c.local();
        let mut builder = PatternBuilder::new(c.free_count());
        // elements: each dense 2x2 spring (d, d + step) of the matrix, plus the ground springs
        let mut elements: Vec<(Vec<usize>, Vec<f64>)> = Vec::new();
        for d in 0..n {
            for step in [1, 2] {
                if d + step < n {
                    let s = -dense[d * n + d + step];
                    elements.push((vec![d, d + step], vec![s, -s, -s, s]));
                }
            }
        }
        elements.push((vec![0], vec![2.0]));
        elements.push((vec![n - 1], vec![1.5]));
        for (dofs, _) in &elements {
            local.add_pattern(dofs, &mut builder);
        }
        let rp = builder.build();
        assert_eq!(rp.col_ptr, reduction.pattern.col_ptr);
        assert_eq!(rp.row_idx, reduction.pattern.row_idx);
        let mut values = vec![0.0; rp.nnz()];
        let mut rhs = c.reduce_vector(&f);
        for (dofs, ke) in &elements {
            local.distribute(dofs, ke, &rp, &mut values, &mut rhs);
        }
        let expected = reduction.matrix(&k);
        assert!(max_diff(&values, &expected) <= 1e-12 * max_abs(&expected));
        let expected = reduction.rhs(&k, &f);
        assert!(max_diff(&rhs, &expected) <= 1e-12 * max_abs(&expected));
    }

    #[test]
    fn dirichlet_only_sets_select_and_copy() {
        let prescribed = [None, Some(0.5), None, None, Some(-1.0), None];
        let c = AffineConstraints::dirichlet(&prescribed);
        assert!(c.is_dirichlet_only());
        assert_eq!(c.equations(), &[0, NO_EQUATION, 1, 2, NO_EQUATION, 3][..]);
        assert_eq!(c.free_dofs(), &[0, 2, 3, 5][..]);
        assert_eq!(c.constants(), &[0.0, 0.5, 0.0, 0.0, -1.0, 0.0][..]);
        // the same set through the builder
        let mut b = ConstraintBuilder::new(6);
        b.dirichlet(1, 0.5).unwrap();
        b.dirichlet(4, -1.0).unwrap();
        let built = b.close().unwrap();
        assert_eq!(built.equations(), c.equations());
        assert_eq!(built.constants(), c.constants());
        // reduction of a Dirichlet-only set: the free block and f - K t
        let (pattern, k, dense) = springs(6);
        let f = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let r = c.reduction(&pattern);
        let values = r.matrix(&k);
        for (a, &i) in c.free_dofs().iter().enumerate() {
            for (b, &j) in c.free_dofs().iter().enumerate() {
                if let Some(p) = r.pattern.position(a, b) {
                    assert_eq!(values[p], dense[i * 6 + j]);
                }
            }
        }
        let rhs = r.rhs(&k, &f);
        for (a, &i) in c.free_dofs().iter().enumerate() {
            let kt = 0.5 * dense[i * 6 + 1] - 1.0 * dense[i * 6 + 4];
            assert!((rhs[a] - (f[i] - kt)).abs() < 1e-14);
        }
    }

    #[test]
    fn expand_and_restrict_round_trip() {
        let (n, _, lines) = example();
        let c = build(n, &lines);
        let y: Vec<f64> = (0..c.free_count()).map(|e| 0.3 * e as f64 - 0.7).collect();
        let u = c.expand(&y);
        assert_eq!(c.restrict(&u), y);
        assert!(c.violation(&u) <= 1e-15);
        assert_eq!(c.expand(&c.restrict(&u)), u);
        // a u that violates a line is not in the range of expand: expand(restrict(u)) fixes it
        let mut bad = u.clone();
        bad[4] += 1.0;
        assert!(c.violation(&bad) > 0.5);
        assert_eq!(c.expand(&c.restrict(&bad)), u);
        // T^T is the transpose of T: y' . T^T f = (T y') . f - t . f
        let f: Vec<f64> = (0..n).map(|d| (d as f64).sin()).collect();
        let tf = c.reduce_vector(&f);
        let lhs: f64 = y.iter().zip(&tf).map(|(a, b)| a * b).sum();
        let rhs: f64 = u.iter().zip(&f).map(|(a, b)| a * b).sum::<f64>()
            - c.constants()
                .iter()
                .zip(&f)
                .map(|(a, b)| a * b)
                .sum::<f64>();
        assert!((lhs - rhs).abs() < 1e-13, "{lhs} vs {rhs}");
    }

    #[test]
    fn chains_are_resolved_and_match_lagrange_multipliers() {
        // u_3 = 2 u_5 + 0.1 with u_5 = 0.5 u_1 - u_6 and u_6 = 0.03 (Dirichlet): a chain of
        // depth two; u_8 = u_3 + u_1 names a constrained master and a free one twice over
        let n = 10;
        let lines = vec![
            (3, vec![(5, 2.0)], 0.1),
            (8, vec![(3, 1.0), (1, 1.0)], 0.0),
            (5, vec![(1, 0.5), (6, -1.0)], 0.0),
            (6, vec![], 0.03),
            (0, vec![], 0.0),
        ];
        let c = build(n, &lines);
        let l3 = c.line(0);
        assert_eq!(l3.dof, 3);
        assert_eq!(l3.masters, &[1][..]);
        assert!((l3.terms[0].1 - 1.0).abs() < 1e-15);
        assert!((l3.constant - (0.1 - 2.0 * 0.03)).abs() < 1e-15);
        // u_8 = u_3 + u_1 = 2 u_1 + 0.04: the master u_1 met twice is merged
        let l8 = c.line(1);
        assert_eq!(l8.masters, &[1][..]);
        assert!((l8.terms[0].1 - 2.0).abs() < 1e-15);
        assert!((l8.constant - 0.04).abs() < 1e-15);
        // the resolved set gives the solution of the set as given
        let (pattern, k, dense) = springs(n);
        let f: Vec<f64> = (0..n).map(|d| 0.2 * d as f64 - 0.5).collect();
        let u = solve_reduced(&c, &pattern, &k, &f);
        let (u_lagrange, _) = solve_lagrange(&dense, &f, &lines);
        let scale = max_abs(&u_lagrange);
        assert!(max_diff(&u, &u_lagrange) <= 1e-12 * scale);
        // a line without chains keeps its masters as given
        let plain = build(n, &[(4, vec![(7, 0.25), (2, -1.0)], 1.0)]);
        assert_eq!(plain.line(0).masters, &[7, 2][..]);
    }

    #[test]
    fn cycles_repeats_and_bad_input_are_refused() {
        let mut b = ConstraintBuilder::new(6);
        b.constrain(1, &[(2, 1.0)], 0.0).unwrap();
        b.constrain(2, &[(4, 0.5), (3, 1.0)], 0.0).unwrap();
        b.constrain(3, &[(1, 2.0)], 0.0).unwrap();
        assert_eq!(
            b.close().unwrap_err(),
            ConstraintError::Cycle {
                dofs: vec![1, 2, 3]
            }
        );
        let mut b = ConstraintBuilder::new(6);
        b.constrain(5, &[(0, 1.0), (5, 0.5)], 0.0).unwrap();
        assert_eq!(
            b.close().unwrap_err(),
            ConstraintError::Cycle { dofs: vec![5] }
        );
        let mut b = ConstraintBuilder::new(6);
        b.dirichlet(2, 1.0).unwrap();
        assert_eq!(
            b.constrain(2, &[(0, 1.0)], 0.0),
            Err(ConstraintError::Repeated { dof: 2 })
        );
        assert_eq!(
            b.constrain(1, &[(6, 1.0)], 0.0),
            Err(ConstraintError::OutOfRange { dof: 6, size: 6 })
        );
        assert_eq!(
            b.constrain(1, &[(0, f64::NAN)], 0.0),
            Err(ConstraintError::NotFinite { dof: 1 })
        );
        // a zero coefficient is no dependency: u_1 = 0 u_2 + 2 u_3 and u_2 = 0 u_1 + 1 resolve
        let mut z = ConstraintBuilder::new(4);
        z.constrain(1, &[(2, 0.0), (3, 2.0)], 0.0).unwrap();
        z.constrain(2, &[(1, 0.0)], 1.0).unwrap();
        let zeros = z.close().unwrap();
        assert_eq!(zeros.line(0).masters, &[3][..]);
        assert_eq!(zeros.line(1).masters, &[] as &[usize]);
        assert_eq!(zeros.expand(&[5.0, 7.0]), vec![5.0, 14.0, 1.0, 7.0]);
        // the refused lines left nothing behind
        let c = b.close().unwrap();
        assert_eq!(c.len(), 1);
        assert_eq!(c.free_count(), 5);
    }
}
