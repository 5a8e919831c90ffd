#!/usr/bin/env python3
"""Exactness as a property: generated hard scenes, every exact algorithm and variant against the
reference, metamorphic relations, and failures shrunk to a few triangles (docs/exactness_fuzzing.md).

    scripts/exactness_fuzz.py run --seconds S [--seed N] [--out DIR] [--corpus DIR]
    scripts/exactness_fuzz.py replay CASE.json ...      (the corpus: each case must hold)
    scripts/exactness_fuzz.py generate SEED             (the config one case runs, on stdout)

Each case is one config: a scene of `mesh` objects (triangles as written) built by the generator
from its seed, a camera and a light that move over a few frames, the reference and every exact
algorithm (default parameters) plus one more variant of each, drawn from that algorithm's list.
A wrong pixel of an exact id is a failure unless the id reported overflow (its pixels written
shadowed and counted: documented, not silent); line_space fails on a pixel it writes lit where
the reference is shadowed (it may only over-occlude). A failure is shrunk (objects, triangles,
frame, resolution) and written as a config plus its one-line reproduction.

Everything reaches `shadowlab` as a file and an argv array; nothing here goes through a shell.
"""
import argparse
import json
import math
import os
import random
import shutil
import struct
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_BINARY = os.path.join(ROOT, "build", "shadowlab")

# Variants a user can select that the docs call exact (docs/algorithms/*.md). Left out on purpose:
# front_face_culling / normal_cone_culling / volumes light_facing (exact for closed meshes only),
# psv wedge_bound vertices (the paper's, may be too narrow), shadow_volumes zpass (wrong with the
# eye inside a volume) and close_calls off (the papers' rasterised counts).
VARIANTS = {
    "psv": [{"traversal": "stack"}, {"traversal": "stackless"}, {"traversal": "hybrid", "hybrid_stack": 2},
            {"wedge": False}, {"wedge_bound": "exact"}, {"depth_skip": True}, {"random_order": False}],
    "metric_tree": [{"query": "pixel"}, {"capsules": False}, {"slabs": False}, {"overlap_interval": False},
                    {"depth_skip": False}, {"cluster_size": 2}, {"tile": "8x8"}, {"tree_builder": "cpu"}],
    "ptsv": [{"bounds": "implicit"}, {"culling_planes": False}, {"two_pass": False}, {"traversal": "invocation"},
             {"traversal": "cooperative"}, {"traversal": "packet"}, {"tile_size": 4}],
    "izb": [{"grid_fit": "samples"}, {"cell_test": False}, {"grid": 64}],
    "bvh_raytrace": [{"short_stack": True}, {"leaf_size": 1}, {"leaf_size": 16}],
    "shadow_volumes": [{"depth_test": "hardware"}],
}
ONE_SIDED = {"line_space": {"n": 6, "d": 3}}  # may write a lit pixel shadowed, never the reverse


def f32(x):
    """x rounded to the float the config reader will make of it (written with repr: exact)."""
    return struct.unpack("f", struct.pack("f", x))[0]


def vec(v):
    return [f32(c) for c in v]


# ---------------------------------------------------------------------------------------------
# The generator: a seeded draw of hard cases, weighted towards what has broken before (fences and
# thin posts at grazing light, slivers, shared edges, coplanar and duplicated triangles, cameras
# inside shadow volumes, spot cones cutting geometry, far offsets).

def add(a, b):
    return [a[0] + b[0], a[1] + b[1], a[2] + b[2]]


def scale(a, s):
    return [a[0] * s, a[1] * s, a[2] * s]


def rand_dir(rng):
    z = rng.uniform(-1, 1)
    phi = rng.uniform(0, 2 * math.pi)
    s = math.sqrt(max(0.0, 1 - z * z))
    return [s * math.cos(phi), s * math.sin(phi), z]


def box(lo, hi):
    """A closed box, wound counter-clockwise seen from outside."""
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    c = [[x0, y0, z0], [x1, y0, z0], [x1, y1, z0], [x0, y1, z0], [x0, y0, z1], [x1, y0, z1], [x1, y1, z1], [x0, y1, z1]]
    quads = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (3, 7, 6, 2), (0, 4, 7, 3), (1, 2, 6, 5)]
    tris = []
    for a, b, cc, d in quads:
        tris += [[c[a], c[b], c[cc]], [c[a], c[cc], c[d]]]
    return tris


def ground(rng, size):
    h = size / 2
    return [[[-h, 0, -h], [-h, 0, h], [h, 0, h]], [[-h, 0, -h], [h, 0, h], [h, 0, -h]]]


def soup(rng, n, extent):
    tris = []
    for _ in range(n):
        size = math.exp(rng.uniform(math.log(0.02), math.log(3.0)))
        c = [rng.uniform(-extent, extent), rng.uniform(0.05, extent), rng.uniform(-extent, extent)]
        if rng.random() < 0.25:  # a sliver: the third vertex near the first edge
            a, b = add(c, scale(rand_dir(rng), size)), add(c, scale(rand_dir(rng), -size))
            t = rng.random()
            off = scale(rand_dir(rng), size * 10 ** rng.uniform(-4, -2))
            tris.append([a, b, add(add(scale(a, 1 - t), scale(b, t)), off)])
        else:
            tris.append([add(c, scale(rand_dir(rng), size / math.sqrt(3))) for _ in range(3)])
    return tris


def posts(rng):
    """Thin posts (closed boxes) and rails: the fence that once had wrong pixels at 512²."""
    tris = []
    count = rng.randint(2, 8)
    width = 10 ** rng.uniform(-2.5, -1.3)
    height = rng.uniform(0.5, 2)
    spacing = rng.uniform(0.1, 0.6)
    for i in range(count):
        x = (i - (count - 1) / 2) * spacing
        tris += box([x - width, 0, -width], [x + width, height, width])
    if rng.random() < 0.7:
        x0 = -(count - 1) / 2 * spacing
        y = height * rng.uniform(0.3, 0.9)
        tris += box([x0, y - width, -width], [-x0, y + width, width])
    return tris


def fan(rng):
    """Triangles sharing one edge at random angles (shared edges at every angle)."""
    a, b = [0, rng.uniform(0.2, 1.0), 0], [rng.uniform(-1, 1), rng.uniform(0.2, 1.5), rng.uniform(-1, 1)]
    tris = []
    for _ in range(rng.randint(2, 6)):
        d = rand_dir(rng)
        tris.append([a, b, add(a, scale(d, rng.uniform(0.3, 1.2)))])
    return tris


def coplanar(rng):
    """Coplanar, touching, duplicated and T-junctioned triangles in one tilted plane."""
    y = rng.uniform(0.3, 1.5)
    tris = []
    for _ in range(rng.randint(2, 6)):
        c = [rng.uniform(-1, 1), y, rng.uniform(-1, 1)]
        s = rng.uniform(0.2, 1.0)
        tris.append([c, add(c, [s, 0, rng.uniform(-s, s)]), add(c, [rng.uniform(-s, s), 0, s])])
    t = tris[0]
    mid = scale(add(t[0], t[1]), 0.5)
    tris.append([t[0], mid, add(mid, [0, 0, -0.4])])  # T-junction on the first triangle's edge
    tris.append([t[1], mid, add(mid, [0, 0, -0.4])])
    if rng.random() < 0.5:
        tris.append(list(t))                 # duplicated
    if rng.random() < 0.5:
        tris.append([t[0], t[2], t[1]])      # duplicated, flipped
    tilt = rng.uniform(0, 0.6)
    return [[[v[0], v[1] + tilt * v[0], v[2]] for v in tri] for tri in tris]


def sheet(rng):
    """An open, bent grid of quads (a heightfield)."""
    n = rng.randint(2, 5)
    s = rng.uniform(0.5, 2.0)
    y0 = rng.uniform(0.3, 1.5)
    amp = rng.uniform(0, 0.5)
    p = [[[(i / n - 0.5) * s, y0 + amp * math.sin(i + j), (j / n - 0.5) * s] for j in range(n + 1)] for i in range(n + 1)]
    tris = []
    for i in range(n):
        for j in range(n):
            tris += [[p[i][j], p[i][j + 1], p[i + 1][j + 1]], [p[i][j], p[i + 1][j + 1], p[i + 1][j]]]
    return tris


def closed_shape(rng):
    """A box or octahedron: closed, later put under a non-uniform (sometimes mirroring) scale."""
    if rng.random() < 0.5:
        return box([-0.3, 0, -0.3], [0.3, 0.6, 0.3])
    v = [[0.4, 0.4, 0], [-0.4, 0.4, 0], [0, 0.8, 0], [0, 0, 0], [0, 0.4, 0.4], [0, 0.4, -0.4]]
    faces = [(0, 2, 4), (4, 2, 1), (1, 2, 5), (5, 2, 0), (0, 4, 3), (4, 1, 3), (1, 5, 3), (5, 0, 3)]
    return [[v[a], v[b], v[c]] for a, b, c in faces]


def roof(rng):
    """A large quad over part of the scene: cameras under it look out of its shadow volume."""
    y = rng.uniform(0.8, 2.0)
    s = rng.uniform(0.8, 2.5)
    return [[[-s, y, -s], [-s, y, s], [s, y, s]], [[-s, y, -s], [s, y, s], [s, y, -s]]]


PARTS = [(soup, 3), (posts, 3), (fan, 2), (coplanar, 2), (sheet, 2), (closed_shape, 2), (roof, 1)]


def pick(rng, weighted):
    total = sum(w for _, w in weighted)
    r = rng.uniform(0, total)
    for item, w in weighted:
        r -= w
        if r <= 0:
            return item
    return weighted[-1][0]


def area2(t):
    a = [t[1][i] - t[0][i] for i in range(3)]
    b = [t[2][i] - t[0][i] for i in range(3)]
    c = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    return math.sqrt(sum(x * x for x in c))


def mesh_object(tris, transform=None, path=None):
    obj = {"tris": [[vec(v) for v in t] for t in tris]}
    obj["tris"] = [t for t in obj["tris"] if area2(t) > 1e-12]
    if transform:
        obj["transform"] = transform
    if path:
        obj["path"] = path
    return obj


def generate(seed):
    """The case of `seed`: a dict of scene objects, camera, light, frames and resolution."""
    rng = random.Random(seed)
    frames = 6  # a run's fixed cost (context, shader compilation) is shared by its frames
    objects = []
    if rng.random() < 0.85:
        objects.append(mesh_object(ground(rng, rng.uniform(4, 12))))
    for _ in range(rng.randint(1, 4)):
        part = pick(rng, PARTS)
        tris = part(rng, rng.randint(1, 40), rng.uniform(0.5, 2)) if part is soup else part(rng)
        transform = {"translate": vec([rng.uniform(-1, 1), 0, rng.uniform(-1, 1)]),
                     "rotate_deg": vec([0, rng.uniform(0, 360), 0])}
        if part is closed_shape or rng.random() < 0.2:  # non-uniform, sometimes mirroring
            transform["scale"] = vec([rng.choice([-1, 1]) * rng.uniform(0.3, 3) for _ in range(3)])
        path = None
        if rng.random() < 0.15:  # a moving part
            path = {"interpolation": "linear",
                    "keyframes": [{"time": float(f), "translate": vec([0.3 * f * rng.uniform(-1, 1), 0, 0.2 * f])}
                                  for f in range(frames)]}
        objects.append(mesh_object(tris, transform, path))
    objects = [o for o in objects if o["tris"]]

    kind = pick(rng, [("point", 4), ("spot", 3), ("directional", 2)])
    light = {"type": kind}
    placement = pick(rng, [("above", 5), ("clutter", 2), ("grazing", 2), ("near_surface", 1)])
    keys = []
    for f in range(frames):
        if placement == "above":
            pos = [rng.uniform(-3, 3), rng.uniform(1.5, 5), rng.uniform(-3, 3)]
        elif placement == "clutter":
            pos = [rng.uniform(-1, 1), rng.uniform(0.2, 1.5), rng.uniform(-1, 1)]
        elif placement == "grazing":
            a = rng.uniform(0, 2 * math.pi)
            pos = [6 * math.cos(a), 6 * math.tan(math.radians(rng.uniform(0.3, 6))), 6 * math.sin(a)]
        else:
            pos = [rng.uniform(-2, 2), 10 ** rng.uniform(-3, -1), rng.uniform(-2, 2)]
        target = [rng.uniform(-1, 1), rng.uniform(0, 0.5), rng.uniform(-1, 1)]
        keys.append({"time": float(f), "position": vec(pos), "target": vec(target)})
    light["path"] = {"keyframes": keys}
    if kind == "spot":
        light["cone_deg"] = f32(rng.uniform(8, 70))

    cam_keys = []
    where = pick(rng, [("orbit", 6), ("under_roof", 2), ("low", 2)])
    for f in range(frames):
        if where == "orbit":
            d = rand_dir(rng)
            pos = scale([d[0], abs(d[1]) + 0.2, d[2]], rng.uniform(3, 7))
        elif where == "under_roof":
            pos = [rng.uniform(-0.7, 0.7), rng.uniform(0.3, 0.7), rng.uniform(-0.7, 0.7)]
        else:
            pos = [rng.uniform(-4, 4), rng.uniform(0.05, 0.4), rng.uniform(-4, 4)]
        target = [rng.uniform(-0.5, 0.5), rng.uniform(0, 0.5), rng.uniform(-0.5, 0.5)]
        if where == "under_roof":
            target = add(pos, [rng.uniform(-1, 1), rng.uniform(-0.6, 0.1), rng.uniform(-1, 1)])
        cam_keys.append({"time": float(f), "position": vec(pos), "target": vec(target)})

    offset = None
    if rng.random() < 0.1:  # far from the origin: everything moved, the sizes made to fit
        offset = vec([rng.choice([-1, 1]) * 10 ** rng.uniform(4, 5.5) for _ in range(3)])
    return {"seed": seed, "frames": frames, "resolution": rng.choice([[48, 48], [64, 48], [64, 64]]),
            "objects": objects, "light": light, "camera": {"fov_y_deg": f32(rng.uniform(30, 90)), "keys": cam_keys},
            "offset": offset}


def moved(p, offset, factor):
    return vec([p[i] * factor + offset[i] for i in range(3)]) if offset else p


def to_config(case, algorithms, name="exactness case"):
    """The experiment config of a case: its objects as `mesh` objects, the given algorithms."""
    offset = case.get("offset")
    # A far scene is made larger so its objects keep 1 % of their size above the float spacing
    # there (docs/scene.md); 2^k keeps the scaling exact.
    factor = 2.0 ** math.ceil(math.log2(max(abs(c) for c in offset) / 1e3)) if offset else 1.0
    objects = []
    for o in case["objects"]:
        obj = {"procedural": "mesh", "vertices": [moved(v, None, 1) for t in o["tris"] for v in t]}
        transform = dict(o.get("transform", {}))
        if offset:
            tr = transform.get("translate", [0, 0, 0])
            transform["translate"] = moved(tr, offset, factor)
            sc = transform.get("scale", 1.0)
            transform["scale"] = [c * factor for c in sc] if isinstance(sc, list) else sc * factor
        if transform:
            obj["transform"] = transform
        if "path" in o:
            path = json.loads(json.dumps(o["path"]))
            if offset:  # the path moves the placed object: its offsets scale with the scene
                for k in path["keyframes"]:
                    k["translate"] = vec([c * factor for c in k["translate"]])
            obj["path"] = path
        objects.append(obj)
    light = json.loads(json.dumps(case["light"]))
    for k in light["path"]["keyframes"]:
        k["position"] = moved(k["position"], offset, factor)
        k["target"] = moved(k["target"], offset, factor)
    cam_keys = [{"time": k["time"], "position": moved(k["position"], offset, factor),
                 "target": moved(k["target"], offset, factor)} for k in case["camera"]["keys"]]
    near = 0.01 * factor
    return {
        "name": name,
        "resolution": case["resolution"],
        "frames": case["frames"],
        "warmup_frames": 0,
        "statistics": "none",
        "scene": {"objects": objects},
        "camera": {"fov_y_deg": case["camera"]["fov_y_deg"], "near": near, "far": 200 * factor,
                   "path": {"keyframes": cam_keys}},
        "light": light,
        "reference": True,
        "algorithms": algorithms,
        "output": {"images_at_frames": [], "plots": False},
    }


# ---------------------------------------------------------------------------------------------
# The differential runner.

class Shadowlab:
    def __init__(self, binary, workdir):
        self.binary = binary
        self.workdir = workdir
        self.runs = 0
        listing = json.loads(subprocess.run([binary, "list", "--json"], check=True, capture_output=True, text=True).stdout)
        self.algorithms = {a["name"]: a for a in listing}

    def exact(self):
        return [n for n, a in self.algorithms.items() if a["exact"] and n != "reference"]

    def takes(self, name, case):
        a = self.algorithms[name]
        if case["light"]["type"] not in a["lights"]:
            return False
        moving = any("path" in o for o in case["objects"])
        return not moving or a["motion"] != "static_only"

    def run(self, config):
        """Runs a config; returns (exit code, summary or None, stderr)."""
        self.runs += 1
        d = tempfile.mkdtemp(dir=self.workdir)
        try:
            cfg = os.path.join(d, "case.json")
            with open(cfg, "w") as f:
                json.dump(config, f)
            out = os.path.join(d, "out")
            p = subprocess.run([self.binary, "run", cfg, "--out", out, "--no-progress"], capture_output=True, text=True,
                               stdin=subprocess.DEVNULL)
            summary = None
            if os.path.exists(os.path.join(out, "summary.json")):
                with open(os.path.join(out, "summary.json")) as f:
                    summary = json.load(f)
            return p.returncode, summary, p.stderr
        finally:
            shutil.rmtree(d, ignore_errors=True)


def entries_for(sl, case, rng, every_variant=False):
    """The algorithm entries a case runs: each exact algorithm that takes its light and motion at
    its defaults, plus one variant of it drawn by `rng` (or all of them), and line_space."""
    out = []
    for name in sl.exact():
        if not sl.takes(name, case):
            continue
        out.append({"id": name, "algorithm": name})
        variants = VARIANTS.get(name, [])
        chosen = variants if every_variant else ([rng.choice(variants)] if variants else [])
        for v in chosen:
            vid = name + "." + "_".join(f"{k}-{str(x).lower()}" for k, x in v.items())
            out.append({"id": vid, "algorithm": name, "params": v})
    for name, params in ONE_SIDED.items():
        if name in sl.algorithms and sl.takes(name, case):
            out.append({"id": name, "algorithm": name, "params": params})
    return out


def failures(summary, entries):
    """[(id, frame list, first wrong pixel, kind)] of the ids that broke their property."""
    found = []
    for e in entries:
        s = summary["algorithms"].get(e["id"])
        acc = s and s.get("accuracy")
        if not acc:
            continue
        one_sided = e["algorithm"] in ONE_SIDED
        wrong = acc["false_lit_pixels"] if one_sided else acc["false_lit_pixels"] + acc["false_shadowed_pixels"]
        if wrong == 0:
            continue
        kind = "overflow" if s.get("overflow", 0) else ("false_lit" if one_sided else "wrong")
        frames = [f for f, n in enumerate(acc["per_frame_wrong_pixels"]) if n]  # null: a frame not measured
        found.append({"id": e["id"], "entry": e, "frames": frames, "pixel": acc["first_wrong_pixel"], "kind": kind,
                      "false_lit": acc["false_lit_pixels"], "false_shadowed": acc["false_shadowed_pixels"]})
    return found


# ---------------------------------------------------------------------------------------------
# Shrinking: delta debugging (Zeller's ddmin) over the objects, then the triangles, then one frame,
# then smaller resolutions; every step is kept only if the same id still fails the same way.

def ddmin(items, fails):
    """A 1-minimal sublist of `items` for which fails(sublist) holds (fails(items) must hold)."""
    n = 2
    while len(items) >= 2:
        chunk = math.ceil(len(items) / n)
        subsets = [items[i:i + chunk] for i in range(0, len(items), chunk)]
        reduced = False
        for i, s in enumerate(subsets):  # a subset alone
            if fails(s):
                items, n, reduced = s, 2, True
                break
        if not reduced:
            for i in range(len(subsets)):  # a complement
                rest = [x for j, s in enumerate(subsets) if j != i for x in s]
                if fails(rest):
                    items, n, reduced = rest, max(n - 1, 2), True
                    break
        if not reduced:
            if n >= len(items):
                break
            n = min(len(items), 2 * n)
    return items


def with_triangles(case, keep):
    """The case with only the (object, triangle) pairs in `keep`; objects left empty are dropped."""
    c = json.loads(json.dumps(case))
    objects = []
    for i, o in enumerate(c["objects"]):
        tris = [t for j, t in enumerate(o["tris"]) if (i, j) in keep]
        if tris:
            o["tris"] = tris
            objects.append(o)
    c["objects"] = objects
    return c


def one_frame(case, f):
    """The case reduced to frame f: every path cut to its keyframe at f's time."""
    c = json.loads(json.dumps(case))
    c["frames"] = 1
    c["camera"]["keys"] = [c["camera"]["keys"][f]]
    c["light"]["path"]["keyframes"] = [c["light"]["path"]["keyframes"][f]]
    for o in c["objects"]:
        if "path" in o:
            o["path"]["keyframes"] = [o["path"]["keyframes"][f]]
    return c


def shrink(sl, case, failure, log=print):
    """The smallest case found on which failure's id still fails; returns (case, failure)."""
    entry = failure["entry"]
    last = {"failure": failure}

    def fails(c):
        if not c["objects"]:
            return False
        code, summary, _ = sl.run(to_config(c, [entry]))
        if code not in (0, 3) or summary is None:
            return False
        found = [f for f in failures(summary, [entry]) if f["kind"] == failure["kind"]]
        if found:
            last["failure"] = found[0]
        return bool(found)

    start = sl.runs
    if len(case["objects"]) > 1:
        keep = ddmin(list(range(len(case["objects"]))), lambda s: fails(dict(case, objects=[case["objects"][i] for i in s])))
        case = dict(case, objects=[case["objects"][i] for i in keep])
    pairs = [(i, j) for i, o in enumerate(case["objects"]) for j in range(len(o["tris"]))]
    keep = ddmin(pairs, lambda s: fails(with_triangles(case, set(s))))
    case = with_triangles(case, set(keep))
    fails(case)
    if case["frames"] > 1:
        for f in last["failure"]["frames"]:
            single = one_frame(case, f)
            if fails(single):
                case = single
                break
    for res in ([32, 32], [16, 16], [8, 8]):
        if res[0] * res[1] < case["resolution"][0] * case["resolution"][1]:
            smaller = dict(case, resolution=res)
            if fails(smaller):
                case = smaller
    fails(case)
    log(f"  shrunk {failure['id']} to {sum(len(o['tris']) for o in case['objects'])} triangles, "
        f"{case['frames']} frame(s), {case['resolution'][0]}x{case['resolution'][1]} in {sl.runs - start} runs")
    return case, last["failure"]


# ---------------------------------------------------------------------------------------------
# Metamorphic relations: rewrites of a case that do not change the scene it describes, so the
# reference and every exact algorithm must give the same image, bit for bit (summary.json's
# visibility_hash_per_frame). A relation the reference breaks is a reference bug.

def permuted(case, rng):
    c = json.loads(json.dumps(case))
    rng.shuffle(c["objects"])
    for o in c["objects"]:
        rng.shuffle(o["tris"])
    return c


def exact_midpoint(a, b):
    m = [f32((a[i] + b[i]) / 2) for i in range(3)]
    return m if all(m[i] == (a[i] + b[i]) / 2 for i in range(3)) else None


def split_along_median(case, rng):
    """One triangle replaced by its two halves along a median, where the edge's midpoint is a float
    (else the halves would not cover it exactly and the relation would not hold)."""
    c = json.loads(json.dumps(case))
    spots = [(i, j, k) for i, o in enumerate(c["objects"]) for j, t in enumerate(o["tris"]) for k in range(3)
             if exact_midpoint(t[k], t[(k + 1) % 3])]
    if not spots:
        return None
    i, j, k = rng.choice(spots)
    t = c["objects"][i]["tris"][j]
    a, b, d = t[k], t[(k + 1) % 3], t[(k + 2) % 3]
    m = exact_midpoint(a, b)
    c["objects"][i]["tris"][j:j + 1] = [[a, m, d], [m, b, d]]
    return c


def duplicated(case, rng):
    c = json.loads(json.dumps(case))
    o = rng.choice(c["objects"])
    o["tris"].append(list(rng.choice(o["tris"])))
    return c


RELATIONS = [("permute", permuted), ("split_median", split_along_median), ("duplicate", duplicated)]
# Parameters that must not change an image (the same walk, more or fewer at a time).
PARAM_RELATIONS = {"bvh_raytrace": {"samples_per_dispatch": 1, "stack_size": 256}, "psv": {"stack_size": 256},
                   "metric_tree": {"stack_size": 256}}


def hashes(summary, ids, frames):
    """Each id's visibility hashes of `frames` only."""
    out = {}
    for i in ids:
        if i in summary["algorithms"]:
            h = summary["algorithms"][i].get("visibility_hash_per_frame") or []
            out[i] = [h[f] if f < len(h) else None for f in frames]
    return out


def same_gbuffer_frames(a, b):
    """The frames whose G-buffers two runs share: a rewritten scene may settle a depth tie between
    coplanar overlapping triangles the other way (the rasteriser keeps the first drawn), and then
    the algorithms start from other points; their images are compared on the other frames."""
    ha, hb = a.get("gbuffer_hash_per_frame") or [], b.get("gbuffer_hash_per_frame") or []
    return [f for f in range(min(len(ha), len(hb))) if ha[f] == hb[f]]


def check_relations(sl, case, entries, base, rng, log):
    """Runs each relation once on `case`; returns the (relation, id) pairs whose image changed."""
    broken = []
    ids = ["reference"] + [e["id"] for e in entries if e["algorithm"] not in ONE_SIDED]
    for name, rewrite in RELATIONS:
        other = rewrite(case, rng)
        if other is None:
            continue
        code, summary, err = sl.run(to_config(other, entries))
        if summary is None:
            broken.append((name, "run", code, err.strip()[-300:]))
            continue
        # The rewritten case is a case too: every id must still match its reference.
        broken += [(name, f["id"], code, "wrong against its reference") for f in failures(summary, entries)
                   if f["kind"] != "overflow"]
        frames = same_gbuffer_frames(base, summary)
        want, got = hashes(base, ids, frames), hashes(summary, ids, frames)
        broken += [(name, i, code, "") for i in ids if got.get(i) != want.get(i)]
    params = [dict(e, id=e["id"] + ".same", params=dict(e.get("params", {}), **PARAM_RELATIONS[e["algorithm"]]))
              for e in entries if e["algorithm"] in PARAM_RELATIONS and "params" not in e]
    if params:
        code, summary, err = sl.run(to_config(case, params))
        if summary is not None:
            frames = same_gbuffer_frames(base, summary)
            want = hashes(base, ids, frames)
            got = hashes(summary, [p["id"] for p in params], frames)
            broken += [("params", p["id"], code, "") for p in params if got.get(p["id"]) != want.get(p["id"][:-5])]
    for b in broken:
        log(f"  relation {b[0]} changed the image of {b[1]} (exit {b[2]}) {b[3]}")
    return broken


# ---------------------------------------------------------------------------------------------
# Cases kept: a shrunk failure is an ordinary config whose expectations hold the property, so
# `shadowlab run CASE --out DIR` reproduces it (exit 3 while it fails) and the corpus replays it.

def corpus_config(case, failure):
    entry = failure["entry"]
    one_sided = entry["algorithm"] in ONE_SIDED
    px = failure.get("pixel") or {}
    cfg = to_config(case, [entry], name=f"exactness case {entry['id']} seed {case['seed']}")
    measure = "accuracy.false_lit" if one_sided else "accuracy.mismatch_ratio_max"
    cfg["expect"] = [{"id": entry["id"], "measure": measure, "max": 0,
                      "note": f"found by scripts/exactness_fuzz.py: {failure['kind']} at frame {px.get('frame')} "
                              f"pixel ({px.get('x')}, {px.get('y')}) (y up from the bottom row)"},
                     {"id": entry["id"], "measure": "overflow", "max": 0}]
    return cfg


def write_case(folder, case, failure):
    os.makedirs(folder, exist_ok=True)
    tris = sum(len(o["tris"]) for o in case["objects"])
    safe = "".join(ch if ch.isalnum() or ch in "-_." else "_" for ch in failure["id"])
    path = os.path.join(folder, f"seed{case['seed']}_{safe}.json")
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        json.dump(corpus_config(case, failure), f, indent=1)
        f.write("\n")
    os.replace(tmp, path)
    return path, tris


def replay(sl, paths, log=print):
    bad = 0
    for p in paths:
        d = tempfile.mkdtemp(dir=sl.workdir)
        try:
            r = subprocess.run([sl.binary, "run", p, "--out", os.path.join(d, "out"), "--no-progress"],
                               capture_output=True, text=True, stdin=subprocess.DEVNULL)
        finally:
            shutil.rmtree(d, ignore_errors=True)
        ok = r.returncode == 0
        bad += not ok
        log(f"{'ok  ' if ok else 'FAIL'} {p} (exit {r.returncode})"
            + ("" if ok else "\n" + r.stderr.strip()[-600:]))
    return bad


# ---------------------------------------------------------------------------------------------
# The campaign.

def campaign(args, sl, log=print):
    started = time.monotonic()
    stats = {"cases": 0, "scene_frames": 0, "algorithm_frames": 0, "refused": 0, "crashes": [], "failures": [],
             "relations_checked": 0, "relations_broken": [], "by_id": {}}
    seed = args.seed
    while time.monotonic() - started < args.seconds and (args.cases == 0 or stats["cases"] < args.cases):
        case = generate(seed)
        rng = random.Random(seed * 7919 + 1)
        entries = entries_for(sl, case, rng)
        if args.only:
            entries = [e for e in entries if e["algorithm"] in args.only]
        seed += 1
        if not case["objects"] or not entries:
            continue
        code, summary, err = sl.run(to_config(case, entries))
        if code == 2:  # the scene was refused (e.g. a triangle the far offset's precision erases)
            stats["refused"] += 1
            log(f"seed {case['seed']}: refused: {err.strip().splitlines()[-1][:200] if err.strip() else ''}")
            continue
        if summary is None or code not in (0, 3):
            stats["crashes"].append({"seed": case["seed"], "exit": code, "stderr": err.strip()[-400:]})
            log(f"seed {case['seed']}: exit {code}: {err.strip()[-400:]}")
            continue
        stats["cases"] += 1
        stats["scene_frames"] += case["frames"]
        stats["algorithm_frames"] += case["frames"] * len(entries)
        for e in entries:
            stats["by_id"].setdefault(e["id"], {"frames": 0, "failures": 0})["frames"] += case["frames"]
        found = failures(summary, entries)
        # Every algorithm wrong on the same first pixel: the reference is the odd one out.
        exact_found = [f for f in found if f["entry"]["algorithm"] not in ONE_SIDED]
        algorithms_wrong = {f["entry"]["algorithm"] for f in exact_found}
        against_reference = len(algorithms_wrong) >= 3 and len({json.dumps(f["pixel"]) for f in exact_found}) == 1
        if against_reference:
            log(f"seed {case['seed']}: {len(algorithms_wrong)} algorithms agree against the reference: suspect the reference")
        for f in found:
            stats["by_id"][f["id"]]["failures"] += 1
            log(f"seed {case['seed']}: {f['id']} {f['kind']}: {f['false_lit']} false lit, {f['false_shadowed']} "
                f"false shadowed, first at {f['pixel']}")
            record = {"seed": case["seed"], "id": f["id"], "kind": f["kind"], "against_reference": against_reference,
                      "false_lit": f["false_lit"],
                      "false_shadowed": f["false_shadowed"], "pixel": f["pixel"]}
            shrunk_of_id = sum(1 for r in stats["failures"] if r["id"] == f["id"] and "shrunk" in r)
            if args.shrink and f["kind"] != "overflow" and shrunk_of_id < args.shrinks_per_id:
                small, last = shrink(sl, case, f, log)
                path, tris = write_case(os.path.join(args.out, "found"), small, last)
                record.update({"shrunk": os.path.relpath(path, args.out), "triangles": tris})
                log(f"  reproduce: build/shadowlab run {path} --out /tmp/case")
            stats["failures"].append(record)
        if args.relations and stats["cases"] % args.relations == 0 and not found:
            stats["relations_checked"] += 1
            stats["relations_broken"] += [{"seed": case["seed"], "relation": b[0], "id": b[1]}
                                          for b in check_relations(sl, case, entries, summary, rng, log)]
    elapsed = time.monotonic() - started
    stats.update({"seconds": round(elapsed, 1), "first_seed": args.seed, "next_seed": seed, "runs": sl.runs,
                  "cases_per_hour": round(3600 * stats["cases"] / max(elapsed, 1e-9))})
    return stats


def print_stats(stats, log=print):
    log(f"\n{stats['cases']} cases ({stats['scene_frames']} scene x frame, {stats['algorithm_frames']} algorithm x frame) "
        f"in {stats['seconds']} s: {stats['cases_per_hour']} cases/hour; seeds {stats['first_seed']}..{stats['next_seed'] - 1}; "
        f"{stats['refused']} refused; {len(stats['crashes'])} crashed runs; {stats['relations_checked']} relation checks, "
        f"{len(stats['relations_broken'])} broken")
    log("by id: cases failed, frames checked")
    for i, s in sorted(stats["by_id"].items()):
        log(f"  {i:40s} {s['failures']:4d} failed, {s['frames']:6d} frames")
    for f in stats["failures"]:
        log(f"  seed {f['seed']} {f['id']} {f['kind']}" + (f" -> {f['shrunk']} ({f['triangles']} triangles)" if "shrunk" in f else ""))


MARK = ".exactness_fuzz"  # names a folder this script made, which a later run may write into again


def check_run_args(args, sl):
    """Why `run`'s arguments cannot be taken (None when they can): values out of range, unknown
    algorithms, and an --out that is a file or a folder of someone else's (not empty, no mark)."""
    if not (args.seconds > 0 and math.isfinite(args.seconds)):  # inf with --cases 0 would never end
        return f"--seconds must be a finite number greater than 0, got {args.seconds}"
    if args.cases < 0 or args.relations < 0 or args.shrinks_per_id < 0:
        return "--cases, --relations and --shrinks-per-id must be 0 or more"
    known = set(sl.exact()) | set(ONE_SIDED)
    unknown = [a for a in args.only if a not in known]
    if unknown:
        return f"--only: not an exact algorithm: {unknown[0][:60]!r} (exact: {', '.join(sorted(known))})"
    if not args.out:
        return "--out must name a folder"
    parent = os.path.dirname(os.path.abspath(args.out))
    if not os.path.lexists(args.out) and not os.path.isdir(parent):
        return f"--out {args.out[:200]!r}: its parent {parent[:200]!r} is not a folder"
    if os.path.lexists(args.out):
        if not os.path.isdir(args.out) or os.path.islink(args.out):
            return f"--out {args.out[:200]!r} is not a folder"
        if os.listdir(args.out) and not os.path.exists(os.path.join(args.out, MARK)):
            return f"--out {args.out[:200]!r} is a folder this script did not make and not empty: choose another"
    return None


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--binary", default=os.environ.get("SHADOWLAB", DEFAULT_BINARY))
    sub = p.add_subparsers(dest="command", required=True)
    r = sub.add_parser("run", help="generate cases for a time budget")
    r.add_argument("--seconds", type=float, required=True)
    r.add_argument("--seed", type=int, default=1)
    r.add_argument("--cases", type=int, default=0, help="stop after this many cases (0: the time budget only)")
    r.add_argument("--out", default="exactness_fuzz_out")
    r.add_argument("--only", nargs="*", default=[], help="algorithms to check (default: every exact one and line_space)")
    r.add_argument("--relations", type=int, default=4, help="check the metamorphic relations on every Nth case (0: never)")
    r.add_argument("--no-shrink", dest="shrink", action="store_false")
    r.add_argument("--shrinks-per-id", type=int, default=3,
                   help="failures of one id shrunk (the rest are recorded as found): a long campaign's time goes to new cases")
    r.add_argument("--expect-failure", action="store_true", help="exit 0 only if a failure was found and shrunk (self-test)")
    rp = sub.add_parser("replay", help="run corpus cases; each must meet its expectations")
    rp.add_argument("cases", nargs="+")
    g = sub.add_parser("generate", help="print the config of one seed's case")
    g.add_argument("seed", type=int)
    args = p.parse_args()

    def refuse(problem):
        print(f"exactness_fuzz.py: error: {problem}", file=sys.stderr)
        return 2

    if not (os.path.isfile(args.binary) and os.access(args.binary, os.X_OK)):
        return refuse(f"--binary {args.binary[:200]!r} is not an executable file (build it, or give its path)")
    if args.command == "replay":
        for c in args.cases:
            if not os.path.isfile(c):
                return refuse(f"replay: {c[:200]!r} is not a file")
    work = tempfile.mkdtemp(prefix="exactness_fuzz.")
    try:
        try:
            sl = Shadowlab(args.binary, work)
        except (subprocess.CalledProcessError, ValueError, KeyError, TypeError, OSError):
            # Fourteenth probe: /bin/true as --binary ended in a JSON traceback.
            return refuse(f"--binary {args.binary[:200]!r} does not answer `list --json` as shadowlab does")
        if args.command == "generate":
            case = generate(args.seed)
            print(json.dumps(to_config(case, entries_for(sl, case, random.Random(args.seed * 7919 + 1))), indent=1))
            return 0
        if args.command == "replay":
            return 1 if replay(sl, args.cases) else 0
        problem = check_run_args(args, sl)
        if problem:
            return refuse(problem)
        try:
            os.makedirs(args.out, exist_ok=True)
            with open(os.path.join(args.out, MARK), "w") as f:
                f.write("exactness_fuzz.py output\n")
        except OSError as e:  # fourteenth probe: an --out under a file was a traceback
            return refuse(f"--out {args.out[:200]!r}: {e.strerror}")
        stats = campaign(args, sl)
        tmp = os.path.join(args.out, "report.json.tmp")
        with open(tmp, "w") as f:
            json.dump(stats, f, indent=1)
        os.replace(tmp, os.path.join(args.out, "report.json"))
        print_stats(stats)
        if args.expect_failure:
            shrunk = [f for f in stats["failures"] if "shrunk" in f]
            return 0 if shrunk else 1
        return 1 if stats["failures"] or stats["crashes"] or stats["relations_broken"] else 0
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
