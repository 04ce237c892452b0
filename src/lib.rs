//! # contact-patch
//!
//! A finite-element contact solver built around a verification harness: the contact patch
//! test of Taylor & Papadopoulos (1991) and the methods surveyed in R. L. Taylor's talk
//! "Finite Element Solution of Contact Problems: From 1974 to 2004".
//!
//! ## Notation
//! 2D, small strain. Displacements `u` live on nodes; the global dof of component `i` of node
//! `a` of body `b` is `offset_b + 2 a + i`. Voigt stress `[sigma_xx, sigma_yy, sigma_xy]`.
//! The discrete equilibrium is `K u = f` with `K = sum_e K_e`, `K_e = int B^T D B t dA`
//! (see [`solid`]); prescribed dofs are eliminated, so the matrix solved is `K_ff`, symmetric
//! positive definite when every body is held against rigid motion. The global dof numbering
//! and which body owns a dof belong to [`model`] (`Body::dof`, `Model::dof_owner`); the
//! equation numbering (which dofs are unknowns) to the affine constraints
//! [`solver::constraints`], which serve the prescribed dofs and constraint elimination alike.
//!
//! ## Layout (a case flows down this list)
//! * [`io::scene`]: the case file (serde, unknown fields and repeated names rejected) — plain data.
//! * [`model`]: the case validated once into typed objects (meshes, materials, dof numbering,
//!   prescribed values, consistent loads, resolved checks, solver settings);
//!   [`model::admit`]: the checks that need the contact rows (rigid modes), and reading a case
//!   file; `model::rigid`: which rigid motions supports and rows leave free.
//! * `mesh`, [`fe`], [`solid`]: meshes and sets, reference elements, elasticity kernels.
//! * [`contact`]: the two axes, meeting in [`contact::Constraint`]:
//!   [`contact::discretization`] (with its `geometry`, `mortar` and `search`) makes rows;
//!   [`contact::enforcement`] (one module per method) says how they are enforced;
//!   [`contact::friction`] is Coulomb's return map (stick, slip, open);
//!   [`contact::state`] is what a solve found; [`contact::forces`] turns row forces into the
//!   forces, pressures and penetrations every report uses.
//! * [`solver`]: [`solver::solve_static`] runs one analysis with the effects its scene names;
//!   [`solver::linear`] the elastic linear system; [`solver::constraints`] affine constraints
//!   `u = T y + t` (Dirichlet data, eliminated contact rows); [`solver::active_set`] load steps, geometry
//!   updates and the active-set loop; [`solver::sparse`] sparse patterns and factorizations
//!   (faer), `solver::dense` small dense eigen-solves. [`post`]: stresses and errors.
//! * [`harness`]: the patch-test tables ([`harness::report`]), case-declared checks
//!   ([`harness::checks`]), exact solutions (`harness::exact`), the tied-layer study
//!   ([`harness::layer`]).
//! * [`io::output`]: `summary.json` and `.vtu` files, written through [`io::paths`] (the one
//!   owner of every path written); [`run`]: one case from file to results, as the command runs it.
//! * [`capability`]: what a case may ask for, asked of the checks `run` makes before its first
//!   solve (the README's generated capability matrix).
//!
//! Physics is opt-in: a scene without contact pairs builds no contact row, and current contact
//! geometry, load steps and geometric stiffness run only when the case's `physics` and `solver`
//! sections ask for them.

pub mod capability;
pub mod contact;
pub mod error;
pub mod fe;
pub mod fe3d;
pub mod harness;
pub mod io;
pub mod mesh;
pub mod model;
pub mod outcome;
pub mod post;
pub mod run;
pub mod run3d;
pub mod solid;
pub mod solid_finite;
pub mod solver;

pub use error::{Error, Result};
