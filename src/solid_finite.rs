//! Finite-deformation (total-Lagrangian) plane-strain solids: hyperelastic energy, element
//! residual and consistent tangent, Cauchy stress.
//!
//! **Kinematics.** With reference coordinates `X` and displacement `u`, the deformation
//! gradient is `F = I + H`, `H = du/dX = sum_a u_a (dN_a/dX)^T`, extended to plane strain by
//! `F_33 = 1` (`F_13 = F_31 = F_23 = F_32 = 0`). The right Cauchy-Green tensor is `C = F^T F`
//! (in-plane block, `C_33 = 1`), the Green-Lagrange strain `E = (C - I) / 2` (`E_33 = 0`) and
//! `J = det F` (the in-plane determinant, since `F_33 = 1`). Both are computed from `H`
//! (`E = (H + H^T + H^T H) / 2`, `ln J = ln_1p(tr H + det H)`), not from `F`, so that a lightly
//! loaded body keeps the round-off of small strain.
//!
//! **Materials** (Lamé constants from `E, nu`: `lambda = E nu / ((1 + nu)(1 - 2 nu))`,
//! `mu = E / (2 (1 + nu))`), energy per reference volume:
//!
//! * compressible neo-Hookean, `W = mu/2 (I_1 - 3 - 2 ln J) + lambda/2 (ln J)^2` with
//!   `I_1 = tr C + 1` the three-dimensional trace (`C_33 = 1`), so
//!   `S = 2 dW/dC = mu (I - C^-1) + lambda ln J C^-1` (in-plane; `S_33 = lambda ln J`) and
//!   `CC_ijkl = lambda C^-1_ij C^-1_kl + (mu - lambda ln J) (C^-1_ik C^-1_jl + C^-1_il C^-1_jk)`
//!   (Bonet & Wood, *Nonlinear Continuum Mechanics for Finite Element Analysis*, 2nd ed.,
//!   eqs. 6.28 and 6.40; plane strain as in their section 6.6);
//! * St. Venant-Kirchhoff, `W = lambda/2 (tr E)^2 + mu E:E`, `S = lambda tr E I + 2 mu E`,
//!   `CC = lambda I (x) I + 2 mu II` (constant: the plane-strain `D` of small strain), and
//!   `S_33 = lambda tr E`.
//!
//! Both reduce to small-strain plane-strain elasticity at `F = I` (same `D`), so the finite
//! and small-strain solutions agree to first order in the load.
//!
//! **Element.** At a quadrature point with weight `w = w_q det J_0 t` (reference configuration),
//! the internal force and the tangent (Bonet & Wood, chapter 9; Wriggers, *Nonlinear Finite
//! Element Methods*, section 4.2) are
//!
//! `f_a = sum_q w F S grad_0 N_a`,
//! `K_ab = sum_q w [B_a^T D B_b + (grad_0 N_a . S grad_0 N_b) I_2]`,
//!
//! material plus geometric part, with Voigt `S = [S_11, S_22, S_12]`,
//! `D_IJ = CC_ijkl` (`I, J` over `11, 22, 12`, engineering shear) and the nonlinear
//! strain-displacement matrix (`dE = B_a du_a`, `N_a,k = dN_a/dX_k`)
//! `B_a = [[F_11 N_a,1, F_21 N_a,1], [F_12 N_a,2, F_22 N_a,2],
//!        [F_11 N_a,2 + F_12 N_a,1, F_21 N_a,2 + F_22 N_a,1]]`.
//! `f` is the gradient of the element energy `sum_q w W(C)` and `K` the gradient of `f`
//! (finite-difference checks below). A quadrature point with `J <= 0` (an inverted element)
//! is refused ([`Inverted`]): the energy is not defined there (`ln J`).
//!
//! **Stress.** The Cauchy stress on the deformed configuration is
//! `sigma = F S F^T / J`, `sigma_33 = S_33 / J`.

use crate::fe::{
    displacement_gradient_at, field_gradient, ElementKind, QuadPoint, ReferenceCell, MAX_NODES,
};
use crate::solid::{ElementMatrix, ElementVector};
use nalgebra::{Matrix2, Matrix3, Matrix3x2, Vector2};

/// The hyperelastic energy of a body under finite deformation.
#[derive(Copy, Clone, Debug, PartialEq)]
pub enum Hyperelastic {
    /// `W = mu/2 (I_1 - 3 - 2 ln J) + lambda/2 (ln J)^2`.
    NeoHookean { lambda: f64, mu: f64 },
    /// `W = lambda/2 (tr E)^2 + mu E:E`.
    SaintVenantKirchhoff { lambda: f64, mu: f64 },
}

/// The Lamé constants `(lambda, mu)` of Young's modulus `E` and Poisson's ratio `nu`.
pub fn lame(youngs_modulus: f64, nu: f64) -> (f64, f64) {
    (
        youngs_modulus * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
        youngs_modulus / (2.0 * (1.0 + nu)),
    )
}

/// Stress state of one deformation gradient: second Piola-Kirchhoff stress (in-plane and
/// out-of-plane) and the Voigt tangent `D = dS/dE`.
#[derive(Copy, Clone, Debug)]
pub struct MaterialPoint {
    pub s: Matrix2<f64>,
    pub s33: f64,
    pub d: Matrix3<f64>,
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

    /// Energy per reference volume at the in-plane displacement gradient `h = F - I`
    /// (`det F > 0`).
    pub fn energy(&self, h: &Matrix2<f64>) -> f64 {
        let (e, ln_j) = green_lagrange(h);
        match *self {
            // I_1 - 3 = tr C - 2 = 2 tr E
            Hyperelastic::NeoHookean { lambda, mu } => {
                mu * (e.trace() - ln_j) + 0.5 * lambda * ln_j * ln_j
            }
            Hyperelastic::SaintVenantKirchhoff { lambda, mu } => {
                0.5 * lambda * e.trace().powi(2) + mu * e.component_mul(&e).sum()
            }
        }
    }

    /// `S`, `S_33` and `D` at the in-plane displacement gradient `h = F - I` (`det F > 0`).
    pub fn material_point(&self, h: &Matrix2<f64>) -> MaterialPoint {
        let (e, ln_j) = green_lagrange(h);
        match *self {
            Hyperelastic::NeoHookean { lambda, mu } => {
                let ci = inverse2(&(Matrix2::identity() + e * 2.0));
                // mu (I - C^-1) + lambda ln J C^-1 = C^-1 (2 mu E + lambda ln J I), free of the
                // cancellation of I - C^-1 at small strain
                let s = ci * (e * (2.0 * mu) + Matrix2::identity() * (lambda * ln_j));
                let s = (s + s.transpose()) * 0.5;
                let m = mu - lambda * ln_j;
                // CC_ijkl = lambda ci_ij ci_kl + m (ci_ik ci_jl + ci_il ci_jk), Voigt 11, 22, 12
                let index = [(0, 0), (1, 1), (0, 1)];
                let d = Matrix3::from_fn(|p, q| {
                    let (i, j) = index[p];
                    let (k, l) = index[q];
                    lambda * ci[(i, j)] * ci[(k, l)]
                        + m * (ci[(i, k)] * ci[(j, l)] + ci[(i, l)] * ci[(j, k)])
                });
                MaterialPoint {
                    s,
                    s33: lambda * ln_j,
                    d,
                }
            }
            Hyperelastic::SaintVenantKirchhoff { lambda, mu } => {
                let s = Matrix2::identity() * (lambda * e.trace()) + e * (2.0 * mu);
                #[rustfmt::skip]
                let d = Matrix3::new(
                    lambda + 2.0 * mu, lambda, 0.0,
                    lambda, lambda + 2.0 * mu, 0.0,
                    0.0, 0.0, mu,
                );
                MaterialPoint {
                    s,
                    s33: lambda * e.trace(),
                    d,
                }
            }
        }
    }

    /// Cauchy stress `[sigma_xx, sigma_yy, sigma_xy]` and `sigma_zz` at the in-plane
    /// displacement gradient `h = F - I`: `sigma = F S F^T / J`, `sigma_33 = S_33 / J`.
    pub fn cauchy(&self, h: &Matrix2<f64>) -> ([f64; 3], f64) {
        let f = Matrix2::identity() + h;
        let j = jacobian(h);
        let p = self.material_point(h);
        let sigma = f * p.s * f.transpose() / j;
        ([sigma[(0, 0)], sigma[(1, 1)], sigma[(0, 1)]], p.s33 / j)
    }
}

/// The Green-Lagrange strain `E = (H + H^T + H^T H) / 2` and `ln J` (`J = 1 + tr H + det H`,
/// through `ln_1p`) from the displacement gradient `H`, without the cancellation of
/// `(F^T F - I) / 2` and `ln det F` at small strain (which would put a round-off floor of
/// `E eps` under the residual of a lightly loaded body).
fn green_lagrange(h: &Matrix2<f64>) -> (Matrix2<f64>, f64) {
    let e = (h + h.transpose() + h.transpose() * h) * 0.5;
    (e, (h.trace() + det2(h)).ln_1p())
}

/// `J = det F = 1 + tr H + det H`.
#[inline(always)]
pub fn jacobian(h: &Matrix2<f64>) -> f64 {
    1.0 + h.trace() + det2(h)
}

/// `det m` of a 2x2 matrix.
#[inline(always)]
pub fn det2(m: &Matrix2<f64>) -> f64 {
    m[(0, 0)] * m[(1, 1)] - m[(0, 1)] * m[(1, 0)]
}

/// `m^-1` of a 2x2 matrix (`det m != 0`).
#[inline(always)]
fn inverse2(m: &Matrix2<f64>) -> Matrix2<f64> {
    Matrix2::new(m[(1, 1)], -m[(0, 1)], -m[(1, 0)], m[(0, 0)]) / det2(m)
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
pub fn deformation_gradient_at(
    kind: ElementKind,
    coords: &[[f64; 2]],
    u_e: &[f64],
    xi: [f64; 2],
) -> (Matrix2<f64>, [f64; 2]) {
    let (h, x) = displacement_gradient_at(kind, coords, u_e, xi);
    (Matrix2::identity() + h, x)
}

/// The reference gradients and weights `w = w_q det J_0 t` of the rule's points, and `H` there;
/// `Err` at the first point with `det F <= 0`.
fn points(
    kind: ElementKind,
    coords: &[[f64; 2]],
    u_e: &[f64],
    thickness: f64,
    rule: &[QuadPoint],
    mut visit: impl FnMut(&[[f64; 2]], f64, &Matrix2<f64>),
) -> Result<(), Inverted> {
    let n = kind.node_count();
    for (q, point) in rule.iter().enumerate() {
        let pv = kind.point_values(coords, point.xi);
        if pv.det_j == 0.0 {
            continue;
        }
        let h = field_gradient(&pv.dndx[..n], u_e);
        let det_f = jacobian(&h);
        if det_f.is_nan() || det_f <= 0.0 {
            return Err(Inverted {
                point: q,
                at: pv.x,
                det_f,
            });
        }
        visit(&pv.dndx[..n], point.weight * pv.det_j * thickness, &h);
    }
    Ok(())
}

/// The element's stored energy `sum_q w W(C)` at the displacements `u_e`.
pub fn element_energy(
    kind: ElementKind,
    coords: &[[f64; 2]],
    u_e: &[f64],
    law: &Hyperelastic,
    thickness: f64,
    rule: &[QuadPoint],
) -> Result<f64, Inverted> {
    let mut energy = 0.0;
    points(kind, coords, u_e, thickness, rule, |_, w, h| {
        energy += w * law.energy(h)
    })?;
    Ok(energy)
}

/// `B_a` of the module docs: `dE (Voigt, engineering shear) = B_a du_a`.
#[inline(always)]
fn strain_displacement(f: &Matrix2<f64>, g: [f64; 2]) -> Matrix3x2<f64> {
    let (g1, g2) = (g[0], g[1]);
    Matrix3x2::new(
        f[(0, 0)] * g1,
        f[(1, 0)] * g1,
        f[(0, 1)] * g2,
        f[(1, 1)] * g2,
        f[(0, 0)] * g2 + f[(0, 1)] * g1,
        f[(1, 0)] * g2 + f[(1, 1)] * g1,
    )
}

/// Internal force `f_a = sum_q w F S grad_0 N_a` and, with `with_tangent`, the consistent
/// tangent `K_ab` (material + geometric) of one element at the displacements `u_e`; the
/// leading `2 n` entries are the element's.
pub fn element_residual_and_tangent(
    kind: ElementKind,
    coords: &[[f64; 2]],
    u_e: &[f64],
    law: &Hyperelastic,
    thickness: f64,
    rule: &[QuadPoint],
    with_tangent: bool,
) -> Result<(ElementVector, ElementMatrix), Inverted> {
    let mut force = ElementVector::zeros();
    let mut k = ElementMatrix::zeros();
    let n = kind.node_count();
    debug_assert!(n <= MAX_NODES);
    points(kind, coords, u_e, thickness, rule, |dndx, w, h| {
        let mp = law.material_point(h);
        let f = &(Matrix2::identity() + h);
        let p = f * mp.s;
        for (a, g) in dndx.iter().enumerate() {
            let fa = p * Vector2::new(g[0], g[1]) * w;
            force[2 * a] += fa[0];
            force[2 * a + 1] += fa[1];
        }
        if !with_tangent {
            return;
        }
        let s_voigt = mp.s;
        for (b, gb) in dndx.iter().enumerate() {
            let db = mp.d * strain_displacement(f, *gb);
            let s_gb = s_voigt * Vector2::new(gb[0], gb[1]);
            for (a, ga) in dndx.iter().enumerate() {
                let material = strain_displacement(f, *ga).tr_mul(&db);
                let geometric = ga[0] * s_gb[0] + ga[1] * s_gb[1];
                let mut block = k.fixed_view_mut::<2, 2>(2 * a, 2 * b);
                block += (material + Matrix2::identity() * geometric) * w;
            }
        }
    })?;
    Ok((force, k))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::scene::Plane;
    use crate::solid::{element_stiffness, Elasticity};

    const KINDS: [ElementKind; 4] = [
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
    fn distorted(kind: ElementKind) -> Vec<[f64; 2]> {
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

    /// Displacements of a finite deformation (stretch, shear and rotation of order 0.2, plus
    /// a nonuniform part), with `det F > 0` everywhere.
    fn deformed(kind: ElementKind, coords: &[[f64; 2]]) -> Vec<f64> {
        let (c, s) = (0.4f64.cos(), 0.4f64.sin());
        let a = Matrix2::new(1.15, 0.2, -0.05, 0.85);
        let r = Matrix2::new(c, -s, s, c);
        let f = r * a;
        let mut u = Vec::new();
        for (i, p) in coords.iter().enumerate().take(kind.node_count()) {
            let x = Vector2::new(p[0], p[1]);
            let y = f * x - x;
            u.push(y[0] + 0.02 * (1.3 * i as f64).sin());
            u.push(y[1] + 0.02 * (0.7 * i as f64 + 0.5).cos());
        }
        u
    }

    fn largest(v: impl IntoIterator<Item = f64>) -> f64 {
        v.into_iter().fold(0.0, |m, x| m.max(x.abs()))
    }

    fn force(
        kind: ElementKind,
        coords: &[[f64; 2]],
        u: &[f64],
        law: &Hyperelastic,
    ) -> ElementVector {
        let rule = kind.stiffness_rule();
        element_residual_and_tangent(kind, coords, u, law, THICKNESS, &rule, false)
            .expect("not inverted")
            .0
    }

    /// `f = dPi/du` and `K = df/du` by central differences at a finite deformation, every
    /// element and both materials, to 1e-7 relative; `K` is symmetric.
    #[test]
    fn residual_is_the_energy_gradient_and_tangent_the_residual_gradient() {
        for law in laws() {
            for kind in KINDS {
                let coords = distorted(kind);
                let rule = kind.stiffness_rule();
                let nd = 2 * kind.node_count();
                let u = deformed(kind, &coords);
                let (f, k) =
                    element_residual_and_tangent(kind, &coords, &u, &law, THICKNESS, &rule, true)
                        .unwrap();
                let f_scale = largest(f.iter().copied());
                let k_scale = largest(k.iter().copied());
                assert!(f_scale > 1.0, "{kind:?}: the state is stressed");
                let h = 1e-6;
                let (mut worst_f, mut worst_k) = (0.0f64, 0.0f64);
                for j in 0..nd {
                    let (mut up, mut um) = (u.clone(), u.clone());
                    up[j] += h;
                    um[j] -= h;
                    let energy = |v: &[f64]| {
                        element_energy(kind, &coords, v, &law, THICKNESS, &rule).unwrap()
                    };
                    let de = (energy(&up) - energy(&um)) / (2.0 * h);
                    worst_f = worst_f.max((de - f[j]).abs() / f_scale);
                    let column = (force(kind, &coords, &up, &law)
                        - force(kind, &coords, &um, &law))
                        / (2.0 * h);
                    for i in 0..nd {
                        worst_k = worst_k.max((column[i] - k[(i, j)]).abs() / k_scale);
                    }
                }
                println!("{kind:?} {law:?}: f vs dPi/du {worst_f:.1e}, K vs df/du {worst_k:.1e}");
                assert!(worst_f < 1e-7, "{kind:?} {law:?}: f vs dPi/du {worst_f:e}");
                assert!(worst_k < 1e-7, "{kind:?} {law:?}: K vs df/du {worst_k:e}");
                for i in 0..nd {
                    for j in 0..nd {
                        assert!((k[(i, j)] - k[(j, i)]).abs() <= 1e-13 * k_scale);
                    }
                }
                assert!(f.rows(nd, f.len() - nd).iter().all(|&v| v == 0.0));
            }
        }
    }

    /// `int_{boundary} N_a P N t dS` for a constant first Piola stress `P` on the reference
    /// element edges (`N dS = [dY, -dX]`).
    fn boundary_force(kind: ElementKind, coords: &[[f64; 2]], p: &Matrix2<f64>) -> Vec<f64> {
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

    /// A homogeneous deformation `x = F X + c` is represented exactly: `F` at every quadrature
    /// point to 1e-13, and the internal force is the boundary integral of the constant traction
    /// `P N` (`P = F S`), so a patch of such elements is in equilibrium inside.
    #[test]
    fn a_homogeneous_deformation_is_exact_on_distorted_elements() {
        let target = Matrix2::new(1.2, 0.15, -0.1, 0.8);
        let c = [0.3, -0.2];
        for law in laws() {
            for kind in KINDS {
                let coords = distorted(kind);
                let u: Vec<f64> = coords
                    .iter()
                    .flat_map(|p| {
                        let x = target * Vector2::new(p[0], p[1]);
                        [x[0] + c[0] - p[0], x[1] + c[1] - p[1]]
                    })
                    .collect();
                for q in kind.stiffness_rule() {
                    let (f, _) = deformation_gradient_at(kind, &coords, &u, q.xi);
                    assert!((f - target).abs().max() < 1e-13, "{kind:?}: {f}");
                }
                let p = target * law.material_point(&(target - Matrix2::identity())).s;
                let expected = boundary_force(kind, &coords, &p);
                let got = force(kind, &coords, &u, &law);
                let scale = largest(expected.iter().copied());
                for (i, want) in expected.iter().enumerate() {
                    assert!(
                        (got[i] - want).abs() < 1e-12 * scale,
                        "{kind:?} {law:?}: f[{i}] = {} vs {want}",
                        got[i]
                    );
                }
            }
        }
    }

    /// The Cauchy stress of a plane-strain stretch `F = diag(a, b)` in closed form:
    /// neo-Hookean `sigma_ii = (mu (F_ii^2 - 1) + lambda ln J) / J`, `sigma_33 = lambda ln J / J`;
    /// St. Venant-Kirchhoff `sigma_ii = F_ii^2 (lambda (E_11 + E_22) + 2 mu E_ii) / J`.
    #[test]
    fn cauchy_stress_of_a_stretch_has_its_closed_form() {
        let (a, b) = (1.3, 0.8);
        let f = Matrix2::new(a, 0.0, 0.0, b);
        let j: f64 = a * b;
        let (lambda, mu) = lame(E, NU);
        let (nh, nh33) = Hyperelastic::neo_hookean(E, NU).cauchy(&(f - Matrix2::identity()));
        let expected = [
            (mu * (a * a - 1.0) + lambda * j.ln()) / j,
            (mu * (b * b - 1.0) + lambda * j.ln()) / j,
            0.0,
        ];
        for i in 0..3 {
            assert!(
                (nh[i] - expected[i]).abs() < 1e-12 * E,
                "{nh:?} {expected:?}"
            );
        }
        assert!((nh33 - lambda * j.ln() / j).abs() < 1e-12 * E);
        let (e1, e2) = (0.5 * (a * a - 1.0), 0.5 * (b * b - 1.0));
        let (sv, sv33) =
            Hyperelastic::saint_venant_kirchhoff(E, NU).cauchy(&(f - Matrix2::identity()));
        let expected = [
            a * a * (lambda * (e1 + e2) + 2.0 * mu * e1) / j,
            b * b * (lambda * (e1 + e2) + 2.0 * mu * e2) / j,
            0.0,
        ];
        for i in 0..3 {
            assert!(
                (sv[i] - expected[i]).abs() < 1e-12 * E,
                "{sv:?} {expected:?}"
            );
        }
        assert!((sv33 - lambda * (e1 + e2) / j).abs() < 1e-12 * E);
    }

    /// Objectivity: a rigid rotation (here 90 degrees, in ten steps, each state checked) gives
    /// no internal force and no stress; a rotation `R` of a stretched state rotates its Cauchy
    /// stress, `sigma(R F) = R sigma(F) R^T`, and leaves `S` unchanged.
    #[test]
    fn rigid_rotations_are_stress_free_and_rotate_the_stress() {
        for law in laws() {
            for kind in KINDS {
                let coords = distorted(kind);
                for step in 1..=10 {
                    let angle = std::f64::consts::FRAC_PI_2 * step as f64 / 10.0;
                    let r = Matrix2::new(angle.cos(), -angle.sin(), angle.sin(), angle.cos());
                    let u: Vec<f64> = coords
                        .iter()
                        .flat_map(|p| {
                            let x = Vector2::new(p[0], p[1]);
                            let y = r * x - x;
                            [y[0], y[1]]
                        })
                        .collect();
                    let f = force(kind, &coords, &u, &law);
                    assert!(
                        largest(f.iter().copied()) < 1e-12 * E,
                        "{kind:?} {angle}: {f}"
                    );
                    let (fg, _) = deformation_gradient_at(kind, &coords, &u, [0.1, 0.2]);
                    let (sigma, zz) = law.cauchy(&(fg - Matrix2::identity()));
                    assert!(largest(sigma) < 1e-12 * E && zz.abs() < 1e-12 * E);
                }
            }
            let f = Matrix2::new(1.2, 0.15, -0.1, 0.8);
            let r = Matrix2::new(0.0, -1.0, 1.0, 0.0);
            let (s0, z0) = law.cauchy(&(f - Matrix2::identity()));
            let (s1, z1) = law.cauchy(&(r * f - Matrix2::identity()));
            let m0 = Matrix2::new(s0[0], s0[2], s0[2], s0[1]);
            let rotated = r * m0 * r.transpose();
            assert!((rotated[(0, 0)] - s1[0]).abs() < 1e-12 * E);
            assert!((rotated[(1, 1)] - s1[1]).abs() < 1e-12 * E);
            assert!((rotated[(0, 1)] - s1[2]).abs() < 1e-12 * E);
            assert!((z0 - z1).abs() < 1e-12 * E);
        }
    }

    /// The small-strain limit: the tangent at `u = 0` is the small-strain plane-strain `K_e`
    /// (1e-13), and at the displacement `eps u` the internal force differs from `K_e eps u` by
    /// `O(eps^2)`: the ratio of the differences at `eps` and `eps / 2` is 4 (to 1 %).
    #[test]
    fn small_deformations_are_small_strain_elasticity() {
        let linear = Elasticity::new(E, NU, Plane::Strain);
        for law in laws() {
            for kind in KINDS {
                let coords = distorted(kind);
                let rule = kind.stiffness_rule();
                let nd = 2 * kind.node_count();
                let zero = vec![0.0; nd];
                let (f0, k0) = element_residual_and_tangent(
                    kind, &coords, &zero, &law, THICKNESS, &rule, true,
                )
                .unwrap();
                assert!(largest(f0.iter().copied()) == 0.0);
                let mut ke = vec![0.0; nd * nd];
                element_stiffness(kind, &coords, &linear, THICKNESS, &rule, &mut ke);
                let scale = largest(ke.iter().copied());
                for i in 0..nd {
                    for j in 0..nd {
                        assert!((k0[(i, j)] - ke[i * nd + j]).abs() < 1e-13 * scale);
                    }
                }
                let shape = deformed(kind, &coords);
                let gap = |eps: f64| {
                    let u: Vec<f64> = shape.iter().map(|v| eps * v).collect();
                    let f = force(kind, &coords, &u, &law);
                    largest(
                        (0..nd).map(|i| f[i] - (0..nd).map(|j| ke[i * nd + j] * u[j]).sum::<f64>()),
                    )
                };
                let (d1, d2) = (gap(1e-3), gap(5e-4));
                let ratio = d1 / d2;
                assert!(
                    (ratio - 4.0).abs() < 0.04,
                    "{kind:?} {law:?}: ratio {ratio}"
                );
            }
        }
    }

    /// An element turned inside out is refused with the point where `det F <= 0`.
    #[test]
    fn inverted_elements_are_refused() {
        let coords = distorted(ElementKind::Q4);
        // mirror x: x = -X, so det F = -1
        let u: Vec<f64> = coords.iter().flat_map(|p| [-2.0 * p[0], 0.0]).collect();
        let rule = ElementKind::Q4.stiffness_rule();
        for law in laws() {
            let err = element_residual_and_tangent(
                ElementKind::Q4,
                &coords,
                &u,
                &law,
                THICKNESS,
                &rule,
                true,
            )
            .unwrap_err();
            assert_eq!(err.point, 0);
            assert!((err.det_f + 1.0).abs() < 1e-12, "{err}");
            assert!(element_energy(ElementKind::Q4, &coords, &u, &law, THICKNESS, &rule).is_err());
        }
    }
}
