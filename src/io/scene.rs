//! The case file: a JSON description of one scene, read with serde into typed objects.
//!
//! A case names its materials, bodies (each with a mesh and named sets), supports, loads, an
//! optional exact solution, the physics it asks for, and the checks that judge the result.
//! Unknown fields are rejected everywhere. Physics is opt-in: a scene that does not ask for a
//! feature never pays for it. Everything here is plain data; `model::Model::build` validates it
//! once and resolves names into indices.
//!
//! Units are the user's; the only convention is compression-positive contact pressure and
//! pressure loads that push against the outward normal.

use crate::fe::ElementKind;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Case {
    /// The JSON Schema the file follows, for editors (`cases/case.schema.json`); not read.
    #[serde(rename = "$schema", default, skip_serializing_if = "Option::is_none")]
    pub schema: Option<String>,
    /// Short identifier; the default output folder is `out/<name>`.
    pub name: String,
    #[serde(default)]
    pub description: String,
    #[serde(default)]
    pub analysis: Analysis,
    #[serde(deserialize_with = "unique_keys")]
    pub materials: BTreeMap<String, MaterialSpec>,
    pub bodies: Vec<BodySpec>,
    #[serde(default)]
    pub supports: Vec<Support>,
    #[serde(default)]
    pub loads: Vec<Load>,
    /// An analytic reference solution, used by `exact` supports/tractions and by checks.
    #[serde(default)]
    pub exact: Option<ExactSpec>,
    #[serde(default)]
    pub physics: Physics,
    /// Contact pairs (frictionless, small strain).
    #[serde(default)]
    pub contact: Vec<ContactSpec>,
    /// Variants of the contact pairs that `contact-patch table` runs (the case itself runs
    /// the pairs as written).
    #[serde(default)]
    pub sweep: Option<SweepSpec>,
    #[serde(default)]
    pub checks: Vec<Check>,
    /// Checks of `checks` the case expects to fail, each with the reason (a known result of the
    /// method as written, not a defect of the run). A listed check that fails is an expected
    /// failure and the case passes; a listed check that passes fails the case, so that the
    /// statement cannot go stale; a check that cannot be measured (error NaN or infinite) fails
    /// the case as always. `contact-patch judge` judges another code's results, whose method
    /// the case does not state, as plain checks.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    #[schemars(extend("default" = []))]
    pub expected_failures: Vec<ExpectedFailure>,
    /// Bounds on the work a case may ask for, checked before anything is allocated.
    #[serde(default)]
    pub limits: Limits,
    /// Load steps, iteration limits and tolerances of the solve.
    #[serde(default)]
    pub solver: SolverSpec,
}

/// How the solve proceeds: the load applied in equal steps, each converged before the next
/// starts from its state, with limits per case instead of global constants.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SolverSpec {
    /// Number of equal load steps (load factor `k / n` at step `k`); default 1.
    #[serde(default = "one_step")]
    pub load_steps: usize,
    /// Most linear solves of the active-set loop in one step; default 200.
    #[serde(default = "two_hundred")]
    pub max_iterations: usize,
    /// Most re-evaluations of the contact geometry in one step (current geometry); default 50.
    #[serde(default = "fifty")]
    pub max_geometry_updates: usize,
    /// Relative change of the displacement below which the geometry updates stop; default 1e-12.
    #[serde(default = "geometry_tolerance")]
    pub geometry_tolerance: f64,
    /// Newton's geometric term of the contact forces in the geometry updates (current geometry,
    /// rows that provide their second derivative): `true` (default) for quadratic convergence,
    /// `false` for the plain fixed point (to compare).
    #[serde(default = "yes")]
    pub geometric_stiffness: bool,
    /// How each load step is solved: `"active_set"` (default; every enforcement method) or
    /// `"newton"` (the residual/tangent Newton core, penalty-type methods: penalty, perturbed
    /// Lagrangian with diagonal perturbation, augmented Lagrangian).
    #[serde(default)]
    pub scheme: Scheme,
    /// The tangent of slipping frictional points (Coulomb pairs, Newton scheme):
    /// `"consistent"` (default, unsymmetric) or `"symmetrized"`.
    #[serde(default)]
    pub friction_tangent: FrictionTangent,
    /// What the active-set scheme does when its active set repeats (cycling):
    /// `"hold"` (default: the points that flip-flopped stay closed while their force is not
    /// tensile beyond the tolerance, then the loop goes on) or `"off"` (stop at once with
    /// `active_set_cycling` and the points named).
    #[serde(default)]
    pub cycling_remedy: CyclingRemedy,
    /// How an active-set iteration of the penalty family gets the solver of its matrix when
    /// few rows changed: `"auto"` (default: a low-rank update of the last factorization on
    /// systems of at least 20,000 equations, else a new factorization), `"refactor"` (always
    /// factor anew) or `"low_rank"` (the update on every size, to compare);
    /// see `src/solver/low_rank.rs`.
    #[serde(default)]
    pub factor_update: FactorUpdate,
    /// The solver of the linear systems: `"direct"` (default: sparse Cholesky) or `"cg_amg"`
    /// (conjugate gradients preconditioned by smoothed-aggregation algebraic multigrid,
    /// `src/solver/amg.rs`), for symmetric positive definite systems only: elasticity and the
    /// penalty and augmented Lagrangian contact rows of the active-set scheme. Every other
    /// system is refused with the reason.
    #[serde(default)]
    pub linear_solver: LinearSolver,
    /// `"cg_amg"`: the relative residual `||b - A x|| / ||b||` at which CG stops; default
    /// 1e-10. A solve that does not reach it within `linear_max_iterations` is an error.
    #[serde(default = "linear_tolerance")]
    pub linear_tolerance: f64,
    /// `"cg_amg"`: the most CG iterations of one linear solve; default 500.
    #[serde(default = "five_hundred")]
    pub linear_max_iterations: usize,
}

/// The solver of the linear systems of a static small-strain solve.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum LinearSolver {
    /// Sparse Cholesky (faer), exact to round-off.
    #[default]
    Direct,
    /// Conjugate gradients with a smoothed-aggregation AMG V-cycle, to a relative residual.
    CgAmg,
}

fn linear_tolerance() -> f64 {
    1e-10
}
fn five_hundred() -> usize {
    500
}

/// Whether the active-set iterations reuse the last factorization with a low-rank
/// (Woodbury) update instead of factoring anew ([`crate::solver::low_rank`]).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum FactorUpdate {
    /// The update on large systems (at least 20,000 equations), a new factorization else.
    #[default]
    Auto,
    /// A new factorization whenever the matrix changes.
    Refactor,
    /// The update whenever few enough rows changed, whatever the size.
    LowRank,
}

/// The remedy of the active-set scheme for a cycling active set
/// ([`crate::solver::active_set`]).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum CyclingRemedy {
    /// Hold the flip-flopping points closed while their force is not tensile beyond the
    /// tolerance.
    #[default]
    Hold,
    /// No remedy: stop with `active_set_cycling` at the first repeated set.
    Off,
}

/// The nonlinear solution scheme of a load step.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Scheme {
    /// Linear solves of the active-set loop inside geometry updates
    /// ([`crate::solver::active_set`]).
    #[default]
    ActiveSet,
    /// Semi-smooth Newton on the residual and tangent, rows searched again at every iterate in
    /// the current geometry ([`crate::solver::newton`], [`crate::solver::contact_newton`]).
    Newton,
}

fn yes() -> bool {
    true
}

/// The most load steps, iterations or geometry updates a case may ask for.
pub const MAX_SOLVER_COUNT: usize = 100_000;

fn one_step() -> usize {
    1
}
fn two_hundred() -> usize {
    200
}
fn fifty() -> usize {
    50
}
fn geometry_tolerance() -> f64 {
    1e-12
}

impl Default for SolverSpec {
    fn default() -> Self {
        SolverSpec {
            load_steps: one_step(),
            max_iterations: two_hundred(),
            max_geometry_updates: fifty(),
            geometry_tolerance: geometry_tolerance(),
            geometric_stiffness: true,
            scheme: Scheme::ActiveSet,
            friction_tangent: FrictionTangent::Consistent,
            cycling_remedy: CyclingRemedy::Hold,
            factor_update: FactorUpdate::Auto,
            linear_solver: LinearSolver::Direct,
            linear_tolerance: linear_tolerance(),
            linear_max_iterations: five_hundred(),
        }
    }
}

/// Bounds on the size of a case, checked before meshing (a case may raise them).
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Limits {
    /// The most nodes all bodies together may have (default 2,000,000, 4 million dofs: four
    /// times the 1M-dof case in `cases/large`).
    #[serde(default = "default_max_nodes")]
    pub nodes: usize,
    /// The most time steps times dofs a dynamic run may ask for (default 100,000,000, about a
    /// minute of stepping on one core).
    #[serde(default = "default_max_step_dofs")]
    pub step_dofs: u64,
    /// The most memory one sparse factorization's values may take, in gigabytes (8 bytes per
    /// entry of the factor, known from its symbolic analysis before anything is allocated);
    /// default 8. An LU is estimated as twice the Cholesky factor of its pattern.
    #[serde(default = "default_factor_gigabytes")]
    pub factor_gigabytes: f64,
    /// The most multiply-adds one sparse factorization may take (`sum_j c_j^2` over the
    /// factor's column counts, known from the symbolic analysis); default 1e12, about 8 times
    /// the 1.3e11 of the Cholesky factor of the million-dof square in `cases/large`.
    #[serde(default = "default_factor_operations")]
    pub factor_operations: f64,
    /// The most iterations times unknowns one iteration loop may take: the active-set loop of
    /// one load step and geometry update, or one Newton solve (a load step, a time step);
    /// default 5,000,000: 11 iterations of the 440,000-dof mesh that takes about half a second
    /// an iteration on this 2-core machine, 200 of a 25,000-dof one. A loop that reaches it
    /// stops with `work_limit`, naming this limit.
    #[serde(default = "default_iteration_dofs")]
    pub iteration_dofs: u64,
}

pub const DEFAULT_MAX_NODES: usize = 2_000_000;
pub const DEFAULT_MAX_STEP_DOFS: u64 = 100_000_000;
pub const DEFAULT_ITERATION_DOFS: u64 = 5_000_000;

fn default_iteration_dofs() -> u64 {
    DEFAULT_ITERATION_DOFS
}

fn default_max_step_dofs() -> u64 {
    DEFAULT_MAX_STEP_DOFS
}

fn default_max_nodes() -> usize {
    DEFAULT_MAX_NODES
}

pub const DEFAULT_FACTOR_GIGABYTES: f64 = 8.0;
pub const DEFAULT_FACTOR_OPERATIONS: f64 = 1e12;

fn default_factor_gigabytes() -> f64 {
    DEFAULT_FACTOR_GIGABYTES
}

fn default_factor_operations() -> f64 {
    DEFAULT_FACTOR_OPERATIONS
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            nodes: DEFAULT_MAX_NODES,
            step_dofs: DEFAULT_MAX_STEP_DOFS,
            factor_gigabytes: DEFAULT_FACTOR_GIGABYTES,
            factor_operations: DEFAULT_FACTOR_OPERATIONS,
            iteration_dofs: DEFAULT_ITERATION_DOFS,
        }
    }
}

/// A JSON object as a map whose keys must differ: a repeated key is an error naming it, where
/// serde's map would keep the last one silently.
/// The JSON Schema of the case format (draft 2020-12), pretty-printed: what
/// `contact-patch schema` prints and `cases/case.schema.json` holds.
pub fn case_schema() -> String {
    let schema = schemars::schema_for!(Case);
    let mut text = serde_json::to_string_pretty(&schema).expect("a schema serializes");
    text.push('\n');
    text
}

fn unique_keys<'de, D, V>(d: D) -> Result<BTreeMap<String, V>, D::Error>
where
    D: serde::Deserializer<'de>,
    V: Deserialize<'de>,
{
    struct UniqueKeys<V>(std::marker::PhantomData<V>);
    impl<'de, V: Deserialize<'de>> serde::de::Visitor<'de> for UniqueKeys<V> {
        type Value = BTreeMap<String, V>;
        fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
            f.write_str("an object of named entries")
        }
        fn visit_map<A: serde::de::MapAccess<'de>>(
            self,
            mut map: A,
        ) -> Result<Self::Value, A::Error> {
            let mut out = BTreeMap::new();
            while let Some(key) = map.next_key::<String>()? {
                if out.contains_key(&key) {
                    return Err(serde::de::Error::custom(format!(
                        "the name '{key}' is defined twice"
                    )));
                }
                let value = map.next_value()?;
                out.insert(key, value);
            }
            Ok(out)
        }
    }
    d.deserialize_map(UniqueKeys(std::marker::PhantomData))
}

/// A facet set of a body.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SurfaceSpec {
    pub body: String,
    pub set: String,
}

/// A rigid, fixed analytic master surface.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum RigidSurface {
    /// The line through `point`; `normal` points to the side where the slave body lives.
    Line { point: [f64; 2], normal: [f64; 2] },
    /// A circle; the slave body lives outside it.
    Circle { centre: [f64; 2], radius: f64 },
    /// (3D) The plane through `point`; `normal` points to the side where the slave body lives.
    Plane { point: [f64; 3], normal: [f64; 3] },
    /// (3D) A sphere; the slave body lives outside it.
    Sphere { centre: [f64; 3], radius: f64 },
}

impl RigidSurface {
    /// The dimension of the space the surface lives in: 2 for a line or circle, 3 for a plane
    /// or sphere.
    pub fn dimension(&self) -> usize {
        match self {
            RigidSurface::Line { .. } | RigidSurface::Circle { .. } => 2,
            RigidSurface::Plane { .. } | RigidSurface::Sphere { .. } => 3,
        }
    }

    /// Whether the surface is flat (a line or a plane): its tangents do not turn along it, so
    /// the slip of a slave node over it is `t . u_s` in any configuration.
    pub fn is_flat(&self) -> bool {
        matches!(self, RigidSurface::Line { .. } | RigidSurface::Plane { .. })
    }

    /// The largest coordinate or radius of a rigid surface: gaps square differences of
    /// positions, and `1e150` keeps a sum of three squared differences of such values finite.
    pub const LARGEST: f64 = 1e150;

    /// Why the surface cannot be used, if it cannot: a zero normal, a radius that is not
    /// positive, a value that is not finite, or one beyond [`Self::LARGEST`] (its gap would
    /// overflow); `None` for a usable surface.
    pub fn problem(&self) -> Option<String> {
        let (values, normal, radius): (&[f64], Option<&[f64]>, Option<f64>) = match self {
            RigidSurface::Line { point, normal } => (point, Some(normal), None),
            RigidSurface::Plane { point, normal } => (point, Some(normal), None),
            RigidSurface::Circle { centre, radius } => (centre, None, Some(*radius)),
            RigidSurface::Sphere { centre, radius } => (centre, None, Some(*radius)),
        };
        let all = values
            .iter()
            .chain(normal.into_iter().flatten())
            .chain(&radius);
        if let Some(v) = all.clone().find(|v| !v.is_finite()) {
            return Some(format!("a value is not finite ({v})"));
        }
        if let Some(n) = normal.filter(|n| n.iter().all(|&c| c == 0.0)) {
            return Some(format!("the normal {n:?} is zero"));
        }
        if let Some(r) = radius.filter(|&r| r <= 0.0) {
            return Some(format!("the radius {r} is not positive"));
        }
        if let Some(v) = all.map(|v| v.abs()).find(|&v| v > Self::LARGEST) {
            return Some(format!(
                "{v} is too large to compute a gap with (coordinates and radii at most {:e}: \
                 the gap squares differences of positions, which would overflow)",
                Self::LARGEST
            ));
        }
        None
    }
}

/// The master side of a pair: a facet set of a body, or a rigid surface.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MasterSpec {
    #[serde(default)]
    pub body: Option<String>,
    #[serde(default)]
    pub set: Option<String>,
    #[serde(default)]
    pub rigid: Option<RigidSurface>,
}

/// One contact pair: slave facets against master facets (or a rigid surface), with a
/// discretization and an enforcement method.
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ContactSpec {
    pub name: String,
    pub slave: SurfaceSpec,
    pub master: MasterSpec,
    pub discretization: DiscretizationSpec,
    pub enforcement: EnforcementSpec,
    /// `frictionless` contact (default), a `tied` (glued) interface, or
    /// `{"coulomb": {"mu": .., "kappa_t": ..}}` friction.
    #[serde(default)]
    pub interaction: Interaction,
    /// How far from the master surface a slave node is still a contact candidate (default:
    /// the largest master facet). Node-to-surface and mortar only.
    #[serde(default)]
    pub search_distance: Option<f64>,
    /// Two-pass node-to-surface with a penalty-type method (penalty, perturbed Lagrangian,
    /// augmented Lagrangian, perturbed tangent): the penalty each pass applies. `full`
    /// (default): `kappa` on the rows of each pass, so where both passes act the interface is
    /// about twice as stiff as one pass's (the penalty error about halves); `halved`:
    /// `kappa / 2` on each pass, the convention of codes that split the penalty between the
    /// passes (the penalty error then matches one pass at `kappa`). Lagrange multipliers and
    /// elimination have no penalty and ignore it.
    #[serde(default, skip_serializing_if = "TwoPassPenalty::is_full")]
    pub two_pass_penalty: TwoPassPenalty,
}

/// The penalty of each pass of a two-pass pair.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum TwoPassPenalty {
    /// `kappa` on each pass.
    #[default]
    Full,
    /// `kappa / 2` on each pass.
    Halved,
}

impl TwoPassPenalty {
    pub fn is_full(&self) -> bool {
        *self == TwoPassPenalty::Full
    }
}

/// What a pair enforces.
#[derive(Copy, Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum Interaction {
    /// Unilateral, frictionless contact: `g >= 0`, `lambda >= 0`, `g lambda = 0`.
    #[default]
    Frictionless,
    /// Both displacement components continuous across the interface (bilateral).
    Tied,
    /// Unilateral contact with Coulomb friction, `|lambda_t| <= mu lambda_n`, regularized by a
    /// tangential penalty `kappa_t` (force per unit area per unit elastic slip; default: the
    /// pair's normal `kappa`). `solver.scheme: "newton"` with the penalty or the perturbed
    /// Lagrangian only (see
    /// [`crate::contact::friction`]).
    Coulomb {
        mu: f64,
        #[serde(default, skip_serializing_if = "Option::is_none")]
        kappa_t: Option<f64>,
    },
}

impl Interaction {
    /// The friction coefficient of a Coulomb pair.
    pub fn friction(&self) -> Option<f64> {
        match *self {
            Interaction::Coulomb { mu, .. } => Some(mu),
            _ => None,
        }
    }
}

impl FrictionTangent {
    /// The name in a case file: `consistent`, `symmetrized`, `laursen_simo`.
    pub fn name(self) -> &'static str {
        match self {
            FrictionTangent::Consistent => "consistent",
            FrictionTangent::Symmetrized => "symmetrized",
            FrictionTangent::LaursenSimo => "laursen_simo",
        }
    }
}

/// The tangent of the frictional rows in a slip state.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum FrictionTangent {
    /// The exact derivative of the return map: unsymmetric in slip (solved by LU).
    #[default]
    Consistent,
    /// The consistent tangent without the slip coupling `s mu w b_t b_n^T` (symmetric, Cholesky;
    /// Newton then converges linearly in slip).
    Symmetrized,
    /// The symmetric augmented form of Laursen & Simo (1993), augmented-Lagrangian pairs only:
    /// the slip force bounded by `mu` times the normal Uzawa multiplier, held fixed during
    /// Newton, so the exact tangent of each Newton solve is symmetric; the Uzawa updates bring
    /// the bound to `mu lambda_n`.
    LaursenSimo,
}

/// The multiplier space of a mortar discretization.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum MultiplierSpace {
    /// The slave shape functions.
    #[default]
    Standard,
    /// Biorthogonal (dual) functions: `D` is diagonal.
    Dual,
}

/// Which normal defines the gap of a node-to-surface constraint.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum NormalChoice {
    /// The outward normal of the master facet at the closest point.
    #[default]
    Master,
    /// The averaged normal of the slave surface at the slave node (smoother sliding).
    Slave,
}

/// How a node-to-surface row with slave normals is linearized under finite kinematics between
/// deformable bodies (`contact::discretization::nodal_normal`).
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum SlaveNormalVariation {
    /// The force along the gap's full gradient (the slave node, its surface neighbours and the
    /// master facet's nodes) and the gap's second derivative in the tangent.
    #[default]
    Consistent,
    /// The seed's smooth-sliding form: the `delta xi` term ignored, the force on the slave node
    /// and the master facet's nodes only; its tangent is unsymmetric (solved by LU).
    SmoothSliding,
}

impl SlaveNormalVariation {
    /// The name the case format gives it.
    pub fn name(self) -> &'static str {
        match self {
            SlaveNormalVariation::Consistent => "consistent",
            SlaveNormalVariation::SmoothSliding => "smooth_sliding",
        }
    }
}

fn one_pass() -> u8 {
    1
}

/// The discretization axis.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum DiscretizationSpec {
    /// Each slave node against the master node at the same place.
    NodeToNode,
    /// Each slave node against the master surface; two passes add the master nodes
    /// against the slave surface.
    NodeToSurface {
        #[serde(default = "one_pass")]
        passes: u8,
        #[serde(default)]
        normal: NormalChoice,
        /// Finite kinematics with slave normals only: `"consistent"` (default) or
        /// `"smooth_sliding"`.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        slave_normal_variation: Option<SlaveNormalVariation>,
    },
    /// Segment-based mortar: weighted gaps `D x_s - M x_m` per slave node.
    Mortar {
        #[serde(default)]
        multiplier: MultiplierSpace,
    },
}

/// When the augmented Lagrangian updates its multipliers.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum MultiplierUpdate {
    /// After every Newton (active-set) iteration.
    #[default]
    PerIteration,
    /// In an outer loop, after the inner Newton loop has converged.
    OuterLoop,
}

/// The enforcement axis. `kappa` is a penalty per unit contact area (pressure per gap).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq, JsonSchema)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum EnforcementSpec {
    Lagrange,
    PerturbedLagrange {
        kappa: f64,
    },
    Penalty {
        kappa: f64,
    },
    PerturbedTangent {
        kappa: f64,
    },
    AugmentedLagrange {
        kappa: f64,
        #[serde(default)]
        update: MultiplierUpdate,
    },
    Elimination,
}

/// One discretization variant of a sweep: a discretization, and which body is the slave of
/// a one-pass run (default: the pair's own slave).
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SweepDiscretization {
    pub discretization: DiscretizationSpec,
    #[serde(default)]
    pub slave: Option<String>,
}

/// The product of discretizations and enforcements that `contact-patch table` runs on the
/// case's first contact pair.
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SweepSpec {
    /// Which table the cells go to: `patch` (default, `reports/patch-table.*`), `tied`
    /// (`reports/tied-table.*`) or `friction` (`reports/friction-table.*`).
    #[serde(default)]
    pub catalogue: Catalogue,
    /// Label of the mesh in tables (e.g. "A").
    pub mesh: String,
    pub discretizations: Vec<SweepDiscretization>,
    pub enforcements: Vec<EnforcementSpec>,
    /// Penalty-type methods run again with kappa times this factor.
    #[serde(default = "thousand")]
    pub penalty_factor: f64,
    /// Uniform pressure of the patch test, for the pressure error.
    pub pressure: f64,
    /// Tolerance of the patch-test verdict (relative to the pressure).
    pub tol: f64,
    /// The frictional patch test (catalogue `friction`): the status every contact point must
    /// end the last load step in, `stick` (tangential traction below the cone) or `slip` (the
    /// punch dragged past it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub expect: Option<ExpectedFriction>,
    /// Friction sweeps: further friction tangents to run the augmented-Lagrangian enforcements
    /// with, each a column of its own (`augmented_lagrange+laursen_simo`); the other
    /// enforcements run with the case's own `solver.friction_tangent` only.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub friction_tangents: Vec<FrictionTangent>,
}

/// The frictional status a friction sweep expects at every contact point of its last step.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum ExpectedFriction {
    /// `|lambda_t| < mu lambda_n` everywhere: the bodies move together (uniform stress).
    Stick,
    /// `|lambda_t| = mu lambda_n` everywhere, against the sliding.
    Slip,
}

/// The tables a sweep's cells go to; the name is the stem of the table's files.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize, JsonSchema,
)]
#[serde(rename_all = "snake_case")]
pub enum Catalogue {
    /// The contact patch test (`patch-table.*`).
    #[default]
    Patch,
    /// The tied patch tests (`tied-table.*`).
    Tied,
    /// The frictional patch tests (`friction-table.*`).
    Friction,
}

impl Catalogue {
    pub fn name(self) -> &'static str {
        match self {
            Catalogue::Patch => "patch",
            Catalogue::Tied => "tied",
            Catalogue::Friction => "friction",
        }
    }
}

fn thousand() -> f64 {
    1000.0
}

#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Analysis {
    #[serde(default)]
    pub plane: Plane,
    #[serde(default = "one")]
    pub thickness: f64,
}

impl Default for Analysis {
    fn default() -> Self {
        Analysis {
            plane: Plane::Strain,
            thickness: 1.0,
        }
    }
}

fn one() -> f64 {
    1.0
}

#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Plane {
    #[default]
    Strain,
    Stress,
}

/// Isotropic linear elasticity.
#[derive(Copy, Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    #[serde(rename = "E")]
    pub youngs_modulus: f64,
    pub nu: f64,
    /// Mass per unit volume; required by `physics.dynamics` for every material a body uses,
    /// read by nothing else.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub density: Option<f64>,
    /// The constitutive law: linear elasticity (small strain), or a hyperelastic energy for
    /// `physics.kinematics: "finite"` (Lamé constants from `E` and `nu`).
    #[serde(default, skip_serializing_if = "MaterialModel::is_linear")]
    pub model: MaterialModel,
}

/// The constitutive law of a material.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum MaterialModel {
    /// `sigma = D eps` (small strain).
    #[default]
    LinearElastic,
    /// Compressible neo-Hookean, `W = mu/2 (I_1 - 3 - 2 ln J) + lambda/2 (ln J)^2` (finite
    /// kinematics only).
    NeoHookean,
    /// St. Venant-Kirchhoff, `W = lambda/2 (tr E)^2 + mu E:E` (finite kinematics only).
    SaintVenantKirchhoff,
}

impl MaterialModel {
    pub fn is_linear(&self) -> bool {
        *self == MaterialModel::LinearElastic
    }
}

#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BodySpec {
    pub name: String,
    pub material: String,
    pub mesh: MeshSpec,
    #[serde(default, deserialize_with = "unique_keys")]
    pub node_sets: BTreeMap<String, NodeSetSpec>,
    #[serde(default, deserialize_with = "unique_keys")]
    pub facet_sets: BTreeMap<String, FacetSetSpec>,
}

#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum MeshSpec {
    /// Structured block from element breaks along x and y.
    Block(BlockSpec),
    /// Nodes and cells given one by one (element node order as in `fe`).
    Explicit(ExplicitMeshSpec),
    /// A Gmsh `.msh` file (MSH 4.1 ASCII or binary, MSH 2.2 ASCII): the 2D elements of one
    /// physical surface; the file's other physical groups become node and facet sets.
    Gmsh(GmshMeshSpec),
    /// A 3D structured block from element breaks along x, y and z (Hex8, Hex27, Tet4,
    /// Tet10; tetrahedra split each grid cell into six). A case with a 3D body is a 3D case:
    /// one body, supports with x, y, z, pressure loads, `uniform_stress_3d` checks; contact,
    /// dynamics, finite strain and sweeps are not built in 3D yet and are refused.
    Block3d(Block3dSpec),
}

#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Block3dSpec {
    pub element: crate::fe3d::SolidKind,
    pub x: Breaks,
    pub y: Breaks,
    pub z: Breaks,
    /// Nodes moved after generation (as for the 2D block): a grid vertex with the
    /// higher-order nodes following it, or a single higher-order node.
    #[serde(default)]
    pub moves: Vec<Move3d>,
}

/// A move of one node of a 3D block.
#[derive(Copy, Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Move3d {
    pub from: [f64; 3],
    pub to: [f64; 3],
}

#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct GmshMeshSpec {
    /// The `.msh` file, relative to the case file's folder.
    pub file: String,
    /// The physical surface (2D physical group) whose elements are the body's cells; may be
    /// left out when the file's 2D elements are all the body's.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub physical: Option<String>,
}

#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BlockSpec {
    pub element: ElementKind,
    pub x: Breaks,
    pub y: Breaks,
    /// Nodes moved after generation, to distort the grid: a move from a grid vertex moves the
    /// vertex and the mid-side and centre nodes follow it (straight sides); a move from any
    /// other node of a quadratic block (a mid-side or centre node, where the vertex moves left
    /// it) moves that node alone, e.g. to curve a side.
    #[serde(default)]
    pub moves: Vec<Move>,
}

/// Element boundaries along one axis: an explicit list, or uniform divisions.
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[serde(untagged)]
pub enum Breaks {
    List(Vec<f64>),
    Uniform(UniformBreaks),
}

/// A list becomes [`Breaks::List`], an object [`Breaks::Uniform`]; anything else is refused
/// with both shapes named (not serde's "did not match any variant of untagged enum").
impl<'de> Deserialize<'de> for Breaks {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct BreaksVisitor;
        impl<'de> serde::de::Visitor<'de> for BreaksVisitor {
            type Value = Breaks;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str(
                    "the breaks of an axis: a list of increasing coordinates [x0, x1, ...] or \
                     {\"from\": x0, \"to\": x1, \"divisions\": n}",
                )
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, seq: A) -> Result<Breaks, A::Error> {
                Vec::<f64>::deserialize(serde::de::value::SeqAccessDeserializer::new(seq))
                    .map(Breaks::List)
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(self, map: A) -> Result<Breaks, A::Error> {
                UniformBreaks::deserialize(serde::de::value::MapAccessDeserializer::new(map))
                    .map(Breaks::Uniform)
            }
        }
        d.deserialize_any(BreaksVisitor)
    }
}

#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct UniformBreaks {
    pub from: f64,
    pub to: f64,
    #[serde(deserialize_with = "positive_count")]
    pub divisions: usize,
}

/// A count of at least 1, with a message that names what is allowed.
fn positive_count<'de, D: serde::Deserializer<'de>>(d: D) -> Result<usize, D::Error> {
    let value = serde_json::Value::deserialize(d)?;
    match value.as_u64() {
        Some(n) if n >= 1 => usize::try_from(n).map_err(|_| {
            serde::de::Error::custom(format!("`divisions` {n} is too large (see `limits`)"))
        }),
        _ => Err(serde::de::Error::custom(format!(
            "`divisions` must be a positive integer, got {value}"
        ))),
    }
}

impl Breaks {
    /// The number of intervals, without building them.
    pub fn intervals(&self) -> usize {
        match self {
            Breaks::List(v) => v.len().saturating_sub(1),
            Breaks::Uniform(u) => u.divisions,
        }
    }

    pub fn values(&self) -> Vec<f64> {
        match self {
            Breaks::List(v) => v.clone(),
            Breaks::Uniform(u) => (0..=u.divisions)
                .map(|i| u.from + (u.to - u.from) * i as f64 / u.divisions.max(1) as f64)
                .collect(),
        }
    }
}

#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Move {
    pub from: [f64; 2],
    pub to: [f64; 2],
}

/// A mesh given node by node and cell by cell: 2D cells of `Q4`, `Q9`, `T3` or `T6` with
/// nodes `[x, y]`, or 3D cells of `Hex8`, `Hex27`, `Tet4` or `Tet10` with nodes `[x, y, z]`
/// (local node orders as VTK's).
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ExplicitMeshSpec {
    pub element: CellName,
    pub nodes: Vec<Vector>,
    pub cells: Vec<Vec<usize>>,
}

/// The element of an explicit mesh, 2D or 3D.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
pub enum CellName {
    Q4,
    Q9,
    T3,
    T6,
    Hex8,
    Hex27,
    Tet4,
    Tet10,
}

impl CellName {
    /// The 2D element, if it is one.
    pub fn plane(self) -> Option<ElementKind> {
        match self {
            CellName::Q4 => Some(ElementKind::Q4),
            CellName::Q9 => Some(ElementKind::Q9),
            CellName::T3 => Some(ElementKind::T3),
            CellName::T6 => Some(ElementKind::T6),
            _ => None,
        }
    }

    /// The 3D element, if it is one.
    pub fn solid(self) -> Option<crate::fe3d::SolidKind> {
        use crate::fe3d::SolidKind;
        match self {
            CellName::Hex8 => Some(SolidKind::Hex8),
            CellName::Hex27 => Some(SolidKind::Hex27),
            CellName::Tet4 => Some(SolidKind::Tet4),
            CellName::Tet10 => Some(SolidKind::Tet10),
            _ => None,
        }
    }
}

#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum NodeSetSpec {
    /// Nodes in a closed axis-aligned box.
    Box(BoxSpec),
    /// The node at a point `[x, y]` (2D) or `[x, y, z]` (3D), within a small tolerance.
    Point(Vector),
    /// Node ids.
    Nodes(Vec<usize>),
}

#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum FacetSetSpec {
    /// Boundary facets whose nodes all lie in a closed axis-aligned box (within 1e-9 x the
    /// body size; a node taken in only by that tolerance is named in a warning).
    Box(BoxSpec),
    /// `[cell, local edge]` pairs. Local edges run counter-clockwise from the cell's first
    /// corner: Q4 and Q9 edge 0 = corners 0-1 (Q9 mid-node 4), 1 = 1-2 (5), 2 = 2-3 (6),
    /// 3 = 3-0 (7); T3 and T6 edge 0 = corners 0-1 (T6 mid-node 3), 1 = 1-2 (4), 2 = 2-0 (5).
    /// Corners are numbered counter-clockwise; a block's cell starts at its lower-left corner.
    Facets(Vec<[usize; 2]>),
}

#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct BoxSpec {
    /// The lowest corner, `[x, y]` (2D) or `[x, y, z]` (3D).
    pub min: Vector,
    /// The highest corner.
    pub max: Vector,
}

/// The keyword `"exact"`: take the value from the case's exact solution.
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum FromExact {
    Exact,
}

/// A prescribed displacement component: a number, or `"exact"`.
#[derive(Copy, Clone, Debug, Serialize, JsonSchema)]
#[serde(untagged)]
pub enum Prescribed {
    Value(f64),
    Exact(FromExact),
}

/// A number becomes [`Prescribed::Value`], the string `"exact"` [`Prescribed::Exact`]; anything
/// else is refused naming the field and both forms (not serde's "did not match any variant of
/// untagged enum").
impl<'de> Deserialize<'de> for Prescribed {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct PrescribedVisitor;
        impl serde::de::Visitor<'_> for PrescribedVisitor {
            type Value = Prescribed;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str(
                    "a support's displacement component (`x`, `y` or `z`): a number, or \
                     \"exact\" for the case's exact solution",
                )
            }
            fn visit_f64<E: serde::de::Error>(self, v: f64) -> Result<Prescribed, E> {
                Ok(Prescribed::Value(v))
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Prescribed, E> {
                Ok(Prescribed::Value(v as f64))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Prescribed, E> {
                Ok(Prescribed::Value(v as f64))
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<Prescribed, E> {
                match v {
                    "exact" => Ok(Prescribed::Exact(FromExact::Exact)),
                    _ => Err(E::invalid_value(serde::de::Unexpected::Str(v), &self)),
                }
            }
        }
        d.deserialize_any(PrescribedVisitor)
    }
}

/// Prescribed displacement components on a node set (`x`, `y` or both).
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Support {
    pub body: String,
    pub set: String,
    #[serde(default)]
    pub x: Option<Prescribed>,
    #[serde(default)]
    pub y: Option<Prescribed>,
    /// The z component, for a 3D body only.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub z: Option<Prescribed>,
    /// The factor of the prescribed values at each load step (one per step of
    /// `solver.load_steps`; default: proportional, `k / n` at step `k`): a load path, e.g.
    /// `[0, 1]` for "not in the first step, fully in the second".
    #[serde(default)]
    pub path: Option<Vec<f64>>,
}

/// A point or a vector of a body: `[x, y]` for a 2D body, `[x, y, z]` for a 3D one (the model
/// checks the count against the body's dimension).
#[derive(Clone, Debug, PartialEq, Serialize, JsonSchema)]
#[serde(transparent)]
pub struct Vector(#[schemars(length(min = 2, max = 3))] pub Vec<f64>);

/// Two or three numbers; any other count is refused naming both forms.
impl<'de> Deserialize<'de> for Vector {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Components;
        impl<'de> serde::de::Visitor<'de> for Components {
            type Value = Vector;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a vector [x, y] (2D body) or [x, y, z] (3D body)")
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, seq: A) -> Result<Vector, A::Error> {
                components(seq, &self).map(Vector)
            }
        }
        d.deserialize_seq(Components)
    }
}

/// Two or three numbers from `seq`, or an error naming what `expected` describes and how many
/// numbers were given.
fn components<'de, A: serde::de::SeqAccess<'de>>(
    mut seq: A,
    expected: &dyn serde::de::Expected,
) -> Result<Vec<f64>, A::Error> {
    let mut out = Vec::with_capacity(3);
    while let Some(v) = seq.next_element::<f64>()? {
        out.push(v);
        if out.len() > 3 {
            break;
        }
    }
    let mut given = out.len();
    if given > 3 {
        while seq.next_element::<serde::de::IgnoredAny>()?.is_some() {
            given += 1;
        }
    }
    if !(2..=3).contains(&given) {
        return Err(serde::de::Error::invalid_length(given, expected));
    }
    Ok(out)
}

/// A traction vector (`[t_x, t_y]` in 2D, `[t_x, t_y, t_z]` in 3D), or `"exact"`
/// (sigma_exact . n).
#[derive(Clone, Debug, Serialize, JsonSchema)]
#[serde(untagged)]
pub enum TractionSpec {
    Vector(Vector),
    Exact(FromExact),
}

/// A list of two or three numbers becomes [`TractionSpec::Vector`], the string `"exact"`
/// [`TractionSpec::Exact`]; anything else is refused naming the field and both forms.
impl<'de> Deserialize<'de> for TractionSpec {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct TractionVisitor;
        impl<'de> serde::de::Visitor<'de> for TractionVisitor {
            type Value = TractionSpec;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str(
                    "a load's `traction`: a vector [t_x, t_y] (2D) or [t_x, t_y, t_z] (3D), force \
                     per area, or \"exact\" for sigma_exact . n of the case's exact solution",
                )
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(
                self,
                seq: A,
            ) -> Result<TractionSpec, A::Error> {
                components(seq, &self).map(|v| TractionSpec::Vector(Vector(v)))
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<TractionSpec, E> {
                match v {
                    "exact" => Ok(TractionSpec::Exact(FromExact::Exact)),
                    _ => Err(E::invalid_value(serde::de::Unexpected::Str(v), &self)),
                }
            }
        }
        d.deserialize_any(TractionVisitor)
    }
}

/// One load: `pressure` or `traction` on a facet set, a concentrated `force` at every node of a
/// node set, or a `body_force` on a whole body.
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Load {
    pub body: String,
    #[serde(default)]
    pub set: Option<String>,
    /// Pressure (force per area) pushing against the outward normal.
    #[serde(default)]
    pub pressure: Option<f64>,
    /// Traction (force per area) in global components.
    #[serde(default)]
    pub traction: Option<TractionSpec>,
    /// Force per volume, `[b_x, b_y]` (2D) or `[b_x, b_y, b_z]` (3D).
    #[serde(default)]
    pub body_force: Option<Vector>,
    /// A concentrated force `[f_x, f_y]` (2D: total, for the case's thickness) or
    /// `[f_x, f_y, f_z]` (3D) at every node of the node set `set`.
    #[serde(default)]
    pub force: Option<Vector>,
    /// The factor of the load at each load step (one per step of `solver.load_steps`; default:
    /// proportional, `k / n` at step `k`): a load path, e.g. a normal load `[1, 1]` and a
    /// tangential one `[0, 1]` (friction is path dependent).
    #[serde(default)]
    pub path: Option<Vec<f64>>,
}

/// Analytic reference solutions.
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum ExactSpec {
    /// Constant stress `[xx, yy, xy]`, displacement `u = eps x` (no rigid motion).
    UniformStress { stress: [f64; 3] },
    /// Timoshenko & Goodier's cantilever: x in [0, length], y in [-depth/2, depth/2], clamped
    /// at x = 0 in the exact sense, parabolic shear `load` (total, per thickness) at x = length.
    TimoshenkoCantilever { load: f64, length: f64, depth: f64 },
}

/// What the scene simulates beyond static, small-strain, frictionless elasticity. Every
/// extra effect is opt-in.
#[derive(Clone, Debug, Default, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Physics {
    #[serde(default)]
    pub kinematics: Kinematics,
    /// Where contact gaps, normals and projections are evaluated.
    #[serde(default)]
    pub contact_geometry: ContactGeometry,
    /// Time stepping (Newmark) instead of a static solve; absent: static, no mass matrix.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dynamics: Option<DynamicsSpec>,
}

/// `physics.dynamics`: Newmark's method from `t = 0` to `end_time` in steps of `dt`, loads and
/// supports constant in time, the bodies at rest and undeformed at `t = 0` except for
/// `initial_velocity`.
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct DynamicsSpec {
    /// The member of Newmark's family.
    #[serde(default)]
    pub integrator: Integrator,
    /// Time step.
    pub dt: f64,
    /// Last time; the number of steps is `end_time / dt` rounded up.
    pub end_time: f64,
    #[serde(default)]
    pub mass: MassKind,
    /// What happens to the velocities, accelerations and contact forces of contacting nodes.
    #[serde(default)]
    pub impact: ImpactTreatment,
    /// Initial velocity of every node of a body, or of a node set of it (later entries win).
    #[serde(default)]
    pub initial_velocity: Vec<InitialVelocity>,
    /// Write a `.vtu` frame every this many steps (and the last); default: about 50 frames.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frame_every: Option<usize>,
}

/// A member of Newmark's family `d+ = d + dt v + dt^2 ((1/2 - beta) a + beta a+)`,
/// `v+ = v + dt ((1 - gamma) a + gamma a+)`.
#[derive(Copy, Clone, Debug, Default, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Integrator {
    /// `beta = 1/4, gamma = 1/2`: the trapezoidal rule, implicit, unconditionally stable,
    /// energy-conserving for linear elasticity.
    #[default]
    AverageAcceleration,
    /// `beta = 0, gamma = 1/2`: explicit with lumped mass, stable for `dt` below `2 / omega_max`.
    CentralDifference,
    /// Any `0 <= beta <= 1/2`, `gamma >= 1/2`.
    Newmark { beta: f64, gamma: f64 },
}

impl Integrator {
    /// `(beta, gamma)`.
    pub fn parameters(self) -> (f64, f64) {
        match self {
            Integrator::AverageAcceleration => (0.25, 0.5),
            Integrator::CentralDifference => (0.0, 0.5),
            Integrator::Newmark { beta, gamma } => (beta, gamma),
        }
    }
}

/// The mass matrix.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum MassKind {
    /// Diagonal, by the HRZ scaling of the consistent diagonal (positive for every element).
    #[default]
    Lumped,
    /// `int rho N^T N dV`.
    Consistent,
}

/// The treatment of impact and release.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum ImpactTreatment {
    /// Newmark's updates as they are.
    #[default]
    Plain,
    /// Taylor's post-impact correction (Hughes, Taylor et al. 1976): the accelerations of
    /// contacting nodes averaged with their masses, the contact forces corrected to match, the
    /// velocities set to the 1D impedance (wave) solution.
    PostImpact,
    /// The contact-stabilized Newmark method of Deuflhard, Krause & Ertel (2008): the predictor
    /// `d_n + dt v_n` is projected onto the admissible set in the mass norm before the
    /// trapezoidal step; energy is conserved away from contact and never gained at impact or
    /// release where the constraints hold exactly (Lagrange multipliers; a penalty's
    /// penetration can return energy, and the run warns when it does) (average acceleration
    /// only).
    ContactStabilized,
}

/// An initial velocity.
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct InitialVelocity {
    pub body: String,
    /// A node set of the body; absent: every node.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub set: Option<String>,
    pub velocity: [f64; 2],
}

/// The configuration in which the contact geometry is evaluated.
#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum ContactGeometry {
    /// Once, in the reference configuration (small sliding; the consistent choice for small
    /// strain and the one the patch test assumes).
    #[default]
    Reference,
    /// Re-evaluated in the current configuration `x = X + u` (finite sliding): the search,
    /// projections, normals and weights are redone at the last solution and the contact problem
    /// re-solved until the displacement stops changing.
    Current,
}

#[derive(Copy, Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Kinematics {
    /// Small strain: `eps = sym grad u`, linear elasticity.
    #[default]
    SmallStrain,
    /// Finite deformation, total Lagrangian, plane strain, hyperelastic materials
    /// (`neo_hookean`, `saint_venant_kirchhoff`); loads in load steps, each cut in half when
    /// Newton fails; contact against rigid masters only, in the current geometry.
    Finite,
}

#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Component {
    X,
    Y,
    /// 3D bodies only.
    Z,
}

impl Component {
    pub fn index(self) -> usize {
        match self {
            Component::X => 0,
            Component::Y => 1,
            Component::Z => 2,
        }
    }
}

/// A check judged after the solve; tolerances belong to the case.
#[derive(Clone, Debug, Serialize, Deserialize, JsonSchema)]
#[serde(tag = "check", rename_all = "snake_case", deny_unknown_fields)]
pub enum Check {
    /// Max over quadrature points (all bodies, or `body`) of |sigma - stress| / max|stress|
    /// over the components xx, yy, xy.
    /// With `per_condition = c` the tolerance is `max(tol, c eps kappa)`, `kappa` the condition
    /// estimate of the last factored system (as for `equilibrium`): a stress from a solve that
    /// lost digits to conditioning (nu near 1/2) is judged by what the solve can give.
    UniformStress {
        #[serde(default)]
        body: Option<String>,
        stress: [f64; 3],
        tol: f64,
        #[serde(default)]
        per_condition: Option<f64>,
    },
    /// 3D cases: max over the quadrature points of |sigma - stress| / max|stress| over the
    /// six components `[xx, yy, zz, yz, xz, xy]`.
    #[serde(rename = "uniform_stress_3d")]
    UniformStress3d { stress: [f64; 6], tol: f64 },
    /// Relative L2 error of the displacement against the case's exact solution.
    ExactDisplacement { tol: f64 },
    /// Sum of the reactions on a supported node set, one component.
    Reaction {
        body: String,
        set: String,
        component: Component,
        value: f64,
        tol: f64,
    },
    /// Every active contact force of a pair equals `-n . sigma_exact . n` times its
    /// tributary area (relative to `max |sigma_exact|`); needs the case's exact solution.
    ContactPressure { pair: String, tol: f64 },
    /// Sum of the contact forces and the equilibrium residual, relative to the largest force.
    ForceBalance { tol: f64 },
    /// One component of the total contact force of a pair on its slave body.
    ContactForce {
        pair: String,
        component: Component,
        value: f64,
        tol: f64,
    },
    /// The largest nodal contact pressure `-f_a . n_a / A_a` of a pair (relative error).
    MaxContactPressure { pair: String, value: f64, tol: f64 },
    /// The largest penetration of a pair (all pairs without `pair`), relative to the contact
    /// element size at the node, is at most `share`.
    MaxPenetration {
        #[serde(default)]
        pair: Option<String>,
        share: f64,
    },
    /// Displacement component at the node nearest to `point` (`[x, y]` in 2D, `[x, y, z]` in
    /// 3D).
    Displacement {
        body: String,
        point: Vector,
        component: Component,
        value: f64,
        tol: f64,
    },
    /// The expected outcome of the contact solve: it ends with `reason` (and, when given, its
    /// message or diagnosis contains `contains`). Replaces the implicit "the contact solve
    /// converged" check, so that a case can expect a named stop.
    TerminatesWith {
        reason: TerminationReason,
        #[serde(default)]
        contains: Option<String>,
    },
    /// The relative equilibrium residual of the answer is at most `tol`, or, with
    /// `per_condition`, at most `max(tol, per_condition * eps * kappa)` with `kappa` the
    /// estimated condition number of the last factored system (a tolerance stated relative to
    /// the conditioning).
    Equilibrium {
        tol: f64,
        #[serde(default)]
        per_condition: Option<f64>,
    },
    /// Chattering bound: the most contact points that change status after one iteration, and
    /// in all iterations of one load step, over the whole solve.
    StatusChanges {
        per_iteration: usize,
        per_step: usize,
    },
    /// The run warns, with a warning that contains `contains` (e.g. a diagnosis expected of a
    /// hard case).
    Warns { contains: String },
}

impl Check {
    /// The check's kind as the case file names it in its `check` field (`"uniform_stress"`,
    /// `"contact_pressure"`, ...), which [`ExpectedFailure::check`] names.
    pub fn kind(&self) -> String {
        match serde_json::to_value(self) {
            Ok(serde_json::Value::Object(fields)) => match fields.get("check") {
                Some(serde_json::Value::String(kind)) => kind.clone(),
                _ => unreachable!("a check serializes with its kind in \"check\""),
            },
            _ => unreachable!("a check serializes as an object"),
        }
    }
}

/// A declared check the case expects to fail (`expected_failures`), named by its kind; the case
/// must declare exactly one check of that kind.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct ExpectedFailure {
    /// The kind of the check, as its `check` field names it (e.g. `"uniform_stress"`).
    pub check: String,
    /// Why it fails: the method and the known result, with a source (required, not empty), e.g.
    /// "node-to-surface one-pass with the punch as slave on a non-matching mesh does not pass
    /// the contact patch test (Taylor & Papadopoulos 1991)".
    #[schemars(length(min = 1))]
    pub reason: String,
}

/// How a contact solve ended, as a case names it (see [`Check::TerminatesWith`]).
#[derive(Copy, Clone, Debug, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum TerminationReason {
    Converged,
    IterationLimit,
    ActiveSetCycling,
    Singular,
    WorkLimit,
}
