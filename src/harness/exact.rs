//! Analytic reference solutions for verification.
//!
//! * Uniform stress `sigma_0`: strain `eps_0 = D^-1 sigma_0`, displacement
//!   `u = [eps_xx x + gamma/2 y, gamma/2 x + eps_yy y]` (no rigid motion). Any isoparametric mesh
//!   must reproduce it exactly (the single-body patch test).
//! * Timoshenko & Goodier's cantilever (Theory of Elasticity, 1970, sec. 21), plane stress with
//!   `I = D^3/12`, x in [0, L], y in [-D/2, D/2]:
//!   `u_x = -P y / (6 E I) [(6L - 3x) x + (2 + nu)(y^2 - D^2/4)]`,
//!   `u_y =  P / (6 E I) [3 nu y^2 (L - x) + (4 + 5 nu) D^2 x / 4 + (3L - x) x^2]`,
//!   `sigma_xx = -P (L - x) y / I`, `sigma_yy = 0`, `sigma_xy = P / (2 I) (D^2/4 - y^2)`.
//!   It is cubic, so Q4/T3 converge as h^2 and Q9/T6 as h^3 in the L2 norm of displacement.
//!   Plane strain uses `E/(1 - nu^2)` and `nu/(1 - nu)` in the same formulas.
//! * Hertz's contact of a rigid cylinder (radius `R`) on an elastic half-space, per unit
//!   thickness under the normal load `P` (K. L. Johnson, *Contact Mechanics*, 1985, sec. 4.2,
//!   eqs. 4.43 and 4.45, with a rigid indenter): half-width `a = sqrt(4 P R / (pi E*))`, pressure
//!   `p(x) = p0 sqrt(1 - x^2/a^2)` for `|x| <= a` (zero outside), `p0 = 2 P / (pi a)`, with
//!   `E* = E/(1 - nu^2)` in plane strain and `E` in plane stress.

use crate::io::scene::ExactSpec;
use crate::solid::Elasticity;

#[derive(Clone, Debug, PartialEq)]
pub enum ExactField {
    UniformStress { stress: [f64; 3] },
    TimoshenkoCantilever { load: f64, length: f64, depth: f64 },
}

impl From<&ExactSpec> for ExactField {
    fn from(spec: &ExactSpec) -> Self {
        match *spec {
            ExactSpec::UniformStress { stress } => ExactField::UniformStress { stress },
            ExactSpec::TimoshenkoCantilever {
                load,
                length,
                depth,
            } => ExactField::TimoshenkoCantilever {
                load,
                length,
                depth,
            },
        }
    }
}

impl ExactField {
    pub fn displacement(&self, p: [f64; 2], mat: &Elasticity) -> [f64; 2] {
        let [x, y] = p;
        match *self {
            ExactField::UniformStress { stress } => {
                let e = mat.strain_of_stress(stress);
                [e[0] * x + 0.5 * e[2] * y, 0.5 * e[2] * x + e[1] * y]
            }
            ExactField::TimoshenkoCantilever {
                load,
                length,
                depth,
            } => {
                let (e, nu) = mat.plane_stress_equivalent();
                let i = depth.powi(3) / 12.0;
                let c = load / (6.0 * e * i);
                let d2 = depth * depth / 4.0;
                [
                    -c * y * ((6.0 * length - 3.0 * x) * x + (2.0 + nu) * (y * y - d2)),
                    c * (3.0 * nu * y * y * (length - x)
                        + (4.0 + 5.0 * nu) * d2 * x
                        + (3.0 * length - x) * x * x),
                ]
            }
        }
    }

    pub fn stress(&self, p: [f64; 2]) -> [f64; 3] {
        let [x, y] = p;
        match *self {
            ExactField::UniformStress { stress } => stress,
            ExactField::TimoshenkoCantilever {
                load,
                length,
                depth,
            } => {
                let i = depth.powi(3) / 12.0;
                [
                    -load * (length - x) * y / i,
                    0.0,
                    load / (2.0 * i) * (depth * depth / 4.0 - y * y),
                ]
            }
        }
    }
}

/// Hertz's pressure under a rigid cylinder on an elastic half-space (see the module notes).
#[derive(Copy, Clone, Debug, PartialEq)]
pub struct HertzCylinder {
    /// Normal load per unit thickness `P`.
    pub load: f64,
    pub radius: f64,
    /// `E*` (plane strain `E/(1 - nu^2)`, plane stress `E`).
    pub modulus: f64,
}

impl HertzCylinder {
    /// The half-width `a`.
    pub fn half_width(&self) -> f64 {
        (4.0 * self.load * self.radius / (std::f64::consts::PI * self.modulus)).sqrt()
    }

    /// The peak pressure `p0`.
    pub fn peak(&self) -> f64 {
        2.0 * self.load / (std::f64::consts::PI * self.half_width())
    }

    /// `p(x)`, `x` measured from the first point of contact.
    pub fn pressure(&self, x: f64) -> f64 {
        let a = self.half_width();
        self.peak() * (1.0 - (x / a).powi(2)).max(0.0).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::io::scene::Plane;

    /// The exact fields are compatible: the strain of the displacement, through D, gives the stress.
    #[test]
    fn displacement_and_stress_agree() {
        let fields = [
            ExactField::UniformStress {
                stress: [1.0, -2.0, 0.5],
            },
            ExactField::TimoshenkoCantilever {
                load: 3.0,
                length: 8.0,
                depth: 2.0,
            },
        ];
        for plane in [Plane::Strain, Plane::Stress] {
            let mat = Elasticity::new(1000.0, 0.3, plane);
            for f in &fields {
                for p in [[0.3, 0.2], [5.0, -0.7], [7.9, 0.99]] {
                    let h = 1e-5;
                    let du = |k: usize, i: usize| {
                        let mut a = p;
                        let mut b = p;
                        a[k] += h;
                        b[k] -= h;
                        (f.displacement(a, &mat)[i] - f.displacement(b, &mat)[i]) / (2.0 * h)
                    };
                    let strain = [du(0, 0), du(1, 1), du(1, 0) + du(0, 1)];
                    let s = mat.stress(strain);
                    let se = f.stress(p);
                    for i in 0..3 {
                        assert!(
                            (s[i] - se[i]).abs() < 1e-6 * (1.0 + se[i].abs()),
                            "{f:?} {plane:?} {i}: {} vs {}",
                            s[i],
                            se[i]
                        );
                    }
                }
            }
        }
    }

    /// The pressure integrates to the load (P = pi a p0 / 2) and the numbers of the committed
    /// cylinder cases (P = 4, R = 10, E = 200, nu = 0.3, plane strain: a = 0.48138, p0 = 5.2899).
    #[test]
    fn hertz_pressure_integrates_to_the_load() {
        let h = HertzCylinder {
            load: 4.0,
            radius: 10.0,
            modulus: 200.0 / (1.0 - 0.09),
        };
        let a = h.half_width();
        assert!((a - 0.48138).abs() < 5e-6, "{a}");
        assert!((h.peak() - 5.2899).abs() < 5e-5, "{}", h.peak());
        // midpoint rule in the angle: x = a sin(theta), p dx = p0 a cos^2(theta) dtheta
        let n = 2000;
        let total: f64 = (0..n)
            .map(|k| {
                let th = -std::f64::consts::FRAC_PI_2
                    + (k as f64 + 0.5) * std::f64::consts::PI / n as f64;
                h.pressure(a * th.sin()) * a * th.cos() * std::f64::consts::PI / n as f64
            })
            .sum();
        assert!((total - 4.0).abs() < 1e-6, "{total}");
        assert_eq!(h.pressure(1.01 * a), 0.0);
    }
}
