//! Small-strain isotropic linear elasticity in 2D: element residual and tangent, stiffness,
//! stress.
//!
//! Voigt notation with engineering shear: `eps = [eps_xx, eps_yy, gamma_xy]`,
//! `sigma = [sigma_xx, sigma_yy, sigma_xy] = D eps`, with
//! plane strain `D = [[l+2m, l, 0], [l, l+2m, 0], [0, 0, m]]` (Lame l, m) and
//! plane stress `D = E/(1-nu^2) [[1, nu, 0], [nu, 1, 0], [0, 0, (1-nu)/2]]`.
//! Out-of-plane stress: `sigma_zz = nu (sigma_xx + sigma_yy)` in plane strain, zero in plane
//! stress.
//!
//! **Residual and tangent.** An element contributes, at its current displacements `u_e`, the
//! internal force and its derivative
//! `f_int(u_e) = int B^T sigma(u_e) t dA` and `K_T = d f_int / d u_e`,
//! with `B_a = [[N_a,x, 0], [0, N_a,y], [N_a,y, N_a,x]]` and each integral evaluated with the
//! element's stiffness rule (see `fe`): `sum_q w_q det J t (...)` at the quadrature points.
//! The strain comes from the displacement gradient `H = du/dx = sum_a u_a (grad N_a)^T` as
//! `eps = [H_xx, H_yy, H_xy + H_yx]`. Equilibrium is `f_int(u) = f_ext` (+ contact forces).
//!
//! **Mass.** For dynamics ([`crate::solver::dynamics`]) an element also gives its consistent
//! mass `M_e = int rho N^T N t dA` ([`element_mass`], both components alike, with a rule exact
//! for `N_a N_b` on straight-sided elements) and its lumped mass by the HRZ scaling of the
//! consistent diagonal (Hinton, Rock & Zienkiewicz, Earthquake Eng. Struct. Dyn. 4 (1976)
//! 245-249): `m_a = M_aa m / sum_b M_bb`, `m` the element's mass, positive for every element
//! (row sums are zero or negative at the corners of T6 and Q9 would be wrong for T6).
//!
//! **Kinematics seam.** [`Kinematics`] says how strain follows from displacement. With small
//! strain (this module; finite deformation has its own kernels in [`crate::solid_finite`],
//! assembled by [`crate::solver::finite_assembly`]) `sigma = D eps` is linear in `u_e`, so
//! `f_int = K_e u_e` and `K_T = K_e = int B^T D B t dA`, the element stiffness; the kernel still
//! integrates `f_int` from the stresses, which is the form that finite strain keeps (there `B`
//! depends on `F = I + H` and `K_T` gains a geometric part). The kernels therefore take the
//! element's reference coordinates *and* its displacements.
//!
//! **Implementation.** Element-level algebra is on fixed-size nalgebra types, sized per element
//! kind at compile time (`N` nodes, `2 N` dofs): `D` a `Matrix3`, the nodes a `2 x N` matrix,
//! the gradients `dN_a/dx` an `N x 2` matrix, `B_a` a `Matrix3x2`, and `K_e` accumulated in
//! 2x2 node blocks `K_ab += w B_a^T (D B_b)` straight into its destination (a row-major view
//! of the caller's slice, or the leading block of an [`ElementMatrix`]), with `B`'s zeros
//! skipped; no heap allocation. `K_e` is bit-for-bit the one of the array loops it replaced
//! (see `add_material_tangent`). Global vectors and matrices (assembly, factorization) stay in
//! `solve`/`sparse` (faer).

use crate::fe::{ElementKind, QuadPoint, ReferenceCell, MAX_NODES};
use crate::io::scene::Plane;
use nalgebra::{
    Const, Matrix, Matrix2, Matrix3, Matrix3x2, MatrixViewMut, SMatrix, SVector, StorageMut,
    Vector3, U1,
};

/// Largest number of element dofs.
pub const MAX_DOFS: usize = 2 * MAX_NODES;

#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Elasticity {
    pub youngs_modulus: f64,
    pub nu: f64,
    pub plane: Plane,
    /// The constitutive matrix `D` (`sigma = D eps`, Voigt notation above).
    pub d: Matrix3<f64>,
}

impl Elasticity {
    pub fn new(youngs_modulus: f64, nu: f64, plane: Plane) -> Self {
        let e = youngs_modulus;
        let d = match plane {
            Plane::Strain => {
                let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
                let mu = e / (2.0 * (1.0 + nu));
                #[rustfmt::skip]
                let d = Matrix3::new(
                    lambda + 2.0 * mu, lambda, 0.0,
                    lambda, lambda + 2.0 * mu, 0.0,
                    0.0, 0.0, mu,
                );
                d
            }
            Plane::Stress => {
                let c = e / (1.0 - nu * nu);
                #[rustfmt::skip]
                let d = Matrix3::new(
                    c, c * nu, 0.0,
                    c * nu, c, 0.0,
                    0.0, 0.0, c * 0.5 * (1.0 - nu),
                );
                d
            }
        };
        Elasticity {
            youngs_modulus,
            nu,
            plane,
            d,
        }
    }

    pub fn stress(&self, strain: [f64; 3]) -> [f64; 3] {
        (self.d * Vector3::from(strain)).into()
    }

    /// In-plane strain that produces the in-plane stress `s` (inverse of `D`).
    pub fn strain_of_stress(&self, s: [f64; 3]) -> [f64; 3] {
        let d = &self.d;
        let det = d[(0, 0)] * d[(1, 1)] - d[(0, 1)] * d[(1, 0)];
        [
            (d[(1, 1)] * s[0] - d[(0, 1)] * s[1]) / det,
            (-d[(1, 0)] * s[0] + d[(0, 0)] * s[1]) / det,
            s[2] / d[(2, 2)],
        ]
    }

    pub fn sigma_zz(&self, s: [f64; 3]) -> f64 {
        match self.plane {
            Plane::Strain => self.nu * (s[0] + s[1]),
            Plane::Stress => 0.0,
        }
    }

    /// Young's modulus and Poisson ratio of the equivalent plane-stress problem (for formulas
    /// written in plane stress).
    pub fn plane_stress_equivalent(&self) -> (f64, f64) {
        match self.plane {
            Plane::Stress => (self.youngs_modulus, self.nu),
            Plane::Strain => (
                self.youngs_modulus / (1.0 - self.nu * self.nu),
                self.nu / (1.0 - self.nu),
            ),
        }
    }
}

/// How strains follow from displacements in this module's kernels: small strain. Finite
/// strain (total Lagrangian: `F = I + H`, Green-Lagrange `E = (F^T F - I) / 2`,
/// `f_int = int B(F)^T S t dA`, `K_T` = material + geometric part) takes a hyperelastic law
/// instead of [`Elasticity`], so it has its own kernels, [`crate::solid_finite`], chosen by
/// `physics.kinematics: "finite"`.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum Kinematics {
    /// `eps = sym grad u`, `f_int = K_e u_e`, `K_T = K_e`.
    SmallStrain,
}

/// An element vector: the leading `2 n` entries (dof order `[u_x0, u_y0, u_x1, ...]`) are the
/// element's, the rest zero.
pub type ElementVector = SVector<f64, MAX_DOFS>;
/// An element matrix: the leading `2 n x 2 n` block is the element's, the rest zero.
pub type ElementMatrix = SMatrix<f64, MAX_DOFS, MAX_DOFS>;

/// One quadrature point of an element of `N` nodes: the gradients `dN_a/dx` (row `a`) and the
/// weight `w = w_q det J t`.
struct Point<const N: usize> {
    dndx: SMatrix<f64, N, 2>,
    w: f64,
}

impl<const N: usize> Point<N> {
    /// `B_a = [[N_a,x, 0], [0, N_a,y], [N_a,y, N_a,x]]`.
    #[inline(always)]
    fn b(&self, a: usize) -> Matrix3x2<f64> {
        let (x, y) = (self.dndx[(a, 0)], self.dndx[(a, 1)]);
        Matrix3x2::new(x, 0.0, 0.0, y, y, x)
    }
}

/// The element's nodes as the columns of a `2 x N` matrix.
#[inline(always)]
fn nodes<const N: usize>(coords: &[[f64; 2]]) -> SMatrix<f64, 2, N> {
    debug_assert!(coords.len() >= N);
    SMatrix::<f64, 2, N>::from_fn(|i, a| coords[a][i])
}

/// The quadrature point `q` on the element with nodes `x` (`N` of them, see [`nodes`]); `None`
/// where `det J = 0`, a point that contributes nothing (the model refuses such elements).
#[inline(always)]
fn point<const N: usize>(
    kind: ElementKind,
    x: &SMatrix<f64, 2, N>,
    q: &QuadPoint,
    thickness: f64,
) -> Option<Point<N>> {
    debug_assert_eq!(kind.node_count(), N);
    let mut n = [0.0; N];
    let mut dn = [[0.0; 2]; N];
    kind.shape(q.xi, &mut n, &mut dn);
    let dn = SMatrix::<f64, N, 2>::from_fn(|a, k| dn[a][k]);
    // J_ik = dx_i/dxi_k = sum_a x_ia dN_a/dxi_k
    let j: Matrix2<f64> = x * dn;
    let det_j = j[(0, 0)] * j[(1, 1)] - j[(0, 1)] * j[(1, 0)];
    if det_j == 0.0 {
        return None;
    }
    let inv = Matrix2::new(j[(1, 1)], -j[(0, 1)], -j[(1, 0)], j[(0, 0)]) / det_j;
    Some(Point {
        dndx: dn * inv,
        w: q.weight * det_j * thickness,
    })
}

/// An `ND x ND` matrix, owned or a view (into a slice, or into an [`ElementMatrix`]).
type MatrixMut<const ND: usize, S> = Matrix<f64, Const<ND>, Const<ND>, S>;
/// An `ND` vector, owned or a view.
type VectorMut<const ND: usize, S> = Matrix<f64, Const<ND>, U1, S>;

/// Adds `w B^T D B` at one point to `k`, block by block: `K_ab += w B_a^T (D B_b)`, with `B`
/// applied through its structure (its zeros skipped).
///
/// Every block is computed, the lower ones too, with the operations of the array kernel this
/// one replaced and in the same order, so that `K_e` is the same to the last bit: the assembly
/// reads the upper triangle in global numbering, which takes local `(a, b)` or `(b, a)` blocks
/// depending on the mesh, and mirroring the upper local blocks instead changes the iteration
/// counts of round-off sensitive cells of the patch table.
#[inline(always)]
fn add_material_tangent<const N: usize, const ND: usize, S>(
    k: &mut MatrixMut<ND, S>,
    p: &Point<N>,
    d: &Matrix3<f64>,
) where
    S: StorageMut<f64, Const<ND>, Const<ND>>,
{
    let (d0, d1, d2) = (d.column(0), d.column(1), d.column(2));
    for b in 0..N {
        let (bx, by) = (p.dndx[(b, 0)], p.dndx[(b, 1)]);
        // D B_b
        let db = Matrix3x2::from_columns(&[d0 * bx + d2 * by, d1 * by + d2 * bx]);
        let (r0, r1, r2) = (db.row(0), db.row(1), db.row(2));
        for a in 0..N {
            let (ax, ay) = (p.dndx[(a, 0)], p.dndx[(a, 1)]);
            // B_a^T (D B_b)
            let kab = Matrix2::from_rows(&[r0 * ax + r2 * ay, r1 * ay + r2 * ax]);
            let mut block = k.fixed_view_mut::<2, 2>(2 * a, 2 * b);
            block += kab * p.w;
        }
    }
}

/// `eps = [H_xx, H_yy, H_xy + H_yx]` from the displacement gradient `H = du/dx = sum_a u_a
/// (dN_a/dx)^T` at one point (column `a` of `u` is node `a`).
#[inline(always)]
fn small_strain_at<const N: usize>(p: &Point<N>, u: &SMatrix<f64, 2, N>) -> Vector3<f64> {
    let h: Matrix2<f64> = u * p.dndx;
    Vector3::new(h[(0, 0)], h[(1, 1)], h[(0, 1)] + h[(1, 0)])
}

/// Adds `w B^T sigma` at one point to `f`, with `sigma = D eps(u)`.
#[inline(always)]
fn add_internal_force<const N: usize, const ND: usize, S>(
    f: &mut VectorMut<ND, S>,
    p: &Point<N>,
    d: &Matrix3<f64>,
    u: &SMatrix<f64, 2, N>,
) where
    S: StorageMut<f64, Const<ND>, U1>,
{
    let w_sigma = (d * small_strain_at(p, u)) * p.w;
    for a in 0..N {
        let mut fa = f.fixed_rows_mut::<2>(2 * a);
        fa += p.b(a).tr_mul(&w_sigma);
    }
}

/// Small strain, for an element of `N` nodes and `ND = 2 N` dofs: adds
/// `f_int = int B^T D eps(u_e) t dA` (`= K_e u_e`) to `f` when given (`u_e` is read only then),
/// and `K_T = K_e = int B^T D B t dA` to `k` when given.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn small_strain<const N: usize, const ND: usize, SF, SK>(
    kind: ElementKind,
    coords: &[[f64; 2]],
    u_e: &[f64],
    material: &Elasticity,
    thickness: f64,
    rule: &[QuadPoint],
    mut f: Option<&mut VectorMut<ND, SF>>,
    mut k: Option<&mut MatrixMut<ND, SK>>,
) where
    SF: StorageMut<f64, Const<ND>, U1>,
    SK: StorageMut<f64, Const<ND>, Const<ND>>,
{
    const { assert!(ND == 2 * N) };
    let u = match f {
        Some(_) => SMatrix::<f64, 2, N>::from_column_slice(&u_e[..ND]),
        None => SMatrix::<f64, 2, N>::zeros(),
    };
    let x = nodes::<N>(coords);
    for q in rule {
        let Some(p) = point(kind, &x, q, thickness) else {
            continue;
        };
        if let Some(f) = f.as_deref_mut() {
            add_internal_force(f, &p, &material.d, &u);
        }
        if let Some(k) = k.as_deref_mut() {
            add_material_tangent(k, &p, &material.d);
        }
    }
}

/// Calls `$body` with `N` (nodes) and `ND` (dofs) bound to the element kind's sizes.
macro_rules! with_sizes {
    ($kind:expr, |$n:ident, $nd:ident| $body:expr) => {
        match $kind {
            ElementKind::Q4 => {
                const $n: usize = 4;
                const $nd: usize = 8;
                $body
            }
            ElementKind::Q9 => {
                const $n: usize = 9;
                const $nd: usize = 18;
                $body
            }
            ElementKind::T3 => {
                const $n: usize = 3;
                const $nd: usize = 6;
                $body
            }
            ElementKind::T6 => {
                const $n: usize = 6;
                const $nd: usize = 12;
                $body
            }
        }
    };
}

/// Element stiffness `K_e` (row-major, `2 n x 2 n`, dof order `[u_x0, u_y0, u_x1, ...]`): the
/// small-strain tangent of [`element_residual_and_tangent`], without the internal force.
pub fn element_stiffness(
    kind: ElementKind,
    coords: &[[f64; 2]],
    material: &Elasticity,
    thickness: f64,
    rule: &[QuadPoint],
    ke: &mut [f64],
) {
    with_sizes!(kind, |N, ND| {
        let ke = &mut ke[..ND * ND];
        ke.fill(0.0);
        // accumulated in place, through a view whose rows are ND apart (row-major)
        let mut k = MatrixViewMut::from_slice_with_strides_generic(
            ke,
            Const::<ND>,
            Const::<ND>,
            Const::<ND>,
            U1,
        );
        small_strain::<N, ND, _, _>(
            kind,
            coords,
            &[],
            material,
            thickness,
            rule,
            None::<&mut SVector<f64, ND>>,
            Some(&mut k),
        );
    })
}

/// Internal force `f_int(u_e)` and tangent `K_T = d f_int / d u_e` of one element at the
/// element displacements `u_e` (`2 n` values, dof order `[u_x0, u_y0, u_x1, ...]`), `coords`
/// being the element's reference (undeformed) nodes.
pub fn element_residual_and_tangent(
    kinematics: Kinematics,
    kind: ElementKind,
    coords: &[[f64; 2]],
    u_e: &[f64],
    material: &Elasticity,
    thickness: f64,
    rule: &[QuadPoint],
) -> (ElementVector, ElementMatrix) {
    let mut f = ElementVector::zeros();
    let mut k = ElementMatrix::zeros();
    match kinematics {
        Kinematics::SmallStrain => with_sizes!(kind, |N, ND| {
            small_strain::<N, ND, _, _>(
                kind,
                coords,
                u_e,
                material,
                thickness,
                rule,
                Some(&mut f.fixed_rows_mut::<ND>(0)),
                Some(&mut k.fixed_view_mut::<ND, ND>(0, 0)),
            );
        }),
    }
    (f, k)
}

/// Internal force `f_int(u_e)` of one element alone (what [`element_residual_and_tangent`]
/// returns first, without the cost of the tangent).
pub fn element_internal_force(
    kinematics: Kinematics,
    kind: ElementKind,
    coords: &[[f64; 2]],
    u_e: &[f64],
    material: &Elasticity,
    thickness: f64,
    rule: &[QuadPoint],
) -> ElementVector {
    let mut f = ElementVector::zeros();
    match kinematics {
        Kinematics::SmallStrain => with_sizes!(kind, |N, ND| {
            small_strain::<N, ND, _, _>(
                kind,
                coords,
                u_e,
                material,
                thickness,
                rule,
                Some(&mut f.fixed_rows_mut::<ND>(0)),
                None::<&mut SMatrix<f64, ND, ND>>,
            );
        }),
    }
    f
}

/// Strain `[eps_xx, eps_yy, gamma_xy]` at natural point `xi` for element displacements `ue`.
pub fn strain_at(
    kind: ElementKind,
    coords: &[[f64; 2]],
    ue: &[f64],
    xi: [f64; 2],
) -> ([f64; 3], [f64; 2]) {
    let pv = kind.point_values(coords, xi);
    let mut e = [0.0; 3];
    for a in 0..kind.node_count() {
        let [dx, dy] = pv.dndx[a];
        let (ux, uy) = (ue[2 * a], ue[2 * a + 1]);
        e[0] += dx * ux;
        e[1] += dy * uy;
        e[2] += dy * ux + dx * uy;
    }
    (e, pv.x)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn distorted(kind: ElementKind) -> Vec<[f64; 2]> {
        // map the reference nodes through a smooth, orientation-preserving map
        kind.node_coordinates()
            .iter()
            .map(|&[s, t]| {
                [
                    2.0 + 1.3 * s + 0.2 * t + 0.05 * s * t,
                    1.0 + 0.1 * s + 0.9 * t,
                ]
            })
            .collect()
    }

    #[test]
    fn stiffness_is_symmetric_with_three_rigid_modes() {
        let mat = Elasticity::new(1000.0, 0.3, Plane::Strain);
        for kind in [
            ElementKind::Q4,
            ElementKind::Q9,
            ElementKind::T3,
            ElementKind::T6,
        ] {
            let coords = distorted(kind);
            let nd = 2 * kind.node_count();
            let mut ke = vec![0.0; nd * nd];
            element_stiffness(kind, &coords, &mat, 1.0, &kind.stiffness_rule(), &mut ke);
            let scale = ke.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for i in 0..nd {
                for j in 0..nd {
                    assert!((ke[i * nd + j] - ke[j * nd + i]).abs() < 1e-12 * scale);
                }
            }
            // rigid modes give zero force
            // translation x, translation y, rotation: u = a + w e_z x p
            for (a, w) in [([1.0, 0.0], 0.0), ([0.0, 1.0], 0.0), ([0.0, 0.0], 1.0)] {
                let u: Vec<f64> = coords
                    .iter()
                    .flat_map(|&p| [a[0] - w * p[1], a[1] + w * p[0]])
                    .collect();
                for i in 0..nd {
                    let f: f64 = (0..nd).map(|j| ke[i * nd + j] * u[j]).sum();
                    assert!(f.abs() < 1e-11 * scale, "{kind:?}: rigid mode force {f}");
                }
            }
            // a uniform strain has positive energy
            let u: Vec<f64> = coords
                .iter()
                .flat_map(|&p| [0.01 * p[0], -0.02 * p[1]])
                .collect();
            let energy: f64 = (0..nd)
                .map(|i| u[i] * (0..nd).map(|j| ke[i * nd + j] * u[j]).sum::<f64>())
                .sum();
            assert!(energy > 0.0);
        }
    }

    const KINDS: [ElementKind; 4] = [
        ElementKind::Q4,
        ElementKind::Q9,
        ElementKind::T3,
        ElementKind::T6,
    ];
    const THICKNESS: f64 = 0.7;

    fn materials() -> [Elasticity; 2] {
        [
            Elasticity::new(1000.0, 0.3, Plane::Strain),
            Elasticity::new(1000.0, 0.3, Plane::Stress),
        ]
    }

    /// Element displacements of no particular form (`2 n` values of order 1e-2).
    fn some_displacements(kind: ElementKind) -> Vec<f64> {
        (0..2 * kind.node_count())
            .map(|i| 0.01 * (1.7 * i as f64 + 0.3).sin())
            .collect()
    }

    fn internal_force(kind: ElementKind, mat: &Elasticity, u: &[f64]) -> ElementVector {
        let coords = distorted(kind);
        let rule = kind.stiffness_rule();
        element_internal_force(
            Kinematics::SmallStrain,
            kind,
            &coords,
            u,
            mat,
            THICKNESS,
            &rule,
        )
    }

    fn largest(v: impl IntoIterator<Item = f64>) -> f64 {
        v.into_iter().fold(0.0, |m, x| m.max(x.abs()))
    }

    #[test]
    fn tangent_is_the_central_difference_of_the_internal_force() {
        for mat in materials() {
            for kind in KINDS {
                let coords = distorted(kind);
                let rule = kind.stiffness_rule();
                let nd = 2 * kind.node_count();
                let u = some_displacements(kind);
                let (f, k) = element_residual_and_tangent(
                    Kinematics::SmallStrain,
                    kind,
                    &coords,
                    &u,
                    &mat,
                    THICKNESS,
                    &rule,
                );
                // the two entry points agree, and nothing is written beyond the element's dofs
                assert_eq!(f, internal_force(kind, &mat, &u));
                assert!(f.rows(nd, MAX_DOFS - nd).iter().all(|&v| v == 0.0));
                assert!(k.columns(nd, MAX_DOFS - nd).iter().all(|&v| v == 0.0));
                assert!(k.rows(nd, MAX_DOFS - nd).iter().all(|&v| v == 0.0));
                // element_stiffness (row-major) is the same tangent
                let mut ke = [0.0; MAX_DOFS * MAX_DOFS];
                element_stiffness(kind, &coords, &mat, THICKNESS, &rule, &mut ke);
                for i in 0..nd {
                    for j in 0..nd {
                        assert_eq!(ke[i * nd + j], k[(i, j)], "{kind:?} K[{i}][{j}]");
                    }
                }
                let h = 1e-6;
                let mut fd = ElementMatrix::zeros();
                for j in 0..nd {
                    let (mut up, mut um) = (u.clone(), u.clone());
                    up[j] += h;
                    um[j] -= h;
                    let column = (internal_force(kind, &mat, &up)
                        - internal_force(kind, &mat, &um))
                        / (2.0 * h);
                    fd.set_column(j, &column);
                    let scale = largest(k.column(j).iter().copied());
                    let err = largest((0..nd).map(|i| column[i] - k[(i, j)]));
                    assert!(
                        err < 1e-7 * scale,
                        "{kind:?} {:?}: column {j} of K_T differs from the central difference by {err:e} (scale {scale:e})",
                        mat.plane
                    );
                }
                // K_T is symmetric, and so is the difference quotient of f_int alone (f_int is
                // the gradient of an energy)
                let scale = largest(k.iter().copied());
                for i in 0..nd {
                    for j in 0..nd {
                        assert!((k[(i, j)] - k[(j, i)]).abs() <= 1e-14 * scale);
                        assert!((fd[(i, j)] - fd[(j, i)]).abs() < 1e-7 * scale);
                    }
                }
            }
        }
    }

    #[test]
    fn rigid_motions_have_no_internal_force() {
        for mat in materials() {
            for kind in KINDS {
                let coords = distorted(kind);
                let scale = {
                    let u = some_displacements(kind);
                    largest(internal_force(kind, &mat, &u).iter().copied()) / 0.01
                };
                // translation x, translation y, infinitesimal rotation u = a + w e_z x p
                for (a, w) in [([1.0, 0.0], 0.0), ([0.0, 1.0], 0.0), ([0.0, 0.0], 1.0)] {
                    let u: Vec<f64> = coords
                        .iter()
                        .flat_map(|&p| [a[0] - w * p[1], a[1] + w * p[0]])
                        .collect();
                    let f = internal_force(kind, &mat, &u);
                    let worst = largest(f.iter().copied());
                    assert!(
                        worst < 1e-12 * scale,
                        "{kind:?} {:?}: rigid motion {a:?}, {w} has internal force {worst:e}",
                        mat.plane
                    );
                }
            }
        }
    }

    /// `int_{boundary} N_a sigma n t ds` for a constant stress, edge by edge (the element's own
    /// isoparametric edges, outward normal = tangent turned clockwise).
    fn boundary_force(kind: ElementKind, coords: &[[f64; 2]], sigma: [f64; 3]) -> Vec<f64> {
        let [sxx, syy, sxy] = sigma;
        let edge = kind.edge_kind();
        let m = edge.node_count();
        let mut f = vec![0.0; 2 * kind.node_count()];
        for nodes in kind.edges() {
            for (s, w) in crate::fe::gauss_legendre(4) {
                let (mut n, mut dn) = ([0.0; 3], [0.0; 3]);
                edge.shape(s, &mut n[..m], &mut dn[..m]);
                let mut tangent = [0.0; 2];
                for (i, &a) in nodes.iter().enumerate() {
                    tangent[0] += dn[i] * coords[a][0];
                    tangent[1] += dn[i] * coords[a][1];
                }
                let normal = [tangent[1], -tangent[0]]; // n ds / dxi
                let traction = [
                    sxx * normal[0] + sxy * normal[1],
                    sxy * normal[0] + syy * normal[1],
                ];
                for (i, &a) in nodes.iter().enumerate() {
                    f[2 * a] += w * n[i] * traction[0] * THICKNESS;
                    f[2 * a + 1] += w * n[i] * traction[1] * THICKNESS;
                }
            }
        }
        f
    }

    #[test]
    fn a_linear_field_has_the_constant_stress_d_eps() {
        // u(x) = c + A x, A neither symmetric nor small: eps = [A_xx, A_yy, A_xy + A_yx]
        let c = [0.3, -0.2];
        let a = [[0.02, -0.05], [0.03, -0.01]];
        let eps = [a[0][0], a[1][1], a[0][1] + a[1][0]];
        for mat in materials() {
            let sigma = mat.stress(eps);
            // sigma = D eps written out, not through `stress`
            let (e, nu) = mat.plane_stress_equivalent();
            let g = e / (2.0 * (1.0 + nu));
            let expected = [
                e / (1.0 - nu * nu) * (eps[0] + nu * eps[1]),
                e / (1.0 - nu * nu) * (eps[1] + nu * eps[0]),
                g * eps[2],
            ];
            for i in 0..3 {
                assert!((sigma[i] - expected[i]).abs() < 1e-12 * largest(expected));
            }
            for kind in KINDS {
                let coords = distorted(kind);
                let u: Vec<f64> = coords
                    .iter()
                    .flat_map(|p| {
                        [
                            c[0] + a[0][0] * p[0] + a[0][1] * p[1],
                            c[1] + a[1][0] * p[0] + a[1][1] * p[1],
                        ]
                    })
                    .collect();
                // the kernel's strain at every quadrature point is eps
                let rule = kind.stiffness_rule();
                with_sizes!(kind, |N, ND| {
                    let um = SMatrix::<f64, 2, N>::from_column_slice(&u[..ND]);
                    let x = nodes::<N>(&coords);
                    for p in rule.iter().filter_map(|q| point(kind, &x, q, THICKNESS)) {
                        let got = small_strain_at(&p, &um);
                        for i in 0..3 {
                            assert!((got[i] - eps[i]).abs() < 1e-13, "{kind:?}: {got:?}");
                        }
                    }
                });
                // and f_int is the boundary integral of the constant traction sigma n
                let f = internal_force(kind, &mat, &u);
                let expected = boundary_force(kind, &coords, sigma);
                let scale = largest(expected.iter().copied());
                assert!(scale > 0.0);
                for (i, want) in expected.iter().enumerate() {
                    assert!(
                        (f[i] - want).abs() < 1e-12 * scale,
                        "{kind:?} {:?}: f_int[{i}] = {} but the traction gives {want}",
                        mat.plane,
                        f[i]
                    );
                }
            }
        }
    }

    #[test]
    fn strain_of_stress_inverts_d() {
        for plane in [Plane::Strain, Plane::Stress] {
            let mat = Elasticity::new(210.0, 0.27, plane);
            let s = [3.0, -7.0, 1.5];
            let back = mat.stress(mat.strain_of_stress(s));
            for i in 0..3 {
                assert!((back[i] - s[i]).abs() < 1e-12);
            }
        }
    }
}

/// The quadrature rule of [`element_mass`]: exact for `N_a N_b det J` on straight-sided
/// (affine) elements and for `N_a N_b` on distorted Q4 up to the bilinear `det J`.
fn mass_rule(kind: ElementKind) -> Vec<QuadPoint> {
    match kind {
        ElementKind::Q4 => crate::fe::gauss_square(3),
        ElementKind::Q9 => crate::fe::gauss_square(4),
        ElementKind::T3 => crate::fe::triangle_rule(2),
        ElementKind::T6 => crate::fe::triangle_rule(5),
    }
}

/// Consistent mass of one element per displacement component: `M_ab = int rho N_a N_b t dA`
/// (`n x n`, row-major into `me`); the element's `2 n x 2 n` mass is `M_ab I_2`.
pub fn element_mass(
    kind: ElementKind,
    coords: &[[f64; 2]],
    density: f64,
    thickness: f64,
    me: &mut [f64],
) {
    let n = kind.node_count();
    let me = &mut me[..n * n];
    me.fill(0.0);
    for q in mass_rule(kind) {
        let pv = kind.point_values(coords, q.xi);
        let w = q.weight * pv.det_j * density * thickness;
        for a in 0..n {
            for b in 0..n {
                me[a * n + b] += w * pv.n[a] * pv.n[b];
            }
        }
    }
}

/// Lumped (HRZ) mass of one element per displacement component, from its consistent mass
/// `me` (`n x n`): `m_a = M_aa (sum_ab M_ab) / (sum_b M_bb)`.
pub fn lumped_mass(me: &[f64], n: usize) -> Vec<f64> {
    let total: f64 = me[..n * n].iter().sum();
    let diagonal: f64 = (0..n).map(|a| me[a * n + a]).sum();
    (0..n).map(|a| me[a * n + a] * total / diagonal).collect()
}

#[cfg(test)]
mod mass_tests {
    use super::*;

    fn total(kind: ElementKind, coords: &[[f64; 2]]) -> (f64, Vec<f64>) {
        let n = kind.node_count();
        let mut me = vec![0.0; n * n];
        element_mass(kind, coords, 7.5, 0.5, &mut me);
        (me.iter().sum(), lumped_mass(&me, n))
    }

    /// The consistent and the lumped mass of every element sum to `rho t A`, and the lumped
    /// masses are positive (a distorted Q4 of area 1.25, a T6 of area 1/2, Q9 and T3).
    #[test]
    fn element_masses_sum_to_the_element_mass_and_lumped_masses_are_positive() {
        let q4 = [[0.0, 0.0], [1.0, 0.0], [1.5, 1.0], [0.0, 1.0]];
        let q9 = [
            [0.0, 0.0],
            [2.0, 0.0],
            [2.0, 1.0],
            [0.0, 1.0],
            [1.0, 0.0],
            [2.0, 0.5],
            [1.0, 1.0],
            [0.0, 0.5],
            [1.0, 0.5],
        ];
        let t3 = [[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]];
        let t6 = [
            [0.0, 0.0],
            [1.0, 0.0],
            [0.0, 1.0],
            [0.5, 0.0],
            [0.5, 0.5],
            [0.0, 0.5],
        ];
        let cases: [(ElementKind, &[[f64; 2]], f64); 4] = [
            (ElementKind::Q4, &q4, 1.25),
            (ElementKind::Q9, &q9, 2.0),
            (ElementKind::T3, &t3, 0.5),
            (ElementKind::T6, &t6, 0.5),
        ];
        for (kind, coords, area) in cases {
            let exact = 7.5 * 0.5 * area;
            let (sum, lumped) = total(kind, coords);
            assert!(
                (sum - exact).abs() < 1e-14 * exact,
                "{kind:?}: {sum} vs {exact}"
            );
            let l: f64 = lumped.iter().sum();
            assert!(
                (l - exact).abs() < 1e-14 * exact,
                "{kind:?}: {l} vs {exact}"
            );
            assert!(lumped.iter().all(|&m| m > 0.0), "{kind:?}: {lumped:?}");
        }
        // T3: the closed form M = rho t A / 12 [[2, 1, 1], [1, 2, 1], [1, 1, 2]]
        let mut me = [0.0; 9];
        element_mass(ElementKind::T3, &t3, 12.0, 1.0, &mut me);
        for a in 0..3 {
            for b in 0..3 {
                let exact = 0.5 * if a == b { 2.0 } else { 1.0 };
                assert!((me[a * 3 + b] - exact).abs() < 1e-15, "{me:?}");
            }
        }
    }
}
