"""`halfback.emit(spec, "materialx")`: the document uses MaterialX 1.38's nodes with their input
names and types (pbrlib_defs.mtlx, restated below), its links resolve, and the graph evaluated by
an independent NumPy reading of the MaterialX specification equals halfback's model where the
two coincide (docs/fit.md, "Renderer-ready output")."""
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import halfback

# node -> {input: type}, and the node's output type (MaterialX 1.38, libraries/pbrlib/pbrlib_defs.mtlx
# and stdlib's surfacematerial; disney_brdf_2012 from libraries/bxdf).
NODEDEFS = {
    "oren_nayar_diffuse_bsdf": ({"weight": "float", "color": "color3", "roughness": "float",
                                 "normal": "vector3"}, "BSDF"),
    "generalized_schlick_bsdf": ({"weight": "float", "color0": "color3", "color90": "color3",
                                  "exponent": "float", "roughness": "vector2", "normal": "vector3",
                                  "tangent": "vector3", "distribution": "string",
                                  "scatter_mode": "string"}, "BSDF"),
    "conductor_bsdf": ({"weight": "float", "ior": "color3", "extinction": "color3",
                        "roughness": "vector2", "normal": "vector3", "tangent": "vector3",
                        "distribution": "string"}, "BSDF"),
    "dielectric_bsdf": ({"weight": "float", "tint": "color3", "ior": "float", "roughness": "vector2",
                         "normal": "vector3", "tangent": "vector3", "distribution": "string",
                         "scatter_mode": "string"}, "BSDF"),
    "add": ({"in1": "BSDF", "in2": "BSDF"}, "BSDF"),
    "surface": ({"bsdf": "BSDF", "edf": "EDF", "opacity": "float"}, "surfaceshader"),
    "surfacematerial": ({"surfaceshader": "surfaceshader", "displacementshader": "displacementshader"},
                        "material"),
    "disney_brdf_2012": ({k: "float" for k in ["metallic", "subsurface", "specular", "roughness",
                                                "specularTint", "anisotropic", "sheen", "sheenTint",
                                                "clearcoat", "clearcoatGloss"]} | {"baseColor": "color3"},
                         "surfaceshader"),
}


def parse(text):
    root = ET.fromstring(text.split("?>", 1)[1])
    assert root.tag == "materialx" and root.get("version") == "1.38"
    nodes = {}
    for el in root:
        assert el.tag in NODEDEFS, el.tag
        inputs, out = NODEDEFS[el.tag]
        assert el.get("type") == out, (el.tag, el.get("type"))
        assert el.get("name") not in nodes
        values = {}
        for i in el:
            assert i.tag == "input" and i.get("name") in inputs, (el.tag, i.get("name"))
            assert i.get("type") == inputs[i.get("name")], (el.tag, i.get("name"), i.get("type"))
            values[i.get("name")] = ("link", i.get("nodename")) if i.get("nodename") else i.get("value")
        nodes[el.get("name")] = (el.tag, values)
    for tag, values in nodes.values():  # every link names a node whose output has the input's type
        for name, v in values.items():
            if isinstance(v, tuple):
                assert v[1] in nodes, v
                assert NODEDEFS[nodes[v[1]][0]][1] == NODEDEFS[tag][0][name]
    return nodes


def floats(text):
    return np.array([float(x) for x in text.split(",")])


def fresnel_exact(eta, k, c):
    """Unpolarised Fresnel reflectance at cos θ = c of an interface to the index η + i k."""
    n = eta + 1j * k
    ct = np.sqrt(1 - (1 - c * c) / (n * n) + 0j)
    rs = (c - n * ct) / (c + n * ct)
    rp = (n * c - ct) / (n * c + ct)
    return 0.5 * (abs(rs) ** 2 + abs(rp) ** 2)


def ggx_d_g2(alpha, wi, wo, h):
    """GGX's D at ĥ and the height-correlated Smith G2 (MaterialX's microfacet BSDFs)."""
    a2 = alpha * alpha
    ch = h[:, 2]
    d = a2 / (np.pi * (ch * ch * (a2 - 1) + 1) ** 2)
    li = np.sqrt(a2 + (1 - a2) * wi[:, 2] ** 2) / wi[:, 2]
    lo = np.sqrt(a2 + (1 - a2) * wo[:, 2] ** 2) / wo[:, 2]
    return d, 2 / (li + lo)


def evaluate(nodes, name, wi, wo):
    """ρ of BSDF node `name` at the pairs (N, 3)."""
    tag, v = nodes[name]
    if tag == "add":
        return evaluate(nodes, v["in1"][1], wi, wo) + evaluate(nodes, v["in2"][1], wi, wo)
    if tag == "oren_nayar_diffuse_bsdf":
        s = float(v["roughness"]) ** 2
        a, b = 1 - 0.5 * s / (s + 0.33), 0.45 * s / (s + 0.09)
        ti, to = np.arccos(wi[:, 2]), np.arccos(wo[:, 2])
        dphi = np.arctan2(wi[:, 1], wi[:, 0]) - np.arctan2(wo[:, 1], wo[:, 0])
        f = a + b * np.maximum(0, np.cos(dphi)) * np.sin(np.maximum(ti, to)) * np.tan(np.minimum(ti, to))
        return floats(v["color"])[None, :] / np.pi * f[:, None]
    h = wi + wo
    h /= np.linalg.norm(h, axis=1)[:, None]
    c = np.sum(wi * h, axis=1)
    ax, ay = floats(v["roughness"])
    assert ax == ay
    d, g = ggx_d_g2(ax, wi, wo, h)
    if tag == "generalized_schlick_bsdf":
        c0, c90, e = floats(v["color0"]), floats(v["color90"]), float(v["exponent"])
        f = c0[None, :] + (c90 - c0)[None, :] * ((1 - c) ** e)[:, None]
    elif tag == "conductor_bsdf":
        eta, k = floats(v["ior"]), floats(v["extinction"])
        f = np.stack([fresnel_exact(eta[j], k[j], c) for j in range(3)], axis=1)
    else:
        assert tag == "dielectric_bsdf" and v["scatter_mode"] == "R"
        f = np.repeat(fresnel_exact(float(v["ior"]), 0, c)[:, None], 3, axis=1)
    return f * (d * g / (4 * wi[:, 2] * wo[:, 2]))[:, None]


def random_pairs(n, seed):
    rng = np.random.default_rng(seed)

    def dirs():
        z = rng.uniform(0.05, 1, n)
        p = rng.uniform(0, 2 * np.pi, n)
        r = np.sqrt(1 - z * z)
        return np.stack([r * np.cos(p), r * np.sin(p), z], axis=1)

    return dirs(), dirs()


@pytest.mark.parametrize("spec", [
    "lambert:albedo_r=0.7,albedo_g=0.4,albedo_b=0.2",
    "oren-nayar:albedo=0.6,sigma=0.5",
    "ggx:alpha=0.3,f0_r=0.9,f0_g=0.6,f0_b=0.3",
    "ggx:alpha=0.2,eta=0.2,k=3.1",
    "ggx:alpha=0.4,eta=1.5",
    "oren-nayar:albedo=0.3,sigma=1.1+ggx:alpha=0.05,f0=0.04+lambert:albedo=0.1",
])
def test_the_graph_is_the_model(spec):
    nodes = parse(halfback.emit(spec, "materialx", "mat"))
    tag, v = nodes["mat"]
    assert tag == "surfacematerial"
    shader = nodes[v["surfaceshader"][1]]
    assert shader[0] == "surface"
    wi, wo = random_pairs(2000, 5)
    got = evaluate(nodes, shader[1]["bsdf"][1], wi, wo)
    want = halfback.load(spec).eval(wi, wo)
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)


def test_disney_is_the_disney_node_with_burleys_parameters():
    spec = ("disney:base_color_red=0.8,base_color_green=0.3,base_color_blue=0.1,metallic=0.2,"
            "roughness=0.4,sheen=0.3,clearcoat=0.5,clearcoat_gloss=0.7")
    nodes = parse(halfback.emit(spec, "materialx", "paint"))
    tag, v = nodes[nodes["paint"][1]["surfaceshader"][1]]
    assert tag == "disney_brdf_2012"
    assert np.allclose(floats(v["baseColor"]), [0.8, 0.3, 0.1])
    assert float(v["clearcoatGloss"]) == 0.7 and float(v["sheen"]) == 0.3
    assert float(v["specular"]) == 0.5 and float(v["sheenTint"]) == 0.5  # the registry's defaults


@pytest.mark.parametrize("spec,words", [("beckmann", "GGX distribution only"),
                                        ("lambert+disney", "surface shader"),
                                        ("abc", "no 'abc' lobe")])
def test_what_materialx_cannot_express_is_refused(spec, words):
    with pytest.raises(ValueError, match=words):
        halfback.emit(spec, "materialx")


@pytest.mark.parametrize("name", ["1a", "a b", 'x"/><evil', "é"])
def test_a_materialx_name_is_an_element_name(name):
    with pytest.raises(ValueError, match="material name"):
        halfback.emit("lambert", "materialx", name=name)
