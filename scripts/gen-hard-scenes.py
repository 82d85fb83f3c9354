#!/usr/bin/env python3
"""Writes scenes/hard/*.toml (and icosphere.obj): the numerical hard cases.

The far and tiny cases are one small scene, scaled and translated; writing them
from one place keeps them the same scene. Run it from the repository root after
editing; the files it writes are committed. Each file opens with comment lines
that tests/tests/hard_cases.rs parses:
  # checks: <the property>
  # tolerance: <share of pixels off by more than 8/255 against the f64 truth, in %>
                (twice the largest share measured on any driver: see read_measured)
  # check: deterministic | cracks    (optional extra checks)
"""
import csv, math, os

OUT = os.path.join(os.path.dirname(__file__), "..", "scenes", "hard")

def v(x):
    return "[" + ", ".join(repr(float(c)) for c in x) + "]"

# The measured share of wrong pixels (off by more than 8/255 against the f64
# truth, 64x64), per driver: comparison/investigations/accuracy/gpu-tolerances.sh
# writes comparison/results/<driver>/accuracy/tolerances.csv, one row per case,
# API and run (the default and each of twinray_common::scene::hard::RUNS, the
# runs tests/tests/hard_cases.rs checks). A case's figure for a driver is the
# largest share over every run and both APIs. Each tolerance is twice the
# largest figure of any driver, but never below FLOOR, and never above the
# ceiling written at the case (the argument to header(); 0 for a case that
# promises no changed pixel). A case no driver measured keeps its ceiling.
RESULTS = os.path.join(os.path.dirname(__file__), "..", "comparison", "results")
DRIVERS = [("mesa-llvmpipe", "Mesa (lavapipe, llvmpipe)"), ("nvidia-h100", "H100"), ("nvidia-h200", "H200")]

def read_measured():
    """{driver: {case: (largest %, runs measured, runs that failed)}}; a driver without its CSV is absent."""
    out = {}
    for driver, _ in DRIVERS:
        path = os.path.join(RESULTS, driver, "accuracy", "tolerances.csv")
        if not os.path.exists(path):
            continue
        cases = {}
        with open(path) as f:
            for row in csv.DictReader(f):
                largest, n, failed = cases.get(row["case"], (0.0, 0, 0))
                if row["wrong_pct"]:
                    cases[row["case"]] = (max(largest, float(row["wrong_pct"])), n + 1, failed)
                else:
                    cases[row["case"]] = (largest, n, failed + 1)
        out[driver] = cases
    return out

MEASURED = read_measured()

def figures(name):
    """[(driver label, (largest %, runs, failed) or None)] for every driver."""
    return [(label, MEASURED.get(d, {}).get(name)) for d, label in DRIVERS]

# One pixel of the 64x64 image is 0.0244%. Where every renderer measured 0,
# twice 0 would fail on the first pixel that another driver's rounding flips
# (an edge pixel whose centre ray grazes a silhouette), so the tolerance keeps
# one pixel.
FLOOR = 0.025

def tolerance_of(name, ceiling):
    values = [f[0] for _, f in figures(name) if f and f[1] > 0]
    if not values:
        return ceiling
    return min(ceiling, max(FLOOR, math.floor(2000 * max(values)) / 1000))

def measured_line(name, tolerance, ceiling):
    def one(label, f):
        if not f or f[1] == 0:
            return f"{label} not measured"
        return f"{label} {f[0]:.3f}%" + (f" ({f[2]} runs failed)" if f[2] else "")
    found = figures(name)
    values = [f[0] for _, f in found if f and f[1] > 0]
    line = "# measured (largest over both APIs, the default and every run of hard::RUNS): " + \
        ", ".join(one(label, f) for label, f in found)
    if not values:
        rule = f"# tolerance rule: the case's own {ceiling}%, as no driver measured it"
    elif tolerance == 0 and max(values) == 0:
        rule = "# tolerance rule: none; no pixel may change, as the case promises and every driver measured"
    elif tolerance == ceiling and 2 * max(values) > ceiling:
        rule = f"# tolerance rule: the case's ceiling {ceiling}% (2x the largest measured is above it)"
    else:
        rule = f"# tolerance rule: 2x the largest measured, at least {FLOOR}% (one pixel: see FLOOR in the generator)"
    return [line, rule]

def header(name, checks, ceiling, extra=(), note=""):
    tolerance = tolerance_of(name, ceiling)
    lines = [f"# hard case: {name}", f"# checks: {checks}", f"# tolerance: {tolerance}%", *measured_line(name, tolerance, ceiling)]
    lines += [f"# check: {e}" for e in extra]
    if note:
        lines += ["#", *[f"# {l}" for l in note.strip().splitlines()]]
    lines += ["# Written by scripts/gen-hard-scenes.py; edit there.", ""]
    return "\n".join(lines) + "\n"

MATERIALS = '''
[[materials]]
name = "ground"
ambient = [0.05, 0.05, 0.05]
diffuse = [0.8, 0.8, 0.8]

[[materials]]
name = "red"
ambient = [0.05, 0.0, 0.0]
diffuse = [0.8, 0.15, 0.1]
specular = [0.3, 0.3, 0.3]
shininess = 32.0

[[materials]]
name = "blue"
ambient = [0.0, 0.0, 0.05]
diffuse = [0.1, 0.2, 0.8]
'''

def small_scene(scale, t, name, checks, tol, note):
    """A sphere and a cube on a ground quad, lit from above: shadows touch the objects."""
    p = lambda x: [c * scale + o for c, o in zip(x, t)]
    s = header(name, checks, tol, note=note)
    s += f'description = "{checks}"\n\n[camera]\neye = {v(p([0.0, 1.6, 3.2]))}\nlook_at = {v(p([0.0, 0.3, 0.0]))}\nfov_y = 45.0\n'
    s += "\n[render]\nbackground = [0.1, 0.1, 0.15]\nmax_depth = 2\n" + MATERIALS
    s += f"\n[[lights]]\nposition = {v(p([1.5, 3.0, 1.0]))}\n"
    s += f'\n[[spheres]]\ncenter = {v(p([-0.55, 0.5, 0.0]))}\nradius = {0.5 * scale!r}\nmaterial = "red"\n'
    g = 2.5
    s += f'\n[[quads]]\ncorners = [{v(p([-g, 0, -g]))}, {v(p([-g, 0, g]))}, {v(p([g, 0, g]))}, {v(p([g, 0, -g]))}]\nmaterial = "ground"\n'
    s += f'\n[[meshes]]\nobj = "../cube.obj"\nmaterial = "blue"\nscale = {0.6 * scale!r}\nrotate_y = 30.0\ntranslate = {v(p([0.6, 0.3, 0.2]))}\nsmooth = false\n'
    return s

def write(name, text):
    with open(os.path.join(OUT, name + ".toml"), "w") as f:
        f.write(text)

FAR_NOTE = """A sphere and a cube resting on a ground quad, lit from above, moved {what}.
In world coordinates f32 values there are {ulp} apart, so hit points would lie
off the surface by about that much (at 1e6, 10.6% of pixels came out wrong on
lavapipe: blocky highlights and detached contact shadows). The GPU gets every
position relative to the local origin (the camera's look-at point on a
power-of-two grid, subtracted in f64), so it traces this scene as if it lay
near the world origin; `--set origin=world` shows what that saves."""

for d in (1e4, 1e5, 1e6, 1e7):
    ulp = 2.0 ** (math.floor(math.log2(d)) - 23)
    exp = int(round(math.log10(d)))
    tol = 0.1 if exp >= 6 else 0.05
    write(f"far-1e{exp}", small_scene(1.0, [d, d, d], f"far-1e{exp}",
          f"the same object at ({d:g}, {d:g}, {d:g}): no shadow acne, no detached shadows", tol,
          FAR_NOTE.format(what=f"to ({d:g}, {d:g}, {d:g})", ulp=f"{ulp:g}")))
for s_, tol in ((1e-3, 0.5), (1e-4, 0.5)):
    exp = int(round(math.log10(s_)))
    write(f"tiny-1e{exp}", small_scene(s_, [0.0, 0.0, 0.0], f"tiny-1e{exp}",
          f"the same object scaled by {s_:g}: no shadow acne, no detached shadows", tol,
          FAR_NOTE.format(what=f"scaled down by {s_:g} (the camera too)", ulp="tiny") .replace(
              "f32 coordinates there are tiny apart, so hit points lie off the surface by\nabout that much",
              "An absolute offset (1e-4, or Wachter & Binder's 1/65536 near the origin)\nis now a large share of the object")))

# ---------------------------------------------------------------- closed mesh
def icosphere(level):
    t = (1 + 5 ** 0.5) / 2
    verts = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
             (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    verts = [tuple(c / math.sqrt(sum(x * x for x in p)) for c in p) for p in verts]
    faces = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2),
             (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11),
             (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    for _ in range(level):
        cache, nf = {}, []
        def mid(a, b):
            k = (min(a, b), max(a, b))
            if k not in cache:
                p = [(x + y) / 2 for x, y in zip(verts[a], verts[b])]
                n = math.sqrt(sum(c * c for c in p))
                verts.append(tuple(c / n for c in p))
                cache[k] = len(verts) - 1
            return cache[k]
        for a, b, c in faces:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            nf += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = nf
    return verts, faces

verts, faces = icosphere(2)
with open(os.path.join(OUT, "icosphere.obj"), "w") as f:
    f.write(f"# Icosphere, 2 subdivisions: {len(verts)} shared vertices, {len(faces)} triangles, closed.\n")
    for p in verts:
        f.write("v {:.7f} {:.7f} {:.7f}\n".format(*p))
    for a, b, c in faces:
        f.write(f"f {a + 1} {b + 1} {c + 1}\n")

C = [1000.0, 1000.0, 1000.0]
add = lambda a, b: [x + y for x, y in zip(a, b)]
s = header("closed-mesh", "a closed mesh (icosphere, 320 triangles with shared edges and vertices) seen in six orientations, 1000 units from the origin: no cracks", 0.2, extra=["cracks"],
           note="""A ray through a crack between two triangles of the front hits the inside of the
back (dark: in its own shadow) or the background (magenta). The crack check counts
pixels inside the reference silhouette (eroded by one pixel) that differ by more
than 8/255; the test allows none with the default configuration.""")
s += 'description = "closed icosphere meshes, six orientations: no cracks"\n'
s += f"\n[camera]\neye = {v(add(C, [0.0, 2.2, 6.5]))}\nlook_at = {v(add(C, [0.0, 0.0, 0.0]))}\nfov_y = 40.0\n"
s += "\n[render]\nbackground = [1.0, 0.0, 1.0]\nmax_depth = 1\n"
s += '\n[[materials]]\nname = "mesh"\nambient = [0.05, 0.05, 0.05]\ndiffuse = [0.2, 0.8, 0.3]\n'
s += f"\n[[lights]]\nposition = {v(add(C, [2.0, 6.0, 8.0]))}\n"
for i, (x, y, rot, sc) in enumerate([(-2.1, 0.9, 0.0, 1.0), (0.0, 0.9, 17.0, 0.97), (2.1, 0.9, 41.0, 1.03),
                                       (-2.1, -1.2, 63.0, 0.99), (0.0, -1.2, 89.0, 1.01), (2.1, -1.2, 131.0, 0.98)]):
    s += f'\n[[meshes]]\nobj = "icosphere.obj"\nmaterial = "mesh"\nscale = {sc!r}\nrotate_y = {rot!r}\ntranslate = {v(add(C, [x, y, 0.0]))}\nsmooth = false\n'
write("closed-mesh", s)

# ---------------------------------------------------------------- the rest
BASE_LIGHT = '\n[[lights]]\nposition = [2.0, 5.0, 4.0]\n'

def simple(name, checks, tol, body, camera, render="max_depth = 5", extra=(), note="", lights=BASE_LIGHT, materials=MATERIALS):
    s = header(name, checks, tol, extra=extra, note=note)
    s += f'description = "{checks}"\n\n[camera]\n{camera}\n\n[render]\nbackground = [0.1, 0.1, 0.15]\n{render}\n'
    s += materials + lights + body
    write(name, s)

GLASS = '''
[[materials]]
name = "glass"
specular = [0.8, 0.8, 0.8]
shininess = 200.0
transparency = 0.95
ior = 1.5
'''
CHECKER = "".join(
    f'\n[[quads]]\ncorners = [[{x}.0, 0.0, {z}.0], [{x}.0, 0.0, {z + 1}.0], [{x + 1}.0, 0.0, {z + 1}.0], [{x + 1}.0, 0.0, {z}.0]]\nmaterial = "{"ground" if (x + z) % 2 == 0 else "blue"}"\n'
    for x in range(-3, 3) for z in range(-3, 3))

simple("grazing", "grazing angles: a tiled floor seen and lit almost edge-on, a sphere on it", 1.0,
       CHECKER + '\n[[spheres]]\ncenter = [0.0, 0.4, -1.0]\nradius = 0.4\nmaterial = "red"\n',
       'eye = [0.0, 0.05, 3.0]\nlook_at = [0.0, 0.0, -3.0]\nfov_y = 30.0',
       lights='\n[[lights]]\nposition = [-40.0, 0.8, -2.0]\n',
       note="""The view ray meets the floor at about 1 degree and the light at about 1 degree:
shadow rays leave almost along the surface, where an offset along the ray adds
almost no height (acne) and the floor's edges between tiles are hit edge-on.""")

simple("inside-glass", "the camera inside a glass sphere, looking out at objects", 1.0,
       '\n[[spheres]]\ncenter = [0.0, 1.0, 0.0]\nradius = 2.0\nmaterial = "glass"\n'
       '\n[[spheres]]\ncenter = [0.0, 0.6, -4.0]\nradius = 0.6\nmaterial = "red"\n'
       '\n[[quads]]\ncorners = [[-8.0, -1.0, -8.0], [-8.0, -1.0, 8.0], [8.0, -1.0, 8.0], [8.0, -1.0, -8.0]]\nmaterial = "ground"\n',
       'eye = [0.0, 1.2, 0.5]\nlook_at = [0.0, 0.6, -4.0]\nfov_y = 60.0', render="max_depth = 6", materials=MATERIALS + GLASS,
       note="""Every primary ray starts inside glass and leaves it (ratio 1.5 -> 1): the
refracted ray must start outside, the reflected one inside; a wrong side on
either shows as noise all over the image.""")

simple("total-internal-reflection", "total internal reflection inside a glass cube seen past its critical angle", 8.0,
       '\n[[meshes]]\nobj = "../cube.obj"\nmaterial = "glass"\nscale = 1.6\nrotate_y = 35.0\ntranslate = [0.0, 0.81, 0.0]\nsmooth = false\n'
       '\n[[spheres]]\ncenter = [0.0, 0.5, -2.5]\nradius = 0.5\nmaterial = "red"\n'
       '\n[[quads]]\ncorners = [[-8.0, 0.0, -8.0], [-8.0, 0.0, 8.0], [8.0, 0.0, 8.0], [8.0, 0.0, -8.0]]\nmaterial = "ground"\n',
       'eye = [2.5, 3.5, 4.0]\nlook_at = [0.0, 0.7, 0.0]\nfov_y = 40.0', render="max_depth = 4",
       materials=MATERIALS + GLASS.replace("ior = 1.5", "ior = 2.0"),
       note="""Rays entering the top of a cube of index 2 (critical angle 30 degrees) meet the
sides beyond it: every such ray reflects inside (k < 0 in the shader) and must
stay inside, without NaN. The cube floats 0.01 above the ground: with its
bottom face on the ground plane the two coplanar faces z-fought, and that
speckle (3.5% of pixels, in the f64 reference too) was what the case measured;
coplanar faces have their own case, `coplanar`.""")

simple("thin-tubes", "the teapot's spout and handle, thin tubes of small triangles seen from 9 units: no shadow acne", 0.2,
       '\n[[meshes]]\nbpt = "../teapot.bpt"\ntessellation = [20, 15]\nmaterial = "red"\nsmooth = true\n',
       'eye = [0.0, 4.2, 8.5]\nlook_at = [2.4, 1.9, 0.0]\nfov_y = 12.0', render="max_depth = 1",
       lights='\n[[lights]]\nposition = [-6.0, 8.0, 6.0]\ncolor = [0.6, 0.55, 0.5]\n'
              '\n[[lights]]\nposition = [7.0, 5.0, 4.0]\ncolor = [0.35, 0.4, 0.5]\n'
              '\n[[lights]]\nposition = [2.5, 6.0, -8.0]\ncolor = [0.3, 0.3, 0.3]\n',
       note="""The spout and handle are tubes a few tenths across, cut into triangles a few
hundredths wide, seen from about 9 units with the teapot scene's three lights.
The hit point o + t d is off such a triangle's plane by an error that grows
with t and with how thin the triangle is; an offset of a few ULPs of the
coordinates from it re-hits the surface (speckled shadow acne). Rebuilt from
the barycentrics, the point's error stays within a few ULPs of the vertices.
With the default offset from o + t d, 0.56% of pixels came out wrong here.""")

SMALL = "".join(
    f'\n[[spheres]]\ncenter = [{-1.2 + 1.2 * j + 0.15 * i:.2f}, {0.22 + 0.04 * ((i * 3 + j) % 3) + 0.15 * ((i + j) % 2):.2f}, {-1.2 + 1.2 * i:.2f}]\n'
    f'radius = {0.22 + 0.04 * ((i * 3 + j) % 3):.2f}\nmaterial = "{"blue" if (i + j) % 2 else "red"}"\n'
    for i in range(3) for j in range(3))
simple("small-spheres", "nine spheres of radius 0.22-0.30 seen from 9.6 units, at ordinary scale: no shadow acne", 0.1,
       SMALL + '\n[[quads]]\ncorners = [[-5.0, 0.0, -5.0], [-5.0, 0.0, 5.0], [5.0, 0.0, 5.0], [5.0, 0.0, -5.0]]\nmaterial = "ground"\n',
       'eye = [1.0, 3.5, 9.0]\nlook_at = [0.0, 0.3, 0.0]\nfov_y = 22.0', render="max_depth = 1",
       lights='\n[[lights]]\nposition = [3.0, 5.0, 2.0]\ncolor = [0.6, 0.6, 0.6]\n'
              '\n[[lights]]\nposition = [-4.0, 3.0, 3.0]\ncolor = [0.5, 0.5, 0.5]\n',
       note="""Nothing here is far or tiny: spheres a few tenths across, 9.6 units from the
eye. The textbook quadratic forms b^2 - 4ac from b^2 ~ 4 D^2 (D the distance
to the sphere), so its hit point is off the surface by ~1e-7 D^2 / r, more
than the scale-aware offset (~1e-6 D) where D / r exceeds ~10: speckled
shadow acne on the spheres (4.8% of pixels wrong on lavapipe with
`--set sphere=quadratic`, 0 with the stable test).""")

simple("nested-glass", "adjacent (touching) and nested glass spheres", 1.5,
       '\n[[spheres]]\ncenter = [-0.7, 0.7, 0.0]\nradius = 0.7\nmaterial = "glass"\n'
       '\n[[spheres]]\ncenter = [0.7, 0.7, 0.0]\nradius = 0.7\nmaterial = "glass"\n'
       '\n[[spheres]]\ncenter = [0.0, 0.9, -2.0]\nradius = 0.9\nmaterial = "glass"\n'
       '\n[[spheres]]\ncenter = [0.0, 0.9, -2.0]\nradius = 0.45\nmaterial = "glass"\n'
       '\n[[spheres]]\ncenter = [0.0, 0.9, -2.0]\nradius = 0.2\nmaterial = "red"\n'
       '\n[[quads]]\ncorners = [[-8.0, 0.0, -8.0], [-8.0, 0.0, 8.0], [8.0, 0.0, 8.0], [8.0, 0.0, -8.0]]\nmaterial = "ground"\n',
       'eye = [0.0, 1.5, 4.0]\nlook_at = [0.0, 0.7, -0.6]\nfov_y = 45.0', render="max_depth = 8", materials=MATERIALS + GLASS,
       note="""Two glass spheres touch at one point; a third holds a smaller glass sphere and a
red core. Rays leave one glass surface a hair away from the next: the offset
decides whether they skip it. (The tracer assumes air outside every surface.)""")

DEGEN = "".join(f'\n[[triangles]]\nvertices = {t}\nmaterial = "red"\n' for t in [
    "[[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]]",
    "[[-1.0, 0.5, 0.0], [-1.0, 0.5, 0.0], [1.0, 0.5, 0.0]]",
    "[[-1.0, -1.0, 0.0], [0.0, 0.0, 0.0], [1.0, 1.0, 0.0]]",
    "[[-1.0, 1.0, 0.0], [0.0, 1.0, 0.0], [1.0, 1.0, 0.0]]",
    "[[0.0, -1.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 0.0]]",
    "[[-1.0, -0.5, 0.0], [1.0, -0.5, 0.0], [1e-30, -0.5, 0.0]]",
    "[[0.3, 0.3, 1.0], [0.3, 0.3, -1.0], [0.3, 0.3, 0.0]]",
])
simple("degenerate", "degenerate triangles (zero area, collinear, a point) across the view: no NaN, no hit", 0.0,
       DEGEN + '\n[[spheres]]\ncenter = [0.0, 0.0, -2.0]\nradius = 1.0\nmaterial = "blue"\n',
       'eye = [0.0, 0.0, 4.0]\nlook_at = [0.0, 0.0, 0.0]\nfov_y = 45.0',
       note="""Seven triangles with zero area lie in front of a sphere, several of them exactly
on pixel-centre rays (the image's middle row and column). None may be hit and
none may produce NaN: the image equals a render without them.""")

simple("coplanar", "coplanar overlapping triangles of two colours: a deterministic result", 10.0,
       '\n[[quads]]\ncorners = [[-1.5, -1.0, 0.0], [1.5, -1.0, 0.0], [1.5, 1.0, 0.0], [-1.5, 1.0, 0.0]]\nmaterial = "red"\n'
       '\n[[quads]]\ncorners = [[-0.5, -1.5, 0.0], [2.0, -1.5, 0.0], [2.0, 0.5, 0.0], [-0.5, 0.5, 0.0]]\nmaterial = "blue"\n',
       'eye = [0.3, 0.4, 4.0]\nlook_at = [0.2, -0.1, 0.0]\nfov_y = 50.0', extra=["deterministic"],
       note="""Two quads in the same plane overlap. Which one a pixel shows depends on the last
bit of each t, so the overlap may speckle ("z-fighting") and differ from the
f64 reference; the check is that repeated renders are identical, bit for bit,
and the tolerance covers the overlap's share of the image.""")

simple("light-on-surface", "a point light lying exactly on the floor, beside a sphere", 0.5,
       '\n[[quads]]\ncorners = [[-4.0, 0.0, -4.0], [-4.0, 0.0, 4.0], [4.0, 0.0, 4.0], [4.0, 0.0, -4.0]]\nmaterial = "ground"\n'
       '\n[[spheres]]\ncenter = [0.0, 0.5, -0.5]\nradius = 0.5\nmaterial = "red"\n',
       'eye = [0.0, 2.5, 3.5]\nlook_at = [0.0, 0.0, -0.5]\nfov_y = 45.0',
       lights='\n[[lights]]\nposition = [1.2, 0.0, 0.3]\n',
       note="""The light lies in the floor's plane: N.L is zero up to rounding, so the floor must
stay unlit (ambient only) and no pixel may divide by a zero distance; the sphere
is lit from the side.""")

simple("light-inside-sphere", "a point light inside a closed opaque sphere: nothing outside is lit", 0.2,
       '\n[[quads]]\ncorners = [[-4.0, 0.0, -4.0], [-4.0, 0.0, 4.0], [4.0, 0.0, 4.0], [4.0, 0.0, -4.0]]\nmaterial = "ground"\n'
       '\n[[spheres]]\ncenter = [0.0, 0.8, 0.0]\nradius = 0.8\nmaterial = "red"\n',
       'eye = [0.0, 2.5, 4.0]\nlook_at = [0.0, 0.5, 0.0]\nfov_y = 45.0',
       lights='\n[[lights]]\nposition = [0.2, 0.9, 0.1]\n',
       note="""The only light sits inside an opaque sphere. Every shadow ray from outside must
hit the sphere: a light leak (a missed sphere test, an offset through the
shell) lights a floor pixel.""")

# Glass that also scatters a little, so the light inside shows on every inner
# surface point it reaches, not only in highlights.
LIT_GLASS = '''
[[materials]]
name = "glass"
diffuse = [0.3, 0.3, 0.3]
specular = [0.8, 0.8, 0.8]
shininess = 200.0
transparency = 0.65
ior = 1.5
'''

simple("light-inside-glass", "a point light inside a glass sphere, near its surface: the inner surface towards it is lit, without speckles", 1.0,
       '\n[[quads]]\ncorners = [[-4.0, -2.0, -3.0], [4.0, -2.0, -3.0], [4.0, 4.0, -3.0], [-4.0, 4.0, -3.0]]\nmaterial = "ground"\n'
       '\n[[spheres]]\ncenter = [0.0, 1.1, 0.0]\nradius = 1.07\nmaterial = "glass"\n',
       'eye = [0.0, 1.1, 4.5]\nlook_at = [0.0, 1.1, 0.0]\nfov_y = 40.0',
       materials=MATERIALS + LIT_GLASS,
       lights=BASE_LIGHT + '\n[[lights]]\nposition = [0.0, 1.1, 1.0165]\ncolor = [0.8, 0.7, 0.5]\n',
       note="""A second light sits inside a glass sphere of radius 1.07, 0.95 of the radius from
its centre towards the eye, in front of a back wall. Shadow rays leave the inner
surface towards it over a short distance, where a hit point a few ULPs off the
surface in f32 is hidden by the very surface it starts on: dark speckles inside
the sphere (OpenGL on llvmpipe: 0.16 % of pixels off by more than 8/255 at
128x128 before the sphere hit's Newton step, none after).""")

simple("huge-ground", "a sphere of radius 1e6 as the ground, a small sphere resting on it", 1.0,
       '\n[[spheres]]\ncenter = [0.0, -1000000.0, 0.0]\nradius = 1000000.0\nmaterial = "ground"\n'
       '\n[[spheres]]\ncenter = [0.0, 0.5, 0.0]\nradius = 0.5\nmaterial = "red"\n',
       'eye = [0.0, 1.5, 4.0]\nlook_at = [0.0, 0.4, 0.0]\nfov_y = 45.0',
       note="""The ground's top is at y = 0, but its centre is 1e6 away: f32 can place a point
relative to that centre only to 1/16, so the ground re-hits itself unless the
offset knows the sphere's size, and the textbook quadratic loses the hit.""")

simple("far-tiny-sphere", "a sphere of radius 1 seen from 1e4 away through a narrow lens, its shadow on a wall behind", 0.5,
       '\n[[spheres]]\ncenter = [0.0, 0.0, -10000.0]\nradius = 1.0\nmaterial = "red"\n'
       '\n[[quads]]\ncorners = [[-3.0, -3.0, -10003.0], [3.0, -3.0, -10003.0], [3.0, 3.0, -10003.0], [-3.0, 3.0, -10003.0]]\nmaterial = "ground"\n',
       'eye = [0.0, 0.0, 0.0]\nlook_at = [0.0, 0.0, -10000.0]\nfov_y = 0.025',
       lights='\n[[lights]]\nposition = [3.0, 4.0, -9990.0]\n',
       note="""From 1e4 away, b^2 and c of the textbook quadratic are about 1e8 and differ by
r^2 = 1: in f32 (8 units apart at 1e8) the discriminant is noise, while the
stable form keeps it. The eye stays at the origin: from there, lanes of Mesa
22.3's SIMD vectors that are no invocation, reading the BVH as zeros, looped in
the walk until the driver's loop budget ran out, and the wall was lost in 4x4
blocks (comparison/investigations/mesa-bvh/README.md).""")
print("wrote", sorted(os.listdir(OUT)))
