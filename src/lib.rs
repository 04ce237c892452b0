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
//! positive definite when every body is held against rigid motion.
//!
//! ## Layout (a case flows down this list; no module imports one above it in the flow)
//! * [`scene`]: the case file (serde, unknown fields and repeated names rejected) — plain data.
//! * [`model`]: the case validated once into typed objects (meshes, materials, dof numbering,
//!   prescribed values, consistent loads, resolved checks, solver settings);
//!   [`admit`]: the checks that need the contact rows (rigid modes), and reading a case file.
//! * [`fe`], [`solid`], [`mesh`]: reference elements, elasticity kernels, meshes and sets.
//! * [`contact`]: the two axes, meeting in [`contact::Constraint`]:
//!   [`contact::discretization`] (with [`contact::mortar`], [`contact::geometry`],
//!   [`contact::search`]) makes rows; [`contact::enforcement`] (one module per method) says how
//!   they are enforced; [`contact::solver`] runs load steps, geometry updates and the active-set
//!   loop; [`contact::state`] is what it found; [`contact::forces`] turns row forces into the
//!   forces, pressures and penetrations every report uses.
//! * [`sparse`], `dense`: sparse patterns and factorizations (faer), small dense eigen-solves;
//!   `rigid`: which rigid motions supports and rows leave free.
//! * [`solve`]: the elastic linear system and its solve; [`analysis`]: the entry that adds
//!   contact when the scene has pairs; [`post`]: stresses.
//! * [`checks`]: case-declared checks and warnings; [`output`]: `summary.json` and `.vtu`
//!   files, written through [`paths`] (the one owner of every path written).
//! * [`harness`], [`report`], [`layer`], `svg`: the patch-test tables and the tied-layer study.
//!
//! Physics is opt-in: a scene without contact pairs builds no contact row, and current contact
//! geometry, load steps and geometric stiffness run only when the case's `physics` and `solver`
//! sections ask for them.

pub mod admit;
pub mod analysis;
pub mod checks;
pub mod contact;
pub(crate) mod dense;
pub mod error;
pub mod exact;
pub mod fe;
pub mod harness;
pub mod layer;
pub mod mesh;
pub mod model;
pub mod output;
pub mod paths;
pub mod post;
pub mod report;
pub(crate) mod rigid;
pub mod run;
pub mod scene;
pub mod solid;
pub mod solve;
pub mod sparse;
pub(crate) mod svg;

pub use error::{Error, Result};
