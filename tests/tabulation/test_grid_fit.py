"""`tablegen grid` (tablegen.tabulation.grid_fit): hits drawn from known laws of α1 and |V⁻| give a grid whose ranges
hold the share asked of the law, within the binomial scatter of n hits; the counts follow the default preset's density;
the [grid] section written reads back through the configuration reader; OpenFOAM's patchPostProcessing records
read with the normals of the case's mesh (ASCII or binary, serial or decomposed) or of --normal; every user error is
one line and exit 2 with nothing written."""

import functools
import gzip
import math

import numpy as np
import pytest

from tablegen import build_table
from tablegen.cli import main
from tablegen.study.hit_records import HIT_COLUMNS
from tablegen.tabulation import grid_fit
from tablegen.tabulation.config import load_config, parse_config, preset_text
from tests.helpers.cli import run_cli, user_error
from tests.helpers.tables import written_out_config

_run = functools.partial(run_cli, main)
_user_error = functools.partial(user_error, main)

SETTINGS = ("seed 7, stream 0, table /x/t.h5, mix prism, halfSizeFactor 1, interpolation scaled, method auto, "
            "spin tolerance 0.001, grain kept (key seed 7)")
OPENFOAM_TITLE = "stochasticRebound"
SATURNE_TITLE = "code_saturne rebound-scatter"
# the hits' law: α1 uniform on [ALPHA1_LOW, 90] deg, |V⁻| log-normal of median SPEED_MEDIAN m/s and log-sd
# SPEED_SIGMA (0.2 to 2 m/s at its 1 and 99 %: the case of a user whose table started at 50 m/s)
ALPHA1_LOW, SPEED_MEDIAN, SPEED_SIGMA = 0.5, 0.63, 0.5


def _unit(v):
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _incident(alpha1, speed, n, rng):
    """V⁻ (N, 3) m/s of incidence α1 (deg) and |V⁻| on walls of unit normals n (N, 3) into the gas, each in a
    random direction along its wall."""
    t = _unit(np.cross(n, rng.standard_normal(n.shape)))
    a = np.radians(alpha1)[:, None]
    return speed[:, None] * (np.cos(a) * t - np.sin(a) * n)


def _law_hits(n_hits, seed):
    """(α1 deg, |V⁻| m/s, V⁻, n) of ``n_hits`` hits of the known law on walls facing random ways."""
    rng = np.random.default_rng(seed)
    alpha1 = rng.uniform(ALPHA1_LOW, 90.0, n_hits)
    speed = SPEED_MEDIAN * np.exp(SPEED_SIGMA * rng.standard_normal(n_hits))
    n = _unit(rng.standard_normal((n_hits, 3)))
    return alpha1, speed, _incident(alpha1, speed, n, rng), n


def _law_share(alpha1_range, speed_range):
    """The share of the known law inside a grid's ranges (α1 deg, |V⁻| m/s):
    P(α1 >= low) P(low <= |V⁻| <= high)."""
    def phi(x):
        return 0.5 * (1.0 + math.erf((math.log(x) - math.log(SPEED_MEDIAN)) / (SPEED_SIGMA * math.sqrt(2.0))))
    a = min(max(alpha1_range[0], ALPHA1_LOW), 90.0)
    return (90.0 - a) / (90.0 - ALPHA1_LOW) * (phi(speed_range[1]) - phi(speed_range[0]))


def _hits_file(path, V, n, title=OPENFOAM_TITLE, patch="walls", spin_ratio=0.0):
    """An adapter's hits file (hit_records' layout, HIT_COLUMNS) of hits V⁻ (N, 3) on normals n (N, 3)."""
    lines = [f"# {title} hits: {SETTINGS}\n", "# columns\n", ",".join(HIT_COLUMNS) + "\n"]
    for i, (v, m) in enumerate(zip(V, n)):
        row = dict.fromkeys(HIT_COLUMNS, "0")
        row.update(patch=patch, origId=str(i), d="2e-4", a="1e-4", spin_ratio=repr(spin_ratio), key="-1", shape="",
                   ratio_ba="nan", ratio_cb="nan", hand="nan", interaction=OPENFOAM_TITLE, wall="")
        row.update({f"V{c}": repr(float(x)) for c, x in zip("xyz", v)})
        row.update({f"n{c}": repr(float(x)) for c, x in zip("xyz", m)})
        lines.append(",".join(row[c] for c in HIT_COLUMNS) + "\n")
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("".join(lines))
    return path


# ------------------------------------------------------------------------------------------- the share covered

# Why these tolerances. The ranges end at order statistics of n hits, chosen so that at least the share `cover` of
# the sample lies inside (and, k being the largest such trim, at most a few hits more: the next trim drops at most
# 3 hits, one per tail, so the sample's share is below cover + 3/n). The law's share of ranges cut at order
# statistics scatters about the sample's share as a binomial proportion does: sd = sqrt(c (1 - c) / n) (for one tail,
# exactly: the law's share beyond the k-th order statistic is Beta(k, n + 1 - k)). So the law's share lies within
# 4 sd + 3/n of cover (a miss once in 16 000 draws for a fixed seed's sample: the seeds below are fixed).
N_HITS = 20_000


def _tolerance(cover, n=N_HITS):
    return 4.0 * math.sqrt(cover * (1.0 - cover) / n) + 3.0 / n


@pytest.mark.parametrize("cover", [0.9, 0.99])
def test_the_ranges_hold_the_share_asked_of_the_hits_law(cover):
    alpha1, speed, V, n = _law_hits(N_HITS, seed=int(cover * 1000))
    got_alpha1, got_speed, into = grid_fit.incidence(V, n)
    assert into.all()
    np.testing.assert_allclose(got_alpha1, alpha1, atol=1e-9)     # the frame-free incidence of the drawn hits
    np.testing.assert_allclose(got_speed, speed, rtol=1e-12)
    a_range, v_range = grid_fit.fit_ranges(got_alpha1, got_speed, cover)
    sample = np.mean(grid_fit.covered(got_alpha1, got_speed, a_range, v_range))
    assert cover <= sample < cover + 3.0 / N_HITS, sample
    assert abs(_law_share(a_range, v_range) - cover) <= _tolerance(cover), (_law_share(a_range, v_range), cover)
    # the grid: its ends rounded outward (never less), speeds geometric over a factor 10
    proposal = grid_fit.propose_grid(got_alpha1, got_speed, cover)
    assert proposal.alpha1_deg[0] <= a_range[0] and proposal.alpha1_deg[-1] == 90.0
    assert proposal.speed_m_s[0] <= v_range[0] and proposal.speed_m_s[-1] >= v_range[1]
    assert proposal.coverage >= cover and proposal.geometric
    law = _law_share((proposal.alpha1_deg[0], 90.0), (proposal.speed_m_s[0], proposal.speed_m_s[-1]))
    assert law >= cover - _tolerance(cover), law
    # geometric speeds and linear α1, up to the interior points' 3 significant digits
    ratios = np.diff(np.log(proposal.speed_m_s))
    assert np.allclose(ratios, ratios.mean(), atol=0.01)
    assert np.allclose(np.diff(proposal.alpha1_deg), np.diff(proposal.alpha1_deg).mean(), atol=0.1)


def test_the_counts_follow_the_default_preset_and_narrow_speed_ranges_are_linear():
    preset = parse_config(preset_text("default"))
    rng = np.random.default_rng(5)
    alpha1 = np.concatenate([[1.0, 90.0], rng.uniform(1.0, 90.0, 500)])
    speed = np.concatenate([[50.0, 300.0], rng.uniform(50.0, 300.0, 500)])
    wide = grid_fit.propose_grid(alpha1, speed, cover=1.0)
    assert (wide.alpha1_deg[0], wide.speed_m_s[0], wide.speed_m_s[-1], wide.coverage) == (1.0, 50.0, 300.0, 1.0)
    assert (len(wide.alpha1_deg), len(wide.speed_m_s)) == (len(preset.alpha1_deg), len(preset.speed_m_s))
    narrow = grid_fit.propose_grid(alpha1, np.clip(speed, 100.0, 250.0), cover=1.0)
    assert not narrow.geometric and narrow.speed_m_s == (100.0, 150.0, 200.0, 250.0)
    given = grid_fit.propose_grid(alpha1, speed, cover=1.0, alpha1_points=5, speed_points=3)
    assert given.alpha1_deg == (1.0, 23.2, 45.5, 67.8, 90.0) and len(given.speed_m_s) == 3


@pytest.mark.parametrize("x, up, expected", [(0.2, True, 0.2), (0.2, False, 0.2), (0.2034, False, 0.2),
                                             (0.2034, True, 0.21), (13.7, False, 13.0), (1234.0, True, 1300.0)])
def test_range_ends_round_outward_to_two_significant_digits(x, up, expected):
    assert grid_fit.tidy(x, up) == expected


# ------------------------------------------------------------------------------------------- the command line

@pytest.fixture(scope="module")
def table_path(tmp_path_factory):
    """A table on 30–90° × 50–300 m/s: the user's guess from the inlet velocity."""
    path = tmp_path_factory.mktemp("grid_table") / "guess.h5"
    build_table(parse_config(written_out_config([30.0, 90.0], [50.0, 300.0], ["prism"], seed=3)), path, workers=1)
    return path


@pytest.fixture(scope="module")
def user_case(tmp_path_factory):
    """A run's hits folder: two OpenFOAM ranks' files (the first also on a second patch) and its law."""
    folder = tmp_path_factory.mktemp("user_case") / "hits"
    alpha1, speed, V, n = _law_hits(4000, seed=11)
    _hits_file(folder / "hits_0.csv", V[:1500], n[:1500])
    _hits_file(folder / "hits_1.csv", V[1500:], n[1500:])
    return folder, alpha1, speed


def test_the_command_reports_the_hits_and_writes_a_grid_the_configuration_reads(user_case, table_path, tmp_path,
                                                                                 capsys):
    folder, alpha1, speed = user_case
    out = tmp_path / "grid.toml"
    code, err, text = _run(["grid", "--from-hits", str(folder), "--table", str(table_path), "-o", str(out)], capsys)
    assert code == 0 and not err, err
    assert "hits read: 4000 records in 2 files" in text and "per patch: walls 4000" in text
    q = np.quantile(speed, grid_fit.QUANTILES)
    assert "|V-| (m/s)    " + "".join(f"{v:>11.4g}" for v in q) in text
    assert f"the table {table_path} (alpha1 30 to 90 deg, |V-| 50 to 300 m/s) covers 0.00 % of the hits" in text
    assert "tablegen calibrate" in text        # these speeds are far below the default wall law's
    config = load_config(out)
    hits = grid_fit.read_hits([folder])
    np.testing.assert_allclose(np.sort(hits.speed), np.sort(speed), rtol=1e-12)
    proposal = grid_fit.propose_grid(hits.alpha1, hits.speed)
    np.testing.assert_allclose(config.alpha1_deg, proposal.alpha1_deg)
    np.testing.assert_allclose(config.speed_m_s, proposal.speed_m_s)
    assert config.shapes == parse_config(preset_text("default")).shapes
    written = out.read_text().splitlines()
    assert written[0] == grid_fit.MARKER
    assert f"covers {100 * proposal.coverage:.2f} % of the 4000 wall hits of {folder} (2 files)" in written[1]
    assert f"proposed grid: covers {100 * proposal.coverage:.2f} % of the hits (asked: 99 %)" in text
    # replaced with --overwrite, the output of this command; printed to stdout without -o, as a grid file too
    code, err, _ = _run(["grid", "--from-hits", str(folder), "--cover", "0.9", "-o", str(out), "--overwrite"], capsys)
    assert code == 0 and "(asked: 90 %)" in out.read_text()
    code, err, text = _run(["grid", "--from-hits", str(folder / "hits_1.csv"), str(folder / "hits_0.csv")], capsys)
    assert code == 0 and text.splitlines()[0] == grid_fit.MARKER
    assert parse_config(text).speed_m_s == config.speed_m_s   # the same hits, however the files are named


def test_both_adapters_titles_patches_and_spinning_hits(tmp_path, capsys):
    alpha1, speed, V, n = _law_hits(300, seed=3)
    _hits_file(tmp_path / "of" / "hits_0.csv", V[:100], n[:100], patch="blade")
    _hits_file(tmp_path / "cs" / "hits_0.csv", V[100:200], n[100:200], title=SATURNE_TITLE, patch="casing")
    _hits_file(tmp_path / "cs" / "hits_1.csv", V[200:], n[200:], title=SATURNE_TITLE, patch="casing", spin_ratio=0.01)
    hits = grid_fit.read_hits([tmp_path])
    np.testing.assert_allclose(np.sort(hits.alpha1), np.sort(alpha1), atol=1e-9)
    assert sum(hits.spinning) == 100 and len(hits.files) == 3
    assert sorted(set(hits.patch)) == ["blade", "casing"] and sum(hits.patch == "casing") == 200
    code, err, text = _run(["grid", "--from-hits", str(tmp_path), "--patch", "casing"], capsys)
    assert code == 0 and "per patch: casing 200" in text and "# note: 100 hits spin" in text


# ------------------------------------------------------------------------------------------- patchPostProcessing

# the header OpenFOAM v1912 writes for a kinematic parcel (PatchPostProcessing::write: "# Time currentProc " and
# the parcel's writeProperties names)
POST_HEADER = ("# Time currentProc  (coordinates0 coordinates1 coordinates2 coordinates3) (position0 position1 "
               "position2) celli tetFacei tetPti facei stepFraction origProc origId active typeId nParticle d dTarget "
               "(U0 U1 U2) rho age tTurb (UTurb0 UTurb1 UTurb2) (f0 f1 f2) (angularMomentum0 angularMomentum1 "
               "angularMomentum2) (torque0 torque1 torque2)")
# one hexahedral cell, all its faces boundary: face 0 the floor y = 0, face 1 the lid y = 1 + 0.5 x ("up") or
# y = 1.5 - 0.5 x ("down"), faces 2 to 5 the sides; the vertices in OpenFOAM's order (normals out of the cell)
HEX_FACES = [(0, 1, 5, 4), (3, 7, 6, 2), (0, 4, 7, 3), (1, 2, 6, 5), (0, 3, 2, 1), (4, 5, 6, 7)]
PATCHES = {"floor": (0, 1), "lid": (1, 1), "sides": (2, 4)}     # name: (startFace, nFaces)
LID = {"up": 1.0, "down": -1.0}      # the lid's slope dy/dx / 0.5


def _hex_points(lid):
    top = (1.0, 1.5) if lid == "up" else (1.5, 1.0)      # the lid's y at x = 0 and at x = 1
    return np.array([(0, 0, 0), (1, 0, 0), (1, top[1], 0), (0, top[0], 0), (0, 0, 1), (1, 0, 1), (1, top[1], 1),
                     (0, top[0], 1)], dtype=float)


def _lid_normal(lid):
    """The lid's unit normal into the gas (into the cell)."""
    return _unit(np.array([0.5 * LID[lid], -1.0, 0.0]))


def _foam_file(path, cls, body: bytes, binary=False):
    entries = {"version": "2.0", "format": "binary" if binary else "ascii", "arch": '"LSB;label=32;scalar=64"',
               "class": cls, "location": '"constant/polyMesh"', "object": path.name.split(".")[0]}
    lines = "".join(f"    {key:<12}{value};\n" for key, value in entries.items())
    header = f"FoamFile\n{{\n{lines}}}\n// * * * //\n\n".encode()
    data = header + body
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_bytes(gzip.compress(data) if path.suffix == ".gz" else data)


def _mesh(folder, lid="up", binary=False):
    """``folder`` (a polyMesh) holding the hexahedron of lid ``lid``: ASCII, or binary with its points gzipped."""
    points = _hex_points(lid)
    boundary = "".join(f"    {name}\n    {{\n        type wall;\n        inGroups 1(wall);\n        nFaces {count};\n"
                       f"        startFace {start};\n    }}\n" for name, (start, count) in PATCHES.items())
    _foam_file(folder / "boundary", "polyBoundaryMesh", f"{len(PATCHES)}\n(\n{boundary})\n".encode())
    if binary:
        _foam_file(folder / "points.gz", "vectorField", b"8\n(" + points.astype("<f8").tobytes() + b")\n", True)
        offsets = np.arange(0, 4 * len(HEX_FACES) + 1, 4, dtype="<i4")
        labels = np.array(HEX_FACES, dtype="<i4").ravel()
        _foam_file(folder / "faces", "faceCompactList", f"{len(offsets)}\n(".encode() + offsets.tobytes()
                   + f")\n\n\n{len(labels)}\n(".encode() + labels.tobytes() + b")\n", True)
    else:
        _foam_file(folder / "points", "vectorField",
                   ("8\n(\n" + "".join(f"({x:g} {y:g} {z:g})\n" for x, y, z in points) + ")\n").encode())
        _foam_file(folder / "faces", "faceList",
                   ("6\n(\n" + "".join(f"4({' '.join(map(str, f))})\n" for f in HEX_FACES) + ")\n").encode())


def _post_row(proc, facei, position, U):
    values = {"currentProc": proc, "facei": facei, "tetFacei": facei, "celli": 0, "origId": 1, "d": 3e-4,
              "nParticle": 1, "rho": 2650, "active": 1, "typeId": -1, "Time": 0.001}
    values.update({f"position{j}": repr(float(x)) for j, x in enumerate(position)})
    values.update({f"U{j}": repr(float(x)) for j, x in enumerate(U)})
    fields = []
    for token in POST_HEADER.lstrip("# ").split():
        name = token.strip("()")
        fields.append(("(" if token.startswith("(") else "") + str(values.get(name, 0))
                      + (")" if token.endswith(")") else ""))
    return " ".join(fields)


def _post_hits(n_hits, proc, lid, seed, patch, x_range=(0.1, 0.9)):
    """(α1, |V⁻|, rows) of hits on ``patch`` ("floor" or "lid") recorded by rank ``proc`` whose mesh has lid
    ``lid``: positions on the face (x in ``x_range``), U moving into it."""
    rng = np.random.default_rng(seed)
    alpha1 = rng.uniform(2.0, 90.0, n_hits)
    speed = rng.uniform(0.2, 2.0, n_hits)
    x, z = rng.uniform(*x_range, n_hits), rng.uniform(0.1, 0.9, n_hits)
    if patch == "floor":
        normal, y = np.array([0.0, 1.0, 0.0]), np.zeros(n_hits)
    else:
        normal = _lid_normal(lid)
        y = _hex_points(lid)[3, 1] + (_hex_points(lid)[2, 1] - _hex_points(lid)[3, 1]) * x
    U = _incident(alpha1, speed, np.tile(normal, (n_hits, 1)), rng)
    rows = [_post_row(proc, PATCHES[patch][0], p, u) for p, u in zip(np.column_stack([x, y, z]), U)]
    return alpha1, speed, rows


def _post_file(case, patch, rows, header=POST_HEADER, time="0.01"):
    path = case / "postProcessing" / "lagrangian" / "kinematicCloud" / "wallHits" / time / f"{patch}.post"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(header + "\n" + "".join(row + "\n" for row in rows))
    return path


@pytest.mark.parametrize("binary", [False, True], ids=["ascii", "binary"])
def test_patch_post_processing_records_read_with_the_normals_of_the_mesh(tmp_path, binary):
    _mesh(tmp_path / "constant" / "polyMesh", "up", binary)
    a_floor, v_floor, floor = _post_hits(50, 0, "up", 1, "floor")
    a_lid, v_lid, lid = _post_hits(70, 0, "up", 2, "lid")
    _post_file(tmp_path, "floor", floor)
    _post_file(tmp_path, "lid", lid[:30])
    _post_file(tmp_path, "lid", lid[30:], time="0.02")        # a later write time: its own records
    hits = grid_fit.read_hits([tmp_path / "postProcessing"])
    assert sorted(f.stem for f in hits.files) == ["floor", "lid", "lid"]
    np.testing.assert_allclose(np.sort(hits.alpha1), np.sort(np.concatenate([a_floor, a_lid])), atol=1e-9)
    np.testing.assert_allclose(np.sort(hits.speed), np.sort(np.concatenate([v_floor, v_lid])), rtol=1e-12)


def test_a_decomposed_run_reads_each_rank_s_mesh_and_another_mesh_is_refused(tmp_path, capsys):
    _mesh(tmp_path / "constant" / "polyMesh", "up")
    _mesh(tmp_path / "processor0" / "constant" / "polyMesh", "up")
    _mesh(tmp_path / "processor1" / "constant" / "polyMesh", "down")
    a0, _, rows0 = _post_hits(40, 0, "up", 3, "lid")
    a1, _, rows1 = _post_hits(40, 1, "down", 4, "lid")
    post = _post_file(tmp_path, "lid", rows0 + rows1)
    hits = grid_fit.read_hits([post])
    np.testing.assert_allclose(hits.alpha1, np.concatenate([a0, a1]), atol=1e-9)
    # rank 1's records on the lid of rank 0's mesh (away from x = 0.5, where the two lids cross): not its mesh
    a_wrong, _, wrong = _post_hits(5, 1, "up", 5, "lid", x_range=(0.1, 0.2))
    _post_file(tmp_path, "lid", rows0 + wrong)
    _user_error(["grid", "--from-hits", str(post)], capsys, str(post), "line 42", "plane of face 1",
                "--normal lid=NX,NY,NZ")
    # ... which --normal replaces: the records then read with the normal given (normalised)
    _post_file(tmp_path, "lid", wrong)
    hits = grid_fit.read_hits([post], normals={"lid": 3 * _lid_normal("up")})
    np.testing.assert_allclose(hits.alpha1, a_wrong, atol=1e-9)


def test_patch_post_processing_without_the_face_columns_or_the_mesh_takes_normal(tmp_path, capsys):
    rng = np.random.default_rng(8)
    alpha1, speed = rng.uniform(5.0, 90.0, 20), rng.uniform(0.5, 1.0, 20)
    U = _incident(alpha1, speed, np.tile([0.0, 0.0, -1.0], (20, 1)), rng)
    filtered = _post_file(tmp_path, "outlet", ["0.1 0 ({!r} {!r} {!r}) 0.0003".format(*map(float, u)) for u in U],
                          header="# Time currentProc (U0 U1 U2) d")
    _user_error(["grid", "--from-hits", str(filtered)], capsys, str(filtered), "line 1", "no facei",
                "--normal outlet=NX,NY,NZ")
    hits = grid_fit.read_hits([filtered], normals={"outlet": (0.0, 0.0, -2.0)})
    np.testing.assert_allclose(hits.alpha1, alpha1, atol=1e-9)
    _, _, rows = _post_hits(5, 0, "up", 9, "floor")
    alone = tmp_path / "copied" / "floor.post"          # copied out of its case: no mesh
    alone.parent.mkdir()
    alone.write_text(POST_HEADER + "\n" + "\n".join(rows) + "\n")
    _user_error(["grid", "--from-hits", str(alone)], capsys, str(alone), "no mesh", "--normal floor=NX,NY,NZ")
    case = tmp_path / "case_without_mesh"
    post = _post_file(case, "floor", rows)
    _user_error(["grid", "--from-hits", str(post)], capsys, "no mesh", "polyMesh", "--normal floor=NX,NY,NZ")
    assert _run(["grid", "--from-hits", str(alone), "--normal", "floor=0,1,0"], capsys)[0] == 0


# ------------------------------------------------------------------------------------------- user errors

def _case_with_hits(tmp_path):
    _, _, V, n = _law_hits(200, seed=2)
    return _hits_file(tmp_path / "run" / "hits_0.csv", V, n)


def _bad_row(tmp_path):
    path = _case_with_hits(tmp_path)
    lines = path.read_text().splitlines()
    lines[5] = lines[5] + ",extra"
    path.write_text("\n".join(lines) + "\n")
    return path


def _into_the_gas(tmp_path):
    _, _, V, n = _law_hits(20, seed=4)
    return _hits_file(tmp_path / "run" / "hits_0.csv", -V, n)


def _text_file(path, text):
    path.write_text(text)
    return path


def _hits_at(tmp_path, alpha1, speed):
    """A hits file of hits at these α1 (deg) and |V⁻| (m/s) on a wall of normal +y."""
    n = np.tile([0.0, 1.0, 0.0], (len(alpha1), 1))
    V = _incident(np.array(alpha1), np.array(speed), n, np.random.default_rng(1))
    return _hits_file(tmp_path / "hits_0.csv", V, n)


def _post_bad_row(tmp_path):
    """A patchPostProcessing file whose third record's U0 is not a number."""
    rows = _post_hits(3, 0, "up", 1, "floor")[2]
    fields = rows[2].split()
    fields[POST_HEADER.lstrip("# ").split().index("(U0")] = "(abc"
    return _post_file(tmp_path, "floor", rows[:2] + [" ".join(fields)])


@pytest.mark.parametrize("make, extra, words", [
    (lambda p: p / "missing", [], ["--from-hits", "missing", "no such file"]),
    (lambda p: p, [], ["no hits files under it", "hits_*.csv", "patchPostProcessing"]),
    (lambda p: _text_file(p / "notes.csv", "a,b\n1,2\n"), [], ["notes.csv, line 1", "not a hits file"]),
    (lambda p: _text_file(p / "hits_0.csv", "# stochasticRebound hits: seed x\n"), [],
     ["hits_0.csv, line 1", "not an adapter's hits header"]),
    (_bad_row, [], ["hits_0.csv, line 6", "37 fields, not 36"]),
    (_post_bad_row, [], ["floor.post, line 4", "not a number"]),
    (_into_the_gas, [], ["zero hits moving into the wall", "20 records"]),
    (_case_with_hits, ["--cover", "0"], ["--cover", "(0, 1]", "'0'"]),
    (_case_with_hits, ["--cover", "1.5"], ["--cover", "(0, 1]", "'1.5'"]),
    (_case_with_hits, ["--cover", "nan"], ["--cover", "(0, 1]"]),
    (_case_with_hits, ["--alpha1-points", "1"], ["--alpha1-points", "[2, 1000]", "got 1"]),
    (_case_with_hits, ["--speed-points", "1001"], ["--speed-points", "[2, 1000]", "got 1001"]),
    (lambda p: _hits_at(p, [30.0, 60.0], [0.01, 100.0]), ["--speed-points", "2"],
     ["--speed-points 2", "factor 1e+04 apart", "at most 16", "--speed-points >= 5"]),
    (_case_with_hits, ["--patch", "blade"], ["--patch blade", "no hits on it", "walls"]),
    (_case_with_hits, ["--normal", "walls=0,1,0"], ["--normal walls", "no patchPostProcessing records"]),
    (_case_with_hits, ["--normal", "walls=0,1"], ["--normal", "PATCH=NX,NY,NZ", "'walls=0,1'"]),
    (_case_with_hits, ["--normal", "w=1,0,0", "--normal", "w=0,1,0"], ["--normal", "'w' twice"]),
    (_post_bad_row, ["--normal", "floor=0,0,0"], ["--normal floor", "not all zero"]),
    (_case_with_hits, ["--table", "missing.h5"], ["missing.h5"]),
], ids=["missing", "empty folder", "other layout", "bad header", "bad row", "bad post row", "none into the wall",
        "cover 0", "cover 1.5", "cover nan", "alpha1 points", "speed points", "speeds too far apart", "patch",
        "normal of an adapter's patch", "normal not 3 numbers", "normal twice", "normal zero", "table missing"])
def test_user_errors_are_one_line_and_write_nothing(tmp_path, capsys, make, extra, words):
    source = make(tmp_path)
    out = tmp_path / "out" / "grid.toml"
    out.parent.mkdir()
    _user_error(["grid", "--from-hits", str(source), "-o", str(out), *extra], capsys, *words)
    assert list(out.parent.iterdir()) == []      # nothing written, no temporary left


def test_outputs_that_are_not_ours_are_kept(tmp_path, capsys):
    source = _case_with_hits(tmp_path)
    out = tmp_path / "grid.toml"
    out.write_text("[grid]\nalpha1_deg = [45.0]\n")
    argv = ["grid", "--from-hits", str(source), "-o", str(out)]
    _user_error(argv, capsys, str(out), "exists", "--overwrite")
    _user_error(argv + ["--overwrite"], capsys, str(out), "not an output of rebound-scatter")
    _user_error(["grid", "--from-hits", str(source), "-o", str(source), "--overwrite"], capsys, "input")
    assert out.read_text() == "[grid]\nalpha1_deg = [45.0]\n" and source.read_text().startswith("# stochasticRebound")
