"""Write the mesh of the case channelRebound: a box of hexahedra in Gmsh's 2.2 ASCII format.

    python make_mesh.py OUT.msh

The channel runs along x from 0 to 0.1 m, 0.02 m by 0.02 m in y and z, in 30 × 6 × 6 cells. Boundary
groups (Gmsh physical names, which code_saturne's preprocessor makes face groups): "inlet" (x = 0, where
the particles come in and leave), "target" (x = 0.1 m, the wall they are shot at) and "walls" (the four
sides); the cells are group "fluid".

Copyright (C) 2026 the rebound-scatter authors. License: GPL-2.0-or-later
(see integrations/code_saturne/LICENSE).
"""

import sys
from pathlib import Path

LENGTH, WIDTH = 0.1, 0.02          # m
NX, NY, NZ = 30, 6, 6              # cells
GROUPS = {"inlet": 1, "target": 2, "walls": 3, "fluid": 4}


def mesh_text(nx: int = NX, ny: int = NY, nz: int = NZ) -> str:
    def node(i, j, k):
        return 1 + i + (nx + 1) * (j + (ny + 1) * k)

    lines = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$PhysicalNames", str(len(GROUPS))]
    lines += [f'{3 if name == "fluid" else 2} {tag} "{name}"' for name, tag in GROUPS.items()]
    lines += ["$EndPhysicalNames", "$Nodes", str((nx + 1) * (ny + 1) * (nz + 1))]
    for k in range(nz + 1):
        for j in range(ny + 1):
            for i in range(nx + 1):
                lines.append(f"{node(i, j, k)} {LENGTH * i / nx!r} {WIDTH * j / ny!r} {WIDTH * k / nz!r}")
    lines.append("$EndNodes")

    elements = []   # (gmsh type, group, nodes): 3 a quadrangle, 5 a hexahedron
    for i, group in ((0, "inlet"), (nx, "target")):
        elements += [(3, group, [node(i, j, k), node(i, j + 1, k), node(i, j + 1, k + 1), node(i, j, k + 1)])
                     for j in range(ny) for k in range(nz)]
    for j in (0, ny):
        elements += [(3, "walls", [node(i, j, k), node(i + 1, j, k), node(i + 1, j, k + 1), node(i, j, k + 1)])
                     for i in range(nx) for k in range(nz)]
    for k in (0, nz):
        elements += [(3, "walls", [node(i, j, k), node(i + 1, j, k), node(i + 1, j + 1, k), node(i, j + 1, k)])
                     for i in range(nx) for j in range(ny)]
    elements += [(5, "fluid", [node(i, j, k), node(i + 1, j, k), node(i + 1, j + 1, k), node(i, j + 1, k),
                               node(i, j, k + 1), node(i + 1, j, k + 1), node(i + 1, j + 1, k + 1),
                               node(i, j + 1, k + 1)])
                 for k in range(nz) for j in range(ny) for i in range(nx)]
    lines += ["$Elements", str(len(elements))]
    for e, (kind, group, nodes) in enumerate(elements, start=1):
        lines.append(f"{e} {kind} 2 {GROUPS[group]} {GROUPS[group]} " + " ".join(map(str, nodes)))
    lines.append("$EndElements")
    return "\n".join(lines) + "\n"


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 1:
        print("usage: python make_mesh.py OUT.msh", file=sys.stderr)
        return 2
    Path(argv[0]).write_text(mesh_text())
    return 0


if __name__ == "__main__":
    sys.exit(main())
