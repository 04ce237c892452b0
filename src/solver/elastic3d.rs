//! One 3D body built in code (tests, studies): its supports and loads, the static small-strain
//! solve `K_ff u_f = f_f - K_fp u_p` and the error norms against a closed form.
//!
//! The solve is the one every model uses: the body becomes a one-body
//! [`crate::model::Model3`] (dofs `3 node + component`) and goes through
//! [`crate::solver::linear::solve_elastic`] (the Dirichlet data as affine constraints, sparse
//! Cholesky with faer, two steps of iterative refinement).
//!
//! Post-processing: element stresses at the quadrature points of the stiffness rule and the
//! error norms against a closed-form field, `||u - u_h||_L2 = (int |u - u_h|^2 dV)^(1/2)` and
//! the energy norm `(int (eps - eps_h) : D (eps - eps_h) dV)^(1/2)`, with the rich rule of
//! each element ([`crate::fe3d::SolidKind::error_rule`]).

use crate::fe::ReferenceCell;
use crate::mesh::{Facet, Mesh3};
use crate::model::{Body3, Model3};
use crate::solid::{body_force_load, facet_traction_load, strain_at, Elasticity, Voigt};
use crate::solver::sparse::WorkLimit;
use nalgebra::{Matrix3, SMatrix};

/// One 3D body with its loads and supports.
#[derive(Clone, Debug)]
pub struct Solid3 {
    pub mesh: Mesh3,
    pub material: Elasticity<3>,
    /// Prescribed value of each dof, if any.
    pub prescribed: Vec<Option<f64>>,
    /// Consistent external nodal forces.
    pub external_force: Vec<f64>,
}

impl Solid3 {
    pub fn new(mesh: Mesh3, material: Elasticity<3>) -> Self {
        let n = 3 * mesh.nodes.len();
        Solid3 {
            mesh,
            material,
            prescribed: vec![None; n],
            external_force: vec![0.0; n],
        }
    }

    /// Global dof of `component` (0 = x, 1 = y, 2 = z) of node `node`.
    pub fn dof(&self, node: usize, component: usize) -> usize {
        3 * node + component
    }

    pub fn dof_count(&self) -> usize {
        3 * self.mesh.nodes.len()
    }

    /// Dofs of cell `c` in element dof order `[x0, y0, z0, x1, ...]`.
    pub fn cell_dofs(&self, c: usize) -> Vec<usize> {
        self.mesh
            .cell(c)
            .iter()
            .flat_map(|&n| [3 * n, 3 * n + 1, 3 * n + 2])
            .collect()
    }

    /// Prescribe the displacement `value(x)` (components given as `Some`) at `nodes`.
    pub fn prescribe(&mut self, nodes: &[usize], value: impl Fn([f64; 3]) -> [Option<f64>; 3]) {
        for &n in nodes {
            let v = value(self.mesh.nodes[n]);
            for (i, vi) in v.into_iter().enumerate() {
                if let Some(vi) = vi {
                    self.prescribed[3 * n + i] = Some(vi);
                }
            }
        }
    }

    /// Add the consistent forces of the traction `t(x, n)` (`n` the outward unit normal) on
    /// `facets`.
    pub fn add_traction(
        &mut self,
        facets: &[Facet],
        traction: &dyn Fn([f64; 3], [f64; 3]) -> [f64; 3],
    ) {
        let facet_kind = self.mesh.kind.facet_kind();
        for &f in facets {
            let nodes = self.mesh.facet_nodes(f);
            let coords: Vec<[f64; 3]> = nodes.iter().map(|&n| self.mesh.nodes[n]).collect();
            let fe = facet_traction_load(facet_kind, &coords, traction);
            for (k, &n) in nodes.iter().enumerate() {
                for i in 0..3 {
                    self.external_force[3 * n + i] += fe[3 * k + i];
                }
            }
        }
    }

    /// Add the consistent forces of the body force `b(x)` on every cell.
    pub fn add_body_force(&mut self, body_force: &dyn Fn([f64; 3]) -> [f64; 3]) {
        let kind = self.mesh.kind;
        for c in 0..self.mesh.cell_count() {
            let fe = body_force_load(
                kind,
                &self.mesh.cell_coords(c),
                &kind.error_rule(),
                body_force,
            );
            for (k, d) in self.cell_dofs(c).into_iter().enumerate() {
                self.external_force[d] += fe[k];
            }
        }
    }

    /// The body as a one-body model named `name`, with the work limit `limit`.
    pub fn model(&self, name: &str, limit: &WorkLimit) -> Model3 {
        let body = Body3 {
            name: name.to_string(),
            material_name: name.to_string(),
            material: self.material,
            hyperelastic: None,
            mesh: self.mesh.clone(),
            dof_offset: 0,
        };
        let mut model = Model3::with_bodies(name, name, vec![body]);
        model.prescribed = self.prescribed.clone();
        model.external_force = self.external_force.clone();
        model.factor_limit = *limit;
        model
    }

    /// Solve for the displacement (every dof, prescribed ones included).
    pub fn solve(&self, limit: &WorkLimit) -> crate::error::Result<Vec<f64>> {
        let model = self.model("solid", limit);
        Ok(crate::solver::linear::solve_elastic(&model, &mut |_| {})?.u)
    }

    /// The stress of the solution `u` at every quadrature point of the stiffness rule, with
    /// the point: `(x, sigma)`.
    pub fn stresses(&self, u: &[f64]) -> Vec<([f64; 3], [f64; 6])> {
        let kind = self.mesh.kind;
        let rule = kind.stiffness_rule();
        let mut out = Vec::new();
        for c in 0..self.mesh.cell_count() {
            let coords = self.mesh.cell_coords(c);
            let u_e: Vec<f64> = self.cell_dofs(c).into_iter().map(|d| u[d]).collect();
            for q in &rule {
                let (eps, x) = strain_at(kind, &coords, &u_e, q.xi);
                out.push((x, self.material.stress(eps)));
            }
        }
        out
    }

    /// `(||u - u_h||_L2, ||u - u_h||_E)` against the closed-form displacement `exact` and its
    /// gradient `exact_gradient` (`H_ij = du_i/dx_j`).
    pub fn error_norms(
        &self,
        u: &[f64],
        exact: &dyn Fn([f64; 3]) -> [f64; 3],
        exact_gradient: &dyn Fn([f64; 3]) -> Matrix3<f64>,
    ) -> (f64, f64) {
        let kind = self.mesh.kind;
        let nn = kind.node_count();
        let (mut l2, mut energy) = (0.0, 0.0);
        for c in 0..self.mesh.cell_count() {
            let coords = self.mesh.cell_coords(c);
            let cell = self.mesh.cell(c);
            for q in kind.error_rule() {
                let pv = kind.point_values(&coords, q.xi);
                let w = q.weight * pv.det_j;
                let mut uh = [0.0; 3];
                let mut hh = Matrix3::zeros();
                for a in 0..nn {
                    for i in 0..3 {
                        let ua = u[3 * cell[a] + i];
                        uh[i] += pv.n[a] * ua;
                        for j in 0..3 {
                            hh[(i, j)] += ua * pv.dndx[a][j];
                        }
                    }
                }
                let ue = exact(pv.x);
                l2 += w * (0..3).map(|i| (ue[i] - uh[i]).powi(2)).sum::<f64>();
                let de =
                    SMatrix::<f64, 6, 1>::from(Voigt::<3>::strain(&(exact_gradient(pv.x) - hh)));
                energy += w * (de.transpose() * self.material.d * de)[(0, 0)];
            }
        }
        (l2.sqrt(), energy.sqrt())
    }
}
