//! The model: a case file validated once into typed objects.
//!
//! `Model::build` resolves every name in the case (materials, bodies, node and facet sets),
//! generates the meshes, checks each element's Jacobian, numbers the dofs
//! (`offset_b + 2 node + component`), collects prescribed values and assembles the consistent
//! external force vector:
//!
//! * traction `t` on a facet: `f_a = int_facet N_a t t_h ds` (`t_h` the thickness),
//! * pressure `p`: `t = -p n` with `n` the outward unit normal (`n ds = [dy, -dx]` for an edge
//!   ordered counter-clockwise around its element),
//! * body force `b`: `f_a = int_cell N_a b t_h dA`,
//!
//! each with a Gauss rule exact for polynomial data on straight edges and affine cells
//! (Line2: 3 points, Line3: 4 points).
//!
//! Everything that can be wrong in the case's data is found here and reported as
//! `Error::Invalid` (what, where, how to fix it); what needs the contact rows (a body that no
//! support or contact can hold against a rigid motion) is checked once by
//! [`crate::model::admit`] before any solve.

pub mod admit;
pub mod dynamics;
pub(crate) mod rigid;
pub mod space;
pub mod stable_step;

use crate::contact::enforcement::Family;
use crate::error::{Error, Result};
use crate::fe::check_geometry;
use crate::fe::{ElementKind, ReferenceCell};
use crate::fe3d::SolidKind;
use crate::harness::exact::ExactField;
use crate::io::paths::{name_problem, NAME_RULE};
use crate::io::scene::{
    Case, Check, DiscretizationSpec, EnforcementSpec, ExactSpec, ExpectedFailure, FacetSetSpec,
    GmshMeshSpec, Interaction, Kinematics, MaterialModel, MeshSpec, MultiplierSpace, NodeSetSpec,
    NormalChoice, Physics, Plane, Prescribed, RigidSurface, SolverSpec, SweepSpec, TractionSpec,
    MAX_SOLVER_COUNT,
};
use crate::mesh::{block, Facet, Mesh};
use crate::solid::Elasticity;
use crate::solid_finite::Hyperelastic;
use space::SolidCell;

/// One elastic body in `D` dimensions (2 unless named) of cells `K`: its mesh (with named
/// sets), material and first global dof.
#[derive(Clone, Debug)]
pub struct Body<const D: usize = 2, K: SolidCell<D> = ElementKind> {
    pub name: String,
    pub material_name: String,
    pub material: K::Material,
    /// The hyperelastic energy under `physics.kinematics: "finite"` (`None` with small strain).
    pub hyperelastic: Option<Hyperelastic>,
    pub mesh: Mesh<D, K>,
    pub dof_offset: usize,
}

/// A 3D body of solid cells.
pub type Body3 = Body<3, SolidKind>;

impl<const D: usize, K: SolidCell<D>> Body<D, K> {
    /// Global dof of `component` (0 = x, 1 = y, 2 = z) of local node `node`.
    pub fn dof(&self, node: usize, component: usize) -> usize {
        self.dof_offset + D * node + component
    }

    pub fn dof_count(&self) -> usize {
        D * self.mesh.nodes.len()
    }

    /// Whether global dof `d` belongs to this body.
    pub fn owns(&self, d: usize) -> bool {
        d >= self.dof_offset && d < self.dof_offset + self.dof_count()
    }

    /// Global dofs of cell `c`, in element dof order `[x0, y0(, z0), x1, ...]`.
    pub fn cell_dofs(&self, c: usize, out: &mut Vec<usize>) {
        out.clear();
        for &n in self.mesh.cell(c) {
            out.extend((0..D).map(|i| self.dof(n, i)));
        }
    }
}

/// A global dof in the user's terms: body index, local node and component (0 = x, 1 = y).
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub struct DofRef {
    pub body: usize,
    pub node: usize,
    pub component: usize,
}

/// The master side of a resolved contact pair.
#[derive(Clone, Debug, PartialEq)]
pub enum MasterSide {
    Body { body: usize, facets: Vec<Facet> },
    Rigid(RigidSurface),
}

/// A load or support on a load path: its consistent forces (zero for a support) and its
/// prescribed dofs (none for a load), at the factors `factors[k - 1]` in step `k`.
#[derive(Clone, Debug)]
pub struct PathPart {
    pub force: Vec<f64>,
    pub dofs: Vec<usize>,
    pub factors: Vec<f64>,
}

/// A contact pair with its names resolved.
#[derive(Clone, Debug)]
pub struct ContactPair {
    pub name: String,
    /// Slave body index and facets.
    pub slave: (usize, Vec<Facet>),
    pub master: MasterSide,
    pub discretization: DiscretizationSpec,
    pub enforcement: EnforcementSpec,
    /// The contact model: frictionless contact or a tied (glued) interface.
    pub interaction: Interaction,
    /// Candidate distance of the search (`None`: the largest master facet).
    pub search_distance: Option<f64>,
    /// The penalty of each pass when the discretization has two passes.
    pub two_pass_penalty: crate::io::scene::TwoPassPenalty,
}

impl ContactPair {
    /// The share of the enforcement's `kappa` each row of this pair applies: 1/2 for two-pass
    /// node-to-surface with `two_pass_penalty: "halved"`, 1 otherwise.
    pub fn penalty_share(&self) -> f64 {
        let two_pass = matches!(
            self.discretization,
            DiscretizationSpec::NodeToSurface { passes: 2, .. }
        );
        if two_pass && self.two_pass_penalty == crate::io::scene::TwoPassPenalty::Halved {
            0.5
        } else {
            1.0
        }
    }

    /// Whether the master is a rigid line or plane (its tangents do not turn: Coulomb friction
    /// is solved against it in the current geometry too, see [`coulomb_obstacle`]).
    pub fn has_flat_rigid_master(&self) -> bool {
        matches!(&self.master, MasterSide::Rigid(r) if r.is_flat())
    }

    /// The same pair with slave and master exchanged (a body master is required).
    pub fn swapped(&self) -> Option<ContactPair> {
        match &self.master {
            MasterSide::Body { body, facets } => Some(ContactPair {
                slave: (*body, facets.clone()),
                master: MasterSide::Body {
                    body: self.slave.0,
                    facets: self.slave.1.clone(),
                },
                ..self.clone()
            }),
            MasterSide::Rigid(_) => None,
        }
    }
}

/// A validated scene, ready to solve.
#[derive(Clone, Debug)]
pub struct Model<const D: usize = 2, K: SolidCell<D> = ElementKind> {
    pub name: String,
    pub description: String,
    /// Where the case came from (used in every message).
    pub source: String,
    pub plane: Plane,
    pub thickness: f64,
    pub bodies: Vec<Body<D, K>>,
    pub dof_count: usize,
    /// Prescribed value of each global dof, if any.
    pub prescribed: Vec<Option<f64>>,
    /// Consistent external nodal forces.
    pub external_force: Vec<f64>,
    /// Loads and supports with a load path of their own (`path` in the case file): their
    /// forces and prescribed dofs, with the factor at each load step. Empty: every load is
    /// proportional to the load factor.
    pub load_path: Vec<PathPart>,
    pub exact: Option<ExactField>,
    pub physics: Physics,
    /// Checks with every name already resolved.
    pub checks: Vec<Check>,
    /// The checks the case expects to fail, each naming the kind of exactly one of `checks`
    /// (validated by [`Model::resolve_checks`]); a run's verdicts carry the reason
    /// ([`Model::expected_failure`]).
    pub expected_failures: Vec<ExpectedFailure>,
    /// `(body index, node set)` of every support, for reaction summaries.
    pub support_sets: Vec<(usize, String)>,
    /// `(index into support_sets, component, dof)` for every dof a support prescribes, in the
    /// order of the case's supports (a dof two supports prescribe is listed twice, the first
    /// support first): which set's reaction a dof counts in.
    pub support_dofs: Vec<(usize, usize, usize)>,
    /// Contact pairs (empty: no contact is simulated).
    pub contact: Vec<ContactPair>,
    /// The case's sweep (used by `contact-patch table`).
    pub sweep: Option<SweepSpec>,
    /// Load steps, limits and tolerances of the solve.
    pub solver: SolverSpec,
    /// Time stepping (`physics.dynamics`); `None`: a static run, no mass matrix.
    pub dynamics: Option<dynamics::Dynamics>,
    /// What building the model found worth saying although nothing is wrong (e.g. a box set
    /// that takes in nodes only by its tolerance); reported with the run's warnings.
    pub warnings: Vec<String>,
    /// The most memory and operations one sparse factorization may take (`limits`).
    pub factor_limit: crate::solver::sparse::WorkLimit,
    /// The most iterations times dofs of one contact iteration loop (`limits.iteration_dofs`).
    pub iteration_dofs: u64,
}

/// Refuse, at line 1 column 1, a JSON file that does not start as one object: a byte-order
/// mark, an array, nothing, or other text. `kind` names the file (`"case file"`) and
/// `examples` where complete ones are (`"the cases under cases/"`). Every JSON file the tool
/// reads as one object (cases, studies) goes through this check.
pub fn refuse_non_object(text: &str, source: &str, kind: &str, examples: &str) -> Result<()> {
    let at_start = |message: String, hint: String| Error::Parse {
        path: source.to_string(),
        line: 1,
        column: 1,
        message,
        hint,
    };
    if text.starts_with('\u{feff}') {
        return Err(at_start(
            "the file starts with a byte-order mark (U+FEFF), which JSON does not allow".into(),
            "save the file as UTF-8 without a byte-order mark".into(),
        ));
    }
    match text.trim_start().chars().next() {
        Some('{') => Ok(()),
        Some('[') => Err(at_start(
            format!("the file holds an array; a {kind} holds one JSON object"),
            format!("write one per file, as an object {{..}}; see {examples}"),
        )),
        None => Err(at_start(
            "the file is empty".into(),
            format!("a {kind} holds one JSON object; see {examples}"),
        )),
        Some(_) => Err(at_start(
            format!("the file does not start with '{{': a {kind} holds one JSON object"),
            format!("see {examples} for complete examples"),
        )),
    }
}

/// Parse case JSON; errors carry line, column and a hint.
pub fn parse(text: &str, source: &str) -> Result<Case> {
    refuse_non_object(text, source, "case file", "the cases under cases/")?;
    serde_json::from_str::<Case>(text).map_err(|e| {
        let message = e.to_string();
        // serde_json appends " at line L column C"; the location is reported separately.
        let message = match message.rfind(" at line ") {
            Some(k) => message[..k].to_string(),
            None => message,
        };
        let hint = if message.contains("is defined twice") {
            "give every entry a unique name (JSON keeps only one of two equal keys)".to_string()
        } else if message.starts_with("unknown field") {
            "remove or rename the field; the accepted names are listed above".to_string()
        } else if message.starts_with("missing field") {
            "add the field; see the cases under cases/ for complete examples".to_string()
        } else if message.starts_with("unknown variant") {
            "use one of the accepted values listed above".to_string()
        } else if e.is_syntax() || e.is_eof() {
            "the file is not valid JSON near this position (a missing comma, bracket or quote?)"
                .to_string()
        } else {
            "the value does not have the expected type or shape; see the cases under cases/"
                .to_string()
        };
        Error::Parse {
            path: source.to_string(),
            line: e.line(),
            column: e.column(),
            message,
            hint,
        }
    })
}

/// A 3D model of solid bodies.
pub type Model3 = Model<3, SolidKind>;

impl<const D: usize, K: SolidCell<D>> Model<D, K> {
    /// The case's loads into [`Model::external_force`] (a load on a `path` also into
    /// [`Model::load_path`]): concentrated forces on node sets, body forces, and pressures and
    /// tractions on facet sets, 2D and 3D; a vector's components must be the body's (`[x, y]`
    /// or `[x, y, z]`).
    pub(crate) fn apply_loads(&mut self, case: &Case) -> Result<()> {
        for (k, load) in case.loads.iter().enumerate() {
            let at = format!("loads[{k}]");
            self.find_body(&load.body, &at)?;
            let bi = self.body_index(&load.body).expect("found above");
            let given = [
                load.pressure.is_some(),
                load.traction.is_some(),
                load.body_force.is_some(),
                load.force.is_some(),
            ];
            if given.iter().filter(|&&g| g).count() != 1 {
                return Err(Error::invalid(
                    &self.source,
                    &at,
                    "a load needs exactly one of \"pressure\", \"traction\", \"force\" or \"body_force\"",
                    "split it into one load per kind",
                ));
            }
            let factors = load_path_factors(case, load.path.as_deref(), &self.source, &at)?;
            let Some(factors) = factors else {
                self.apply_load(load, bi, &at)?;
                continue;
            };
            // a load on a path is assembled on its own, then added to the total
            let total = std::mem::replace(&mut self.external_force, vec![0.0; self.dof_count]);
            let result = self.apply_load(load, bi, &at);
            let force = std::mem::replace(&mut self.external_force, total);
            result?;
            for (f, p) in self.external_force.iter_mut().zip(&force) {
                *f += p;
            }
            self.load_path.push(PathPart {
                force,
                dofs: Vec::new(),
                factors,
            });
        }
        Ok(())
    }

    /// The `D` components of the vector or point `v` of a body (`what` names it in the message).
    fn body_vector(&self, v: &[f64], what: &str, body: &str, at: &str) -> Result<[f64; D]> {
        if v.len() != D {
            let form = if D == 2 { "[x, y]" } else { "[x, y, z]" };
            return Err(Error::invalid(
                &self.source,
                at,
                format!(
                    "the {what} has {} components, but body '{body}' is {D}D",
                    v.len()
                ),
                format!("give the {what} as {form}"),
            ));
        }
        if !v.iter().all(|x| x.is_finite()) {
            return Err(Error::invalid(
                &self.source,
                at,
                format!("the {what} is not finite"),
                "give finite numbers",
            ));
        }
        Ok(std::array::from_fn(|i| v[i]))
    }

    /// Assemble one load on body `bi` into `external_force`.
    fn apply_load(&mut self, load: &crate::io::scene::Load, bi: usize, at: &str) -> Result<()> {
        let body_name = &self.bodies[bi].name;
        if let Some(force) = &load.force {
            let Some(set) = &load.set else {
                return Err(Error::invalid(
                    &self.source,
                    at,
                    "a concentrated force needs a node \"set\"",
                    "add \"set\": the name of a node set of the body (e.g. a \"point\" set)",
                ));
            };
            let force = self.body_vector(&force.0, "force", body_name, at)?;
            let body = &self.bodies[bi];
            for &n in self.find_node_set(body, set, at)? {
                for (i, f) in force.iter().enumerate() {
                    self.external_force[body.dof(n, i)] += f;
                }
            }
            return Ok(());
        }
        if let Some(b) = &load.body_force {
            if load.set.is_some() {
                return Err(Error::invalid(
                    &self.source,
                    at,
                    "a body force acts on the whole body and takes no \"set\"",
                    "remove \"set\"",
                ));
            }
            let b = self.body_vector(&b.0, "body force", body_name, at)?;
            add_body_force(
                &self.bodies[bi],
                b,
                self.thickness,
                &mut self.external_force,
            );
            return Ok(());
        }
        let Some(set) = &load.set else {
            return Err(Error::invalid(
                &self.source,
                at,
                "a pressure or traction needs a facet \"set\"",
                "add \"set\": the name of a facet set of the body",
            ));
        };
        let traction = match (load.pressure, &load.traction) {
            (Some(p), _) => {
                if !p.is_finite() {
                    return Err(Error::invalid(
                        &self.source,
                        at,
                        "the pressure is not finite",
                        "give a finite number",
                    ));
                }
                FacetLoad::Pressure(p)
            }
            (_, Some(TractionSpec::Vector(t))) => {
                FacetLoad::Vector(self.body_vector(&t.0, "traction", body_name, at)?)
            }
            (_, Some(TractionSpec::Exact(_))) if D == 3 => {
                return Err(Error::invalid(
                    &self.source,
                    at,
                    "\"exact\" as a traction in 3D is not built yet",
                    "give the traction as [x, y, z]",
                ))
            }
            (_, Some(TractionSpec::Exact(_))) => FacetLoad::Exact(self.require_exact(at)?),
            _ => unreachable!("exactly one load kind checked above"),
        };
        let body = &self.bodies[bi];
        let facets = self.find_facet_set(body, set, at)?;
        let kind = body.mesh.kind;
        for &f in facets {
            let nodes = body.mesh.facet_nodes(f);
            let coords: Vec<[f64; D]> = nodes.iter().map(|&n| body.mesh.nodes[n]).collect();
            let force = &mut self.external_force;
            kind.add_facet_load(&coords, &traction, self.thickness, &mut |a, i, v| {
                force[body.dof(nodes[a], i)] += v
            });
        }
        Ok(())
    }

    fn require_exact(&self, location: &str) -> Result<ExactField> {
        self.exact.clone().ok_or_else(|| {
            Error::invalid(
                &self.source,
                location,
                "\"exact\" is used but the case defines no exact solution",
                "add an \"exact\" section (e.g. {\"kind\": \"uniform_stress\", \"stress\": [0, -10, 0]}) or give a number",
            )
        })
    }

    /// The case's supports: the prescribed components of node sets (a number, or `"exact"`
    /// for the exact field's value in 2D), each dof listed in [`Model::support_dofs`] under its
    /// set for the reactions; two supports that prescribe one dof must agree to 1e-12
    /// (relative). 2D and 3D alike: a component past the dimension (`z` in 2D) is refused.
    pub(crate) fn apply_supports(&mut self, case: &Case) -> Result<()> {
        const AXES: [&str; 3] = ["x", "y", "z"];
        for (k, s) in case.supports.iter().enumerate() {
            let at = format!("supports[{k}]");
            self.find_body(&s.body, &at)?;
            let bi = self.body_index(&s.body).expect("found above");
            let nodes = self.find_node_set(&self.bodies[bi], &s.set, &at)?.to_vec();
            let entry = (bi, s.set.clone());
            let set_index = match self.support_sets.iter().position(|e| *e == entry) {
                Some(i) => i,
                None => {
                    self.support_sets.push(entry);
                    self.support_sets.len() - 1
                }
            };
            let given = [s.x, s.y, s.z];
            if D == 2 && s.z.is_some() {
                return Err(Error::invalid(
                    &self.source,
                    &at,
                    format!(
                        "the support gives a z component, but body '{}' is 2D",
                        s.body
                    ),
                    "remove \"z\" (a 2D body has the components x and y)",
                ));
            }
            if given.iter().all(Option::is_none) {
                return Err(Error::invalid(
                    &self.source,
                    &at,
                    "the support fixes no component",
                    if D == 2 {
                        "add \"x\" and/or \"y\" (a number, or \"exact\")"
                    } else {
                        "add \"x\", \"y\" and/or \"z\" (numbers)"
                    },
                ));
            }
            let factors = load_path_factors(case, s.path.as_deref(), &self.source, &at)?;
            let mut path_dofs = Vec::new();
            for (comp, value) in given.into_iter().enumerate().take(D) {
                let Some(value) = value else { continue };
                if let Prescribed::Value(v) = value {
                    if !v.is_finite() {
                        return Err(Error::invalid(
                            &self.source,
                            &at,
                            "the prescribed value is not finite",
                            "give a finite number",
                        ));
                    }
                }
                let exact = match value {
                    Prescribed::Exact(_) if D == 3 => {
                        return Err(Error::invalid(
                            &self.source,
                            &at,
                            "\"exact\" as a prescribed value in 3D is not built yet",
                            "give a number",
                        ))
                    }
                    Prescribed::Exact(_) => Some(self.require_exact(&at)?),
                    Prescribed::Value(_) => None,
                };
                let body = &self.bodies[bi];
                for &n in &nodes {
                    let p = body.mesh.nodes[n];
                    let v = match (value, &exact) {
                        (Prescribed::Value(v), _) => v,
                        (_, Some(f)) => K::exact_displacement(f, p, &body.material)
                            .expect("exact fields are refused in 3D above")[comp],
                        _ => unreachable!("exact checked above"),
                    };
                    let dof = body.dof(n, comp);
                    if factors.is_some() {
                        path_dofs.push(dof);
                    }
                    self.support_dofs.push((set_index, comp, dof));
                    match self.prescribed[dof] {
                        Some(old)
                            if (old - v).abs() > 1e-12 * (old.abs() + v.abs()).max(1e-300) =>
                        {
                            let at_point: Vec<String> = p.iter().map(|x| x.to_string()).collect();
                            return Err(Error::invalid(
                                &self.source,
                                &at,
                                format!(
                                    "node {n} of body '{}' at ({}) gets u_{} = {v} here but {old} from an earlier support",
                                    body.name, at_point.join(", "), AXES[comp]
                                ),
                                "remove one of the conflicting supports or make their values agree",
                            ));
                        }
                        _ => self.prescribed[dof] = Some(v),
                    }
                }
            }
            if let Some(factors) = factors {
                self.load_path.push(PathPart {
                    force: Vec::new(),
                    dofs: path_dofs,
                    factors,
                });
            }
        }
        Ok(())
    }

    /// A model of `bodies` (numbered from dof 0 in order) named `name`, read from `source`:
    /// nothing prescribed, no loads, no contact, the default physics, solver and limits; the
    /// caller fills in what its scene has.
    pub fn with_bodies(name: &str, source: &str, mut bodies: Vec<Body<D, K>>) -> Self {
        let mut offset = 0;
        for b in &mut bodies {
            b.dof_offset = offset;
            offset += b.dof_count();
        }
        let limits = crate::io::scene::Limits::default();
        Model {
            name: name.to_string(),
            description: String::new(),
            source: source.to_string(),
            plane: Plane::Strain,
            thickness: 1.0,
            bodies,
            dof_count: offset,
            prescribed: vec![None; offset],
            external_force: vec![0.0; offset],
            load_path: Vec::new(),
            exact: None,
            physics: Physics::default(),
            checks: Vec::new(),
            expected_failures: Vec::new(),
            support_sets: Vec::new(),
            support_dofs: Vec::new(),
            contact: Vec::new(),
            sweep: None,
            solver: SolverSpec::default(),
            dynamics: None,
            warnings: Vec::new(),
            factor_limit: crate::solver::sparse::WorkLimit {
                gigabytes: limits.factor_gigabytes,
                operations: limits.factor_operations,
            },
            iteration_dofs: limits.iteration_dofs,
        }
    }

    /// The largest body's size (a length scale for geometric tolerances).
    pub fn size(&self) -> f64 {
        self.bodies
            .iter()
            .map(|b| b.mesh.size())
            .fold(0.0, f64::max)
    }

    /// The same model under the load factor `t`: external forces and prescribed values times
    /// `t`.
    pub fn with_load_factor(&self, t: f64) -> Self {
        let mut m = self.clone();
        for f in &mut m.external_force {
            *f *= t;
        }
        for v in m.prescribed.iter_mut().flatten() {
            *v *= t;
        }
        m
    }

    /// The model at load step `k` of `n`: the proportional loads and supports at the factor
    /// `k / n`, those on a load path at their own factor for step `k`. The model itself (no
    /// copy) where that is the whole load: the last step of a model without a load path.
    pub fn at_step(&self, k: usize, n: usize) -> std::borrow::Cow<'_, Self> {
        if k == n && self.load_path.is_empty() {
            std::borrow::Cow::Borrowed(self)
        } else {
            std::borrow::Cow::Owned(self.at_load(k as f64, n))
        }
    }

    /// The model at the (possibly fractional) load step `s` of `n`, `0 < s <= n`: the
    /// proportional loads and supports at `s / n`; those on a load path at their factor
    /// interpolated linearly between the steps `floor(s)` and `ceil(s)` (zero before step 1).
    /// At a whole `s = k` this is [`Model::at_step`]`(k, n)` exactly.
    pub fn at_load(&self, s: f64, n: usize) -> Self {
        let t = s / n as f64;
        if self.load_path.is_empty() {
            return self.with_load_factor(t);
        }
        let k = (s.ceil() as usize).clamp(1, n);
        let path_factor = |factors: &[f64]| {
            let upper = factors[k - 1];
            if s == k as f64 {
                return upper;
            }
            let lower = if k >= 2 { factors[k - 2] } else { 0.0 };
            let w = s - (k - 1) as f64;
            lower + w * (upper - lower)
        };
        let mut m = self.clone();
        let mut path_dof = vec![None; self.dof_count];
        for part in &self.load_path {
            for &d in &part.dofs {
                path_dof[d] = Some(path_factor(&part.factors));
            }
        }
        // proportional forces: the total minus the parts (round-off where both act on a dof)
        let mut proportional = self.external_force.clone();
        for part in &self.load_path {
            for (p, f) in proportional.iter_mut().zip(&part.force) {
                *p -= f;
            }
        }
        for (i, f) in m.external_force.iter_mut().enumerate() {
            *f = proportional[i] * t;
        }
        for part in &self.load_path {
            let factor = path_factor(&part.factors);
            for (f, p) in m.external_force.iter_mut().zip(&part.force) {
                *f += factor * p;
            }
        }
        for (d, v) in m.prescribed.iter_mut().enumerate() {
            if let Some(v) = v {
                *v *= path_dof[d].unwrap_or(t);
            }
        }
        // the loads are applied: a loaded model is loaded once (its own last step is itself)
        m.load_path.clear();
        m
    }

    /// Body, node and component of global dof `d`: the one inverse of the numbering
    /// `offset_b + D node + component` (bodies are numbered in order, so a binary search on
    /// the offsets finds the body). `None` past the last dof.
    pub fn dof_owner(&self, d: usize) -> Option<DofRef> {
        let b = self
            .bodies
            .partition_point(|b| b.dof_offset <= d)
            .checked_sub(1)?;
        let body = &self.bodies[b];
        body.owns(d).then(|| {
            let local = d - body.dof_offset;
            DofRef {
                body: b,
                node: local / D,
                component: local % D,
            }
        })
    }

    /// The point (reference coordinates, zero past `D`) of the node of global dof `d`;
    /// `None` for a dof of no node.
    pub fn dof_point(&self, d: usize) -> Option<[f64; 3]> {
        self.dof_owner(d).map(|owner| {
            let mut point = [0.0; 3];
            point[..D].copy_from_slice(&self.bodies[owner.body].mesh.nodes[owner.node]);
            point
        })
    }

    /// The point of each free equation's node ([`Model::dof_point`] of `free_dofs[e]`; NaN for
    /// an equation of no node), for orderings that use the geometry.
    pub fn equation_points(&self, free_dofs: &[usize]) -> Vec<[f64; 3]> {
        free_dofs
            .iter()
            .map(|&d| self.dof_point(d).unwrap_or([f64::NAN; 3]))
            .collect()
    }

    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    pub fn body(&self, name: &str) -> Option<&Body<D, K>> {
        self.bodies.iter().find(|b| b.name == name)
    }

    /// The reason the case gives for expecting `check`, one of [`Model::checks`], to fail, or
    /// `None` when the case does not list its kind in `expected_failures`.
    pub fn expected_failure(&self, check: &Check) -> Option<&str> {
        let kind = check.kind();
        self.expected_failures
            .iter()
            .find(|e| e.check == kind)
            .map(|e| e.reason.as_str())
    }

    pub(crate) fn find_body(&self, name: &str, location: &str) -> Result<&Body<D, K>> {
        self.body(name).ok_or_else(|| {
            let known: Vec<&str> = self.bodies.iter().map(|b| b.name.as_str()).collect();
            Error::invalid(
                &self.source,
                location,
                format!("body '{name}' does not exist"),
                format!("use one of the bodies {known:?}"),
            )
        })
    }

    pub(crate) fn find_node_set<'a>(
        &self,
        body: &'a Body<D, K>,
        set: &str,
        location: &str,
    ) -> Result<&'a [usize]> {
        body.mesh
            .node_sets
            .get(set)
            .map(|v| v.as_slice())
            .ok_or_else(|| {
                let known: Vec<&String> = body.mesh.node_sets.keys().collect();
                Error::invalid(
                    &self.source,
                    location,
                    format!("body '{}' has no node set '{set}'", body.name),
                    format!("define it under the body's \"node_sets\" or use one of {known:?}"),
                )
            })
    }

    pub(crate) fn find_facet_set<'a>(
        &self,
        body: &'a Body<D, K>,
        set: &str,
        location: &str,
    ) -> Result<&'a [Facet]> {
        body.mesh
            .facet_sets
            .get(set)
            .map(|v| v.as_slice())
            .ok_or_else(|| {
                let known: Vec<&String> = body.mesh.facet_sets.keys().collect();
                Error::invalid(
                    &self.source,
                    location,
                    format!("body '{}' has no facet set '{set}'", body.name),
                    format!("define it under the body's \"facet_sets\" or use one of {known:?}"),
                )
            })
    }

    /// A contact surface needs facets: an empty facet set (a geometric set whose facets all
    /// left the side of the bounding box it selects, say) is refused at the set, not later
    /// as a pair that finds no slave node within reach.
    fn refuse_empty_surface(
        &self,
        body: &Body<D, K>,
        set: &str,
        facets: &[Facet],
        location: &str,
    ) -> Result<()> {
        if !facets.is_empty() {
            return Ok(());
        }
        Err(Error::invalid(
            &self.source,
            location,
            format!(
                "facet set '{set}' of body '{}' is empty, so the pair has no contact surface (an automatic side set holds the boundary facets whose nodes all lie on that side of the body's bounding box; a node moved off it drops its facets)",
                body.name
            ),
            "give the body a facet set with the surface's facets under \"facet_sets\", or keep the moved nodes on the side",
        ))
    }

    /// The pair of a `max_penetration` check at `location` (2D and 3D): `pair` must exist, and
    /// without one the case must have pairs.
    pub(crate) fn resolve_max_penetration(&self, pair: Option<&str>, location: &str) -> Result<()> {
        if let Some(pair) = pair {
            self.find_pair(pair, location)?;
        } else if self.contact.is_empty() {
            return Err(Error::invalid(
                &self.source,
                location,
                "max_penetration needs contact pairs, and the case has none",
                "remove the check or add a pair",
            ));
        }
        Ok(())
    }

    fn find_pair(&self, name: &str, location: &str) -> Result<usize> {
        self.contact
            .iter()
            .position(|p| p.name == name)
            .ok_or_else(|| {
                let known: Vec<&str> = self.contact.iter().map(|p| p.name.as_str()).collect();
                Error::invalid(
                    &self.source,
                    location,
                    format!("contact pair '{name}' does not exist"),
                    format!("use one of {known:?}"),
                )
            })
    }

    pub(crate) fn resolve_contact(&mut self, case: &Case) -> Result<()> {
        for (k, spec) in case.contact.iter().enumerate() {
            let at = format!("contact[{k}] '{}'", spec.name);
            if self.contact.iter().any(|p| p.name == spec.name) {
                return Err(Error::invalid(
                    &self.source,
                    &at,
                    "a second contact pair has this name",
                    "give every pair a unique name",
                ));
            }
            let slave_body = self.find_body(&spec.slave.body, &format!("{at}.slave"))?;
            let slave_facets = self
                .find_facet_set(slave_body, &spec.slave.set, &format!("{at}.slave"))?
                .to_vec();
            self.refuse_empty_surface(
                slave_body,
                &spec.slave.set,
                &slave_facets,
                &format!("{at}.slave"),
            )?;
            let slave = (
                self.body_index(&spec.slave.body).expect("found"),
                slave_facets,
            );
            let m = &spec.master;
            let master = match (&m.body, &m.set, &m.rigid) {
                (Some(b), Some(set), None) => {
                    let body = self.find_body(b, &format!("{at}.master"))?;
                    let facets = self.find_facet_set(body, set, &format!("{at}.master"))?.to_vec();
                    self.refuse_empty_surface(body, set, &facets, &format!("{at}.master"))?;
                    let body = self.body_index(b).expect("found");
                    if body == slave.0 {
                        return Err(Error::invalid(&self.source, format!("{at}.master"), "self-contact (slave and master on one body) is not supported", "use two bodies"));
                    }
                    MasterSide::Body { body, facets }
                }
                (None, None, Some(rigid)) => {
                    if rigid.dimension() != D {
                        let hint = if D == 2 { "a 2D body meets a \"line\" or a \"circle\"" } else { "a 3D body meets a \"plane\" or a \"sphere\"" };
                        return Err(Error::invalid(&self.source, format!("{at}.master.rigid"), format!("the rigid surface is {}D and the bodies are {D}D", rigid.dimension()), hint));
                    }
                    if let Some(why) = rigid.problem() {
                        return Err(Error::invalid(&self.source, format!("{at}.master.rigid"), format!("the rigid surface cannot be used: {why}"), "give a finite, non-zero normal, or a positive radius; a sphere or circle far larger than the bodies is a plane or a line to them: give one"));
                    }
                    MasterSide::Rigid(rigid.clone())
                }
                _ => {
                    return Err(Error::invalid(
                        &self.source,
                        format!("{at}.master"),
                        "the master needs either \"body\" and \"set\", or \"rigid\"",
                        "e.g. {\"body\": \"foundation\", \"set\": \"top\"} or {\"rigid\": {\"kind\": \"line\", \"point\": [0, 0], \"normal\": [0, 1]}}",
                    ))
                }
            };
            if let DiscretizationSpec::NodeToSurface { passes, .. } = spec.discretization {
                if passes != 1 && passes != 2 {
                    return Err(Error::invalid(
                        &self.source,
                        format!("{at}.discretization.passes"),
                        format!("passes must be 1 or 2, got {passes}"),
                        "use 1 (one-pass) or 2 (two-pass)",
                    ));
                }
            }
            validate_enforcement(
                &spec.enforcement,
                &self.source,
                &format!("{at}.enforcement"),
            )?;
            let two_pass = |d: &DiscretizationSpec| {
                matches!(d, DiscretizationSpec::NodeToSurface { passes: 2, .. })
            };
            if !spec.two_pass_penalty.is_full()
                && !two_pass(&spec.discretization)
                && !case.sweep.as_ref().is_some_and(|sw| {
                    sw.discretizations
                        .iter()
                        .any(|d| two_pass(&d.discretization))
                })
            {
                return Err(Error::invalid(
                    &self.source,
                    format!("{at}.two_pass_penalty"),
                    "is \"halved\", but neither the pair nor its sweep has a two-pass discretization, so it would change nothing",
                    "remove it, or use {\"kind\": \"node_to_surface\", \"passes\": 2}",
                ));
            }
            if let Some(d) = spec.search_distance {
                if !(d.is_finite() && d > 0.0) {
                    return Err(Error::invalid(
                        &self.source,
                        format!("{at}.search_distance"),
                        format!("the search distance must be positive, got {d}"),
                        "give a distance larger than the initial gaps",
                    ));
                }
            }
            let newton = case.solver.scheme == crate::io::scene::Scheme::Newton;
            if let Interaction::Coulomb { mu, kappa_t } = spec.interaction {
                validate_coulomb(case, spec, mu, kappa_t, &self.source, &at)?;
            }
            let family_of = |e| crate::contact::enforcement::method(e).kernel().family();
            if newton
                && !matches!(
                    family_of(&spec.enforcement),
                    Family::PenaltyRegularized
                        | Family::LagrangeMultipliers
                        | Family::PerturbedTangent
                        | Family::Elimination
                )
            {
                return Err(Error::invalid(
                    &self.source,
                    format!("{at}.enforcement"),
                    format!(
                        "the Newton scheme (solver.scheme \"newton\") solves penalty-type methods, the perturbed tangent, Lagrange multipliers and constraint elimination, not {}",
                        family_of(&spec.enforcement).describe()
                    ),
                    "use penalty, the perturbed Lagrangian, the augmented Lagrangian, the perturbed tangent or Lagrange multipliers, or solver.scheme \"active_set\"",
                ));
            }
            if let (true, Some(first)) = (newton, self.contact.first()) {
                // elimination reduces the whole Newton step: it combines with itself only
                let eliminates = |e| family_of(e) == Family::Elimination;
                if eliminates(&first.enforcement) != eliminates(&spec.enforcement) {
                    return Err(Error::invalid(
                        &self.source,
                        format!("{at}.enforcement"),
                        format!(
                            "with solver.scheme \"newton\", constraint elimination reduces every Newton step and combines only with itself, and pair '{}' uses {}",
                            first.name,
                            family_of(&first.enforcement).describe()
                        ),
                        "use constraint elimination for every pair, or another method for this one",
                    ));
                }
            }
            if newton
                && family_of(&spec.enforcement) == Family::Elimination
                && case.physics.contact_geometry == crate::io::scene::ContactGeometry::Current
            {
                return Err(Error::invalid(
                    &self.source,
                    format!("{at}.enforcement"),
                    "with solver.scheme \"newton\", constraint elimination is solved in the reference contact geometry only (the rows searched again at every iterate could change the dofs they own)".to_string(),
                    "set \"physics\": {\"contact_geometry\": \"reference\"}, or solver.scheme \"active_set\"",
                ));
            }
            if newton && newton_mortar_obstacle(&spec.enforcement, &spec.discretization) {
                return Err(Error::invalid(
                    &self.source,
                    format!("{at}.enforcement"),
                    "the Newton scheme does not yet solve the perturbed Lagrangian's consistent (non-diagonal) coupling of standard mortar multipliers".to_string(),
                    "use solver.scheme \"active_set\" for this pair, or dual mortar multipliers (where the perturbed Lagrangian is the penalty method)",
                ));
            }
            if let (Some(first), false) = (self.contact.first(), newton) {
                let (a, b) = (family_of(&first.enforcement), family_of(&spec.enforcement));
                if a != b {
                    return Err(Error::invalid(
                        &self.source,
                        format!("{at}.enforcement"),
                        format!(
                            "the pairs of a case are solved together, and this pair's method cannot be combined with those of pair '{}' ({})",
                            first.name,
                            a.describe()
                        ),
                        "methods of one family combine, a method per pair: penalty, perturbed Lagrangian and augmented Lagrangian; Lagrange multipliers, the perturbed tangent and constraint elimination each only with themselves (with solver.scheme \"newton\", Lagrange multipliers, the perturbed tangent and penalty-type methods combine too)",
                    ));
                }
            }
            let same_facets = |a: &[Facet], b: &[Facet]| {
                let key = |f: &Facet| (f.cell, f.edge);
                let mut a: Vec<_> = a.iter().map(key).collect();
                let mut b: Vec<_> = b.iter().map(key).collect();
                a.sort_unstable();
                b.sort_unstable();
                a == b
            };
            let repeated = self.contact.iter().find(|p| {
                let same_slave = p.slave.0 == slave.0 && same_facets(&p.slave.1, &slave.1);
                match (&p.master, &master) {
                    (MasterSide::Rigid(a), MasterSide::Rigid(b)) => same_slave && a == b,
                    (
                        MasterSide::Body {
                            body: pb,
                            facets: pf,
                        },
                        MasterSide::Body { body: b, facets: f },
                    ) => {
                        (same_slave && pb == b && same_facets(pf, f))
                            || (p.slave.0 == *b
                                && same_facets(&p.slave.1, f)
                                && *pb == slave.0
                                && same_facets(pf, &slave.1))
                    }
                    _ => false,
                }
            });
            if let Some(p) = repeated {
                return Err(Error::invalid(
                    &self.source,
                    &at,
                    format!(
                        "the pair repeats the surfaces of pair '{}'; together they would enforce the same contact twice",
                        p.name
                    ),
                    "remove one of the two pairs (a two-pass pair is \"passes\": 2 on one pair)",
                ));
            }
            self.contact.push(ContactPair {
                name: spec.name.clone(),
                slave,
                master,
                discretization: spec.discretization.clone(),
                enforcement: spec.enforcement.clone(),
                interaction: spec.interaction,
                search_distance: spec.search_distance,
                two_pass_penalty: spec.two_pass_penalty,
            });
        }
        if let Some(sweep) = &case.sweep {
            if self.contact.is_empty() {
                return Err(Error::invalid(
                    &self.source,
                    "sweep",
                    "a sweep varies the first contact pair, but the case has none",
                    "add a \"contact\" pair",
                ));
            }
            for (k, e) in sweep.enforcements.iter().enumerate() {
                validate_enforcement(e, &self.source, &format!("sweep.enforcements[{k}]"))?;
            }
            for (k, d) in sweep.discretizations.iter().enumerate() {
                if let Some(slave) = &d.slave {
                    let pair = &self.contact[0];
                    let names: Vec<&str> = std::iter::once(pair.slave.0)
                        .chain(match &pair.master {
                            MasterSide::Body { body, .. } => Some(*body),
                            MasterSide::Rigid(_) => None,
                        })
                        .map(|b| self.bodies[b].name.as_str())
                        .collect();
                    if !names.contains(&slave.as_str()) {
                        return Err(Error::invalid(
                            &self.source,
                            format!("sweep.discretizations[{k}].slave"),
                            format!("'{slave}' is not a body of the first contact pair"),
                            format!("use one of {names:?}"),
                        ));
                    }
                }
            }
            if !(sweep.penalty_factor.is_finite()
                && sweep.penalty_factor > 0.0
                && sweep.tol.is_finite()
                && sweep.tol > 0.0
                && sweep.pressure.is_finite()
                && sweep.pressure != 0.0)
            {
                return Err(Error::invalid(
                    &self.source,
                    "sweep",
                    "penalty_factor and tol must be positive and pressure non-zero",
                    "e.g. \"penalty_factor\": 1000, \"tol\": 1e-10, \"pressure\": 10",
                ));
            }
            let friction = sweep.catalogue == crate::io::scene::Catalogue::Friction;
            let coulomb = case
                .contact
                .first()
                .is_some_and(|c| c.interaction.friction().is_some());
            if friction != (sweep.expect.is_some() && coulomb) {
                return Err(Error::invalid(
                    &self.source,
                    "sweep",
                    "a friction sweep (\"catalogue\": \"friction\") needs a Coulomb first pair and the status it expects (\"expect\"), and only a friction sweep takes \"expect\"",
                    "with a Coulomb pair give \"catalogue\": \"friction\" and \"expect\": \"stick\" or \"slip\"; otherwise leave \"expect\" out",
                ));
            }
            if !friction && !sweep.friction_tangents.is_empty() {
                return Err(Error::invalid(
                    &self.source,
                    "sweep.friction_tangents",
                    "friction tangents vary only in a friction sweep (\"catalogue\": \"friction\")",
                    "leave \"friction_tangents\" out of this sweep",
                ));
            }
        }
        Ok(())
    }

    /// A check's component: in 2D `x` or `y`, in 3D any.
    fn plane_component(&self, component: crate::io::scene::Component, at: &str) -> Result<()> {
        if D == 2 && component == crate::io::scene::Component::Z {
            return Err(Error::invalid(
                &self.source,
                at,
                "the check names the component z, but the case is 2D",
                "use \"x\" or \"y\"",
            ));
        }
        Ok(())
    }

    /// The case's checks, validated against the model (names, tolerances, the dimension) into
    /// [`Model::checks`]: one set of rules for 2D and 3D. A 3D case takes every check but
    /// those against a 2D stress or the exact field (`uniform_stress`, `exact_displacement`,
    /// `contact_pressure`), which it refuses by name.
    pub(crate) fn resolve_checks(&mut self, case: &Case) -> Result<()> {
        for (k, check) in case.checks.iter().enumerate() {
            let at = format!("checks[{k}]");
            // the checks against a 2D stress or the case's exact field (exact fields are 2D)
            let planar = matches!(
                check,
                Check::UniformStress { .. }
                    | Check::ExactDisplacement { .. }
                    | Check::ContactPressure { .. }
            );
            if D == 3 && planar {
                return Err(Error::invalid(
                    &self.source,
                    &at,
                    "this check is not judged in 3D (uniform_stress, exact_displacement and contact_pressure are checks against a 2D stress or exact field)",
                    "use uniform_stress_3d with six components [xx, yy, zz, yz, xz, xy], or another check",
                ));
            }
            let tol = match check {
                Check::UniformStress {
                    body,
                    tol,
                    per_condition,
                    ..
                } => {
                    if let Some(b) = body {
                        self.find_body(b, &at)?;
                    }
                    if per_condition.is_some_and(|c| !(c.is_finite() && c >= 0.0)) {
                        return Err(Error::invalid(
                            &self.source,
                            &at,
                            format!("per_condition must be a non-negative number, got {per_condition:?}"),
                            "give e.g. 10 (the tolerance becomes max(tol, 10 eps times the condition estimate))",
                        ));
                    }
                    *tol
                }
                Check::ExactDisplacement { tol } => {
                    self.require_exact(&at)?;
                    *tol
                }
                Check::UniformStress3d { stress, tol } => {
                    if D == 2 {
                        return Err(Error::invalid(
                            &self.source,
                            &at,
                            "uniform_stress_3d is a check of 3D cases, and this case's bodies are 2D",
                            "use \"uniform_stress\" with the components [xx, yy, xy]",
                        ));
                    }
                    if !stress.iter().all(|v| v.is_finite()) {
                        return Err(Error::invalid(
                            &self.source,
                            &at,
                            "the stress must be finite",
                            "give six finite components [xx, yy, zz, yz, xz, xy]",
                        ));
                    }
                    *tol
                }
                Check::Reaction {
                    body,
                    set,
                    tol,
                    component,
                    ..
                } => {
                    let b = self.find_body(body, &at)?;
                    self.find_node_set(b, set, &at)?;
                    self.plane_component(*component, &at)?;
                    *tol
                }
                Check::Displacement {
                    body,
                    point,
                    tol,
                    component,
                    ..
                } => {
                    self.find_body(body, &at)?;
                    self.body_vector(&point.0, "point", body, &at)?;
                    self.plane_component(*component, &at)?;
                    *tol
                }
                Check::MaxPenetration { pair, share } => {
                    self.resolve_max_penetration(pair.as_deref(), &at)?;
                    *share
                }
                Check::ContactForce {
                    pair,
                    tol,
                    component,
                    ..
                } => {
                    self.find_pair(pair, &at)?;
                    self.plane_component(*component, &at)?;
                    *tol
                }
                Check::MaxContactPressure { pair, tol, .. } => {
                    self.find_pair(pair, &at)?;
                    *tol
                }
                Check::ContactPressure { pair, tol } => {
                    self.find_pair(pair, &at)?;
                    self.require_exact(&at)?;
                    *tol
                }
                Check::TerminatesWith { .. } | Check::StatusChanges { .. } => {
                    if self.contact.is_empty() {
                        return Err(Error::invalid(
                            &self.source,
                            &at,
                            "terminates_with and status_changes judge the contact solve, but the case has no contact",
                            "remove the check or add a contact pair",
                        ));
                    }
                    0.0
                }
                Check::Warns { .. } => 0.0,
                Check::Equilibrium { tol, per_condition } => {
                    if per_condition.is_some_and(|c| !(c.is_finite() && c >= 0.0)) {
                        return Err(Error::invalid(
                            &self.source,
                            &at,
                            format!("per_condition must be a non-negative number, got {per_condition:?}"),
                            "give e.g. 10 (the tolerance becomes 10 eps times the condition estimate)",
                        ));
                    }
                    *tol
                }
                Check::ForceBalance { tol } => {
                    if self.contact.is_empty() {
                        return Err(Error::invalid(
                            &self.source,
                            &at,
                            "force_balance checks contact forces, but the case has no contact",
                            "remove the check or add a contact pair",
                        ));
                    }
                    *tol
                }
            };
            if !(tol.is_finite() && tol >= 0.0) {
                return Err(Error::invalid(
                    &self.source,
                    &at,
                    format!("tolerance must be a non-negative number, got {tol}"),
                    "give e.g. 1e-10",
                ));
            }
            self.checks.push(check.clone());
        }
        self.resolve_expected_failures(case)
    }

    /// The case's `expected_failures`, validated against its checks into
    /// [`Model::expected_failures`]: each entry names, with a reason that is not empty, the kind
    /// of exactly one declared check, once, and a check that has a measured error (`warns` and
    /// `terminates_with` pass or fail without one, so they cannot fail by a measured error).
    fn resolve_expected_failures(&mut self, case: &Case) -> Result<()> {
        let kinds: Vec<String> = case.checks.iter().map(Check::kind).collect();
        for (k, entry) in case.expected_failures.iter().enumerate() {
            let at = format!("expected_failures[{k}]");
            let invalid = |problem: String, hint: String| {
                Err(Error::invalid(&self.source, &at, problem, hint))
            };
            if entry.reason.trim().is_empty() {
                return invalid(
                    "the reason is empty".into(),
                    "say why the check fails: the method, the known result and its source, e.g. \"node-to-surface one-pass with the punch as slave on a non-matching mesh does not pass the contact patch test (Taylor & Papadopoulos 1991)\"".into(),
                );
            }
            let declared: Vec<usize> = (0..kinds.len())
                .filter(|&i| kinds[i] == entry.check)
                .collect();
            match declared.as_slice() {
                [] => {
                    let listed = if kinds.is_empty() {
                        "the case declares no checks".to_string()
                    } else {
                        format!("its checks are: {}", kinds.join(", "))
                    };
                    return invalid(
                        format!(
                            "the case declares no check of kind '{}' ({listed})",
                            entry.check
                        ),
                        "name the kind of one of the case's checks (its \"check\" field), or remove the entry".into(),
                    );
                }
                [_] => {}
                several => {
                    let at: Vec<String> = several.iter().map(|i| format!("checks[{i}]")).collect();
                    return invalid(
                        format!(
                            "the case declares {} checks of kind '{}' ({}), and an entry names one check by its kind",
                            several.len(),
                            entry.check,
                            at.join(", ")
                        ),
                        format!("keep one check of kind '{}' in this case (move the others to a case of their own), or remove the entry", entry.check),
                    );
                }
            }
            if matches!(entry.check.as_str(), "warns" | "terminates_with") {
                return invalid(
                    format!(
                        "a '{}' check passes or fails without a measured error, so it cannot fail as expected",
                        entry.check
                    ),
                    if entry.check == "warns" {
                        "remove the entry; if the run is not expected to warn so, remove the check"
                    } else {
                        "remove the entry and state the ending the solve is expected to have in the check's \"reason\""
                    }
                    .into(),
                );
            }
            if let Some(j) = case.expected_failures[..k]
                .iter()
                .position(|e| e.check == entry.check)
            {
                return invalid(
                    format!(
                        "the kind '{}' is listed twice (also at expected_failures[{j}])",
                        entry.check
                    ),
                    "keep one entry for it".into(),
                );
            }
            self.expected_failures.push(entry.clone());
        }
        Ok(())
    }
}

impl Model {
    /// Validate `case` and build the model. `source` names the case in messages.
    pub fn build(case: &Case, source: &str) -> Result<Model> {
        let invalid = |location: String, problem: String, hint: &str| {
            Error::invalid(source, location, problem, hint)
        };
        let name_rule = |location: String, name: &str| match name_problem(name) {
            None => Ok(()),
            Some(problem) => Err(invalid(location, problem, NAME_RULE)),
        };
        name_rule("name".into(), &case.name)?;
        for (bi, spec) in case.bodies.iter().enumerate() {
            name_rule(format!("bodies[{bi}].name"), &spec.name)?;
        }
        for (k, spec) in case.contact.iter().enumerate() {
            name_rule(format!("contact[{k}].name"), &spec.name)?;
        }
        let plane = case.analysis.plane;
        let thickness = case.analysis.thickness;
        if !(thickness.is_finite() && thickness > 0.0) {
            return Err(invalid(
                "analysis.thickness".into(),
                format!("thickness must be a positive number, got {thickness}"),
                "use the out-of-plane thickness (1 for plane strain per unit length)",
            ));
        }
        for (name, m) in &case.materials {
            if !(m.youngs_modulus.is_finite() && m.youngs_modulus > 0.0) {
                return Err(invalid(
                    format!("materials.{name}.E"),
                    format!(
                        "Young's modulus must be positive and finite, got {}",
                        m.youngs_modulus
                    ),
                    "give E > 0",
                ));
            }
            if !(m.nu.is_finite() && m.nu > -1.0 && m.nu < 0.5) {
                return Err(invalid(
                    format!("materials.{name}.nu"),
                    format!("Poisson's ratio must lie in (-1, 0.5), got {}", m.nu),
                    "nu = 0.5 (incompressible) is not supported by displacement elements; use e.g. 0.499",
                ));
            }
        }
        if case.bodies.is_empty() {
            return Err(invalid(
                "bodies".into(),
                "the case has no bodies".into(),
                "add at least one body",
            ));
        }

        check_size(case, source)?;
        check_solver_settings(case, source)?;
        let mut bodies: Vec<Body> = Vec::new();
        let mut set_warnings = Vec::new();
        let mut offset = 0;
        for (bi, spec) in case.bodies.iter().enumerate() {
            let at = format!("bodies[{bi}] '{}'", spec.name);
            if bodies.iter().any(|b| b.name == spec.name) {
                return Err(invalid(
                    at,
                    format!("a second body is named '{}'", spec.name),
                    "give every body a unique name",
                ));
            }
            let Some(mat) = case.materials.get(&spec.material) else {
                let known: Vec<&String> = case.materials.keys().collect();
                return Err(invalid(
                    format!("{at}.material"),
                    format!("material '{}' is not defined", spec.material),
                    &format!("define it under \"materials\" or use one of {known:?}"),
                ));
            };
            let mut mesh = build_mesh(&spec.mesh, source, &at, &mut set_warnings)?;
            check_read_size(case, &bodies, &mesh, source, &at)?;
            check_cells(&mesh, source, &at)?;
            set_warnings.extend(add_user_sets(&mut mesh, spec, source, &at)?);
            let body = Body {
                name: spec.name.clone(),
                material_name: spec.material.clone(),
                material: Elasticity::new(mat.youngs_modulus, mat.nu, plane),
                hyperelastic: match (case.physics.kinematics, mat.model) {
                    (Kinematics::Finite, MaterialModel::NeoHookean) => {
                        Some(Hyperelastic::neo_hookean(mat.youngs_modulus, mat.nu))
                    }
                    (Kinematics::Finite, MaterialModel::SaintVenantKirchhoff) => Some(
                        Hyperelastic::saint_venant_kirchhoff(mat.youngs_modulus, mat.nu),
                    ),
                    _ => None,
                },
                mesh,
                dof_offset: offset,
            };
            offset += body.dof_count();
            bodies.push(body);
        }

        match &case.exact {
            Some(ExactSpec::UniformStress { stress }) if stress.iter().any(|v| !v.is_finite()) => {
                return Err(invalid(
                    "exact.stress".into(),
                    format!("the stress must be finite, got {stress:?}"),
                    "give three finite components [xx, yy, xy]",
                ))
            }
            Some(ExactSpec::TimoshenkoCantilever {
                load,
                length,
                depth,
            }) if !(load.is_finite()
                && *length > 0.0
                && *depth > 0.0
                && length.is_finite()
                && depth.is_finite()) =>
            {
                return Err(invalid(
                    "exact".into(),
                    format!(
                        "the cantilever needs a finite load and a positive, finite length and depth, got load {load}, length {length}, depth {depth}"
                    ),
                    "the exact solution divides by the depth and the length",
                ))
            }
            _ => {}
        }
        let exact = case.exact.as_ref().map(ExactField::from);
        let mut model = Model {
            warnings: set_warnings,
            name: case.name.clone(),
            description: case.description.clone(),
            source: source.to_string(),
            plane,
            thickness,
            dof_count: offset,
            prescribed: vec![None; offset],
            external_force: vec![0.0; offset],
            load_path: Vec::new(),
            bodies,
            exact,
            physics: case.physics.clone(),
            checks: Vec::new(),
            expected_failures: Vec::new(),
            support_sets: Vec::new(),
            support_dofs: Vec::new(),
            contact: Vec::new(),
            sweep: case.sweep.clone(),
            solver: case.solver.clone(),
            dynamics: None,
            factor_limit: crate::solver::sparse::WorkLimit {
                gigabytes: case.limits.factor_gigabytes,
                operations: case.limits.factor_operations,
            },
            iteration_dofs: case.limits.iteration_dofs,
        };
        model.apply_supports(case)?;
        model.apply_loads(case)?;
        model.resolve_contact(case)?;
        model.resolve_checks(case)?;
        model.dynamics = dynamics::resolve(case, &model)?;
        model.check_kinematics(case)?;
        Ok(model)
    }

    /// What finite kinematics solves so far, refused otherwise with the reason: hyperelastic
    /// materials exactly when `physics.kinematics` is `"finite"`, plane strain, static, and
    /// frictionless contact in the current geometry (Newton scheme) against rigid masters or,
    /// between deformable bodies, node-to-surface with master normals and mortar.
    fn check_kinematics(&self, case: &Case) -> Result<()> {
        let invalid = |location: String, problem: String, hint: &str| {
            Err(Error::invalid(&self.source, location, problem, hint))
        };
        let finite = case.physics.kinematics == Kinematics::Finite;
        self.check_slave_normal_variation(finite)?;
        if !finite {
            for (name, m) in &case.materials {
                if !m.model.is_linear() {
                    return invalid(
                        format!("materials.{name}.model"),
                        format!("the hyperelastic material '{name}' needs finite kinematics"),
                        "set \"physics\": {\"kinematics\": \"finite\"}, or use \"model\": \"linear_elastic\" for small strain",
                    );
                }
            }
            return Ok(());
        }
        for (bi, (spec, body)) in case.bodies.iter().zip(&self.bodies).enumerate() {
            if body.hyperelastic.is_none() {
                return invalid(
                    format!("bodies[{bi}] '{}'.material", spec.name),
                    format!(
                        "finite kinematics needs a hyperelastic material, but '{}' is linear elastic",
                        spec.material
                    ),
                    &format!(
                        "give materials.{} \"model\": \"neo_hookean\" or \"saint_venant_kirchhoff\"",
                        spec.material
                    ),
                );
            }
        }
        if self.plane != Plane::Strain {
            return invalid(
                "analysis.plane".into(),
                "finite kinematics is built for plane strain only".into(),
                "set \"analysis\": {\"plane\": \"strain\"}",
            );
        }
        if case.physics.dynamics.is_some() {
            return invalid(
                "physics.dynamics".into(),
                "finite kinematics with dynamics is not built yet (the static solve only)".into(),
                "remove physics.dynamics, or use small-strain kinematics",
            );
        }
        if case.sweep.is_some() {
            return invalid(
                "sweep".into(),
                "finite kinematics is not built into the sweeps of the harness yet".into(),
                "remove the sweep and run the case as it is",
            );
        }
        for (k, pair) in self.contact.iter().enumerate() {
            let at = format!("contact[{k}] '{}'", pair.name);
            if matches!(pair.interaction, Interaction::Coulomb { .. })
                && !pair.has_flat_rigid_master()
            {
                return invalid(
                    format!("{at}.interaction"),
                    "finite kinematics with friction is built against a rigid line or plane only, so far (against a deformable or curved master the slip is the motion relative to the master's material point in its convected coordinates, which is not built)".into(),
                    "use a frictionless pair, let the master be a rigid line or plane, or use small-strain kinematics",
                );
            }
            if let MasterSide::Body { .. } = pair.master {
                // between deformable bodies: node-to-surface with master normals, whose gap
                // has its full second derivative (contact::discretization::node_to_segment),
                // and mortar
                let refused = match pair.discretization {
                    _ if pair.interaction == Interaction::Tied => Some((
                        format!("{at}.interaction"),
                        "finite kinematics with a tied pair between deformable bodies is not built yet (a tie holds the reference offsets, which rotate with the bodies)",
                        "use a frictionless pair, or small-strain kinematics",
                    )),
                    // node-to-surface with either normal (nodal_normal.rs for slave normals),
                    // node-to-node where the nodes stay matched, standard and dual mortar (the
                    // gap's exact gradient and second derivative, mortar_linearization.rs)
                    DiscretizationSpec::NodeToSurface { .. }
                    | DiscretizationSpec::NodeToNode
                    | DiscretizationSpec::Mortar { .. } => None,
                };
                if let Some((location, problem, hint)) = refused {
                    return invalid(location, problem.into(), hint);
                }
            }
        }
        if !self.contact.is_empty() {
            if case.solver.scheme != crate::io::scene::Scheme::Newton {
                return invalid(
                    "solver.scheme".into(),
                    "finite kinematics with contact is solved by the Newton scheme only".into(),
                    "set \"solver\": {\"scheme\": \"newton\"}",
                );
            }
            if case.physics.contact_geometry != crate::io::scene::ContactGeometry::Current {
                return invalid(
                    "physics.contact_geometry".into(),
                    "finite kinematics needs the contact geometry of the current configuration"
                        .into(),
                    "set \"physics\": {\"contact_geometry\": \"current\"}",
                );
            }
            if !case.solver.geometric_stiffness {
                return invalid(
                    "solver.geometric_stiffness".into(),
                    "finite kinematics needs the full tangent of the contact rows".into(),
                    "remove \"geometric_stiffness\": false",
                );
            }
        }
        Ok(())
    }

    /// `slave_normal_variation` selects how slave normals are linearized at finite strain
    /// between deformable bodies: given anywhere else it means nothing, and is refused.
    fn check_slave_normal_variation(&self, finite: bool) -> Result<()> {
        for (k, pair) in self.contact.iter().enumerate() {
            let DiscretizationSpec::NodeToSurface {
                normal,
                slave_normal_variation: Some(variation),
                ..
            } = pair.discretization
            else {
                continue;
            };
            let why = if normal != NormalChoice::Slave {
                "it selects how slave normals are linearized, and this pair takes master normals"
            } else if !finite {
                "it selects the linearization of slave normals under finite kinematics, and this case is small strain (its rows are linear)"
            } else if matches!(pair.master, MasterSide::Rigid(_)) {
                "it selects the linearization of slave normals between deformable bodies, and this pair's master is rigid"
            } else {
                continue;
            };
            return Err(Error::invalid(
                &self.source,
                format!(
                    "contact[{k}] '{}'.discretization.slave_normal_variation",
                    pair.name
                ),
                format!("\"{}\" means nothing here: {why}", variation.name()),
                "remove \"slave_normal_variation\", or use \"normal\": \"slave\" with \"physics\": {\"kinematics\": \"finite\"} between deformable bodies",
            ));
        }
        Ok(())
    }
}

/// The factors of a load path (`None`: proportional), one per load step of `case`, checked
/// (`source` and `at` name the case and the load or support in messages).
pub(crate) fn load_path_factors(
    case: &Case,
    path: Option<&[f64]>,
    source: &str,
    at: &str,
) -> Result<Option<Vec<f64>>> {
    let Some(path) = path else { return Ok(None) };
    let n = case.solver.load_steps;
    if path.len() != n {
        return Err(Error::invalid(
            source,
            format!("{at}.path"),
            format!(
                "a load path has one factor per load step: {} given, solver.load_steps is {n}",
                path.len()
            ),
            "give solver.load_steps factors, e.g. [0, 1] with \"load_steps\": 2",
        ));
    }
    if let Some(v) = path.iter().find(|v| !v.is_finite()) {
        return Err(Error::invalid(
            source,
            format!("{at}.path"),
            format!("the load path's factors must be finite, got {v}"),
            "give finite numbers",
        ));
    }
    Ok(Some(path.to_vec()))
}

/// A Coulomb pair: its parameters, and what this slice of friction solves (the Newton scheme,
/// penalty-type normal laws, the perturbed tangent or Lagrange multipliers, the reference
/// geometry).
fn validate_coulomb(
    case: &Case,
    spec: &crate::io::scene::ContactSpec,
    mu: f64,
    kappa_t: Option<f64>,
    source: &str,
    at: &str,
) -> Result<()> {
    let here = format!("{at}.interaction.coulomb");
    if !(mu.is_finite() && mu >= 0.0) {
        return Err(Error::invalid(
            source,
            format!("{here}.mu"),
            format!("the friction coefficient mu must be a finite number >= 0, got {mu}"),
            "give e.g. \"mu\": 0.3 (mu = 0 is frictionless with tangential rows)",
        ));
    }
    if let (Some(_), EnforcementSpec::Lagrange) = (kappa_t, &spec.enforcement) {
        return Err(Error::invalid(
            source,
            format!("{here}.kappa_t"),
            "the tangential penalty kappa_t has no role with Lagrange multipliers: their stick is exact",
            "leave kappa_t out for this pair, or use the penalty as its enforcement",
        ));
    }
    if let Some(k) = kappa_t {
        if !(k.is_finite() && k > 0.0) {
            return Err(Error::invalid(
                source,
                format!("{here}.kappa_t"),
                format!("the tangential penalty kappa_t must be positive and finite, got {k}"),
                "leave it out to use the pair's normal kappa, or give a positive value",
            ));
        }
    }
    if case.solver.friction_tangent == crate::io::scene::FrictionTangent::LaursenSimo
        && !matches!(spec.enforcement, EnforcementSpec::AugmentedLagrange { .. })
    {
        return Err(Error::invalid(
            source,
            format!("{at}.enforcement"),
            format!(
                "solver.friction_tangent \"laursen_simo\" bounds the slip force by the normal Uzawa multiplier of the augmented Lagrangian; this pair uses {}",
                crate::contact::enforcement::method(&spec.enforcement).name()
            ),
            "give this pair {\"kind\": \"augmented_lagrange\", ..} as enforcement, or use \"friction_tangent\": \"consistent\" or \"symmetrized\"",
        ));
    }
    if let Some(o) = coulomb_obstacle(
        case.solver.scheme,
        case.physics.contact_geometry,
        &spec.enforcement,
        spec.master
            .rigid
            .as_ref()
            .is_some_and(RigidSurface::is_flat),
    ) {
        let field = match o.field {
            "coulomb" => here,
            f => format!("{at}.{f}"),
        };
        return Err(Error::invalid(source, field, o.why, o.fix));
    }
    Ok(())
}

/// Whether the Newton scheme refuses this pair: the perturbed Lagrangian's consistent
/// (non-diagonal) coupling of standard mortar multipliers is not solved there yet.
pub fn newton_mortar_obstacle(
    enforcement: &EnforcementSpec,
    discretization: &DiscretizationSpec,
) -> bool {
    matches!(enforcement, EnforcementSpec::PerturbedLagrange { .. })
        && matches!(
            discretization,
            DiscretizationSpec::Mortar {
                multiplier: MultiplierSpace::Standard
            }
        )
}

/// Why a Coulomb pair cannot be solved as specified, and how to fix it.
#[derive(Clone, Debug, PartialEq)]
pub struct CoulombObstacle {
    /// The field of the pair at fault: `enforcement`, `discretization` or `coulomb` (the
    /// interaction itself, for the scheme and the geometry).
    pub field: &'static str,
    pub why: String,
    pub fix: String,
}

/// What this slice of friction solves: the Newton scheme, penalty-type normal laws (penalty,
/// perturbed Lagrangian, augmented Lagrangian, perturbed tangent) or Lagrange multipliers, the
/// reference geometry; every discretization (node-to-node, node-to-surface one- and two-pass
/// with master or slave normals, rigid masters, standard and dual mortar with the weighted
/// tangential slip); in the current geometry (and so under finite kinematics) against a flat
/// rigid master (`flat_rigid_master`: a line or a plane), whose tangents do not turn, so the
/// slip `t . u_s` of a slave node is the distance it slid over the master in any
/// configuration. Against a deformable or curved master the slip of the current geometry is
/// the motion relative to the master's material point in its convected coordinates, which is
/// not built. `None` when the combination is solved;
/// used by [`Model::build`] and by the friction table (its `n/a` cells).
pub fn coulomb_obstacle(
    scheme: crate::io::scene::Scheme,
    geometry: crate::io::scene::ContactGeometry,
    enforcement: &EnforcementSpec,
    flat_rigid_master: bool,
) -> Option<CoulombObstacle> {
    let obstacle = |field, why: &str, fix: &str| {
        Some(CoulombObstacle {
            field,
            why: why.to_string(),
            fix: fix.to_string(),
        })
    };
    if scheme != crate::io::scene::Scheme::Newton {
        return obstacle(
            "coulomb",
            "Coulomb friction is solved by the Newton scheme only",
            "set \"solver\": {\"scheme\": \"newton\"}",
        );
    }
    if matches!(enforcement, EnforcementSpec::Elimination) {
        // a slipping point has no constraint on its tangential motion to eliminate, only a
        // dependent force mu lambda_n t whose lambda_n is itself an eliminated reaction
        return obstacle(
            "enforcement",
            "Coulomb friction with constraint elimination is not solved: stick rows could be eliminated as ties, but a slipping point constrains no tangential motion (its force mu lambda_n acts along the tangent, with lambda_n a reaction recovered only after the reduced solve), so the slip set needs the reactions inside the elimination's own Newton loop, which it does not have",
            "use Lagrange multipliers (the same exact stick and slip) or the augmented Lagrangian for this pair",
        );
    }
    if !matches!(
        enforcement,
        EnforcementSpec::Penalty { .. }
            | EnforcementSpec::PerturbedLagrange { .. }
            | EnforcementSpec::AugmentedLagrange { .. }
            | EnforcementSpec::PerturbedTangent { .. }
            | EnforcementSpec::Lagrange
    ) {
        return obstacle(
            "enforcement",
            &format!(
                "Coulomb friction needs the penalty, the perturbed Lagrangian, the augmented Lagrangian, the perturbed tangent or Lagrange multipliers as normal law, not {}",
                crate::contact::enforcement::method(enforcement).name()
            ),
            "use the penalty, the perturbed Lagrangian, the augmented Lagrangian, the perturbed tangent or Lagrange multipliers for this pair",
        );
    }
    if geometry != crate::io::scene::ContactGeometry::Reference && !flat_rigid_master {
        return obstacle(
            "coulomb",
            "Coulomb friction in the current contact geometry (and so under finite kinematics) is solved against a rigid line or plane only, so far: against a deformable or curved master the slip is the motion relative to the master's material point in its convected coordinates, which is not built",
            "set \"physics\": {\"contact_geometry\": \"reference\"} with small-strain kinematics, or let the pair's master be a rigid line or plane",
        );
    }
    None
}

fn validate_enforcement(e: &EnforcementSpec, source: &str, at: &str) -> Result<()> {
    if let Some(kappa) = crate::contact::enforcement::method(e).kappa() {
        if !(kappa.is_finite() && kappa > 0.0) {
            return Err(Error::invalid(
                source,
                at,
                format!("kappa must be positive and finite, got {kappa}"),
                "a penalty of 10 to 1000 times E / h is a common start",
            ));
        }
    }
    Ok(())
}

fn build_mesh(spec: &MeshSpec, source: &str, at: &str, notes: &mut Vec<String>) -> Result<Mesh> {
    match spec {
        MeshSpec::Gmsh(g) if gmsh_file_is_3d(g, source) => Err(three_d_through_the_plane_model(
            source,
            format!("{at}.mesh.gmsh"),
        )),
        MeshSpec::Gmsh(g) => {
            let (mesh, mirrored) = read_gmsh_mesh(g, source, at)?;
            if mirrored > 0 {
                notes.push(format!(
                    "{at}.mesh.gmsh: {mirrored} cell(s) of '{}' ran clockwise and were renumbered counter-clockwise",
                    g.file
                ));
            }
            Ok(mesh)
        }
        MeshSpec::Block3d(_) => Err(three_d_through_the_plane_model(
            source,
            format!("{at}.mesh.block3d"),
        )),
        MeshSpec::Block(b) => {
            let xs = b.x.values();
            let ys = b.y.values();
            if xs.iter().chain(&ys).any(|v| !v.is_finite()) {
                return Err(Error::invalid(
                    source,
                    format!("{at}.mesh.block"),
                    "a break is not finite",
                    "give finite coordinates",
                ));
            }
            let moves: Vec<_> = b.moves.iter().map(|m| (m.from, m.to)).collect();
            block(b.element, &xs, &ys, &moves).map_err(|e| {
                Error::invalid(
                    source,
                    format!("{at}.mesh.block"),
                    e,
                    "fix the breaks or moves",
                )
            })
        }
        MeshSpec::Explicit(e) => match e.element.plane() {
            Some(kind) => explicit_mesh(e, kind, source, at),
            None => Err(three_d_through_the_plane_model(
                source,
                format!("{at}.mesh.explicit"),
            )),
        },
    }
}

/// The refusal of a 3D body in a case that goes through the 2D model (a case with 2D and 3D
/// bodies, or `export`).
fn three_d_through_the_plane_model(source: &str, at: String) -> Error {
    Error::invalid(
        source,
        at,
        "a 3D body in a case that goes through the 2D model: 3D cases run with `contact-patch run`, `check`, `judge`, `table` and `study`, with 3D bodies only (no 2D bodies beside them); `export` is 2D for now",
        "run the case with `contact-patch run CASE`, `check CASE` or `table CASE`, or give the body a 2D mesh",
    )
}

/// Whether the Gmsh file of `g` (relative to the case file `source`'s folder) holds 3D cells
/// (tetrahedra or hexahedra); a file that cannot be read is not (its reader names the
/// problem).
pub(crate) fn gmsh_file_is_3d(g: &GmshMeshSpec, source: &str) -> bool {
    let folder = std::path::Path::new(source)
        .parent()
        .unwrap_or(std::path::Path::new(""));
    std::fs::read(folder.join(&g.file))
        .ok()
        .and_then(|bytes| crate::io::gmsh_read::read_msh(&bytes).ok())
        .is_some_and(|content| crate::io::gmsh_read::cell_dimension(&content) == 3)
}

/// The mesh of an explicit spec of `kind` cells (2D or 3D): every node with the body's `D`
/// finite coordinates, every cell with its node count of existing nodes.
pub(crate) fn explicit_mesh<const D: usize, K: ReferenceCell<D>>(
    e: &crate::io::scene::ExplicitMeshSpec,
    kind: K,
    source: &str,
    at: &str,
) -> Result<Mesh<D, K>> {
    let nn = kind.node_count();
    let mut nodes = Vec::with_capacity(e.nodes.len());
    for (i, p) in e.nodes.iter().enumerate() {
        let place = format!("{at}.mesh.explicit.nodes[{i}]");
        if p.0.len() != D {
            return Err(Error::invalid(
                source,
                place,
                format!(
                    "the node has {} coordinates, but {:?} cells are {D}D",
                    p.0.len(),
                    e.element
                ),
                if D == 2 {
                    "give every node as [x, y]"
                } else {
                    "give every node as [x, y, z]"
                },
            ));
        }
        if !p.0.iter().all(|x| x.is_finite()) {
            return Err(Error::invalid(
                source,
                place,
                "the coordinates are not finite",
                "give finite coordinates",
            ));
        }
        nodes.push(std::array::from_fn::<f64, D, _>(|k| p.0[k]));
    }
    let mut conn = Vec::with_capacity(nn * e.cells.len());
    for (c, cell) in e.cells.iter().enumerate() {
        if cell.len() != nn {
            return Err(Error::invalid(
                source,
                format!("{at}.mesh.explicit.cells[{c}]"),
                format!(
                    "a {:?} cell needs {nn} nodes, got {}",
                    e.element,
                    cell.len()
                ),
                if D == 2 {
                    "list corners counter-clockwise, then mid-side nodes (then the Q9 centre)"
                } else {
                    "list the nodes in VTK's order: corners (a hexahedron's bottom face counter-clockwise seen from above, then the top), then mid-edge nodes (then Hex27's face centres and centre)"
                },
            ));
        }
        for &n in cell {
            if n >= e.nodes.len() {
                return Err(Error::invalid(
                    source,
                    format!("{at}.mesh.explicit.cells[{c}]"),
                    format!(
                        "node {n} does not exist (the mesh has {} nodes, numbered from 0)",
                        e.nodes.len()
                    ),
                    "use node indices below the number of nodes",
                ));
            }
        }
        conn.extend_from_slice(cell);
    }
    if e.cells.is_empty() {
        return Err(Error::invalid(
            source,
            format!("{at}.mesh.explicit.cells"),
            "the mesh has no cells",
            "add cells",
        ));
    }
    Ok(Mesh::new(kind, nodes, conn))
}

/// The mesh of a body from a Gmsh file, the file named relative to the case file's folder
/// (`source`), and the number of cells renumbered from clockwise.
pub(crate) fn read_gmsh_mesh<const D: usize, K: crate::io::gmsh_read::GmshCell<D>>(
    g: &GmshMeshSpec,
    source: &str,
    at: &str,
) -> Result<(Mesh<D, K>, usize)> {
    let folder = std::path::Path::new(source)
        .parent()
        .unwrap_or(std::path::Path::new(""));
    let path = folder.join(&g.file);
    let shown = path.display().to_string();
    let bytes = std::fs::read(&path).map_err(|e| {
        Error::invalid(
            source,
            format!("{at}.mesh.gmsh.file"),
            format!("cannot read '{shown}': {e}"),
            "name a .msh file that exists, relative to the case file's folder",
        )
    })?;
    crate::io::gmsh_read::read_msh(&bytes)
        .and_then(|content| crate::io::gmsh_read::body_mesh(&content, g.physical.as_deref()))
        .map_err(|e| {
            Error::invalid(
                source,
                format!("{at}.mesh.gmsh ({shown}, {})", e.place),
                e.problem,
                e.hint,
            )
        })
}

/// The solver's counts and tolerances of `case` (`solver.load_steps`, `max_iterations`,
/// `max_geometry_updates`, `linear_tolerance`, `linear_max_iterations`,
/// `geometry_tolerance`), each within its range, for 2D and 3D cases alike.
pub(crate) fn check_solver_settings(case: &Case, source: &str) -> Result<()> {
    let counts = [
        ("solver.load_steps", case.solver.load_steps),
        ("solver.max_iterations", case.solver.max_iterations),
        (
            "solver.max_geometry_updates",
            case.solver.max_geometry_updates,
        ),
    ];
    for (field, n) in counts {
        if !(1..=MAX_SOLVER_COUNT).contains(&n) {
            return Err(Error::invalid(
                source,
                field,
                format!("must be from 1 to {MAX_SOLVER_COUNT}, got {n}"),
                "the defaults (1 load step, 200 iterations, 50 geometry updates) suit most cases",
            ));
        }
    }
    let tol = case.solver.linear_tolerance;
    if !(tol.is_finite() && tol > 0.0 && tol < 1.0) {
        return Err(Error::invalid(
            source,
            "solver.linear_tolerance",
            format!("must lie in (0, 1), got {tol}"),
            "the default is 1e-10 (the relative residual of the CG solve)",
        ));
    }
    let n = case.solver.linear_max_iterations;
    if !(1..=MAX_SOLVER_COUNT).contains(&n) {
        return Err(Error::invalid(
            source,
            "solver.linear_max_iterations",
            format!("must be from 1 to {MAX_SOLVER_COUNT}, got {n}"),
            "the default is 500",
        ));
    }
    let tol = case.solver.geometry_tolerance;
    if !(tol.is_finite() && tol > 0.0) {
        return Err(Error::invalid(
            source,
            "solver.geometry_tolerance",
            format!("must be a positive number, got {tol}"),
            "the default is 1e-12",
        ));
    }
    Ok(())
}

/// The nodes read from Gmsh files count against `limits.nodes` once read (a block's or an
/// explicit mesh's count is checked from the spec by [`check_size`]).
pub(crate) fn check_read_size<const D: usize, K: SolidCell<D>>(
    case: &Case,
    built: &[Body<D, K>],
    mesh: &Mesh<D, K>,
    source: &str,
    at: &str,
) -> Result<()> {
    let total: usize = built.iter().map(|b| b.mesh.nodes.len()).sum::<usize>() + mesh.nodes.len();
    if total > case.limits.nodes {
        return Err(Error::invalid(
            source,
            format!("{at}.mesh"),
            format!(
                "the meshes have {total} nodes, above the limit of {}",
                case.limits.nodes
            ),
            "use a coarser mesh, or raise \"limits\": {\"nodes\": N} if the machine has the memory",
        ));
    }
    Ok(())
}

/// The node count of every mesh, from the spec alone (nothing is allocated), against
/// `limits.nodes`, and the work of the block meshes' sparse solve ([`block_work`]) against
/// `limits.factor_gigabytes` and `limits.factor_operations` ([`check_work`]), in 2D and 3D.
pub(crate) fn check_size(case: &Case, source: &str) -> Result<()> {
    for (field, value) in [
        ("factor_gigabytes", case.limits.factor_gigabytes),
        ("factor_operations", case.limits.factor_operations),
    ] {
        if !(value.is_finite() && value > 0.0) {
            return Err(Error::invalid(
                source,
                format!("limits.{field}"),
                format!("{value} is not a positive number"),
                "give a positive limit, or leave the field out for its default",
            ));
        }
    }
    let limit = case.limits.nodes as u128;
    let mut total: u128 = 0;
    let mut work = SolveWork::default();
    for (bi, spec) in case.bodies.iter().enumerate() {
        let (nodes, body_work) = match &spec.mesh {
            MeshSpec::Block(b) => {
                let order = if b.element.is_quadratic() { 2 } else { 1 };
                let along = |n: usize| order * n as u128 + 1;
                let nodes = along(b.x.intervals()) * along(b.y.intervals());
                (
                    nodes,
                    Some(block_work(b.element, [b.x.intervals(), b.y.intervals()])),
                )
            }
            MeshSpec::Block3d(b) => {
                let order = if crate::fe::ReferenceCell::is_quadratic(b.element) {
                    2
                } else {
                    1
                };
                let along = |n: usize| order * n as u128 + 1;
                let nodes = along(b.x.intervals())
                    .saturating_mul(along(b.y.intervals()))
                    .saturating_mul(along(b.z.intervals()));
                let intervals = [b.x.intervals(), b.y.intervals(), b.z.intervals()];
                (nodes, Some(block_work(b.element, intervals)))
            }
            MeshSpec::Explicit(e) => (e.nodes.len() as u128, None),
            // counted once read (check_read_size)
            MeshSpec::Gmsh(_) => (0, None),
        };
        total = total.saturating_add(nodes);
        let at = format!("bodies[{bi}] '{}'.mesh", spec.name);
        if total > limit {
            return Err(Error::invalid(
                source,
                at,
                format!(
                    "the meshes would have {total} nodes or more, above the limit of {limit}"
                ),
                "use fewer divisions, or raise \"limits\": {\"nodes\": N} if the machine has the memory",
            ));
        }
        if let Some(body_work) = body_work {
            work.add(&body_work);
            check_work(case, source, &at, &work)?;
        }
    }
    Ok(())
}

/// What the meshes of a case ask of the sparse solve, estimated from the block specs before
/// anything is allocated ([`block_work`]), summed over the bodies (each body's factor apart:
/// bodies meet through contact rows only).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct SolveWork {
    /// Stored entries (upper triangle) of the stiffness matrix.
    pub matrix_entries: f64,
    /// Entries of the factor: at least the matrix's, and the dense block of the separator.
    pub factor_entries: f64,
    /// Multiply-adds of the factorization (`sum_j c_j^2`, the measure of
    /// [`crate::solver::sparse::FactorWork`]).
    pub factor_operations: f64,
}

impl SolveWork {
    fn add(&mut self, other: &SolveWork) {
        self.matrix_entries += other.matrix_entries;
        self.factor_entries += other.factor_entries;
        self.factor_operations += other.factor_operations;
    }
}

/// The work of the sparse solve of a block mesh of `kind` cells with `intervals` elements
/// along each axis, in any dimension (`D` dofs a node), from the spec alone. Estimates kept
/// below what the assembly and the symbolic analysis find (`tests` of this module compare
/// them on block meshes of every element), so that a case refused here would have been refused
/// there, after the allocation of its matrix:
///
/// * the stiffness's stored entries: quadrilaterals and hexahedra couple every pair of nodes of
///   a cell, and the coupled pairs of a tensor-product lattice are the product over the axes
///   of the pairs along one axis, `n (p + 1)^2 - (n - 1)` for `n` elements of order `p` (exact
///   without supports); triangles and tetrahedra count their vertices and the neighbours along
///   the axes only (a lower bound);
/// * the factor: the smallest plane across the lattice (all nodes but those along the longest
///   axis) separates the mesh, and whatever the ordering the factor holds a dense block about
///   that size (a grid's treewidth); half its dofs, `s`, are counted as a dense block: `s^2 / 2`
///   entries (at least the matrix's) and `s^3 / 3` multiply-adds.
pub(crate) fn block_work<const D: usize, C: crate::fe::ReferenceCell<D>>(
    kind: C,
    intervals: [usize; D],
) -> SolveWork {
    let tensor = kind.corner_count() == 1 << D;
    let dofs = D as f64;
    // the lattice of the nodes counted: every node of a tensor-product cell, the vertices of
    // a simplex mesh
    let order = if tensor && kind.is_quadratic() {
        2.0
    } else {
        1.0
    };
    let along: [f64; D] = std::array::from_fn(|i| order * intervals[i] as f64 + 1.0);
    let nodes: f64 = along.iter().product();
    let pairs = if tensor {
        intervals
            .iter()
            .map(|&n| {
                let n = n as f64;
                n * (order + 1.0).powi(2) - (n - 1.0)
            })
            .product::<f64>()
    } else {
        // each vertex with itself, and both ends of each lattice edge along an axis
        let edges: f64 = (0..D).map(|i| nodes / along[i] * (along[i] - 1.0)).sum();
        nodes + 2.0 * edges
    };
    let matrix_entries = (dofs * dofs * pairs + dofs * nodes) / 2.0;
    let longest = along.iter().copied().fold(0.0, f64::max);
    let separator = dofs * (nodes / longest) / 2.0;
    SolveWork {
        matrix_entries,
        factor_entries: matrix_entries.max(separator * separator / 2.0),
        factor_operations: separator.powi(3) / 3.0,
    }
}

/// `work` against the case's limits (`limits.factor_gigabytes`, 8 bytes a factor entry, and
/// `limits.factor_operations`); with `solver.linear_solver: "cg_amg"` no factor is made, and
/// the matrix's values and row indices (16 bytes an entry) count against the gigabytes.
fn check_work(case: &Case, source: &str, at: &str, work: &SolveWork) -> Result<()> {
    let gigabytes = case.limits.factor_gigabytes;
    let operations = case.limits.factor_operations;
    let matrix = format!(
        "the meshes would give a stiffness matrix of about {:.3e} stored entries",
        work.matrix_entries
    );
    if case.solver.linear_solver == crate::io::scene::LinearSolver::CgAmg {
        let needed = work.matrix_entries * 16.0 / 1e9;
        if needed > gigabytes {
            return Err(Error::invalid(
                source,
                at,
                format!("{matrix} ({needed:.2} GB with their row indices), above the limit of {gigabytes} GB (limits.factor_gigabytes)"),
                "use fewer divisions or a linear element, or raise \"limits\": {\"factor_gigabytes\": G} if the machine has the memory",
            ));
        }
        return Ok(());
    }
    let needed = work.factor_entries * 8.0 / 1e9;
    if needed > gigabytes || work.factor_operations > operations {
        return Err(Error::invalid(
            source,
            at,
            format!(
                "{matrix}, and its sparse factorization at least {:.3e} factor entries ({needed:.2} GB) and {:.2e} multiply-adds, above the limits of {gigabytes} GB (limits.factor_gigabytes) and {operations:.1e} multiply-adds (limits.factor_operations)",
                work.factor_entries, work.factor_operations
            ),
            "use fewer divisions or a linear element, or raise \"limits\": {\"factor_gigabytes\": G, \"factor_operations\": N} if the machine has the memory and the time, or use \"solver\": {\"linear_solver\": \"cg_amg\"} where it applies",
        ));
    }
    Ok(())
}

/// Every cell must have a positive Jacobian at its nodes and quadrature points (2D and 3D).
pub(crate) fn check_cells<const D: usize, K: SolidCell<D>>(
    mesh: &Mesh<D, K>,
    source: &str,
    at: &str,
) -> Result<()> {
    for c in 0..mesh.cell_count() {
        let coords = mesh.cell_coords(c);
        if let Err(bad) = check_geometry(mesh.kind, &coords, &mesh.kind.stiffness_rule()) {
            let overflow = !bad.det_j.is_finite()
                || coords
                    .iter()
                    .any(|p| !p.iter().map(|x| x * x).sum::<f64>().is_finite());
            let what = if overflow {
                "too large to compute with: its coordinates overflow"
            } else if bad.inverted {
                "inverted (negative Jacobian)"
            } else if D == 2 {
                "degenerate (zero-area)"
            } else {
                "degenerate (zero-volume)"
            };
            let point: Vec<String> = bad.at.iter().map(|x| format!("{x:.6}")).collect();
            return Err(Error::invalid(
                source,
                format!("{at}: element {c} (nodes {:?})", mesh.cell(c)),
                format!(
                    "the element is {what}: det J = {:.3e} at ({})",
                    bad.det_j,
                    point.join(", ")
                ),
                if overflow {
                    "coordinates must stay far below 1e154 (their squares must be finite); choose other length units"
                } else if D == 2 {
                    "list the corners counter-clockwise, keep every interior angle below 180 degrees and mid-side nodes near the middle of their sides"
                } else {
                    "number the corners as VTK does (a hexahedron's bottom face counter-clockwise seen from above, then the top face above it; a tetrahedron's base counter-clockwise seen from its apex), keep the moves small against the element size and mid-edge nodes near the middle of their edges"
                },
            ));
        }
    }
    Ok(())
}

/// The nodes of `nodes` that lie outside the box `[lo, hi]` (taken in by the tolerance only),
/// as a warning naming the set `loc`.
fn widened_box_warning<const D: usize, K: ReferenceCell<D>>(
    mesh: &Mesh<D, K>,
    nodes: impl Iterator<Item = usize>,
    (lo, hi): ([f64; D], [f64; D]),
    loc: &str,
) -> Option<String> {
    let outside = |n: &usize| {
        let p = mesh.nodes[*n];
        (0..D)
            .map(|i| (lo[i] - p[i]).max(p[i] - hi[i]))
            .fold(0.0f64, f64::max)
    };
    let mut out: Vec<(usize, f64)> = nodes
        .map(|n| (n, outside(&n)))
        .filter(|(_, d)| *d > 0.0)
        .collect();
    out.sort_unstable_by_key(|x| x.0);
    out.dedup_by_key(|x| x.0);
    let &(n, d) = out.iter().max_by(|a, b| a.1.total_cmp(&b.1))?;
    Some(format!(
        "{loc}: {} node(s) lie outside the box {} and are in the set only by the \
         tolerance of 1e-9 x the body size ({:.3e}); the farthest is node {n} at ({}), {d:.3e} \
         outside. Widen the box to take them in on purpose, or narrow it to leave them out",
        out.len(),
        box_words(lo, hi),
        mesh.tolerance(),
        point_words(mesh.nodes[n]),
    ))
}

/// `[lo_x, hi_x] x [lo_y, hi_y] (x [lo_z, hi_z])`.
fn box_words<const D: usize>(lo: [f64; D], hi: [f64; D]) -> String {
    (0..D)
        .map(|i| format!("[{}, {}]", lo[i], hi[i]))
        .collect::<Vec<_>>()
        .join(" x ")
}

/// `x, y(, z)`.
fn point_words<const D: usize>(p: [f64; D]) -> String {
    p.iter()
        .map(|x| x.to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// The `D` coordinates of the point `v` of a set (`what` names it in the message).
fn set_point<const D: usize>(v: &[f64], what: &str, source: &str, loc: &str) -> Result<[f64; D]> {
    if v.len() != D {
        let form = if D == 2 { "[x, y]" } else { "[x, y, z]" };
        return Err(Error::invalid(
            source,
            loc,
            format!(
                "the {what} has {} coordinates, but the body is {D}D",
                v.len()
            ),
            format!("give the {what} as {form}"),
        ));
    }
    Ok(std::array::from_fn(|i| v[i]))
}

/// Add the body's named sets to `mesh`; returns the warnings about them.
pub(crate) fn add_user_sets<const D: usize, K: ReferenceCell<D>>(
    mesh: &mut Mesh<D, K>,
    spec: &crate::io::scene::BodySpec,
    source: &str,
    at: &str,
) -> Result<Vec<String>> {
    let tol = mesh.tolerance();
    let mut warnings = Vec::new();
    let built_in = if D == 2 {
        "left, right, bottom, top, the corners and all"
    } else {
        "left, right, front, back, bottom, top, the corners and all"
    };
    let box_of = |b: &crate::io::scene::BoxSpec, loc: &str| -> Result<([f64; D], [f64; D])> {
        Ok((
            set_point::<D>(&b.min.0, "box's min", source, loc)?,
            set_point::<D>(&b.max.0, "box's max", source, loc)?,
        ))
    };
    for (name, set) in &spec.node_sets {
        let loc = format!("{at}.node_sets.{name}");
        if mesh.node_sets.contains_key(name) {
            return Err(Error::invalid(
                source,
                loc,
                format!("'{name}' is a built-in set name"),
                format!("choose another name; the built-in sets are {built_in}"),
            ));
        }
        let nodes = match set {
            NodeSetSpec::Box(b) => {
                let (lo, hi) = box_of(b, &loc)?;
                mesh.nodes_in_box(lo, hi, tol)
            }
            NodeSetSpec::Point(p) => {
                let p = set_point::<D>(&p.0, "point", source, &loc)?;
                match mesh.nearest_node(p) {
                    Some((n, d)) if d <= tol => vec![n],
                    Some((n, d)) => {
                        return Err(Error::invalid(
                            source,
                            loc,
                            format!(
                                "no node at ({}); the nearest is node {n} at ({}), {d:.3e} away",
                                point_words(p),
                                point_words(mesh.nodes[n])
                            ),
                            "give the exact coordinates of a node",
                        ));
                    }
                    None => Vec::new(),
                }
            }
            NodeSetSpec::Nodes(ids) => {
                if let Some(&bad) = ids.iter().find(|&&n| n >= mesh.nodes.len()) {
                    return Err(Error::invalid(
                        source,
                        loc,
                        format!(
                            "node {bad} does not exist (the body has {} nodes)",
                            mesh.nodes.len()
                        ),
                        "use node indices below the number of nodes",
                    ));
                }
                ids.clone()
            }
        };
        if nodes.is_empty() {
            return Err(Error::invalid(
                source,
                loc,
                "the set selects no node",
                "check the box limits against the body's coordinates",
            ));
        }
        if let NodeSetSpec::Box(b) = set {
            let corners = box_of(b, &loc)?;
            warnings.extend(widened_box_warning(
                mesh,
                nodes.iter().copied(),
                corners,
                &loc,
            ));
        }
        mesh.node_sets.insert(name.clone(), nodes);
    }
    for (name, set) in &spec.facet_sets {
        let loc = format!("{at}.facet_sets.{name}");
        if mesh.facet_sets.contains_key(name) {
            return Err(Error::invalid(
                source,
                loc,
                format!("'{name}' is a built-in set name"),
                if D == 2 {
                    "choose another name; the built-in facet sets are left, right, bottom and top"
                } else {
                    "choose another name; the built-in facet sets are left, right, front, back, bottom and top"
                },
            ));
        }
        let facets = match set {
            FacetSetSpec::Box(b) => {
                let (lo, hi) = box_of(b, &loc)?;
                mesh.facets_in_box(lo, hi, tol)
            }
            FacetSetSpec::Facets(list) => {
                let mut out = Vec::new();
                for &[cell, edge] in list {
                    if cell >= mesh.cell_count() || edge >= mesh.kind.facets().len() {
                        return Err(Error::invalid(
                            source,
                            loc,
                            format!("facet [{cell}, {edge}] does not exist"),
                            if D == 2 {
                                "use [cell, local edge] with valid indices"
                            } else {
                                "use [cell, local face] with valid indices"
                            },
                        ));
                    }
                    out.push(Facet { cell, edge });
                }
                out
            }
        };
        if facets.is_empty() {
            return Err(Error::invalid(
                source,
                loc,
                "the set selects no boundary facet",
                "a facet enters a box set only when all its nodes lie in the box",
            ));
        }
        if let FacetSetSpec::Box(b) = set {
            let corners = box_of(b, &loc)?;
            let nodes: Vec<usize> = facets.iter().flat_map(|&f| mesh.facet_nodes(f)).collect();
            warnings.extend(widened_box_warning(mesh, nodes.into_iter(), corners, &loc));
            warnings.extend(separate_pieces_warning(mesh, &facets, &loc));
        }
        mesh.facet_sets.insert(name.clone(), facets);
    }
    Ok(warnings)
}

/// A box facet set whose facets do not form one connected piece of boundary (two facets are
/// connected when they share an end node) has caught facets away from the edge or arc it was
/// drawn around, e.g. the end of another side that reaches into the box: a warning naming the
/// set, the number of pieces and each piece's facets and extent. `None` for one piece.
fn separate_pieces_warning<const D: usize, K: ReferenceCell<D>>(
    mesh: &Mesh<D, K>,
    facets: &[Facet],
    loc: &str,
) -> Option<String> {
    // each facet's corners (an edge's two ends in 2D)
    let ends: Vec<Vec<usize>> = facets
        .iter()
        .map(|&f| {
            let n = mesh.facet_nodes(f);
            n[..mesh.kind.facet_corner_count(f.edge)].to_vec()
        })
        .collect();
    // union-find over the facets, joined through shared end nodes
    let mut parent: Vec<usize> = (0..facets.len()).collect();
    fn root(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    let mut first_at: std::collections::HashMap<usize, usize> = Default::default();
    for (i, e) in ends.iter().enumerate() {
        for &n in e {
            match first_at.get(&n) {
                Some(&j) => {
                    let (a, b) = (root(&mut parent, i), root(&mut parent, j));
                    parent[a] = b;
                }
                None => {
                    first_at.insert(n, i);
                }
            }
        }
    }
    let mut pieces: std::collections::BTreeMap<usize, (usize, [f64; D], [f64; D])> =
        Default::default();
    for (i, e) in ends.iter().enumerate() {
        let r = root(&mut parent, i);
        let piece = pieces
            .entry(r)
            .or_insert((0, [f64::INFINITY; D], [f64::NEG_INFINITY; D]));
        piece.0 += 1;
        for &n in e {
            for k in 0..D {
                piece.1[k] = piece.1[k].min(mesh.nodes[n][k]);
                piece.2[k] = piece.2[k].max(mesh.nodes[n][k]);
            }
        }
    }
    if pieces.len() < 2 {
        // the turn between consecutive edges (2D)
        if D != 2 {
            return None;
        }
        let ends: Vec<[usize; 2]> = ends.iter().map(|e| [e[0], e[1]]).collect();
        return sharp_turn_warning(&mesh.nodes, &ends, loc);
    }
    let listed: Vec<String> = pieces
        .values()
        .map(|(count, lo, hi)| format!("{count} facet(s) in {}", box_words(*lo, *hi)))
        .collect();
    Some(format!(
        "{loc}: the box takes in {} separate pieces of boundary ({}); a box drawn around one edge \
         or arc has caught facets of another. Shrink the box to the piece meant, or list the \
         facets, or make one set per piece",
        pieces.len(),
        listed.join("; ")
    ))
}

/// A box facet set that turns a corner sharper than 45 degrees where two of its facets meet
/// (the angle between the chords of consecutive facets) has caught the end of another side:
/// a warning naming the set and the corners. `None` if it turns no such corner (an arc meshed
/// finely turns by a few degrees per facet).
fn sharp_turn_warning<const D: usize>(
    nodes: &[[f64; D]],
    ends: &[[usize; 2]],
    loc: &str,
) -> Option<String> {
    let chord = |e: &[usize; 2]| {
        let (a, b) = (nodes[e[0]], nodes[e[1]]);
        [b[0] - a[0], b[1] - a[1]]
    };
    let mut corners = Vec::new();
    for into in ends {
        // boundary facets run counter-clockwise, so the next facet starts where this one ends
        for out in ends.iter().filter(|o| o[0] == into[1]) {
            let (u, v) = (chord(into), chord(out));
            let cos = (u[0] * v[0] + u[1] * v[1]) / (u[0].hypot(u[1]) * v[0].hypot(v[1]));
            let angle = cos.clamp(-1.0, 1.0).acos().to_degrees();
            if angle > 45.0 {
                let p = nodes[into[1]];
                corners.push(format!("{angle:.0} degrees at ({}, {})", p[0], p[1]));
            }
        }
    }
    if corners.is_empty() {
        return None;
    }
    Some(format!(
        "{loc}: the box's facets turn {} corner(s) sharper than 45 degrees ({}); a box drawn \
         around one edge or arc has caught facets of another side. Shrink the box to the side \
         meant, or list the facets, or make one set per side",
        corners.len(),
        corners.join("; ")
    ))
}

/// A load on a facet: a pressure against the outward normal, a traction vector, or the exact
/// field's traction `sigma_exact . n` (2D).
#[derive(Clone, Debug)]
pub enum FacetLoad<const D: usize> {
    Pressure(f64),
    Vector([f64; D]),
    Exact(ExactField),
}

/// Consistent nodal forces of a distributed load on one edge of kind `kind` with nodes at
/// `coords` (2D, times `thickness`): `add(a, i, value)` per quadrature point.
pub(crate) fn add_edge_load(
    kind: crate::fe::EdgeKind,
    coords: &[[f64; 2]],
    load: &FacetLoad<2>,
    thickness: f64,
    add: &mut dyn FnMut(usize, usize, f64),
) {
    let nn = kind.node_count();
    let mut n = [0.0; 3];
    let mut dn = [0.0; 3];
    for (s, w) in kind.load_rule() {
        kind.shape(s, &mut n[..nn], &mut dn[..nn]);
        let mut x = [0.0; 2];
        let mut dx = [0.0; 2];
        for a in 0..nn {
            let p = coords[a];
            for i in 0..2 {
                x[i] += n[a] * p[i];
                dx[i] += dn[a] * p[i];
            }
        }
        // n ds = [dy, -dx] ds for a counter-clockwise edge.
        let n_ds = [dx[1], -dx[0]];
        let length = (n_ds[0] * n_ds[0] + n_ds[1] * n_ds[1]).sqrt();
        let t_ds = match load {
            FacetLoad::Pressure(p) => [-p * n_ds[0], -p * n_ds[1]],
            FacetLoad::Vector(t) => [t[0] * length, t[1] * length],
            FacetLoad::Exact(f) => {
                let s = f.stress(x);
                [
                    s[0] * n_ds[0] + s[2] * n_ds[1],
                    s[2] * n_ds[0] + s[1] * n_ds[1],
                ]
            }
        };
        for a in 0..nn {
            for i in 0..2 {
                add(a, i, w * thickness * n[a] * t_ds[i]);
            }
        }
    }
}

/// Consistent nodal forces of a constant body force over the whole body (2D: times the
/// thickness), by the cells' load rule.
fn add_body_force<const D: usize, K: SolidCell<D>>(
    body: &Body<D, K>,
    b: [f64; D],
    thickness: f64,
    force: &mut [f64],
) {
    use crate::fe::PointGeometry;
    let kind = body.mesh.kind;
    let rule = kind.load_rule();
    for c in 0..body.mesh.cell_count() {
        let coords = body.mesh.cell_coords(c);
        let cell = body.mesh.cell(c);
        for q in &rule {
            let pv = kind.point_values(&coords, q.xi);
            let w = q.weight * pv.jacobian_determinant() * thickness;
            let n = pv.values();
            for (a, &node) in cell.iter().enumerate() {
                for i in 0..D {
                    force[body.dof(node, i)] += w * n[a] * b[i];
                }
            }
        }
    }
}

#[cfg(test)]
mod dof_numbering_tests {
    use super::*;

    #[test]
    fn dof_owner_inverts_the_numbering() {
        let text = r#"{"name": "two", "materials": {"m": {"E": 1.0, "nu": 0.3}},
            "bodies": [
              {"name": "a", "material": "m", "mesh": {"block": {"element": "Q4", "x": [0, 1, 2], "y": [0, 1]}}},
              {"name": "b", "material": "m", "mesh": {"block": {"element": "Q9", "x": [0, 1], "y": [1, 2]}}}],
            "supports": [{"body": "a", "set": "bottom", "x": 0.0, "y": 0.0},
                         {"body": "b", "set": "top", "x": 0.0, "y": 0.0}]}"#;
        let model = Model::build(&parse(text, "two").unwrap(), "two").unwrap();
        let mut seen = 0;
        for (bi, b) in model.bodies.iter().enumerate() {
            for node in 0..b.mesh.nodes.len() {
                for component in 0..2 {
                    let d = b.dof(node, component);
                    assert_eq!(
                        model.dof_owner(d),
                        Some(DofRef {
                            body: bi,
                            node,
                            component
                        })
                    );
                    assert!(b.owns(d));
                    seen += 1;
                }
            }
        }
        assert_eq!(seen, model.dof_count);
        assert_eq!(model.dof_owner(model.dof_count), None);
    }
}

#[cfg(test)]
mod solve_work_tests {
    use super::*;
    use crate::solver::sparse::{Cholesky, UNLIMITED};

    /// The matrix entries and the factor's entries and multiply-adds the assembly and the
    /// symbolic analysis find for the block mesh `mesh` (JSON) without supports (every dof
    /// free), and the estimate of [`block_work`].
    fn found_and_estimated(mesh: &str) -> (SolveWork, SolveWork) {
        let text = format!(
            r#"{{"name": "w", "materials": {{"m": {{"E": 1.0, "nu": 0.3}}}},
                "bodies": [{{"name": "b", "material": "m", "mesh": {mesh}}}]}}"#
        );
        let case = parse(&text, "w").unwrap();
        let (pattern, points, estimate) = if crate::run3d::is_3d(&case, "") {
            let model = crate::run3d::build3(&case, "w").unwrap();
            let sys = crate::solver::linear::assemble(&model, &[]);
            let points = model.equation_points(sys.constraints.free_dofs());
            let MeshSpec::Block3d(b) = &case.bodies[0].mesh else {
                unreachable!()
            };
            let along = [b.x.intervals(), b.y.intervals(), b.z.intervals()];
            (sys.pattern, points, block_work(b.element, along))
        } else {
            let model = Model::build(&case, "w").unwrap();
            let sys = crate::solver::linear::assemble(&model, &[]);
            let points = model.equation_points(sys.constraints.free_dofs());
            let MeshSpec::Block(b) = &case.bodies[0].mesh else {
                unreachable!()
            };
            (
                sys.pattern,
                points,
                block_work(b.element, [b.x.intervals(), b.y.intervals()]),
            )
        };
        let work = Cholesky::analyse_at(&pattern, Some(&points), &UNLIMITED)
            .unwrap()
            .work();
        let found = SolveWork {
            matrix_entries: pattern.nnz() as f64,
            factor_entries: work.entries as f64,
            factor_operations: work.operations,
        };
        (found, estimate)
    }

    /// The estimate is below what the assembly and the analysis find on block meshes of every
    /// element (so a case it refuses would be refused after its matrix was allocated), the
    /// matrix's entries exact for quadrilaterals and hexahedra.
    #[test]
    fn the_block_work_estimate_is_below_what_the_solve_finds() {
        let axis = |n: usize| format!(r#"{{"from": 0, "to": 1, "divisions": {n}}}"#);
        let two = |e: &str, n: usize, m: usize| {
            format!(
                r#"{{"block": {{"element": "{e}", "x": {}, "y": {}}}}}"#,
                axis(n),
                axis(m)
            )
        };
        let three = |e: &str, n: usize, m: usize, k: usize| {
            format!(
                r#"{{"block3d": {{"element": "{e}", "x": {}, "y": {}, "z": {}}}}}"#,
                axis(n),
                axis(m),
                axis(k)
            )
        };
        let meshes = [
            (two("Q4", 60, 40), true),
            (two("Q9", 30, 20), true),
            (two("T3", 60, 40), false),
            (two("T6", 30, 20), false),
            (three("Hex8", 12, 10, 8), true),
            (three("Hex8", 20, 20, 2), true),
            (three("Hex27", 6, 5, 4), true),
            (three("Tet4", 12, 10, 8), false),
            (three("Tet10", 6, 5, 4), false),
        ];
        for (mesh, tensor) in meshes {
            let (found, estimate) = found_and_estimated(&mesh);
            println!(
                "{mesh}: matrix {:.3e} of {:.3e}, factor entries {:.3e} of {:.3e}, operations {:.3e} of {:.3e}",
                estimate.matrix_entries,
                found.matrix_entries,
                estimate.factor_entries,
                found.factor_entries,
                estimate.factor_operations,
                found.factor_operations
            );
            if tensor {
                assert_eq!(estimate.matrix_entries, found.matrix_entries, "{mesh}");
            } else {
                assert!(estimate.matrix_entries <= found.matrix_entries, "{mesh}");
            }
            assert!(estimate.factor_entries <= found.factor_entries, "{mesh}");
            assert!(
                estimate.factor_operations <= found.factor_operations,
                "{mesh}"
            );
        }
    }
}

#[cfg(test)]
mod expected_failure_tests {
    use super::*;

    /// The message of building a one-block case with `checks` and `expected_failures` (JSON),
    /// or `None` when it builds.
    fn refusal(checks: &str, expected_failures: &str) -> Option<String> {
        let text = format!(
            r#"{{"name": "x", "materials": {{"m": {{"E": 1.0, "nu": 0.3}}}},
                "bodies": [{{"name": "b", "material": "m", "mesh": {{"block": {{"element": "Q4",
                    "x": [0, 1], "y": [0, 1]}}}}}}],
                "checks": {checks}, "expected_failures": {expected_failures}}}"#
        );
        let case = parse(&text, "x").unwrap();
        Model::build(&case, "x").err().map(|e| e.to_string())
    }

    const STRESS: &str = r#"{"check": "uniform_stress", "stress": [0, 0, 0], "tol": 1e-10}"#;
    const DISPLACEMENT: &str = r#"{"check": "displacement", "body": "b", "point": [1, 1],
        "component": "x", "value": 0, "tol": 1e-10}"#;

    #[test]
    fn an_entry_names_one_declared_check_with_a_reason() {
        let why = r#""a known result""#;
        // one check of the kind, with a reason: built, and the model knows the reason by check
        let text = format!(
            r#"{{"name": "x", "materials": {{"m": {{"E": 1.0, "nu": 0.3}}}},
                "bodies": [{{"name": "b", "material": "m", "mesh": {{"block": {{"element": "Q4",
                    "x": [0, 1], "y": [0, 1]}}}}}}],
                "checks": [{STRESS}, {DISPLACEMENT}],
                "expected_failures": [{{"check": "displacement", "reason": {why}}}]}}"#
        );
        let model = Model::build(&parse(&text, "x").unwrap(), "x").unwrap();
        assert_eq!(model.expected_failure(&model.checks[0]), None);
        assert_eq!(
            model.expected_failure(&model.checks[1]),
            Some("a known result")
        );
        let entry = |kind: &str| format!(r#"{{"check": "{kind}", "reason": {why}}}"#);
        let cases = [
            (
                format!("[{STRESS}]"),
                format!("[{}]", entry("reaction")),
                "expected_failures[0]: the case declares no check of kind 'reaction' (its checks are: uniform_stress)",
            ),
            (
                "[]".to_string(),
                format!("[{}]", entry("uniform_stress")),
                "(the case declares no checks)",
            ),
            (
                format!("[{STRESS}, {STRESS}]"),
                format!("[{}]", entry("uniform_stress")),
                "the case declares 2 checks of kind 'uniform_stress' (checks[0], checks[1])",
            ),
            (
                format!("[{STRESS}]"),
                format!("[{}, {}]", entry("uniform_stress"), entry("uniform_stress")),
                "expected_failures[1]: the kind 'uniform_stress' is listed twice (also at expected_failures[0])",
            ),
            (
                format!(r#"[{STRESS}, {{"check": "warns", "contains": "w"}}]"#),
                format!("[{}]", entry("warns")),
                "a 'warns' check passes or fails without a measured error",
            ),
            (
                format!("[{STRESS}]"),
                r#"[{"check": "uniform_stress", "reason": ""}]"#.to_string(),
                "expected_failures[0]: the reason is empty",
            ),
        ];
        for (checks, listed, said) in cases {
            let message = refusal(&checks, &listed).expect("refused");
            assert!(message.contains(said), "{message}");
            assert!(message.contains("hint: "), "{message}");
        }
    }
}
