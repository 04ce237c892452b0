#!/usr/bin/env python3
"""Our export of a case -> Kratos Multiphysics input: the worked example of judging another
contact code with the catalogue (docs/judge-your-code.md walks through it).

    python crosscheck/kratos_convert.py EXPORT/<case> KRATOS_DIR --contact alm|penalty [--kappa K]

reads what `contact-patch export CASE --out EXPORT` wrote for one case,

    EXPORT/<case>/<case>.json   the sidecar: bodies with their node and facet sets, the supports
                                and loads resolved on the mesh (every prescribed displacement and
                                every consistent nodal force by body, node and Gmsh tag), the
                                contact pairs;
    EXPORT/<case>/<body>.vtu    each body's mesh (VTK node order, ASCII) with our node numbers,

and writes the three files a Kratos structural analysis reads:

    KRATOS_DIR/<case>.mdpa             nodes, elements, contact edges, loads, fixed displacements
    KRATOS_DIR/ProjectParameters.json  the solver (static, contact) and the contact process
    KRATOS_DIR/materials.json          linear elastic plane strain/stress per body
    KRATOS_DIR/bodies.json             for kratos_solve.py: which Kratos nodes and cells make which
                                       of our bodies (to write <body>.vtu results)

Nothing here is Kratos' code: it writes Kratos' input format (facts from its documentation and
its test inputs) from our sidecar. What maps to what:

* node `n` of body `b` is Kratos node `offset_b + n + 1`, the Gmsh tag of the export
  (`node_tag_offset` in the sidecar), so results can be traced to the .msh too;
* Q4 cells -> `SmallDisplacementElement2D4N` (2x2 Gauss, as ours); T3 -> `...2D3N`; every
  body has its own `Properties` (E, nu, thickness; plane strain or stress law);
* a prescribed displacement (`resolved.prescribed_displacements`) -> `NodalData DISPLACEMENT_X`
  (or `_Y`) with the fixity flag 1 and the value: Kratos keeps the dof fixed at that value;
* a consistent nodal force (`resolved.consistent_nodal_forces`, the tractions, pressures and
  `"exact"` loads already integrated by our tool) -> a `PointLoadCondition2D1N` on the node with
  its `POINT_LOAD` in `ConditionalData`: no load integration happens in Kratos, so both codes
  see the same right-hand side;
* each contact pair -> its slave and master facets as `LineCondition2D2N` in sub model parts
  `<pair>_slave`, `<pair>_master` and `<pair>` (both): the contact process searches `<pair>`
  and takes `<pair>_slave` as the slave side (`assume_master_slave`). Kratos' 2D mortar
  conditions exist for 2-node edges only, so a pair on Q9/T6 facets (3-node edges) is refused
  with exit code 3 and that reason (the cross-check writes it to the results' `<case>/
  not-applicable.txt`, so that `contact-patch table --results` shows the cell as n/a with it);
* a tied pair (`"interaction": "tied"`) -> Kratos' mortar mesh tying (`MeshTyingProcess`,
  `mortar_type: ComponentsMeshTying`, Lagrange multipliers); with `--contact penalty` it is
  refused (exit 3): Kratos' penalty contact is frictionless or frictional, it has no tie;
* `--contact alm`: `ALMContactFrictionless` (mortar, augmented Lagrangian; Kratos picks the
  penalty of the augmentation from the stiffness unless `--kappa` is given);
  `--contact penalty`: `PenaltyContactFrictionless` (mortar, penalty `--kappa`, pressure per
  unit gap; default: the case's sweep kappa, else the pair's own).

Exit 0 on success, 3 when Kratos cannot take the case (the reason on stderr, one line starting
with "n/a:"), 2 on bad input.
"""

import argparse
import json
import math
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

# VTK cell type -> (our element, Kratos element, nodes per cell). Kratos' Quadrilateral2D4 and
# Triangle2D3 take their nodes counter-clockwise, as VTK does.
ELEMENTS = {
    9: ("Q4", "SmallDisplacementElement2D4N", 4),
    5: ("T3", "SmallDisplacementElement2D3N", 3),
    28: ("Q9", "SmallDisplacementElement2D9N", 9),
    22: ("T6", "SmallDisplacementElement2D6N", 6),
}


class NotApplicable(Exception):
    """Kratos cannot solve this case as stated (the message says why)."""


def read_vtu(path):
    """Points (x, y) and cells [(vtk type, [nodes])] of one of our ASCII .vtu meshes."""
    root = ET.parse(path).getroot()
    piece = root.find("UnstructuredGrid/Piece")
    arrays = {a.get("Name"): a for a in piece.iter("DataArray")}
    flat = [float(v) for v in piece.find("Points/DataArray").text.split()]
    points = [(flat[i], flat[i + 1]) for i in range(0, len(flat), 3)]
    conn = [int(v) for v in arrays["connectivity"].text.split()]
    offsets = [int(v) for v in arrays["offsets"].text.split()]
    types = [int(v) for v in arrays["types"].text.split()]
    cells, start = [], 0
    for end, t in zip(offsets, types):
        cells.append((t, conn[start:end]))
        start = end
    return points, cells


def kappa_of(sidecar, pair, given):
    """The penalty for --contact penalty: --kappa, else the sweep's (the catalogue's cells),
    else the pair's own enforcement kappa."""
    if given is not None:
        return given
    sweep = sidecar.get("sweep") or {}
    for e in sweep.get("enforcements", []):
        if e.get("kind") == "penalty" and "kappa" in e:
            return float(e["kappa"])
    enf = pair.get("enforcement", {})
    if "kappa" in enf:
        return float(enf["kappa"])
    raise NotApplicable(f"pair {pair['name']!r}: no penalty kappa in the case; give --kappa")


def rigid_line_body(rigid, owner, slave_body, slave_facets, bodies, nodes, elements, fixed_nodes):
    """Mesh a rigid line (point p, normal n pointing to the slave side) as a strip of Q4 cells
    behind it, every node held: Kratos' mortar needs a meshed master. The strip's surface nodes
    are the slave nodes projected onto the line (so its edges are as fine as the slave's where
    the slave is fine), plus one edge beyond each end; the strip is one cell deep. Its nodes
    and elements get ids after the bodies'; returns its surface edges, ordered so that the
    strip lies on their right (outward normal towards the slave), its Properties id and its
    nodes. The strip is not one of the case's bodies: no results are written for it."""
    (px, py), (nx, ny) = rigid["point"], rigid["normal"]
    length = math.hypot(nx, ny)
    nx, ny = nx / length, ny / length
    tx, ty = ny, -nx  # the tangent: (t, n) is a right-handed pair
    used = sorted({n for f in slave_facets for n in f})
    s = sorted({round((slave_body["points"][n][0] - px) * tx + (slave_body["points"][n][1] - py) * ty,
                      12) for n in used})
    h = min(b - a for a, b in zip(s, s[1:])) if len(s) > 1 else 1.0
    s = [s[0] - (s[1] - s[0] if len(s) > 1 else h)] + s + [s[-1] + (s[-1] - s[-2] if len(s) > 1 else h)]
    depth = max(s[-1] - s[0], h) / 10.0
    first = max(i for i, _ in nodes) + 1
    top = list(range(first, first + len(s)))
    bottom = list(range(first + len(s), first + 2 * len(s)))
    for ids, d in ((top, 0.0), (bottom, depth)):
        for i, si in zip(ids, s):
            nodes.append((i, (px + si * tx - d * nx, py + si * ty - d * ny)))
    fixed_nodes.extend(top + bottom)
    prop = max(b["property"] for b in bodies.values()) + 1
    eid = max(i for rows in elements.values() for i, *_ in rows)
    rows = elements.setdefault("SmallDisplacementElement2D4N", [])
    # with t = (n_y, -n_x) the cell (bottom_i, bottom_i+1, top_i+1, top_i) runs counter-clockwise
    # when (t, n) is a right-handed pair: t x n = n_y^2 + n_x^2 > 0, always
    for k in range(len(s) - 1):
        eid += 1
        rows.append((eid, prop, [bottom[k], bottom[k + 1], top[k + 1], top[k]], owner))
    return [(top[k + 1], top[k]) for k in range(len(s) - 1)], prop, top + bottom


def convert(export_dir, out_dir, contact, kappa=None):
    export_dir, out_dir = Path(export_dir), Path(out_dir)
    case = export_dir.name
    sidecar = json.loads((export_dir / f"{case}.json").read_text())
    if not sidecar.get("format", "").startswith("contact-patch export"):
        raise ValueError(f"{export_dir}: not a contact-patch export (no 'format')")
    plane = sidecar["analysis"]["plane"]
    thickness = float(sidecar["analysis"]["thickness"])

    # --- bodies: nodes, cells, properties ----------------------------------------------------
    bodies = {}
    nodes, elements = [], {}  # Kratos id -> (x, y); Kratos element name -> [(id, prop, nodes)]
    eid = 0
    for prop, body in enumerate(sidecar["bodies"], start=1):
        offset = int(body["node_tag_offset"])
        points, cells = read_vtu(export_dir / body["vtu"])
        ids = [offset + n + 1 for n in range(len(points))]
        nodes.extend(zip(ids, points))
        body_cells = []
        for vtk_type, conn in cells:
            if vtk_type not in ELEMENTS:
                raise NotApplicable(f"body {body['name']!r}: VTK cell type {vtk_type}")
            name = ELEMENTS[vtk_type][1]
            eid += 1
            elements.setdefault(name, []).append((eid, prop, [ids[n] for n in conn], body["name"]))
            body_cells.append((vtk_type, [ids[n] for n in conn]))
        bodies[body["name"]] = {
            "name": body["name"],
            "property": prop,
            "offset": offset,
            "nodes": ids,
            "points": points,
            "cells": body_cells,
            "E": body["material"]["E"],
            "nu": body["material"]["nu"],
            "facet_sets": body["facet_sets"],
        }

    # --- contact pairs: 2-node edges on each side ---------------------------------------------
    conditions = []  # (id, nodes) of LineCondition2D2N
    fixed_nodes = []  # nodes of meshed rigid obstacles, held at zero displacement
    obstacles = []  # the meshed rigid obstacles as Kratos bodies
    pair_parts = []  # (pair name, tied, slave cond ids, master cond ids, kappa)
    cid = 0
    for pair in sidecar.get("contact") or []:
        tied = pair.get("interaction") == "tied"
        if tied and contact == "penalty":
            raise NotApplicable(
                f"pair {pair['name']!r} is tied: Kratos' penalty contact process has contact_type "
                "Frictionless or Frictional only, no mesh tying (its tie is the mortar "
                "MeshTyingProcess with Lagrange multipliers)")
        if not tied and pair.get("interaction") not in (None, "frictionless"):
            raise NotApplicable(f"pair {pair['name']!r}: interaction {pair.get('interaction')!r}")
        sides = []
        for side in ("slave", "master"):
            spec = pair[side]
            if spec.get("rigid"):
                if side == "slave" or spec["rigid"].get("kind") != "line" or tied:
                    raise NotApplicable(
                        f"pair {pair['name']!r}: a rigid {side} ({spec['rigid'].get('kind')}); "
                        "Kratos' mortar contact pairs two meshed surfaces, and only a rigid line "
                        "is meshed here (as a held strip)")
                slave_spec = pair["slave"]
                slave_body = bodies[slave_spec["body"]]
                slave_facets = slave_body["facet_sets"][slave_spec["set"]]["facets"]
                edges, prop, strip_nodes = rigid_line_body(
                    spec["rigid"], f"{pair['name']}_rigid", slave_body, slave_facets, bodies, nodes,
                    elements, fixed_nodes)
                eid = max(i for rows in elements.values() for i, *_ in rows)
                # the strip: a body of Kratos' model only, of the slave's material (held)
                obstacles.append({"name": f"{pair['name']}_rigid", "property": prop,
                                  "nodes": strip_nodes, "E": slave_body["E"],
                                  "nu": slave_body["nu"]})
                ids = []
                for a, b in edges:
                    cid += 1
                    conditions.append((cid, slave_body["property"], [a, b]))
                    ids.append(cid)
                sides.append(ids)
                continue
            body = bodies[spec["body"]]
            facets = body["facet_sets"][spec["set"]]["facets"]
            ids = []
            for f in facets:
                if len(f) != 2:
                    raise NotApplicable(
                        f"pair {pair['name']!r}: {len(f)}-node contact edges ({spec['body']}/"
                        f"{spec['set']}); Kratos' 2D mortar conditions take 2-node edges only")
                cid += 1
                conditions.append((cid, body["property"], [body["offset"] + n + 1 for n in f]))
                ids.append(cid)
            sides.append(ids)
        k = None if tied else (kappa_of(sidecar, pair, kappa) if contact == "penalty" else kappa)
        pair_parts.append((pair["name"], tied, sides[0], sides[1], k))
    if not pair_parts:
        raise NotApplicable("the case has no contact pair")
    if len(pair_parts) > 10:
        raise NotApplicable("more than 10 pairs (Kratos' contact processes take keys 0-9)")

    # --- supports and loads, as resolved by our tool ------------------------------------------
    fixed = {"x": [(n, 0.0) for n in fixed_nodes], "y": [(n, 0.0) for n in fixed_nodes]}
    for p in sidecar["resolved"]["prescribed_displacements"]:
        fixed[p["component"]].append((p["gmsh_node_tag"], float(p["value"])))
    loads = {}
    for f in sidecar["resolved"]["consistent_nodal_forces"]:
        v = loads.setdefault(f["gmsh_node_tag"], [0.0, 0.0])
        v[0 if f["component"] == "x" else 1] += float(f["force"])

    # --- the .mdpa ------------------------------------------------------------------------------
    out_dir.mkdir(parents=True, exist_ok=True)
    m = [f"// {case}: written by crosscheck/kratos_convert.py from {export_dir.name}/{case}.json",
         "Begin ModelPartData", "End ModelPartData", "",
         "Begin Properties 0", "End Properties"]
    for b in list(bodies.values()) + obstacles:
        # declared here for the elements; their values come from materials.json (Kratos warns
        # that it overwrites them)
        m += [f"Begin Properties {b['property']}", "End Properties"]
    m += ["", "Begin Nodes"]
    m += [f"  {i} {x!r} {y!r} 0.0" for i, (x, y) in nodes]
    m += ["End Nodes", ""]
    for name, rows in elements.items():
        m += [f"Begin Elements {name}"]
        m += [f"  {i} {p} " + " ".join(map(str, conn)) for i, p, conn, _ in rows]
        m += ["End Elements", ""]
    m += ["Begin Conditions LineCondition2D2N"]
    m += [f"  {i} {p} {a} {b}" for i, p, (a, b) in conditions]
    m += ["End Conditions", ""]
    load_ids = {}
    if loads:
        m += ["Begin Conditions PointLoadCondition2D1N"]
        for tag in sorted(loads):
            cid += 1
            load_ids[tag] = cid
            m += [f"  {cid} 0 {tag}"]
        m += ["End Conditions", "", "Begin ConditionalData POINT_LOAD"]
        m += [f"  {load_ids[t]} [3]({loads[t][0]!r},{loads[t][1]!r},0.0)" for t in sorted(loads)]
        m += ["End ConditionalData", ""]
    for comp in ("x", "y"):
        if fixed[comp]:
            m += [f"Begin NodalData DISPLACEMENT_{comp.upper()}"]
            m += [f"  {tag} 1 {v!r}" for tag, v in fixed[comp]]
            m += ["End NodalData", ""]

    def sub_model_part(name, node_ids, element_ids=(), condition_ids=()):
        m.append(f"Begin SubModelPart {name}")
        for block, ids in (("Nodes", node_ids), ("Elements", element_ids),
                           ("Conditions", condition_ids)):
            m.append(f"  Begin SubModelPart{block}")
            m.extend(f"    {i}" for i in ids)
            m.append(f"  End SubModelPart{block}")
        m.extend([f"End SubModelPart", ""])

    for bname, b in bodies.items():
        eids = [i for rows in elements.values() for i, _, _, owner in rows if owner == bname]
        sub_model_part(bname, b["nodes"], eids)
    for ob in obstacles:
        eids = [i for rows in elements.values() for i, _, _, owner in rows if owner == ob["name"]]
        sub_model_part(ob["name"], ob["nodes"], eids)
    if loads:
        sub_model_part("point_loads", sorted(loads), (), [load_ids[t] for t in sorted(loads)])
    cond_nodes = {i: conn for i, _, conn in conditions}
    for name, _, slave, master, _ in pair_parts:
        for part, ids in ((f"{name}_slave", slave), (f"{name}_master", master),
                          (name, slave + master)):
            ns = sorted({n for i in ids for n in cond_nodes[i]})
            sub_model_part(part, ns, (), ids)
    (out_dir / f"{case}.mdpa").write_text("\n".join(m) + "\n")

    # --- materials.json -----------------------------------------------------------------------
    law = {"strain": "LinearElasticPlaneStrain2DLaw", "stress": "LinearElasticPlaneStress2DLaw"}
    materials = {"properties": [{
        "model_part_name": f"Structure.{bname}",
        "properties_id": b["property"],
        "Material": {
            "constitutive_law": {"name": law[plane]},
            "Variables": {"YOUNG_MODULUS": b["E"], "POISSON_RATIO": b["nu"],
                          "THICKNESS": thickness, "DENSITY": 1.0},
            "Tables": {}}} for bname, b in list(bodies.items())
                          + [(ob["name"], ob) for ob in obstacles]]}
    (out_dir / "materials.json").write_text(json.dumps(materials, indent=2) + "\n")

    # --- ProjectParameters.json ---------------------------------------------------------------
    tied = pair_parts[0][1]
    if any(p[1] != tied for p in pair_parts):
        raise NotApplicable("tied and frictionless pairs in one case (one mortar_type per solve)")
    mortar_type = ("ComponentsMeshTying" if tied else
                   {"alm": "ALMContactFrictionless", "penalty": "PenaltyContactFrictionless"}[contact])
    keys = {str(k): [name] for k, (name, *_rest) in enumerate(pair_parts)}
    slaves = {str(k): [f"{name}_slave"] for k, (name, *_rest) in enumerate(pair_parts)}
    if tied:
        process = {
            "python_module": "mesh_tying_process",
            "kratos_module": "KratosMultiphysics.ContactStructuralMechanicsApplication",
            "process_name": "MeshTyingProcess",
            "Parameters": {"model_part_name": "Structure", "mesh_tying_model_part": keys,
                           "assume_master_slave": slaves, "variable_name": "DISPLACEMENT"}}
    else:
        params = {"model_part_name": "Structure", "contact_model_part": keys,
                  "assume_master_slave": slaves, "contact_type": "Frictionless"}
        k = pair_parts[0][4]
        if k is not None:
            # the penalty (pressure per unit gap) taken as given, not scaled by Kratos
            params["advance_ALM_parameters"] = {"manual_ALM": True, "penalty": k,
                                                "scale_factor": 1.0, "use_scale_factor": False}
        process = {
            "python_module": "alm_contact_process" if contact == "alm" else "penalty_contact_process",
            "kratos_module": "KratosMultiphysics.ContactStructuralMechanicsApplication",
            "process_name": "ALMContactProcess" if contact == "alm" else "PenaltyContactProcess",
            "Parameters": params}
    project = {
        "problem_data": {"problem_name": case, "parallel_type": "OpenMP",
                         "start_time": 0.0, "end_time": 1.0, "echo_level": 0},
        "solver_settings": {
            "model_part_name": "Structure",
            "domain_size": 2,
            "solver_type": "Static",
            "analysis_type": "non_linear",  # contact is: Newton on the active set
            "echo_level": 0,
            "model_import_settings": {"input_type": "mdpa", "input_filename": case},
            "material_import_settings": {"materials_filename": "materials.json"},
            "contact_settings": {"mortar_type": mortar_type},
            "time_stepping": {"time_step": 1.0},
            "compute_reactions": False,
            "convergence_criterion": "contact_residual_criterion",
            # tight: the catalogue judges to 1e-10, so Newton must not stop at Kratos' defaults
            # (relative only: an absolute 1e-14 stopped the Hertz ALM at a relative 1e-9)
            "displacement_relative_tolerance": 1e-13,
            "displacement_absolute_tolerance": 0.0,
            "residual_relative_tolerance": 1e-13,
            "residual_absolute_tolerance": 0.0,
            # Kratos' default tangent of the mortar contact omits the normals' derivatives: on a
            # curved surface (Hertz) Newton then converges linearly (measured: about 0.76 per
            # iteration), and with the derivatives ("normal_variation") it diverged there
            "max_iteration": 100,
            # Eigen's sparse LU (LinearSolversApplication): the same solution as the skyline LU,
            # half the time on the Hertz mesh
            "linear_solver_settings": {"solver_type": "LinearSolversApplication.sparse_lu"},
        },
        "processes": {"constraints_process_list": [], "loads_process_list": [],
                      "contact_process_list": [process]},
        "output_processes": {},
    }
    (out_dir / "ProjectParameters.json").write_text(json.dumps(project, indent=2) + "\n")

    # --- bodies.json: for writing results per body ---------------------------------------------
    meta = {"case": case, "contact": contact, "mortar_type": mortar_type,
            "thickness": thickness,
            "pairs": [{"name": n, "tied": t, "slave": f"{n}_slave", "master": f"{n}_master",
                       "kappa": k, "slave_facets": [cond_nodes[i] for i in slave]}
                      for n, t, slave, _, k in pair_parts],
            "bodies": [{"name": bname, "nodes": b["nodes"], "points": b["points"],
                        "cells": b["cells"]} for bname, b in bodies.items()]}
    (out_dir / "bodies.json").write_text(json.dumps(meta) + "\n")
    return mortar_type


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("export", help="EXPORT/<case>: the folder contact-patch export wrote")
    ap.add_argument("out", help="folder for the Kratos input")
    ap.add_argument("--contact", choices=["alm", "penalty"], default="alm")
    ap.add_argument("--kappa", type=float, help="penalty (pressure per unit gap)")
    a = ap.parse_args(argv)
    try:
        mortar = convert(a.export, a.out, a.contact, a.kappa)
    except NotApplicable as e:
        print(f"n/a: {e}", file=sys.stderr)
        return 3
    except (OSError, KeyError, ValueError) as e:
        print(f"kratos_convert: {a.export}: {e!r}", file=sys.stderr)
        return 2
    print(f"{a.out}: {mortar}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
