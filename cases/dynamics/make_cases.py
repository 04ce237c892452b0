#!/usr/bin/env python3
"""Writes the dynamic impact cases of benchmarks.md section 6 (1D wave solutions, c = sqrt(E/rho)).

A 2D strip with nu = 0 whose every node has u_y = 0 (rollers) is exactly 1D. Run from this folder:
python3 make_cases.py. The exact values each case is judged against are in its description and in
tests/dynamics.rs; `contact-patch impact-report` runs every treatment and mass on them."""
import json

def strip(name, material, x0, x1, nx, h=0.1, element="Q4"):
    return {"name": name, "material": material,
            "mesh": {"block": {"element": element, "x": {"from": x0, "to": x1, "divisions": nx},
                               "y": {"from": 0.0, "to": h, "divisions": 1}}}}

def case(name, description, materials, bodies, contact, velocity, dt, end, enforcement):
    return {
        "$schema": "../case.schema.json",
        "name": name,
        "description": description,
        "analysis": {"plane": "strain", "thickness": 1.0},
        "materials": materials,
        "bodies": bodies,
        "supports": [{"body": b["name"], "set": "all", "y": 0.0} for b in bodies],
        "physics": {"dynamics": {"integrator": "average_acceleration", "dt": dt, "end_time": end,
                                 "mass": "lumped", "impact": "plain",
                                 "initial_velocity": velocity}},
        "contact": [dict(c, enforcement=enforcement) for c in contact],
        "solver": {"scheme": "newton"},
        # at end_time (twice the contact duration) the bars have separated: no contact force
        # is left, and Lagrange multipliers never let a node penetrate
        "checks": [
            {"check": "contact_force", "pair": contact[0]["name"], "component": "x",
             "value": 0.0, "tol": 1e-12},
            {"check": "max_penetration", "share": 1e-12},
        ],
    }

def write(c):
    with open(c["name"] + ".json", "w") as f:
        json.dump(c, f, indent=2)
        f.write("\n")

lagrange = {"kind": "lagrange"}
# bar on a rigid wall: L = 1, E = 100, rho = 1 (c = 10), v0 = 0.01, touching the wall at t = 0
write(case("bar-on-rigid-wall",
           "A bar (L = 1, height 0.1, Q4 20 x 1, nu = 0, u_y = 0: exactly 1D; E = 100, rho = 1, c = 10) moving at v0 = 0.01 touches a rigid wall at x = 1 at t = 0. Exact: contact stress rho c v0 = 0.1 for 0 < t < 2L/c = 0.2, then the bar leaves with -v0. dt = h/c = 0.005 (Courant number 1).",
           {"bar": {"E": 100.0, "nu": 0.0, "density": 1.0}},
           [strip("bar", "bar", 0.0, 1.0, 20)],
           [{"name": "wall", "slave": {"body": "bar", "set": "right"},
             "master": {"rigid": {"kind": "line", "point": [1.0, 0.0], "normal": [-1.0, 0.0]}},
             "discretization": {"kind": "node_to_surface", "passes": 1}}],
           [{"body": "bar", "velocity": [0.01, 0.0]}], 0.005, 0.4, lagrange))
# two identical bars: striker [0, 1] at v0, target [1, 2] at rest, node to node
write(case("two-identical-bars",
           "Two identical bars (L = 1 each, Q4 20 x 1, nu = 0, u_y = 0; E = 100, rho = 1, c = 10): the striker [0, 1] at v0 = 0.01 touches the target [1, 2] at rest at t = 0. Exact: contact stress rho c v0 / 2 = 0.05 for 0 < t < 2L/c = 0.2; then the striker is at rest and the target moves at v0.",
           {"bar": {"E": 100.0, "nu": 0.0, "density": 1.0}},
           [strip("striker", "bar", 0.0, 1.0, 20), strip("target", "bar", 1.0, 2.0, 20)],
           [{"name": "interface", "slave": {"body": "striker", "set": "right"},
             "master": {"body": "target", "set": "left"},
             "discretization": {"kind": "node_to_node"}}],
           [{"body": "striker", "velocity": [0.01, 0.0]}], 0.005, 0.4, lagrange))
# bars of different impedance with L1/c1 = L2/c2: striker E = 100, rho = 1 (c = 10, Z = 10),
# L = 1; target E = 400, rho = 4 (c = 10, Z = 40), L = 1: v* = Z1 v1 / (Z1 + Z2) = 0.2 v1
write(case("two-bars-different-impedance",
           "Striker [0, 1] (E = 100, rho = 1: c = 10, Z = 10) at v1 = 0.01 touches the target [1, 2] (E = 400, rho = 4: c = 10, Z = 40) at rest at t = 0; both Q4 20 x 1, nu = 0, u_y = 0, L1/c1 = L2/c2. Exact (benchmarks.md 6): the interface moves at v* = (Z1 v1 + Z2 v2)/(Z1 + Z2) = 0.002, contact stress Z1 Z2 (v1 - v2)/(Z1 + Z2) = 0.08 for 0 < t < 0.2; after separation the striker moves at v1 (Z1 - Z2)/(Z1 + Z2) = -0.006 and the target at 2 Z1 v1/(Z1 + Z2) = 0.004 (momentum and energy conserved).",
           {"soft": {"E": 100.0, "nu": 0.0, "density": 1.0},
            "stiff": {"E": 400.0, "nu": 0.0, "density": 4.0}},
           [strip("striker", "soft", 0.0, 1.0, 20), strip("target", "stiff", 1.0, 2.0, 20)],
           [{"name": "interface", "slave": {"body": "striker", "set": "right"},
             "master": {"body": "target", "set": "left"},
             "discretization": {"kind": "node_to_node"}}],
           [{"body": "striker", "velocity": [0.01, 0.0]}], 0.005, 0.4, lagrange))

# a 2D elastic block dropped on an elastic foundation (benchmarks.md section 6, issue 11): no
# closed form; judged on no energy gain and the release time under time-step refinement
# (tests/dynamics.rs). Block [0.5, 1.5] x [1, 2] at v = (0, -0.01) touches the foundation
# [0, 2] x [0, 1] (bottom clamped) at t = 0; both E = 100, nu = 0.3, rho = 1, plane strain:
# c_p = sqrt(E (1 - nu) / ((1 + nu)(1 - 2 nu) rho)) = 11.60; the 1D estimate of the contact
# time of the block alone is 2 H / c_p = 0.172 (the foundation's compliance lengthens it).
def block_drop(name, discretization, rigid=False):
    block = {"name": "block", "material": "m",
             "mesh": {"block": {"element": "Q4", "x": {"from": 0.5, "to": 1.5, "divisions": 8},
                                "y": {"from": 1.0, "to": 2.0, "divisions": 8}}}}
    foundation = {"name": "foundation", "material": "m",
                  "mesh": {"block": {"element": "Q4", "x": {"from": 0.0, "to": 2.0, "divisions": 16},
                                     "y": {"from": 0.0, "to": 1.0, "divisions": 8}}}}
    if rigid:
        bodies, supports = [block], []
        master = {"rigid": {"kind": "line", "point": [1.0, 1.0], "normal": [0.0, 1.0]}}
        where = "a rigid foundation (the line y = 1)"
    else:
        bodies = [block, foundation]
        supports = [{"body": "foundation", "set": "bottom", "x": 0.0, "y": 0.0}]
        master = {"body": "foundation", "set": "top"}
        where = "an elastic foundation [0, 2] x [0, 1] (Q4 16 x 8, bottom clamped)"
    return {
        "$schema": "../case.schema.json",
        "name": name,
        "description": f"A block [0.5, 1.5] x [1, 2] (Q4 8 x 8) moving at v = (0, -0.01) touches {where} at t = 0; E = 100, nu = 0.3, rho = 1, plane strain (c_p = 11.60, 2 H / c_p = 0.172). {discretization['kind']} contact, Lagrange multipliers, the seed's post-impact correction, dt = 0.01 (about h / c_p). No closed form: tests/dynamics.rs checks that the energy never grows and that the release time converges as dt is halved; reports/block-drop.md shows the contact force history.",
        "analysis": {"plane": "strain", "thickness": 1.0},
        "materials": {"m": {"E": 100.0, "nu": 0.3, "density": 1.0}},
        "bodies": bodies,
        "supports": supports,
        "physics": {"dynamics": {"integrator": "average_acceleration", "dt": 0.01, "end_time": 0.5,
                                 "mass": "lumped", "impact": "post_impact",
                                 "initial_velocity": [{"body": "block", "velocity": [0.0, -0.01]}]}},
        "contact": [{"name": "drop", "slave": {"body": "block", "set": "bottom"},
                     "master": master, "discretization": discretization,
                     "enforcement": lagrange}],
        "solver": {"scheme": "newton"},
        # at end_time the block has left: no contact force is left, and Lagrange multipliers
        # let no node penetrate
        "checks": [
            {"check": "contact_force", "pair": "drop", "component": "y", "value": 0.0,
             "tol": 1e-12},
            {"check": "max_penetration", "share": 1e-12},
        ],
    }

write(block_drop("block-drop-node-to-surface", {"kind": "node_to_surface", "passes": 1}))
write(block_drop("block-drop-mortar", {"kind": "mortar"}))
write(block_drop("block-drop-rigid", {"kind": "node_to_surface", "passes": 1}, rigid=True))


def sliding_block(name, enforcement, interaction):
    """A block sliding on a rigid floor under a suddenly applied pressure, Coulomb friction."""
    how = ("Lagrange multipliers for the normal and the tangential force" if enforcement["kind"] == "lagrange"
           else f"penalty kappa = {enforcement['kappa']:g}, kappa_t = {interaction['coulomb']['kappa_t']:g}")
    return {
        "$schema": "../case.schema.json",
        "name": name,
        "description": "A block [0, 1] x [0, 1] (Q4 4 x 4, E = 100, nu = 0.3, rho = 1, plane strain) "
                       "resting on a rigid floor (the line y = 0) slides at v = (0.5, 0) under a "
                       "pressure p = 1 on its top applied at t = 0; Coulomb friction mu = 0.3 "
                       f"({how}), average acceleration, dt = 0.01 to t = 0.5, plain impact "
                       "treatment. Every closed point slips backwards against the motion, so "
                       "the friction force is -mu times the normal force at every step and "
                       "Newmark's momentum balance gives p_x(T) - p_x(0) = -mu (p_y(T) - p_y(0) + P T) "
                       "with P = 1 the total load (tests/dynamics.rs, to round-off); the block "
                       "slows from p_x = 0.5 to about 0.357 (a rigid block would reach "
                       "0.5 - mu P T = 0.35) and the friction moment lifts its trailing edge.",
        "analysis": {"plane": "strain", "thickness": 1.0},
        "materials": {"m": {"E": 100.0, "nu": 0.3, "density": 1.0}},
        "bodies": [{"name": "block", "material": "m",
                    "mesh": {"block": {"element": "Q4", "x": {"from": 0.0, "to": 1.0, "divisions": 4},
                                       "y": {"from": 0.0, "to": 1.0, "divisions": 4}}}}],
        "supports": [],
        "loads": [{"body": "block", "set": "top", "pressure": 1.0}],
        "physics": {"dynamics": {"integrator": "average_acceleration", "dt": 0.01, "end_time": 0.5,
                                 "mass": "lumped", "impact": "plain",
                                 "initial_velocity": [{"body": "block", "velocity": [0.5, 0.0]}]}},
        "contact": [{"name": "floor", "slave": {"body": "block", "set": "bottom"},
                     "master": {"rigid": {"kind": "line", "point": [0.0, 0.0], "normal": [0.0, 1.0]}},
                     "discretization": {"kind": "node_to_surface", "passes": 1},
                     "enforcement": enforcement, "interaction": interaction}],
        "solver": {"scheme": "newton"},
        # dynamic equilibrium K d - f - B^T lambda - T^T lambda_t + M a = 0 at the last step;
        # Lagrange multipliers let no node penetrate, the penalty lets it by about N / kappa
        "checks": [{"check": "equilibrium", "tol": 1e-11},
                   {"check": "max_penetration",
                    "share": 1e-12 if enforcement["kind"] == "lagrange" else 1e-4}],
    }

write(sliding_block("sliding-block-friction-lagrange", {"kind": "lagrange"}, {"coulomb": {"mu": 0.3}}))
write(sliding_block("sliding-block-friction-penalty", {"kind": "penalty", "kappa": 1e5},
                    {"coulomb": {"mu": 0.3, "kappa_t": 1e5}}))
