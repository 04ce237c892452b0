//! Small-strain contact: two orthogonal axes that meet in one small type (frictionless, tied,
//! and Coulomb friction through [`friction`]).
//!
//! **The meeting point.** Every discretization turns a contact pair into a list of
//! [`Constraint`]s: a gap that is affine in the displacements,
//!
//! ```text
//! g_i(u) = g0_i + sum_k c_ik u_{d_ik}        (g >= 0 open, g < 0 penetration)
//! ```
//!
//! with its tributary area `A_i` (the slave node's share of the slave surface times the
//! thickness), its normal, and the slave dof an elimination may solve for. With small-strain
//! kinematics the geometry (closest points, normals, weights) is taken once, in the reference
//! configuration; the rows are then fixed for the whole solve, so the sparsity pattern and the
//! symbolic factorization are computed once from all candidate rows.
//!
//! **The discretization axis** ([`discretization`]): node-to-node, node-to-surface one-pass and
//! two-pass (master or slave normals, the corner condition), rigid analytic masters.
//!
//! **The enforcement axis** ([`enforcement`], [`crate::solver::active_set`]): with the contact force `lambda_i`
//! (compression positive) equilibrium reads `K u = f + B^T lambda`, `B_ik = dg_i/du_k`, and
//!
//! * Lagrange multiplier: `g_i = 0` on the active set (an indefinite saddle-point system),
//! * perturbed Lagrangian: `g_i + lambda_i / (kappa A_i) = 0`,
//! * penalty: `lambda_i = -kappa A_i g_i` eliminated up front,
//! * perturbed tangent: the Lagrange residual with the perturbed Lagrangian tangent,
//! * augmented Lagrangian: `lambda_i = lambda_k,i - kappa A_i g_i` with the Uzawa update
//!   `lambda_k <- lambda` per Newton iteration or in an outer loop,
//! * constraint elimination: each active row solved for its own slave dof.
//!
//! Coulomb pairs give every row its tangential slip measures too ([`TangentRow`], one per
//! tangent direction); the return map of [`friction`] (penalty regularization, Newton scheme)
//! turns them into a tangential force.
//!
//! All six are written once against [`Constraint`] (Taylor 2004, "1985: Solution Methods":
//! the augmented perturbed form "can reduce to all other forms").

pub mod discretization;
pub mod enforcement;
pub mod forces;
pub mod friction;
pub mod results;
pub mod rows;
pub mod state;

/// One linearized contact constraint (a row of `B`) in `D` dimensions (2 unless named: the
/// normal, the slave normal and the slave point have `D` components; 3 for 3D bodies).
#[derive(Clone, Debug, PartialEq)]
pub struct Constraint<const D: usize = 2> {
    /// Global dofs of the gradient row.
    pub dofs: Vec<usize>,
    /// `dg/du` for each of `dofs`.
    pub coeffs: Vec<f64>,
    /// Gap at `u = 0`.
    pub g0: f64,
    /// Tributary area of the slave node (length x thickness); 1 for lumped node-to-node pairs
    /// on a surface without facets.
    pub area: f64,
    /// The gradient of the gap with respect to the slave node's displacement (points from
    /// master to slave): the unit normal for master normals, rigid surfaces and mortar,
    /// `n_m / (n_m . nu)` for slave normals, `e_x` or `e_y` for tied rows. The row's force on
    /// the slave node is `lambda * normal`.
    pub normal: [f64; D],
    /// Outward unit normal of the slave surface at the slave node (zero for rigid slaves).
    pub slave_normal: [f64; D],
    /// Body and local node of the slave node, and its reference position.
    pub slave_body: usize,
    pub slave_node: usize,
    pub point: [f64; D],
    /// 1 for the first pass, 2 for the second pass of a two-pass discretization.
    pub pass: u8,
    /// The slave dof this constraint may be solved for (largest |c| among the slave dofs).
    pub owner: usize,
    /// Index of the contact pair in the model.
    pub pair: usize,
    /// A tie: always active, its force may have either sign.
    pub bilateral: bool,
    /// The row's line of the multiplier mass `M_jk = int Phi_j Phi_k dGamma` (length x
    /// thickness) over the slave nodes `k` of the same pair, pass and direction (`j` is this
    /// row's slave node, listed too), when the discretization's multipliers are not lumped;
    /// empty when the mass is the lumped `diag(area)` (node-based rows, dual mortar). Its
    /// entries sum to `area`. Only the perturbed Lagrangian uses it (see
    /// [`enforcement`]): `C = A^-1 M A^-1 / kappa`.
    pub mass: Vec<(usize, f64)>,
    /// The part of the slave node's tributary that this row's master covers, facet by facet:
    /// `(facet, t int_{covered part of the facet} N_a ds)`, `facet` an index into the pair's
    /// slave facets of this pass (the facets of its [`discretization::geometry::Surface`]).
    /// Node-based rows and rigid masters cover the node's whole tributary (`N_a` integrated
    /// over each facet that holds it: a node has a row where a master facet lies under it);
    /// mortar rows between bodies the pieces of the slave facets that a master facet overlaps.
    /// Empty where it is not computed (3D mortar): the node then counts as not covered. Only
    /// the recovery of the nodal traction uses it ([`forces`]).
    pub cover: Vec<(usize, f64)>,
    /// The tangential slip measures of a frictional (Coulomb) pair, one per tangent direction
    /// (`D - 1`: one in 2D, an orthonormal pair of the tangent plane in 3D), empty elsewhere:
    /// physics is opt-in, a frictionless scene builds no tangential row.
    pub tangents: Vec<TangentRow<D>>,
    /// Finite kinematics, node-to-surface with master normals between deformable bodies: the
    /// row's nodes and positions for the second derivative of its gap
    /// ([`discretization::node_to_segment`]); `None` elsewhere (small strain builds none).
    pub segment: Option<discretization::node_to_segment::SegmentLinearization>,
    /// Finite kinematics, node-to-surface with slave normals and node-to-node between
    /// deformable bodies: the row's nodes (the normal's surface neighbours included) for the
    /// variation of its nodal normal ([`discretization::nodal_normal`]); `None` elsewhere.
    pub nodal_normal: Option<discretization::nodal_normal::NodalNormalLinearization>,
    /// Finite kinematics, mortar between deformable bodies: the second derivative of the row's
    /// gap, computed with the row (`contact::discretization::mortar_linearization`); `None`
    /// elsewhere (small strain builds none).
    pub hessian: Option<GapHessian>,
    /// Finite kinematics, 2D node-to-surface: the row holds a slave node that is past the
    /// master surface's free end (beyond the end's extension, no master facet under it) against
    /// the nearest vertex two master facets share, for Newton's iterates only. Its gap is the
    /// distance to that vertex, positive, so it carries no force at a converged state; the
    /// node is reported `unmeasured` (its gap is not a gap to the master under it: there is
    /// none). `false` for every other row.
    pub past_free_end: bool,
}

/// Where a row acts, in any dimension: its dofs, the slave dof it may be solved for and the
/// slave point (what an enforcement method's applicability depends on).
#[derive(Clone, Copy, Debug)]
pub struct RowSite<'a> {
    pub dofs: &'a [usize],
    pub owner: usize,
    pub point: &'a [f64],
}

impl RowSite<'_> {
    /// The slave point in words, `(x, y)` or `(x, y, z)`.
    pub fn at(&self) -> String {
        let at: Vec<String> = self.point.iter().map(|x| x.to_string()).collect();
        format!("({})", at.join(", "))
    }
}

/// The second derivative of a row's gap over the dofs it depends on, evaluated where the row
/// was built: `values[a * dofs.len() + b] = d2 g / du_{dofs[a]} du_{dofs[b]}` (symmetric).
#[derive(Clone, Debug, PartialEq)]
pub struct GapHessian {
    pub dofs: Vec<usize>,
    pub values: Vec<f64>,
}

/// The tangential slip of a contact point along one tangent, `g_t(u) = sum_k c_ik u_{d_ik}`
/// (zero at `u = 0`): the relative displacement of the slave node against its master point
/// along the unit tangent `t`, with the normal row's projection weights, `g_t = t . (u_s -
/// sum_m N_m u_m)` (rigid masters: `t . u_s`). In 2D `t = (-n_y, n_x)` for the row's normal `n`;
/// in 3D a point has two, an orthonormal frame `t_1, t_2` of the plane normal to `n`
/// ([`tangent_frame`]).
#[derive(Clone, Debug, PartialEq)]
pub struct TangentRow<const D: usize = 2> {
    pub dofs: Vec<usize>,
    pub coeffs: Vec<f64>,
    /// The unit tangent `t`: the row's tangential force on the slave node is `lambda_t t`.
    pub direction: [f64; D],
}

/// An orthonormal frame `t_1, t_2` of the plane normal to the unit vector `n` (3D), with
/// `t_1 x t_2 = n`: `t_1` is `n x e`, normalized, for the axis `e` least aligned with `n` (so
/// that the cross product is far from zero), `t_2 = n x t_1`. The frame is a function of `n`
/// alone, so every row with the same normal has the same tangents.
pub fn tangent_frame(n: [f64; 3]) -> [[f64; 3]; 2] {
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let least = (1..3).fold(
        0,
        |best, i| {
            if n[i].abs() < n[best].abs() {
                i
            } else {
                best
            }
        },
    );
    let mut e = [0.0; 3];
    e[least] = 1.0;
    let t1 = cross(n, e);
    let l = t1.iter().map(|v| v * v).sum::<f64>().sqrt();
    let t1 = t1.map(|v| v / l);
    [t1, cross(n, t1)]
}

impl<const D: usize> TangentRow<D> {
    /// The slip measure at `u`.
    pub fn slip(&self, u: &[f64]) -> f64 {
        self.dofs
            .iter()
            .zip(&self.coeffs)
            .map(|(&d, c)| c * u[d])
            .sum()
    }
}

/// A row's identity across iterations, geometry updates and load steps: pair, pass, slave body
/// and node, and for ties the direction (0 = x, 1 = y, 2 = z: the largest component of the
/// tie's normal, the first of equal ones).
pub(crate) type RowKey = (usize, u8, usize, usize, u8);

/// The identity of row `r`.
pub(crate) fn row_key<const D: usize>(r: &Constraint<D>) -> RowKey {
    let direction = if r.bilateral {
        (1..D).fold(0, |best, i| {
            if r.normal[i].abs() > r.normal[best].abs() {
                i
            } else {
                best
            }
        }) as u8
    } else {
        0
    };
    (r.pair, r.pass, r.slave_body, r.slave_node, direction)
}

impl<const D: usize> Constraint<D> {
    /// Where the row acts (see [`RowSite`]).
    pub fn site(&self) -> RowSite<'_> {
        RowSite {
            dofs: &self.dofs,
            owner: self.owner,
            point: &self.point,
        }
    }

    /// Gap for the displacement `u`.
    pub fn gap(&self, u: &[f64]) -> f64 {
        self.g0
            + self
                .dofs
                .iter()
                .zip(&self.coeffs)
                .map(|(&d, c)| c * u[d])
                .sum::<f64>()
    }

    /// The gradients the row restrains: the normal one, then the tangential ones (if any).
    pub fn gradients(&self) -> impl Iterator<Item = (&[usize], &[f64])> {
        std::iter::once((&self.dofs[..], &self.coeffs[..]))
            .chain(self.tangents.iter().map(|t| (&t.dofs[..], &t.coeffs[..])))
    }

    /// Every dof of the row's normal and tangential gradients and of its second derivative
    /// (each once).
    pub fn all_dofs(&self) -> Vec<usize> {
        let mut d = self.dofs.clone();
        for t in &self.tangents {
            for &x in &t.dofs {
                if !d.contains(&x) {
                    d.push(x);
                }
            }
        }
        let curvature_dofs = self
            .segment
            .as_ref()
            .map(|s| &s.dofs)
            .into_iter()
            .chain(self.nodal_normal.as_ref().map(|n| &n.dofs))
            .chain(self.hessian.as_ref().map(|h| &h.dofs));
        for dofs in curvature_dofs {
            for &x in dofs {
                if !d.contains(&x) {
                    d.push(x);
                }
            }
        }
        d
    }
}
