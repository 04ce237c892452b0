//! Small-strain isotropic linear elasticity in 3D: constitutive matrix, element residual and
//! tangent, consistent loads.
//!
//! Voigt notation with engineering shears, `eps = [e_xx, e_yy, e_zz, g_yz, g_xz, g_xy]`
//! (`g_ij = H_ij + H_ji`, `H = du/dx`), `sigma = [s_xx, s_yy, s_zz, s_yz, s_xz, s_xy] = D eps`
//! with `D = lambda m m^T + mu diag(2, 2, 2, 1, 1, 1)`, `m = [1, 1, 1, 0, 0, 0]`,
//! `lambda = E nu / ((1 + nu)(1 - 2 nu))`, `mu = E / (2 (1 + nu))` (e.g. Hughes, The Finite
//! Element Method, 2000, section 2.7).
//!
//! An element contributes `f_int(u_e) = int B^T D eps(u_e) dV` and `K_T = K_e = int B^T D B dV`
//! with `B_a` the `6 x 3` operator `eps = sum_a B_a u_a`, both with the element's stiffness
//! rule ([`crate::fe3d`]), as the 2D kernels of [`crate::solid`] do (there with a thickness).
//! Element algebra is on fixed-size nalgebra types: `D` a `6 x 6` matrix, `B_a` a `6 x 3`
//! matrix, `K_e` accumulated in `3 x 3` node blocks `K_ab += w B_a^T (D B_b)`.
//!
//! Consistent loads: a body force `b(x)` gives `f_a = int N_a b dV` ([`body_force_load`]); a
//! traction `t(x)` on a facet gives `f_a = int N_a t dA` with `dA = |x_s x x_t| ds dt` on the
//! facet's 2D reference element ([`facet_traction_load`]); both with rich rules
//! ([`SolidKind::error_rule`], Gauss 5x5 or Radon's 7-point rule on facets).

use crate::fe::{
    field_gradient, gauss_square, triangle_rule, ElementKind, QuadPoint, ReferenceCell,
};
use crate::fe3d::{SolidKind, MAX_SOLID_NODES};
use nalgebra::{Matrix3, SMatrix, Vector3};

/// The `6 x 6` constitutive matrix.
pub type Stiffness6 = SMatrix<f64, 6, 6>;
/// A `6 x 3` strain-displacement block.
type StrainBlock = SMatrix<f64, 6, 3>;

/// An isotropic linear elastic material in 3D.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Elasticity3 {
    pub youngs_modulus: f64,
    pub nu: f64,
    /// `sigma = D eps` (Voigt order above).
    pub d: Stiffness6,
}

impl Elasticity3 {
    pub fn new(youngs_modulus: f64, nu: f64) -> Self {
        let lambda = youngs_modulus * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
        let mu = youngs_modulus / (2.0 * (1.0 + nu));
        let mut d = Stiffness6::zeros();
        for i in 0..3 {
            for j in 0..3 {
                d[(i, j)] = lambda;
            }
            d[(i, i)] += 2.0 * mu;
            d[(i + 3, i + 3)] = mu;
        }
        Elasticity3 {
            youngs_modulus,
            nu,
            d,
        }
    }

    pub fn stress(&self, strain: [f64; 6]) -> [f64; 6] {
        (self.d * SMatrix::<f64, 6, 1>::from(strain)).into()
    }

    /// Lame's second parameter (the shear modulus).
    pub fn mu(&self) -> f64 {
        self.youngs_modulus / (2.0 * (1.0 + self.nu))
    }

    /// Lame's first parameter.
    pub fn lambda(&self) -> f64 {
        self.youngs_modulus * self.nu / ((1.0 + self.nu) * (1.0 - 2.0 * self.nu))
    }
}

/// `B_a` from the gradient `g = dN_a/dx`: rows `e_xx, e_yy, e_zz, g_yz, g_xz, g_xy`.
#[inline(always)]
fn strain_block(g: [f64; 3]) -> StrainBlock {
    let [x, y, z] = g;
    #[rustfmt::skip]
    let b = StrainBlock::new(
        x, 0.0, 0.0,
        0.0, y, 0.0,
        0.0, 0.0, z,
        0.0, z, y,
        z, 0.0, x,
        y, x, 0.0,
    );
    b
}

/// Voigt strain from the displacement gradient `H` (`H_ij = du_i/dx_j`).
pub fn voigt_strain(h: &Matrix3<f64>) -> [f64; 6] {
    [
        h[(0, 0)],
        h[(1, 1)],
        h[(2, 2)],
        h[(1, 2)] + h[(2, 1)],
        h[(0, 2)] + h[(2, 0)],
        h[(0, 1)] + h[(1, 0)],
    ]
}

/// Element stiffness `K_e = int B^T D B dV` (row-major, `3 n x 3 n`, dof order
/// `[u_x0, u_y0, u_z0, u_x1, ...]`) with the rule `rule`.
pub fn element_stiffness3(
    kind: SolidKind,
    coords: &[[f64; 3]],
    material: &Elasticity3,
    rule: &[QuadPoint<3>],
    ke: &mut [f64],
) {
    let nn = kind.node_count();
    let nd = 3 * nn;
    let ke = &mut ke[..nd * nd];
    ke.fill(0.0);
    let mut blocks = [StrainBlock::zeros(); MAX_SOLID_NODES];
    for q in rule {
        let pv = kind.point_values(coords, q.xi);
        if pv.det_j == 0.0 {
            continue;
        }
        let w = q.weight * pv.det_j;
        for a in 0..nn {
            blocks[a] = strain_block(pv.dndx[a]);
        }
        for b in 0..nn {
            let db = material.d * blocks[b];
            for a in 0..nn {
                let kab: Matrix3<f64> = blocks[a].tr_mul(&db) * w;
                for i in 0..3 {
                    for j in 0..3 {
                        ke[(3 * a + i) * nd + 3 * b + j] += kab[(i, j)];
                    }
                }
            }
        }
    }
}

/// Internal force `f_int(u_e) = int B^T D eps(u_e) dV` of one element (length `3 n`).
pub fn element_internal_force3(
    kind: SolidKind,
    coords: &[[f64; 3]],
    u_e: &[f64],
    material: &Elasticity3,
    rule: &[QuadPoint<3>],
) -> Vec<f64> {
    let nn = kind.node_count();
    let mut f = vec![0.0; 3 * nn];
    for q in rule {
        let pv = kind.point_values(coords, q.xi);
        if pv.det_j == 0.0 {
            continue;
        }
        let eps = voigt_strain(&field_gradient(&pv.dndx[..nn], u_e));
        let w_sigma = material.d * SMatrix::<f64, 6, 1>::from(eps) * (q.weight * pv.det_j);
        for a in 0..nn {
            let fa: Vector3<f64> = strain_block(pv.dndx[a]).tr_mul(&w_sigma);
            for i in 0..3 {
                f[3 * a + i] += fa[i];
            }
        }
    }
    f
}

/// Voigt strain of the element displacements `u_e` at the natural point `xi`, with the point.
pub fn strain_at3(
    kind: SolidKind,
    coords: &[[f64; 3]],
    u_e: &[f64],
    xi: [f64; 3],
) -> ([f64; 6], [f64; 3]) {
    let pv = kind.point_values(coords, xi);
    (
        voigt_strain(&field_gradient(&pv.dndx[..kind.node_count()], u_e)),
        pv.x,
    )
}

/// Consistent nodal forces `f_a = int N_a b(x) dV` of a body force on one element.
pub fn body_force_load(
    kind: SolidKind,
    coords: &[[f64; 3]],
    body_force: &dyn Fn([f64; 3]) -> [f64; 3],
) -> Vec<f64> {
    let nn = kind.node_count();
    let mut f = vec![0.0; 3 * nn];
    for q in kind.error_rule() {
        let pv = kind.point_values(coords, q.xi);
        let b = body_force(pv.x);
        let w = q.weight * pv.det_j;
        for a in 0..nn {
            for i in 0..3 {
                f[3 * a + i] += w * pv.n[a] * b[i];
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

/// Consistent nodal forces `f_a = int N_a t(x, n) dA` of a traction on one facet, whose nodes
/// `coords` are in facet order ([`ReferenceCell::facets`]); `traction` gets the point and the
/// outward unit normal (so a pressure `p` is `|_, n| -p n`).
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

    /// The reference element's nodes under a fixed non-affine distortion (positive volume).
    fn distorted(kind: SolidKind) -> Vec<[f64; 3]> {
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

    fn material() -> Elasticity3 {
        Elasticity3::new(210.0, 0.3)
    }

    fn stiffness(kind: SolidKind) -> (usize, Vec<f64>) {
        let nd = 3 * kind.node_count();
        let mut ke = vec![0.0; nd * nd];
        element_stiffness3(
            kind,
            &distorted(kind),
            &material(),
            &kind.stiffness_rule(),
            &mut ke,
        );
        (nd, ke)
    }

    #[test]
    fn stiffness_is_symmetric_with_six_zero_energy_rigid_modes() {
        for kind in SolidKind::ALL {
            let (nd, ke) = stiffness(kind);
            let largest = ke.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            for a in 0..nd {
                for b in 0..nd {
                    assert!(
                        (ke[a * nd + b] - ke[b * nd + a]).abs() <= 1e-13 * largest,
                        "{kind:?}: K not symmetric at ({a}, {b})"
                    );
                }
            }
            // three translations and three rotations u = w x x give K u = 0
            let coords = distorted(kind);
            let mut modes: Vec<Vec<f64>> = Vec::new();
            for axis in 0..3 {
                let mut u = vec![0.0; nd];
                for a in 0..kind.node_count() {
                    u[3 * a + axis] = 1.0;
                }
                modes.push(u);
                let mut w = Vector3::zeros();
                w[axis] = 1.0;
                let mut u = vec![0.0; nd];
                for (a, p) in coords.iter().enumerate() {
                    let r = w.cross(&Vector3::from(*p));
                    for i in 0..3 {
                        u[3 * a + i] = r[i];
                    }
                }
                modes.push(u);
            }
            for (m, u) in modes.iter().enumerate() {
                for a in 0..nd {
                    let ku: f64 = (0..nd).map(|b| ke[a * nd + b] * u[b]).sum();
                    assert!(
                        ku.abs() <= 1e-12 * largest,
                        "{kind:?}: mode {m} gives K u = {ku} at dof {a}"
                    );
                }
            }
            // and exactly six: the stiffness has rank nd - 6. Gaussian elimination with full
            // pivoting: the pivots after nd - 6 steps are at round-off level.
            let mut a = ke.clone();
            let mut rank = 0;
            let mut used_r = vec![false; nd];
            let mut used_c = vec![false; nd];
            loop {
                let mut best = (0.0, 0, 0);
                for r in 0..nd {
                    for c in 0..nd {
                        if !used_r[r] && !used_c[c] && a[r * nd + c].abs() > best.0 {
                            best = (a[r * nd + c].abs(), r, c);
                        }
                    }
                }
                if best.0 <= 1e-9 * largest {
                    break;
                }
                let (_, pr, pc) = best;
                used_r[pr] = true;
                used_c[pc] = true;
                rank += 1;
                for r in 0..nd {
                    if used_r[r] {
                        continue;
                    }
                    let factor = a[r * nd + pc] / a[pr * nd + pc];
                    for c in 0..nd {
                        a[r * nd + c] -= factor * a[pr * nd + c];
                    }
                }
            }
            assert_eq!(rank, nd - 6, "{kind:?}: rank of K_e");
        }
    }

    #[test]
    fn tangent_is_the_central_difference_of_the_internal_force() {
        for kind in SolidKind::ALL {
            let (nd, ke) = stiffness(kind);
            let coords = distorted(kind);
            let rule = kind.stiffness_rule();
            let u: Vec<f64> = (0..nd)
                .map(|i| 1e-3 * ((i * 7 % 11) as f64 - 5.0))
                .collect();
            let f0 = element_internal_force3(kind, &coords, &u, &material(), &rule);
            let largest = ke.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            // f_int = K_e u_e
            for a in 0..nd {
                let ku: f64 = (0..nd).map(|b| ke[a * nd + b] * u[b]).sum();
                assert!(
                    (f0[a] - ku).abs() <= 1e-12 * largest,
                    "{kind:?}: f_int != K u"
                );
            }
            let h = 1e-6;
            for b in 0..nd {
                let (mut up, mut um) = (u.clone(), u.clone());
                up[b] += h;
                um[b] -= h;
                let fp = element_internal_force3(kind, &coords, &up, &material(), &rule);
                let fm = element_internal_force3(kind, &coords, &um, &material(), &rule);
                for a in 0..nd {
                    let fd = (fp[a] - fm[a]) / (2.0 * h);
                    assert!(
                        (fd - ke[a * nd + b]).abs() <= 1e-7 * largest,
                        "{kind:?}: dF_{a}/du_{b}: {fd} vs {}",
                        ke[a * nd + b]
                    );
                }
            }
        }
    }

    #[test]
    fn a_linear_field_has_the_strain_of_its_gradient_and_stress_d_eps() {
        let h = Matrix3::new(1e-3, 2e-4, -3e-4, 5e-4, -2e-3, 1e-4, -4e-4, 3e-4, 1.5e-3);
        let expected = voigt_strain(&h);
        for kind in SolidKind::ALL {
            let coords = distorted(kind);
            let u: Vec<f64> = coords
                .iter()
                .flat_map(|p| {
                    let v = h * Vector3::from(*p);
                    [v[0], v[1], v[2]]
                })
                .collect();
            let (eps, _) = strain_at3(kind, &coords, &u, [0.1, 0.2, 0.15]);
            for i in 0..6 {
                assert!((eps[i] - expected[i]).abs() < 1e-15, "{kind:?} eps_{i}");
            }
        }
        // uniaxial stress: eps = s/E [1, -nu, -nu, 0, 0, 0] gives sigma = [s, 0, 0, 0, 0, 0]
        let m = material();
        let s = 3.0;
        let e = m.youngs_modulus;
        let sigma = m.stress([s / e, -m.nu * s / e, -m.nu * s / e, 0.0, 0.0, 0.0]);
        assert!((sigma[0] - s).abs() < 1e-13);
        for v in &sigma[1..] {
            assert!(v.abs() < 1e-13);
        }
        // pure shear: sigma_xy = mu gamma_xy
        let sigma = m.stress([0.0, 0.0, 0.0, 0.0, 0.0, 2e-3]);
        assert!((sigma[5] - m.mu() * 2e-3).abs() < 1e-15);
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
            let f = body_force_load(kind, &coords, &|_| [1.0, -2.0, 3.0]);
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
