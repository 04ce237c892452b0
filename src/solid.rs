//! Small-strain isotropic linear elasticity in 2D: element stiffness, internal force, stress.
//!
//! Voigt notation with engineering shear: `eps = [eps_xx, eps_yy, gamma_xy]`,
//! `sigma = [sigma_xx, sigma_yy, sigma_xy] = D eps`, with
//! plane strain `D = [[l+2m, l, 0], [l, l+2m, 0], [0, 0, m]]` (Lame l, m) and
//! plane stress `D = E/(1-nu^2) [[1, nu, 0], [nu, 1, 0], [0, 0, (1-nu)/2]]`.
//! The element stiffness is `K_e = int B^T D B t dA` with `B_a = [[N_a,x, 0], [0, N_a,y],
//! [N_a,y, N_a,x]]`, evaluated with the element's stiffness rule (see `fe`); the internal force
//! is `K_e u_e`. Out-of-plane stress: `sigma_zz = nu (sigma_xx + sigma_yy)` in plane strain,
//! zero in plane stress.

use crate::fe::{point_values, ElementKind, QuadPoint, MAX_NODES};
use crate::io::scene::Plane;

/// Largest number of element dofs.
pub const MAX_DOFS: usize = 2 * MAX_NODES;

#[derive(Copy, Clone, Debug, PartialEq)]
pub struct Elasticity {
    pub youngs_modulus: f64,
    pub nu: f64,
    pub plane: Plane,
    pub d: [[f64; 3]; 3],
}

impl Elasticity {
    pub fn new(youngs_modulus: f64, nu: f64, plane: Plane) -> Self {
        let e = youngs_modulus;
        let d = match plane {
            Plane::Strain => {
                let lambda = e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
                let mu = e / (2.0 * (1.0 + nu));
                [
                    [lambda + 2.0 * mu, lambda, 0.0],
                    [lambda, lambda + 2.0 * mu, 0.0],
                    [0.0, 0.0, mu],
                ]
            }
            Plane::Stress => {
                let c = e / (1.0 - nu * nu);
                [
                    [c, c * nu, 0.0],
                    [c * nu, c, 0.0],
                    [0.0, 0.0, c * 0.5 * (1.0 - nu)],
                ]
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
        let d = &self.d;
        [
            d[0][0] * strain[0] + d[0][1] * strain[1] + d[0][2] * strain[2],
            d[1][0] * strain[0] + d[1][1] * strain[1] + d[1][2] * strain[2],
            d[2][0] * strain[0] + d[2][1] * strain[1] + d[2][2] * strain[2],
        ]
    }

    /// In-plane strain that produces the in-plane stress `s` (inverse of `D`).
    pub fn strain_of_stress(&self, s: [f64; 3]) -> [f64; 3] {
        let d = &self.d;
        let det = d[0][0] * d[1][1] - d[0][1] * d[1][0];
        [
            (d[1][1] * s[0] - d[0][1] * s[1]) / det,
            (-d[1][0] * s[0] + d[0][0] * s[1]) / det,
            s[2] / d[2][2],
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

/// An element whose Jacobian is not positive somewhere.
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct BadGeometry {
    pub det_j: f64,
    pub at: [f64; 2],
    pub inverted: bool,
}

/// Check that `det J` is positive (relative to the element size) at the nodes and the
/// quadrature points of the stiffness rule.
pub fn check_geometry(kind: ElementKind, coords: &[[f64; 2]]) -> Result<(), BadGeometry> {
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for p in coords {
        for i in 0..2 {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    }
    let scale = ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2)).max(f64::MIN_POSITIVE);
    let points = kind
        .node_coordinates()
        .iter()
        .copied()
        .chain(kind.stiffness_rule().into_iter().map(|q| q.xi));
    for xi in points {
        let pv = point_values(kind, coords, xi);
        if pv.det_j.is_nan() || pv.det_j <= 1e-10 * scale {
            return Err(BadGeometry {
                det_j: pv.det_j,
                at: pv.x,
                inverted: pv.det_j < 0.0,
            });
        }
    }
    Ok(())
}

/// Element stiffness `K_e` (row-major, `2 n x 2 n`, dof order `[u_x0, u_y0, u_x1, ...]`).
pub fn element_stiffness(
    kind: ElementKind,
    coords: &[[f64; 2]],
    material: &Elasticity,
    thickness: f64,
    rule: &[QuadPoint],
    ke: &mut [f64],
) {
    let nn = kind.node_count();
    let nd = 2 * nn;
    ke[..nd * nd].iter_mut().for_each(|v| *v = 0.0);
    let d = &material.d;
    for q in rule {
        let pv = point_values(kind, coords, q.xi);
        let w = q.weight * pv.det_j * thickness;
        for b in 0..nn {
            let [bx, by] = pv.dndx[b];
            // D B_b (3 x 2)
            let db = [
                [d[0][0] * bx + d[0][2] * by, d[0][1] * by + d[0][2] * bx],
                [d[1][0] * bx + d[1][2] * by, d[1][1] * by + d[1][2] * bx],
                [d[2][0] * bx + d[2][2] * by, d[2][1] * by + d[2][2] * bx],
            ];
            for a in 0..nn {
                let [ax, ay] = pv.dndx[a];
                // B_a^T (D B_b)
                let k00 = ax * db[0][0] + ay * db[2][0];
                let k01 = ax * db[0][1] + ay * db[2][1];
                let k10 = ay * db[1][0] + ax * db[2][0];
                let k11 = ay * db[1][1] + ax * db[2][1];
                let (r, c) = (2 * a, 2 * b);
                ke[r * nd + c] += w * k00;
                ke[r * nd + c + 1] += w * k01;
                ke[(r + 1) * nd + c] += w * k10;
                ke[(r + 1) * nd + c + 1] += w * k11;
            }
        }
    }
}

/// Strain `[eps_xx, eps_yy, gamma_xy]` at natural point `xi` for element displacements `ue`.
pub fn strain_at(
    kind: ElementKind,
    coords: &[[f64; 2]],
    ue: &[f64],
    xi: [f64; 2],
) -> ([f64; 3], [f64; 2]) {
    let pv = point_values(kind, coords, xi);
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
    fn inverted_and_degenerate_elements_are_detected() {
        let good = vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        assert!(check_geometry(ElementKind::Q4, &good).is_ok());
        let clockwise = vec![[0.0, 0.0], [0.0, 1.0], [1.0, 1.0], [1.0, 0.0]];
        assert!(
            check_geometry(ElementKind::Q4, &clockwise)
                .unwrap_err()
                .inverted
        );
        let collapsed = vec![[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]];
        let err = check_geometry(ElementKind::T3, &collapsed).unwrap_err();
        assert!(!err.inverted && err.det_j.abs() < 1e-12);
        // a bow-tie (non-convex beyond repair) is inverted somewhere inside
        let bowtie = vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]];
        assert!(check_geometry(ElementKind::Q4, &bowtie).is_err());
    }
}
