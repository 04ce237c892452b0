"""Writes the 3D Gmsh meshes of the cases in this folder with the `gmsh` Python package (PyPI,
`pip install gmsh`; these files were written with gmsh 4.15.2):

  patch-tet4.msh    MSH 4.1 ASCII   the box [0, 1] x [0, 0.8] x [0, 1.2], unstructured
                                    4-node tetrahedra (size 0.3)
  patch-tet10.msh   MSH 2.2 ASCII   the same box, 10-node tetrahedra
  patch-hex8.msh    MSH 4.1 binary  the same box, unstructured 8-node hexahedra (tetrahedra
                                    of size 0.5, each split in four by Gmsh's subdivision)
  patch-hex27.msh   MSH 4.1 binary  the same box, 27-node hexahedra
  punch-on-foundation.msh
                    MSH 4.1 binary  two bodies that do not share nodes: a foundation
                                    [0, 1]^2 x [0, 1] of unstructured 4-node tetrahedra
                                    (size 0.3) and a punch [0, 1]^2 x [1, 1.5] of 8-node
                                    hexahedra on a 4 x 4 x 2 grid, so the interface does not
                                    match
  hertz-sphere-h*.msh
                    MSH 4.1 binary  a quarter of the lower half of a sphere of radius 10
                                    (x >= 0, y >= 0, z <= 10, centre (0, 0, 10)) touching the
                                    plane z = 0 at the origin, 4-node tetrahedra of size h
                                    (0.4, 0.2, 0.1) within 1.5 of the origin, growing to 2.5
                                    at distance 8

Physical groups. The patch box: the volume "block", its faces "base" (z = 0) and "lid"
(z = 1.2), its corners "origin" (0, 0, 0) and "x_end" (1, 0, 0). The two bodies: volumes
"foundation" and "punch"; the foundation's faces "foundation_base" (z = 0), "foundation_top"
(z = 1), "foundation_x0" (x = 0), "foundation_y0" (y = 0); the punch's "punch_bottom" (z = 1),
"punch_lid" (z = 1.5), "punch_x0", "punch_y0". The sphere: the volume "sphere", its curved
face "surface", its flat face "flat" (z = 10) and the symmetry planes "sym_x0" (x = 0) and
"sym_y0" (y = 0). (The names avoid the built-in sets left, right, front, back, bottom, top.)

Run from this folder: python3 make_meshes.py
"""

import gmsh

BOX = (1.0, 0.8, 1.2)


def start(name):
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.model.add(name)


def save(name, version, binary):
    gmsh.option.setNumber("Mesh.MshFileVersion", version)
    gmsh.option.setNumber("Mesh.Binary", 1 if binary else 0)
    gmsh.write(name + ".msh")
    gmsh.finalize()


def faces_at(volume, axis, value):
    """The faces of `volume` on the plane coordinate `axis` = `value` (OCC pads the bounding
    boxes by its tolerance, 1e-7)."""
    found = []
    for dim, tag in gmsh.model.getBoundary([(3, volume)], oriented=False):
        lo = gmsh.model.getBoundingBox(dim, tag)
        if abs(lo[axis] - value) < 1e-6 and abs(lo[axis + 3] - value) < 1e-6:
            found.append(tag)
    return found


def point_at(x, y, z):
    """The geometric point at (x, y, z)."""
    for _, tag in gmsh.model.getEntities(0):
        if max(abs(a - b) for a, b in zip(gmsh.model.getValue(0, tag, []), (x, y, z))) < 1e-9:
            return tag
    raise ValueError(f"no point at {(x, y, z)}")


def patch(name, order, hexahedra, version, binary):
    start(name)
    occ = gmsh.model.occ
    block = occ.addBox(0.0, 0.0, 0.0, *BOX)
    occ.synchronize()
    gmsh.model.addPhysicalGroup(3, [block], name="block")
    gmsh.model.addPhysicalGroup(2, faces_at(block, 2, 0.0), name="base")
    gmsh.model.addPhysicalGroup(2, faces_at(block, 2, BOX[2]), name="lid")
    gmsh.model.addPhysicalGroup(0, [point_at(0.0, 0.0, 0.0)], name="origin")
    gmsh.model.addPhysicalGroup(0, [point_at(BOX[0], 0.0, 0.0)], name="x_end")
    size = 0.5 if hexahedra else 0.3
    gmsh.option.setNumber("Mesh.MeshSizeMax", size)
    gmsh.option.setNumber("Mesh.MeshSizeMin", size)
    if hexahedra:
        gmsh.option.setNumber("Mesh.SubdivisionAlgorithm", 2)
    gmsh.model.mesh.generate(3)
    if order > 1:
        gmsh.option.setNumber("Mesh.SecondOrderIncomplete", 0)
        gmsh.model.mesh.setOrder(order)
    save(name, version, binary)


def punch_on_foundation(name):
    start(name)
    occ = gmsh.model.occ
    foundation = occ.addBox(0.0, 0.0, 0.0, 1.0, 1.0, 1.0)
    punch = occ.addBox(0.0, 0.0, 1.0, 1.0, 1.0, 0.5)
    occ.synchronize()
    for body, volume, bottom, top in [
        ("foundation", foundation, 0.0, 1.0),
        ("punch", punch, 1.0, 1.5),
    ]:
        gmsh.model.addPhysicalGroup(3, [volume], name=body)
        low, high = ("base", "top") if body == "foundation" else ("bottom", "lid")
        gmsh.model.addPhysicalGroup(2, faces_at(volume, 2, bottom), name=f"{body}_{low}")
        gmsh.model.addPhysicalGroup(2, faces_at(volume, 2, top), name=f"{body}_{high}")
        gmsh.model.addPhysicalGroup(2, faces_at(volume, 0, 0.0), name=f"{body}_x0")
        gmsh.model.addPhysicalGroup(2, faces_at(volume, 1, 0.0), name=f"{body}_y0")
    # the punch: a transfinite 4 x 4 x 2 grid of hexahedra; the foundation: tetrahedra
    mesh = gmsh.model.mesh
    for dim, tag in gmsh.model.getBoundary([(3, punch)], combined=False, oriented=False,
                                            recursive=True):
        if dim == 1:
            lo = gmsh.model.getBoundingBox(1, tag)
            vertical = abs(lo[5] - lo[2]) > 1e-3
            mesh.setTransfiniteCurve(tag, 3 if vertical else 5)
    for _, tag in gmsh.model.getBoundary([(3, punch)], oriented=False):
        mesh.setTransfiniteSurface(tag)
        mesh.setRecombine(2, tag)
    mesh.setTransfiniteVolume(punch)
    mesh.setRecombine(3, punch)
    gmsh.option.setNumber("Mesh.MeshSizeMax", 0.3)
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.3)
    mesh.generate(3)
    save(name, 4.1, True)


def hertz_sphere(name, h):
    start(name)
    occ = gmsh.model.occ
    radius = 10.0
    ball = occ.addSphere(0.0, 0.0, radius, radius)
    box = occ.addBox(0.0, 0.0, 0.0, radius, radius, radius)
    (quarter,), _ = occ.intersect([(3, ball)], [(3, box)])
    occ.synchronize()
    volume = quarter[1]
    gmsh.model.addPhysicalGroup(3, [volume], name="sphere")
    flat = faces_at(volume, 2, radius)
    sym_x = faces_at(volume, 0, 0.0)
    sym_y = faces_at(volume, 1, 0.0)
    curved = [
        t
        for _, t in gmsh.model.getBoundary([(3, volume)], oriented=False)
        if t not in flat + sym_x + sym_y
    ]
    gmsh.model.addPhysicalGroup(2, curved, name="surface")
    gmsh.model.addPhysicalGroup(2, flat, name="flat")
    gmsh.model.addPhysicalGroup(2, sym_x, name="sym_x0")
    gmsh.model.addPhysicalGroup(2, sym_y, name="sym_y0")
    # size h within 1.5 of the contact point (0, 0, 0), growing to 2.5 at distance 8
    pole = point_at(0.0, 0.0, 0.0)
    field = gmsh.model.mesh.field
    distance = field.add("Distance")
    field.setNumbers(distance, "PointsList", [pole])
    threshold = field.add("Threshold")
    field.setNumber(threshold, "InField", distance)
    field.setNumber(threshold, "SizeMin", h)
    field.setNumber(threshold, "SizeMax", 2.5)
    field.setNumber(threshold, "DistMin", 1.5)
    field.setNumber(threshold, "DistMax", 8.0)
    field.setAsBackgroundMesh(threshold)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.model.mesh.generate(3)
    save(name, 4.1, True)


if __name__ == "__main__":
    patch("patch-tet4", 1, False, 4.1, False)
    patch("patch-tet10", 2, False, 2.2, False)
    patch("patch-hex8", 1, True, 4.1, True)
    patch("patch-hex27", 2, True, 4.1, True)
    punch_on_foundation("punch-on-foundation")
    for h, label in [(0.4, "0.4"), (0.2, "0.2"), (0.1, "0.1")]:
        hertz_sphere(f"hertz-sphere-h{label}", h)
