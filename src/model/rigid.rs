//! Rigid-body modes, and the test whether supports and constraint rows hold them.
//!
//! Body `b` (centre `c`, size `s` of its bounding box) has three rigid modes, written at a node
//! `p` as
//!
//! ```text
//! t_x = (1, 0),   t_y = (0, 1),   r = (-(p_y - c_y), p_x - c_x) / s
//! ```
//!
//! (the rotation about the centre, scaled by the size so that the three are commensurate). A
//! rigid motion of all bodies is `q = [q_b]` (three coordinates per body); its displacement at
//! dof `d` of body `b` is `u_d = sum_k q_bk m_k(d)`.
//!
//! A restraint is a linear function of the displacement that must vanish: a prescribed dof
//! (`u_d = 0`) or a constraint row `sum_i c_i u_{d_i}` (an active contact row, a tie). In modal
//! coordinates restraint `j` reads `a_j . q` with `(a_j)_bk = sum_i c_ji m_k(d_ji)`. The rigid
//! motions that no restraint sees are the null space of the Gram matrix
//!
//! ```text
//! G = sum_j a_j a_j^T        (3 nb x 3 nb, symmetric positive semi-definite)
//! ```
//!
//! found by a symmetric eigen-decomposition: eigenvalues `<= 1e-10` of the largest are null.
//! The stiffness `K_ff + sum_active w b b^T` is singular exactly on these motions (plus the
//! mechanisms inside a body, which the factorization reports). A free motion is named after the
//! body it moves most and the pure mode (x, y, rotation) that lies most in the null space; the
//! projection `q` of that mode on the null space is a rotation about the point where its
//! displacement `t + omega (-(p_y - c_y), p_x - c_x)` vanishes, `p = c + (-t_y, t_x) / omega`,
//! named as such when `p` lies within `FAR_CENTRE` body sizes, else as a translation.

use crate::contact::Constraint;
use crate::model::Model;

/// Null eigenvalues of the Gram matrix, relative to the largest.
pub const NULL_EIGENVALUE: f64 = 1e-10;

/// A free rotation about a centre farther than this many body sizes is named as the
/// translation it is closest to.
pub const FAR_CENTRE: f64 = 10.0;

/// One of the three rigid-body modes of a body.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RigidMode {
    TranslateX,
    TranslateY,
    Rotate,
}

impl std::fmt::Display for RigidMode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            RigidMode::TranslateX => "translate in x",
            RigidMode::TranslateY => "translate in y",
            RigidMode::Rotate => "rotate",
        })
    }
}

/// A rigid motion that no restraint holds.
#[derive(Clone, Debug, PartialEq)]
pub struct FreeMode {
    /// The body the free motions move most.
    pub body: usize,
    /// The kind of the body's free motion: a rotation when its centre lies within
    /// `FAR_CENTRE` body sizes, else the translation it is closest to.
    pub mode: RigidMode,
    /// The centre of a free rotation.
    pub centre: Option<[f64; 2]>,
    /// What holds the body, in words (supports, constraint rows at which nodes), and why that
    /// leaves the mode free.
    pub why: String,
}

/// The rigid modes of every body of a model, with the Gram matrix of its prescribed dofs.
pub struct RigidModes<'a> {
    model: &'a Model,
    /// Centre and size of each body.
    frames: Vec<([f64; 2], f64)>,
    /// Gram matrix of the prescribed dofs (row-major, `3 nb` square).
    prescribed_gram: Vec<f64>,
    /// Prescribed `[x, y]` components of each body.
    prescribed_count: Vec<[usize; 2]>,
}

impl<'a> RigidModes<'a> {
    pub fn new(model: &'a Model) -> Self {
        let frames: Vec<([f64; 2], f64)> = model
            .bodies
            .iter()
            .map(|b| {
                let [lo, hi] = b.mesh.bounding_box();
                (
                    [0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1])],
                    b.mesh.size(),
                )
            })
            .collect();
        let nm = 3 * model.bodies.len();
        let mut modes = RigidModes {
            model,
            frames,
            prescribed_gram: vec![0.0; nm * nm],
            prescribed_count: vec![[0; 2]; model.bodies.len()],
        };
        let mut gram = vec![0.0; nm * nm];
        for (d, p) in model.prescribed.iter().enumerate() {
            if p.is_some() {
                if let Some((b, m)) = modes.at(d) {
                    let mut a = vec![0.0; nm];
                    a[3 * b..3 * b + 3].copy_from_slice(&m);
                    add_outer(&mut gram, &a);
                    modes.prescribed_count[b][(d - model.bodies[b].dof_offset) % 2] += 1;
                }
            }
        }
        modes.prescribed_gram = gram;
        modes
    }

    /// The body of global dof `d` and the values `(t_x, t_y, r)` of its three modes there.
    pub fn at(&self, d: usize) -> Option<(usize, [f64; 3])> {
        let b = self.model.dof_owner(d)?.body;
        let body = &self.model.bodies[b];
        let local = d - body.dof_offset;
        let p = body.mesh.nodes[local / 2];
        let (c, s) = self.frames[b];
        Some(if local.is_multiple_of(2) {
            (b, [1.0, 0.0, -(p[1] - c[1]) / s])
        } else {
            (b, [0.0, 1.0, (p[0] - c[0]) / s])
        })
    }

    /// The displacement of the rigid motion `q` (three coordinates per body) at global dof `d`.
    pub fn displacement(&self, q: &[f64], d: usize) -> f64 {
        self.at(d)
            .map_or(0.0, |(b, m)| (0..3).map(|k| q[3 * b + k] * m[k]).sum())
    }

    /// The modal vector `a` of the restraint `sum_i c_i u_{d_i}`: `a . q` is its value for the
    /// rigid motion `q`.
    pub fn restraint(&self, dofs: &[usize], coeffs: &[f64]) -> Vec<f64> {
        let mut a = vec![0.0; 3 * self.model.bodies.len()];
        for (&d, &c) in dofs.iter().zip(coeffs) {
            if let Some((b, m)) = self.at(d) {
                for k in 0..3 {
                    a[3 * b + k] += c * m[k];
                }
            }
        }
        a
    }

    /// An orthonormal basis of the rigid motions (three coordinates per body) that neither the
    /// prescribed dofs nor `rows` (global dofs and coefficients) restrain.
    pub fn free_motions<'r>(
        &self,
        rows: impl IntoIterator<Item = (&'r [usize], &'r [f64])>,
    ) -> Vec<Vec<f64>> {
        let nm = 3 * self.model.bodies.len();
        let mut gram = self.prescribed_gram.clone();
        for (dofs, coeffs) in rows {
            add_outer(&mut gram, &self.restraint(dofs, coeffs));
        }
        let (eig, vecs) = crate::solver::dense::symmetric_eigen(&gram, nm);
        let max = eig.iter().fold(0.0f64, |m, &e| m.max(e.abs()));
        (0..nm)
            .filter(|&k| eig[k].abs() <= NULL_EIGENVALUE * max)
            .map(|k| (0..nm).map(|i| vecs[i * nm + k]).collect())
            .collect()
    }

    /// Close rows until no rigid motion is free: while the rows `active` leave a motion free,
    /// the open rows that restrain one of the free motions (`|N^T a_i| > 1e-8 |a_i|`) and whose
    /// gap is within `1e-9 size` of the smallest such gap are closed (closest points first).
    /// `gaps[i]` is the gap of `rows[i]` at the start.
    pub fn close_free_bodies(
        &self,
        rows: &[Constraint],
        gaps: &[f64],
        size: f64,
        active: &mut [bool],
    ) {
        loop {
            let basis = self.free_motions(
                rows.iter()
                    .zip(active.iter())
                    .filter(|(_, &a)| a)
                    .flat_map(|(r, _)| r.gradients()),
            );
            if basis.is_empty() {
                return;
            }
            let holding: Vec<usize> = (0..rows.len())
                .filter(|&i| !active[i])
                .filter(|&i| {
                    // a frictional row restrains along its tangent too (it sticks when closed)
                    rows[i].gradients().any(|(dofs, coeffs)| {
                        let a = self.restraint(dofs, coeffs);
                        let norm = a.iter().map(|v| v * v).sum::<f64>().sqrt();
                        let seen = basis
                            .iter()
                            .map(|q| q.iter().zip(&a).map(|(x, y)| x * y).sum::<f64>().powi(2))
                            .sum::<f64>()
                            .sqrt();
                        seen > 1e-8 * norm
                    })
                })
                .collect();
            let Some(smallest) = holding.iter().map(|&i| gaps[i]).min_by(f64::total_cmp) else {
                return;
            };
            for &i in &holding {
                if gaps[i] <= smallest + 1e-9 * size {
                    active[i] = true;
                }
            }
        }
    }

    /// Name the free motions `basis` (non-empty): the body they move most, its pure mode that
    /// lies most in them, and what holds the body among the prescribed dofs and `rows`.
    pub fn describe(&self, basis: &[Vec<f64>], rows: &[&Constraint]) -> FreeMode {
        let nb = self.model.bodies.len();
        // weight of pure mode (b, k) in the free space: |N^T e_bk|^2
        let weight = |b: usize, k: usize| basis.iter().map(|v| v[3 * b + k].powi(2)).sum::<f64>();
        let body = (0..nb)
            .max_by(|&a, &b| {
                let wa: f64 = (0..3).map(|k| weight(a, k)).sum();
                let wb: f64 = (0..3).map(|k| weight(b, k)).sum();
                wa.total_cmp(&wb).then(b.cmp(&a))
            })
            .expect("a model has a body");
        let best = (0..3).map(|k| weight(body, k)).fold(0.0f64, f64::max);
        let k = (0..3)
            .find(|&k| weight(body, k) >= best - 1e-9)
            .expect("a largest weight");
        // the free motion closest to that pure mode: its projection on the free space
        let e = 3 * body + k;
        let mut q = [0.0; 3];
        for v in basis {
            for (i, qi) in q.iter_mut().enumerate() {
                *qi += v[3 * body + i] * v[e];
            }
        }
        let (c, s) = self.frames[body];
        let omega = q[2] / s;
        let norm = q.iter().map(|v| v * v).sum::<f64>().sqrt();
        // u(p) = t + omega (-(p_y - c_y), p_x - c_x) vanishes at the centre of rotation
        let centre = (omega.abs() > 1e-12 * norm / s)
            .then(|| [c[0] - q[1] / omega, c[1] + q[0] / omega])
            .filter(|p| ((p[0] - c[0]).powi(2) + (p[1] - c[1]).powi(2)).sqrt() <= FAR_CENTRE * s);
        let mode = match centre {
            Some(_) => RigidMode::Rotate,
            None if q[0].abs() >= q[1].abs() => RigidMode::TranslateX,
            None => RigidMode::TranslateY,
        };
        FreeMode {
            body,
            mode,
            centre,
            why: self.restraints(body, mode, rows),
        }
    }

    /// What holds `body`: its supports and the rows acting on it, in words.
    fn restraints(&self, body: usize, mode: RigidMode, rows: &[&Constraint]) -> String {
        let b = &self.model.bodies[body];
        let on_body: Vec<&&Constraint> = rows
            .iter()
            .filter(|r| r.dofs.iter().any(|&d| b.owns(d)))
            .collect();
        let [px, py] = self.prescribed_count[body];
        let supports = match (px, py) {
            (0, 0) => "no supports".to_string(),
            (x, 0) => format!("u_x prescribed at {x} node(s) and no u_y"),
            (0, y) => format!("u_y prescribed at {y} node(s) and no u_x"),
            (x, y) => format!("u_x prescribed at {x} and u_y at {y} node(s)"),
        };
        if on_body.is_empty() {
            let detail = match mode {
                _ if px == 0 && py == 0 => "nothing holds it",
                RigidMode::TranslateX if px == 0 => "no node has u_x prescribed",
                RigidMode::TranslateY if py == 0 => "no node has u_y prescribed",
                _ => "the prescribed components all lie along one line of action",
            };
            return format!("it has {supports} and no closed contact or tie: {detail}");
        }
        let mut nodes: Vec<[f64; 2]> = Vec::new();
        for r in &on_body {
            if !nodes.contains(&r.point) {
                nodes.push(r.point);
            }
        }
        let listed: Vec<String> = nodes
            .iter()
            .take(3)
            .map(|p| format!("({}, {})", p[0], p[1]))
            .collect();
        let more = if nodes.len() > 3 { ", ..." } else { "" };
        let at = if nodes.len() == 1 {
            format!("only one node {}", listed[0])
        } else {
            format!("{} nodes {}{more}", nodes.len(), listed.join(", "))
        };
        format!(
            "it has {supports} and is held otherwise only by {} constraint row(s) at {at}; frictionless contact pushes along its normals only, which leaves this motion free",
            on_body.len()
        )
    }
}

impl FreeMode {
    /// The motion in words: "translate in x", "rotate about (0, 4)".
    pub fn motion(&self) -> String {
        match self.centre {
            Some(p) => format!("{} about ({}, {})", self.mode, round(p[0]), round(p[1])),
            None => self.mode.to_string(),
        }
    }
}

/// `v` to six decimals, without a negative zero.
fn round(v: f64) -> f64 {
    (v * 1e6).round() / 1e6 + 0.0
}

/// `G += a a^T`.
fn add_outer(gram: &mut [f64], a: &[f64]) {
    let n = a.len();
    for i in 0..n {
        if a[i] == 0.0 {
            continue;
        }
        for j in 0..n {
            gram[i * n + j] += a[i] * a[j];
        }
    }
}

/// The first rigid mode that the prescribed dofs of `model` and the constraint `rows` leave
/// free: which body, which mode, and why.
pub fn free_rigid_mode(model: &Model, rows: &[&Constraint]) -> Option<FreeMode> {
    let modes = RigidModes::new(model);
    let basis = modes.free_motions(rows.iter().flat_map(|r| r.gradients()));
    (!basis.is_empty()).then(|| modes.describe(&basis, rows))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 2 x 1 Q4 block whose prescribed dofs are those of `supports` (set, x, y), built past
    /// the model's own rigid-mode check.
    fn block(supports: &[(&str, bool, bool)]) -> Model {
        let text = r#"{"name": "b", "materials": {"m": {"E": 100.0, "nu": 0.3}},
            "bodies": [{"name": "b", "material": "m", "mesh": {"block": {"element": "Q4",
              "x": [0, 1, 2], "y": [0, 1]}}}],
            "supports": [{"body": "b", "set": "bottom", "x": 0.0, "y": 0.0}]}"#;
        let mut model = Model::build(&crate::model::parse(text, "b").unwrap(), "b").unwrap();
        let mut prescribed = vec![None; model.dof_count];
        let body = &model.bodies[0];
        for &(set, x, y) in supports {
            for &n in &body.mesh.node_sets[set] {
                for (c, on) in [(0, x), (1, y)] {
                    if on {
                        prescribed[body.dof(n, c)] = Some(0.0);
                    }
                }
            }
        }
        model.prescribed = prescribed;
        model
    }

    #[test]
    fn free_motions_are_named_by_body_kind_and_centre() {
        let free = free_rigid_mode(&block(&[("bottom_left", true, true)]), &[]).unwrap();
        assert_eq!(free.motion(), "rotate about (0, 0)");
        let free = free_rigid_mode(&block(&[("bottom", false, true)]), &[]).unwrap();
        assert_eq!(free.motion(), "translate in x");
        assert!(
            free.why.contains("no node has u_x prescribed"),
            "{}",
            free.why
        );
        let held = [("bottom", false, true), ("bottom_left", true, false)];
        assert_eq!(free_rigid_mode(&block(&held), &[]), None);
    }
}
