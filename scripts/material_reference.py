#!/usr/bin/env python3
"""Independent per-vertex reference for qsgi with the glTF materials modelled (issue 57), with Mitsuba 3.

Development only (CI reads committed outputs; it never runs this). The same contract as
scripts/reference.py: the vertices (positions, normals, triangles) come from a qsgi frame PLY — the
points qsgi estimates at — and the output is a PLY `qsgi compare` reads, radiosity B per vertex.
What differs: the Mitsuba scene is built from the glTF itself, with its UVs, vertex colours,
textures, alpha, sidedness, transmission and emissive textures, and the direct term's shadow rays
pass through the surfaces light can pass through.

  scripts/material_reference.py SCENE.gltf QSGI_FRAME.ply OUT.ply [--spp N] [--seed S] [--sky R,G,B]
                                [--config CONFIG] [--vertices N] [--back BACK.ply] [--stats STATS.npz]
                                [--direct-only] [--threads T] [--chunk C]

Geometry. The glTF (.gltf with files or data URIs, or .glb) is flattened as qsgi does (scene roots
in order, depth-first pre-order, each node's TRIANGLES primitives in order; node matrices or TRS;
strips and fans refused), and its world positions must match the PLY's vertex for vertex (within
1e-5 of the scene's diagonal, else exit 1: the frame is of another scene, or refined by
--subdivide). Each primitive becomes a Mitsuba mesh of the PLY's positions, flat-shaded (face
normals), each triangle rewound so that its counter-clockwise side is qsgi's front (the side its
vertex normals face; scripts/helmet_reference.py oriented_faces), with its UV sets and COLOR_0 as
mesh attributes. Skins and morph targets are not posed (the position check refuses a posed frame).

Materials, per glTF 2.0 and its extensions (every value read at the hit point):
  - base colour rho = baseColorFactor x baseColorTexture (sRGB-decoded, at the texture's texCoord,
    through KHR_texture_transform, which may override texCoord) x COLOR_0 (float, or unsigned
    byte/short normalized, RGB or RGBA; linear). Lambertian (Mitsuba `diffuse`); metallic, roughness,
    specular, clearcoat, sheen, normal and occlusion maps are not modelled (a note names those used).
  - texture lookups are this script's own (drjit gathers on the decoded image, so nothing depends on
    Mitsuba's bitmap conventions): UV (0, 0) is the image's top-left corner; the sampler's magFilter
    NEAREST takes texel floor(u W), floor(v H); LINEAR (and an absent magFilter) interpolates
    bilinearly between texel centres; no mip-mapping (minFilter ignored); wrapS and wrapT each
    REPEAT (default), CLAMP_TO_EDGE or MIRRORED_REPEAT, applied per texel index.
  - alpha = baseColorFactor.a x the base colour texture's alpha (linear) x COLOR_0's alpha. MASK:
    Mitsuba `mask` whose opacity is 1 where alpha >= alphaCutoff (default 0.5) and 0 elsewhere,
    decided per hit from the point-sampled (or filtered) alpha, so holes are exact in a NEAREST
    texture; BLEND: `mask` of opacity alpha (a share 1 - alpha passes straight through, from either
    side); OPAQUE (default) ignores alpha. A `mask`'s holes are a `null` lobe: rays go straight on.
  - doubleSided: the diffuse lobe wrapped in `twosided` (both sides reflect with rho); otherwise a
    ray reaching a surface's back is absorbed (the back is black, as in qsgi's gather).
  - KHR_materials_transmission, T = transmissionFactor x the red channel of transmissionTexture
    (linear): `blendbsdf` of weight T between the diffuse lobe (rho; `twosided` when doubleSided)
    and a `thindielectric` with int_ior = ext_ior = 1, specular_reflectance 0 and
    specular_transmittance rho. With the two indices equal its Fresnel reflectance is 0, so it is a
    straight pass-through (a Null lobe, -wi) of weight rho, from either side whatever doubleSided
    says: a share T of the light goes straight on tinted by the base colour, the share 1 - T is
    reflected diffusely with the base colour — glTF's mix of the specular BTDF and the diffuse BRDF
    for a dielectric, with roughness, refraction offset and the specular (Fresnel) reflection left
    out, as issue 57 defines it. A plain `thindielectric` (eta 1.5) would instead reflect about 8 %
    specularly at normal incidence (more at grazing) and transmit untinted; a `null` cannot be
    tinted; `mask` takes a scalar opacity. metallicFactor is not read (every surface is the
    dielectric it would be with metallicFactor 0: glTF's default of 1 would make a transmissive
    material a metal that transmits nothing); a transmissive material with metallicFactor other than
    0, given or by default, is named in a note. KHR_materials_volume and _ior are ignored (noted).
  - emission L_e = emissiveFactor x emissiveTexture (sRGB) x KHR_materials_emissive_strength, a
    Mitsuba `area` emitter on the front side only (qsgi's rule), its radiance evaluated at the
    point's UV. The mesh's own UV set is the emissive texture's, so that Mitsuba's emitter samples
    (which know the UV but not the mesh's attributes) read the right texel; the other textures read
    their UV sets from mesh attributes. An emissive primitive's triangles whose texels are all black
    (checked conservatively over each triangle's UV box, a texel of margin) are left without the
    emitter, so that Mitsuba's emitter sampling (uniform by area within an emitter) does not waste
    samples on them; they emit nothing either way. Emission is not cut by alpha (a note names an
    emissive MASK or BLEND material), nor emitted from the back of a doubleSided surface.
  - the material's texture values are Python `mi.Texture` subclasses, evaluated in the JIT kernels.

Lights: emissive surfaces; KHR_lights_punctual point lights on root nodes and a CONFIG's point lights
(scripts/reference.py gltf_point_lights); a uniform sky (--sky R,G,B, or CONFIG's) as Mitsuba's
`constant` emitter.

Irradiance at vertex v (normal n), from the start point o of scripts/reference.py query_points
(1e-4 of the diagonal off the surface, 5e-4 towards the incident triangles' centroid), E = E_direct
+ E_indirect per path:
  - E_direct: light that reaches o straight from an emitter, through any chain of pass-through
    surfaces. One sample per path of each kind: an emissive triangle chosen in proportion to an
    estimate of its power (16 points of its texture, plus a floor where its UV box holds a non-black
    texel, so every point that emits can be chosen) and a point uniform on it; a cosine-weighted
    direction for the sky; every point light. Its shadow ray is traced by this script as a loop of
    Mitsuba intersections, each hit multiplying the transmittance by the hit's
    BSDF.eval_null_transmission (mask: 1 - opacity; blendbsdf: T x rho; diffuse: 0), up to 16
    surfaces (beyond: blocked). Mitsuba's own next-event estimation (sample_emitter_direction with
    visibility, scripts/reference.py's) would stop at the first such surface.
  - E_indirect: pi x the radiance along a cosine-weighted ray about n from Mitsuba's `path` integrator
    (which passes mask holes, blends and panes by sampling their Null lobes; its emitter samples are
    blocked by such surfaces, but then its BSDF-sampled paths through them take the full MIS weight,
    so it stays unbiased), minus the emission that ray sees straight on: the same transmittance loop
    along the ray summing each hit's emission (and the sky's where it escapes) times the
    transmittance before it — the expectation of what the path integrator counted before the first
    scattering, which E_direct holds. So direct light through a pane is counted once, and the split
    is reference.py's where nothing passes light.
The standard error of E is from the spread of its spp samples (reference.py per_vertex_samples).

Output B = rho_reflect x E + pi L_e, at the vertex's own texel: rho_reflect = rho x (1 - T) x (alpha
for BLEND), the share of the irradiance the surface reflects diffusely; L_e at the vertex's emissive
texel (front side). A vertex of a MASK material whose alpha is below the cutoff (in a hole: no
surface there) is not referenced (B = 0, `referenced` 0; the column is written whenever any vertex
is left out, as with --vertices, and `qsgi compare` then judges the others alone). The PLY's normals
are written as read.

--back BACK.ply: the back sides of doubleSided materials: the same irradiance with the normal
negated at their vertices (not in holes), B = rho_reflect x E_back (no emission), written with
negated normals and `referenced` 1 there, 0 elsewhere.
--stats STATS.npz: E, its standard error, rho_reflect, L_e, referenced, in_hole (and E_back,
E_back_stderr with --back) per vertex, for checks.
--direct-only: E = E_direct (for checks against analytic direct light; no path tracing).
--vertices N: N vertices only, drawn as reference.py draws them (the same seed, the same ones).

Setup: as scripts/reference.py (pip install mitsuba drjit numpy; LLVM 19 for Dr.Jit, found by
reference.py). PNG and JPEG textures are decoded by Mitsuba's Bitmap (no PIL).

Runtimes and noise, the scenes of scripts/make_material_scenes.py, --spp 1024, 2 threads (Mitsuba
3.9.1 llvm_ad_rgb), whole run: textured_floor 13 s (noise of E, sqrt(sum sigma^2 / sum E^2), 1.5 %),
vertex_colour 11 s (1.2 %), alpha_mask 16 s with --back (3.2 %: paths through a cut-out lose
Mitsuba's emitter samples), alpha_blend 16 s (3.4 %), glass_window 13 s (9.7 %: sky through a small
window; three quarters of the variance is indirect light, so about 16384 paths for 2.4 %),
emissive_texture 14 s (5.9 %), materials_room 36 s (4.7 %); 210-280 MB.

Checked on those scenes (numbers in the commit that added this script): the factor twins
(make_material_scenes.py --twins) through scripts/reference.py agree within noise region by region
(the textured floor's colour bleeding, COLOR_0, the screen as a primitive of its own); direct light
(--direct-only) agrees with numpy quadratures over the panel through the checker card, the blend card,
the window times 0.9 x tint, and over the screen, each within 0.1-1 %; a pane of transmission 1 and
white tint equals the open window and a MASK card cut out everywhere equals no card, full E, within
noise; --back equals the front of the mirrored card.
"""
import argparse
import base64
import json
import math
import os
import struct
import sys
import tempfile
import time
import urllib.parse

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import reference  # noqa: E402  (sets DRJIT_LIBLLVM_PATH before Dr.Jit loads)
from helmet_reference import node_matrix, oriented_faces  # noqa: E402

import drjit as dr  # noqa: E402
import mitsuba as mi  # noqa: E402

mi.set_variant("llvm_ad_rgb")  # before the mi.Texture subclass below

NEAREST, LINEAR = 9728, 9729
REPEAT, CLAMP, MIRROR = 10497, 33071, 33648
MAX_CHAIN = 16  # surfaces a straight ray passes through before it counts as blocked
POWER_POINTS = 16  # texture samples per emissive triangle for its sampling weight
NOT_MODELLED = ("KHR_materials_volume", "KHR_materials_ior", "KHR_materials_clearcoat", "KHR_materials_sheen",
                "KHR_materials_specular", "KHR_materials_iridescence", "KHR_materials_anisotropy",
                "KHR_materials_unlit", "KHR_materials_dispersion", "KHR_materials_diffuse_transmission",
                "KHR_materials_pbrSpecularGlossiness")


def note(message):
    print("material_reference.py: " + message, file=sys.stderr)


# ---------------------------------------------------------------------------------------------
# glTF reading: buffers, accessors (normalized integers, strides, sparse), images

COMPONENTS = {5120: ("i1", 127.0), 5121: ("u1", 255.0), 5122: ("<i2", 32767.0), 5123: ("<u2", 65535.0),
              5125: ("<u4", None), 5126: ("<f4", None)}
WIDTH = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT2": 4, "MAT3": 9, "MAT4": 16}


class Gltf:
    def __init__(self, path):
        self.path, self.folder = path, os.path.dirname(os.path.abspath(path))
        with open(path, "rb") as f:
            data = f.read()
        self.glb_bin = None
        if data[:4] == b"glTF":
            offset = 12
            self.doc = None
            while offset + 8 <= len(data):
                length, kind = struct.unpack_from("<II", data, offset)
                chunk = data[offset + 8:offset + 8 + length]
                if kind == 0x4E4F534A:
                    self.doc = json.loads(chunk)
                elif kind == 0x004E4942 and self.glb_bin is None:
                    self.glb_bin = chunk
                offset += 8 + length
            if self.doc is None:
                sys.exit(f"{path}: a GLB without a JSON chunk")
        else:
            self.doc = json.loads(data)
        self.buffers = {}

    def uri_bytes(self, uri, where):
        if uri.startswith("data:"):
            header, _, payload = uri.partition(",")
            return base64.b64decode(payload) if header.endswith(";base64") else urllib.parse.unquote_to_bytes(payload)
        path = os.path.join(self.folder, urllib.parse.unquote(uri))
        if not os.path.isfile(path):
            sys.exit(f"{self.path}: {where}: {uri} is not a file")
        with open(path, "rb") as f:
            return f.read()

    def buffer(self, i):
        if i not in self.buffers:
            b = self.doc["buffers"][i]
            self.buffers[i] = self.uri_bytes(b["uri"], f"buffers[{i}]") if "uri" in b else self.glb_bin
        return self.buffers[i]

    def view_bytes(self, i):
        v = self.doc["bufferViews"][i]
        start = v.get("byteOffset", 0)
        return self.buffer(v["buffer"])[start:start + v["byteLength"]]

    def _read(self, view, offset, component, width, count, stride=None):
        dtype, _ = COMPONENTS[component]
        size = np.dtype(dtype).itemsize
        v = self.doc["bufferViews"][view]
        stride = stride or v.get("byteStride") or size * width
        raw = np.frombuffer(self.buffer(v["buffer"]), np.uint8)
        start = v.get("byteOffset", 0) + offset
        if count and start + (count - 1) * stride + size * width > len(raw):
            sys.exit(f"{self.path}: bufferViews[{view}] read beyond its buffer")
        rows = np.lib.stride_tricks.as_strided(raw[start:], (count, size * width), (stride, 1))
        return rows.copy().view(dtype).reshape(count, width)

    def accessor(self, i):
        """Accessor i as float64 (count, width), normalized integers mapped to [0, 1] or [-1, 1]."""
        a = self.doc["accessors"][i]
        width, component = WIDTH[a["type"]], a["componentType"]
        if "bufferView" in a:
            out = self._read(a["bufferView"], a.get("byteOffset", 0), component, width, a["count"]).astype(np.float64)
        else:
            out = np.zeros((a["count"], width))
        sparse = a.get("sparse")
        if sparse:
            idx = sparse["indices"]
            where = self._read(idx["bufferView"], idx.get("byteOffset", 0), idx["componentType"], 1,
                               sparse["count"]).reshape(-1).astype(np.int64)
            val = sparse["values"]
            out[where] = self._read(val["bufferView"], val.get("byteOffset", 0), component, width, sparse["count"])
        scale = COMPONENTS[component][1]
        if a.get("normalized") and scale:
            out = np.maximum(out / scale, -1.0)
        return out

    def image_rgba(self, i):
        """Image i as float64 (H, W, 4) in [0, 1], the stored (encoded) values, decoded by Mitsuba's Bitmap."""
        im = self.doc["images"][i]
        data = self.view_bytes(im["bufferView"]) if "bufferView" in im else self.uri_bytes(im["uri"], f"images[{i}]")
        suffix = ".jpg" if data[:2] == b"\xff\xd8" else ".png"
        with tempfile.NamedTemporaryFile(suffix=suffix) as f:
            f.write(data)
            f.flush()
            bitmap = mi.Bitmap(f.name)
        a = np.array(bitmap)
        scale = {np.dtype(np.uint8): 255.0, np.dtype(np.uint16): 65535.0}.get(a.dtype, 1.0)
        a = a.astype(np.float64) / scale
        if a.ndim == 2:
            a = a[:, :, None]
        channels = a.shape[2]
        if channels == 1:
            a = np.concatenate([a, a, a, np.ones_like(a)], 2)
        elif channels == 2:
            a = np.concatenate([a[:, :, :1]] * 3 + [a[:, :, 1:]], 2)
        elif channels == 3:
            a = np.concatenate([a, np.ones_like(a[:, :, :1])], 2)
        return a


def srgb_to_linear(c):
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


# ---------------------------------------------------------------------------------------------
# Textures: a lookup (glTF sampler rules) and the Mitsuba texture built on it

def wrap_index(i, n, mode, xp):
    """Texel index i (float, integral) wrapped into [0, n) as glTF's sampler says; xp: np or dr."""
    if mode == CLAMP:
        return xp.clip(i, 0, n - 1) if xp is np else dr.clip(i, 0, n - 1)
    if mode == MIRROR:
        m = i - 2 * n * xp.floor(i / (2 * n))
        return xp.where(m < n, m, 2 * n - 1 - m) if xp is np else dr.select(m < n, m, 2 * n - 1 - m)
    return i - n * xp.floor(i / n)


class TextureLookup:
    """One textureInfo: the decoded image (linear RGBA, as its role says), its sampler, its UV set and
    KHR_texture_transform."""

    def __init__(self, gltf, info, srgb, where):
        doc = gltf.doc
        texture = doc["textures"][info["index"]]
        source = texture.get("source")
        if source is None:
            sys.exit(f"{gltf.path}: {where}: textures[{info['index']}] has no source image")
        rgba = gltf.image_rgba(source)
        if srgb:
            rgba[:, :, :3] = srgb_to_linear(rgba[:, :, :3])
        self.image = rgba
        self.height, self.width = rgba.shape[:2]
        self.data = mi.Float(rgba.astype(np.float32).ravel())
        sampler = doc["samplers"][texture["sampler"]] if "sampler" in texture else {}
        self.nearest = sampler.get("magFilter") == NEAREST
        self.wrap_s, self.wrap_t = sampler.get("wrapS", REPEAT), sampler.get("wrapT", REPEAT)
        self.tex_coord = info.get("texCoord", 0)
        self.matrix = np.eye(3)
        transform = info.get("extensions", {}).get("KHR_texture_transform")
        if transform:
            ox, oy = transform.get("offset", [0.0, 0.0])
            r = transform.get("rotation", 0.0)
            sx, sy = transform.get("scale", [1.0, 1.0])
            c, s = math.cos(r), math.sin(r)
            self.matrix = (np.array([[1, 0, ox], [0, 1, oy], [0, 0, 1.0]]) @ np.array([[c, s, 0], [-s, c, 0], [0, 0, 1.0]])
                           @ np.array([[sx, 0, 0], [0, sy, 0], [0, 0, 1.0]]))
            self.tex_coord = transform.get("texCoord", self.tex_coord)

    def transform_np(self, uv):
        return uv @ self.matrix[:2, :2].T + self.matrix[:2, 2]

    def lookup(self, u, v):
        """RGBA (four mi.Float) at texture coordinates (u, v) (mi.Float, before the transform)."""
        m = self.matrix
        tu = float(m[0, 0]) * u + float(m[0, 1]) * v + float(m[0, 2])
        tv = float(m[1, 0]) * u + float(m[1, 1]) * v + float(m[1, 2])
        w, h = self.width, self.height

        def fetch(ix, iy):
            index = mi.UInt32(wrap_index(iy, h, self.wrap_t, dr) * w + wrap_index(ix, w, self.wrap_s, dr)) * 4
            return [dr.gather(mi.Float, self.data, index + c) for c in range(4)]

        if self.nearest:
            return fetch(dr.floor(tu * w), dr.floor(tv * h))
        x, y = tu * w - 0.5, tv * h - 0.5
        x0, y0 = dr.floor(x), dr.floor(y)
        fx, fy = x - x0, y - y0
        c00, c10, c01, c11 = fetch(x0, y0), fetch(x0 + 1, y0), fetch(x0, y0 + 1), fetch(x0 + 1, y0 + 1)
        return [(c00[k] * (1 - fx) + c10[k] * fx) * (1 - fy) + (c01[k] * (1 - fx) + c11[k] * fx) * fy for k in range(4)]

    def lookup_np(self, uv):
        """RGBA (n, 4) at the given untransformed UVs, through the same code (for vertices)."""
        values = self.lookup(mi.Float(uv[:, 0].astype(np.float32)), mi.Float(uv[:, 1].astype(np.float32)))
        return np.stack([np.array(c, np.float64) for c in values], 1)

    def max_over_boxes(self, uv_triangles, channels):
        """For each triangle's UVs (n, 3, 2), the largest value of `channels` over the texels its UV box
        touches, a texel of margin (conservative for NEAREST and LINEAR)."""
        t = np.stack([self.transform_np(uv_triangles[:, k]) for k in range(3)], 1)
        values = self.image[:, :, channels].max(2)
        out = np.zeros(len(t))
        for f in range(len(t)):
            ranges = []
            for axis, n, mode in ((0, self.width, self.wrap_s), (1, self.height, self.wrap_t)):
                lo, hi = math.floor(t[f, :, axis].min() * n) - 1, math.floor(t[f, :, axis].max() * n) + 1
                idx = np.arange(lo, hi + 1, dtype=np.float64) if hi - lo < 2 * n + 2 else np.arange(n, dtype=np.float64)
                ranges.append(np.unique(wrap_index(idx, n, mode, np).astype(np.int64)))
            out[f] = values[np.ix_(ranges[1], ranges[0])].max()
        return out


class GltfTexture(mi.Texture):
    """A material quantity at a surface point, as glTF defines it. role: "rgb" (factor x texture.rgb x
    COLOR_0.rgb), "alpha" (factor x texture.a x COLOR_0.a), "mask" (alpha >= cutoff: 1, else 0), "red"
    (factor x texture.r: transmission), "emission" (factor x texture.rgb; the UV is the mesh's own, si.uv)."""

    def __init__(self, props):
        mi.Texture.__init__(self, props)

    def setup(self, role, factor, lookup=None, cutoff=0.5, name=""):
        self.role, self.factor, self.lookup_, self.cutoff, self.name = role, factor, lookup, cutoff, name
        self.colour = role in ("rgb", "alpha", "mask")
        self.mean_, self.max_ = float(np.mean(factor)), float(np.max(factor))
        if lookup is not None:
            channel = {"rgb": slice(0, 3), "emission": slice(0, 3), "red": slice(0, 1)}.get(role, slice(3, 4))
            self.mean_ *= float(lookup.image[:, :, channel].mean())
            self.max_ *= float(lookup.image[:, :, channel].max())
        return self

    def _texel(self, si, active):
        if self.lookup_ is None:
            return None
        if self.role == "emission":
            u, v = si.uv.x, si.uv.y
        else:
            uv = si.shape.eval_attribute_3("vertex_uv%d" % self.lookup_.tex_coord, si, active)
            u, v = uv.x, uv.y
        return self.lookup_.lookup(u, v)

    def eval(self, si, active=True):
        texel = self._texel(si, active)
        c = mi.Color3f(*[float(x) for x in self.factor[:3]])
        if texel is not None:
            c = c * mi.Color3f(texel[0], texel[1], texel[2])
        if self.colour:
            c = c * si.shape.eval_attribute_3("vertex_color", si, active)
        return c

    def eval_3(self, si, active=True):
        return self.eval(si, active)

    def eval_1(self, si, active=True):
        texel = self._texel(si, active)
        value = mi.Float(float(self.factor[0]))
        if self.role == "red":
            return value * texel[0] if texel is not None else value
        if texel is not None:
            value = value * texel[3]
        value = value * si.shape.eval_attribute_1("vertex_alpha", si, active)
        if self.role == "mask":
            return dr.select(value >= self.cutoff, mi.Float(1.0), mi.Float(0.0))
        return value

    def mean(self):
        return self.mean_

    def max(self):
        return self.max_

    def is_spatially_varying(self):
        # False: an `area` emitter then samples its shape uniformly by area and evaluates this at the
        # sample's UV (Mitsuba's other path would need a UV parameterisation in [0, 1]^2).
        return False

    def to_string(self):
        return f"GltfTexture[{self.name} {self.role}]"


mi_texture_registered = False


def new_texture(*args, **kwargs):
    global mi_texture_registered
    if not mi_texture_registered:
        mi.register_texture("gltf_material_texture", lambda props: GltfTexture(props))
        mi_texture_registered = True
    return GltfTexture(mi.Properties()).setup(*args, **kwargs)


# ---------------------------------------------------------------------------------------------
# Materials

class Material:
    def __init__(self, gltf, index):
        where = f"materials[{index}]" if index is not None else "the default material"
        m = gltf.doc["materials"][index] if index is not None else {}
        self.name = m.get("name", where)
        pbr = m.get("pbrMetallicRoughness", {})
        ext = m.get("extensions", {})
        self.base_factor = np.array(pbr.get("baseColorFactor", [1, 1, 1, 1]), np.float64)
        self.base_tex = TextureLookup(gltf, pbr["baseColorTexture"], True, where) if "baseColorTexture" in pbr else None
        self.alpha_mode = m.get("alphaMode", "OPAQUE")
        self.cutoff = m.get("alphaCutoff", 0.5)
        if not (isinstance(self.cutoff, (int, float)) and self.cutoff >= 0):
            sys.exit(f"{gltf.path}: {where}.alphaCutoff {self.cutoff!r} is not a non-negative number")
        self.double_sided = bool(m.get("doubleSided", False))
        tr = ext.get("KHR_materials_transmission")
        self.transmission = float(tr.get("transmissionFactor", 0.0)) if tr else 0.0
        if not 0 <= self.transmission <= 1:
            sys.exit(f"{gltf.path}: {where} transmissionFactor {self.transmission} is outside [0, 1]")
        self.transmission_tex = (TextureLookup(gltf, tr["transmissionTexture"], False, where)
                                 if tr and "transmissionTexture" in tr else None)
        self.transmissive = self.transmission > 0
        strength = ext.get("KHR_materials_emissive_strength", {}).get("emissiveStrength", 1.0)
        self.emission = np.array(m.get("emissiveFactor", [0, 0, 0]), np.float64) * strength
        self.emissive_tex = TextureLookup(gltf, m["emissiveTexture"], True, where) if "emissiveTexture" in m else None
        self.emissive = self.emission.max() > 0 and (self.emissive_tex is None or self.emissive_tex.image[:, :, :3].max() > 0)
        ignored = [k for k in ("metallicRoughnessTexture",) if k in pbr] + [k for k in ("normalTexture", "occlusionTexture")
                                                                            if k in m]
        ignored += [k for k in ext if k in NOT_MODELLED]
        if ignored:
            note(f"{where} ({self.name}): not modelled: {', '.join(ignored)}")
        if self.transmissive and pbr.get("metallicFactor", 1.0) != 0:
            note(f"{where} ({self.name}): transmissive with metallicFactor {pbr.get('metallicFactor', 1.0)} "
                 f"({'given' if 'metallicFactor' in pbr else 'the default'}): read as a dielectric (metallic 0)")
        if self.emissive and self.alpha_mode != "OPAQUE":
            note(f"{where} ({self.name}): emissive and {self.alpha_mode}: its emission is not cut by alpha here")
        if self.emissive and self.double_sided:
            note(f"{where} ({self.name}): emissive and doubleSided: it emits from its front only here")
        # The UV set the mesh carries as its own (Mitsuba's emitter samples read that one).
        self.primary_set = self.emissive_tex.tex_coord if self.emissive_tex else 0
        self.uv_sets = {t.tex_coord for t in (self.base_tex, self.transmission_tex, self.emissive_tex) if t}
        self._bsdf = self._emission_texture = None

    def bsdf(self):
        if self._bsdf is None:
            rho = new_texture("rgb", self.base_factor[:3], self.base_tex, name=self.name)
            surface = mi.load_dict({"type": "diffuse", "reflectance": rho})
            if self.double_sided:
                surface = mi.load_dict({"type": "twosided", "bsdf": surface})
            if self.transmissive:
                weight = new_texture("red", [self.transmission], self.transmission_tex, name=self.name)
                through = mi.load_dict({"type": "thindielectric", "int_ior": 1.0, "ext_ior": 1.0,
                                        "specular_reflectance": {"type": "uniform", "value": 0.0},
                                        "specular_transmittance": rho})
                surface = mi.load_dict({"type": "blendbsdf", "weight": weight, "bsdf_0": surface, "bsdf_1": through})
            if self.alpha_mode in ("MASK", "BLEND"):
                role = "mask" if self.alpha_mode == "MASK" else "alpha"
                opacity = new_texture(role, [self.base_factor[3]], self.base_tex, cutoff=self.cutoff, name=self.name)
                surface = mi.load_dict({"type": "mask", "opacity": opacity, "bsdf": surface})
            self._bsdf = surface
        return self._bsdf

    def emission_texture(self):
        if self._emission_texture is None:
            self._emission_texture = new_texture("emission", self.emission, self.emissive_tex, name=self.name)
        return self._emission_texture

    # Per-vertex values (numpy), through the same lookups
    def vertex_values(self, uvs, colour):
        """rho (n, 3), alpha (n,), T (n,), L_e (n, 3) at vertices with UV sets `uvs` and COLOR_0 `colour` (n, 4)."""
        n = len(colour)
        rho = np.tile(self.base_factor[:3], (n, 1)) * colour[:, :3]
        alpha = np.full(n, self.base_factor[3]) * colour[:, 3]
        if self.base_tex:
            texel = self.base_tex.lookup_np(uvs[self.base_tex.tex_coord])
            rho *= texel[:, :3]
            alpha *= texel[:, 3]
        T = np.full(n, self.transmission)
        if self.transmission_tex:
            T *= self.transmission_tex.lookup_np(uvs[self.transmission_tex.tex_coord])[:, 0]
        Le = np.tile(self.emission, (n, 1))
        if self.emissive_tex:
            Le *= self.emissive_tex.lookup_np(uvs[self.emissive_tex.tex_coord])[:, :3]
        return rho, alpha, T, Le


# ---------------------------------------------------------------------------------------------
# Flattening (qsgi's order) with UVs and COLOR_0

class Primitive:
    pass


def flatten(gltf):
    doc = gltf.doc
    prims, offset = [], 0

    def visit(n, parent):
        nonlocal offset
        node = doc["nodes"][n]
        world = parent @ node_matrix(node)
        if "mesh" in node:
            for k, prim in enumerate(doc["meshes"][node["mesh"]]["primitives"]):
                mode = prim.get("mode", 4)
                if mode not in (4, 5, 6):
                    continue
                where = f"meshes[{node['mesh']}].primitives[{k}]"
                if mode != 4:
                    sys.exit(f"{gltf.path}: {where}: triangle strips and fans are not read here")
                attrs = prim["attributes"]
                p = gltf.accessor(attrs["POSITION"])
                index = (gltf.accessor(prim["indices"]).reshape(-1).astype(np.int64) if "indices" in prim
                         else np.arange(len(p)))
                q = Primitive()
                q.where, q.material, q.offset, q.count = where, prim.get("material"), offset, len(p)
                q.positions = p @ world[:3, :3].T + world[:3, 3]
                q.faces = index.reshape(-1, 3)
                q.uvs = {}
                for s in range(8):
                    if f"TEXCOORD_{s}" in attrs:
                        q.uvs[s] = gltf.accessor(attrs[f"TEXCOORD_{s}"])[:, :2]
                colour = np.ones((len(p), 4))
                if "COLOR_0" in attrs:
                    a = doc["accessors"][attrs["COLOR_0"]]
                    if a["type"] not in ("VEC3", "VEC4") or a["componentType"] not in (5126, 5121, 5123) or (
                            a["componentType"] != 5126 and not a.get("normalized")):
                        sys.exit(f"{gltf.path}: {where}: COLOR_0 must be float, or normalized unsigned byte or short, "
                                 f"VEC3 or VEC4")
                    c = gltf.accessor(attrs["COLOR_0"])
                    colour[:, :c.shape[1]] = c
                q.colour = colour
                prims.append(q)
                offset += len(p)
        for c in node.get("children", []):
            visit(c, world)

    for n in doc["scenes"][doc.get("scene", 0)]["nodes"]:
        visit(n, np.eye(4))
    return prims


# ---------------------------------------------------------------------------------------------
# The Mitsuba scene

def make_mesh(name, positions, faces, uv_primary, attributes, bsdf, emitter):
    props = mi.Properties()
    props["bsdf"] = bsdf
    if emitter is not None:
        props["emitter"] = emitter
    mesh = mi.Mesh(name, len(positions), len(faces), props=props, has_vertex_normals=False, has_vertex_texcoords=True)
    params = mi.traverse(mesh)
    params["vertex_positions"] = mi.Float(positions.astype(np.float32).ravel())
    params["vertex_texcoords"] = mi.Float(uv_primary.astype(np.float32).ravel())
    params["faces"] = mi.UInt32(faces.astype(np.uint32).ravel())
    params.update()
    for key, value in attributes.items():
        mesh.add_attribute(key, value.shape[1], mi.Float(value.astype(np.float32).ravel()))
    return mesh


class EmitterTable:
    """Every emitting triangle (oriented), with its power estimate, for this script's direct light."""

    def __init__(self):
        self.p, self.uv, self.slot, self.weight, self.textures = [], [], [], [], []

    def add(self, texture, tri_positions, tri_uv, weights):
        self.textures.append(texture)
        self.p.append(tri_positions)
        self.uv.append(tri_uv)
        self.slot.append(np.full(len(tri_positions), len(self.textures) - 1))
        self.weight.append(weights)

    def finish(self):
        if not self.p:
            self.count = 0
            return
        p, uv = np.concatenate(self.p), np.concatenate(self.uv)
        weight = np.concatenate(self.weight)
        keep = weight > 0
        p, uv, weight, slot = p[keep], uv[keep], weight[keep], np.concatenate(self.slot)[keep]
        self.count = len(p)
        if not self.count:
            return
        cross = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
        area = 0.5 * np.linalg.norm(cross, axis=1)
        self.normal = cross / np.maximum(2 * area, 1e-30)[:, None]
        f = lambda a: mi.Float(np.ascontiguousarray(a, np.float32))  # noqa: E731
        self.corners = [[f(p[:, k, c]) for c in range(3)] for k in range(3)]
        self.uvs = [[f(uv[:, k, c]) for c in range(2)] for k in range(3)]
        self.normals = [f(self.normal[:, c]) for c in range(3)]
        self.area = f(area)
        self.slots = mi.UInt32(slot.astype(np.uint32))
        self.distribution = mi.DiscreteDistribution(f(weight))
        self.power_share = weight / weight.sum()


def triangle_power_weights(texture, material, tri_positions, tri_uv):
    """Sampling weights: area x (the mean luminance of L_e at POWER_POINTS points + a floor where the UV box
    holds a texel that emits); 0 where it cannot emit."""
    n = len(tri_positions)
    area = 0.5 * np.linalg.norm(np.cross(tri_positions[:, 1] - tri_positions[:, 0],
                                         tri_positions[:, 2] - tri_positions[:, 0]), axis=1)
    if material.emissive_tex is None:
        return area * float(material.emission.mean())
    box_max = material.emissive_tex.max_over_boxes(tri_uv, [0, 1, 2]) * float(material.emission.max())
    side = int(round(math.sqrt(POWER_POINTS)))
    a, b = np.meshgrid((np.arange(side) + 0.5) / side, (np.arange(side) + 0.5) / side)
    a, b = a.ravel(), b.ravel()
    s = np.sqrt(a)
    b1, b2 = s * (1 - b), s * b  # stratified uniform points of a triangle
    b0 = 1 - b1 - b2
    uv = (b0[None, :, None] * tri_uv[:, None, 0] + b1[None, :, None] * tri_uv[:, None, 1]
          + b2[None, :, None] * tri_uv[:, None, 2]).reshape(-1, 2)
    si = dr.zeros(mi.SurfaceInteraction3f, len(uv))
    si.uv = mi.Point2f(mi.Float(uv[:, 0].astype(np.float32)), mi.Float(uv[:, 1].astype(np.float32)))
    c = texture.eval(si)
    le = np.stack([np.array(c.x), np.array(c.y), np.array(c.z)], 1).astype(np.float64).reshape(n, len(a), 3).mean(2).mean(1)
    return np.where(box_max > 0, area * (le + 0.05 * box_max), 0.0)


def build_scene(gltf, prims, materials, positions, faces_oriented, point_lights, sky):
    shapes = {"type": "scene", "integrator": {"type": "path", "max_depth": 64, "rr_depth": 8}}
    table = EmitterTable()
    for i, q in enumerate(prims):
        mat = materials[q.material]
        for s in mat.uv_sets:
            if s not in q.uvs:
                sys.exit(f"{gltf.path}: {q.where} lacks TEXCOORD_{s}, which {mat.name} reads")
        v0, v1 = q.offset, q.offset + q.count
        local = faces_oriented[q.faces_range] - v0
        zero = np.zeros((q.count, 2))
        uv_attr = {f"vertex_uv{s}": np.concatenate([q.uvs.get(s, zero), np.zeros((q.count, 1))], 1) for s in (0, 1)}
        attributes = dict(uv_attr, vertex_color=q.colour[:, :3], vertex_alpha=q.colour[:, 3:4])
        uv_primary = q.uvs.get(mat.primary_set, zero)
        pos = positions[v0:v1]
        emitting = np.zeros(len(local), bool)
        if mat.emissive:
            tri_uv = uv_primary[local]
            emitting = (mat.emissive_tex.max_over_boxes(tri_uv, [0, 1, 2]) > 0) if mat.emissive_tex else np.ones(len(local), bool)
        for part, members in (("", ~emitting), ("_emitter", emitting)):
            if not members.any():
                continue
            emitter = None
            if part:
                emitter = mi.load_dict({"type": "area", "radiance": mat.emission_texture()})
                tri_pos, tri_uv = pos[local[members]], uv_primary[local[members]]
                table.add(mat.emission_texture(), tri_pos, tri_uv,
                          triangle_power_weights(mat.emission_texture(), mat, tri_pos, tri_uv))
            shapes[f"prim{i:05d}{part}"] = make_mesh(f"prim{i}{part}", pos, local[members], uv_primary, attributes,
                                                     mat.bsdf(), emitter)
    for k, (p, intensity) in enumerate(point_lights):
        shapes[f"light{k}"] = {"type": "point", "position": list(p), "intensity": {"type": "rgb", "value": list(intensity)}}
    if sky is not None:
        shapes["sky"] = {"type": "constant", "radiance": {"type": "rgb", "value": list(sky)}}
    table.finish()
    return mi.load_dict(shapes), table


# ---------------------------------------------------------------------------------------------
# Light transport

def channel_max(c):
    return dr.maximum(dr.maximum(c.x, c.y), c.z)


def transmittance(scene, o, d, dist, active):
    """The transmittance of the straight segment from o along d (unit) for dist (inf: to the sky), through
    every pass-through surface on it (BSDF.eval_null_transmission at each hit; 0 at an opaque one)."""
    T = mi.Color3f(1.0)
    finite = not (isinstance(dist, float) and math.isinf(dist))
    ray = mi.Ray3f(o, d)
    if finite:
        ray.maxt = dist * (1 - 1e-4)
        target = o + d * dist
    active = mi.Bool(active)
    for _ in range(MAX_CHAIN):
        si = scene.ray_intersect(ray, active)
        hit = active & si.is_valid()
        t = si.bsdf(ray).eval_null_transmission(si, hit)
        T = dr.select(hit, T * t, T)
        active = hit & (channel_max(T) > 0)
        ray = si.spawn_ray_to(target) if finite else si.spawn_ray(d)
        dr.eval(T, active, ray)
        if not dr.any(active):
            break
    return dr.select(active, mi.Color3f(0.0), T)


def seen_emission(scene, ray, active=True):
    """The emission a ray sees straight on: each hit's (and the sky's) times the transmittance before it."""
    D, T = mi.Color3f(0.0), mi.Color3f(1.0)
    active = mi.Bool(active)
    d = ray.d
    for _ in range(MAX_CHAIN):
        si = scene.ray_intersect(ray, active)
        emitted = si.emitter(scene).eval(si, active)
        D = dr.select(active, D + T * emitted, D)
        hit = active & si.is_valid()
        t = si.bsdf(ray).eval_null_transmission(si, hit)
        T = dr.select(hit, T * t, mi.Color3f(0.0))
        active = hit & (channel_max(T) > 0)
        ray = si.spawn_ray(d)
        dr.eval(D, T, active, ray)
        if not dr.any(active):
            break
    return D


def make_sampler_function(scene, table, point_lights, sky, direct_only):
    integrator = scene.integrator()

    def direct(o, n, sampler):
        E = mi.Color3f(0.0)
        if table.count:
            index, pmf = table.distribution.sample_pmf(sampler.next_1d())
            b = mi.warp.square_to_uniform_triangle(sampler.next_2d())
            w0, w1, w2 = 1 - b.x - b.y, b.x, b.y
            g = lambda arr: dr.gather(mi.Float, arr, index)  # noqa: E731
            corner = [mi.Point3f(*[g(table.corners[k][c]) for c in range(3)]) for k in range(3)]
            y = corner[0] * w0 + corner[1] * w1 + corner[2] * w2
            uvc = [mi.Point2f(*[g(table.uvs[k][c]) for c in range(2)]) for k in range(3)]
            si = dr.zeros(mi.SurfaceInteraction3f)
            si.uv = uvc[0] * w0 + uvc[1] * w1 + uvc[2] * w2
            slot = dr.gather(mi.UInt32, table.slots, index)
            Le = mi.Color3f(0.0)
            for k, texture in enumerate(table.textures):
                Le = dr.select(slot == k, texture.eval(si), Le)
            ny = mi.Vector3f(*[g(table.normals[c]) for c in range(3)])
            to = y - o
            dist = dr.norm(to)
            d = to / dist
            cos_x, cos_y = dr.dot(n, d), -dr.dot(ny, d)
            ok = (cos_x > 0) & (cos_y > 0) & (pmf > 0)
            geometry = dr.select(ok, cos_x * cos_y * g(table.area) / (dist * dist * pmf), 0.0)
            T = transmittance(scene, o, d, dist, ok)
            E += Le * T * geometry
        if sky is not None:
            d = mi.Frame3f(n).to_world(mi.warp.square_to_cosine_hemisphere(sampler.next_2d()))
            E += mi.Color3f(*sky) * dr.pi * transmittance(scene, o, d, math.inf, True)
        for p, intensity in point_lights:
            to = mi.Point3f(*[float(c) for c in p]) - o
            dist = dr.norm(to)
            d = to / dist
            cos_x = dr.dot(n, d)
            T = transmittance(scene, o, d, dist, cos_x > 0)
            E += mi.Color3f(*[float(c) for c in intensity]) * T * dr.maximum(cos_x, 0) / (dist * dist)
        return E

    def sample(o, n, sampler):
        E = direct(o, n, sampler)
        if direct_only:
            return E
        d = mi.Frame3f(n).to_world(mi.warp.square_to_cosine_hemisphere(sampler.next_2d()))
        ray = mi.Ray3f(o, d)
        L, _, _ = integrator.sample(scene, sampler, ray)
        return E + dr.pi * (L - seen_emission(scene, ray))

    return sample


# ---------------------------------------------------------------------------------------------

def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("scene")
    ap.add_argument("frame_ply")
    ap.add_argument("out")
    ap.add_argument("--spp", type=int, default=1024, help="paths per vertex (default 1024)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--config", help="qsgi config whose point lights and sky are added")
    ap.add_argument("--sky", help="R,G,B: a uniform sky of this radiance, as qsgi's --sky")
    ap.add_argument("--vertices", type=int, help="only this many vertices, drawn uniformly (as reference.py)")
    ap.add_argument("--back", metavar="BACK.ply", help="also the back sides of doubleSided materials (see above)")
    ap.add_argument("--stats", metavar="STATS.npz", help="per-vertex E, its standard error and the materials (see above)")
    ap.add_argument("--direct-only", action="store_true", help="E = E_direct only (checks)")
    ap.add_argument("--threads", type=int, default=0, help="Dr.Jit worker threads (0: all cores)")
    ap.add_argument("--chunk", type=int, default=0, help="vertices per wavefront (0: about 2^19 paths a wavefront)")
    args = ap.parse_args()
    if args.vertices is not None and args.vertices < 1:
        ap.error("--vertices must be at least 1")
    if args.spp < 1:
        ap.error("--spp must be at least 1")

    if args.threads > 0:
        dr.set_thread_count(args.threads)
    started = time.time()
    positions, normals, ply_faces = reference.read_ply(args.frame_ply)
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-30)
    gltf = Gltf(args.scene)
    prims = flatten(gltf)
    g_positions = np.concatenate([q.positions for q in prims]) if prims else np.zeros((0, 3))
    if len(g_positions) != len(positions):
        sys.exit(f"{args.frame_ply} has {len(positions)} vertices but {args.scene} flattens to {len(g_positions)}")
    diagonal = float(np.linalg.norm(positions.max(0) - positions.min(0)))
    worst = float(np.abs(g_positions - positions).max())
    if worst > 1e-5 * max(1.0, diagonal):
        sys.exit(f"{args.frame_ply}: its vertices are not {args.scene}'s in qsgi's order (off by {worst:.3g})")
    faces = np.concatenate([q.faces + q.offset for q in prims])
    start = 0
    for q in prims:
        q.faces_range = slice(start, start + len(q.faces))
        start += len(q.faces)
    oriented, flipped = oriented_faces(positions, normals, faces)
    materials = {}
    for q in prims:
        if q.material not in materials:
            materials[q.material] = Material(gltf, q.material)
    sky = [float(c) for c in args.sky.split(",")] if args.sky else reference.config_sky(args.config)
    if sky is not None and len(sky) == 1:
        sky = sky * 3
    point_lights = reference.gltf_point_lights(args.scene, args.config)
    scene, table = build_scene(gltf, prims, materials, positions, oriented, point_lights, sky)
    if table.count == 0 and sky is None and not point_lights:
        note("the scene has no light (no emissive triangle, sky or point light)")

    # Per-vertex materials: rho_reflect, L_e, holes, double-sidedness.
    n = len(positions)
    rho_reflect, Le, in_hole, two_sided = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n, bool), np.zeros(n, bool)
    for q in prims:
        mat = materials[q.material]
        v = slice(q.offset, q.offset + q.count)
        rho, alpha, T, emission = mat.vertex_values(q.uvs, q.colour)
        share = (1 - T) * (alpha if mat.alpha_mode == "BLEND" else 1.0)
        rho_reflect[v] = rho * share[:, None]
        Le[v] = emission
        if mat.alpha_mode == "MASK":
            in_hole[v] = alpha < mat.cutoff
        two_sided[v] = mat.double_sided

    chosen = np.arange(n)
    if args.vertices is not None and args.vertices < n:
        chosen = np.sort(np.random.default_rng(args.seed).choice(n, args.vertices, replace=False))
    selected = np.zeros(n, bool)
    selected[chosen] = True
    referenced = selected & ~in_hole
    chunk = args.chunk or max(1, (1 << 19) // args.spp)
    sample = make_sampler_function(scene, table, point_lights, sky, args.direct_only)
    built = time.time() - started

    origins = reference.query_points(positions, normals, ply_faces, diagonal)
    which = np.flatnonzero(referenced)
    E, E_err = np.zeros((n, 3)), np.zeros((n, 3))
    t0 = time.time()
    E[which], E_err[which] = reference.per_vertex_samples(origins[which], normals[which], args.spp, args.seed, chunk, sample)
    seconds = time.time() - t0
    B = rho_reflect * E + np.pi * Le
    B[~referenced] = 0
    kind = "direct light only" if args.direct_only else "path tracer"
    comment = (f"qsgi material reference: Mitsuba {mi.__version__} {kind} with the glTF materials, {args.spp} paths + "
               f"emitter samples per vertex, shadow rays through pass-through surfaces, seed {args.seed}, "
               f"{len(which)} of {n} vertices ({int(in_hole.sum())} in MASK holes), {seconds:.0f} s")
    reference.write_ply(args.out, positions, normals, ply_faces, B, comment,
                        None if referenced.all() else referenced.astype(np.uint8))
    print(comment)
    print(f"  scene built in {built:.1f} s; {len(prims)} primitives, {len(materials)} materials, {table.count} emitting "
          f"triangles, {flipped} triangles rewound to qsgi's front; {dr.thread_count()} threads")
    stats = dict(E=E, E_stderr=E_err, rho_reflect=rho_reflect, Le=Le, referenced=referenced, in_hole=in_hole,
                 spp=args.spp, seed=args.seed, seconds=seconds, direct_only=args.direct_only)

    if args.back:
        back = np.flatnonzero(two_sided & selected & ~in_hole)
        back_origins = reference.query_points(positions, -normals, ply_faces, diagonal)
        E_back, E_back_err = np.zeros((n, 3)), np.zeros((n, 3))
        t0 = time.time()
        if len(back):
            E_back[back], E_back_err[back] = reference.per_vertex_samples(back_origins[back], -normals[back], args.spp,
                                                                          args.seed + 7919, chunk, sample)
        back_ref = np.zeros(n, np.uint8)
        back_ref[back] = 1
        B_back = rho_reflect * E_back
        B_back[back_ref == 0] = 0
        comment_back = (f"qsgi material reference, back sides of doubleSided materials (normals negated): Mitsuba "
                        f"{mi.__version__} {kind}, {args.spp} paths + emitter samples per vertex, seed {args.seed}, "
                        f"{len(back)} of {n} vertices, {time.time() - t0:.0f} s")
        reference.write_ply(args.back, positions, -normals, ply_faces, B_back, comment_back, back_ref)
        print(comment_back)
        stats.update(E_back=E_back, E_back_stderr=E_back_err, back_referenced=back_ref.astype(bool))
    if args.stats:
        np.savez_compressed(args.stats, **stats)


if __name__ == "__main__":
    main()
