//! Rigid-body modes, and the test whether supports and constraint rows hold them.
//!
//! Body `b` (centre `c`, size `s` of its bounding box) has three rigid modes, written at a node
//! `p` as
//!
//! ```text
//! t_x = (1, 0),   t_y = (0, 1),   r = (-(p_y - c_y), p_x - c_x) / s
//! ```
//!
//! (the rotation about the centre, scaled by the size so that the three are commensurate). In
//! 3D a body has six: the translations `e_x, e_y, e_z` and the rotations `e_a x (p - c) / s`
//! about the axes `a = x, y, z` through its centre (in 2D the one rotation is the one about
//! `z`). A rigid motion of all bodies is `q = [q_b]` (`M = D (D + 1) / 2` coordinates per
//! body); its displacement at dof `d` of body `b` is `u_d = sum_k q_bk m_k(d)`.
//!
//! A restraint is a linear function of the displacement that must vanish: a prescribed dof
//! (`u_d = 0`) or a constraint row `sum_i c_i u_{d_i}` (an active contact row, a tie). In modal
//! coordinates restraint `j` reads `a_j . q` with `(a_j)_bk = sum_i c_ji m_k(d_ji)`. The rigid
//! motions that no restraint sees are the null space of the Gram matrix
//!
//! ```text
//! G = sum_j a_j a_j^T        (M nb x M nb, symmetric positive semi-definite)
//! ```
//!
//! found by a symmetric eigen-decomposition: eigenvalues `<= 1e-10` of the largest are null.
//! The stiffness `K_ff + sum_active w b b^T` is singular exactly on these motions (plus the
//! mechanisms inside a body, which the factorization reports). A free motion is named after the
//! body it moves most and the pure mode (x, y, rotation) that lies most in the null space; the
//! projection `q` of that mode on the null space is a rotation about the point where its
//! displacement `t + omega (-(p_y - c_y), p_x - c_x)` vanishes, `p = c + (-t_y, t_x) / omega`,
//! named as such when `p` lies within `FAR_CENTRE` body sizes, else as a translation. In 3D the
//! free motion is named by its pure mode (a translation along or a rotation about an axis).

use crate::contact::Constraint;
use crate::model::space::SolidCell;
use crate::model::Model;

/// Null eigenvalues of the Gram matrix, relative to the largest.
pub const NULL_EIGENVALUE: f64 = 1e-10;

/// A free rotation about a centre farther than this many body sizes is named as the
/// translation it is closest to.
pub const FAR_CENTRE: f64 = 10.0;

/// One of the rigid-body modes of a body (`Rotate` is the 2D rotation; 3D names its axis).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RigidMode {
    TranslateX,
    TranslateY,
    Rotate,
    TranslateZ,
    /// A 3D rotation about the axis `0 = x, 1 = y, 2 = z` through the body's centre.
    RotateAbout(usize),
}

impl std::fmt::Display for RigidMode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            RigidMode::TranslateX => "translate in x",
            RigidMode::TranslateY => "translate in y",
            RigidMode::Rotate => "rotate",
            RigidMode::TranslateZ => "translate in z",
            RigidMode::RotateAbout(0) => "rotate about the x axis",
            RigidMode::RotateAbout(1) => "rotate about the y axis",
            RigidMode::RotateAbout(_) => "rotate about the z axis",
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
    /// The centre of a free rotation (2D).
    pub centre: Option<[f64; 2]>,
    /// What holds the body, in words (supports, constraint rows at which nodes), and why that
    /// leaves the mode free.
    pub why: String,
}

/// The number of rigid modes of a body in `D` dimensions, `D (D + 1) / 2`.
pub const fn mode_count(d: usize) -> usize {
    d * (d + 1) / 2
}

/// The rigid modes of every body of a model, with the Gram matrix of its prescribed dofs.
pub struct RigidModes<'a, const D: usize = 2, K: SolidCell<D> = crate::fe::ElementKind> {
    model: &'a Model<D, K>,
    /// Centre and size of each body.
    frames: Vec<([f64; D], f64)>,
    /// Gram matrix of the prescribed dofs (row-major, `M nb` square).
    prescribed_gram: Vec<f64>,
    /// Prescribed components (x, y(, z)) of each body.
    prescribed_count: Vec<[usize; D]>,
}

impl<'a, const D: usize, K: SolidCell<D>> RigidModes<'a, D, K> {
    /// Modes per body.
    const M: usize = mode_count(D);

    pub fn new(model: &'a Model<D, K>) -> Self {
        let frames: Vec<([f64; D], f64)> = model
            .bodies
            .iter()
            .map(|b| {
                let [lo, hi] = b.mesh.bounding_box();
                (
                    std::array::from_fn(|i| 0.5 * (lo[i] + hi[i])),
                    b.mesh.size(),
                )
            })
            .collect();
        let m = Self::M;
        let nm = m * model.bodies.len();
        let mut modes = RigidModes {
            model,
            frames,
            prescribed_gram: vec![0.0; nm * nm],
            prescribed_count: vec![[0; D]; model.bodies.len()],
        };
        let mut gram = vec![0.0; nm * nm];
        for (d, p) in model.prescribed.iter().enumerate() {
            if p.is_some() {
                if let Some((b, mode)) = modes.at(d) {
                    let mut a = vec![0.0; nm];
                    a[m * b..m * b + m].copy_from_slice(&mode[..m]);
                    add_outer(&mut gram, &a);
                    modes.prescribed_count[b][(d - model.bodies[b].dof_offset) % D] += 1;
                }
            }
        }
        modes.prescribed_gram = gram;
        modes
    }

    /// The body of global dof `d` and the values of its modes there (the first `M` entries:
    /// the translations, then the rotations; in 2D `(t_x, t_y, r)`).
    pub fn at(&self, d: usize) -> Option<(usize, [f64; 6])> {
        let b = self.model.dof_owner(d)?.body;
        let body = &self.model.bodies[b];
        let local = d - body.dof_offset;
        let p = body.mesh.nodes[local / D];
        let (c, s) = self.frames[b];
        let i = local % D;
        let r = |j: usize| (p[j] - c[j]) / s;
        let mut mode = [0.0; 6];
        mode[i] = 1.0;
        if D == 2 {
            // the rotation about z: (-r_y, r_x)
            mode[2] = if i == 0 { -r(1) } else { r(0) };
        } else {
            // (e_a x r)_i for the axes a = x, y, z
            for a in 0..3 {
                mode[3 + a] = match (a, i) {
                    (0, 1) => -r(2),
                    (0, 2) => r(1),
                    (1, 0) => r(2),
                    (1, 2) => -r(0),
                    (2, 0) => -r(1),
                    (2, 1) => r(0),
                    _ => 0.0,
                };
            }
        }
        Some((b, mode))
    }

    /// The displacement of the rigid motion `q` (`M` coordinates per body) at global dof `d`.
    pub fn displacement(&self, q: &[f64], d: usize) -> f64 {
        let m = Self::M;
        self.at(d).map_or(0.0, |(b, mode)| {
            (0..m).map(|k| q[m * b + k] * mode[k]).sum()
        })
    }

    /// The modal vector `a` of the restraint `sum_i c_i u_{d_i}`: `a . q` is its value for the
    /// rigid motion `q`.
    pub fn restraint(&self, dofs: &[usize], coeffs: &[f64]) -> Vec<f64> {
        let m = Self::M;
        let mut a = vec![0.0; m * self.model.bodies.len()];
        for (&d, &c) in dofs.iter().zip(coeffs) {
            if let Some((b, mode)) = self.at(d) {
                for k in 0..m {
                    a[m * b + k] += c * mode[k];
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
        let nm = Self::M * self.model.bodies.len();
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
        rows: &[Constraint<D>],
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
    pub fn describe(&self, basis: &[Vec<f64>], rows: &[&Constraint<D>]) -> FreeMode {
        let m = Self::M;
        let nb = self.model.bodies.len();
        // weight of pure mode (b, k) in the free space: |N^T e_bk|^2
        let weight = |b: usize, k: usize| basis.iter().map(|v| v[m * b + k].powi(2)).sum::<f64>();
        let body = (0..nb)
            .max_by(|&a, &b| {
                let wa: f64 = (0..m).map(|k| weight(a, k)).sum();
                let wb: f64 = (0..m).map(|k| weight(b, k)).sum();
                wa.total_cmp(&wb).then(b.cmp(&a))
            })
            .expect("a model has a body");
        let best = (0..m).map(|k| weight(body, k)).fold(0.0f64, f64::max);
        let k = (0..m)
            .find(|&k| weight(body, k) >= best - 1e-9)
            .expect("a largest weight");
        if D == 3 {
            let mode = match k {
                0 => RigidMode::TranslateX,
                1 => RigidMode::TranslateY,
                2 => RigidMode::TranslateZ,
                k => RigidMode::RotateAbout(k - 3),
            };
            return FreeMode {
                body,
                mode,
                centre: None,
                why: self.restraints(body, mode, rows),
            };
        }
        // the free motion closest to that pure mode: its projection on the free space
        let e = m * body + k;
        let mut q = [0.0; 3];
        for v in basis {
            for (i, qi) in q.iter_mut().enumerate() {
                *qi += v[m * body + i] * v[e];
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

    /// The supports of `body` in words, and why they leave `mode` free when no row acts on it.
    fn supports(&self, body: usize, mode: RigidMode) -> (String, &'static str) {
        let count = self.prescribed_count[body];
        if D == 2 {
            let (px, py) = (count[0], count[1]);
            let supports = match (px, py) {
                (0, 0) => "no supports".to_string(),
                (x, 0) => format!("u_x prescribed at {x} node(s) and no u_y"),
                (0, y) => format!("u_y prescribed at {y} node(s) and no u_x"),
                (x, y) => format!("u_x prescribed at {x} and u_y at {y} node(s)"),
            };
            let detail = match mode {
                _ if px == 0 && py == 0 => "nothing holds it",
                RigidMode::TranslateX if px == 0 => "no node has u_x prescribed",
                RigidMode::TranslateY if py == 0 => "no node has u_y prescribed",
                _ => "the prescribed components all lie along one line of action",
            };
            return (supports, detail);
        }
        let supports = if count.iter().all(|&c| c == 0) {
            "no supports".to_string()
        } else {
            let parts: Vec<String> = (0..D)
                .map(|i| format!("u_{} at {}", K::axis_name(i), count[i]))
                .collect();
            format!("prescribed {} node(s)", parts.join(", "))
        };
        let detail = match mode {
            _ if count.iter().all(|&c| c == 0) => "nothing holds it",
            RigidMode::TranslateX if count[0] == 0 => "no node has u_x prescribed",
            RigidMode::TranslateY if count[1] == 0 => "no node has u_y prescribed",
            RigidMode::TranslateZ if count[2] == 0 => "no node has u_z prescribed",
            _ => "the prescribed components do not hold this motion",
        };
        (supports, detail)
    }

    /// What holds `body`: its supports and the rows acting on it, in words.
    fn restraints(&self, body: usize, mode: RigidMode, rows: &[&Constraint<D>]) -> String {
        let b = &self.model.bodies[body];
        let on_body: Vec<&&Constraint<D>> = rows
            .iter()
            .filter(|r| r.dofs.iter().any(|&d| b.owns(d)))
            .collect();
        let (supports, detail) = self.supports(body, mode);
        if on_body.is_empty() {
            return format!("it has {supports} and no closed contact or tie: {detail}");
        }
        let mut nodes: Vec<[f64; D]> = Vec::new();
        for r in &on_body {
            if !nodes.contains(&r.point) {
                nodes.push(r.point);
            }
        }
        let listed: Vec<String> = nodes
            .iter()
            .take(3)
            .map(|p| {
                let at: Vec<String> = p.iter().map(|x| x.to_string()).collect();
                format!("({})", at.join(", "))
            })
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
pub fn free_rigid_mode<const D: usize, K: SolidCell<D>>(
    model: &Model<D, K>,
    rows: &[&Constraint<D>],
) -> Option<FreeMode> {
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

    /// A 2 x 1 x 1 Hex8 block held by `supports` (JSON), as a 3D model.
    fn block3(supports: &str) -> crate::model::Model3 {
        let text = format!(
            r#"{{"name": "b", "materials": {{"m": {{"E": 100.0, "nu": 0.3}}}},
            "bodies": [{{"name": "b", "material": "m", "mesh": {{"block3d": {{"element": "Hex8",
              "x": [0, 1, 2], "y": [0, 1], "z": [0, 1]}}}}}}],
            "supports": {supports}}}"#
        );
        crate::run3d::build3(&crate::model::parse(&text, "b").unwrap(), "b").unwrap()
    }

    #[test]
    fn free_motions_in_3d_are_named_by_axis() {
        let model = block3(r#"[{"body": "b", "set": "bottom", "z": 0.0}]"#);
        let free = free_rigid_mode(&model, &[]).unwrap();
        assert_eq!(free.motion(), "translate in x");
        assert!(
            free.why.contains("no node has u_x prescribed"),
            "{}",
            free.why
        );
        let model = block3(
            r#"[{"body": "b", "set": "bottom", "z": 0.0},
                {"body": "b", "set": "bottom_front_left", "x": 0.0, "y": 0.0}]"#,
        );
        let free = free_rigid_mode(&model, &[]).unwrap();
        assert_eq!(free.motion(), "rotate about the z axis");
        assert!(
            free.why
                .contains("prescribed u_x at 1, u_y at 1, u_z at 6 node(s)"),
            "{}",
            free.why
        );
        let model = block3(
            r#"[{"body": "b", "set": "bottom", "z": 0.0},
                {"body": "b", "set": "bottom_front_left", "x": 0.0, "y": 0.0},
                {"body": "b", "set": "bottom_front_right", "y": 0.0}]"#,
        );
        assert_eq!(free_rigid_mode(&model, &[]), None);
    }
}
