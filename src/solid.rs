//! Small-strain isotropic linear elasticity in `D = 2` (plane strain, plane stress, with a
//! thickness) and `D = 3`, written once for both: constitutive matrix, element stiffness,
//! internal force and strain; the 2D element mass; consistent loads on solid cells.
//!
//! **Voigt notation** ([`Voigt`]) with engineering shears: the strain of the displacement
//! gradient `H = du/dx` is `eps_p = H_ii` for a normal component `p = (i, i)` and
//! `eps_p = H_ij + H_ji` for a shear `p = (i, j)`, in the order
//! `[xx, yy, xy]` (2D) and `[xx, yy, zz, yz, xz, xy]` (3D); `sigma = D eps` in the same order.
//! With Lamé's `lambda = E nu / ((1 + nu)(1 - 2 nu))`, `mu = E / (2 (1 + nu))`:
//!
//! * 3D: `D = lambda m m^T + mu diag(2, 2, 2, 1, 1, 1)`, `m = [1, 1, 1, 0, 0, 0]` (e.g.
//!   Hughes, *The Finite Element Method*, 2000, section 2.7);
//! * plane strain: the in-plane block of the 3D `D`,
//!   `D = [[l+2m, l, 0], [l, l+2m, 0], [0, 0, m]]`, with the out-of-plane stress
//!   `sigma_zz = nu (sigma_xx + sigma_yy)`;
//! * plane stress: `D = E/(1-nu^2) [[1, nu, 0], [nu, 1, 0], [0, 0, (1-nu)/2]]`, `sigma_zz = 0`.
//!
//! **Residual and tangent.** An element contributes, at its current displacements `u_e`, the
//! internal force and its derivative
//! `f_int(u_e) = int B^T sigma(u_e) t dV` and `K_T = d f_int / d u_e = int B^T D B t dV`
//! (`t` the thickness in 2D, 1 in 3D), each integral evaluated with the element's stiffness
//! rule ([`crate::fe`], [`crate::fe3d`]): `sum_q w_q det J t (...)` at the quadrature points.
//! `B_a` is the `V x D` operator `eps = sum_a B_a u_a` (`V = D (D + 1) / 2`): for a normal
//! component `p = (i, i)` its row is `N_a,i` in column `i`; for a shear `p = (i, j)` it is
//! `N_a,j` in column `i` and `N_a,i` in column `j`, e.g. in 2D
//! `B_a = [[N_a,x, 0], [0, N_a,y], [N_a,y, N_a,x]]`. Equilibrium is `f_int(u) = f_ext`
//! (+ contact forces). With small strain `sigma = D eps` is linear in `u_e`, so
//! `f_int = K_e u_e`; the kernel still integrates `f_int` from the stresses (with the strain
//! from `H`), the form that finite strain keeps. Finite deformation (`physics.kinematics:
//! "finite"`) has its own kernels, [`crate::solid_finite`], with a hyperelastic law in place of
//! [`Elasticity`].
//!
//! **Implementation.** `K_e` is accumulated in `D x D` node blocks
//! `K_ab += w B_a^T (D B_b)` with `B`'s zeros skipped (each entry of `D B_b` and of
//! `B_a^T (D B_b)` a sum over the Voigt components where `B` is not zero, in ascending order),
//! every block computed (the lower ones too) and written straight into the caller's row-major
//! slice; no heap allocation. The order of operations is that of the 2D array kernel these
//! replaced, so that `K_e` is the same to the last bit: the assembly reads the upper triangle in
//! global numbering, which takes local `(a, b)` or `(b, a)` blocks depending on the mesh, and
//! mirroring the upper local blocks instead changes the iteration counts of round-off sensitive
//! cells of the patch table. The material's `D` is stored as a `6 x 6` matrix whose leading
//! `V x V` block is used. Global vectors and matrices (assembly, factorization) stay in
//! `solve`/`sparse` (faer).
//!
//! **Mass** (2D, for dynamics, [`crate::solver::dynamics`]). An element gives its consistent
//! mass `M_e = int rho N^T N t dA` ([`element_mass`], both components alike, with a rule exact
//! for `N_a N_b` on straight-sided elements) and its lumped mass by the HRZ scaling of the
//! consistent diagonal (Hinton, Rock & Zienkiewicz, Earthquake Eng. Struct. Dyn. 4 (1976)
//! 245-249): `m_a = M_aa m / sum_b M_bb`, `m` the element's mass, positive for every element
//! (row sums are zero or negative at the corners of T6 and Q9 would be wrong for T6).
//!
//! **Consistent loads** on solid cells (3D; 2D edge loads are [`crate::model`]'s): a body force
//! `b(x)` gives `f_a = int N_a b dV` ([`body_force_load`]); a traction `t(x)` on a facet gives
//! `f_a = int N_a t dA` with `dA = |x_s x x_t| ds dt` on the facet's 2D reference element
//! ([`facet_traction_load`]); both with rich rules (the cell's error rule; Gauss 5x5 or
//! Radon's 7-point rule on facets).

use crate::fe::{
    field_gradient, gauss_square, triangle_rule, ElementKind, PointGeometry, QuadPoint,
    ReferenceCell, MAX_NODES,
};
use crate::io::scene::Plane;
use nalgebra::{SMatrix, Vector3};

/// Largest number of element dofs in 2D.
pub const MAX_DOFS: usize = 2 * MAX_NODES;

/// A constitutive matrix in Voigt notation: the leading `V x V` block (`V` =
/// [`Voigt::SIZE`]) is the material's, the rest zero.
pub type VoigtMatrix = SMatrix<f64, 6, 6>;

/// Voigt notation in `D` dimensions (module docs): the tensor index pairs of the components.
pub struct Voigt<const D: usize>;

impl<const D: usize> Voigt<D> {
    /// The number of components, `D (D + 1) / 2`.
    pub const SIZE: usize = D * (D + 1) / 2;

    /// The index pairs `(i, j)`, `i <= j`, of the components: normal ones first, then the
    /// shears.
    pub const PAIRS: &'static [(usize, usize)] = match D {
        2 => &[(0, 0), (1, 1), (0, 1)],
        3 => &[(0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1)],
        _ => panic!("solids are 2D or 3D"),
    };

    /// The strain `eps_p = H_ii` (normal) or `H_ij + H_ji` (shear) of the displacement
    /// gradient `H` (`H_ij = du_i/dx_j`); `V` must be [`Voigt::SIZE`].
    pub fn strain<const V: usize>(h: &SMatrix<f64, D, D>) -> [f64; V] {
        const { assert!(V == D * (D + 1) / 2) };
        std::array::from_fn(|p| {
            let (i, j) = Self::PAIRS[p];
            if i == j {
                h[(i, i)]
            } else {
                h[(i, j)] + h[(j, i)]
            }
        })
    }

    /// The components `(t_ij + t_ji) / 2` of the symmetric part of the tensor `t` (`V` =
    /// [`Voigt::SIZE`]).
    pub fn symmetric_components<const V: usize>(t: &SMatrix<f64, D, D>) -> [f64; V] {
        const { assert!(V == D * (D + 1) / 2) };
        std::array::from_fn(|p| {
            let (i, j) = Self::PAIRS[p];
            0.5 * (t[(i, j)] + t[(j, i)])
        })
    }

    /// The components `p` (ascending) where column `c` of `B_a` is not zero, with the
    /// gradient component `k` that is there: `B_a[p][c] = N_a,k`.
    #[inline(always)]
    fn column_terms(c: usize) -> impl Iterator<Item = (usize, usize)> + Clone {
        Self::PAIRS
            .iter()
            .enumerate()
            .filter_map(move |(p, &(i, j))| match () {
                _ if i == c => Some((p, j)),
                _ if j == c => Some((p, i)),
                _ => None,
            })
    }

    /// The isotropic `D` of Lamé's `lambda`, `mu`: `lambda + 2 mu` on the normal diagonal,
    /// `lambda` off it, `mu` on the shear diagonal (plane strain in 2D).
    pub fn isotropic(lambda: f64, mu: f64) -> VoigtMatrix {
        let mut d = VoigtMatrix::zeros();
        for (p, &(i, j)) in Self::PAIRS.iter().enumerate() {
            for (q, &(k, l)) in Self::PAIRS.iter().enumerate() {
                d[(p, q)] = match (i == j, k == l) {
                    (true, true) if p == q => lambda + 2.0 * mu,
                    (true, true) => lambda,
                    (false, false) if p == q => mu,
                    _ => 0.0,
                };
            }
        }
        d
    }
}

/// An isotropic linear elastic material in `D` dimensions (plane strain or plane stress in
/// 2D).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Elasticity<const D: usize = 2> {
    pub youngs_modulus: f64,
    pub nu: f64,
    /// The 2D reduction; `None` in 3D.
    plane: Option<Plane>,
    /// The constitutive matrix `D` (`sigma = D eps`, Voigt order of [`Voigt`]).
    pub d: VoigtMatrix,
}

/// Lamé's `(lambda, mu)` of Young's modulus `E` and Poisson's ratio `nu`.
pub fn lame(youngs_modulus: f64, nu: f64) -> (f64, f64) {
    (
        youngs_modulus * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
        youngs_modulus / (2.0 * (1.0 + nu)),
    )
}

impl Elasticity<2> {
    /// The 2D material of a plane-strain or plane-stress section.
    pub fn new(youngs_modulus: f64, nu: f64, plane: Plane) -> Self {
        let d = match plane {
            Plane::Strain => {
                let (lambda, mu) = lame(youngs_modulus, nu);
                Voigt::<2>::isotropic(lambda, mu)
            }
            Plane::Stress => {
                let c = youngs_modulus / (1.0 - nu * nu);
                let mut d = VoigtMatrix::zeros();
                d[(0, 0)] = c;
                d[(0, 1)] = c * nu;
                d[(1, 0)] = c * nu;
                d[(1, 1)] = c;
                d[(2, 2)] = c * 0.5 * (1.0 - nu);
                d
            }
        };
        Elasticity {
            youngs_modulus,
            nu,
            plane: Some(plane),
            d,
        }
    }

    /// Plane strain or plane stress.
    pub fn plane(&self) -> Plane {
        self.plane.expect("a 2D material has its plane")
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

    /// The out-of-plane stress of the in-plane stress `s`.
    pub fn sigma_zz(&self, s: [f64; 3]) -> f64 {
        match self.plane() {
            Plane::Strain => self.nu * (s[0] + s[1]),
            Plane::Stress => 0.0,
        }
    }

    /// Young's modulus and Poisson ratio of the equivalent plane-stress problem (for formulas
    /// written in plane stress).
    pub fn plane_stress_equivalent(&self) -> (f64, f64) {
        match self.plane() {
            Plane::Stress => (self.youngs_modulus, self.nu),
            Plane::Strain => (
                self.youngs_modulus / (1.0 - self.nu * self.nu),
                self.nu / (1.0 - self.nu),
            ),
        }
    }
}

impl Elasticity<3> {
    /// The 3D material of a solid body.
    pub fn solid(youngs_modulus: f64, nu: f64) -> Self {
        let (lambda, mu) = lame(youngs_modulus, nu);
        Elasticity {
            youngs_modulus,
            nu,
            plane: None,
            d: Voigt::<3>::isotropic(lambda, mu),
        }
    }
}

impl<const D: usize> Elasticity<D> {
    /// `sigma = D eps` (Voigt, `V` = [`Voigt::SIZE`]).
    pub fn stress<const V: usize>(&self, strain: [f64; V]) -> [f64; V] {
        const { assert!(V == D * (D + 1) / 2) };
        std::array::from_fn(|p| {
            (1..V).fold(self.d[(p, 0)] * strain[0], |s, q| {
                s + self.d[(p, q)] * strain[q]
            })
        })
    }

    /// Lamé's second parameter (the shear modulus).
    pub fn mu(&self) -> f64 {
        lame(self.youngs_modulus, self.nu).1
    }

    /// Lamé's first parameter (of the 3D law, also in plane stress).
    pub fn lambda(&self) -> f64 {
        lame(self.youngs_modulus, self.nu).0
    }
}

/// Adds `w B^T D B` at one point with gradients `dndx` to the row-major `D n x D n` matrix
/// `ke`, block by block: `K_ab += w B_a^T (D B_b)`, `B` applied through its structure.
#[inline(always)]
fn add_material_tangent<const D: usize>(
    ke: &mut [f64],
    dndx: &[[f64; D]],
    d: &VoigtMatrix,
    w: f64,
) {
    let voigt = Voigt::<D>::SIZE;
    let nd = D * dndx.len();
    for (b, gb) in dndx.iter().enumerate() {
        // D B_b, V x D
        let mut db = [[0.0; D]; 6];
        for c in 0..D {
            let mut terms = Voigt::<D>::column_terms(c);
            let (p0, k0) = terms.next().expect("every column of B has a term");
            for (r, row) in db.iter_mut().enumerate().take(voigt) {
                row[c] = terms
                    .clone()
                    .fold(d[(r, p0)] * gb[k0], |s, (p, k)| s + d[(r, p)] * gb[k]);
            }
        }
        for (a, ga) in dndx.iter().enumerate() {
            // B_a^T (D B_b)
            for i in 0..D {
                let mut terms = Voigt::<D>::column_terms(i);
                let (p0, k0) = terms.next().expect("every column of B has a term");
                for j in 0..D {
                    let kab = terms
                        .clone()
                        .fold(db[p0][j] * ga[k0], |s, (p, k)| s + db[p][j] * ga[k]);
                    ke[(D * a + i) * nd + D * b + j] += kab * w;
                }
            }
        }
    }
}

/// Adds `w B^T sigma` at one point to `f`, with `sigma = D eps(u)` and the strain from the
/// displacement gradient `H = sum_a u_a (dN_a/dx)^T`.
#[inline(always)]
fn add_internal_force<const D: usize>(
    f: &mut [f64],
    dndx: &[[f64; D]],
    d: &VoigtMatrix,
    u_e: &[f64],
    w: f64,
) {
    let voigt = Voigt::<D>::SIZE;
    let h = field_gradient(dndx, u_e);
    let mut eps = [0.0; 6];
    for (p, &(i, j)) in Voigt::<D>::PAIRS.iter().enumerate() {
        eps[p] = if i == j {
            h[(i, i)]
        } else {
            h[(i, j)] + h[(j, i)]
        };
    }
    let mut w_sigma = [0.0; 6];
    for (p, ws) in w_sigma.iter_mut().enumerate().take(voigt) {
        *ws = (1..voigt).fold(d[(p, 0)] * eps[0], |s, q| s + d[(p, q)] * eps[q]) * w;
    }
    for (a, g) in dndx.iter().enumerate() {
        for i in 0..D {
            let mut terms = Voigt::<D>::column_terms(i);
            let (p0, k0) = terms.next().expect("every column of B has a term");
            f[D * a + i] += terms.fold(g[k0] * w_sigma[p0], |s, (p, k)| s + g[k] * w_sigma[p]);
        }
    }
}

/// Calls `visit(dndx, w)` at every point of `rule` with `det J != 0` (a point with `det J = 0`
/// contributes nothing; the model refuses such elements): the gradients `dN_a/dx` of the
/// cell's nodes and the weight `w = w_q det J t`.
#[inline(always)]
fn for_each_point<const D: usize, C: ReferenceCell<D>>(
    kind: C,
    coords: &[[f64; D]],
    thickness: f64,
    rule: &[QuadPoint<D>],
    mut visit: impl FnMut(&[[f64; D]], f64),
) {
    let n = kind.node_count();
    for q in rule {
        let pv = kind.point_values(coords, q.xi);
        let det_j = pv.jacobian_determinant();
        if det_j == 0.0 {
            continue;
        }
        visit(&pv.gradients()[..n], q.weight * det_j * thickness);
    }
}

/// Element stiffness `K_e = int B^T D B t dV` (row-major, `D n x D n`, dof order
/// `[u_x0, u_y0, (u_z0,) u_x1, ...]`) with the rule `rule`; `thickness` is 1 in 3D.
pub fn element_stiffness<const D: usize, C: ReferenceCell<D>>(
    kind: C,
    coords: &[[f64; D]],
    material: &Elasticity<D>,
    thickness: f64,
    rule: &[QuadPoint<D>],
    ke: &mut [f64],
) {
    let nd = D * kind.node_count();
    let ke = &mut ke[..nd * nd];
    ke.fill(0.0);
    for_each_point(kind, coords, thickness, rule, |dndx, w| {
        add_material_tangent(ke, dndx, &material.d, w)
    });
}

/// Internal force `f_int(u_e) = int B^T D eps(u_e) t dV` (`= K_e u_e`) of one element at the
/// element displacements `u_e` (`D n` values), written to `f[..D n]`.
pub fn element_internal_force<const D: usize, C: ReferenceCell<D>>(
    kind: C,
    coords: &[[f64; D]],
    u_e: &[f64],
    material: &Elasticity<D>,
    thickness: f64,
    rule: &[QuadPoint<D>],
    f: &mut [f64],
) {
    let f = &mut f[..D * kind.node_count()];
    f.fill(0.0);
    for_each_point(kind, coords, thickness, rule, |dndx, w| {
        add_internal_force(f, dndx, &material.d, u_e, w)
    });
}

/// Voigt strain `eps = sum_a B_a u_a` of the element displacements `u_e` at the natural point
/// `xi`, with the point (`V` = [`Voigt::SIZE`]).
pub fn strain_at<const D: usize, const V: usize, C: ReferenceCell<D>>(
    kind: C,
    coords: &[[f64; D]],
    u_e: &[f64],
    xi: [f64; D],
) -> ([f64; V], [f64; D]) {
    const { assert!(V == D * (D + 1) / 2) };
    let pv = kind.point_values(coords, xi);
    let mut eps = [0.0; V];
    for (a, g) in pv.gradients()[..kind.node_count()].iter().enumerate() {
        let u = &u_e[D * a..D * a + D];
        for (e, &(i, j)) in eps.iter_mut().zip(Voigt::<D>::PAIRS) {
            *e += if i == j {
                g[i] * u[i]
            } else {
                g[j] * u[i] + g[i] * u[j]
            };
        }
    }
    (eps, pv.point())
}

/// Consistent nodal forces `f_a = int N_a b(x) dV` of a body force on one cell, with the rule
/// `rule` (a rich one: the cell's error rule).
pub fn body_force_load<const D: usize, C: ReferenceCell<D>>(
    kind: C,
    coords: &[[f64; D]],
    rule: &[QuadPoint<D>],
    body_force: &dyn Fn([f64; D]) -> [f64; D],
) -> Vec<f64> {
    let nn = kind.node_count();
    let mut f = vec![0.0; D * nn];
    for q in rule {
        let pv = kind.point_values(coords, q.xi);
        let b = body_force(pv.point());
        let w = q.weight * pv.jacobian_determinant();
        for a in 0..nn {
            for i in 0..D {
                f[D * a + i] += w * pv.values()[a] * b[i];
            }
        }
    }
    f
}

/// A rich rule on a facet's 2D reference element.
fn facet_rule(facet: ElementKind) -> Vec<QuadPoint> {
    match facet {
        ElementKind::Q4 | ElementKind::Q9 => gauss_square(5),
        ElementKind::T3 | ElementKind::T6 => triangle_rule(5),
    }
}

/// Consistent nodal forces `f_a = int N_a t(x, n) dA` of a traction on one facet of a solid
/// cell, whose nodes `coords` are in facet order ([`ReferenceCell::facets`]); `traction` gets
/// the point and the outward unit normal (so a pressure `p` is `|_, n| -p n`).
pub fn facet_traction_load(
    facet: ElementKind,
    coords: &[[f64; 3]],
    traction: &dyn Fn([f64; 3], [f64; 3]) -> [f64; 3],
) -> Vec<f64> {
    let nn = facet.node_count();
    let mut f = vec![0.0; 3 * nn];
    let mut n = [0.0; 9];
    let mut dn = [[0.0; 2]; 9];
    for q in facet_rule(facet) {
        facet.shape(q.xi, &mut n[..nn], &mut dn[..nn]);
        let mut x = Vector3::zeros();
        let (mut ts, mut tt) = (Vector3::zeros(), Vector3::zeros());
        for a in 0..nn {
            let p = Vector3::from(coords[a]);
            x += p * n[a];
            ts += p * dn[a][0];
            tt += p * dn[a][1];
        }
        let normal_area = ts.cross(&tt);
        let area = normal_area.dot(&normal_area).sqrt();
        if area == 0.0 {
            continue;
        }
        let unit = normal_area / area;
        let t = traction([x[0], x[1], x[2]], [unit[0], unit[1], unit[2]]);
        for a in 0..nn {
            for i in 0..3 {
                f[3 * a + i] += q.weight * area * n[a] * t[i];
            }
        }
    }
    f
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fe3d::SolidKind;
    use nalgebra::SVector;

    const PLANE_KINDS: [ElementKind; 4] = [
        ElementKind::Q4,
        ElementKind::Q9,
        ElementKind::T3,
        ElementKind::T6,
    ];
    const THICKNESS: f64 = 0.7;

    /// The reference element's nodes through a smooth, orientation-preserving map.
    fn distorted_plane(kind: ElementKind) -> Vec<[f64; 2]> {
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

    /// The reference cell's nodes under a fixed non-affine distortion (positive volume).
    fn distorted_solid(kind: SolidKind) -> Vec<[f64; 3]> {
        kind.node_coordinates()
            .iter()
            .map(|p| {
                let [x, y, z] = *p;
                [
                    1.1 * x + 0.1 * y + 0.03 * y * z,
                    0.9 * y - 0.05 * x + 0.04 * x * z,
                    1.2 * z + 0.02 * x * y + 0.05 * x,
                ]
            })
            .collect()
    }

    fn plane_materials() -> [Elasticity; 2] {
        [
            Elasticity::new(1000.0, 0.3, Plane::Strain),
            Elasticity::new(1000.0, 0.3, Plane::Stress),
        ]
    }

    fn solid_material() -> Elasticity<3> {
        Elasticity::solid(210.0, 0.3)
    }

    fn largest(v: impl IntoIterator<Item = f64>) -> f64 {
        v.into_iter().fold(0.0, |m, x| m.max(x.abs()))
    }

    /// The cases of every test below: each element kind (2D with both materials and a
    /// thickness, 3D with thickness 1) with its distorted nodes.
    fn for_each_case(
        mut plane: impl FnMut(ElementKind, &[[f64; 2]], &Elasticity, f64),
        mut solid: impl FnMut(SolidKind, &[[f64; 3]], &Elasticity<3>, f64),
    ) {
        for mat in plane_materials() {
            for kind in PLANE_KINDS {
                plane(kind, &distorted_plane(kind), &mat, THICKNESS);
            }
        }
        for kind in SolidKind::ALL {
            solid(kind, &distorted_solid(kind), &solid_material(), 1.0);
        }
    }

    fn stiffness<const D: usize, C: ReferenceCell<D>>(
        kind: C,
        coords: &[[f64; D]],
        mat: &Elasticity<D>,
        thickness: f64,
        rule: &[QuadPoint<D>],
    ) -> Vec<f64> {
        let nd = D * kind.node_count();
        let mut ke = vec![0.0; nd * nd];
        element_stiffness(kind, coords, mat, thickness, rule, &mut ke);
        ke
    }

    fn internal_force<const D: usize, C: ReferenceCell<D>>(
        kind: C,
        coords: &[[f64; D]],
        u: &[f64],
        mat: &Elasticity<D>,
        thickness: f64,
        rule: &[QuadPoint<D>],
    ) -> Vec<f64> {
        let mut f = vec![0.0; D * kind.node_count()];
        element_internal_force(kind, coords, u, mat, thickness, rule, &mut f);
        f
    }

    /// The rigid motions of the nodes `coords`: `D` translations and the `D (D - 1) / 2`
    /// infinitesimal rotations `u_i = -x_j, u_j = x_i` in each plane `(i, j)`.
    fn rigid_motions<const D: usize>(coords: &[[f64; D]]) -> Vec<Vec<f64>> {
        let mut modes = Vec::new();
        for axis in 0..D {
            modes.push(
                coords
                    .iter()
                    .flat_map(|_| (0..D).map(move |i| if i == axis { 1.0 } else { 0.0 }))
                    .collect(),
            );
        }
        for i in 0..D {
            for j in i + 1..D {
                let mut u = vec![0.0; D * coords.len()];
                for (a, p) in coords.iter().enumerate() {
                    u[D * a + i] = -p[j];
                    u[D * a + j] = p[i];
                }
                modes.push(u);
            }
        }
        modes
    }

    /// The rank of the row-major `nd x nd` matrix `a` by Gaussian elimination with full
    /// pivoting, pivots below `1e-9` of the largest entry counting as zero.
    fn rank(mut a: Vec<f64>, nd: usize) -> usize {
        let largest = largest(a.iter().copied());
        let mut rank = 0;
        let (mut used_r, mut used_c) = (vec![false; nd], vec![false; nd]);
        loop {
            let mut best = (0.0, 0, 0);
            for r in (0..nd).filter(|&r| !used_r[r]) {
                for c in (0..nd).filter(|&c| !used_c[c]) {
                    if a[r * nd + c].abs() > best.0 {
                        best = (a[r * nd + c].abs(), r, c);
                    }
                }
            }
            if best.0 <= 1e-9 * largest {
                return rank;
            }
            let (_, pr, pc) = best;
            used_r[pr] = true;
            used_c[pc] = true;
            rank += 1;
            for r in (0..nd).filter(|&r| !used_r[r]) {
                let factor = a[r * nd + pc] / a[pr * nd + pc];
                for c in 0..nd {
                    a[r * nd + c] -= factor * a[pr * nd + c];
                }
            }
        }
    }

    /// `K_e` is symmetric, the rigid motions give no internal force, there are no others
    /// (rank `D n - D (D + 1) / 2`), and a uniform strain has positive energy.
    fn check_stiffness<const D: usize, C: ReferenceCell<D>>(
        kind: C,
        coords: &[[f64; D]],
        mat: &Elasticity<D>,
        thickness: f64,
        rule: &[QuadPoint<D>],
    ) {
        let nd = D * kind.node_count();
        let ke = stiffness(kind, coords, mat, thickness, rule);
        let scale = largest(ke.iter().copied());
        for i in 0..nd {
            for j in 0..nd {
                assert!((ke[i * nd + j] - ke[j * nd + i]).abs() <= 1e-13 * scale);
            }
        }
        let modes = rigid_motions(coords);
        for u in &modes {
            let f = internal_force(kind, coords, u, mat, thickness, rule);
            for i in 0..nd {
                let ku: f64 = (0..nd).map(|j| ke[i * nd + j] * u[j]).sum();
                assert!(ku.abs() < 1e-11 * scale, "{kind:?}: rigid mode K u = {ku}");
                assert!(
                    f[i].abs() < 1e-11 * scale,
                    "{kind:?}: rigid mode f = {}",
                    f[i]
                );
            }
        }
        assert_eq!(
            rank(ke.clone(), nd),
            nd - modes.len(),
            "{kind:?}: rank of K_e"
        );
        let u: Vec<f64> = coords
            .iter()
            .flat_map(|p| (0..D).map(move |i| 0.01 * (i as f64 - 0.5) * p[i]))
            .collect();
        let energy: f64 = (0..nd)
            .map(|i| u[i] * (0..nd).map(|j| ke[i * nd + j] * u[j]).sum::<f64>())
            .sum();
        assert!(energy > 0.0, "{kind:?}");
    }

    #[test]
    fn stiffness_is_symmetric_with_only_the_rigid_modes_at_zero_energy() {
        for_each_case(
            |kind, coords, mat, t| check_stiffness(kind, coords, mat, t, &kind.stiffness_rule()),
            |kind, coords, mat, t| check_stiffness(kind, coords, mat, t, &kind.stiffness_rule()),
        );
    }

    /// `f_int = K_e u_e` and every column of `K_e` is the central difference of `f_int`
    /// (1e-7 of the largest entry).
    fn check_tangent<const D: usize, C: ReferenceCell<D>>(
        kind: C,
        coords: &[[f64; D]],
        mat: &Elasticity<D>,
        thickness: f64,
        rule: &[QuadPoint<D>],
    ) {
        let nd = D * kind.node_count();
        let ke = stiffness(kind, coords, mat, thickness, rule);
        let scale = largest(ke.iter().copied());
        let u: Vec<f64> = (0..nd)
            .map(|i| 0.01 * (1.7 * i as f64 + 0.3).sin())
            .collect();
        let f = internal_force(kind, coords, &u, mat, thickness, rule);
        for i in 0..nd {
            let ku: f64 = (0..nd).map(|j| ke[i * nd + j] * u[j]).sum();
            assert!((f[i] - ku).abs() <= 1e-12 * scale, "{kind:?}: f_int != K u");
        }
        let h = 1e-6;
        for j in 0..nd {
            let (mut up, mut um) = (u.clone(), u.clone());
            up[j] += h;
            um[j] -= h;
            let fp = internal_force(kind, coords, &up, mat, thickness, rule);
            let fm = internal_force(kind, coords, &um, mat, thickness, rule);
            for i in 0..nd {
                let fd = (fp[i] - fm[i]) / (2.0 * h);
                assert!(
                    (fd - ke[i * nd + j]).abs() < 1e-7 * scale,
                    "{kind:?}: dF_{i}/du_{j}: {fd} vs {}",
                    ke[i * nd + j]
                );
            }
        }
    }

    #[test]
    fn tangent_is_the_central_difference_of_the_internal_force() {
        for_each_case(
            |kind, coords, mat, t| check_tangent(kind, coords, mat, t, &kind.stiffness_rule()),
            |kind, coords, mat, t| check_tangent(kind, coords, mat, t, &kind.stiffness_rule()),
        );
    }

    /// `u(x) = c + A x` has the strain of `A` at every point (`strain_at` and the kernel's
    /// `H`).
    fn check_linear_field<const D: usize, const V: usize, C: ReferenceCell<D>>(
        kind: C,
        coords: &[[f64; D]],
        a: &SMatrix<f64, D, D>,
    ) {
        let expected: [f64; V] = Voigt::<D>::strain(a);
        let u: Vec<f64> = coords
            .iter()
            .flat_map(|p| {
                let x = SVector::<f64, D>::from(*p);
                let v = a * x;
                (0..D).map(move |i| 0.3 - 0.1 * i as f64 + v[i])
            })
            .collect();
        for &xi in kind.node_coordinates() {
            let (eps, _) = strain_at::<D, V, C>(kind, coords, &u, xi);
            let h = crate::fe::displacement_gradient_at(kind, coords, &u, xi).0;
            let from_h: [f64; V] = Voigt::<D>::strain(&h);
            for p in 0..V {
                assert!((eps[p] - expected[p]).abs() < 1e-13, "{kind:?} eps_{p}");
                assert!((from_h[p] - expected[p]).abs() < 1e-13, "{kind:?} eps_{p}");
            }
        }
    }

    #[test]
    fn a_linear_field_has_the_strain_of_its_gradient_and_the_stress_d_eps() {
        // A neither symmetric nor small
        let a2 = nalgebra::Matrix2::new(0.02, -0.05, 0.03, -0.01);
        for kind in PLANE_KINDS {
            check_linear_field::<2, 3, _>(kind, &distorted_plane(kind), &a2);
        }
        let a3 = nalgebra::Matrix3::new(1e-3, 2e-4, -3e-4, 5e-4, -2e-3, 1e-4, -4e-4, 3e-4, 1.5e-3);
        for kind in SolidKind::ALL {
            check_linear_field::<3, 6, _>(kind, &distorted_solid(kind), &a3);
        }
        // 2D: sigma = D eps written out
        let eps: [f64; 3] = Voigt::<2>::strain(&a2);
        for mat in plane_materials() {
            let sigma = mat.stress(eps);
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
        }
        // 3D uniaxial stress: eps = s/E [1, -nu, -nu, 0, 0, 0] gives sigma = [s, 0, 0, 0, 0, 0]
        let m = solid_material();
        let (s, e) = (3.0, m.youngs_modulus);
        let sigma = m.stress([s / e, -m.nu * s / e, -m.nu * s / e, 0.0, 0.0, 0.0]);
        assert!((sigma[0] - s).abs() < 1e-13);
        assert!(sigma[1..].iter().all(|v| v.abs() < 1e-13));
        // pure shear: sigma_xy = mu gamma_xy
        let sigma = m.stress([0.0, 0.0, 0.0, 0.0, 0.0, 2e-3]);
        assert!((sigma[5] - m.mu() * 2e-3).abs() < 1e-15);
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

    /// In 2D the internal force of a linear field is the boundary integral of its constant
    /// traction `sigma n` (in 3D the finite-strain kernels check the same with
    /// [`facet_traction_load`]).
    #[test]
    fn a_linear_field_has_the_internal_force_of_its_boundary_traction() {
        let a = [[0.02, -0.05], [0.03, -0.01]];
        let eps = [a[0][0], a[1][1], a[0][1] + a[1][0]];
        for mat in plane_materials() {
            let sigma = mat.stress(eps);
            for kind in PLANE_KINDS {
                let coords = distorted_plane(kind);
                let u: Vec<f64> = coords
                    .iter()
                    .flat_map(|p| {
                        [
                            0.3 + a[0][0] * p[0] + a[0][1] * p[1],
                            -0.2 + a[1][0] * p[0] + a[1][1] * p[1],
                        ]
                    })
                    .collect();
                let rule = kind.stiffness_rule();
                let f = internal_force(kind, &coords, &u, &mat, THICKNESS, &rule);
                let expected = boundary_force(kind, &coords, sigma);
                let scale = largest(expected.iter().copied());
                assert!(scale > 0.0);
                for (i, want) in expected.iter().enumerate() {
                    assert!(
                        (f[i] - want).abs() < 1e-12 * scale,
                        "{kind:?} {:?}: f_int[{i}] = {} but the traction gives {want}",
                        mat.plane(),
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

    #[test]
    fn consistent_loads_integrate_to_the_total_force() {
        // a unit cube element: a traction t on a face sums to t (area 1); a body force b to b
        for kind in SolidKind::ALL {
            let coords: Vec<[f64; 3]> = kind
                .node_coordinates()
                .iter()
                .map(|p| {
                    if kind.is_hexahedron() {
                        p.map(|x| 0.5 * (x + 1.0))
                    } else {
                        *p
                    }
                })
                .collect();
            let volume = if kind.is_hexahedron() { 1.0 } else { 1.0 / 6.0 };
            let f = body_force_load(kind, &coords, &kind.error_rule(), &|_| [1.0, -2.0, 3.0]);
            for (i, b) in [1.0, -2.0, 3.0].into_iter().enumerate() {
                let sum: f64 = f.iter().skip(i).step_by(3).sum();
                assert!((sum - b * volume).abs() < 1e-14, "{kind:?}");
            }
            for (k, local) in kind.facets().iter().enumerate() {
                let fc: Vec<[f64; 3]> = local.iter().map(|&a| coords[a]).collect();
                // a unit pressure: the force is minus the outward area vector
                let f = facet_traction_load(kind.facet_kind(), &fc, &|_, n| n.map(|v| -v));
                let total: Vec<f64> = (0..3)
                    .map(|i| f.iter().skip(i).step_by(3).sum::<f64>())
                    .collect();
                // the area vector of the facet from its corners (flat facets)
                let c: Vec<Vector3<f64>> = local
                    .iter()
                    .take(kind.facet_kind().corner_count())
                    .map(|&a| Vector3::from(coords[a]))
                    .collect();
                let area_vector = if c.len() == 4 {
                    (c[2] - c[0]).cross(&(c[3] - c[1])) * 0.5
                } else {
                    (c[1] - c[0]).cross(&(c[2] - c[0])) * 0.5
                };
                for i in 0..3 {
                    assert!(
                        (total[i] + area_vector[i]).abs() < 1e-14,
                        "{kind:?} facet {k}: {total:?} vs {area_vector:?}"
                    );
                }
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
