//! Finite-deformation (total-Lagrangian) solids in `D = 2` (plane strain, with a thickness)
//! and `D = 3`, written once for both: hyperelastic energy, element residual and consistent
//! tangent, Cauchy stress.
//!
//! **Kinematics.** With reference coordinates `X` and displacement `u`, the deformation
//! gradient is `F = I + H`, `H = du/dX = sum_a u_a (grad_0 N_a)^T`; in plane strain it is
//! extended by `F_33 = 1` (`F_13 = F_31 = F_23 = F_32 = 0`), so `C_33 = 1`, `E_33 = 0` and
//! `J = det F` is the in-plane determinant. The right Cauchy-Green tensor is `C = F^T F`, the
//! Green-Lagrange strain `E = (C - I) / 2` and `J = det F = 1 + I_1(H) + ... + I_D(H)` with the
//! principal invariants of `H` (2D: `tr H`, `det H`; 3D: `tr H`,
//! `I_2 = ((tr H)^2 - tr H^2) / 2`, `det H`). Both are computed from `H`
//! (`E = (H + H^T + H^T H) / 2`, `ln J = ln_1p(I_1 + ... + I_D)`), not from `F`, so that a
//! lightly loaded body keeps the round-off of small strain. The in-plane (2D) or full (3D)
//! tensors are `D x D` matrices; the dimension enters only through the invariants and the
//! inverse of `C` ([`principal_invariants`], `inverse`), and Voigt order is that of
//! [`crate::solid::Voigt`] (`11, 22, 12`; `11, 22, 33, 23, 13, 12`, engineering shears).
//!
//! **Materials** (Lamé constants from `E, nu`, [`crate::solid::lame`]), energy per reference
//! volume (Bonet & Wood, *Nonlinear Continuum Mechanics for Finite Element Analysis*, 2nd ed.,
//! sections 6.4.3 and 6.5, eqs. 6.28 and 6.40; plane strain as in their section 6.6):
//!
//! * compressible neo-Hookean, `W = mu/2 (I_C - 3 - 2 ln J) + lambda/2 (ln J)^2` with `I_C`
//!   the three-dimensional trace of `C` (`tr C + 1` in plane strain), so
//!   `S = 2 dW/dC = mu (I - C^-1) + lambda ln J C^-1` (evaluated as
//!   `C^-1 (2 mu E + lambda ln J I)`; in plane strain `S_33 = lambda ln J`) and
//!   `CC_IJKL = lambda C^-1_IJ C^-1_KL + (mu - lambda ln J)(C^-1_IK C^-1_JL + C^-1_IL C^-1_JK)`;
//! * St. Venant-Kirchhoff, `W = lambda/2 (tr E)^2 + mu E:E`, `S = lambda tr E I + 2 mu E`,
//!   `CC = lambda I (x) I + 2 mu II` (constant: the small-strain `D` of [`crate::solid`],
//!   plane strain in 2D), and in plane strain `S_33 = lambda tr E`.
//!
//! Both reduce to small-strain elasticity at `F = I` (same `D`), so the finite and small-strain
//! solutions agree to first order in the load.
//!
//! **Element** (Bonet & Wood chapter 9; Wriggers, *Nonlinear Finite Element Methods*,
//! section 4.2). At a quadrature point with weight `w = w_q det J_0 t` (reference
//! configuration; `t` the thickness in 2D, 1 in 3D) the internal force and the tangent are
//!
//! `f_a = sum_q w F S grad_0 N_a` (`= w B_a^T S_v`),
//! `K_ab = sum_q w [B_a^T D B_b + (grad_0 N_a . S grad_0 N_b) I_D]`,
//!
//! material plus geometric part, with `D_pq = CC_IJKL` (`p = (I, J)`, `q = (K, L)`) and the
//! nonlinear strain-displacement matrix `dE_v = B_a du_a` with rows
//! `B_a[(I, I), i] = F_iI N_a,I` and `B_a[(I, J), i] = F_iI N_a,J + F_iJ N_a,I` (`I != J`);
//! in 2D `B_a = [[F_11 N_a,1, F_21 N_a,1], [F_12 N_a,2, F_22 N_a,2],
//! [F_11 N_a,2 + F_12 N_a,1, F_21 N_a,2 + F_22 N_a,1]]`.
//! `f` is the gradient of the element energy `sum_q w W(C)` and `K` the gradient of `f`
//! (finite-difference checks below, for `D = 2` and `D = 3`). A quadrature point with `J <= 0`
//! (an inverted element) is refused ([`Inverted`]): the energy is not defined there (`ln J`).
//!
//! **Stress.** The Cauchy stress on the deformed configuration is `sigma = F S F^T / J`, in
//! plane strain with `sigma_33 = S_33 / J` ([`Hyperelastic::cauchy`]).
//!
//! **Arithmetic.** Every operation is the one of the former 2D-only and 3D-only kernels, in
//! their order, so that their numbers are kept to the last bit (`C^-1` is symmetrized before
//! it enters `D`, a no-op in 2D where the closed-form inverse of the symmetric `C` is exactly
//! symmetric).

use crate::fe::{
    displacement_gradient_at, field_gradient, PointGeometry, QuadPoint, ReferenceCell,
};
use crate::solid::{lame, Voigt, VoigtMatrix};
use nalgebra::{Matrix2, Matrix3, SMatrix, SVector};

/// The hyperelastic energy of a body under finite deformation.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Hyperelastic {
    /// `W = mu/2 (I_C - 3 - 2 ln J) + lambda/2 (ln J)^2`.
    NeoHookean { lambda: f64, mu: f64 },
    /// `W = lambda/2 (tr E)^2 + mu E:E`.
    SaintVenantKirchhoff { lambda: f64, mu: f64 },
}

/// Stress state of one deformation gradient: second Piola-Kirchhoff stress and the Voigt
/// tangent `D = dS/dE` (its leading `V x V` block, [`VoigtMatrix`]).
#[derive(Copy, Clone, Debug)]
pub struct MaterialPoint<const D: usize> {
    pub s: SMatrix<f64, D, D>,
    /// `S_33`: the out-of-plane stress in plane strain (`D = 2`), `s[(2, 2)]` in 3D.
    pub s33: f64,
    pub d: VoigtMatrix,
}

/// The principal invariants `I_1, ..., I_D` of `h`, with `det(I + h) = 1 + I_1 + ... + I_D`:
/// `tr h, det h` in 2D; `tr h, ((tr h)^2 - tr h^2) / 2, det h` in 3D.
pub fn principal_invariants<const D: usize>(h: &SMatrix<f64, D, D>) -> [f64; D] {
    let mut invariants = [0.0; D];
    invariants[0] = h.trace();
    match D {
        2 => invariants[1] = h[(0, 0)] * h[(1, 1)] - h[(0, 1)] * h[(1, 0)],
        3 => {
            invariants[1] = 0.5 * (h.trace().powi(2) - (h * h).trace());
            invariants[2] = Matrix3::from_fn(|i, j| h[(i, j)]).determinant();
        }
        _ => unreachable!("solids are 2D or 3D"),
    }
    invariants
}

/// `J = det F = 1 + I_1(H) + ... + I_D(H)`.
#[inline(always)]
pub fn jacobian<const D: usize>(h: &SMatrix<f64, D, D>) -> f64 {
    principal_invariants(h).iter().fold(1.0, |j, i| j + i)
}

/// The Green-Lagrange strain `E = (H + H^T + H^T H) / 2` and `ln J` (through `ln_1p`) from
/// the displacement gradient `H`, without the cancellation of `(F^T F - I) / 2` and
/// `ln det F` at small strain (which would put a round-off floor of `E eps` under the residual
/// of a lightly loaded body).
fn green_lagrange<const D: usize>(h: &SMatrix<f64, D, D>) -> (SMatrix<f64, D, D>, f64) {
    let e = (h + h.transpose() + h.transpose() * h) * 0.5;
    let invariants = principal_invariants(h);
    let ln_j = invariants[1..]
        .iter()
        .fold(invariants[0], |s, i| s + i)
        .ln_1p();
    (e, ln_j)
}

/// `m^-1` (`NaN` where `m` is singular): the adjugate over `det m` in 2D, LU in 3D.
fn inverse<const D: usize>(m: &SMatrix<f64, D, D>) -> SMatrix<f64, D, D> {
    match D {
        2 => {
            let det = m[(0, 0)] * m[(1, 1)] - m[(0, 1)] * m[(1, 0)];
            let inverse = Matrix2::new(m[(1, 1)], -m[(0, 1)], -m[(1, 0)], m[(0, 0)]) / det;
            SMatrix::from_fn(|i, j| inverse[(i, j)])
        }
        3 => {
            let inverse = Matrix3::from_fn(|i, j| m[(i, j)])
                .try_inverse()
                .unwrap_or_else(|| Matrix3::from_element(f64::NAN));
            SMatrix::from_fn(|i, j| inverse[(i, j)])
        }
        _ => unreachable!("solids are 2D or 3D"),
    }
}

impl Hyperelastic {
    pub fn neo_hookean(youngs_modulus: f64, nu: f64) -> Self {
        let (lambda, mu) = lame(youngs_modulus, nu);
        Hyperelastic::NeoHookean { lambda, mu }
    }

    pub fn saint_venant_kirchhoff(youngs_modulus: f64, nu: f64) -> Self {
        let (lambda, mu) = lame(youngs_modulus, nu);
        Hyperelastic::SaintVenantKirchhoff { lambda, mu }
    }

    /// Energy per reference volume at the displacement gradient `h = F - I` (`det F > 0`).
    pub fn energy<const D: usize>(&self, h: &SMatrix<f64, D, D>) -> f64 {
        let (e, ln_j) = green_lagrange(h);
        match *self {
            // I_C - 3 = 2 tr E
            Hyperelastic::NeoHookean { lambda, mu } => {
                mu * (e.trace() - ln_j) + 0.5 * lambda * ln_j * ln_j
            }
            Hyperelastic::SaintVenantKirchhoff { lambda, mu } => {
                0.5 * lambda * e.trace().powi(2) + mu * e.component_mul(&e).sum()
            }
        }
    }

    /// `S`, `S_33` and `D` at the displacement gradient `h = F - I` (`det F > 0`).
    pub fn material_point<const D: usize>(&self, h: &SMatrix<f64, D, D>) -> MaterialPoint<D> {
        let (e, ln_j) = green_lagrange(h);
        let identity = SMatrix::<f64, D, D>::identity();
        let (s, d, s33) = match *self {
            Hyperelastic::NeoHookean { lambda, mu } => {
                let ci = inverse(&(identity + e * 2.0));
                // mu (I - C^-1) + lambda ln J C^-1 = C^-1 (2 mu E + lambda ln J I), free of the
                // cancellation of I - C^-1 at small strain
                let s = ci * (e * (2.0 * mu) + identity * (lambda * ln_j));
                let s = (s + s.transpose()) * 0.5;
                let m = mu - lambda * ln_j;
                let ci = (ci + ci.transpose()) * 0.5;
                let mut d = VoigtMatrix::zeros();
                for (p, &(i, j)) in Voigt::<D>::PAIRS.iter().enumerate() {
                    for (q, &(k, l)) in Voigt::<D>::PAIRS.iter().enumerate() {
                        d[(p, q)] = lambda * ci[(i, j)] * ci[(k, l)]
                            + m * (ci[(i, k)] * ci[(j, l)] + ci[(i, l)] * ci[(j, k)]);
                    }
                }
                (s, d, lambda * ln_j)
            }
            Hyperelastic::SaintVenantKirchhoff { lambda, mu } => {
                let s = identity * (lambda * e.trace()) + e * (2.0 * mu);
                (s, Voigt::<D>::isotropic(lambda, mu), lambda * e.trace())
            }
        };
        let s33 = if D == 2 { s33 } else { s[(2, 2)] };
        MaterialPoint { s, s33, d }
    }

    /// The Cauchy stress tensor `sigma = F S F^T / J` at the displacement gradient `h = F - I`
    /// (as computed, not symmetrized), in plane strain with `sigma_33 = S_33 / J` and
    /// `sigma_i3 = 0`.
    pub fn cauchy<const D: usize>(&self, h: &SMatrix<f64, D, D>) -> Matrix3<f64> {
        let f = SMatrix::<f64, D, D>::identity() + h;
        let j = jacobian(h);
        let p = self.material_point(h);
        let sigma = f * p.s * f.transpose() / j;
        let mut out = Matrix3::zeros();
        out.fixed_view_mut::<D, D>(0, 0).copy_from(&sigma);
        if D == 2 {
            out[(2, 2)] = p.s33 / j;
        }
        out
    }
}

/// A quadrature point where `J = det F <= 0`: the element is inverted (or degenerate) in the
/// current configuration.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Inverted<const D: usize = 2> {
    /// The quadrature point (index in the element's rule) and its reference position.
    pub point: usize,
    pub at: [f64; D],
    pub det_f: f64,
}

impl<const D: usize> std::fmt::Display for Inverted<D> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let at: Vec<String> = self.at.iter().map(|x| x.to_string()).collect();
        write!(
            f,
            "det F = {:.3e} <= 0 at quadrature point {} (reference position ({}))",
            self.det_f,
            self.point,
            at.join(", ")
        )
    }
}

/// The deformation gradient at natural point `xi` of an element with reference nodes `coords`
/// and displacements `u_e`, with the reference position of the point.
pub fn deformation_gradient_at<const D: usize, C: ReferenceCell<D>>(
    kind: C,
    coords: &[[f64; D]],
    u_e: &[f64],
    xi: [f64; D],
) -> (SMatrix<f64, D, D>, [f64; D]) {
    let (h, x) = displacement_gradient_at(kind, coords, u_e, xi);
    (SMatrix::identity() + h, x)
}

/// Calls `visit(dndx, w, H)` at every point of `rule` (reference gradients, weight
/// `w = w_q det J_0 t`, displacement gradient); `Err` at the first point with `det F <= 0`.
fn for_each_point<const D: usize, C: ReferenceCell<D>>(
    kind: C,
    coords: &[[f64; D]],
    u_e: &[f64],
    thickness: f64,
    rule: &[QuadPoint<D>],
    mut visit: impl FnMut(&[[f64; D]], f64, &SMatrix<f64, D, D>),
) -> Result<(), Inverted<D>> {
    let n = kind.node_count();
    for (q, point) in rule.iter().enumerate() {
        let pv = kind.point_values(coords, point.xi);
        let det_j = pv.jacobian_determinant();
        if det_j == 0.0 {
            continue;
        }
        let dndx = &pv.gradients()[..n];
        let h = field_gradient(dndx, u_e);
        let det_f = jacobian(&h);
        if det_f.is_nan() || det_f <= 0.0 {
            return Err(Inverted {
                point: q,
                at: pv.point(),
                det_f,
            });
        }
        visit(dndx, point.weight * det_j * thickness, &h);
    }
    Ok(())
}

/// The element's stored energy `sum_q w W(C)` at the displacements `u_e`.
pub fn element_energy<const D: usize, C: ReferenceCell<D>>(
    kind: C,
    coords: &[[f64; D]],
    u_e: &[f64],
    law: &Hyperelastic,
    thickness: f64,
    rule: &[QuadPoint<D>],
) -> Result<f64, Inverted<D>> {
    let mut energy = 0.0;
    for_each_point(kind, coords, u_e, thickness, rule, |_, w, h| {
        energy += w * law.energy(h)
    })?;
    Ok(energy)
}

/// `B_a` of the module docs (`V x D`, rows past `V` zero): `dE_v = B_a du_a` at the
/// deformation gradient `f`, `g = grad_0 N_a`.
#[inline(always)]
fn strain_displacement<const D: usize>(f: &SMatrix<f64, D, D>, g: &[f64; D]) -> [[f64; D]; 6] {
    let mut b = [[0.0; D]; 6];
    for (row, &(i, j)) in b.iter_mut().zip(Voigt::<D>::PAIRS) {
        for (c, entry) in row.iter_mut().enumerate() {
            *entry = if i == j {
                f[(c, i)] * g[i]
            } else {
                f[(c, i)] * g[j] + f[(c, j)] * g[i]
            };
        }
    }
    b
}

/// Internal force `f_a = sum_q w F S grad_0 N_a` into `force[..D n]` and, with
/// `with_tangent`, the consistent tangent `K_ab` (material + geometric, row-major
/// `D n x D n`) into `k[..(D n)^2]` of one element at the displacements `u_e`; both are
/// overwritten.
#[allow(clippy::too_many_arguments)]
pub fn element_residual_and_tangent<const D: usize, C: ReferenceCell<D>>(
    kind: C,
    coords: &[[f64; D]],
    u_e: &[f64],
    law: &Hyperelastic,
    thickness: f64,
    rule: &[QuadPoint<D>],
    with_tangent: bool,
    force: &mut [f64],
    k: &mut [f64],
) -> Result<(), Inverted<D>> {
    let voigt = Voigt::<D>::SIZE;
    let nd = D * kind.node_count();
    force[..nd].fill(0.0);
    if with_tangent {
        k[..nd * nd].fill(0.0);
    }
    let mut blocks = [[[0.0; D]; 6]; crate::fe3d::MAX_SOLID_NODES];
    for_each_point(kind, coords, u_e, thickness, rule, |dndx, w, h| {
        let mp = law.material_point(h);
        let f = SMatrix::<f64, D, D>::identity() + h;
        let p = f * mp.s;
        for (a, g) in dndx.iter().enumerate() {
            let fa = p * SVector::<f64, D>::from(*g) * w;
            for i in 0..D {
                force[D * a + i] += fa[i];
            }
        }
        if !with_tangent {
            return;
        }
        for (block, g) in blocks.iter_mut().zip(dndx) {
            *block = strain_displacement(&f, g);
        }
        for (b, gb) in dndx.iter().enumerate() {
            // D B_b
            let mut db = [[0.0; D]; 6];
            for (r, row) in db.iter_mut().enumerate().take(voigt) {
                for (c, entry) in row.iter_mut().enumerate() {
                    *entry = (1..voigt).fold(mp.d[(r, 0)] * blocks[b][0][c], |s, q| {
                        s + mp.d[(r, q)] * blocks[b][q][c]
                    });
                }
            }
            let s_gb = mp.s * SVector::<f64, D>::from(*gb);
            for (a, ga) in dndx.iter().enumerate() {
                let geometric = (1..D).fold(ga[0] * s_gb[0], |s, i| s + ga[i] * s_gb[i]);
                for i in 0..D {
                    for j in 0..D {
                        let material = (1..voigt).fold(blocks[a][0][i] * db[0][j], |s, q| {
                            s + blocks[a][q][i] * db[q][j]
                        });
                        let diagonal = if i == j { geometric } else { 0.0 };
                        k[(D * a + i) * nd + D * b + j] += (material + diagonal) * w;
                    }
                }
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fe::ElementKind;
    use crate::fe3d::SolidKind;
    use crate::io::scene::Plane;
    use crate::solid::{element_stiffness, facet_traction_load, Elasticity};
    use nalgebra::{Vector2, Vector3};

    const PLANE_KINDS: [ElementKind; 4] = [
        ElementKind::Q4,
        ElementKind::Q9,
        ElementKind::T3,
        ElementKind::T6,
    ];
    const THICKNESS: f64 = 0.7;
    const E: f64 = 1000.0;
    const NU: f64 = 0.3;

    fn laws() -> [Hyperelastic; 2] {
        [
            Hyperelastic::neo_hookean(E, NU),
            Hyperelastic::saint_venant_kirchhoff(E, NU),
        ]
    }

    /// The reference element mapped through a smooth orientation-preserving map (curved
    /// sides for Q9 and T6).
    fn distorted_plane(kind: ElementKind) -> Vec<[f64; 2]> {
        kind.node_coordinates()
            .iter()
            .map(|&[s, t]| {
                [
                    2.0 + 1.3 * s + 0.2 * t + 0.05 * s * t + 0.04 * t * t,
                    1.0 + 0.1 * s + 0.9 * t - 0.03 * s * s,
                ]
            })
            .collect()
    }

    /// The reference cell mapped through a smooth orientation-preserving map (curved faces
    /// for Hex27 and Tet10).
    fn distorted_solid(kind: SolidKind) -> Vec<[f64; 3]> {
        kind.node_coordinates()
            .iter()
            .map(|&[x, y, z]| {
                [
                    2.0 + 1.1 * x + 0.1 * y + 0.03 * y * z + 0.04 * z * z,
                    1.0 + 0.9 * y - 0.05 * x + 0.04 * x * z,
                    -0.5 + 1.2 * z + 0.02 * x * y + 0.05 * x - 0.03 * y * y,
                ]
            })
            .collect()
    }

    fn rotation2(angle: f64) -> Matrix2<f64> {
        Matrix2::new(angle.cos(), -angle.sin(), angle.sin(), angle.cos())
    }

    fn rotation3(axis: [f64; 3], angle: f64) -> Matrix3<f64> {
        nalgebra::Rotation3::from_axis_angle(
            &nalgebra::Unit::new_normalize(Vector3::from(axis)),
            angle,
        )
        .into_inner()
    }

    /// The nodal displacements of `x = F X + c` plus `wobble` times a nonuniform field.
    fn mapped<const D: usize>(
        coords: &[[f64; D]],
        f: &SMatrix<f64, D, D>,
        c: [f64; D],
        wobble: f64,
    ) -> Vec<f64> {
        let mut u = Vec::new();
        for (a, p) in coords.iter().enumerate() {
            let x = SVector::<f64, D>::from(*p);
            let y = f * x - x;
            for i in 0..D {
                let phase = (0.7 + 0.3 * i as f64) * a as f64 + 0.5 * i as f64;
                u.push(y[i] + c[i] + wobble * phase.sin());
            }
        }
        u
    }

    /// A large deformation (stretch, shear and rotation of order 0.2 to 0.4, plus a
    /// nonuniform part) with `det F > 0` everywhere.
    fn deformed_plane(coords: &[[f64; 2]]) -> Vec<f64> {
        let f = rotation2(0.4) * Matrix2::new(1.15, 0.2, -0.05, 0.85);
        mapped(coords, &f, [0.0; 2], 0.02)
    }

    fn deformed_solid(coords: &[[f64; 3]]) -> Vec<f64> {
        let a = Matrix3::new(1.25, 0.2, -0.1, -0.05, 0.85, 0.15, 0.1, -0.1, 1.1);
        mapped(
            coords,
            &(rotation3([0.3, -0.5, 0.8], 0.6) * a),
            [0.0; 3],
            0.02,
        )
    }

    fn largest(v: impl IntoIterator<Item = f64>) -> f64 {
        v.into_iter().fold(0.0, |m, x| m.max(x.abs()))
    }

    fn force_and_tangent<const D: usize, C: ReferenceCell<D>>(
        kind: C,
        coords: &[[f64; D]],
        u: &[f64],
        law: &Hyperelastic,
        thickness: f64,
        rule: &[QuadPoint<D>],
    ) -> (Vec<f64>, Vec<f64>) {
        let nd = D * kind.node_count();
        let (mut f, mut k) = (vec![0.0; nd], vec![0.0; nd * nd]);
        element_residual_and_tangent(kind, coords, u, law, thickness, rule, true, &mut f, &mut k)
            .expect("not inverted");
        (f, k)
    }

    /// `f = dPi/du` and `K = df/du` by central differences (1e-7 relative), `K` symmetric.
    fn check_gradients<const D: usize, C: ReferenceCell<D>>(
        kind: C,
        coords: &[[f64; D]],
        u: &[f64],
        law: &Hyperelastic,
        thickness: f64,
        rule: &[QuadPoint<D>],
    ) {
        let nd = D * kind.node_count();
        let (f, k) = force_and_tangent(kind, coords, u, law, thickness, rule);
        let f_scale = largest(f.iter().copied());
        let k_scale = largest(k.iter().copied());
        assert!(f_scale > 1.0, "{kind:?}: the state is stressed");
        let h = 1e-6;
        let energy = |v: &[f64]| {
            element_energy(kind, coords, v, law, thickness, rule).expect("not inverted")
        };
        let (mut worst_f, mut worst_k) = (0.0f64, 0.0f64);
        for j in 0..nd {
            let (mut up, mut um) = (u.to_vec(), u.to_vec());
            up[j] += h;
            um[j] -= h;
            let de = (energy(&up) - energy(&um)) / (2.0 * h);
            worst_f = worst_f.max((de - f[j]).abs() / f_scale);
            let (fp, _) = force_and_tangent(kind, coords, &up, law, thickness, rule);
            let (fm, _) = force_and_tangent(kind, coords, &um, law, thickness, rule);
            for i in 0..nd {
                let column = (fp[i] - fm[i]) / (2.0 * h);
                worst_k = worst_k.max((column - k[i * nd + j]).abs() / k_scale);
            }
        }
        println!("{kind:?} {law:?}: f vs dPi/du {worst_f:.1e}, K vs df/du {worst_k:.1e}");
        assert!(worst_f < 1e-7, "{kind:?} {law:?}: f vs dPi/du {worst_f:e}");
        assert!(worst_k < 1e-7, "{kind:?} {law:?}: K vs df/du {worst_k:e}");
        for i in 0..nd {
            for j in 0..nd {
                assert!((k[i * nd + j] - k[j * nd + i]).abs() <= 1e-12 * k_scale);
            }
        }
    }

    /// `f = dPi/du` and `K = df/du` at a large deformation of a distorted element, every
    /// element of both dimensions and both materials.
    #[test]
    fn residual_is_the_energy_gradient_and_tangent_the_residual_gradient() {
        for law in laws() {
            for kind in PLANE_KINDS {
                let coords = distorted_plane(kind);
                let u = deformed_plane(&coords);
                check_gradients(kind, &coords, &u, &law, THICKNESS, &kind.stiffness_rule());
            }
            for kind in SolidKind::ALL {
                let coords = distorted_solid(kind);
                let u = deformed_solid(&coords);
                check_gradients(kind, &coords, &u, &law, 1.0, &kind.stiffness_rule());
            }
        }
    }

    /// The small-strain limit: the tangent at `u = 0` is the small-strain `K_e` (plane strain
    /// in 2D; 1e-13), and at the displacement `eps u` the internal force differs from
    /// `K_e eps u` by `O(eps^2)`: the ratio of the differences at `eps` and `eps / 2` is 4
    /// (to 1 %).
    fn check_small_strain_limit<const D: usize, C: ReferenceCell<D>>(
        kind: C,
        coords: &[[f64; D]],
        shape: &[f64],
        law: &Hyperelastic,
        linear: &Elasticity<D>,
        thickness: f64,
        rule: &[QuadPoint<D>],
    ) {
        let nd = D * kind.node_count();
        let (f0, k0) = force_and_tangent(kind, coords, &vec![0.0; nd], law, thickness, rule);
        assert!(largest(f0) == 0.0);
        let mut ke = vec![0.0; nd * nd];
        element_stiffness(kind, coords, linear, thickness, rule, &mut ke);
        let scale = largest(ke.iter().copied());
        for (a, b) in k0.iter().zip(&ke) {
            assert!((a - b).abs() < 1e-13 * scale, "{kind:?} {law:?}");
        }
        let gap = |eps: f64| {
            let u: Vec<f64> = shape.iter().map(|v| eps * v).collect();
            let (f, _) = force_and_tangent(kind, coords, &u, law, thickness, rule);
            largest((0..nd).map(|i| f[i] - (0..nd).map(|j| ke[i * nd + j] * u[j]).sum::<f64>()))
        };
        let ratio = gap(1e-3) / gap(5e-4);
        assert!(
            (ratio - 4.0).abs() < 0.04,
            "{kind:?} {law:?}: ratio {ratio}"
        );
    }

    #[test]
    fn small_deformations_are_small_strain_elasticity() {
        for law in laws() {
            for kind in PLANE_KINDS {
                let coords = distorted_plane(kind);
                let (shape, linear) = (
                    deformed_plane(&coords),
                    Elasticity::new(E, NU, Plane::Strain),
                );
                let rule = kind.stiffness_rule();
                check_small_strain_limit(kind, &coords, &shape, &law, &linear, THICKNESS, &rule);
            }
            for kind in SolidKind::ALL {
                let coords = distorted_solid(kind);
                let (shape, linear) = (deformed_solid(&coords), Elasticity::solid(E, NU));
                let rule = kind.stiffness_rule();
                check_small_strain_limit(kind, &coords, &shape, &law, &linear, 1.0, &rule);
            }
        }
    }

    /// An element turned inside out (`x = -X`, `det F = -1`) is refused with the point, never
    /// a NaN.
    fn check_refused<const D: usize, C: ReferenceCell<D>>(
        kind: C,
        coords: &[[f64; D]],
        rule: &[QuadPoint<D>],
    ) {
        let mut mirror = SMatrix::<f64, D, D>::identity();
        mirror[(0, 0)] = -1.0;
        let u = mapped(coords, &mirror, [0.0; D], 0.0);
        let nd = D * kind.node_count();
        for law in laws() {
            let (mut f, mut k) = (vec![0.0; nd], vec![0.0; nd * nd]);
            let err = element_residual_and_tangent(
                kind, coords, &u, &law, 1.0, rule, true, &mut f, &mut k,
            )
            .unwrap_err();
            assert_eq!(err.point, 0);
            assert!((err.det_f + 1.0).abs() < 1e-12, "{err}");
            assert!(err.to_string().contains("det F = -1.000e0 <= 0"), "{err}");
            assert!(element_energy(kind, coords, &u, &law, 1.0, rule).is_err());
        }
    }

    #[test]
    fn inverted_elements_are_refused() {
        for kind in PLANE_KINDS {
            check_refused(kind, &distorted_plane(kind), &kind.stiffness_rule());
        }
        for kind in SolidKind::ALL {
            check_refused(kind, &distorted_solid(kind), &kind.stiffness_rule());
        }
    }

    /// `int_{boundary} N_a P N t dS` for a constant first Piola stress `P` on the reference
    /// element edges (`N dS = [dY, -dX]`).
    fn edge_force(kind: ElementKind, coords: &[[f64; 2]], p: &Matrix2<f64>) -> Vec<f64> {
        let edge = kind.edge_kind();
        let m = edge.node_count();
        let mut f = vec![0.0; 2 * kind.node_count()];
        for nodes in kind.edges() {
            for (s, w) in crate::fe::gauss_legendre(5) {
                let (mut n, mut dn) = ([0.0; 3], [0.0; 3]);
                edge.shape(s, &mut n[..m], &mut dn[..m]);
                let mut tangent = [0.0; 2];
                for (i, &a) in nodes.iter().enumerate() {
                    tangent[0] += dn[i] * coords[a][0];
                    tangent[1] += dn[i] * coords[a][1];
                }
                let traction = p * Vector2::new(tangent[1], -tangent[0]);
                for (i, &a) in nodes.iter().enumerate() {
                    f[2 * a] += w * n[i] * traction[0] * THICKNESS;
                    f[2 * a + 1] += w * n[i] * traction[1] * THICKNESS;
                }
            }
        }
        f
    }

    /// `int_{boundary} N_a P N dS` on the facets of a solid cell.
    fn facet_force(kind: SolidKind, coords: &[[f64; 3]], p: &Matrix3<f64>) -> Vec<f64> {
        let mut f = vec![0.0; 3 * kind.node_count()];
        for facet in kind.facets() {
            let fc: Vec<[f64; 3]> = facet.iter().map(|&a| coords[a]).collect();
            let fe = facet_traction_load(kind.facet_kind(), &fc, &|_, n| {
                (p * Vector3::from(n)).into()
            });
            for (i, &a) in facet.iter().enumerate() {
                for j in 0..3 {
                    f[3 * a + j] += fe[3 * i + j];
                }
            }
        }
        f
    }

    /// A homogeneous deformation `x = F X + c` is represented exactly: `F` at every quadrature
    /// point to 1e-13, and the internal force is the boundary integral of the constant traction
    /// `P N` (`P = F S`, `N` the reference outward normal), so a patch of such elements is in
    /// equilibrium inside (to `tolerance` of the largest nodal force).
    #[allow(clippy::too_many_arguments)]
    fn check_homogeneous<const D: usize, C: ReferenceCell<D>>(
        kind: C,
        coords: &[[f64; D]],
        target: &SMatrix<f64, D, D>,
        law: &Hyperelastic,
        thickness: f64,
        rule: &[QuadPoint<D>],
        boundary: &[f64],
        tolerance: f64,
    ) {
        let u = mapped(
            coords,
            target,
            std::array::from_fn(|i| 0.3 - 0.25 * i as f64),
            0.0,
        );
        for q in rule {
            let (f, _) = deformation_gradient_at(kind, coords, &u, q.xi);
            assert!((f - target).abs().max() < 1e-13, "{kind:?}: {f}");
        }
        let (got, _) = force_and_tangent(kind, coords, &u, law, thickness, rule);
        let scale = largest(boundary.iter().copied());
        for (i, want) in boundary.iter().enumerate() {
            assert!(
                (got[i] - want).abs() < tolerance * scale,
                "{kind:?} {law:?}: f[{i}] = {} vs {want}",
                got[i]
            );
        }
    }

    /// The distorted cell with straight edges for Tet10 (mid-edge nodes at the midpoints of
    /// their corners, as the mesher builds them): on a curved Tet10 the divergence theorem
    /// needs `grad_0 N_a det J_0` (degree 3) integrated exactly, beyond the stiffness rule's
    /// degree 2. Hex27 keeps its curved faces (Gauss 3x3x3 integrates them exactly).
    fn distorted_patch_cell(kind: SolidKind) -> Vec<[f64; 3]> {
        let mut coords = distorted_solid(kind);
        if kind == SolidKind::Tet10 {
            const EDGES: [[usize; 2]; 6] = [[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]];
            for (k, [a, b]) in EDGES.iter().enumerate() {
                coords[4 + k] = std::array::from_fn(|i| 0.5 * (coords[*a][i] + coords[*b][i]));
            }
        }
        coords
    }

    #[test]
    fn a_homogeneous_deformation_is_exact_on_distorted_elements() {
        let target2 = Matrix2::new(1.2, 0.15, -0.1, 0.8);
        let target3 = rotation3([1.0, 1.0, 0.2], 0.4)
            * Matrix3::new(1.2, 0.15, -0.1, -0.1, 0.8, 0.05, 0.08, 0.02, 1.1);
        for law in laws() {
            let p2 = target2 * law.material_point(&(target2 - Matrix2::identity())).s;
            for kind in PLANE_KINDS {
                let coords = distorted_plane(kind);
                let boundary = edge_force(kind, &coords, &p2);
                let rule = kind.stiffness_rule();
                check_homogeneous(
                    kind, &coords, &target2, &law, THICKNESS, &rule, &boundary, 1e-12,
                );
            }
            let p3 = target3 * law.material_point(&(target3 - Matrix3::identity())).s;
            for kind in SolidKind::ALL {
                let coords = distorted_patch_cell(kind);
                let boundary = facet_force(kind, &coords, &p3);
                let rule = kind.stiffness_rule();
                check_homogeneous(kind, &coords, &target3, &law, 1.0, &rule, &boundary, 1e-11);
            }
        }
    }

    /// The Cauchy stress of a stretch `F = diag(s_1, .., s_D)` in closed form: neo-Hookean
    /// `sigma_ii = (mu (s_i^2 - 1) + lambda ln J) / J`, St. Venant-Kirchhoff
    /// `sigma_ii = s_i^2 (lambda tr E + 2 mu E_ii) / J`, no shear; in plane strain
    /// `sigma_33 = lambda ln J / J` and `lambda tr E / J`.
    fn check_stretch<const D: usize>(stretch: [f64; D]) {
        let j: f64 = stretch.iter().product();
        let h = SMatrix::<f64, D, D>::from_diagonal(&SVector::from(stretch.map(|s| s - 1.0)));
        let (lambda, mu) = lame(E, NU);
        let nh = Hyperelastic::neo_hookean(E, NU).cauchy(&h);
        let sv = Hyperelastic::saint_venant_kirchhoff(E, NU).cauchy(&h);
        let strain = stretch.map(|s| 0.5 * (s * s - 1.0));
        let trace: f64 = strain.iter().sum();
        for i in 0..3 {
            let (want_nh, want_sv) = match stretch.get(i) {
                Some(s) => (
                    (mu * (s * s - 1.0) + lambda * j.ln()) / j,
                    s * s * (lambda * trace + 2.0 * mu * strain[i]) / j,
                ),
                None => (lambda * j.ln() / j, lambda * trace / j),
            };
            assert!((nh[(i, i)] - want_nh).abs() < 1e-12 * E, "{nh}");
            assert!((sv[(i, i)] - want_sv).abs() < 1e-12 * E, "{sv}");
            for k in (0..3).filter(|&k| k != i) {
                assert!(nh[(i, k)].abs() < 1e-12 * E && sv[(i, k)].abs() < 1e-12 * E);
            }
        }
    }

    #[test]
    fn cauchy_stress_of_a_stretch_has_its_closed_form() {
        check_stretch([1.3, 0.8]);
        check_stretch([1.3, 0.8, 1.1]);
    }

    /// Objectivity: the rigid rotations `rotations` (each state checked) give no internal
    /// force and no stress; the rotation `r` of the stretched state `f` rotates its Cauchy
    /// stress, `sigma(R F) = R sigma(F) R^T`, and leaves `S` unchanged.
    fn check_objectivity<const D: usize, C: ReferenceCell<D>>(
        kind: C,
        coords: &[[f64; D]],
        rotations: &[SMatrix<f64, D, D>],
        f: &SMatrix<f64, D, D>,
        r: &SMatrix<f64, D, D>,
        rule: &[QuadPoint<D>],
    ) {
        let identity = SMatrix::<f64, D, D>::identity();
        let mut r3 = Matrix3::identity();
        r3.fixed_view_mut::<D, D>(0, 0).copy_from(r);
        for law in laws() {
            for rotation in rotations {
                let u = mapped(
                    coords,
                    rotation,
                    std::array::from_fn(|i| 0.1 * i as f64),
                    0.0,
                );
                let (force, _) = force_and_tangent(kind, coords, &u, &law, 1.0, rule);
                assert!(
                    largest(force.iter().copied()) < 1e-12 * E,
                    "{kind:?}: {force:?}"
                );
                let (h, _) = displacement_gradient_at(kind, coords, &u, rule[0].xi);
                assert!(law.cauchy(&h).abs().max() < 1e-12 * E);
            }
            let sigma = law.cauchy(&(f - identity));
            let rotated = law.cauchy(&(r * f - identity));
            assert!((r3 * sigma * r3.transpose() - rotated).abs().max() < 1e-12 * E);
            let s0 = law.material_point(&(f - identity));
            let s1 = law.material_point(&(r * f - identity));
            assert!((s0.s - s1.s).abs().max() < 1e-12 * E && (s0.s33 - s1.s33).abs() < 1e-12 * E);
        }
    }

    /// Up to 90 degrees in ten steps (about a skew axis in 3D).
    #[test]
    fn rigid_rotations_are_stress_free_and_rotate_the_stress() {
        let angles = (1..=10).map(|step| std::f64::consts::FRAC_PI_2 * step as f64 / 10.0);
        let plane: Vec<Matrix2<f64>> = angles.clone().map(rotation2).collect();
        let solid: Vec<Matrix3<f64>> = angles.map(|a| rotation3([0.2, -0.7, 1.0], a)).collect();
        for kind in PLANE_KINDS {
            let f = Matrix2::new(1.2, 0.15, -0.1, 0.8);
            let rule = kind.stiffness_rule();
            check_objectivity(
                kind,
                &distorted_plane(kind),
                &plane,
                &f,
                &rotation2(1.1),
                &rule,
            );
        }
        for kind in SolidKind::ALL {
            let f = Matrix3::new(1.2, 0.15, -0.1, -0.1, 0.8, 0.05, 0.08, 0.02, 1.1);
            let r = rotation3([0.5, 0.3, -0.8], 1.1);
            check_objectivity(
                kind,
                &distorted_solid(kind),
                &solid,
                &f,
                &r,
                &kind.stiffness_rule(),
            );
        }
    }
}
