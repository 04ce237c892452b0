//! What a case may ask for: the capability matrix of the README, asked of the validation every
//! run goes through, so that it cannot drift from what the tool accepts.
//!
//! [`admitted`] makes every check `contact-patch run` makes before its first solve: the case
//! built into a model (`Model::build` and `model::admit` in 2D, `run3d::build3` and the rigid
//! modes in 3D), the linear solver's admission (`solver::iterative::refuse_unless_admitted`),
//! and the contact rows built at the start configuration with each pair's enforcement asked
//! whether it can treat them (`solver::refuse_obstacles`, which the active-set and Newton
//! solves call on their rows). A combination is asked on a small scene ([`Scene`]: a punch
//! pressed onto a foundation of the same footprint on matching grids, or onto a rigid line or
//! plane), so a refusal names a rule of the tool, not a property of a mesh. "yes" means such a
//! case passes every check before the solve; whether the solve converges and passes the patch
//! test is what the tables (`contact-patch table`, 3D included, and `finite-patch`) judge.
//!
//! [`matrix_markdown`] writes the two tables of the README: discretizations x enforcement
//! methods (frictionless, small strain, static; each dimension), and dimension x kinematics x
//! interaction x static/dynamic (the discretizations accepted, or the reason for none).
//! `tests/docs.rs` keeps README's block equal to it (`UPDATE_README=1` rewrites it).

use crate::error::{Error, Result};
use crate::io::scene::ContactGeometry;
use crate::model::Model;
use serde_json::{json, Value};

/// The contact discretizations a pair may name, against a deformable or a rigid master.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Discretization {
    NodeToNode,
    NodeToSurface1,
    NodeToSurface2,
    MortarStandard,
    MortarDual,
    RigidNodeToSurface,
    RigidMortarStandard,
    RigidMortarDual,
}

impl Discretization {
    pub const ALL: [Discretization; 8] = [
        Discretization::NodeToNode,
        Discretization::NodeToSurface1,
        Discretization::NodeToSurface2,
        Discretization::MortarStandard,
        Discretization::MortarDual,
        Discretization::RigidNodeToSurface,
        Discretization::RigidMortarStandard,
        Discretization::RigidMortarDual,
    ];

    /// The row's name in the matrix.
    pub fn title(self) -> &'static str {
        match self {
            Discretization::NodeToNode => "node-to-node",
            Discretization::NodeToSurface1 => "node-to-surface, one pass",
            Discretization::NodeToSurface2 => "node-to-surface, two passes",
            Discretization::MortarStandard => "mortar, standard multipliers",
            Discretization::MortarDual => "mortar, dual multipliers",
            Discretization::RigidNodeToSurface => "rigid master, node-to-surface",
            Discretization::RigidMortarStandard => "rigid master, mortar standard",
            Discretization::RigidMortarDual => "rigid master, mortar dual",
        }
    }

    /// A short name, for the lists of the physics matrix.
    pub fn short(self) -> &'static str {
        match self {
            Discretization::NodeToNode => "n2n",
            Discretization::NodeToSurface1 => "n2s",
            Discretization::NodeToSurface2 => "n2s-2",
            Discretization::MortarStandard => "mortar",
            Discretization::MortarDual => "dual",
            Discretization::RigidNodeToSurface => "rigid n2s",
            Discretization::RigidMortarStandard => "rigid mortar",
            Discretization::RigidMortarDual => "rigid dual",
        }
    }

    fn rigid(self) -> bool {
        matches!(
            self,
            Discretization::RigidNodeToSurface
                | Discretization::RigidMortarStandard
                | Discretization::RigidMortarDual
        )
    }

    fn spec(self) -> Value {
        match self {
            Discretization::NodeToNode => json!({"kind": "node_to_node"}),
            Discretization::NodeToSurface1 | Discretization::RigidNodeToSurface => {
                json!({"kind": "node_to_surface", "passes": 1})
            }
            Discretization::NodeToSurface2 => json!({"kind": "node_to_surface", "passes": 2}),
            Discretization::MortarStandard | Discretization::RigidMortarStandard => {
                json!({"kind": "mortar", "multiplier": "standard"})
            }
            Discretization::MortarDual | Discretization::RigidMortarDual => {
                json!({"kind": "mortar", "multiplier": "dual"})
            }
        }
    }
}

/// The enforcement methods, as a case names them.
pub const ENFORCEMENTS: [(&str, &str); 6] = [
    ("lagrange", "Lagrange multipliers"),
    ("perturbed_lagrange", "perturbed Lagrangian"),
    ("penalty", "penalty"),
    ("perturbed_tangent", "perturbed tangent"),
    ("augmented_lagrange", "augmented Lagrangian"),
    ("elimination", "constraint elimination"),
];

/// The interaction of a pair.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interaction {
    Frictionless,
    Tied,
    Coulomb,
}

/// One scene whose admission is asked: a punch on a foundation (or on a rigid master) with
/// the cell's physics and one contact pair.
#[derive(Clone, Copy, Debug)]
pub struct Scene {
    pub dim: usize,
    pub finite: bool,
    pub interaction: Interaction,
    pub dynamic: bool,
    pub discretization: Discretization,
    /// The case's name of the enforcement method (see [`ENFORCEMENTS`]).
    pub enforcement: &'static str,
    pub newton: bool,
    pub current_geometry: bool,
}

impl Scene {
    /// The case file of the scene.
    pub fn case(&self) -> Value {
        let d3 = self.dim == 3;
        let axis = |from: f64, to: f64| json!({"from": from, "to": to, "divisions": 2});
        let block = |lo: f64, hi: f64| {
            if d3 {
                json!({"block3d": {"element": "Hex8", "x": axis(0.0, 1.0), "y": axis(0.0, 1.0), "z": axis(lo, hi)}})
            } else {
                json!({"block": {"element": "Q4", "x": axis(0.0, 1.0), "y": axis(lo, hi)}})
            }
        };
        let mut material = json!({"E": 1000.0, "nu": 0.3});
        if self.finite {
            material["model"] = json!("neo_hookean");
        }
        if self.dynamic {
            material["density"] = json!(1.0);
        }
        let rigid = self.discretization.rigid();
        let mut bodies = vec![json!({"name": "punch", "material": "m", "mesh": block(0.0, 1.0)})];
        // the punch held in the tangential directions, the foundation everywhere at its bottom
        let mut supports = vec![json!({"body": "punch", "set": "left", "x": 0.0})];
        if d3 {
            supports.push(json!({"body": "punch", "set": "front", "y": 0.0}));
        }
        let master = if rigid {
            if d3 {
                json!({"rigid": {"kind": "plane", "point": [0.0, 0.0, 0.0], "normal": [0.0, 0.0, 1.0]}})
            } else {
                json!({"rigid": {"kind": "line", "point": [0.0, 0.0], "normal": [0.0, 1.0]}})
            }
        } else {
            bodies.push(json!({"name": "foundation", "material": "m", "mesh": block(-1.0, 0.0)}));
            let mut held = json!({"body": "foundation", "set": "bottom", "x": 0.0, "y": 0.0});
            if d3 {
                held["z"] = json!(0.0);
            }
            supports.push(held);
            json!({"body": "foundation", "set": "top"})
        };
        let interaction = match self.interaction {
            Interaction::Frictionless => json!("frictionless"),
            Interaction::Tied => json!("tied"),
            Interaction::Coulomb => json!({"coulomb": {"mu": 0.3}}),
        };
        let mut enforcement = json!({"kind": self.enforcement});
        if !matches!(self.enforcement, "lagrange" | "elimination") {
            enforcement["kappa"] = json!(1.0e6);
        }
        let mut physics = json!({});
        if self.finite {
            physics["kinematics"] = json!("finite");
        }
        if self.current_geometry {
            physics["contact_geometry"] = json!("current");
        }
        if self.dynamic {
            physics["dynamics"] = json!({
                "integrator": "average_acceleration", "dt": 0.01, "end_time": 0.02,
                "mass": "lumped", "impact": "plain"
            });
        }
        let mut case = json!({
            "name": "capability",
            "materials": {"m": material},
            "bodies": bodies,
            "supports": supports,
            "loads": [{"body": "punch", "set": "top", "pressure": 1.0}],
            "contact": [{
                "name": "c",
                "slave": {"body": "punch", "set": "bottom"},
                "master": master,
                "interaction": interaction,
                "discretization": self.discretization.spec(),
                "enforcement": enforcement
            }],
            "physics": physics,
            "solver": {"scheme": if self.newton { "newton" } else { "active_set" }}
        });
        if !d3 {
            case["analysis"] = json!({"plane": "strain", "thickness": 1.0});
        }
        case
    }

    /// Whether the tool accepts the scene: `Err` holds the reason it gives.
    pub fn admitted(&self) -> std::result::Result<(), String> {
        let source = "capability";
        let case = crate::model::parse(&self.case().to_string(), source).map_err(|e| reason(&e))?;
        admitted(&case, source).map_err(|e| reason(&e))
    }
}

/// The problem of an error, without where it was found and the hint.
fn reason(e: &Error) -> String {
    match e {
        Error::Invalid { problem, .. } | Error::Solver { problem, .. } => problem.clone(),
        Error::Parse { message, .. } => message.clone(),
        other => other.to_string(),
    }
}

/// Every check `contact-patch run` makes on `case` (read from `source`) before its first
/// solve; `Ok` when it would start solving.
pub fn admitted(case: &crate::io::scene::Case, source: &str) -> Result<()> {
    if crate::run3d::is_3d(case, source) {
        let model = crate::run3d::build3(case, source)?;
        crate::model::admit::check_rigid_modes(&model)?;
        before_the_solve(&model)
    } else {
        let model = crate::model::admit::admit(Model::build(case, source)?)?;
        before_the_solve(&model)
    }
}

/// The solver's own refusals: the linear solver's admission, and each pair's method asked
/// whether it can treat the pair's rows at the start configuration.
fn before_the_solve<const D: usize, K: crate::contact::discretization::Discretize<D>>(
    model: &Model<D, K>,
) -> Result<()> {
    crate::solver::iterative::refuse_unless_admitted(model)?;
    if model.contact.is_empty() {
        return Ok(());
    }
    let current = model.physics.contact_geometry == ContactGeometry::Current;
    let areas = if current {
        crate::contact::rows::reference_areas(model)?
    } else {
        crate::contact::rows::ReferenceAreas::new()
    };
    let start = vec![0.0; model.dof_count];
    let rows = crate::contact::rows::rows_at(model, current.then_some((start.as_slice(), &areas)))?;
    crate::solver::refuse_obstacles(model, &rows)
}

/// Whether a discretization and an enforcement method apply together, frictionless, small
/// strain and static, in dimension `dim`, under either solution scheme: `Err` the reason the
/// default scheme (active set) gives.
pub fn axes_cell(
    dim: usize,
    discretization: Discretization,
    enforcement: &'static str,
) -> std::result::Result<(), String> {
    let scene = |newton| Scene {
        dim,
        finite: false,
        interaction: Interaction::Frictionless,
        dynamic: false,
        discretization,
        enforcement,
        newton,
        current_geometry: false,
    };
    let active_set = scene(false).admitted();
    if active_set.is_ok() || scene(true).admitted().is_ok() {
        return Ok(());
    }
    active_set
}

/// The discretizations accepted with some enforcement method, scheme and contact geometry
/// for the physics of one cell; when none is, the refusal of the attempt a user would make
/// first (node-to-surface, penalty, the Newton scheme, the current geometry for a static
/// finite-strain scene).
pub fn physics_cell(
    dim: usize,
    finite: bool,
    interaction: Interaction,
    dynamic: bool,
) -> std::result::Result<Vec<Discretization>, String> {
    let mut accepted = Vec::new();
    for discretization in Discretization::ALL {
        let mut found = false;
        for &(enforcement, _) in &ENFORCEMENTS {
            for newton in [false, true] {
                for current_geometry in [false, true] {
                    let scene = Scene {
                        dim,
                        finite,
                        interaction,
                        dynamic,
                        discretization,
                        enforcement,
                        newton,
                        current_geometry,
                    };
                    if scene.admitted().is_ok() {
                        found = true;
                    }
                }
            }
        }
        if found {
            accepted.push(discretization);
        }
    }
    if !accepted.is_empty() {
        return Ok(accepted);
    }
    // the reason of the attempt a user would make: the Newton scheme (friction and dynamics
    // need it), node-to-surface, penalty, the current geometry under static finite strain
    Err(Scene {
        dim,
        finite,
        interaction,
        dynamic,
        discretization: Discretization::NodeToSurface1,
        enforcement: "penalty",
        newton: true,
        current_geometry: finite && !dynamic,
    }
    .admitted()
    .expect_err("no discretization was accepted"))
}

/// The reasons of a matrix, numbered in the order they are first met.
#[derive(Default)]
struct Reasons(Vec<String>);

impl Reasons {
    /// A cell's text: `yes` (with `detail`), or `n/a (k)` for the `k`-th reason.
    fn cell(&mut self, outcome: std::result::Result<String, String>) -> String {
        match outcome {
            Ok(detail) => detail,
            Err(why) => {
                let why = why.replace('\n', " ");
                let k = match self.0.iter().position(|w| *w == why) {
                    Some(k) => k,
                    None => {
                        self.0.push(why);
                        self.0.len() - 1
                    }
                };
                format!("n/a ({})", k + 1)
            }
        }
    }

    fn markdown(&self) -> String {
        self.0
            .iter()
            .enumerate()
            .map(|(k, why)| format!("{}. {why}\n", k + 1))
            .collect()
    }
}

/// The README's capability matrix, in Markdown: the two tables and the numbered reasons of
/// their `n/a` cells.
pub fn matrix_markdown() -> String {
    let mut reasons = Reasons::default();
    let mut out = String::new();
    for dim in [2, 3] {
        out.push_str(&format!(
            "**{dim}D, discretization x enforcement** (frictionless, small strain, static; the active-set or the Newton scheme):\n\n| | {} |\n|---|{}\n",
            ENFORCEMENTS.map(|(_, t)| t).join(" | "),
            "---|".repeat(ENFORCEMENTS.len())
        ));
        for d in Discretization::ALL {
            let cells: Vec<String> = ENFORCEMENTS
                .iter()
                .map(|&(e, _)| reasons.cell(axes_cell(dim, d, e).map(|()| "yes".into())))
                .collect();
            out.push_str(&format!("| {} | {} |\n", d.title(), cells.join(" | ")));
        }
        out.push('\n');
    }
    out.push_str("**Physics** (each cell: the discretizations accepted with some enforcement method, or why none is):\n\n| dimension | strain | interaction | static | dynamic |\n|---|---|---|---|---|\n");
    for dim in [2, 3] {
        for finite in [false, true] {
            for (interaction, name) in [
                (Interaction::Frictionless, "frictionless"),
                (Interaction::Tied, "tied"),
                (Interaction::Coulomb, "Coulomb"),
            ] {
                let cells: Vec<String> = [false, true]
                    .iter()
                    .map(|&dynamic| {
                        reasons.cell(physics_cell(dim, finite, interaction, dynamic).map(|list| {
                            format!(
                                "yes: {}",
                                list.iter()
                                    .map(|d| d.short())
                                    .collect::<Vec<_>>()
                                    .join(", ")
                            )
                        }))
                    })
                    .collect();
                out.push_str(&format!(
                    "| {dim}D | {} | {name} | {} |\n",
                    if finite { "finite" } else { "small" },
                    cells.join(" | ")
                ));
            }
        }
    }
    out.push_str("\nn2n node-to-node, n2s node-to-surface (one pass; n2s-2 two passes), mortar and dual: segment-based mortar with standard or dual multipliers; rigid: against the scene's rigid master, a line in 2D and a plane in 3D. The reasons, as the tool gives them:\n\n");
    out.push_str(&reasons.markdown());
    out
}
