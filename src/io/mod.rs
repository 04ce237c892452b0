//! Everything that crosses the tool's boundary: the case file ([`scene`], plain serde data),
//! the paths the tool writes ([`paths`], the one owner of every written path), the results it
//! writes ([`output`]: `summary.json` and `.vtu` files) and its plots (`svg`); [`contact_output`]
//! writes the per-pair contact results through [`vtu`]; [`timeline`] the histories and frames
//! of a time integration; [`export`] and [`gmsh`] write a case for other codes, and
//! [`vtu_read`] reads their results back; [`gmsh_read`] reads a body's mesh from a Gmsh file.

pub mod contact_output;
pub mod export;
pub mod gmsh;
pub mod gmsh_read;
pub mod output;
pub mod paths;
pub mod scene;
pub(crate) mod svg;
pub mod timeline;
pub mod vtu;
pub mod vtu_read;
