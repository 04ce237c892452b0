//! Contact forces, pressures and gaps read from another code's point results, so that `judge`
//! and `table --results` apply a case's contact checks to them.
//!
//! Point fields read at the nodes of every pair's contact surfaces (the slave surface, and the
//! master body's surface), matched to our nodes by position (see [`crate::harness::judge`]):
//!
//! * `contact_force` (2 or 3 components): the nodal contact force `f_a` the interface puts on
//!   the node's body (the assembled contact term of the residual; zero away from contact);
//! * `contact_pressure` (1 component): `p_a`, **positive in compression**; for our tool
//!   `p_a = -f_a . n_a / A_a` (`n_a` the outward normal of the surface at the node,
//!   `A_a = t int N_a ds` the tributary area), for a penalty code `kappa (-g_a)_+`;
//! * `contact_gap` (1 component): the gap `g_a` (`g < 0`: penetration), for `max_penetration`;
//! * `contact_status` (1 component, optional): `0` marks a surface node that carries no
//!   contact constraint in the other code (ours: no row, e.g. beyond the master's end); every
//!   other surface node of the slave side (and, for two-pass pairs, of the master side) is a
//!   contact point.
//!
//! From them the same [`PairForces`] as [`crate::contact::forces`] builds from our rows:
//!
//! ```text
//! by force:     f_a from contact_force,          p_a = -f_a . n_a / A_a
//! by pressure:  p_a from contact_pressure,       f_a = -p_a A_a n_a   (normal forces only)
//! net force on a side F = sum_a f_a,   net moment M = sum_a x_a x f_a,
//! penetration  max_a (-g_a)_+ / h_a  (h_a the longest slave facet at the node)
//! ```
//!
//! and each check takes what it needs: `contact_pressure` and `max_contact_pressure` the
//! pressure (`contact_pressure`, else `contact_force`; a tie's whole traction needs
//! `contact_force`), `contact_force` and `force_balance` the nodal forces (`contact_force`,
//! else `-p A n` for frictionless pairs, where the forces are normal), `max_penetration` the
//! gaps. `force_balance`'s out-of-balance force is `sum |K u - f - f_c|` over the free dofs with
//! our `K` and `f` and the results' nodal contact forces `f_c`. A check whose field is missing
//! is not judged and says which field it needs. A node on the surfaces of two pairs carries one
//! field value, the sum of both pairs' forces; such pairs' checks are not judged.
//!
//! **Configuration.** The surfaces (normals `n_a`, areas `A_a`) and the points `x_a` of the
//! moments are those of the configuration the case's contact geometry names, the rule of our
//! own run ([`crate::contact::forces::pair_forces`]): the reference positions `X_a` for
//! `contact_geometry: "reference"`, the deformed ones `X_a + u_a` (`u` the results'
//! displacement) for `"current"`, where our rows are evaluated at `X + u` and a code that
//! evaluates contact in the deformed geometry balances its moments.
//!
//! **The pressure's area.** `contact_pressure` is read per unit area of that same
//! configuration ([`PressureArea::Case`], the default). A code that reports its pressure per
//! unit deformed area whatever the case says ([`PressureArea::Deformed`], `--pressure-area
//! deformed`) has it turned into the case's: the force is `f_a = -p_a A_a(X + u) n_a(X + u)`,
//! and the pressure judged `p_a A_a(X + u) / A_a`, with `A_a` and `n_a` of the case's
//! configuration. For a case with `contact_geometry: "current"` the two are the same.

use crate::contact::discretization::geometry::Surface;
use crate::contact::forces::{element_sizes, NodalTraction, PairForces, Penetration};
use crate::error::Result;
use crate::harness::outside_results::{
    field, Results, ResultsFile, CONTACT_FORCE_FIELD, CONTACT_GAP_FIELD, CONTACT_PRESSURE_FIELD,
    CONTACT_STATUS_FIELD,
};
use crate::io::scene::{Check, ContactGeometry, DiscretizationSpec, Interaction};
use crate::model::{MasterSide, Model};
use std::collections::{BTreeMap, BTreeSet};

/// The area another code's `contact_pressure` is per (module notes, **The pressure's area**).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PressureArea {
    /// Per unit area of the configuration the case's contact geometry names.
    #[default]
    Case,
    /// Per unit area of the deformed configuration `X + u`.
    Deformed,
}

impl PressureArea {
    /// The option's words: `case` or `deformed`.
    pub fn parse(text: &str) -> std::result::Result<PressureArea, String> {
        match text {
            "case" => Ok(PressureArea::Case),
            "deformed" => Ok(PressureArea::Deformed),
            other => Err(format!(
                "'{other}': give 'case' (per area of the case's contact geometry, the default) \
                 or 'deformed' (per deformed area, at X + u)"
            )),
        }
    }
}

/// What the results give for one pair.
#[derive(Clone, Debug, Default)]
pub struct OutsidePair {
    /// Nodal forces from `contact_force` (pressures from them).
    pub by_force: Option<PairForces>,
    /// Pressures from `contact_pressure` (forces `-p A n`).
    pub by_pressure: Option<PairForces>,
    /// Whether `contact_gap` gave the penetration.
    pub gaps: bool,
    /// Why nothing can be judged for this pair, if so.
    pub refused: Option<String>,
    pub frictionless: bool,
    pub tied: bool,
}

/// The contact data of another code's results.
#[derive(Clone, Debug, Default)]
pub struct OutsideContact {
    pub pairs: Vec<OutsidePair>,
    /// `f_c` at every dof (from `contact_force`, else from `contact_pressure` for frictionless
    /// pairs), when every pair has one.
    pub nodal_force: Option<Vec<f64>>,
    /// Whether each field was found in every results file.
    pub force_field: bool,
    pub pressure_field: bool,
    pub gap_field: bool,
}

/// Which forces a check is judged with, or why it is not judged.
pub enum Source {
    Forces(Vec<PairForces>, &'static str),
    NotJudged(String),
    /// Not a contact check.
    NoContact,
}

fn two_pass(model: &Model, k: usize) -> bool {
    matches!(
        model.contact[k].discretization,
        DiscretizationSpec::NodeToSurface { passes: 2, .. }
    )
}

/// Read the contact fields of `results` at the matched points (`matched[b][n]`: the point of
/// node `n` of body `b`), `u` the results' displacement at every dof (module notes,
/// **Configuration**).
pub fn read(
    model: &Model,
    results: &Results,
    matched: &[Vec<usize>],
    u: &[f64],
    pressure_area: PressureArea,
) -> Result<OutsideContact> {
    let config = (model.physics.contact_geometry == ContactGeometry::Current).then_some(u);
    // the configuration the results' pressure is per, where it differs from the case's
    let pressure_config =
        (pressure_area == PressureArea::Deformed && config.is_none()).then_some(u);
    let file_of = |b: usize| -> &ResultsFile { results.of_body(b) };
    let all_have = |name: &str| results.files().iter().all(|f| f.has(name));
    let mut out = OutsideContact {
        force_field: all_have(CONTACT_FORCE_FIELD),
        pressure_field: all_have(CONTACT_PRESSURE_FIELD),
        gap_field: all_have(CONTACT_GAP_FIELD),
        ..OutsideContact::default()
    };
    // surface nodes of each pair, to find nodes shared by two pairs
    let mut owners: BTreeMap<(usize, usize), BTreeSet<usize>> = BTreeMap::new();
    let mut sides_of = Vec::new();
    for (k, pair) in model.contact.iter().enumerate() {
        let mut sides = vec![(pair.slave.0, pair.slave.1.clone(), true)];
        if let MasterSide::Body { body, facets } = &pair.master {
            sides.push((*body, facets.clone(), two_pass(model, k)));
        }
        for (b, facets, _) in &sides {
            for &f in facets {
                for n in model.bodies[*b].mesh.facet_nodes(f) {
                    owners.entry((*b, n)).or_default().insert(k);
                }
            }
        }
        sides_of.push(sides);
    }
    let mut nodal_force = vec![0.0; model.dof_count];
    let mut every_pair_has_forces = true;
    for (k, pair) in model.contact.iter().enumerate() {
        let tied = pair.interaction == Interaction::Tied;
        let frictionless = pair.interaction == Interaction::Frictionless;
        let mut this = OutsidePair {
            tied,
            frictionless,
            ..OutsidePair::default()
        };
        let sides = &sides_of[k];
        let shared = owners.iter().find(|((b, _), pairs)| {
            pairs.len() > 1 && pairs.contains(&k) && sides.iter().any(|s| s.0 == *b)
        });
        if let Some(((b, n), _)) = shared {
            this.refused = Some(format!(
                "node {n} of body '{}' lies on the surfaces of several pairs, and its field \
                 value is their sum",
                model.bodies[*b].name
            ));
        }
        if this.refused.is_some() {
            every_pair_has_forces = false;
            out.pairs.push(this);
            continue;
        }
        let side_files = |name: &str| sides.iter().all(|(b, _, _)| file_of(*b).has(name));
        let surfaces: Vec<Surface> = sides
            .iter()
            .map(|(b, facets, _)| {
                Surface::of_body(*b, &model.bodies[*b], facets, model.thickness, config)
            })
            .collect();
        let pressure_surfaces: Option<Vec<Surface>> = pressure_config.map(|u| {
            sides
                .iter()
                .map(|(b, facets, _)| {
                    Surface::of_body(*b, &model.bodies[*b], facets, model.thickness, Some(u))
                })
                .collect()
        });
        let carries: Vec<bool> = sides.iter().map(|s| s.2).collect();
        let has_force = side_files(CONTACT_FORCE_FIELD);
        let has_pressure = side_files(CONTACT_PRESSURE_FIELD);
        let has_gap = side_files(CONTACT_GAP_FIELD);
        let build = |use_force: bool| -> Result<PairForces> {
            let mut nodes = Vec::new();
            let (mut on_slave, mut on_master) = ([0.0; 2], [0.0; 2]);
            let (mut net_moment, mut force_scale) = (0.0, 0.0);
            for (s, (surface, &rows)) in surfaces.iter().zip(&carries).enumerate() {
                let file = file_of(surface.body);
                let force_values = field(file, CONTACT_FORCE_FIELD, 2)?;
                let pressure_values = field(file, CONTACT_PRESSURE_FIELD, 1)?;
                let status = field(file, CONTACT_STATUS_FIELD, 1)?;
                for (&n, data) in &surface.nodes {
                    let point = matched[surface.body][n];
                    let body = &model.bodies[surface.body];
                    let (force, pressure) = if use_force {
                        let v = force_values.expect("checked above").at(point);
                        let f = [v[0], v[1]];
                        (
                            f,
                            -(f[0] * data.normal[0] + f[1] * data.normal[1]) / data.area,
                        )
                    } else {
                        let p = pressure_values.expect("checked above").at(point)[0];
                        // the area and normal the pressure is per (module notes)
                        let per = pressure_surfaces
                            .as_ref()
                            .and_then(|d| d[s].nodes.get(&n))
                            .unwrap_or(data);
                        (
                            [-p * per.area * per.normal[0], -p * per.area * per.normal[1]],
                            p * per.area / data.area,
                        )
                    };
                    let x = match config {
                        Some(u) => [
                            body.mesh.nodes[n][0] + u[body.dof(n, 0)],
                            body.mesh.nodes[n][1] + u[body.dof(n, 1)],
                        ],
                        None => body.mesh.nodes[n],
                    };
                    let target = if s == 0 {
                        &mut on_slave
                    } else {
                        &mut on_master
                    };
                    target[0] += force[0];
                    target[1] += force[1];
                    net_moment += x[0] * force[1] - x[1] * force[0];
                    force_scale += force[0].hypot(force[1]);
                    let marked_off = status.is_some_and(|st| st.at(point)[0] == 0.0);
                    // another code's nodal values: its traction is its force per tributary
                    // area (no covered share is known)
                    let nn = data.normal;
                    nodes.push(NodalTraction {
                        body: surface.body,
                        node: n,
                        point: x,
                        area: data.area,
                        covered_area: data.area,
                        normal: nn,
                        force,
                        traction: [force[0] / data.area, force[1] / data.area],
                        pressure,
                        shear: (-force[0] * nn[1] + force[1] * nn[0]) / data.area,
                        carries_rows: rows && !marked_off,
                    });
                }
            }
            if let MasterSide::Rigid(_) = pair.master {
                on_master = [-on_slave[0], -on_slave[1]];
            }
            let mut penetration = Penetration::default();
            if has_gap {
                let sizes: Vec<BTreeMap<usize, f64>> = surfaces.iter().map(element_sizes).collect();
                for t in nodes.iter().filter(|t| t.carries_rows) {
                    let s = surfaces.iter().position(|s| s.body == t.body).unwrap_or(0);
                    let file = file_of(t.body);
                    let g = field(file, CONTACT_GAP_FIELD, 1)?
                        .expect("checked above")
                        .at(matched[t.body][t.node])[0];
                    let depth = (-g).max(0.0);
                    let h = sizes[s].get(&t.node).copied().unwrap_or(0.0);
                    let share = if h > 0.0 { depth / h } else { 0.0 };
                    penetration.depth = penetration.depth.max(depth);
                    if share > penetration.share_of_element
                        || penetration.at.is_none() && depth > 0.0
                    {
                        penetration.share_of_element = share;
                        penetration.at = Some((t.body, t.node, t.point));
                    }
                }
            }
            Ok(PairForces {
                pair: k,
                on_slave,
                on_master,
                net_moment: [0.0, 0.0, net_moment],
                force_scale,
                nodes,
                penetration,
            })
        };
        if has_force {
            this.by_force = Some(build(true)?);
        }
        if has_pressure {
            this.by_pressure = Some(build(false)?);
        }
        this.gaps = has_gap;
        match this.forces() {
            Some((forces, _)) => {
                for t in &forces.nodes {
                    let body = &model.bodies[t.body];
                    nodal_force[body.dof(t.node, 0)] += t.force[0];
                    nodal_force[body.dof(t.node, 1)] += t.force[1];
                }
            }
            None => every_pair_has_forces = false,
        }
        out.pairs.push(this);
    }
    if every_pair_has_forces && !model.contact.is_empty() {
        out.nodal_force = Some(nodal_force);
    }
    Ok(out)
}

impl OutsidePair {
    /// The nodal forces of the pair: `contact_force`, else `-p A n` for a frictionless pair.
    pub fn forces(&self) -> Option<(&PairForces, &'static str)> {
        match (&self.by_force, &self.by_pressure) {
            (Some(f), _) => Some((f, CONTACT_FORCE_FIELD)),
            (None, Some(p)) if self.frictionless => Some((p, CONTACT_PRESSURE_FIELD)),
            _ => None,
        }
    }

    /// The pressures of the pair: `contact_pressure` (not for a tie, whose whole traction is
    /// judged), else from `contact_force`.
    pub fn pressures(&self) -> Option<(&PairForces, &'static str)> {
        match (&self.by_pressure, &self.by_force) {
            (Some(p), _) if !self.tied => Some((p, CONTACT_PRESSURE_FIELD)),
            (_, Some(f)) => Some((f, CONTACT_FORCE_FIELD)),
            _ => None,
        }
    }

    fn missing_forces(&self) -> String {
        if self.frictionless {
            format!("a '{CONTACT_FORCE_FIELD}' or '{CONTACT_PRESSURE_FIELD}' point field")
        } else {
            format!(
                "a '{CONTACT_FORCE_FIELD}' point field (the pair is tied or frictional: its \
                 forces are not normal to the surface)"
            )
        }
    }
}

impl OutsideContact {
    /// The forces a contact check is judged with (for each pair it names) and the field they
    /// came from, or why it is not judged.
    pub fn source(&self, model: &Model, check: &Check) -> Source {
        let index = |name: &str| model.contact.iter().position(|p| p.name == name);
        let refused = |k: usize| {
            self.pairs[k]
                .refused
                .clone()
                .map(|why| format!("contact '{}': {why}", model.contact[k].name))
        };
        let one = |name: &str,
                   pick: &dyn Fn(&OutsidePair) -> Option<(&PairForces, &'static str)>,
                   missing: &dyn Fn(&OutsidePair) -> String| {
            let Some(k) = index(name) else {
                return Source::NotJudged(format!("no contact pair '{name}'"));
            };
            if let Some(why) = refused(k) {
                return Source::NotJudged(why);
            }
            match pick(&self.pairs[k]) {
                Some((f, from)) => Source::Forces(vec![f.clone()], from),
                None => Source::NotJudged(format!(
                    "it needs {} on the surfaces of '{name}', which the results do not hold",
                    missing(&self.pairs[k])
                )),
            }
        };
        let pressure_missing = |p: &OutsidePair| {
            if p.tied {
                format!("a '{CONTACT_FORCE_FIELD}' point field (a tie's whole traction is judged)")
            } else {
                format!("a '{CONTACT_PRESSURE_FIELD}' or '{CONTACT_FORCE_FIELD}' point field")
            }
        };
        match check {
            Check::ContactPressure { pair, .. } | Check::MaxContactPressure { pair, .. } => {
                one(pair, &|p| p.pressures(), &pressure_missing)
            }
            Check::ContactForce { pair, .. } => one(pair, &|p| p.forces(), &|p| p.missing_forces()),
            Check::MaxPenetration { pair, .. } => {
                let ks: Vec<usize> = match pair {
                    Some(name) => match index(name) {
                        Some(k) => vec![k],
                        None => return Source::NotJudged(format!("no contact pair '{name}'")),
                    },
                    None => (0..model.contact.len()).collect(),
                };
                let mut forces = Vec::new();
                for k in ks {
                    if let Some(why) = refused(k) {
                        return Source::NotJudged(why);
                    }
                    let p = &self.pairs[k];
                    match (p.gaps, p.by_force.as_ref().or(p.by_pressure.as_ref())) {
                        (true, Some(f)) => forces.push(f.clone()),
                        _ => {
                            return Source::NotJudged(format!(
                                "it needs a '{CONTACT_GAP_FIELD}' point field (and a \
                                 '{CONTACT_PRESSURE_FIELD}' or '{CONTACT_FORCE_FIELD}' one) on \
                                 the surfaces of '{}', which the results do not hold",
                                model.contact[k].name
                            ))
                        }
                    }
                }
                Source::Forces(forces, CONTACT_GAP_FIELD)
            }
            Check::ForceBalance { .. } => {
                let mut forces = Vec::new();
                let mut from = CONTACT_FORCE_FIELD;
                for (k, p) in self.pairs.iter().enumerate() {
                    if let Some(why) = refused(k) {
                        return Source::NotJudged(why);
                    }
                    match p.forces() {
                        Some((f, field)) => {
                            forces.push(f.clone());
                            if field != CONTACT_FORCE_FIELD {
                                from = field;
                            }
                        }
                        None => {
                            return Source::NotJudged(format!(
                                "it needs {} on the surfaces of '{}', which the results do not \
                                 hold",
                                p.missing_forces(),
                                model.contact[k].name
                            ))
                        }
                    }
                }
                if self.nodal_force.is_none() {
                    return Source::NotJudged("the results give no nodal contact forces".into());
                }
                Source::Forces(forces, from)
            }
            _ => Source::NoContact,
        }
    }
}
