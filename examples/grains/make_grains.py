"""Write a small population of irregular convex grains as OBJ meshes, reproducibly (docs/model.md §9).

Each grain is the convex hull of a random cloud of points: a Gaussian cloud stretched along three random axes
(proportions drawn per grain) and turned at random, in millimetres, about the size of a sand grain. The same
seed writes the same files. Needs the build extra (scipy, for the hull).

    python examples/grains/make_grains.py                 # rewrites the grain_*.obj files beside this script
    python examples/grains/make_grains.py --out my_grains --count 12 --seed 7
"""

import argparse
from pathlib import Path

import numpy as np
from scipy.spatial import ConvexHull

SEED = 20261121
COUNT = 6
POINTS = (40, 80, 160, 320, 640, 1280)          # cloud sizes, cycled: more points, more hull vertices (15 to 37 here)
SIZE_MM = 0.3                                    # the clouds' spread along their longest axis, mm
DIGITS = 6                                       # decimals written (a micrometre's thousandth): small, exact files


def random_grain(rng, n_points):
    """Vertices (k, 3) in mm and outward triangles (m, 3) of the hull of one random cloud."""
    proportions = np.sort(rng.uniform(0.45, 1.0, size=3))[::-1]
    q = rng.normal(size=4)
    w, x, y, z = q / np.linalg.norm(q)           # a uniformly random rotation (normalised Gaussian quaternion)
    turn = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    cloud = np.round(SIZE_MM * (rng.normal(size=(n_points, 3)) * proportions) @ turn.T, DIGITS)
    hull = ConvexHull(cloud)
    triangles = hull.simplices.copy()
    p = cloud[triangles]
    inward = (np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]) * hull.equations[:, :3]).sum(axis=1) < 0
    triangles[inward] = triangles[inward][:, ::-1]
    used = np.unique(triangles)
    index = np.full(len(cloud), -1)
    index[used] = np.arange(len(used))
    return cloud[used], index[triangles]


def obj_text(vertices, triangles, name):
    """An OBJ mesh: one 'v x y z' line per vertex (mm), one 'f i j k' per triangle (1-based, outward)."""
    lines = [f"# {name}: convex hull of a random point cloud, mm (examples/grains/make_grains.py)", f"o {name}"]
    lines += [f"v {x:.{DIGITS}f} {y:.{DIGITS}f} {z:.{DIGITS}f}" for x, y, z in vertices]
    lines += [f"f {i + 1} {j + 1} {k + 1}" for i, j, k in triangles]
    return "\n".join(lines) + "\n"


def write_grains(folder, count=COUNT, seed=SEED):
    """Write grain_1.obj ... grain_<count>.obj into ``folder``; return their paths."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    paths = []
    for k in range(count):
        name = f"grain_{k + 1}"
        vertices, triangles = random_grain(rng, POINTS[k % len(POINTS)])
        path = folder / f"{name}.obj"
        path.write_text(obj_text(vertices, triangles, name))
        paths.append(path)
    return paths


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=Path(__file__).resolve().parent, type=Path, help="output folder")
    parser.add_argument("--count", default=COUNT, type=int, help="number of grains")
    parser.add_argument("--seed", default=SEED, type=int, help="seed of the point clouds")
    args = parser.parse_args(argv)
    for path in write_grains(args.out, args.count, args.seed):
        print(path)


if __name__ == "__main__":
    main()
