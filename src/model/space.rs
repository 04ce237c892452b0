//! The dimension seam: what a body's cells supply to the one code path of the model, the
//! assembly and the contact solve, in `D = 2` (plane cells, [`ElementKind`]) and `D = 3` (solid
//! cells, [`SolidKind`]).
//!
//! Dofs are numbered `offset_b + D node + component` in both; a cell's element stiffness is
//! `K_e = int_cell B^T C B dV` over its stiffness rule (times the thickness in 2D), with the
//! plane-strain or plane-stress `C` of [`crate::solid::Elasticity`] in 2D and its isotropic
//! 6x6 `C` in 3D (one kernel for both, [`crate::solid`]) (Hughes, *The Finite Element Method*, 2000,
//! chapters 2-3). Everything that does not depend on the dimension (dof numbering, sparsity,
//! Dirichlet elimination, the active-set loop and every enforcement method) is written once
//! against this trait.

use crate::fe::{ElementKind, QuadPoint, ReferenceCell};
use crate::fe3d::SolidKind;
use crate::harness::exact::ExactField;
use crate::model::{FacetLoad, Model};
use crate::solid::{element_internal_force, element_stiffness, facet_traction_load, Elasticity};
use crate::solid_finite::{element_residual_and_tangent, Hyperelastic, Inverted};

/// The cell kinds of a `D`-dimensional elastic body.
pub trait SolidCell<const D: usize>: ReferenceCell<D> + Send + Sync + 'static {
    /// The small-strain elastic material of a body of these cells.
    type Material: Clone + std::fmt::Debug + Send + Sync;

    /// The quadrature rule of the element stiffness.
    fn stiffness_rule(self) -> Vec<QuadPoint<D>>;

    /// The element stiffness `K_e` (row-major, `D n` square, `n` the cell's node count) of the
    /// cell at `coords` with the rule `rule` (of [`SolidCell::stiffness_rule`]); `thickness`
    /// multiplies it in 2D and is 1 in 3D.
    fn element_stiffness(
        self,
        coords: &[[f64; D]],
        material: &Self::Material,
        thickness: f64,
        rule: &[QuadPoint<D>],
        ke: &mut [f64],
    );

    /// The small-strain internal force `f_e = int_cell B^T C B u_e dV` of the cell at `coords`
    /// under the element displacement `u_e`, added to `out` (`D n` entries).
    fn add_internal_force(
        self,
        coords: &[[f64; D]],
        u_e: &[f64],
        material: &Self::Material,
        thickness: f64,
        rule: &[QuadPoint<D>],
        out: &mut [f64],
    );

    /// The total-Lagrangian internal force `f_e` (into `force[..D n]`) and, with
    /// `with_tangent`, the consistent tangent `K_e` (material + geometric, row-major, into
    /// `k[..(D n)^2]`) of the cell at `coords` under the element displacement `u_e`, for the
    /// hyperelastic energy `law` ([`crate::solid_finite`]; in 2D plane strain, times the
    /// thickness); `Err` at a quadrature point with
    /// `det F <= 0`.
    #[allow(clippy::too_many_arguments)]
    fn finite_residual_and_tangent(
        self,
        coords: &[[f64; D]],
        u_e: &[f64],
        law: &Hyperelastic,
        thickness: f64,
        rule: &[QuadPoint<D>],
        with_tangent: bool,
        force: &mut [f64],
        k: &mut [f64],
    ) -> Result<(), Inverted<D>>;

    /// The model as a 2D model, where the physics built only in 2D (finite strain, dynamics,
    /// friction, exact fields) lives; `None` in 3D, where the model refuses those scenes.
    fn as_plane(model: &Model<D, Self>) -> Option<&Model>
    where
        Self: Sized;

    /// Young's modulus of `material` (scales, messages).
    fn youngs_modulus(material: &Self::Material) -> f64;

    /// The quadrature rule of loads over the cell (body forces): the cell's error rule.
    fn load_rule(self) -> Vec<QuadPoint<D>>;

    /// The consistent nodal forces `f_a = int_facet N_a t dA` of the facet load `load` on the
    /// facet of a cell of this kind whose nodes (the facet's own order) are at `coords`
    /// (times `thickness` in 2D): `add(a, i, value)` for each contribution to component `i`
    /// of the facet's node `a`. 2D: [`crate::model::add_edge_load`]; 3D:
    /// [`crate::solid::facet_traction_load`] (an exact field is 2D only).
    fn add_facet_load(
        self,
        coords: &[[f64; D]],
        load: &FacetLoad<D>,
        thickness: f64,
        add: &mut dyn FnMut(usize, usize, f64),
    );

    /// The exact field's displacement at `p` for `material` (2D; `None` in 3D, which has no
    /// exact fields).
    fn exact_displacement(
        field: &ExactField,
        p: [f64; D],
        material: &Self::Material,
    ) -> Option<[f64; D]>;

    /// The axis names of the components, `x, y(, z)`.
    fn axis_name(component: usize) -> &'static str {
        ["x", "y", "z"][component]
    }
}

/// Adds the small-strain internal force of [`element_internal_force`] to `out` (`D n` entries).
fn add_internal_force<const D: usize, C: ReferenceCell<D>>(
    kind: C,
    coords: &[[f64; D]],
    u_e: &[f64],
    material: &Elasticity<D>,
    thickness: f64,
    rule: &[QuadPoint<D>],
    out: &mut [f64],
) {
    let mut fe = [0.0; 3 * crate::fe3d::MAX_SOLID_NODES];
    element_internal_force(kind, coords, u_e, material, thickness, rule, &mut fe);
    for (o, f) in out.iter_mut().zip(&fe[..D * kind.node_count()]) {
        *o += f;
    }
}

impl SolidCell<2> for ElementKind {
    type Material = Elasticity;

    fn element_stiffness(
        self,
        coords: &[[f64; 2]],
        material: &Elasticity,
        thickness: f64,
        rule: &[QuadPoint<2>],
        ke: &mut [f64],
    ) {
        element_stiffness(self, coords, material, thickness, rule, ke);
    }

    fn stiffness_rule(self) -> Vec<QuadPoint<2>> {
        ElementKind::stiffness_rule(self)
    }

    fn add_internal_force(
        self,
        coords: &[[f64; 2]],
        u_e: &[f64],
        material: &Elasticity,
        thickness: f64,
        rule: &[QuadPoint<2>],
        out: &mut [f64],
    ) {
        add_internal_force(self, coords, u_e, material, thickness, rule, out);
    }

    fn finite_residual_and_tangent(
        self,
        coords: &[[f64; 2]],
        u_e: &[f64],
        law: &Hyperelastic,
        thickness: f64,
        rule: &[QuadPoint<2>],
        with_tangent: bool,
        force: &mut [f64],
        k: &mut [f64],
    ) -> Result<(), Inverted<2>> {
        element_residual_and_tangent(
            self,
            coords,
            u_e,
            law,
            thickness,
            rule,
            with_tangent,
            force,
            k,
        )
    }

    fn as_plane(model: &Model) -> Option<&Model> {
        Some(model)
    }

    fn youngs_modulus(material: &Elasticity) -> f64 {
        material.youngs_modulus
    }

    fn exact_displacement(
        field: &ExactField,
        p: [f64; 2],
        material: &Elasticity,
    ) -> Option<[f64; 2]> {
        Some(field.displacement(p, material))
    }

    fn load_rule(self) -> Vec<QuadPoint<2>> {
        self.error_rule()
    }

    fn add_facet_load(
        self,
        coords: &[[f64; 2]],
        load: &FacetLoad<2>,
        thickness: f64,
        add: &mut dyn FnMut(usize, usize, f64),
    ) {
        crate::model::add_edge_load(self.edge_kind(), coords, load, thickness, add);
    }
}

impl SolidCell<3> for SolidKind {
    type Material = Elasticity<3>;

    fn element_stiffness(
        self,
        coords: &[[f64; 3]],
        material: &Elasticity<3>,
        _thickness: f64,
        rule: &[QuadPoint<3>],
        ke: &mut [f64],
    ) {
        element_stiffness(self, coords, material, 1.0, rule, ke);
    }

    fn stiffness_rule(self) -> Vec<QuadPoint<3>> {
        SolidKind::stiffness_rule(self)
    }

    fn add_internal_force(
        self,
        coords: &[[f64; 3]],
        u_e: &[f64],
        material: &Elasticity<3>,
        _thickness: f64,
        rule: &[QuadPoint<3>],
        out: &mut [f64],
    ) {
        add_internal_force(self, coords, u_e, material, 1.0, rule, out);
    }

    fn finite_residual_and_tangent(
        self,
        coords: &[[f64; 3]],
        u_e: &[f64],
        law: &Hyperelastic,
        _thickness: f64,
        rule: &[QuadPoint<3>],
        with_tangent: bool,
        force: &mut [f64],
        k: &mut [f64],
    ) -> Result<(), Inverted<3>> {
        element_residual_and_tangent(self, coords, u_e, law, 1.0, rule, with_tangent, force, k)
    }

    fn as_plane(_model: &Model<3, SolidKind>) -> Option<&Model> {
        None
    }

    fn youngs_modulus(material: &Elasticity<3>) -> f64 {
        material.youngs_modulus
    }

    fn exact_displacement(_: &ExactField, _: [f64; 3], _: &Elasticity<3>) -> Option<[f64; 3]> {
        None
    }

    fn load_rule(self) -> Vec<QuadPoint<3>> {
        self.error_rule()
    }

    fn add_facet_load(
        self,
        coords: &[[f64; 3]],
        load: &FacetLoad<3>,
        _thickness: f64,
        add: &mut dyn FnMut(usize, usize, f64),
    ) {
        let fe = match load {
            FacetLoad::Pressure(p) => {
                facet_traction_load(self.facet_kind(), coords, &|_, n| n.map(|v| -p * v))
            }
            FacetLoad::Vector(t) => facet_traction_load(self.facet_kind(), coords, &|_, _| *t),
            FacetLoad::Exact(_) => unreachable!("exact fields are refused in 3D"),
        };
        for a in 0..coords.len() {
            for i in 0..3 {
                add(a, i, fe[3 * a + i]);
            }
        }
    }
}
