//! Everything that crosses the tool's boundary: the case file ([`scene`], plain serde data),
//! the paths the tool writes ([`paths`], the one owner of every written path), the results it
//! writes ([`output`]: `summary.json` and `.vtu` files) and its plots (`svg`); the histories and frames of a time integration ([`timeline`]).

pub mod export;
pub mod gmsh;
pub mod output;
pub mod paths;
pub mod scene;
pub(crate) mod svg;
pub mod vtu_read;
pub mod timeline;
