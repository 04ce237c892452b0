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
//! ## Layout
//! * [`scene`]: the case file (serde, unknown fields rejected) — plain data.
//! * [`model`]: the case validated once into typed objects (meshes, materials, dof numbering,
//!   prescribed values, consistent loads, resolved checks).
//! * [`fe`], [`solid`], [`mesh`]: reference elements, elasticity kernels, meshes and sets.
//! * [`sparse`]: sparsity pattern computed once, scatter-assembly, sparse Cholesky (faer).
//! * [`solve`]: the static solve with a timing breakdown; [`post`]: stresses.
//! * [`checks`]: case-declared checks; [`output`]: `summary.json` and VTK `.vtu` files.
//!
//! The contact axes (discretization x enforcement), friction, dynamics and finite deformation
//! plug into the opt-in [`scene::Physics`] section and into the equation numbering of
//! [`solve`]; a scene that does not ask for them never builds them.

pub mod admit;
pub mod analysis;
pub mod checks;
pub mod contact;
pub mod dense;
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
pub mod rigid;
pub mod run;
pub mod scene;
pub mod solid;
pub mod solve;
pub mod sparse;
pub mod svg;

pub use error::{Error, Result};
