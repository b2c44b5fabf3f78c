#!/usr/bin/python3
"""Convert third-party sector meshes to shroudsim's .msh convention, and .msh to .vtu.

  convert_mesh.py to-msh INPUT OUTPUT.msh [--map NAME=GROUP ...] [--sectors Nb]
  convert_mesh.py to-vtu INPUT.msh OUTPUT.vtu [--surfaces]

to-msh
  Reads any volume mesh meshio reads (Abaqus .inp, Nastran .bdf/.nas, VTU, gmsh .msh,
  ...) made of 4-node or 10-node tetrahedra, and writes gmsh MSH 2.2 ASCII with
    - the tetrahedra (gmsh "tetra"/"tetra10", gmsh node ordering: vertices 0..3, then
      edge nodes 4:(0,1) 5:(1,2) 6:(0,2) 7:(0,3) 8:(2,3) 9:(1,3)) in the 3D physical
      group "sector";
    - the boundary triangles ("triangle"/"triangle6", outward normals) of the 2D physical
      groups hub, cyclic_low, cyclic_high, shroud_low, shroud_high
  (docs/physics.md section 1; src/mesh/mesh.hpp).

  Named sets of the input become groups:
    - node sets (Abaqus *NSET, meshio point_sets, 0/1 point-data flags such as the ones
      to-vtu writes): the group's triangles are the boundary faces (faces of exactly one
      tetrahedron) whose three corner nodes all belong to the set;
    - face sets (Abaqus *ELSET of S3/STRI3/CPS3 elements, gmsh physical surfaces, meshio
      cell_sets of triangles): the triangles themselves, which must be boundary faces;
    - integer cell data of triangles, e.g. Nastran property ids: set "nastran:ref=12"
      holds the triangles with nastran:ref == 12 (map it: --map nastran:ref=12=hub).
  A set whose name equals a group name (case-insensitively) is taken as-is; --map
  SRC=GROUP takes set SRC for GROUP (repeat --map to unite several sets into one group).
  A face set is preferred over a node set of the same name.

  10-node tetrahedra: the midside nodes are matched to the edges geometrically (nearest
  edge midpoint), so a reader's ordering mix-up (Abaqus C3D10 / Nastran CTETRA vs gmsh)
  cannot slip through; tetrahedra with negative volume are reoriented (vertices 1 and 2
  swapped with their edge nodes). Nodes used by no tetrahedron are dropped. Both counts are
  reported.

  --sectors Nb checks that cyclic_high (shroud_high) is cyclic_low (shroud_low) rotated by
  +2*pi/Nb about z, node for node, and reports the pair counts.

  The output is written to a temporary file in the output folder and renamed, so a failed
  run never leaves a partial file.

to-vtu
  Writes the volume cells of a .msh file to .vtu for ParaView, with cell data
  "physical_id" (gmsh physical tag) and "elementary_id", and one point-data flag (0/1)
  per named 2D physical group (nodes of the group's triangles). --surfaces also writes
  the boundary triangles (their physical_id tells the groups apart).

Needs meshio and numpy: run with /usr/bin/python3 (Debian python3-meshio), which the
shebang names.

Exit status: 0 done; 2 bad input (usage, unreadable file, missing group, unsupported or
invalid mesh), with one message naming the file; 1 anything else.
"""
import argparse
import contextlib
import io
import math
import os
import sys
import tempfile

try:
    import numpy as np
    import meshio
except ImportError as exc:  # pragma: no cover - depends on the interpreter
    sys.stderr.write(
        f"convert_mesh: error: {exc}; run with /usr/bin/python3 "
        "(Debian python3-meshio, python3-numpy)\n")
    sys.exit(1)

PROG = "convert_mesh"
VOLUME_GROUP = "sector"
SURFACE_GROUPS = ("hub", "cyclic_low", "cyclic_high", "shroud_low", "shroud_high")
# Physical tags written to the .msh: sector = 1 (dim 3), then the 2D groups in order.
PHYSICAL_TAG = {VOLUME_GROUP: 1, **{g: i + 2 for i, g in enumerate(SURFACE_GROUPS)}}

TET_TYPES = {"tetra": 4, "tetra4": 4, "tetra10": 10}  # meshio reads C3D4H as "tetra4"
TRI_TYPES = {"triangle": 3, "triangle6": 6, "triangle7": 7}
OTHER_VOLUME_PREFIXES = ("hexahedron", "wedge", "pyramid", "tetra")

# meshio keeps tetra10 in VTK order (edges (0,1) (1,2) (0,2) (0,3) (1,3) (2,3)); gmsh
# swaps the last two. The permutation is its own inverse.
MESHIO_TO_GMSH_TET10 = np.array([0, 1, 2, 3, 4, 5, 6, 7, 9, 8])
# gmsh tet10 edges, local vertex pairs of nodes 4..9.
TET10_EDGES = np.array([[0, 1], [1, 2], [0, 2], [0, 3], [2, 3], [1, 3]])
# Swapping vertices 1 and 2 flips the orientation; edges (0,1)<->(0,2), (1,3)<->(2,3).
REORIENT = {4: np.array([0, 2, 1, 3]),
            10: np.array([0, 2, 1, 3, 6, 5, 4, 7, 9, 8])}
# Outward faces of a positive tet in gmsh ordering (triangle6: vertices then (a,b) (b,c)
# (c,a) edge nodes).
FACES = {4: np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]),
         10: np.array([[0, 2, 1, 6, 5, 4], [0, 1, 3, 4, 9, 7],
                       [0, 3, 2, 7, 8, 6], [1, 2, 3, 5, 8, 9]])}


class InputError(Exception):
    """Bad input: reported as one message, exit status 2."""


def warn(msg):
    sys.stderr.write(f"{PROG}: warning: {msg}\n")


# --------------------------------------------------------------------------- geometry
def signed_volumes(points, tets):
    """Six times the signed volume of each tetrahedron (corner nodes 0..3)."""
    x0 = points[tets[:, 0]]
    a = points[tets[:, 1]] - x0
    b = points[tets[:, 2]] - x0
    c = points[tets[:, 3]] - x0
    return np.einsum("ij,ij->i", a, np.cross(b, c))


def fix_midside_order(points, tets, chunk=50000):
    """Reorders the edge nodes 4..9 of each tet10 (gmsh ordering) so that node 4+e is the
    node nearest to the midpoint of edge e. Returns (tets, n_reordered, worst relative
    distance of a midside node from its edge midpoint)."""
    out = tets.copy()
    n_changed, worst = 0, 0.0
    for start in range(0, len(tets), chunk):
        t = tets[start:start + chunk]
        a, b = points[t[:, TET10_EDGES[:, 0]]], points[t[:, TET10_EDGES[:, 1]]]
        mid = 0.5 * (a + b)                                            # (n, edge, 3)
        nodes = points[t[:, 4:]]                                       # (n, node, 3)
        dist = np.linalg.norm(mid[:, :, None, :] - nodes[:, None, :, :], axis=3)
        choice = np.argmin(dist, axis=2)                               # node for each edge
        matched = np.take_along_axis(dist, choice[:, :, None], axis=2)[:, :, 0]
        edge_len = np.linalg.norm(a - b, axis=2)
        with np.errstate(divide="ignore", invalid="ignore"):
            rel = np.nan_to_num(matched / edge_len, nan=np.inf)
        ok = np.all(np.sort(choice, axis=1) == np.arange(6), axis=1) & np.all(rel <= 0.5,
                                                                              axis=1)
        if not np.all(ok):
            bad = np.flatnonzero(~ok)
            raise InputError(
                f"10-node tetrahedron {start + bad[0] + 1} of the volume cells has midside "
                "nodes that are not near distinct edge midpoints "
                f"({len(bad)} such among elements {start + 1}..{start + len(t)})")
        n_changed += int(np.count_nonzero(np.any(choice != np.arange(6), axis=1)))
        out[start:start + chunk, 4:] = np.take_along_axis(t[:, 4:], choice, axis=1)
        if rel.size:
            worst = max(worst, float(rel.max()))
    return out, n_changed, worst


def match_rows(queries, table):
    """Index into table of each row of queries (rows compared exactly), -1 if absent.
    table rows must be unique."""
    if len(queries) == 0:
        return np.zeros(0, dtype=np.int64)
    both = np.vstack([table, queries])
    _, inverse = np.unique(both, axis=0, return_inverse=True)
    inverse = inverse.ravel()
    owner = np.full(inverse.max() + 1, -1, dtype=np.int64)
    owner[inverse[:len(table)]] = np.arange(len(table))
    return owner[inverse[len(table):]]


def boundary_faces(tets):
    """Faces belonging to exactly one tetrahedron, oriented outward (tets positive).
    Returns (faces (m, 3|6), sorted corner keys (m, 3))."""
    npe = tets.shape[1]
    faces = tets[:, FACES[npe]].reshape(-1, FACES[npe].shape[1])
    keys = np.sort(faces[:, :3], axis=1)
    _, first, inverse, counts = np.unique(keys, axis=0, return_index=True,
                                          return_inverse=True, return_counts=True)
    if np.any(counts > 2):
        raise InputError(f"{int(np.count_nonzero(counts > 2))} faces are shared by more "
                         "than two tetrahedra (duplicate or overlapping elements)")
    once = first[counts == 1]
    once.sort()
    return faces[once], keys[once]


def rotation_z(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def nearest(src, dst):
    """For each row of src: (index of the nearest row of dst, distance)."""
    try:
        from scipy.spatial import cKDTree  # optional, faster
        dist, idx = cKDTree(dst).query(src)
        return np.asarray(idx), np.asarray(dist)
    except ImportError:
        idx = np.empty(len(src), dtype=np.int64)
        dist = np.empty(len(src))
        for s in range(0, len(src), 512):
            d = np.linalg.norm(src[s:s + 512, None, :] - dst[None, :, :], axis=2)
            idx[s:s + 512] = np.argmin(d, axis=1)
            dist[s:s + 512] = d[np.arange(len(d)), idx[s:s + 512]]
        return idx, dist


def count_pairs(points, low_nodes, high_nodes, angle, tol):
    """Number of low nodes whose rotation by `angle` lands on a distinct high node, or
    None when the two sets cannot be paired one to one."""
    if len(low_nodes) != len(high_nodes) or len(low_nodes) == 0:
        return None
    rotated = points[low_nodes] @ rotation_z(angle).T
    idx, dist = nearest(rotated, points[high_nodes])
    if np.all(dist <= tol) and len(np.unique(idx)) == len(idx):
        return len(idx)
    return None


# --------------------------------------------------------------------------- reading
class Sets:
    """Named sets found in a meshio mesh, in original point indices."""

    def __init__(self):
        self.node = {}    # name -> point indices
        self.face = {}    # name -> (k, 3) corner nodes of triangles
        self.volume = {}  # name -> number of volume cells (cannot make a face group)
        self.other = {}   # name -> description

    def names(self):
        return sorted(set(self.node) | set(self.face) | set(self.volume) | set(self.other))

    def add_face(self, name, tri):
        old = self.face.get(name)
        self.face[name] = tri if old is None else np.vstack([old, tri])


def collect_sets(mesh):
    sets = Sets()
    for name, idx in mesh.point_sets.items():
        sets.node[name] = np.unique(np.asarray(idx, dtype=np.int64))
    for name, data in mesh.point_data.items():
        arr = np.asarray(data)
        if arr.ndim == 1 and len(arr) and (arr.dtype.kind in "biuf") \
                and np.all((arr == 0) | (arr == 1)) and name not in sets.node:
            sets.node[name] = np.flatnonzero(arr)

    for name, blocks in mesh.cell_sets.items():
        for block, idx in zip(mesh.cells, blocks):
            idx = np.asarray(idx, dtype=np.int64)
            if idx.size == 0:
                continue
            if block.type in TRI_TYPES:
                sets.add_face(name, block.data[idx, :3])
            elif block.type.startswith(OTHER_VOLUME_PREFIXES):
                sets.volume[name] = sets.volume.get(name, 0) + idx.size
            else:
                sets.other[name] = f"{block.type} cells"

    # Integer cell data on triangles: gmsh physical names, or KEY=VALUE.
    tag_names = {}
    for fname, value in mesh.field_data.items():
        value = np.asarray(value).ravel()
        if len(value) >= 2 and int(value[1]) == 2:
            tag_names[int(value[0])] = fname
    for key, blocks in mesh.cell_data.items():
        for block, values in zip(mesh.cells, blocks):
            values = np.asarray(values)
            if block.type not in TRI_TYPES or values.ndim != 1 or values.dtype.kind not in "iu":
                continue
            unique = np.unique(values)
            if len(unique) > 1000:   # element ids or the like, not group tags
                continue
            for value in unique:
                tri = block.data[values == value, :3]
                if key == "gmsh:physical" and int(value) in tag_names:
                    sets.add_face(tag_names[int(value)], tri)
                if key != "gmsh:geometrical":
                    sets.add_face(f"{key}={int(value)}", tri)
    return sets


def read_tets(mesh, path):
    """The tetrahedra in gmsh node ordering, and their node count."""
    blocks = [b for b in mesh.cells if b.type in TET_TYPES]
    others = {}
    for b in mesh.cells:
        if b.type not in TET_TYPES and b.type.startswith(OTHER_VOLUME_PREFIXES):
            others[b.type] = others.get(b.type, 0) + len(b.data)
    if others:
        desc = ", ".join(f"{n} {t}" for t, n in sorted(others.items()))
        raise InputError(f"only tetrahedral meshes are supported; {path} holds {desc}")
    sizes = sorted({TET_TYPES[b.type] for b in blocks})
    if not sizes:
        raise InputError(f"{path} holds no tetrahedra (cells: "
                         f"{', '.join(sorted({b.type for b in mesh.cells})) or 'none'})")
    if len(sizes) > 1:
        raise InputError(f"{path} mixes 4-node and 10-node tetrahedra")
    tets = np.vstack([np.asarray(b.data, dtype=np.int64) for b in blocks])
    if sizes[0] == 10:
        tets = tets[:, MESHIO_TO_GMSH_TET10]
    return tets, tets.shape[1]


def parse_maps(items):
    maps = []
    for item in items or []:
        src, sep, dst = item.rpartition("=")
        if not sep or not src or not dst:
            raise InputError(f"--map {item!r}: expected NAME=GROUP")
        if dst not in SURFACE_GROUPS:
            raise InputError(f"--map {item!r}: unknown group {dst!r} "
                             f"(groups: {', '.join(SURFACE_GROUPS)})")
        maps.append((src, dst))
    return maps


def find_set(sets, name):
    """Exact name first, then case-insensitive. Returns (kind, name) or None."""
    for exact in (True, False):
        for kind, table in (("face", sets.face), ("node", sets.node),
                            ("volume", sets.volume), ("other", sets.other)):
            for key in table:
                if (key == name) if exact else (key.lower() == name.lower()):
                    return kind, key
    return None


# --------------------------------------------------------------------------- to-msh
def atomic_write(out_path, writer):
    out_dir = os.path.dirname(os.path.abspath(out_path))
    fd, tmp = tempfile.mkstemp(dir=out_dir, prefix="." + os.path.basename(out_path) + ".",
                               suffix=".tmp")
    os.close(fd)
    try:
        writer(tmp)
        os.chmod(tmp, 0o644)
        os.replace(tmp, out_path)
    except BaseException as exc:
        if os.path.exists(tmp):
            os.unlink(tmp)
        if isinstance(exc, OSError):
            raise InputError(f"{out_path}: cannot write ({exc.strerror or exc})") from None
        raise


# Abaqus element types meshio 5.0 does not know (gmsh's own .inp export writes CPS6 for
# triangle6, for instance). Added to meshio's table only when missing.
EXTRA_ABAQUS_TYPES = {
    "CPS6": "triangle6", "CPS6M": "triangle6", "CPE6M": "triangle6", "M3D3": "triangle",
    "M3D6": "triangle6", "SFM3D3": "triangle", "SFM3D6": "triangle6", "S3T": "triangle",
    "C3D4T": "tetra", "DC3D4": "tetra", "C3D10T": "tetra10", "C3D10HS": "tetra10",
    "C3D10MT": "tetra10", "DC3D10": "tetra10",
}


def extend_abaqus_types():
    try:
        from meshio.abaqus import _abaqus
    except ImportError:
        return
    for name, cell_type in EXTRA_ABAQUS_TYPES.items():
        _abaqus.abaqus_to_meshio_type.setdefault(name, cell_type)


def read_input(path, file_format):
    """meshio.read, but its failures (it prints and calls sys.exit) become InputError."""
    if not os.path.isfile(path):
        raise InputError(f"{path}: no such file")
    extend_abaqus_types()
    printed = io.StringIO()
    try:
        with contextlib.redirect_stdout(printed), contextlib.redirect_stderr(printed):
            return meshio.read(path, file_format=file_format)
    except (Exception, SystemExit) as exc:  # meshio raises many kinds, or exits
        detail = " ".join(printed.getvalue().split()) or f"{type(exc).__name__}: {exc}"
        raise InputError(f"{path}: cannot read ({detail})") from None


def to_msh(args):
    path = args.input
    maps = parse_maps(args.map)
    if args.sectors is not None and args.sectors < 2:
        raise InputError(f"--sectors {args.sectors}: need at least 2 sectors")
    if not os.path.isdir(os.path.dirname(os.path.abspath(args.output))):
        raise InputError(f"{args.output}: output folder does not exist")
    mesh = read_input(path, args.format)
    points = np.asarray(mesh.points, dtype=float)
    if points.shape[1] != 3:
        raise InputError(f"{path}: points are {points.shape[1]}-dimensional, need 3D")
    tets, npe = read_tets(mesh, path)
    sets = collect_sets(mesh)

    # Resolve the groups before any heavy work, so a missing one fails fast.
    sources = {g: [] for g in SURFACE_GROUPS}
    problems = []
    for src, dst in maps:
        found = find_set(sets, src)
        if found is None:
            problems.append(f"--map {src}={dst}: no set named {src!r}")
        else:
            sources[dst].append(found)
    for g in SURFACE_GROUPS:
        if not sources[g]:
            found = find_set(sets, g)
            if found is not None:
                sources[g].append(found)
    missing = [g for g in SURFACE_GROUPS if not sources[g]]
    for g in SURFACE_GROUPS:
        for kind, name in sources[g]:
            if kind == "volume":
                problems.append(f"set {name!r} for {g} holds volume elements, not faces "
                                "(give a node set or a set of surface triangles)")
            elif kind == "other":
                problems.append(f"set {name!r} for {g} holds {sets.other[name]}, not "
                                "triangles")
    if missing or problems:
        parts = []
        if missing:
            parts.append("missing group(s) " + ", ".join(missing))
        parts.extend(problems)
        names = sets.names()
        avail = ", ".join(names[:20]) + (f", ... ({len(names) - 20} more)"
                                         if len(names) > 20 else "") if names else "none"
        raise InputError(f"{path}: " + "; ".join(parts) + f" (sets in the input: {avail}; "
                         "name them with --map NAME=GROUP)")

    # Element checks: midside ordering, orientation.
    n_reordered = 0
    if npe == 10:
        try:
            tets, n_reordered, worst = fix_midside_order(points, tets)
        except InputError as exc:
            raise InputError(f"{path}: {exc}") from None
        if worst > 0.25:
            warn(f"{path}: a midside node lies {worst:.2f} edge lengths from its edge "
                 "midpoint (strongly curved element)")
    vol = signed_volumes(points, tets)
    scale = np.ptp(points[np.unique(tets[:, :4])], axis=0).max() if len(tets) else 0.0
    # Degenerate: |6V| tiny against the cube of the element's longest edge.
    corners = points[tets[:, :4]]
    longest = np.zeros(len(tets))
    for i, j in ((0, 1), (1, 2), (0, 2), (0, 3), (2, 3), (1, 3)):
        longest = np.maximum(longest, np.linalg.norm(corners[:, i] - corners[:, j], axis=1))
    degenerate = np.abs(vol) <= 1e-10 * longest ** 3
    if np.any(degenerate):
        raise InputError(f"{path}: {int(np.count_nonzero(degenerate))} tetrahedra have "
                         f"zero volume (first: element {int(np.flatnonzero(degenerate)[0]) + 1})")
    negative = vol < 0
    n_reoriented = int(np.count_nonzero(negative))
    tets[negative] = tets[negative][:, REORIENT[npe]]

    try:
        faces, keys = boundary_faces(tets)
    except InputError as exc:
        raise InputError(f"{path}: {exc}") from None
    used = np.zeros(len(points), dtype=bool)
    used[tets.ravel()] = True
    group_faces = {}
    for g in SURFACE_GROUPS:
        chosen = []
        for kind, name in sources[g]:
            if kind == "node":
                idx = sets.node[name]
                if idx.size and (idx.min() < 0 or idx.max() >= len(points)):
                    raise InputError(f"{path}: node set {name!r} refers to missing nodes")
                in_set = np.zeros(len(points), dtype=bool)
                in_set[idx] = True
                hit = np.flatnonzero(np.all(in_set[faces[:, :3]], axis=1))
                if hit.size == 0:
                    raise InputError(f"{path}: group {g}: node set {name!r} contains no "
                                     "boundary face (all three corners in the set)")
                covered = np.zeros(len(points), dtype=bool)
                covered[faces[hit].ravel()] = True
                loose = int(np.count_nonzero(in_set & used & ~covered))
                if loose:
                    warn(f"{path}: group {g}: {loose} of {idx.size} nodes of set {name!r} "
                         "lie on no boundary face of the group")
                chosen.append(hit)
            else:
                tri = np.sort(sets.face[name], axis=1)
                hit = match_rows(tri, keys)
                if np.any(hit < 0):
                    raise InputError(f"{path}: group {g}: {int(np.count_nonzero(hit < 0))} "
                                     f"of {len(hit)} triangles of set {name!r} are not "
                                     "boundary faces of the tetrahedra")
                chosen.append(hit)
        group_faces[g] = np.unique(np.concatenate(chosen))

    owner = {}
    for g in SURFACE_GROUPS:
        for f in group_faces[g]:
            owner.setdefault(int(f), []).append(g)
    shared = {}
    for groups in owner.values():
        if len(groups) > 1:
            shared[" and ".join(groups)] = shared.get(" and ".join(groups), 0) + 1
    for groups, n in shared.items():
        warn(f"{path}: {n} boundary faces belong to both {groups}")
    for low, high in (("cyclic_low", "cyclic_high"), ("shroud_low", "shroud_high")):
        nl = len(np.unique(faces[group_faces[low]]))
        nh = len(np.unique(faces[group_faces[high]]))
        if nl != nh:
            warn(f"{path}: {low} has {nl} nodes but {high} has {nh}; they cannot be "
                 "paired node for node")

    # Cyclic / shroud pairing check.
    pair_note = ""
    if args.sectors is not None:
        alpha = 2.0 * math.pi / args.sectors
        tol = 1e-6 * max(scale, 1e-300)
        notes = []
        for low, high in (("cyclic_low", "cyclic_high"), ("shroud_low", "shroud_high")):
            ln = np.unique(faces[group_faces[low]])
            hn = np.unique(faces[group_faces[high]])
            n = count_pairs(points, ln, hn, alpha, tol)
            if n is None:
                hint = ""
                if count_pairs(points, ln, hn, -alpha, tol) is not None:
                    hint = f" ({high} is {low} rotated by -alpha: swap the two names)"
                raise InputError(
                    f"{path}: {high} ({len(hn)} nodes) is not {low} ({len(ln)} nodes) "
                    f"rotated by +2*pi/{args.sectors} about z{hint}")
            notes.append(f"{low.split('_')[0]} pairs {n}")
        pair_note = f"; Nb={args.sectors}: " + ", ".join(notes)

    # Drop unused nodes and renumber.
    new_index = np.full(len(points), -1, dtype=np.int64)
    new_index[used] = np.arange(int(np.count_nonzero(used)))
    n_dropped = len(points) - int(np.count_nonzero(used))
    out_points = points[used]
    tet_type = "tetra" if npe == 4 else "tetra10"
    tri_type = "triangle" if npe == 4 else "triangle6"
    out_tets = new_index[tets]
    if npe == 10:
        out_tets = out_tets[:, MESHIO_TO_GMSH_TET10]   # meshio order; the writer swaps back
    cells = [(tet_type, out_tets)]
    physical = [np.full(len(tets), PHYSICAL_TAG[VOLUME_GROUP], dtype=np.int32)]
    elementary = [np.full(len(tets), 1, dtype=np.int32)]
    for i, g in enumerate(SURFACE_GROUPS):
        tri = new_index[faces[group_faces[g]]]
        cells.append((tri_type, tri))
        physical.append(np.full(len(tri), PHYSICAL_TAG[g], dtype=np.int32))
        elementary.append(np.full(len(tri), i + 1, dtype=np.int32))
    field_data = {VOLUME_GROUP: np.array([PHYSICAL_TAG[VOLUME_GROUP], 3])}
    field_data.update({g: np.array([PHYSICAL_TAG[g], 2]) for g in SURFACE_GROUPS})
    out = meshio.Mesh(out_points, cells,
                      cell_data={"gmsh:physical": physical, "gmsh:geometrical": elementary},
                      field_data=field_data)
    atomic_write(args.output, lambda tmp: meshio.gmsh.write(
        tmp, out, fmt_version="2.2", binary=False))

    counts = " ".join(f"{g}={len(group_faces[g])}" for g in SURFACE_GROUPS)
    print(f"{PROG}: {args.output}: {len(out_points)} nodes, {len(tets)} {tet_type} "
          f"elements; {tri_type}s {counts}; reoriented {n_reoriented} negative-volume "
          f"tets, reordered midside nodes of {n_reordered} tets, dropped {n_dropped} "
          f"unused nodes{pair_note}")
    return 0


# --------------------------------------------------------------------------- to-vtu
def to_vtu(args):
    path = args.input
    if not os.path.isdir(os.path.dirname(os.path.abspath(args.output))):
        raise InputError(f"{args.output}: output folder does not exist")
    mesh = read_input(path, "gmsh")
    physical = mesh.cell_data.get("gmsh:physical")
    elementary = mesh.cell_data.get("gmsh:geometrical")
    if physical is None:
        warn(f"{path}: no physical tags; physical_id is 0")
        physical = [np.zeros(len(b.data), dtype=np.int32) for b in mesh.cells]
    if elementary is None:
        elementary = [np.zeros(len(b.data), dtype=np.int32) for b in mesh.cells]
    names = {}
    for fname, value in mesh.field_data.items():
        value = np.asarray(value).ravel()
        if len(value) >= 2:
            names[(int(value[1]), int(value[0]))] = fname

    cells, phys_out, elem_out = [], [], []
    flags = {}
    n_volume = 0
    for block, phys, elem in zip(mesh.cells, physical, elementary):
        phys = np.asarray(phys, dtype=np.int32)
        is_volume = block.type.startswith(OTHER_VOLUME_PREFIXES)
        is_tri = block.type in TRI_TYPES
        if is_volume or (args.surfaces and is_tri):
            cells.append((block.type, block.data))
            phys_out.append(phys)
            elem_out.append(np.asarray(elem, dtype=np.int32))
            n_volume += len(block.data) if is_volume else 0
        if is_tri:
            for tag in np.unique(phys):
                name = names.get((2, int(tag)), f"physical_{int(tag)}")
                flag = flags.setdefault(name, np.zeros(len(mesh.points), dtype=np.int32))
                flag[np.asarray(block.data)[phys == tag].ravel()] = 1
    if n_volume == 0:
        raise InputError(f"{path}: no volume cells")
    out = meshio.Mesh(mesh.points, cells, point_data=flags,
                      cell_data={"physical_id": phys_out, "elementary_id": elem_out})
    atomic_write(args.output, lambda tmp: meshio.vtu.write(tmp, out))
    types = ", ".join(sorted({t for t, _ in cells}))
    flag_note = " ".join(f"{k}={int(v.sum())}" for k, v in sorted(flags.items()))
    print(f"{PROG}: {args.output}: {len(mesh.points)} nodes, {n_volume} volume cells "
          f"({types}); node flags {flag_note or 'none'}")
    return 0


# --------------------------------------------------------------------------- CLI
def build_parser():
    p = argparse.ArgumentParser(
        prog="convert_mesh.py",
        description=__doc__.split("\n\n", 1)[1],
        formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    m = sub.add_parser(
        "to-msh", help="any meshio-readable tet mesh with named sets -> shroudsim .msh",
        description="Convert a tetrahedral mesh with named node/face sets to gmsh MSH 2.2 "
                    "ASCII with physical groups sector (3D) and hub, cyclic_low, "
                    "cyclic_high, shroud_low, shroud_high (2D boundary triangles).")
    m.add_argument("input", help="input mesh (format from the extension, or --format)")
    m.add_argument("output", help="output .msh file")
    m.add_argument("--map", action="append", metavar="NAME=GROUP",
                   help="take input set NAME for GROUP (one of: " + ", ".join(SURFACE_GROUPS)
                        + "); repeatable, several sets for one group are united; "
                          "integer cell data sets are named KEY=VALUE, "
                          "e.g. --map nastran:ref=12=hub")
    m.add_argument("--sectors", type=int, metavar="Nb",
                   help="check that the high faces are the low faces rotated by +2*pi/Nb "
                        "about z, node for node")
    m.add_argument("--format", metavar="FMT",
                   help="meshio input format when the extension is ambiguous "
                        "(abaqus, nastran, vtu, gmsh, ...)")
    m.set_defaults(func=to_msh)
    v = sub.add_parser(
        "to-vtu", help=".msh -> .vtu for ParaView (physical ids, node flags per group)",
        description="Write the volume cells of a .msh file to .vtu with cell data "
                    "physical_id/elementary_id and a 0/1 point-data flag per named 2D "
                    "physical group.")
    v.add_argument("input", help="input .msh file")
    v.add_argument("output", help="output .vtu file")
    v.add_argument("--surfaces", action="store_true",
                   help="also write the boundary triangles of the 2D groups")
    v.set_defaults(func=to_vtu)
    return p


def main(argv=None):
    args = build_parser().parse_args(argv)  # usage errors exit 2
    try:
        return args.func(args)
    except InputError as exc:
        sys.stderr.write(f"{PROG}: error: {exc}\n")
        return 2
    except OSError as exc:
        sys.stderr.write(f"{PROG}: error: {exc}\n")
        return 2 if exc.filename else 1


if __name__ == "__main__":
    sys.exit(main())
