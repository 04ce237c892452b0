#!/usr/bin/env python3
"""Writes hertz-profile.json: the block-on-rigid-cylinder case (Lagrange multipliers) on a
graded Q4 mesh, spacing 0.02 over |x| <= 0.8 and y <= 0.4, growing by 1.15 per element outside;
and hertz-profile-standard-mortar.json, hertz-profile-dual-mortar.json: the same with mortar
rows (standard and dual multipliers) against the rigid circle.
Run from this folder: python3 make_hertz_profile.py"""
import json


def graded(fine_to, h, end, growth=1.15):
    xs = [0.0]
    while xs[-1] < fine_to - 1e-12:
        xs.append(round(xs[-1] + h, 10))
    step = h
    while xs[-1] < end - 1e-12:
        step *= growth
        nxt = xs[-1] + step
        if end - nxt < 0.5 * growth * step:
            nxt = end
        xs.append(round(min(nxt, end), 10))
    return xs


half = graded(0.8, 0.02, 4.0)
case = json.load(open("block-on-rigid-cylinder-lagrange.json"))
case["name"] = "hertz-profile"
case["description"] = (
    "Hertz's cylinder on a graded mesh, for the pressure profile: a block (width 8, height 4, "
    "Q4, spacing 0.02 over |x| <= 0.8 and y <= 0.4, growing by 1.15 per element outside; "
    "written by make_hertz_profile.py) pressed by a uniform pressure 0.5 on its top (P = 4 per "
    "unit thickness) onto a rigid cylinder of radius R = 10 touching its bottom at x = 0. "
    "Hertz (half-space, plane strain, rigid indenter): a = sqrt(4 P R/(pi E*)) = 0.48138, "
    "E* = E/(1 - nu^2), p(x) = p0 sqrt(1 - x^2/a^2), p0 = 2P/(pi a) = 5.2899. "
    "`contact-patch profile cases/contact/hertz-profile.json --pair cylinder` plots the nodal "
    "pressures (the pressure column of cylinder.contact.csv) against p(x); "
    "tests/contact_results.rs compares them."
)
block = case["bodies"][0]["mesh"]["block"]
block["x"] = [-v for v in reversed(half[1:])] + half
block["y"] = graded(0.4, 0.02, 4.0)
out = {"$schema": "../case.schema.json"}
out.update(case)
with open("hertz-profile.json", "w") as f:
    json.dump(out, f, indent=2)
    f.write("\n")

for multiplier in ["standard", "dual"]:
    name = f"hertz-profile-{multiplier}-mortar"
    variant = json.loads(json.dumps(out))
    variant["name"] = name
    variant["description"] = (
        out["description"]
        .replace(
            "Hertz's cylinder on a graded mesh, for the pressure profile:",
            f"Hertz's cylinder on a graded mesh with {multiplier} mortar against the rigid circle "
            f"(the circle's exact radial gap weighted by the {multiplier} multipliers, no master "
            "dofs):",
        )
        .replace("profile cases/contact/hertz-profile.json", f"profile cases/contact/{name}.json")
        .replace("tests/contact_results.rs compares them.", "tests/rigid_mortar.rs compares them.")
    )
    variant["contact"][0]["discretization"] = {"kind": "mortar", "multiplier": multiplier}
    with open(f"{name}.json", "w") as f:
        json.dump(variant, f, indent=2)
        f.write("\n")
