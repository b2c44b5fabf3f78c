#!/usr/bin/python3
"""Tests of tools/convert_mesh.py (run: /usr/bin/python3 -m unittest -v this_file).

The meshes are built here: an annular sector (Nb = 12) of a structured (r, theta, z) grid,
each hexahedron split into 6 tetrahedra (Kuhn split, conforming), 4- or 10-node, written
as Abaqus .inp by hand (C3D4/C3D10 node ordering, *NSET / *ELSET sets). The converted
.msh is checked through meshio, through a direct parse of the MSH 2.2 text (the on-disk
node ordering, which meshio would permute) and through the gmsh binary (-check, and a
gmsh re-save read back).
"""
import itertools
import math
import os
import shutil
import subprocess
import sys
import tempfile
import unittest

try:
    import numpy as np
    import meshio
except ImportError:  # the Debian python3-meshio / python3-numpy are not installed
    meshio = None

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TOOL = os.path.join(ROOT, "tools", "convert_mesh.py")
GROUPS = ("hub", "cyclic_low", "cyclic_high", "shroud_low", "shroud_high")

NB = 12
ALPHA = 2 * math.pi / NB
R0, R1, H = 0.10, 0.16, 0.03
NR, NT, NZ = 4, 3, 2     # cells along r, theta, z
K_SPLIT = 2              # cyclic faces: r bands [0, K); shroud faces: r bands [K, NR)
N_TETS = 6 * NR * NT * NZ
EXPECTED = {"hub": 2 * NT * NZ,
            "cyclic_low": 2 * K_SPLIT * NZ, "cyclic_high": 2 * K_SPLIT * NZ,
            "shroud_low": 2 * (NR - K_SPLIT) * NZ, "shroud_high": 2 * (NR - K_SPLIT) * NZ}
# Abaqus C3D10 = meshio/VTK edge order (0,1) (1,2) (2,0) (0,3) (1,3) (2,3).
ABQ_EDGES = [(0, 1), (1, 2), (2, 0), (0, 3), (1, 3), (2, 3)]
GMSH_EDGES = [(0, 1), (1, 2), (0, 2), (0, 3), (2, 3), (1, 3)]
TRI6_EDGES = [(0, 1), (1, 2), (2, 0)]
ABQ_FLIP = [0, 2, 1, 3, 6, 5, 4, 7, 9, 8]        # swap vertices 1, 2 (Abaqus order)
# Geometric tolerance: coordinates are written with 17 significant digits.
TOL = 1e-12


def build_sector(order, flip_every=0):
    """Annular sector mesh. Returns (points, tets in Abaqus order (1-based ids later),
    node sets by group name, indices of the tets written with negative volume)."""
    r = np.linspace(R0, R1, NR + 1)
    t = np.linspace(0.0, ALPHA, NT + 1)
    z = np.linspace(0.0, H, NZ + 1)
    index = np.arange((NR + 1) * (NT + 1) * (NZ + 1)).reshape(NR + 1, NT + 1, NZ + 1)
    rr, tt, zz = np.meshgrid(r, t, z, indexing="ij")
    points = np.column_stack([(rr * np.cos(tt)).ravel(), (rr * np.sin(tt)).ravel(),
                              zz.ravel()])
    tets = []
    for i, j, k in itertools.product(range(NR), range(NT), range(NZ)):
        for perm in itertools.permutations(range(3)):
            v = [0, 0, 0]
            path = [tuple(v)]
            for axis in perm:
                v[axis] += 1
                path.append(tuple(v))
            tets.append([index[i + a, j + b, k + c] for a, b, c in path])
    tets = np.array(tets)
    # all positive first
    vol = signed6(points, tets)
    tets[vol < 0] = tets[vol < 0][:, [0, 2, 1, 3]]
    ir, it = np.unravel_index(np.arange(len(points)), index.shape)[:2]
    sets = {"hub": ir == 0,
            "cyclic_low": (it == 0) & (ir <= K_SPLIT),
            "cyclic_high": (it == NT) & (ir <= K_SPLIT),
            "shroud_low": (it == 0) & (ir >= K_SPLIT),
            "shroud_high": (it == NT) & (ir >= K_SPLIT)}
    if order == 2:
        edges = np.sort(tets[:, ABQ_EDGES], axis=2).reshape(-1, 2)
        uniq, inverse = np.unique(edges, axis=0, return_inverse=True)
        mid_ids = len(points) + inverse.reshape(len(tets), 6)
        points = np.vstack([points, 0.5 * (points[uniq[:, 0]] + points[uniq[:, 1]])])
        tets = np.hstack([tets, mid_ids])
        sets = {g: np.concatenate([m, m[uniq[:, 0]] & m[uniq[:, 1]]]) for g, m in sets.items()}
    flipped = np.arange(0, len(tets), flip_every) if flip_every else np.zeros(0, int)
    perm = ABQ_FLIP[:tets.shape[1]] if order == 2 else [0, 2, 1, 3]
    tets[flipped] = tets[flipped][:, perm]
    return points, tets, {g: np.flatnonzero(m) for g, m in sets.items()}, flipped


def signed6(points, tets):
    x0 = points[tets[:, 0]]
    return np.einsum("ij,ij->i", points[tets[:, 1]] - x0,
                     np.cross(points[tets[:, 2]] - x0, points[tets[:, 3]] - x0))


def id_lines(ids, per_line=8):
    ids = [str(i + 1) for i in ids]
    return "".join(",".join(ids[s:s + per_line]) + "\n" for s in range(0, len(ids), per_line))


def write_inp(path, points, tets, node_sets=None, face_sets=None, extra_points=0):
    """Abaqus input by hand. face_sets: name -> (k, 3) triangles as S3 elements."""
    etype = "C3D4" if tets.shape[1] == 4 else "C3D10"
    with open(path, "w") as f:
        f.write("*HEADING\nshroudsim convert_mesh test\n*NODE\n")
        pts = np.vstack([points, np.full((extra_points, 3), 9.0)])
        for i, p in enumerate(pts):
            f.write(f"{i + 1}, {p[0]!r}, {p[1]!r}, {p[2]!r}\n")
        f.write(f"*ELEMENT, TYPE={etype}, ELSET=SOLID\n")
        for e, row in enumerate(tets):
            f.write(f"{e + 1}, " + ", ".join(str(n + 1) for n in row) + "\n")
        eid = len(tets)
        for name, tri in (face_sets or {}).items():
            f.write("*ELEMENT, TYPE=S3, ELSET=" + name + "\n")
            for row in tri:
                eid += 1
                f.write(f"{eid}, " + ", ".join(str(n + 1) for n in row) + "\n")
        for name, ids in (node_sets or {}).items():
            f.write(f"*NSET, NSET={name}\n" + id_lines(ids))


def read_gmsh(path):
    # With the format named, meshio does not first try (and print the failure of) its
    # other ".msh" reader (ANSYS).
    return meshio.read(path, file_format="gmsh")


def read_msh22(path):
    """Minimal MSH 2.2 ASCII parser: (points, {physical name: (dim, tag)},
    [(gmsh type, physical, nodes 0-based)]), nodes in the file's own order."""
    with open(path) as f:
        lines = f.read().split("\n")
    i = 0
    names, points, elements = {}, None, []
    while i < len(lines):
        line = lines[i].strip()
        if line == "$MeshFormat":
            assert lines[i + 1].split()[:2] == ["2.2", "0"], lines[i + 1]
        elif line == "$PhysicalNames":
            for k in range(int(lines[i + 1])):
                dim, tag, name = lines[i + 2 + k].split()
                names[name.strip('"')] = (int(dim), int(tag))
        elif line == "$Nodes":
            n = int(lines[i + 1])
            data = np.array([lines[i + 2 + k].split() for k in range(n)], dtype=float)
            assert np.all(data[:, 0] == np.arange(1, n + 1))
            points = data[:, 1:]
        elif line == "$Elements":
            for k in range(int(lines[i + 1])):
                v = [int(x) for x in lines[i + 2 + k].split()]
                ntags = v[2]
                elements.append((v[1], v[3], np.array(v[3 + ntags:]) - 1))
        i += 1
    return points, names, elements


@unittest.skipIf(meshio is None, "meshio (Debian python3-meshio) is not installed")
class ConvertMeshTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="convert_mesh_test_")

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def path(self, name):
        return os.path.join(self.tmp, name)

    def run_tool(self, *args):
        return subprocess.run([sys.executable, TOOL, *args], capture_output=True,
                              text=True, timeout=120)

    def convert(self, *args):
        res = self.run_tool(*args)
        self.assertEqual(res.returncode, 0, msg=res.stderr + res.stdout)
        return res

    def gmsh_reads(self, msh):
        """gmsh -check is clean and a gmsh re-save keeps the groups; returns the
        triangle counts per physical name of the re-saved mesh."""
        gmsh = shutil.which("gmsh")
        self.assertIsNotNone(gmsh, "gmsh binary not found")
        res = subprocess.run([gmsh, "-check", msh], capture_output=True, text=True,
                             timeout=60)
        self.assertEqual(res.returncode, 0, res.stdout + res.stderr)
        log = res.stdout + res.stderr
        self.assertNotIn("Error", log)
        self.assertNotIn("Warning", log)
        resaved = self.path("gmsh_resaved.msh")
        res = subprocess.run([gmsh, msh, "-0", "-format", "msh22", "-o", resaved],
                             capture_output=True, text=True, timeout=60)
        self.assertEqual(res.returncode, 0, res.stdout + res.stderr)
        self.assertNotIn("Error", res.stdout + res.stderr)
        m = read_gmsh(resaved)
        tag_to_name = {int(v[0]): k for k, v in m.field_data.items()}
        counts = {}
        for block, phys in zip(m.cells, m.cell_data["gmsh:physical"]):
            for tag in np.unique(phys):
                key = (tag_to_name.get(int(tag), str(tag)), block.type)
                counts[key] = counts.get(key, 0) + int(np.count_nonzero(phys == tag))
        return counts

    def check_msh(self, msh, points_in, order):
        """Common checks of a converted mesh; returns (points, elements by group)."""
        pts, names, elements = read_msh22(msh)
        self.assertEqual(set(names), set(GROUPS) | {"sector"})
        self.assertEqual(names["sector"][0], 3)
        for g in GROUPS:
            self.assertEqual(names[g][0], 2, g)
        np.testing.assert_allclose(pts, points_in, rtol=0, atol=TOL)
        tet_type, tri_type = (4, 2) if order == 1 else (11, 9)
        by_name = {name: [] for name in names}
        tag_name = {tag: name for name, (dim, tag) in names.items()}
        for etype, phys, nodes in elements:
            name = tag_name[phys]
            self.assertEqual(etype, tet_type if name == "sector" else tri_type, name)
            by_name[name].append(nodes)
        by_name = {k: np.array(v) for k, v in by_name.items()}
        tets = by_name["sector"]
        self.assertEqual(len(tets), N_TETS)
        self.assertTrue(np.all(signed6(pts, tets) > 0), "negative tets left")
        for g in GROUPS:
            self.assertEqual(len(by_name[g]), EXPECTED[g], g)
        if order == 2:  # gmsh ordering on disk: midside nodes at edge midpoints
            for e, (a, b) in enumerate(GMSH_EDGES):
                np.testing.assert_allclose(pts[tets[:, 4 + e]],
                                           0.5 * (pts[tets[:, a]] + pts[tets[:, b]]),
                                           rtol=0, atol=TOL, err_msg=f"tet edge {e}")
            for g in GROUPS:
                tri = by_name[g]
                for e, (a, b) in enumerate(TRI6_EDGES):
                    np.testing.assert_allclose(pts[tri[:, 3 + e]],
                                               0.5 * (pts[tri[:, a]] + pts[tri[:, b]]),
                                               rtol=0, atol=TOL, err_msg=f"{g} edge {e}")
        # Outward normals: hub points to -r, cyclic_low to -theta, cyclic_high to +theta.
        for g, expect in (("hub", "r-"), ("cyclic_low", "t-"), ("cyclic_high", "t+"),
                          ("shroud_low", "t-"), ("shroud_high", "t+")):
            tri = by_name[g]
            n = np.cross(pts[tri[:, 1]] - pts[tri[:, 0]], pts[tri[:, 2]] - pts[tri[:, 0]])
            c = pts[tri[:, :3]].mean(axis=1)
            theta = np.arctan2(c[:, 1], c[:, 0])
            er = np.column_stack([np.cos(theta), np.sin(theta), 0 * theta])
            et = np.column_stack([-np.sin(theta), np.cos(theta), 0 * theta])
            d = np.einsum("ij,ij->i", n, er if expect[0] == "r" else et)
            self.assertTrue(np.all(d < 0) if expect[1] == "-" else np.all(d > 0), g)
        return pts, by_name

    # ------------------------------------------------------------------ tests
    def test_tet4_node_sets_map_case_and_reorientation(self):
        points, tets, sets, flipped = build_sector(order=1, flip_every=5)
        self.assertTrue(np.all(signed6(points, tets)[flipped] < 0))
        inp = self.path("sector4.inp")
        write_inp(inp, points, tets, node_sets={
            "HUB": sets["hub"], "CYC_LO": sets["cyclic_low"],
            "Cyclic_High": sets["cyclic_high"], "SHR_A": sets["shroud_low"],
            "shroud_high": sets["shroud_high"]}, extra_points=1)
        out = self.path("out4.msh")
        res = self.convert("to-msh", inp, out, "--map", "CYC_LO=cyclic_low",
                           "--map", "SHR_A=shroud_low", "--sectors", str(NB))
        self.assertIn(f"reoriented {len(flipped)} negative-volume tets", res.stdout)
        self.assertIn(f"{len(points)} nodes, {N_TETS} tetra elements", res.stdout)
        self.assertIn("dropped 1 unused nodes", res.stdout)
        self.assertIn("cyclic pairs 9, shroud pairs 9", res.stdout)
        for g in GROUPS:
            self.assertIn(f"{g}={EXPECTED[g]}", res.stdout)
        self.assertEqual(len(res.stdout.strip().splitlines()), 1)
        self.check_msh(out, points, order=1)
        # meshio reads it back with the named groups
        m = read_gmsh(out)
        self.assertEqual({k: int(v[1]) for k, v in m.field_data.items()},
                         {"sector": 3, **{g: 2 for g in GROUPS}})
        np.testing.assert_allclose(m.points, points, rtol=0, atol=TOL)
        # gmsh reads it back, groups intact
        counts = self.gmsh_reads(out)
        self.assertEqual(counts[("sector", "tetra")], N_TETS)
        for g in GROUPS:
            self.assertEqual(counts[(g, "triangle")], EXPECTED[g], g)

    def test_tet10_ordering_and_reorientation(self):
        points, tets, sets, flipped = build_sector(order=2, flip_every=3)
        # A few elements written in gmsh order by a careless exporter: the tool must
        # find the midside nodes by geometry.
        garbled = np.arange(1, len(tets), 7)
        tets[garbled] = tets[garbled][:, [0, 1, 2, 3, 4, 5, 6, 7, 9, 8]]
        inp = self.path("sector10.inp")
        write_inp(inp, points, tets, node_sets=sets)
        out = self.path("out10.msh")
        res = self.convert("to-msh", inp, out)
        self.assertIn(f"{N_TETS} tetra10 elements", res.stdout)
        self.assertIn(f"reoriented {len(flipped)} negative-volume tets", res.stdout)
        self.assertIn(f"reordered midside nodes of {len(garbled)}", res.stdout)
        pts, by_name = self.check_msh(out, points, order=2)
        # the volume of the sector is preserved (straight-sided tets: chordal volume)
        vol = signed6(pts, by_name["sector"]).sum() / 6
        chord = 0.5 * NT * math.sin(ALPHA / NT) * (R1 ** 2 - R0 ** 2) * H
        self.assertAlmostEqual(vol, chord, delta=1e-12)
        counts = self.gmsh_reads(out)
        self.assertEqual(counts[("sector", "tetra10")], N_TETS)
        for g in GROUPS:
            self.assertEqual(counts[(g, "triangle6")], EXPECTED[g], g)
        # meshio's own view: its tetra10 is VTK-ordered, same midpoints.
        m = read_gmsh(out)
        t10 = m.get_cells_type("tetra10")
        for e, (a, b) in enumerate(ABQ_EDGES):
            np.testing.assert_allclose(m.points[t10[:, 4 + e]],
                                       0.5 * (m.points[t10[:, a]] + m.points[t10[:, b]]),
                                       rtol=0, atol=TOL)

    def test_face_sets_from_surface_elements(self):
        points, tets, sets, _ = build_sector(order=1)
        # Boundary faces of the Kuhn mesh from node sets, written as S3 surface elements
        # with arbitrary vertex order: the tool must orient them outward.
        faces = {}
        all_faces = np.sort(tets[:, [[0, 1, 2], [0, 1, 3], [0, 2, 3], [1, 2, 3]]]
                            .reshape(-1, 3), axis=1)
        uniq, counts = np.unique(all_faces, axis=0, return_counts=True)
        boundary = uniq[counts == 1]
        for g, ids in sets.items():
            mask = np.zeros(len(points), bool)
            mask[ids] = True
            tri = boundary[np.all(mask[boundary], axis=1)]
            faces[g.upper() + "_FACES"] = tri[:, ::-1] if g.endswith("low") else tri
        inp = self.path("faces.inp")
        write_inp(inp, points, tets, face_sets=faces)
        out = self.path("faces.msh")
        self.convert("to-msh", inp, out,
                     *sum((["--map", f"{g.upper()}_FACES={g}"] for g in GROUPS), []))
        self.check_msh(out, points, order=1)

    def test_missing_group_exit_2_and_no_output(self):
        points, tets, sets, _ = build_sector(order=1)
        del sets["shroud_high"]
        inp = self.path("missing.inp")
        write_inp(inp, points, tets, node_sets=sets)
        out = self.path("missing.msh")
        res = self.run_tool("to-msh", inp, out)
        self.assertEqual(res.returncode, 2, res.stderr)
        self.assertIn(inp, res.stderr)
        self.assertIn("shroud_high", res.stderr)
        self.assertEqual(len(res.stderr.strip().splitlines()), 1, res.stderr)
        self.assertFalse(os.path.exists(out))
        self.assertEqual(sorted(os.listdir(self.tmp)), ["missing.inp"])  # no temp files
        # a failed write (the output is a folder) leaves no temporary file behind
        points, tets, sets, _ = build_sector(order=1)
        complete = self.path("complete.inp")
        write_inp(complete, points, tets, node_sets=sets)
        folder = self.path("folder.msh")
        os.mkdir(folder)
        res = self.run_tool("to-msh", complete, folder)
        self.assertEqual(res.returncode, 2, res.stderr)
        self.assertIn("cannot write", res.stderr)
        self.assertEqual(sorted(os.listdir(self.tmp)),
                         ["complete.inp", "folder.msh", "missing.inp"])
        self.assertEqual(os.listdir(folder), [])
        os.rmdir(folder)
        # an unknown --map source is bad input too
        res = self.run_tool("to-msh", inp, out, "--map", "NOPE=shroud_high")
        self.assertEqual(res.returncode, 2)
        self.assertIn("NOPE", res.stderr)
        self.assertFalse(os.path.exists(out))

    def test_invalid_meshes_exit_2(self):
        points, tets, sets, _ = build_sector(order=2)
        bad = tets.copy()
        bad[5, 9] = bad[40, 9]           # a midside node of another element
        inp, out = self.path("bad10.inp"), self.path("bad10.msh")
        write_inp(inp, points, bad, node_sets=sets)
        res = self.run_tool("to-msh", inp, out)
        self.assertEqual(res.returncode, 2, res.stderr)
        self.assertIn("tetrahedron 6 ", res.stderr)
        self.assertIn(inp, res.stderr)
        self.assertFalse(os.path.exists(out))
        p4, t4, s4, _ = build_sector(order=1)
        t4 = t4.copy()
        t4[3, 3] = t4[3, 2]              # zero volume
        write_inp(inp, p4, t4, node_sets=s4)
        res = self.run_tool("to-msh", inp, out)
        self.assertEqual(res.returncode, 2, res.stderr)
        self.assertIn("zero volume", res.stderr)
        self.assertFalse(os.path.exists(out))
        write_inp(inp, p4, np.vstack([t4[:3], t4[:3], t4[4:]]), node_sets=s4)  # duplicates
        res = self.run_tool("to-msh", inp, out)
        self.assertEqual(res.returncode, 2, res.stderr)
        self.assertIn("more than two tetrahedra", res.stderr)

    def test_sectors_mismatch_exit_2(self):
        points, tets, sets, _ = build_sector(order=1)
        inp = self.path("s.inp")
        write_inp(inp, points, tets, node_sets=sets)
        out = self.path("s.msh")
        res = self.run_tool("to-msh", inp, out, "--sectors", "10")
        self.assertEqual(res.returncode, 2)
        self.assertIn("cyclic_high", res.stderr)
        self.assertFalse(os.path.exists(out))
        # swapped names are recognised
        res = self.run_tool("to-msh", inp, out, "--sectors", str(NB),
                            "--map", "cyclic_low=cyclic_high", "--map", "cyclic_high=cyclic_low")
        self.assertEqual(res.returncode, 2)
        self.assertIn("swap", res.stderr)

    def test_to_vtu_round_trip(self):
        points, tets, sets, _ = build_sector(order=2)
        inp = self.path("v.inp")
        write_inp(inp, points, tets, node_sets=sets)
        msh = self.path("v.msh")
        self.convert("to-msh", inp, msh)
        vtu = self.path("v.vtu")
        self.convert("to-vtu", msh, vtu)
        m = meshio.read(vtu)
        self.assertEqual([b.type for b in m.cells], ["tetra10"])
        self.assertEqual(len(m.cells[0].data), N_TETS)
        self.assertTrue(np.all(m.cell_data["physical_id"][0] == 1))
        np.testing.assert_allclose(m.points, points, rtol=0, atol=TOL)
        for g in GROUPS:
            flag = np.asarray(m.point_data[g])
            self.assertTrue(set(np.unique(flag)) <= {0, 1})
            # the flagged nodes are the nodes of the set (all lie on the group's faces)
            np.testing.assert_array_equal(np.flatnonzero(flag), sets[g], err_msg=g)
        # VTK ordering in the .vtu: midside nodes at the midpoints
        t10 = m.cells[0].data
        for e, (a, b) in enumerate(ABQ_EDGES):
            np.testing.assert_allclose(m.points[t10[:, 4 + e]],
                                       0.5 * (m.points[t10[:, a]] + m.points[t10[:, b]]),
                                       rtol=0, atol=TOL)
        # and the point flags make the .vtu a valid to-msh input again
        msh2 = self.path("v2.msh")
        self.convert("to-msh", vtu, msh2)
        self.check_msh(msh2, points, order=2)
        # --surfaces adds the triangles with their group ids
        vtu2 = self.path("v2.vtu")
        self.convert("to-vtu", "--surfaces", msh, vtu2)
        m2 = meshio.read(vtu2)
        self.assertEqual(sum(len(b.data) for b in m2.cells if b.type == "triangle6"),
                         sum(EXPECTED.values()))

    def test_gmsh_input_with_physical_names(self):
        # the tool's own output is a valid input (physical names -> face sets)
        points, tets, sets, _ = build_sector(order=1)
        inp = self.path("g.inp")
        write_inp(inp, points, tets, node_sets=sets)
        msh = self.path("g.msh")
        self.convert("to-msh", inp, msh)
        msh2 = self.path("g2.msh")
        self.convert("to-msh", msh, msh2)
        self.check_msh(msh2, points, order=1)

    def test_nastran_property_ids_as_groups(self):
        # CTETRA (10-node) + CTRIA6 with property ids, written by meshio's Nastran writer
        points, tets, sets, _ = build_sector(order=2, flip_every=4)
        inp = self.path("n.inp")
        write_inp(inp, points, tets, node_sets=sets)
        msh = self.path("n.msh")
        self.convert("to-msh", inp, msh)
        m = read_gmsh(msh)
        bdf = self.path("n.bdf")
        meshio.nastran.write(bdf, meshio.Mesh(
            m.points, [(b.type, b.data) for b in m.cells],
            cell_data={"nastran:ref": [np.asarray(p) for p in m.cell_data["gmsh:physical"]]}))
        tag = {g: int(m.field_data[g][0]) for g in GROUPS}
        out = self.path("n2.msh")
        res = self.run_tool("to-msh", bdf, out)          # property ids need --map
        self.assertEqual(res.returncode, 2)
        self.assertIn("nastran:ref=2", res.stderr)
        self.convert("to-msh", bdf, out,
                     *sum((["--map", f"nastran:ref={tag[g]}={g}"] for g in GROUPS), []))
        self.check_msh(out, points, order=2)

    def test_gmsh_exported_abaqus_curved_tet10(self):
        # A real exporter: gmsh meshes a curved annular sector (second order, midside
        # nodes on the cylinders) and writes Abaqus C3D10 + CPS6 elsets + node sets.
        # The conversion must give exactly gmsh's own native .msh elements.
        gmsh = shutil.which("gmsh")
        self.assertIsNotNone(gmsh, "gmsh binary not found")
        geo = self.path("ann.geo")
        with open(geo, "w") as f:
            f.write(f"""SetFactory("OpenCASCADE");
a = 2*Pi/{NB};
Cylinder(1) = {{0,0,0, 0,0,{H}, {R1}, a}};
Cylinder(2) = {{0,0,0, 0,0,{H}, {R0}, a}};
BooleanDifference(3) = {{ Volume{{1}}; Delete; }}{{ Volume{{2}}; Delete; }};
Physical Volume("SOLID") = {{3}};
Physical Surface("HUB") = {{6}};
Physical Surface("LOW") = {{5}};
Physical Surface("HIGH") = {{3}};
Physical Surface("BOTTOM") = {{4}};
Physical Surface("TOP") = {{2}};
Mesh.MeshSizeMax = 0.02;
Mesh.ElementOrder = 2;
Mesh.SaveGroupsOfNodes = 1;
""")
        inp, native = self.path("ann.inp"), self.path("ann_native.msh")
        for fmt, out in (("inp", inp), ("msh22", native)):
            res = subprocess.run([gmsh, geo, "-3", "-format", fmt, "-o", out],
                                 capture_output=True, text=True, timeout=60)
            self.assertEqual(res.returncode, 0, res.stdout + res.stderr)
        out = self.path("ann.msh")
        res = self.convert("to-msh", inp, out, "--map", "LOW=cyclic_low",
                           "--map", "HIGH=cyclic_high", "--map", "BOTTOM=shroud_low",
                           "--map", "TOP=shroud_high")
        self.assertIn("reordered midside nodes of 0", res.stdout)
        self.assertIn("reoriented 0 negative-volume tets", res.stdout)
        pts, _, elements = read_msh22(out)
        npts, nnames, nelements = read_msh22(native)
        np.testing.assert_allclose(pts, npts, rtol=0, atol=TOL)
        ours = np.array([e[2] for e in elements if e[0] == 11])
        theirs = np.array([e[2] for e in nelements if e[0] == 11])
        np.testing.assert_array_equal(ours, theirs)   # same tets, same node order
        tag_name = {tag: name for name, (dim, tag) in nnames.items()}
        rename = {"HUB": "hub", "LOW": "cyclic_low", "HIGH": "cyclic_high",
                  "BOTTOM": "shroud_low", "TOP": "shroud_high"}
        _, onames, _ = read_msh22(out)
        otag_name = {tag: name for name, (dim, tag) in onames.items()}
        for src, dst in rename.items():
            a = sorted(tuple(sorted(e[2])) for e in nelements
                       if e[0] == 9 and tag_name[e[1]] == src)
            b = sorted(tuple(sorted(e[2])) for e in elements
                       if e[0] == 9 and otag_name[e[1]] == dst)
            self.assertGreater(len(a), 0)
            self.assertEqual(a, b, dst)
        self.gmsh_reads(out)

    def test_help_documents_commands(self):
        res = self.convert("--help")
        for word in ("to-msh", "to-vtu", "--map", "--sectors", "cyclic_low", "shroud_high",
                     "hub", "sector", "node set", "exit status"):
            self.assertIn(word.lower(), res.stdout.lower(), word)
        self.assertEqual(self.run_tool("to-msh").returncode, 2)  # usage error


if __name__ == "__main__":
    unittest.main()
