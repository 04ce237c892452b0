//! Finite-deformation (total-Lagrangian) solids in 3D: hyperelastic energy, element residual
//! and consistent tangent, Cauchy stress, for Hex8, Hex27, Tet4 and Tet10 cells. The 3D
//! counterpart of [`crate::solid_finite`] (plane strain), with the same laws
//! ([`Hyperelastic`]) and the same refusal of inverted elements ([`Inverted`]).
//!
//! **Kinematics.** With reference coordinates `X` and displacement `u`, `F = I + H`,
//! `H = du/dX = sum_a u_a (grad_0 N_a)^T`, `C = F^T F`, the Green-Lagrange strain
//! `E = (H + H^T + H^T H) / 2` and `J = det F = 1 + tr H + I_2(H) + det H`
//! (`I_2 = ((tr H)^2 - tr H^2) / 2`), `ln J` through `ln_1p`: computed from `H`, not from `F`,
//! so that a lightly loaded body keeps the round-off of small strain.
//!
//! **Materials** (Lamé constants `lambda`, `mu`), energy per reference volume (Bonet & Wood,
//! *Nonlinear Continuum Mechanics for Finite Element Analysis*, 2nd ed., sections 6.4.3 and
//! 6.5, eqs. 6.28 and 6.40):
//!
//! * compressible neo-Hookean, `W = mu/2 (tr C - 3 - 2 ln J) + lambda/2 (ln J)^2`,
//!   `S = mu (I - C^-1) + lambda ln J C^-1` (evaluated as `C^-1 (2 mu E + lambda ln J I)`) and
//!   `CC_IJKL = lambda C^-1_IJ C^-1_KL + (mu - lambda ln J)(C^-1_IK C^-1_JL + C^-1_IL C^-1_JK)`;
//! * St. Venant-Kirchhoff, `W = lambda/2 (tr E)^2 + mu E:E`, `S = lambda tr E I + 2 mu E`,
//!   `CC = lambda I (x) I + 2 mu II` (the small-strain `D` of [`crate::solid`]).
//!
//! **Element** (Bonet & Wood chapter 9; Wriggers, *Nonlinear Finite Element Methods*,
//! section 4.2). At a quadrature point of weight `w = w_q det J_0` (reference configuration),
//! Voigt order `11, 22, 33, 23, 13, 12` with engineering shears (as [`crate::solid`]),
//!
//! `f_a = sum_q w B_a^T S_v` (`= w F S grad_0 N_a`),
//! `K_ab = sum_q w [B_a^T D B_b + (grad_0 N_a . S grad_0 N_b) I_3]`,
//!
//! material plus geometric part, `D_pq = CC_IJKL` (`p = (I, J)`, `q = (K, L)`), and the
//! nonlinear strain-displacement matrix `dE_v = B_a du_a` with rows
//! `B_a[(I, I), i] = F_iI N_a,I` and `B_a[(I, J), i] = F_iI N_a,J + F_iJ N_a,I` (`I != J`).
//! `f` is the gradient of the element energy `sum_q w W` and `K` the gradient of `f`
//! (finite-difference checks below). A quadrature point with `J <= 0` (an inverted element)
//! is refused ([`Inverted`]): the energy is not defined there (`ln J`).
//!
//! **Stress.** The Cauchy stress on the deformed configuration is `sigma = F S F^T / J`
//! (Voigt `[xx, yy, zz, yz, xz, xy]`).

use crate::fe::{field_gradient, QuadPoint, ReferenceCell};
use crate::fe3d::{SolidKind, MAX_SOLID_NODES};
use crate::solid_finite::{Hyperelastic, Inverted};
use nalgebra::{Matrix3, SMatrix, Vector3};

/// The `6 x 6` material tangent `D = dS_v / dE_v` (Voigt, engineering shears).
pub type Tangent6 = SMatrix<f64, 6, 6>;
type StrainBlock = SMatrix<f64, 6, 3>;

/// The tensor index pairs of the Voigt components `11, 22, 33, 23, 13, 12`.
const VOIGT: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1)];

/// Stress state of one deformation gradient in 3D: second Piola-Kirchhoff stress and the
/// Voigt tangent `D = dS/dE`.
#[derive(Copy, Clone, Debug)]
pub struct MaterialPoint3 {
    pub s: Matrix3<f64>,
    pub d: Tangent6,
}

/// `I_2(H) = ((tr H)^2 - tr H^2) / 2`, the second invariant.
fn second_invariant(h: &Matrix3<f64>) -> f64 {
    0.5 * (h.trace().powi(2) - (h * h).trace())
}

/// `J = det(I + H) = 1 + tr H + I_2(H) + det H`.
pub fn jacobian3(h: &Matrix3<f64>) -> f64 {
    1.0 + h.trace() + second_invariant(h) + h.determinant()
}

/// `E = (H + H^T + H^T H) / 2` and `ln J` (through `ln_1p`) from the displacement gradient.
fn green_lagrange3(h: &Matrix3<f64>) -> (Matrix3<f64>, f64) {
    let e = (h + h.transpose() + h.transpose() * h) * 0.5;
    let ln_j = (h.trace() + second_invariant(h) + h.determinant()).ln_1p();
    (e, ln_j)
}

impl Hyperelastic {
    /// Energy per reference volume at the displacement gradient `h = F - I` (`det F > 0`).
    pub fn energy3(&self, h: &Matrix3<f64>) -> f64 {
        let (e, ln_j) = green_lagrange3(h);
        match *self {
            // tr C - 3 = 2 tr E
            Hyperelastic::NeoHookean { lambda, mu } => {
                mu * (e.trace() - ln_j) + 0.5 * lambda * ln_j * ln_j
            }
            Hyperelastic::SaintVenantKirchhoff { lambda, mu } => {
                0.5 * lambda * e.trace().powi(2) + mu * e.component_mul(&e).sum()
            }
        }
    }

    /// `S` and `D` at the displacement gradient `h = F - I` (`det F > 0`).
    pub fn material_point3(&self, h: &Matrix3<f64>) -> MaterialPoint3 {
        let (e, ln_j) = green_lagrange3(h);
        match *self {
            Hyperelastic::NeoHookean { lambda, mu } => {
                let c = Matrix3::identity() + e * 2.0;
                let ci = c
                    .try_inverse()
                    .unwrap_or_else(|| Matrix3::from_element(f64::NAN));
                // mu (I - C^-1) + lambda ln J C^-1 = C^-1 (2 mu E + lambda ln J I), free of the
                // cancellation of I - C^-1 at small strain
                let s = ci * (e * (2.0 * mu) + Matrix3::identity() * (lambda * ln_j));
                let s = (s + s.transpose()) * 0.5;
                let m = mu - lambda * ln_j;
                let ci = (ci + ci.transpose()) * 0.5;
                let d = Tangent6::from_fn(|p, q| {
                    let (i, j) = VOIGT[p];
                    let (k, l) = VOIGT[q];
                    lambda * ci[(i, j)] * ci[(k, l)]
                        + m * (ci[(i, k)] * ci[(j, l)] + ci[(i, l)] * ci[(j, k)])
                });
                MaterialPoint3 { s, d }
            }
            Hyperelastic::SaintVenantKirchhoff { lambda, mu } => {
                let s = Matrix3::identity() * (lambda * e.trace()) + e * (2.0 * mu);
                let mut d = Tangent6::zeros();
                for i in 0..3 {
                    for j in 0..3 {
                        d[(i, j)] = lambda;
                    }
                    d[(i, i)] += 2.0 * mu;
                    d[(i + 3, i + 3)] = mu;
                }
                MaterialPoint3 { s, d }
            }
        }
    }

    /// Cauchy stress `[xx, yy, zz, yz, xz, xy]` at the displacement gradient `h = F - I`:
    /// `sigma = F S F^T / J`.
    pub fn cauchy3(&self, h: &Matrix3<f64>) -> [f64; 6] {
        let f = Matrix3::identity() + h;
        let sigma = f * self.material_point3(h).s * f.transpose() / jacobian3(h);
        VOIGT.map(|(i, j)| 0.5 * (sigma[(i, j)] + sigma[(j, i)]))
    }
}

/// Calls `visit(dndx, w, H)` at every point of `rule` (reference gradients, weight
/// `w_q det J_0`); `Err` at the first point with `det F <= 0`.
fn points3(
    kind: SolidKind,
    coords: &[[f64; 3]],
    u_e: &[f64],
    rule: &[QuadPoint<3>],
    mut visit: impl FnMut(&[[f64; 3]], f64, &Matrix3<f64>),
) -> Result<(), Inverted<3>> {
    let n = kind.node_count();
    for (q, point) in rule.iter().enumerate() {
        let pv = kind.point_values(coords, point.xi);
        if pv.det_j == 0.0 {
            continue;
        }
        let h = field_gradient(&pv.dndx[..n], u_e);
        let det_f = jacobian3(&h);
        if det_f.is_nan() || det_f <= 0.0 {
            return Err(Inverted {
                point: q,
                at: pv.x,
                det_f,
            });
        }
        visit(&pv.dndx[..n], point.weight * pv.det_j, &h);
    }
    Ok(())
}

/// The cell's stored energy `sum_q w W(C)` at the displacements `u_e`.
pub fn element_energy3(
    kind: SolidKind,
    coords: &[[f64; 3]],
    u_e: &[f64],
    law: &Hyperelastic,
    rule: &[QuadPoint<3>],
) -> Result<f64, Inverted<3>> {
    let mut energy = 0.0;
    points3(kind, coords, u_e, rule, |_, w, h| {
        energy += w * law.energy3(h)
    })?;
    Ok(energy)
}

/// `B_a` of the module docs: `dE_v = B_a du_a` at the deformation gradient `f`.
#[inline(always)]
fn strain_displacement3(f: &Matrix3<f64>, g: [f64; 3]) -> StrainBlock {
    StrainBlock::from_fn(|p, i| {
        let (a, b) = VOIGT[p];
        if a == b {
            f[(i, a)] * g[a]
        } else {
            f[(i, a)] * g[b] + f[(i, b)] * g[a]
        }
    })
}

/// Internal force `f_a = sum_q w F S grad_0 N_a` into `force[..3 n]` and, with `with_tangent`,
/// the consistent tangent `K_ab` (material + geometric, row-major `3 n x 3 n`) into
/// `k[..(3 n)^2]` of one cell at the displacements `u_e`; both are overwritten.
#[allow(clippy::too_many_arguments)]
pub fn element_residual_and_tangent3(
    kind: SolidKind,
    coords: &[[f64; 3]],
    u_e: &[f64],
    law: &Hyperelastic,
    rule: &[QuadPoint<3>],
    with_tangent: bool,
    force: &mut [f64],
    k: &mut [f64],
) -> Result<(), Inverted<3>> {
    let n = kind.node_count();
    let nd = 3 * n;
    force[..nd].fill(0.0);
    if with_tangent {
        k[..nd * nd].fill(0.0);
    }
    let mut blocks = [StrainBlock::zeros(); MAX_SOLID_NODES];
    points3(kind, coords, u_e, rule, |dndx, w, h| {
        let mp = law.material_point3(h);
        let f = Matrix3::identity() + h;
        let p = f * mp.s;
        for (a, g) in dndx.iter().enumerate() {
            let fa = p * Vector3::from(*g) * w;
            for i in 0..3 {
                force[3 * a + i] += fa[i];
            }
        }
        if !with_tangent {
            return;
        }
        for (a, g) in dndx.iter().enumerate() {
            blocks[a] = strain_displacement3(&f, *g);
        }
        for (b, gb) in dndx.iter().enumerate() {
            let db = mp.d * blocks[b];
            let s_gb = mp.s * Vector3::from(*gb);
            for (a, ga) in dndx.iter().enumerate() {
                let material = blocks[a].tr_mul(&db);
                let geometric = Vector3::from(*ga).dot(&s_gb);
                for i in 0..3 {
                    for j in 0..3 {
                        let diagonal = if i == j { geometric } else { 0.0 };
                        k[(3 * a + i) * nd + 3 * b + j] += w * (material[(i, j)] + diagonal);
                    }
                }
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fe::displacement_gradient_at;
    use crate::solid::{element_stiffness, facet_traction_load, Elasticity};

    const KINDS: [SolidKind; 4] = [
        SolidKind::Hex8,
        SolidKind::Hex27,
        SolidKind::Tet4,
        SolidKind::Tet10,
    ];
    const E: f64 = 1000.0;
    const NU: f64 = 0.3;

    fn laws() -> [Hyperelastic; 2] {
        [
            Hyperelastic::neo_hookean(E, NU),
            Hyperelastic::saint_venant_kirchhoff(E, NU),
        ]
    }

    /// The reference cell mapped through a smooth orientation-preserving map (curved faces
    /// for Hex27 and Tet10).
    fn distorted(kind: SolidKind) -> Vec<[f64; 3]> {
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

    fn rotation(axis: [f64; 3], angle: f64) -> Matrix3<f64> {
        nalgebra::Rotation3::from_axis_angle(
            &nalgebra::Unit::new_normalize(Vector3::from(axis)),
            angle,
        )
        .into_inner()
    }

    /// A large deformation (stretch, shear and rotation of order 0.2 to 0.4, plus a
    /// nonuniform part) with `det F > 0` everywhere.
    fn deformed(coords: &[[f64; 3]]) -> Vec<f64> {
        let a = Matrix3::new(1.25, 0.2, -0.1, -0.05, 0.85, 0.15, 0.1, -0.1, 1.1);
        let f = rotation([0.3, -0.5, 0.8], 0.6) * a;
        let mut u = Vec::new();
        for (i, p) in coords.iter().enumerate() {
            let x = Vector3::from(*p);
            let y = f * x - x;
            let i = i as f64;
            u.push(y[0] + 0.02 * (1.3 * i).sin());
            u.push(y[1] + 0.02 * (0.7 * i + 0.5).cos());
            u.push(y[2] - 0.02 * (0.4 * i + 0.2).sin());
        }
        u
    }

    fn homogeneous(coords: &[[f64; 3]], f: &Matrix3<f64>, c: [f64; 3]) -> Vec<f64> {
        coords
            .iter()
            .flat_map(|p| {
                let x = Vector3::from(*p);
                let y = f * x - x;
                [y[0] + c[0], y[1] + c[1], y[2] + c[2]]
            })
            .collect()
    }

    fn largest(v: impl IntoIterator<Item = f64>) -> f64 {
        v.into_iter().fold(0.0, |m, x| m.max(x.abs()))
    }

    fn force_and_tangent(
        kind: SolidKind,
        coords: &[[f64; 3]],
        u: &[f64],
        law: &Hyperelastic,
    ) -> (Vec<f64>, Vec<f64>) {
        let nd = 3 * kind.node_count();
        let (mut f, mut k) = (vec![0.0; nd], vec![0.0; nd * nd]);
        element_residual_and_tangent3(
            kind,
            coords,
            u,
            law,
            &kind.stiffness_rule(),
            true,
            &mut f,
            &mut k,
        )
        .expect("not inverted");
        (f, k)
    }

    /// `f = dPi/du` and `K = df/du` by central differences at a large deformation of a
    /// distorted cell, every element and both materials, to 1e-7 relative; `K` is symmetric.
    #[test]
    fn residual_is_the_energy_gradient_and_tangent_the_residual_gradient() {
        for law in laws() {
            for kind in KINDS {
                let coords = distorted(kind);
                let rule = kind.stiffness_rule();
                let nd = 3 * kind.node_count();
                let u = deformed(&coords);
                let (f, k) = force_and_tangent(kind, &coords, &u, &law);
                let f_scale = largest(f.iter().copied());
                let k_scale = largest(k.iter().copied());
                assert!(f_scale > 10.0, "{kind:?}: the state is stressed");
                let h = 1e-6;
                let (mut worst_f, mut worst_k) = (0.0f64, 0.0f64);
                let energy = |v: &[f64]| element_energy3(kind, &coords, v, &law, &rule).unwrap();
                for j in 0..nd {
                    let (mut up, mut um) = (u.clone(), u.clone());
                    up[j] += h;
                    um[j] -= h;
                    let de = (energy(&up) - energy(&um)) / (2.0 * h);
                    worst_f = worst_f.max((de - f[j]).abs() / f_scale);
                    let (fp, _) = force_and_tangent(kind, &coords, &up, &law);
                    let (fm, _) = force_and_tangent(kind, &coords, &um, &law);
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
        }
    }

    /// The distorted cell with straight edges for Tet10 (mid-edge nodes at the midpoints of
    /// their corners, as the mesher builds them): on a curved Tet10 the divergence theorem
    /// needs `grad_0 N_a det J_0` (degree 3) integrated exactly, beyond the stiffness rule's
    /// degree 2. Hex27 keeps its curved faces (Gauss 3x3x3 integrates them exactly).
    fn distorted_patch_cell(kind: SolidKind) -> Vec<[f64; 3]> {
        let mut coords = distorted(kind);
        if kind == SolidKind::Tet10 {
            const EDGES: [[usize; 2]; 6] = [[0, 1], [1, 2], [2, 0], [0, 3], [1, 3], [2, 3]];
            for (k, [a, b]) in EDGES.iter().enumerate() {
                coords[4 + k] = std::array::from_fn(|i| 0.5 * (coords[*a][i] + coords[*b][i]));
            }
        }
        coords
    }

    /// A homogeneous deformation `x = F X + c` is represented exactly: `F` at every quadrature
    /// point to 1e-13, and the internal force is the facet integral of the constant traction
    /// `P N` (`P = F S`, `N` the reference outward normal), so a patch of such cells is in
    /// equilibrium inside (1e-11 of the largest nodal force).
    #[test]
    fn a_homogeneous_deformation_is_exact_on_distorted_cells() {
        let target = rotation([1.0, 1.0, 0.2], 0.4)
            * Matrix3::new(1.2, 0.15, -0.1, -0.1, 0.8, 0.05, 0.08, 0.02, 1.1);
        let c = [0.3, -0.2, 0.1];
        for law in laws() {
            for kind in KINDS {
                let coords = distorted_patch_cell(kind);
                let u = homogeneous(&coords, &target, c);
                for q in kind.stiffness_rule() {
                    let (h, _) = displacement_gradient_at(kind, &coords, &u, q.xi);
                    let f = Matrix3::identity() + h;
                    assert!((f - target).abs().max() < 1e-13, "{kind:?}: {f}");
                }
                let p = target * law.material_point3(&(target - Matrix3::identity())).s;
                let mut expected = vec![0.0; 3 * kind.node_count()];
                for facet in kind.facets() {
                    let fc: Vec<[f64; 3]> = facet.iter().map(|&a| coords[a]).collect();
                    let fe = facet_traction_load(kind.facet_kind(), &fc, &|_, n| {
                        (p * Vector3::from(n)).into()
                    });
                    for (i, &a) in facet.iter().enumerate() {
                        for j in 0..3 {
                            expected[3 * a + j] += fe[3 * i + j];
                        }
                    }
                }
                let (got, _) = force_and_tangent(kind, &coords, &u, &law);
                let scale = largest(expected.iter().copied());
                for (i, want) in expected.iter().enumerate() {
                    assert!(
                        (got[i] - want).abs() < 1e-11 * scale,
                        "{kind:?} {law:?}: f[{i}] = {} vs {want}",
                        got[i]
                    );
                }
            }
        }
    }

    /// The Cauchy stress of a stretch `F = diag(a, b, c)` in closed form: neo-Hookean
    /// `sigma_ii = (mu (F_ii^2 - 1) + lambda ln J) / J`, St. Venant-Kirchhoff
    /// `sigma_ii = F_ii^2 (lambda tr E + 2 mu E_ii) / J`; no shear.
    #[test]
    fn cauchy_stress_of_a_stretch_has_its_closed_form() {
        let stretch = [1.3, 0.8, 1.1];
        let j: f64 = stretch.iter().product();
        let h = Matrix3::from_diagonal(&Vector3::from(stretch.map(|s| s - 1.0)));
        let (lambda, mu) = crate::solid_finite::lame(E, NU);
        let nh = Hyperelastic::neo_hookean(E, NU).cauchy3(&h);
        let sv = Hyperelastic::saint_venant_kirchhoff(E, NU).cauchy3(&h);
        let strain = stretch.map(|s| 0.5 * (s * s - 1.0));
        let trace: f64 = strain.iter().sum();
        for i in 0..3 {
            let s = stretch[i];
            let want_nh = (mu * (s * s - 1.0) + lambda * j.ln()) / j;
            let want_sv = s * s * (lambda * trace + 2.0 * mu * strain[i]) / j;
            assert!((nh[i] - want_nh).abs() < 1e-12 * E, "{nh:?}");
            assert!((sv[i] - want_sv).abs() < 1e-12 * E, "{sv:?}");
            assert!(nh[i + 3].abs() < 1e-12 * E && sv[i + 3].abs() < 1e-12 * E);
        }
    }

    /// Objectivity: a rigid rotation (up to 90 degrees about a skew axis, in ten steps, each
    /// state checked) gives no internal force and no stress; a rotation `R` of a stressed state
    /// rotates its Cauchy stress, `sigma(R F) = R sigma(F) R^T`, and leaves `S` unchanged.
    #[test]
    fn rigid_rotations_are_stress_free_and_rotate_the_stress() {
        let to_matrix =
            |s: [f64; 6]| Matrix3::new(s[0], s[5], s[4], s[5], s[1], s[3], s[4], s[3], s[2]);
        for law in laws() {
            for kind in KINDS {
                let coords = distorted(kind);
                for step in 1..=10 {
                    let angle = std::f64::consts::FRAC_PI_2 * step as f64 / 10.0;
                    let r = rotation([0.2, -0.7, 1.0], angle);
                    let u = homogeneous(&coords, &r, [0.1, 0.0, -0.3]);
                    let (f, _) = force_and_tangent(kind, &coords, &u, &law);
                    assert!(
                        largest(f.iter().copied()) < 1e-12 * E,
                        "{kind:?} {angle}: {f:?}"
                    );
                    let (h, _) = displacement_gradient_at(kind, &coords, &u, kind.centre());
                    assert!(largest(law.cauchy3(&h)) < 1e-12 * E);
                }
            }
            let f = Matrix3::new(1.2, 0.15, -0.1, -0.1, 0.8, 0.05, 0.08, 0.02, 1.1);
            let r = rotation([0.5, 0.3, -0.8], 1.1);
            let i3 = Matrix3::identity();
            let sigma = to_matrix(law.cauchy3(&(f - i3)));
            let rotated = to_matrix(law.cauchy3(&(r * f - i3)));
            assert!((r * sigma * r.transpose() - rotated).abs().max() < 1e-12 * E);
            let s0 = law.material_point3(&(f - i3)).s;
            let s1 = law.material_point3(&(r * f - i3)).s;
            assert!((s0 - s1).abs().max() < 1e-12 * E);
        }
    }

    /// The small-strain limit: the tangent at `u = 0` is the small-strain `K_e` of
    /// [`crate::solid`] (1e-13), and at the displacement `eps u` the internal force differs
    /// from `K_e eps u` by `O(eps^2)`: the ratio of the differences at `eps` and `eps / 2` is
    /// 4 (to 1 %).
    #[test]
    fn small_deformations_are_small_strain_elasticity() {
        let linear = Elasticity::solid(E, NU);
        for law in laws() {
            for kind in KINDS {
                let coords = distorted(kind);
                let rule = kind.stiffness_rule();
                let nd = 3 * kind.node_count();
                let zero = vec![0.0; nd];
                let (f0, k0) = force_and_tangent(kind, &coords, &zero, &law);
                assert!(largest(f0) == 0.0);
                let mut ke = vec![0.0; nd * nd];
                element_stiffness(kind, &coords, &linear, 1.0, &rule, &mut ke);
                let scale = largest(ke.iter().copied());
                for (a, b) in k0.iter().zip(&ke) {
                    assert!((a - b).abs() < 1e-13 * scale, "{kind:?} {law:?}");
                }
                let shape = deformed(&coords);
                let gap = |eps: f64| {
                    let u: Vec<f64> = shape.iter().map(|v| eps * v).collect();
                    let (f, _) = force_and_tangent(kind, &coords, &u, &law);
                    largest(
                        (0..nd).map(|i| f[i] - (0..nd).map(|j| ke[i * nd + j] * u[j]).sum::<f64>()),
                    )
                };
                let ratio = gap(1e-3) / gap(5e-4);
                assert!(
                    (ratio - 4.0).abs() < 0.04,
                    "{kind:?} {law:?}: ratio {ratio}"
                );
            }
        }
    }

    /// A cell turned inside out is refused with the point where `det F <= 0`, never a NaN.
    #[test]
    fn inverted_cells_are_refused() {
        for kind in KINDS {
            let coords = distorted(kind);
            // mirror x: x = -X, so det F = -1
            let mirror = Matrix3::from_diagonal(&Vector3::new(-1.0, 1.0, 1.0));
            let u = homogeneous(&coords, &mirror, [0.0; 3]);
            let rule = kind.stiffness_rule();
            let nd = 3 * kind.node_count();
            for law in laws() {
                let (mut f, mut k) = (vec![0.0; nd], vec![0.0; nd * nd]);
                let err = element_residual_and_tangent3(
                    kind, &coords, &u, &law, &rule, true, &mut f, &mut k,
                )
                .unwrap_err();
                assert_eq!(err.point, 0);
                assert!((err.det_f + 1.0).abs() < 1e-12, "{err}");
                assert!(err.to_string().contains("det F = -1.000e0 <= 0"), "{err}");
                assert!(element_energy3(kind, &coords, &u, &law, &rule).is_err());
            }
        }
    }
}
