#!/usr/bin/env python3
"""`ulam radiosity`'s photometry against analytic cases in the spirit of CIE 171:2006, every scene and
luminaire file written here: a point source's direct illuminance on a plane (E = I cos / d^2, exact:
no noise), an area source's illuminance by Lambert's contour integral, the diffuse furnace (E = M /
(1 - rho) lux at any point, L = E / pi on it), a two-surface enclosure (a dome over a disc: uniform
radiosity on each, from the 2 x 2 system), the EN 12464-1 work plane of a point source (E mean,
E min, U0 against sums of I cos / d^2), the flux in lm, and malformed input refused with its line.
Monte Carlo answers are checked to 4 sigma of their reported standard error; fixed seeds.
Run from the source root: photometry_test.py path/to/ulam
"""
import json
import math
import os
import re
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ulam_status import code  # noqa: E402  (the enum of include/ulam.h)

ULAM = sys.argv[1]


def run(args, code=0):
    p = subprocess.run([ULAM, "radiosity"] + args, capture_output=True, text=True, timeout=600)
    if p.returncode != code:
        sys.exit(f"exit {p.returncode} (expected {code}) for {args}:\n{p.stdout}\n{p.stderr}")
    return p


def write(d, name, text):
    path = os.path.join(d, name)
    with open(path, "w") as f:
        f.write(text)
    return path


def obj(d, name, verts, faces, mtl):
    """An OBJ scene of faces (material, vertex indices from 1) and its MTL (name -> (Kd, Ke))."""
    lines = [f"mtllib {name}.mtl"] + [f"v {x!r} {y!r} {z!r}" for x, y, z in verts]
    cur = None
    for m, f in faces:
        if m != cur:
            lines += [f"o {m}", f"usemtl {m}"]
            cur = m
        lines.append("f " + " ".join(str(i) for i in f))
    write(d, name + ".mtl", "".join(f"newmtl {m}\nKd {kd} {kd} {kd}\nKe {ke} {ke} {ke}\n" for m, (kd, ke) in mtl.items()))
    return write(d, name + ".obj", "\n".join(lines) + "\n")


def isotropic_cosine_ies(d):
    """A rotationally symmetric table, linear in gamma between 10-degree steps: I = 200 - gamma for
    gamma <= 90, 0 above."""
    g = list(range(0, 181, 10))
    cd = [200 - a if a <= 90 else 0 for a in g]
    return write(d, "lamp.ies", "IESNA:LM-63-2002\n[TEST] linear in gamma\nTILT=NONE\n"
                 f"1 1000 1 {len(g)} 1 1 2 0 0 0\n1.0 1.0 10\n" + " ".join(map(str, g)) + "\n0\n" +
                 " ".join(map(str, cd)) + "\n")


def intensity(gamma):
    return 200 - gamma if gamma <= 90 else 0.0


def floor_scene(d, s):
    """A 4 x 4 m black floor at y = 0 in units of 1/s m (s = 1000: millimetres)."""
    v = [(-2 * s, 0, -2 * s), (2 * s, 0, -2 * s), (2 * s, 0, 2 * s), (-2 * s, 0, 2 * s)]
    return obj(d, "floor", v, [("black", (4, 3, 2, 1))], {"black": (0, 0)})


def check_point_source(d):
    """Direct illuminance of a point source 2.5 m over the floor, the scene in millimetres."""
    lamp = isotropic_cosine_ies(d)
    scene = floor_scene(d, 1000.0)
    pts = [(0.3, 0.0, 0.2), (1.1, 0.0, -0.7), (-1.9, 0.0, 1.3)]
    args = [scene, "--unit", "mm", "--luminaire", f"{lamp}@0,2500,0", "--walks", "256", "--json"]
    for x, y, z in pts:
        args += ["--at", f"{x * 1000},{y},{z * 1000}"]
    out = json.loads(run(args).stdout)
    ph = out["photometry"]
    # the table's flux: trapezoid in gamma of (200 - g) sin g, exact for the linear pieces (checked by the
    # library test); here its order of magnitude and the stated rated flux
    assert abs(ph["luminaires"][0]["rated_lm"] - 1000) < 1e-9, ph
    for (x, y, z), p in zip(pts, ph["points"]):
        dist = math.sqrt(x * x + 2.5 ** 2 + z * z)
        cos = 2.5 / dist
        gamma = math.degrees(math.acos(cos))
        E = intensity(gamma) * cos / dist ** 2
        assert abs(p["illuminance_lx"] - E) <= 1e-9 * E, (p, E)
        assert p["illuminance_lx_stderr"] == 0 and p["luminance_cd_m2"] == 0, p  # black floor: no reflection


def contour_factor(x, n, poly):
    """Lambert's contour integral: the form factor from a differential area at x (unit normal n) to
    polygon poly (seen from x, counter-clockwise about its own normal facing x), sum over edges of
    angle(a, b) n . (a x b) / |a x b| / (2 pi)."""
    F = 0.0
    for i in range(len(poly)):
        a = [poly[i][k] - x[k] for k in range(3)]
        b = [poly[(i + 1) % len(poly)][k] - x[k] for k in range(3)]
        c = [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
        lc = math.sqrt(sum(t * t for t in c))
        la, lb = math.sqrt(sum(t * t for t in a)), math.sqrt(sum(t * t for t in b))
        ang = math.acos(max(-1.0, min(1.0, sum(a[k] * b[k] for k in range(3)) / (la * lb))))
        F += ang * sum(n[k] * c[k] for k in range(3)) / lc
    return abs(F) / (2 * math.pi)


def check_area_source(d):
    """A 1 x 0.6 m Lambertian panel (Ke = 500 lm/m2) tilted 30 degrees over a black floor, in mm."""
    s = 1000.0
    t = math.radians(30)
    # panel corners: centred at (0.4, 1.2, 0.1) m, spanning u = (1, 0, 0) and v = (0, -sin t, cos t) ... facing down-ish
    c = (0.4, 1.2, 0.1)
    u = (0.5, 0.0, 0.0)
    v = (0.0, 0.3 * math.sin(t), 0.3 * math.cos(t))
    panel = [tuple(c[k] + su * u[k] + sv * v[k] for k in range(3)) for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1))]
    # face it downward: normal = u x v must have y < 0, else reverse
    nrm = (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])
    if nrm[1] > 0:
        panel = panel[::-1]
    verts = [(-2 * s, 0, -2 * s), (2 * s, 0, -2 * s), (2 * s, 0, 2 * s), (-2 * s, 0, 2 * s)] + \
        [tuple(p * s for p in q) for q in panel]
    scene = obj(d, "panel", verts, [("black", (4, 3, 2, 1)), ("panel", (5, 6, 7, 8))],
                {"black": (0, 0), "panel": (0, 500)})
    pts = [(0.2, 0.0, 0.3), (-1.0, 0.0, 0.9), (1.5, 0.0, -1.2)]
    args = [scene, "--unit", "mm", "--rel-err", "0.003", "--seed", "3", "--json"]
    for x, y, z in pts:
        args += ["--at", f"{x * s},{y},{z * s}"]
    out = json.loads(run(args).stdout)
    for (x, y, z), p in zip(pts, out["photometry"]["points"]):
        E = 500.0 * contour_factor((x, y, z), (0, 1, 0), panel)
        zscore = (p["illuminance_lx"] - E) / p["illuminance_lx_stderr"]
        print(f"  E {p['illuminance_lx']:.6g} lx, truth {E:.6g}, z = {zscore:+.2f}")
        assert abs(zscore) < 4, (p, E, zscore)
        assert p["illuminance_lx_ci95_lo"] <= E * (1 + 1e-9) and E <= p["illuminance_lx_ci95_hi"] * (1 + 1e-9) or \
            abs(zscore) < 4, (p, E)


def check_furnace(d):
    """A closed 3 m cube, every face Ke = 100 lm/m2 and Kd = 0.6: E = 100 / 0.4 = 250 lx everywhere, L = 250 / pi."""
    s = 3.0
    v = [(x * s, y * s, z * s) for x in (0, 1) for y in (0, 1) for z in (0, 1)]  # index 1 + 4x + 2y + z
    i = lambda x, y, z: 1 + 4 * x + 2 * y + z  # noqa: E731
    faces = [
        ("wall", (i(0, 0, 0), i(1, 0, 0), i(1, 0, 1), i(0, 0, 1))),  # floor y = 0
        ("wall", (i(0, 1, 0), i(0, 1, 1), i(1, 1, 1), i(1, 1, 0))),  # ceiling
        ("wall", (i(0, 0, 0), i(0, 0, 1), i(0, 1, 1), i(0, 1, 0))),  # x = 0
        ("wall", (i(1, 0, 0), i(1, 1, 0), i(1, 1, 1), i(1, 0, 1))),  # x = s
        ("wall", (i(0, 0, 0), i(0, 1, 0), i(1, 1, 0), i(1, 0, 0))),  # z = 0
        ("wall", (i(0, 0, 1), i(1, 0, 1), i(1, 1, 1), i(0, 1, 1))),  # z = s
    ]
    faces = [(m, f[::-1]) for m, f in faces]  # counter-clockwise seen from inside
    scene = obj(d, "furnace", v, faces, {"wall": (0.6, 100)})
    out = json.loads(run([scene, "--at", "1.1,0,0.7", "--at", "3,1.3,2.2", "--at", "1.5,1.5,1.5,0.3,0.4,0.5",
                          "--unit", "m", "--rel-err", "0.004", "--json"]).stdout)
    for k, p in enumerate(out["photometry"]["points"]):
        zscore = (p["illuminance_lx"] - 250.0) / p["illuminance_lx_stderr"]
        print(f"  E {p['illuminance_lx']:.6g} lx, truth {250.0:.6g}, z = {zscore:+.2f}")
        assert abs(zscore) < 4, (k, p)
        if k < 2:
            zl = (p["luminance_cd_m2"] - 250.0 / math.pi) / (0.6 * p["illuminance_lx_stderr"] / math.pi)
            assert abs(zl) < 4, (k, p)
        else:
            assert p["luminance_cd_m2"] is None, p  # a sensor in the air: no surface, no luminance


def check_two_surface(d):
    """A hemispherical dome (radius 1 m, Kd 0.7) over a disc (Kd 0.3, Ke 1000 lm/m2): on a sphere every
    point sees the disc with form factor 1/2 and the dome with 1/2, so radiosity is uniform on each:
    B2 = rho2 B1 / (2 - rho2), B1 = M / (1 - rho1 rho2 / (2 - rho2)); E on the disc = B2, on the dome
    (B1 + B2) / 2.  The dome is faceted (96 x 24): its vertices on the sphere, the facets' chords
    inside it; what that moves is measured below against the answer's own error."""
    nphi, nth, R = 96, 24, 1.0
    verts = [(0.0, 0.0, 0.0), (0.0, R, 0.0)]  # disc centre 1, pole 2
    ring = lambda j, i: 3 + (j - 1) * nphi + (i % nphi)  # noqa: E731  ring j = 1 (equator) .. nth - 1
    for j in range(1, nth):
        th = math.pi / 2 * (j - 1) / (nth - 1)  # elevation of ring j: 0 at the equator
        for i in range(nphi):
            ph = 2 * math.pi * i / nphi
            verts.append((R * math.cos(th) * math.cos(ph), R * math.sin(th), R * math.cos(th) * math.sin(ph)))
    faces = []
    for i in range(nphi):  # the disc: a fan from the centre, normal +y
        faces.append(("disc", (1, ring(1, i + 1), ring(1, i))))
    for j in range(1, nth - 1):
        for i in range(nphi):
            faces.append(("dome", (ring(j, i), ring(j, i + 1), ring(j + 1, i + 1), ring(j + 1, i))))
    for i in range(nphi):
        faces.append(("dome", (ring(nth - 1, i), ring(nth - 1, i + 1), 2)))

    def inward(f):  # orient each dome face toward the centre
        p = [verts[k - 1] for k in f]
        a = [p[1][k] - p[0][k] for k in range(3)]
        b = [p[2][k] - p[0][k] for k in range(3)]
        n = (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
        c = [sum(q[k] for q in p) / len(p) for k in range(3)]
        return f if sum(n[k] * c[k] for k in range(3)) < 0 else f[::-1]
    faces = [(m, inward(f) if m == "dome" else f) for m, f in faces]
    scene = obj(d, "dome", verts, faces, {"disc": (0.3, 1000), "dome": (0.7, 0)})
    r1, r2, M = 0.3, 0.7, 1000.0
    B1 = M / (1 - r1 * r2 / (2 - r2))
    B2 = r2 * B1 / (2 - r2)
    # a point inside a disc triangle, and the centroid of a dome facet half way up
    fa = faces[nphi + (nth // 2) * nphi + 5][1]
    c = [sum(verts[k - 1][m] for k in fa) / len(fa) for m in range(3)]
    out = json.loads(run([scene, "--at", "0.31,0,0.12", "--at", ",".join(repr(t) for t in c), "--unit", "m",
                          "--rel-err", "0.005", "--seed", "5", "--json"]).stdout)
    for p, E in zip(out["photometry"]["points"], (B2, (B1 + B2) / 2)):
        zscore = (p["illuminance_lx"] - E) / p["illuminance_lx_stderr"]
        print(f"  E {p['illuminance_lx']:.6g} lx, truth {E:.6g}, z = {zscore:+.2f}")
        assert abs(zscore) < 4, (p, E, zscore)


def sphere(nphi, nth, R):
    """A faceted sphere of radius R about the origin: vertices on it, quads between rings and triangles at
    the poles, each face counter-clockwise seen from inside; (vertices, faces)."""
    verts = [(0.0, -R, 0.0), (0.0, R, 0.0)]
    ring = lambda j, i: 3 + (j - 1) * nphi + (i % nphi)  # noqa: E731  rings 1 .. nth - 1, south to north
    for j in range(1, nth):
        th = -math.pi / 2 + math.pi * j / nth
        for i in range(nphi):
            ph = 2 * math.pi * i / nphi
            verts.append((R * math.cos(th) * math.cos(ph), R * math.sin(th), R * math.cos(th) * math.sin(ph)))
    faces = [(1, ring(1, i), ring(1, i + 1)) for i in range(nphi)]
    faces += [(ring(j, i), ring(j, i + 1), ring(j + 1, i + 1), ring(j + 1, i)) for j in range(1, nth - 1)
              for i in range(nphi)]
    faces += [(ring(nth - 1, i), ring(nth - 1, i + 1), 2) for i in range(nphi)]
    out = []
    for f in faces:
        p = [verts[k - 1] for k in f]
        a = [p[1][k] - p[0][k] for k in range(3)]
        b = [p[2][k] - p[0][k] for k in range(3)]
        n = (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
        c = [sum(q[k] for q in p) / len(p) for k in range(3)]
        out.append(f if sum(n[k] * c[k] for k in range(3)) < 0 else f[::-1])
    return verts, out


def check_integrating_sphere(d):
    """A luminaire off-centre in a sphere (radius 2 m, Kd 0.8): on a sphere G(x, y) = 1 / A for any two
    of its points, so the reflected illuminance is the same everywhere, rho Phi / (A (1 - rho)) (Phi the
    flux the walls receive, A their area) whatever the luminaire and its place, and the patch-mean first
    bounce the luminaire's light goes through is exact there (only patch totals matter).  E = that + the
    direct I cos / d^2, within 4 sigma; the flux line equals the table's flux to the midpoint rule."""
    lamp = isotropic_cosine_ies(d)
    R, rho = 2.0, 0.8
    verts, faces = sphere(64, 32, R)
    scene = obj(d, "sphere", verts, [("wall", f) for f in faces], {"wall": (rho, 0)})
    pos = (0.3, 0.5, -0.2)
    # the walls' area and two points on facets: the centroids of a south and a north facet
    area = 0.0
    for f in faces:
        p = [verts[k - 1] for k in f]
        for t in range(1, len(p) - 1):
            a = [p[t][k] - p[0][k] for k in range(3)]
            b = [p[t + 1][k] - p[0][k] for k in range(3)]
            area += 0.5 * math.sqrt((a[1] * b[2] - a[2] * b[1]) ** 2 + (a[2] * b[0] - a[0] * b[2]) ** 2 +
                                    (a[0] * b[1] - a[1] * b[0]) ** 2)
    pts = []
    for f in (faces[64 * 3 + 7], faces[64 * 20 + 40]):
        pts.append([sum(verts[k - 1][m] for k in f) / len(f) for m in range(3)])
    args = [scene, "--luminaire", f"{lamp}@{pos[0]},{pos[1]},{pos[2]}", "--rel-err", "0.005", "--seed", "9", "--json"]
    for x in pts:
        args += ["--at", ",".join(repr(t) for t in x)]
    out = json.loads(run(args).stdout)
    ph = out["photometry"]
    phi = ph["flux_onto_surfaces_lm"]
    table = ph["luminaires"][0]["flux_lm"]
    assert abs(phi / table - 1) < 2e-3, (phi, table)  # all of it lands (the midpoint rule's error)
    indirect = rho * phi / (area * (1 - rho))
    for x, p in zip(pts, ph["points"]):
        v = [pos[k] - x[k] for k in range(3)]
        dist = math.sqrt(sum(t * t for t in v))
        n = out["points"][ph["points"].index(p)]["normal"]  # the facet's own normal
        cos = sum(v[k] * n[k] for k in range(3)) / dist
        gamma = math.degrees(math.acos(v[1] / dist))  # from the lamp toward x (-v) against the nadir -y
        E = intensity(gamma) * cos / dist ** 2 + indirect
        zscore = (p["illuminance_lx"] - E) / p["illuminance_lx_stderr"]
        print(f"  E {p['illuminance_lx']:.6g} lx, truth {E:.6g}, z = {zscore:+.2f}")
        assert abs(zscore) < 4, (p, E, zscore)


def check_many_emitters(d):
    """A faceted sphere (Kd 0.5) whose 2048 facets each emit their own Ke (more than 64 groups of one
    emission and normal: the score bounds group emitters by normal and power, as the luminaires'
    first bounce makes them): on a sphere H = sum_p A_p Ke_p / (A (1 - rho)) at every point.  The
    95% intervals of 40 points (each its own seed) cover it at least 33 times (the 0.999 binomial
    lower bound at 0.95 is 33)."""
    verts, faces = sphere(64, 32, 1.0)
    mats, tot, area = {}, 0.0, 0.0
    fs = []
    for k, f in enumerate(faces):
        ke = 50 + 450 * ((k * 7919) % 2048) / 2047.0  # 2048 different emissions
        mats[f"m{k}"] = (0.5, ke)
        fs.append((f"m{k}", f))
        p = [verts[i - 1] for i in f]
        a = 0.0
        for t in range(1, len(p) - 1):
            u = [p[t][m] - p[0][m] for m in range(3)]
            v = [p[t + 1][m] - p[0][m] for m in range(3)]
            a += 0.5 * math.sqrt((u[1] * v[2] - u[2] * v[1]) ** 2 + (u[2] * v[0] - u[0] * v[2]) ** 2 +
                                 (u[0] * v[1] - u[1] * v[0]) ** 2)
        tot += a * ke
        area += a
    scene = obj(d, "lit_sphere", verts, fs, mats)
    H = tot / area / (1 - 0.5)
    args = [scene, "--unit", "m", "--walks", "1000", "--seed", "11", "--json"]
    for k in range(40):
        f = faces[(k * 97) % len(faces)]
        args += ["--at", ",".join(repr(sum(verts[i - 1][m] for i in f) / len(f)) for m in range(3))]
    pts = json.loads(run(args).stdout)["photometry"]["points"]
    covered = sum(p["illuminance_lx_ci95_lo"] <= H <= p["illuminance_lx_ci95_hi"] for p in pts)
    print(f"  {covered} of 40 intervals cover {H:.6g} lx")
    assert covered >= 33, (covered, H, pts[:3])


def check_workplane(d):
    """EN 12464-1 on a 6 x 4 m black room floor lit by the table 2.5 m up: E mean, E min, E max and U0
    of the grid's points against I cos / d^2 at the very same points (exact: no reflection)."""
    lamp = isotropic_cosine_ies(d)
    s = 1.0
    v = [(0, 0, 0), (6 * s, 0, 0), (6 * s, 0, 4 * s), (0, 0, 4 * s)]
    scene = obj(d, "room", v, [("black", (4, 3, 2, 1))], {"black": (0, 0)})
    csv = os.path.join(d, "grid.csv")
    p = run([scene, "--luminaire", f"{lamp}@3,2.5,2", "--en12464", "0,0,0:6,0,4", "--walks", "256",
             "--out", csv, "--json"])
    wp = json.loads(p.stdout)["photometry"]["workplane"]
    grid = json.loads(p.stdout)["grid"]
    assert grid["nu"] == 9 and grid["nv"] == 5, grid  # 5 x 3 m inside the band, p = 0.616 m
    E = []
    for i in range(9):
        for j in range(5):
            x, z = 0.5 + 5 * (i + 0.5) / 9, 0.5 + 3 * (j + 0.5) / 5
            dist = math.sqrt((x - 3) ** 2 + 2.5 ** 2 + (z - 2) ** 2)
            cos = 2.5 / dist
            E.append(intensity(math.degrees(math.acos(cos))) * cos / dist ** 2)
    mean = sum(E) / len(E)
    for key, val in (("mean_lx", mean), ("min_lx", min(E)), ("max_lx", max(E)), ("u0", min(E) / mean)):
        assert abs(wp[key] - val) <= 1e-9 * val, (key, wp[key], val)
        assert wp[key + "_lo" if key != "u0" else "u0_lo"] == wp[key] or abs(wp[key + "_lo" if key != "u0" else "u0_lo"] - wp[key]) < 1e-9 * val
    text = run([scene, "--luminaire", f"{lamp}@3,2.5,2", "--en12464", "0,0,0:6,0,4", "--walks", "256"]).stdout
    assert re.search(r"EN 12464-1 +grid 9 x 5 .*over 5 x 3 m .*p = 0.2 x 5\^log10\(5\) = 0.616 m", text), text
    assert re.search(r"U0 = E min / E mean 0\.\d+ \(0\.\d+ \.\. 0\.\d+\)", text), text


def check_examples(d):
    """examples/luminaires: the IES file and its EULUMDAT twin give the same flux and the same lux."""
    scene = floor_scene(d, 1000.0)
    res = []
    for f in ("downlight.ies", "downlight.ldt"):
        out = json.loads(run([scene, "--unit", "mm", "--luminaire", f"examples/luminaires/{f}@100,2400,-300",
                              "--at", "500,0,700", "--at", "-1500,0,100", "--walks", "256", "--json"]).stdout)
        res.append(out["photometry"])
    a, b = res
    assert abs(a["luminaires"][0]["flux_lm"] - b["luminaires"][0]["flux_lm"]) < 1e-9 * a["luminaires"][0]["flux_lm"]
    assert a["luminaires"][0]["rated_lm"] == b["luminaires"][0]["rated_lm"] == 1000
    for p, q in zip(a["points"], b["points"]):
        assert abs(p["illuminance_lx"] - q["illuminance_lx"]) <= 1e-9 * p["illuminance_lx"] and p["illuminance_lx"] > 0
    # a patch run's JSON carries the luminaires and the flux too; its text the patch's luminance
    args = ["examples/scenes/cornell_box.obj", "--unit", "mm", "--luminaire",
            "examples/luminaires/downlight.ies@278,540,280", "--direct", "--ff-rays", "100", "--patch", "floor"]
    ph = json.loads(run(args + ["--json"]).stdout)["photometry"]
    assert ph["luminaires"][0]["rated_lm"] == 1000 and 0 < ph["flux_onto_surfaces_lm"] < ph["luminaires"][0]["flux_lm"]
    assert re.search(r"luminance +[0-9.]+ cd/m2 \(B_Y / pi\)", run(args).stdout)


def check_refused(d):
    """Malformed luminaires and options: a located message, no partial output."""
    bad = write(d, "bad.ies", "IESNA:LM-63-2002\nTILT=NONE\n1 1000 1 3 1 1 2 0 0 0\n1 1 10\n0 90 180\n0\n1 oops 3\n")
    scene = floor_scene(d, 1.0)
    p = run([scene, "--luminaire", f"{bad}@0,2,0", "--at", "0.1,0,0.1"], code=code("ESYNTAX"))
    assert re.search(r"bad.ies:7: error: .*a candela value", p.stderr) and p.stdout == "", (p.stderr, p.stdout)
    p = run([scene, "--luminaire", "nothing.ies@0,2", "--at", "0.1,0,0.1"], code=2)
    assert "--luminaire expects FILE@x,y,z" in p.stderr, p.stderr
    p = run([scene, "--luminaire", f"{bad}@0,2,0,0,-1,0,0,-1,0", "--at", "0.1,0,0.1"], code=2)
    assert "--luminaire expects" in p.stderr, p.stderr
    lamp = isotropic_cosine_ies(d)
    mm = floor_scene(d, 1000.0)  # 4000 units across with no --unit: lux would be 1e6 too high, so a warning
    p = run([mm, "--luminaire", f"{lamp}@0,2500,0", "--at", "100,0,100", "--walks", "100"])
    assert re.search(r"warning: .*4000 units across, read as metres.*--unit mm", p.stderr), p.stderr
    assert "warning" not in run([mm, "--luminaire", f"{lamp}@0,2500,0", "--at", "100,0,100", "--walks", "100",
                                 "--unit", "mm"]).stderr
    p = run([scene, "--unit", "furlong", "--at", "0.1,0,0.1"], code=2)
    assert "--unit" in p.stderr, p.stderr
    p = run([scene, "--en12464", "0,0,0:0.8,0,3", "--walks", "10"], code=2)
    assert "wall band" in p.stderr, p.stderr
    p = run([scene, "--en12464", "0,0,0:3,0,3", "--grid", "0,0,0:1,0,1:2x2"], code=2)
    assert "not with --grid" in p.stderr, p.stderr


def check_first_bounce_time(d):
    """The luminaires' first bounce (every patch's direct light: 2.6e7 shadow rays here, 6400 patches
    and 500 luminaires) ignored --time: it now stops at --time, prints nothing and says how far it
    got (it would have to finish to print anything true)."""
    scene = floor_scene(d, 1)
    lamp = isotropic_cosine_ies(d)
    args = [scene, "--subdivide", "0.05", "--at", "0.1,0,0.1", "--walks", "100", "--time", "0.5"]
    for k in range(500):
        args += ["--luminaire", f"{lamp}@{(k % 25) * 0.16 - 2:.2f},2.5,{(k // 25) * 0.2 - 2:.2f}"]
    p = run(args, code=code("ENOCONV"))
    m = re.search(r"error: --time ran out during the luminaires' direct light \((\d+) of 6400 patches lit\): nothing "
                  r"to print \(raise --time\)", p.stderr)
    assert m and int(m.group(1)) < 6400 and p.stdout == "", (p.stdout, p.stderr)
    print(f"  stopped with {m.group(1)} of 6400 patches lit")


def main():
    with tempfile.TemporaryDirectory() as d:
        for check in (check_point_source, check_area_source, check_furnace, check_two_surface, check_integrating_sphere,
                      check_many_emitters, check_workplane, check_examples,
                      check_refused, check_first_bounce_time):
            check(d)
            print(check.__name__, "ok")


if __name__ == "__main__":
    main()
